//! Names the vertices of a triangle mesh around a vertex `V` of valence `K` by their cone
//! coordinates, the names the triangle stencil tables' layouts use
//! (`schemes::triangle_local::TrianglePoint`): `V` is the centre, its neighbours
//! counter-clockwise from a chosen first one are `(1, 0)` of sectors `0..K`, and every other
//! point is `(a, b)`, `a >= 1`, `b >= 0`, of the sector whose skew chart holds it (`a + b` is its
//! graph distance from `V`).
//!
//! The chart grows face by face from `V`'s fan: a triangle `(p, q, r)`, counter-clockwise, with
//! `p` and `q` named, has `r = p + R (q - p)` in `p`'s sector chart, `R (a, b) = (-b, a + b)` the
//! lattice's 60-degree turn (neighbours lie in the same or an adjacent sector, so one turn of
//! the chart relates their coordinates). Where the mesh around `V` is not the regular
//! `K`-valent cone — another irregular vertex, or a boundary, within the radius — some point
//! gets two names or none, and the chart says so instead of guessing.

use schemes::triangle_local::{canonical_triangle_point, TrianglePoint};

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::{neighbours, rotate_to};

/// The cone coordinates of the vertices within graph distance `radius` of a vertex.
#[derive(Clone, Debug)]
pub struct ConeChart {
    /// The valence `K` of the centre.
    pub valence: u32,
    radius: i64,
    /// The vertex of every point ([`NONE`] if none), by [`ConeChart::slot`].
    vertex_of: Vec<u32>,
}

/// Scratch space for charts of one mesh: which faces and vertices the current chart has seen
/// and what it named them, stamped so that nothing is cleared between charts.
#[derive(Clone, Debug)]
pub struct ConeCharts {
    stamp: u32,
    face_seen: Vec<u32>,
    vertex_seen: Vec<u32>,
    vertex_point: Vec<TrianglePoint>,
}

/// `(a, b)` turned by `turns` sixths of a full turn counter-clockwise, in skew coordinates.
fn turn(a: i64, b: i64, turns: i64) -> (i64, i64) {
    let (mut a, mut b) = (a, b);
    for _ in 0..turns.rem_euclid(6) {
        (a, b) = (-b, a + b);
    }
    (a, b)
}

/// Graph distance from the centre.
fn ring(p: TrianglePoint) -> i64 {
    match p {
        TrianglePoint::Centre => 0,
        TrianglePoint::Sector { a, b, .. } => a + b,
    }
}

