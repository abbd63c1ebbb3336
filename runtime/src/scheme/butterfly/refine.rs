//! One uniform step of the modified butterfly (Zorin, Schröder and Sweldens 1996) on a closed
//! triangle mesh: the rules of `schemes::TriangleScheme` "butterfly" that the butterfly stencil
//! tables were generated with, numbered as [`crate::scheme::triangle::split`] says.
//!
//! The scheme interpolates: every vertex keeps its position. The new point on the edge
//! `(a, b)`, whose triangles are `(a, b, c)` and `(b, a, d)`, is
//!
//! * both ends of valence 6: the eight-point rule `1/2 (a + b) + 1/8 (c + d) - 1/16 (w_1 + .. +
//!   w_4)`, the wings `w_i` the far vertices of the four triangles across the edges `bc`, `ca`,
//!   `ad`, `db` (Zorin et al.'s ten-point rule at `w = 0`);
//! * one end `a` of valence `K != 6`: `3/4 a + sum_j s_j E_j`, `E_0 = b` and on around `a`
//!   counter-clockwise (`s_j` from [`schemes::TriangleScheme::butterfly_extraordinary`]: 5/12,
//!   -1/12, -1/12 at `K = 3`; 3/8, 0, -1/8, 0 at `K = 4`;
//!   `(1/4 + cos(2πj/K) + cos(4πj/K)/2)/K` from 5 on);
//! * both ends extraordinary: the average of the two ends' rules.
//!
//! The scheme's boundary rules are not implemented: a mesh with a boundary is refused.

use schemes::TriangleScheme;

use crate::mesh::topology::Mesh;
use crate::mesh::triangle_topology::{require_closed_triangles, ring_from};
use crate::scheme::loop_scheme::refine::LoopRefinement;
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::split::TriangleSplit;
use crate::RuntimeError;

/// The butterfly's extraordinary edge weights `(3/4, s_0 .. s_{K-1})` of every valence, as f64.
#[derive(Clone, Debug)]
pub struct ButterflyWeights {
    by_valence: Vec<Option<(f64, Vec<f64>)>>,
}

impl ButterflyWeights {
    /// The weights for every valence up to `max_valence`.
    pub fn new(max_valence: usize) -> Result<Self, RuntimeError> {
        let scheme = TriangleScheme::by_name("butterfly")
            .ok_or_else(|| RuntimeError::Unsupported("the butterfly is not catalogued".into()))?;
        let by_valence = (0..=max_valence)
            .map(|k| {
                (k >= 3)
                    .then(|| scheme.butterfly_extraordinary(k as u32))
                    .flatten()
                    .map(|(q, s)| (q.value, s.iter().map(|w| w.value).collect()))
            })
            .collect();
        Ok(ButterflyWeights { by_valence })
    }

    fn of(&self, valence: usize) -> Option<&(f64, Vec<f64>)> {
        self.by_valence.get(valence)?.as_ref()
    }
}

/// The far vertex of the triangle across the edge of half-edge `h` (a closed mesh).
fn across(mesh: &Mesh, h: usize) -> u32 {
    mesh.head(mesh.next(mesh.twin[h] as usize))
}

/// One butterfly step of the closed triangle mesh `mesh` as rows over its vertices (f64: the
/// extraordinary weights have cosines): refined vertex `i`, numbered as
/// [`crate::scheme::triangle::split`] says, is `sum w p_j` over row `i`. Why a map: the same
/// rules then position the refined mesh ([`butterfly_refine`]) and compose into the per-frame
/// stencil of an isolation. Refuses a boundary, or a vertex of valence below 3.
pub fn butterfly_stencil(mesh: &Mesh) -> Result<Stencil<f64>, RuntimeError> {
    require_closed_triangles(mesh, "butterfly")?;
    rows(mesh, &TriangleSplit::new(mesh))
}

/// The rules of the module docs over `split`'s numbering (`mesh` closed, all triangles).
fn rows(mesh: &Mesh, split: &TriangleSplit) -> Result<Stencil<f64>, RuntimeError> {
    let nv = mesh.positions.len();
    let valence: Vec<usize> = mesh.valences();
    let max_valence = valence.iter().copied().max().unwrap_or(0);
    let weights = ButterflyWeights::new(max_valence)?;
    // The extraordinary rule of the tail `a` of half-edge `h`, every weight times `factor`.
    let extraordinary = |h: usize, factor: f64| -> Result<Vec<(u32, f64)>, RuntimeError> {
        let a = mesh.face_vertices[h];
        let (q, s) = weights.of(valence[a as usize]).ok_or_else(|| {
            RuntimeError::Unsupported(format!(
                "vertex {a} has valence {}: the butterfly needs at least 3",
                valence[a as usize]
            ))
        })?;
        let mut row = vec![(a, factor * q)];
        row.extend(
            ring_from(mesh, h)
                .iter()
                .zip(s)
                .map(|(&e, &w)| (e, factor * w)),
        );
        Ok(row)
    };
    // The scheme interpolates: old vertices stay.
    let mut stencil = Stencil::identity(nv);
    for &h in &split.first_halfedge {
        let h = h as usize;
        let t = mesh.twin[h] as usize;
        let (a, b) = (mesh.face_vertices[h], mesh.head(h));
        let row = match (valence[a as usize] == 6, valence[b as usize] == 6) {
            (true, true) => {
                let c = mesh.head(mesh.next(h));
                let d = mesh.head(mesh.next(t));
                let mut row = vec![(a, 0.5), (b, 0.5), (c, 0.125), (d, 0.125)];
                row.extend(
                    [mesh.next(h), mesh.prev(h), mesh.next(t), mesh.prev(t)]
                        .iter()
                        .map(|&g| (across(mesh, g), -1.0 / 16.0)),
                );
                row
            }
            (false, true) => extraordinary(h, 1.0)?,
            (true, false) => extraordinary(t, 1.0)?,
            (false, false) => {
                let mut row = extraordinary(h, 0.5)?;
                row.extend(extraordinary(t, 0.5)?);
                row
            }
        };
        stencil.push_row(row);
    }
    Ok(stencil)
}

