//! The vertices of a regular patch's layout found by walking half-edges, instead of growing a
//! [`crate::scheme::triangle::cone_chart::ConeChart`] around the patch's corner: most triangles of an isolated
//! mesh are regular patches, and a chart per triangle (a flood fill with a name check per
//! vertex) cost seconds on meshes of a few hundred thousand triangles.
//!
//! The walk is a recipe made once per layout on the regular lattice: starting from the
//! triangle's half-edge `corner 0 -> corner 1` (the chart's `V -> E_0`), a list of `next` and
//! `twin` steps, each from a half-edge already reached, whose tails are the layout's points.
//! It crosses only edges of the layout's triangles (lattice triangles whose corners are all
//! layout points), the triangles a chart restricted to the layout (`ConeCharts::chart_within`)
//! grows through.
//!
//! On a mesh the walk develops the lattice into the mesh along its path. It **answers only
//! when the chart would give the same vertices**, and otherwise says nothing (the caller then
//! asks the chart, for its answer and its reason): when every face is a triangle, every step
//! has a twin, every vertex reached is interior of valence 6, and the layout's vertices are
//! distinct. Then the development is the same along every path through the layout's
//! triangles (they form a disc whose inner vertices are regular, so turning around one closes
//! after six triangles), so the chart names every vertex it reaches as the walk does; and since
//! the layout's vertices are distinct, no triangle the chart skips is one of the layout's, so
//! the chart reaches all of them and finds no vertex with two names.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use schemes::triangle_local::TrianglePoint;

use crate::mesh::topology::{Mesh, NONE};

/// The lattice direction `d` (sixths of a turn counter-clockwise from `(1, 0)`), in skew
/// coordinates: `(1,0), (0,1), (-1,1), (-1,0), (0,-1), (1,-1)`.
fn direction(d: usize) -> (i64, i64) {
    [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)][d % 6]
}

/// A point of the regular (valence-6) cone in lattice coordinates: `(a, b)_s` is `R^s (a, b)`,
/// `R (a, b) = (-b, a + b)` the 60-degree turn.
fn lattice_point(p: TrianglePoint) -> (i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0),
        TrianglePoint::Sector { s, a, b } => {
            let (mut a, mut b) = (a, b);
            for _ in 0..s % 6 {
                (a, b) = (-b, a + b);
            }
            (a, b)
        }
    }
}

/// A lattice half-edge: its tail and its direction. In the counter-clockwise lattice triangle
/// to its left, `next` turns by 120 degrees at the head, and the twin runs back from the head.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct LatticeHalfedge {
    tail: (i64, i64),
    d: usize,
}

impl LatticeHalfedge {
    fn head(self) -> (i64, i64) {
        let (x, y) = direction(self.d);
        (self.tail.0 + x, self.tail.1 + y)
    }

    fn next(self) -> Self {
        LatticeHalfedge {
            tail: self.head(),
            d: (self.d + 2) % 6,
        }
    }

    fn twin(self) -> Self {
        LatticeHalfedge {
            tail: self.head(),
            d: (self.d + 3) % 6,
        }
    }

    /// The corners of the triangle to the left, sorted (a name for the triangle).
    fn triangle(self) -> [(i64, i64); 3] {
        let mut t = [self.tail, self.head(), self.next().head()];
        t.sort_unstable();
        t
    }
}

/// One step of a walk: the half-edge `next` or `twin` of the half-edge reached at an earlier
/// step (index 0 is the starting half-edge).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    Next(usize),
    Twin(usize),
}

/// A walk reaching every point of a regular layout from the half-edge `V -> E_0`.
#[derive(Clone, Debug)]
pub struct LatticeWalk {
    /// Half-edge `i + 1` of a walk is `steps[i]` of an earlier one.
    steps: Vec<Step>,
    /// For every layout point, in the layout's order, the half-edge whose tail it is.
    tails: Vec<usize>,
}

