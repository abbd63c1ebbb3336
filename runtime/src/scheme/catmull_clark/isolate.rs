//! Isolation: Catmull–Clark steps until every face is a table patch (a quad with at most one
//! irregular corner, and no interior irregular corner next to the boundary).
//!
//! This version refines the whole mesh (one step makes every face a quad, a second separates
//! irregular vertices); rates then apply to the faces of the refined mesh, and every refined face
//! remembers the input face it lies in ([`Isolation::origin`]).

use rayon::prelude::*;

use crate::mesh::topology::Mesh;
use crate::mesh::VertexSource;
use crate::scheme::catmull_clark::adaptive::bspline_patch;
use crate::scheme::catmull_clark::refine::refine;
use crate::scheme::patch::gather_patches;
use crate::scheme::patch::FacePatch;
use crate::scheme::stencil::Stencil;
use crate::MeshError;

/// At most this many steps are tried (two always suffice for a valid mesh).
pub const MAX_STEPS: usize = 3;

/// An isolated mesh and where its faces come from.
#[derive(Clone, Debug)]
pub struct Isolation {
    /// The refined mesh, every face a table patch.
    pub mesh: Mesh,
    /// The patch of every face.
    pub patches: Vec<FacePatch>,
    /// Refinement steps taken.
    pub steps: usize,
    /// The input face every face of `mesh` lies in.
    pub origin: Vec<u32>,
    /// For every face of `mesh`, the corner of its parent it was made at, one per step (the
    /// first for the step from the input mesh).
    pub corners: Vec<[u8; MAX_STEPS]>,
    /// Number of sides of every input face.
    pub input_sides: Vec<u32>,
    /// Every vertex of `mesh` as a combination of the input mesh's vertices: the refinement
    /// steps composed, so a moved input maps to the isolated control points without refining
    /// again (the identity when no step was taken and no vertex was split).
    pub refinement: Stencil<f64>,
    /// Every input face's 16 input vertices (`net[a][b]` at `(a - 1, b - 1)` of its grid, `a`
    /// along its `u`) where it is a bicubic B-spline patch of plain vertices: a quad, no hole,
    /// no sharp feature or boundary that reflects a point (`adaptive::bspline_patch`); empty when
    /// isolation took no step. Its isolated faces are pieces of that one patch.
    pub input_nets: Vec<Option<[[u32; 4]; 4]>>,
}

impl Isolation {
    /// The input face and its own parameters of a point given on face `source.face` of the
    /// isolated mesh, exactly ([`Isolation::input_map`]).
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        self.input_map(source.face as usize).apply(source)
    }

    /// Every point of `sources` (given on faces of the isolated mesh) on its input face, in
    /// place and in parallel, one [`InputMap`] per run of points on the same face (a dual grid
    /// lists each face's points together).
    pub fn map_to_input(&self, sources: &mut [VertexSource]) {
        sources
            .par_chunk_by_mut(|a, b| a.face == b.face)
            .for_each(|run| {
                let map = self.input_map(run[0].face as usize);
                for source in run {
                    *source = map.apply(*source);
                }
            });
    }

    /// How the points of isolated face `face` map to its input face. Child `c` of a quad covers
    /// the quarter at its corner `c` and runs from that corner (`refine.rs`): its `(s, t)` is
    /// the parent's `(s/2, t/2)`, `(1 - t/2, s/2)`, `(1 - s/2, 1 - t/2)`, `(t/2, 1 - s/2)` for
    /// `c = 0..3`, so the denominator doubles per step: on numerators `(u, v)` over `d`, a step
    /// is linear in `(u, v, d)`, and so are the steps composed. A non-quad input face has no
    /// parameterization of its own: the point is left in the parameters of the sub-face (the
    /// quad of the first step at its corner `subface`), the Ptex / OpenSubdiv convention. A face
    /// beyond the isolated mesh maps to itself.
    pub fn input_map(&self, face: usize) -> InputMap {
        // Rows of the map on (u, v, d), from the identity; each step multiplies from the left.
        let mut rows = [[1i64, 0, 0], [0, 1, 0], [0, 0, 1]];
        let mut subface = 0;
        let (Some(corners), Some(&origin)) = (self.corners.get(face), self.origin.get(face)) else {
            return InputMap {
                face: face as u32,
                subface,
                rows,
            };
        };
        let quad = self.input_sides.get(origin as usize) == Some(&4);
        for level in (0..self.steps.min(MAX_STEPS)).rev() {
            let c = corners[level];
            if level == 0 && !quad {
                subface = c;
                break;
            }
            let [u, v, d] = rows;
            let twice = |r: [i64; 3]| r.map(|x| 2 * x);
            let minus = |a: [i64; 3], b: [i64; 3]| std::array::from_fn(|k| a[k] - b[k]);
            rows = match c {
                0 => [u, v, twice(d)],
                1 => [minus(twice(d), v), u, twice(d)],
                2 => [minus(twice(d), u), minus(twice(d), v), twice(d)],
                _ => [v, minus(twice(d), u), twice(d)],
            };
        }
        InputMap {
            face: origin,
            subface,
            rows,
        }
    }
}