impl ConeCharts {
    /// Scratch space for charts of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        ConeCharts {
            stamp: 0,
            face_seen: vec![0; mesh.faces()],
            vertex_seen: vec![0; mesh.positions.len()],
            vertex_point: vec![TrianglePoint::Centre; mesh.positions.len()],
        }
    }

    /// Name the vertices within `radius` of `centre`, with `first` (a neighbour of `centre`) as
    /// `E_0`; `Err` says where the mesh is not a regular cone around `centre`.
    pub fn chart(
        &mut self,
        mesh: &Mesh,
        centre: u32,
        first: u32,
        radius: i64,
    ) -> Result<ConeChart, String> {
        self.chart_within(mesh, centre, first, radius, |_| true)
    }

    /// [`Self::chart`], naming beyond the one-ring only the points `within` accepts (growing
    /// through the triangles whose third corner it accepts): a layout needs no more, and a
    /// regular patch's layout may lie beside an extraordinary vertex that a whole ball around
    /// its corner would wrap around (a valence-3 cone has only 180 degrees).
    pub fn chart_within(
        &mut self,
        mesh: &Mesh,
        centre: u32,
        first: u32,
        radius: i64,
        within: impl Fn(TrianglePoint) -> bool,
    ) -> Result<ConeChart, String> {
        if mesh.is_boundary_vertex(centre as usize) {
            return Err(format!("vertex {centre} is on the boundary"));
        }
        let ring0 = rotate_to(&neighbours(mesh, centre as usize), first)
            .ok_or_else(|| format!("vertex {first} is not a neighbour of {centre}"))?;
        let valence = ring0.len() as u32;
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.face_seen.fill(0);
            self.vertex_seen.fill(0);
            self.stamp = 1;
        }
        let radius = radius.max(1);
        let slots = 1 + valence as usize * (radius * (radius + 1) / 2) as usize;
        let mut chart = ConeChart {
            valence,
            radius,
            vertex_of: vec![NONE; slots],
        };
        self.name(&mut chart, centre, TrianglePoint::Centre)?;
        for (s, &e) in ring0.iter().enumerate() {
            let point = TrianglePoint::Sector {
                s: s as u32,
                a: 1,
                b: 0,
            };
            self.name(&mut chart, e, point)?;
        }
        let mut stack: Vec<usize> = mesh.fan(centre as usize);
        while let Some(h) = stack.pop() {
            let f = mesh.face_of[h] as usize;
            if self.face_seen[f] == self.stamp {
                continue;
            }
            self.face_seen[f] = self.stamp;
            let (p, q) = (mesh.face_vertices[h], mesh.head(h));
            let r = mesh.head(mesh.next(h));
            let point = self.third(valence, p, q)?;
            if ring(point) > radius || !within(point) {
                continue;
            }
            self.name(&mut chart, r, point)?;
            for g in [mesh.next(h), mesh.prev(h)] {
                match mesh.twin[g] {
                    NONE => {
                        return Err(format!(
                            "edge ({}, {}) within {radius} of vertex {centre} is on the boundary",
                            mesh.face_vertices[g],
                            mesh.head(g)
                        ))
                    }
                    t if self.face_seen[mesh.face_of[t as usize] as usize] != self.stamp => {
                        stack.push(t as usize)
                    }
                    _ => {}
                }
            }
        }
        Ok(chart)
    }

    /// Give `vertex` the name `point`, or fail if either already has another.
    fn name(
        &mut self,
        chart: &mut ConeChart,
        vertex: u32,
        point: TrianglePoint,
    ) -> Result<(), String> {
        let slot = chart.slot(point, 0).ok_or("a point beyond the radius")?;
        let seen = self.vertex_seen[vertex as usize] == self.stamp;
        let taken = chart.vertex_of[slot];
        match (seen, taken) {
            (false, NONE) => {
                self.vertex_seen[vertex as usize] = self.stamp;
                self.vertex_point[vertex as usize] = point;
                chart.vertex_of[slot] = vertex;
                Ok(())
            }
            (true, v) if v == vertex && self.vertex_point[vertex as usize] == point => Ok(()),
            _ => Err(format!(
                "vertex {vertex} is reached as two different points around the centre: the \
                 mesh there is not a regular cone"
            )),
        }
    }

    /// The name of the third corner of the counter-clockwise triangle `(p, q, r)`.
    fn third(&self, valence: u32, p: u32, q: u32) -> Result<TrianglePoint, String> {
        let named = |v: u32| {
            if self.vertex_seen[v as usize] == self.stamp {
                Ok(self.vertex_point[v as usize])
            } else {
                Err(format!("vertex {v} has no name yet"))
            }
        };
        let (p, q) = (named(p)?, named(q)?);
        let k = i64::from(valence);
        // The chart: p's sector (q's when p is the centre).
        let sector = match (p, q) {
            (TrianglePoint::Sector { s, .. }, _)
            | (TrianglePoint::Centre, TrianglePoint::Sector { s, .. }) => i64::from(s),
            _ => return Err("an edge from the centre to itself".to_owned()),
        };
        let in_chart = |x: TrianglePoint| match x {
            TrianglePoint::Centre => (0, 0),
            TrianglePoint::Sector { s, a, b } => {
                // Adjacent sectors differ by -1, 0 or 1 (mod K).
                let mut d = (i64::from(s) - sector).rem_euclid(k);
                if d > k / 2 {
                    d -= k;
                }
                turn(a, b, d)
            }
        };
        let (pa, pb) = in_chart(p);
        let (qa, qb) = in_chart(q);
        let (da, db) = turn(qa - pa, qb - pb, 1);
        Ok(canonical_triangle_point(valence, sector, pa + da, pb + db))
    }
}