impl LatticeWalk {
    /// The walk to the points of `layout` (a layout at valence 6, read in sector 0), through the
    /// lattice triangles whose corners are all layout points, breadth first from the triangle
    /// `(0,0), (1,0), (0,1)`; `None` if some point is not reached that way (then no chart
    /// restricted to the layout names it either).
    pub fn new(layout: &[TrianglePoint]) -> Option<Self> {
        let points: Vec<(i64, i64)> = layout.iter().map(|&p| lattice_point(p)).collect();
        let inside: BTreeSet<(i64, i64)> = points.iter().copied().collect();
        let start = LatticeHalfedge { tail: (0, 0), d: 0 };
        if !start.triangle().iter().all(|c| inside.contains(c)) {
            return None;
        }
        // Every half-edge reached, the step that reached it (index i + 1 <- steps[i]).
        let mut reached = vec![start];
        let mut steps: Vec<Step> = Vec::new();
        let mut tail_of: BTreeMap<(i64, i64), usize> = BTreeMap::new();
        let mut seen: BTreeSet<[(i64, i64); 3]> = BTreeSet::from([start.triangle()]);
        let mut queue = VecDeque::from([0usize]);
        let mut add = |reached: &mut Vec<LatticeHalfedge>, h: LatticeHalfedge, step: Step| {
            reached.push(h);
            steps.push(step);
            reached.len() - 1
        };
        while let Some(i) = queue.pop_front() {
            // The triangle's three half-edges, then the neighbours across each edge.
            let next = reached[i].next();
            let j = add(&mut reached, next, Step::Next(i));
            let next = reached[j].next();
            let k = add(&mut reached, next, Step::Next(j));
            for h in [i, j, k] {
                tail_of.entry(reached[h].tail).or_insert(h);
            }
            for h in [i, j, k] {
                let twin = reached[h].twin();
                let triangle = twin.triangle();
                if triangle.iter().all(|c| inside.contains(c)) && seen.insert(triangle) {
                    let t = add(&mut reached, twin, Step::Twin(h));
                    queue.push_back(t);
                }
            }
        }
        // The module docs' argument needs the layout's triangles to form a disc: they are
        // connected (all reached from the first), and a connected planar region of triangles
        // has no holes exactly when V - E + F = 1.
        let mut vertices = BTreeSet::new();
        let mut edges = BTreeSet::new();
        for t in &seen {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                vertices.insert(a);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        if vertices.len() + seen.len() != edges.len() + 1 {
            return None;
        }
        let tails: Vec<usize> = points
            .iter()
            .map(|p| tail_of.get(p).copied())
            .collect::<Option<_>>()?;
        // Keep only the steps the tails need, renumbered in order (a step's source comes
        // before it).
        let mut needed = vec![false; reached.len()];
        let mut stack = tails.clone();
        while let Some(h) = stack.pop() {
            if std::mem::replace(&mut needed[h], true) || h == 0 {
                continue;
            }
            stack.push(match steps[h - 1] {
                Step::Next(g) | Step::Twin(g) => g,
            });
        }
        let mut renumber = vec![usize::MAX; reached.len()];
        renumber[0] = 0;
        let mut kept = Vec::new();
        for h in 1..reached.len() {
            if needed[h] {
                kept.push(match steps[h - 1] {
                    Step::Next(g) => Step::Next(renumber[g]),
                    Step::Twin(g) => Step::Twin(renumber[g]),
                });
                renumber[h] = kept.len();
            }
        }
        Some(LatticeWalk {
            steps: kept,
            tails: tails.iter().map(|&h| renumber[h]).collect(),
        })
    }

    /// The half-edges a walk visits (the starting one included): its cost.
    pub fn visits(&self) -> usize {
        self.steps.len() + 1
    }

    /// The layout's vertices for the walk from half-edge `start` of a triangle mesh into
    /// `points` (cleared first), using `halfedges` as scratch space; `false` (and `points`
    /// meaningless) where the walk cannot vouch for the chart's answer: a face that is not a
    /// triangle, a step without a twin, a vertex that is not `regular` (interior of valence 6),
    /// or a vertex reached twice.
    pub fn walk(
        &self,
        mesh: &Mesh,
        start: usize,
        regular: &[bool],
        halfedges: &mut Vec<usize>,
        points: &mut Vec<u32>,
    ) -> bool {
        // Triangles only, so that triangle f owns half-edges 3f, 3f + 1, 3f + 2.
        if mesh.face_vertices.len() != 3 * mesh.faces() {
            return false;
        }
        halfedges.clear();
        halfedges.push(start);
        for step in &self.steps {
            let h = match *step {
                Step::Next(g) => match halfedges[g] % 3 {
                    2 => halfedges[g] - 2,
                    _ => halfedges[g] + 1,
                },
                Step::Twin(g) => match mesh.twin[halfedges[g]] {
                    NONE => return false,
                    t => t as usize,
                },
            };
            halfedges.push(h);
        }
        points.clear();
        for &h in &self.tails {
            let v = mesh.face_vertices[halfedges[h]];
            if !regular[v as usize] {
                return false;
            }
            points.push(v);
        }
        // A few dozen points: pairwise is cheaper than sorting a copy.
        !points
            .iter()
            .enumerate()
            .any(|(i, v)| points[i + 1..].contains(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::lattice_torus;
    use crate::scheme::triangle::cone_chart::ConeChart;

    /// The radius-2 hexagon: every point within two rings of the centre.
    fn hexagon() -> Vec<TrianglePoint> {
        let mut layout = vec![TrianglePoint::Centre];
        for m in 1..=2i64 {
            for s in 0..6 {
                for b in 0..m {
                    layout.push(TrianglePoint::Sector { s, a: m - b, b });
                }
            }
        }
        layout
    }

    #[test]
    fn on_a_regular_torus_the_walk_names_what_the_chart_names() {
        let layout = hexagon();
        let walk = LatticeWalk::new(&layout).expect("a hexagon is a disc of triangles");
        // The hexagon's 24 triangles, each entered by a twin and left by two nexts at most.
        assert!(walk.visits() <= 3 * 24, "{}", walk.visits());
        let mesh = lattice_torus(9, |a, b| [a as f64, b as f64, 0.0]);
        let regular = vec![true; mesh.positions.len()];
        let (mut halfedges, mut points) = (Vec::new(), Vec::new());
        for f in 0..mesh.faces() {
            let corners = mesh.face(f);
            let chart = ConeChart::new(&mesh, corners[0], corners[1], 2).expect("regular");
            let start = mesh.face_halfedges(f).start;
            assert!(walk.walk(&mesh, start, &regular, &mut halfedges, &mut points));
            let want: Vec<u32> = layout
                .iter()
                .map(|&p| chart.vertex(p, 0).expect("within the chart"))
                .collect();
            assert_eq!(points, want, "face {f}");
        }
    }

    #[test]
    fn a_torus_too_small_for_the_layout_is_refused() {
        // On a 4 x 4 torus the hexagon's opposite points coincide.
        let walk = LatticeWalk::new(&hexagon()).expect("a disc");
        let mesh = lattice_torus(4, |a, b| [a as f64, b as f64, 0.0]);
        let regular = vec![true; mesh.positions.len()];
        let (mut halfedges, mut points) = (Vec::new(), Vec::new());
        assert!(!walk.walk(&mesh, 0, &regular, &mut halfedges, &mut points));
    }

    #[test]
    fn a_layout_that_is_not_joined_by_triangles_has_no_walk() {
        let layout = [
            TrianglePoint::Centre,
            TrianglePoint::Sector { s: 0, a: 1, b: 0 },
            TrianglePoint::Sector { s: 1, a: 1, b: 0 },
            TrianglePoint::Sector { s: 3, a: 3, b: 0 },
        ];
        assert!(LatticeWalk::new(&layout).is_none());
    }

    /// The radius-4 hexagon without `(1, 1)` (two rings inside its rim): its triangles surround
    /// a hole (V - E + F = 0), where turning around the missing vertex need not close on a mesh,
    /// so there is no walk.
    #[test]
    fn a_layout_with_a_hole_has_no_walk() {
        let mut layout = vec![TrianglePoint::Centre];
        for m in 1..=4i64 {
            for s in 0..6 {
                for b in 0..m {
                    let p = TrianglePoint::Sector { s, a: m - b, b };
                    if lattice_point(p) != (1, 1) {
                        layout.push(p);
                    }
                }
            }
        }
        assert!(LatticeWalk::new(&layout).is_none());
        layout.push(TrianglePoint::Sector { s: 0, a: 1, b: 1 });
        assert!(
            LatticeWalk::new(&layout).is_some(),
            "the full hexagon is a disc"
        );
    }
}