/// Where an isolated face lies in its input quad ([`Isolation::placement`]): the cell
/// `(a, b)` of the input face's `2^steps x 2^steps` grid of cells (`a` along the input face's
/// `u`), and the quarter turns `turns` from the input face's `(u, v)` axes to the isolated
/// face's own (its `u` axis along the input face's `u`, `v`, `-u`, `-v` for 0..=3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// Quarter turns, `0..4`.
    pub turns: u8,
    /// The cell along the input face's `u`.
    pub a: u32,
    /// The cell along the input face's `v`.
    pub b: u32,
}

impl Isolation {
    /// Where isolated face `face` lies in its input face, if that is a quad
    /// ([`Isolation::input_map`]'s affine map read as a cell and a rotation: the children of a
    /// quad are its corner quarters turned by their corner, so every step composes a turn).
    pub fn placement(&self, face: usize) -> Option<Placement> {
        if self.input_sides.get(*self.origin.get(face)? as usize) != Some(&4) {
            return None;
        }
        let [u, v, _] = self.input_map(face).rows;
        // The face's own axes and origin in the input face, in cells (the last column is the
        // origin's numerator over the denominator's factor `2^steps`).
        let (axis_u, axis_v, origin) = ((u[0], v[0]), (u[1], v[1]), (u[2], v[2]));
        let turns = match axis_u {
            (1, 0) => 0,
            (0, 1) => 1,
            (-1, 0) => 2,
            (0, -1) => 3,
            _ => return None,
        };
        // The cell's lower corner: the origin moved back along whichever axis points down.
        let a = origin.0 + axis_u.0.min(0) + axis_v.0.min(0);
        let b = origin.1 + axis_u.1.min(0) + axis_v.1.min(0);
        Some(Placement {
            turns,
            a: u32::try_from(a).ok()?,
            b: u32::try_from(b).ok()?,
        })
    }
}

/// The map from the points of one isolated face to its input face ([`Isolation::input_map`]):
/// the input face, the sub-face of a non-quad, and the integer linear map on `(u, v, d)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputMap {
    face: u32,
    subface: u8,
    rows: [[i64; 3]; 3],
}

impl InputMap {
    /// `source` on the input face. For a point of the face (`u, v <= d`) the numerators stay in
    /// `0..=d'` (the maps are the corner quarters' affine maps), so they fit in `u32` whenever
    /// the denominator `d'` does; a point beyond the face wraps, as the steps' `u32` arithmetic
    /// did.
    pub fn apply(&self, source: VertexSource) -> VertexSource {
        let x = [
            i64::from(source.u),
            i64::from(source.v),
            i64::from(source.denominator),
        ];
        let row = |r: [i64; 3]| (r[0] * x[0] + r[1] * x[1] + r[2] * x[2]) as u32;
        VertexSource {
            face: self.face,
            u: row(self.rows[0]),
            v: row(self.rows[1]),
            denominator: row(self.rows[2]),
            subface: self.subface,
        }
    }
}