impl ConeChart {
    /// Name the vertices within `radius` of `centre` (one chart; [`ConeCharts`] reuses its
    /// scratch space over many).
    pub fn new(mesh: &Mesh, centre: u32, first: u32, radius: i64) -> Result<Self, String> {
        ConeCharts::new(mesh).chart(mesh, centre, first, radius)
    }

    /// Where `point`, read `rotation` sectors on, is stored (`None` beyond the radius).
    fn slot(&self, point: TrianglePoint, rotation: u32) -> Option<usize> {
        match point {
            TrianglePoint::Centre => Some(0),
            TrianglePoint::Sector { s, a, b } => {
                let m = a + b;
                if a < 1 || b < 0 || m > self.radius {
                    return None;
                }
                let per_sector = (self.radius * (self.radius + 1) / 2) as usize;
                let s = ((s + rotation) % self.valence) as usize;
                Some(1 + s * per_sector + ((m - 1) * m / 2 + b) as usize)
            }
        }
    }

    /// The vertex named `point` in sector-`rotation` terms: `(a, b)_s` is looked up as
    /// `(a, b)_{s + rotation}` (the layouts are written for sector 0).
    pub fn vertex(&self, point: TrianglePoint, rotation: u32) -> Option<u32> {
        let v = self.vertex_of[self.slot(point, rotation)?];
        (v != NONE).then_some(v)
    }

    /// The name of `vertex`, if it is within the chart.
    pub fn point(&self, vertex: u32) -> Option<TrianglePoint> {
        let slot = self.vertex_of.iter().position(|&v| v == vertex)?;
        if slot == 0 {
            return Some(TrianglePoint::Centre);
        }
        let per_sector = (self.radius * (self.radius + 1) / 2) as usize;
        let (s, mut rest) = ((slot - 1) / per_sector, ((slot - 1) % per_sector) as i64);
        let mut m = 1;
        while rest >= m {
            rest -= m;
            m += 1;
        }
        Some(TrianglePoint::Sector {
            s: s as u32,
            a: m - rest,
            b: rest,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron};

    fn torus(m: i64) -> Mesh {
        lattice_torus(m, |a, b| [a as f64, b as f64, 0.0])
    }

    /// On the plane the cone coordinates are the lattice's, sector by sector: `(a, b)_s` is the
    /// lattice point `R^s (a, b)`.
    #[test]
    fn on_a_regular_torus_the_chart_is_the_lattice() {
        let m = 16;
        let mesh = torus(m);
        let index = |a: i64, b: i64| (a.rem_euclid(m) + m * b.rem_euclid(m)) as u32;
        let (ca, cb) = (5, 7);
        let chart = ConeChart::new(&mesh, index(ca, cb), index(ca + 1, cb), 4).expect("regular");
        assert_eq!(chart.valence, 6);
        for s in 0..6u32 {
            for a in 1..=4i64 {
                for b in 0..=4 - a {
                    let (x, y) = turn(a, b, i64::from(s));
                    let p = TrianglePoint::Sector { s, a, b };
                    assert_eq!(chart.vertex(p, 0), Some(index(ca + x, cb + y)), "{p:?}");
                }
            }
        }
        // Rotating the lookup by one sector turns the lattice by 60 degrees.
        let p = TrianglePoint::Sector { s: 0, a: 2, b: 1 };
        let (x, y) = turn(2, 1, 1);
        assert_eq!(chart.vertex(p, 1), Some(index(ca + x, cb + y)));
        // Nothing beyond the radius is named.
        assert_eq!(
            chart.vertex(TrianglePoint::Sector { s: 0, a: 5, b: 0 }, 0),
            None
        );
    }

    #[test]
    fn an_octahedron_is_a_four_valent_cone_until_it_closes() {
        let mesh = octahedron();
        let chart = ConeChart::new(&mesh, 4, 0, 1).expect("the one-ring is a cone");
        assert_eq!(chart.valence, 4);
        assert_eq!(
            chart.point(2),
            Some(TrianglePoint::Sector { s: 1, a: 1, b: 0 })
        );
        // At radius 2 the opposite pole is reached as (1,1) of every sector: not a cone.
        assert!(ConeChart::new(&mesh, 4, 0, 2).is_err());
    }
}