/// Refine the closed triangle mesh `mesh` once: the positions are [`butterfly_stencil`]'s rows
/// applied to the coarse positions, and the rows come back with the mesh.
pub fn butterfly_refine(mesh: &Mesh) -> Result<LoopRefinement, RuntimeError> {
    require_closed_triangles(mesh, "butterfly")?;
    let nv = mesh.positions.len();
    let split = TriangleSplit::new(mesh);
    let stencil = rows(mesh, &split)?;
    let positions = stencil.apply(&mesh.positions);
    let faces = split.child_faces(mesh, nv);
    let refined = Mesh::new(positions, &faces, &[], mesh.boundary)?;
    Ok(LoopRefinement {
        mesh: refined,
        edges: split.edges,
        stencil,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron};
    use schemes::triangle::TriangleRefinement;
    use schemes::BoundaryMode;

    /// The regular rule's weights, read from the scheme at the lattice offsets of the edge
    /// `(0,0)-(1,0)` named in the module docs: `a, b, c, d` and the wings.
    #[test]
    fn the_eight_point_rule_is_the_schemes() {
        let scheme = TriangleScheme::by_name("butterfly").expect("catalogued");
        let TriangleRefinement::Dyadic {
            edge,
            edge_denominator,
        } = scheme.refinement
        else {
            panic!("the butterfly is dyadic");
        };
        let weight = |o: (i64, i64)| {
            edge.iter()
                .find(|&&(q, _)| q == o)
                .map_or(0.0, |&(_, w)| w as f64 / edge_denominator as f64)
        };
        for (o, w) in [
            ((0, 0), 0.5),
            ((1, 0), 0.5),
            ((0, 1), 0.125),
            ((1, -1), 0.125),
            ((1, 1), -1.0 / 16.0),
            ((-1, 1), -1.0 / 16.0),
            ((0, -1), -1.0 / 16.0),
            ((2, -1), -1.0 / 16.0),
        ] {
            assert_eq!(weight(o), w, "offset {o:?}");
        }
        let total: f64 = edge
            .iter()
            .map(|&(_, w)| w as f64 / edge_denominator as f64)
            .sum();
        assert_eq!(total, 1.0, "no other offsets carry weight");
    }

    /// Expected numbers by hand from the valence-4 rule: the edge (+x, +y) of the octahedron,
    /// both ends of valence 4: each end gives 3/4 a + 3/8 b - 1/8 (the vertex opposite b).
    #[test]
    fn an_octahedron_refines_by_the_valence_four_rule() {
        let r = butterfly_refine(&octahedron()).expect("refines");
        assert_eq!((r.mesh.positions.len(), r.mesh.faces()), (18, 32));
        assert_eq!(r.mesh.euler_characteristic(), 2);
        // Vertices interpolate.
        assert_eq!(r.mesh.positions[0], [1.0, 0.0, 0.0]);
        // From +x: 3/4 (1,0,0) + 3/8 (0,1,0) - 1/8 (0,-1,0) = (3/4, 1/2, 0); from +y by symmetry
        // (1/2, 3/4, 0); the average (5/8, 5/8, 0).
        let e = r.edges.iter().position(|e| *e == [0, 2]).expect("edge 0-2");
        assert_eq!(r.mesh.positions[6 + e], [0.625, 0.625, 0.0]);
        // Every new vertex is regular; the old ones keep valence 4.
        for v in 0..18 {
            let k = r.mesh.fan_iter(v).count();
            assert_eq!(k, if v < 6 { 4 } else { 6 }, "vertex {v}");
        }
    }

    /// The eight-point rule has cubic precision: where the control points sample a cubic of
    /// the lattice coordinates, the edge points sample it at the edge midpoints (checked away
    /// from the seams of a 12 x 12 torus, whose positions do not wrap).
    #[test]
    fn the_regular_rule_reproduces_cubics() {
        let m = 12i64;
        let g = |a: f64, b: f64| a * a * a - 2.0 * a * a * b + 0.5 * b * b * b - a * b + 3.0;
        let torus = lattice_torus(m, |a, b| {
            let (a, b) = (a as f64, b as f64);
            [a, b, g(a, b)]
        });
        let r = butterfly_refine(&torus).expect("refines");
        let mut checked = 0;
        for (e, &[x, y]) in r.edges.iter().enumerate() {
            let (p, q) = (torus.positions[x as usize], torus.positions[y as usize]);
            if [p, q]
                .iter()
                .any(|c| c[0] < 3.0 || c[0] > 8.0 || c[1] < 3.0 || c[1] > 8.0)
            {
                continue;
            }
            let (a, b) = ((p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0);
            let got = r.mesh.positions[(m * m) as usize + e];
            assert!((got[2] - g(a, b)).abs() < 1e-9, "edge {x}-{y}: {got:?}");
            assert!((got[0] - a).abs() < 1e-12 && (got[1] - b).abs() < 1e-12);
            checked += 1;
        }
        assert!(checked > 50, "{checked} edges checked");
    }

    #[test]
    fn a_mesh_with_a_boundary_is_refused() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let m = Mesh::new(p, &[vec![0, 1, 2]], &[], BoundaryMode::EdgeOnly).expect("valid");
        let e = butterfly_refine(&m).expect_err("open");
        assert!(e.to_string().contains("boundary"), "{e}");
    }
}