/// Refine until every face is a patch; keeps the face ancestry. A refinement step turns face `f`
/// into one quad per corner, numbered by the face's half-edges (`refine.rs`), so a child's parent
/// is the face of its half-edge.
pub fn isolate_with_origins(mesh: &Mesh) -> Result<Isolation, MeshError> {
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    let mut corners = vec![[0u8; MAX_STEPS]; mesh.faces()];
    // Vertices that split non-manifold ones start as copies of their input vertex.
    let mut refinement = Stencil::new(mesh.input_vertices());
    for v in 0..mesh.positions.len() {
        refinement.push_row(vec![(mesh.origin(v) as u32, 1.0)]);
    }
    let input_sides = (0..mesh.faces())
        .map(|f| mesh.face(f).len() as u32)
        .collect();
    for steps in 0..=MAX_STEPS {
        match gather_patches(&current) {
            Ok(patches) => {
                let input_nets = if steps == 0 {
                    Vec::new()
                } else {
                    (0..mesh.faces()).map(|f| input_net(mesh, f)).collect()
                };
                return Ok(Isolation {
                    input_nets,
                    mesh: current,
                    patches,
                    steps,
                    origin,
                    corners,
                    input_sides,
                    refinement,
                });
            }
            Err(e) if steps == MAX_STEPS => return Err(e),
            Err(_) => {
                // Child h of the refined mesh is made at half-edge h of the current one.
                corners = (0..current.face_vertices.len())
                    .map(|h| {
                        let f = current.face_of[h] as usize;
                        let mut path = corners[f];
                        path[steps] = (h - current.face_halfedges(f).start) as u8;
                        path
                    })
                    .collect();
                origin = current
                    .face_of
                    .iter()
                    .map(|&f| origin[f as usize])
                    .collect();
                let step = refine(&current);
                refinement = refinement.then(&step.stencil);
                current = step.mesh;
            }
        }
    }
    unreachable!("the loop returns at its last step")
}

/// Face `f`'s B-spline net as input vertices ([`Isolation::input_nets`]): split copies of a
/// non-manifold vertex are their input vertex (the same point).
fn input_net(mesh: &Mesh, f: usize) -> Option<[[u32; 4]; 4]> {
    if mesh.holes.get(f).copied().unwrap_or(true) {
        return None;
    }
    // `bspline_patch` reads a refined mesh, all quads: here the faces around the corners must
    // be quads for its walk to find the net.
    let quad = |h: usize| mesh.face_halfedges(mesh.face_of[h] as usize).len() == 4;
    if !mesh
        .face(f)
        .iter()
        .all(|&v| mesh.fan_iter(v as usize).all(quad))
    {
        return None;
    }
    let net = bspline_patch::<f64>(mesh, f)?;
    let mut out = [[0u32; 4]; 4];
    for (column, cells) in out.iter_mut().zip(&net) {
        for (v, combo) in column.iter_mut().zip(cells) {
            match combo.as_slice() {
                [(vertex, w)] if *w == 1.0 => {
                    *v = u32::try_from(mesh.origin(*vertex as usize)).ok()?
                }
                _ => return None,
            }
        }
    }
    Some(out)
}

/// The isolated mesh, its patches and the number of refinement steps taken.
pub fn isolate(mesh: &Mesh) -> Result<(Mesh, Vec<FacePatch>, usize), MeshError> {
    isolate_with_origins(mesh).map(|i| (i.mesh, i.patches, i.steps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::cube;

    /// A pentagon and a triangle sharing an edge.
    fn pentagon_and_triangle() -> Mesh {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.5, 1.0, 0.0],
            [0.5, 1.5, 0.0],
            [-0.5, 1.0, 0.0],
            [0.5, -1.0, 0.0],
        ];
        let faces = vec![vec![0, 1, 2, 3, 4], vec![1, 0, 5]];
        Mesh::new(p, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("valid")
    }

    /// One step makes five quads of the pentagon, then three of the triangle.
    #[test]
    fn origins_follow_the_half_edges() {
        let iso = isolate_with_origins(&pentagon_and_triangle()).expect("isolates");
        assert!(iso.steps >= 1);
        let quads = 8 * 4usize.pow(iso.steps as u32 - 1);
        assert_eq!(iso.origin.len(), quads);
        let fives = iso.origin.iter().filter(|&&f| f == 0).count();
        assert_eq!(fives * 3, (quads - fives) * 5);
    }

    /// The corner steps one at a time, from the last step to the first: what
    /// [`Isolation::input_map`] composes (the implementation before the maps).
    fn step_by_step(iso: &Isolation, source: VertexSource) -> VertexSource {
        let face = source.face as usize;
        let (mut u, mut v, mut d) = (source.u, source.v, source.denominator);
        let mut subface = 0;
        for level in (0..iso.steps).rev() {
            let c = iso.corners[face][level];
            if level == 0 && iso.input_sides[iso.origin[face] as usize] != 4 {
                subface = c;
                break;
            }
            (u, v) = match c {
                0 => (u, v),
                1 => (2 * d - v, u),
                2 => (2 * d - u, 2 * d - v),
                _ => (v, 2 * d - u),
            };
            d *= 2;
        }
        VertexSource {
            face: iso.origin[face],
            u,
            v,
            denominator: d,
            subface,
        }
    }

    /// The placements of a cube's isolated faces tile each input face once, and each face's
    /// cell and turns carry its own corners to the cell's corners as [`Isolation::input_map`]
    /// maps them.
    #[test]
    fn placements_tile_their_input_faces() {
        let iso = isolate_with_origins(&cube()).expect("isolates");
        let cells = 1u32 << iso.steps;
        let mut seen = std::collections::HashSet::new();
        for face in 0..iso.mesh.faces() {
            let p = iso.placement(face).expect("a quad's face has a placement");
            assert!(p.turns < 4 && p.a < cells && p.b < cells);
            assert!(
                seen.insert((iso.origin[face], p.a, p.b)),
                "one face per cell"
            );
            // The face's corner (0, 0) turned `turns` times about the cell's centre.
            let corner = [(0, 0), (1, 0), (1, 1), (0, 1)][usize::from(p.turns)];
            let source = VertexSource {
                face: face as u32,
                u: 0,
                v: 0,
                denominator: 1,
                subface: 0,
            };
            let mapped = iso.input_source(source);
            assert_eq!(mapped.denominator, cells);
            assert_eq!((mapped.u, mapped.v), (p.a + corner.0, p.b + corner.1));
            // Its `u` axis: the corner (1, 0) one cell along the turned axis.
            let axis = [(1, 0), (0, 1), (-1, 0), (0, -1)][usize::from(p.turns)];
            let mapped = iso.input_source(VertexSource { u: 1, ..source });
            assert_eq!(
                (i64::from(mapped.u), i64::from(mapped.v)),
                (
                    i64::from(p.a + corner.0) + axis.0,
                    i64::from(p.b + corner.1) + axis.1
                )
            );
        }
        assert_eq!(seen.len(), iso.mesh.faces());
    }

    /// Every face's map gives the steps' point for points across the face (corners, sides,
    /// inside; denominators up to Lai–Cheng's `2^24`), on a cube (two steps, every input face a
    /// quad) and on a pentagon beside a triangle (sub-faces); and the maps by runs give the
    /// points one by one, whatever the order of the faces.
    #[test]
    fn input_maps_are_the_corner_steps_composed() {
        for mesh in [cube(), pentagon_and_triangle()] {
            let iso = isolate_with_origins(&mesh).expect("isolates");
            assert!(iso.steps >= 1);
            let mut all = Vec::new();
            for face in 0..iso.mesh.faces() as u32 {
                for d in [1u32, 2, 6, 48, 1 << 24] {
                    for (u, v) in [
                        (0, 0),
                        (d, 0),
                        (d, d),
                        (0, d),
                        (d / 2, 0),
                        (d / 3, d - d / 5),
                    ] {
                        let source = VertexSource {
                            face,
                            u,
                            v,
                            denominator: d,
                            subface: 0,
                        };
                        assert_eq!(iso.input_source(source), step_by_step(&iso, source));
                        all.push(source);
                    }
                }
            }
            // Runs of one face, then the faces interleaved point by point.
            let interleaved: Vec<VertexSource> = (0..30)
                .flat_map(|k| all.iter().skip(k).step_by(30).copied())
                .collect();
            for mut sources in [all.clone(), interleaved] {
                let expected: Vec<VertexSource> =
                    sources.iter().map(|&s| step_by_step(&iso, s)).collect();
                iso.map_to_input(&mut sources);
                assert_eq!(sources, expected);
            }
        }
    }
}
