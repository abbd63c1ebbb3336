//! Isolation for triangle schemes: whole-mesh refinement steps until every triangle is a table
//! patch, with every refined triangle remembering where it lies in the input triangle.
//!
//! The schemes differ in how they refine ([`crate::scheme::loop_scheme::refine`], [`crate::scheme::butterfly::refine`],
//! [`crate::scheme::sqrt3::refine`]), into four or nine ([`Split`]), and in what makes a triangle a patch
//! ([`crate::scheme::loop_scheme::isolate`], [`crate::scheme::triangle::region_patch`]); the bookkeeping of children and
//! parameters ([`crate::scheme::triangle::split`]) is this module's, and so is the composition
//! of the steps' rules into one map from the input's vertices to the isolated mesh's
//! ([`TriangleIsolation::refinement`]), so that moving the input's control points needs no
//! refinement.

use crate::mesh::topology::Mesh;
use crate::mesh::VertexSource;
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::patch::{Phantoms, TrianglePatch};
use crate::scheme::triangle::split::Split;
use crate::RuntimeError;

/// The most refinement steps any triangle scheme's isolation takes.
pub const MAX_ISOLATION_STEPS: usize = 4;

/// An isolated triangle mesh and where its triangles come from.
#[derive(Clone, Debug)]
pub struct TriangleIsolation {
    /// The (possibly refined) mesh, every triangle a table patch.
    pub mesh: Mesh,
    /// The patch of every triangle.
    pub patches: Vec<TrianglePatch>,
    /// The phantom points some patches read (control points numbered after the mesh's
    /// vertices).
    pub phantoms: Phantoms,
    /// Refinement steps taken.
    pub steps: usize,
    /// How every step split a triangle.
    pub split: Split,
    /// The input triangle every triangle of `mesh` lies in.
    pub origin: Vec<u32>,
    /// For every triangle of `mesh`, which child of its parent it is ([`crate::scheme::triangle::split`]
    /// numbering), one per step, the first for the step from the input mesh.
    pub child: Vec<[u8; MAX_ISOLATION_STEPS]>,
    /// The isolated mesh's vertices as combinations of the input's: row `i` is vertex `i` of
    /// `mesh` (`mesh.positions.len()` rows; the phantoms are not rows), over the input mesh's
    /// vertices (its columns), the steps' rules composed in order ([`Stencil::then`]); the
    /// identity when no step is taken. Why: the per-frame path applies it to moved input
    /// control points instead of refining again; `refinement.apply(&input.positions)` is
    /// `mesh.positions` up to rounding.
    pub refinement: Stencil<f64>,
}

impl TriangleIsolation {
    /// The input triangle and its own barycentric parameters of a point given on triangle
    /// `source.face` of the isolated mesh, exactly: a child's domain is an affine image of its
    /// parent's ([`Split::child_to_parent`]), so the denominator grows by the split's factor
    /// per step.
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        let f = source.face as usize;
        let (mut u, mut v, mut d) = (source.u, source.v, source.denominator);
        for level in (0..self.steps).rev() {
            (u, v) = self.split.child_to_parent(self.child[f][level], u, v, d);
            d *= self.split.factor();
        }
        VertexSource {
            face: self.origin[f],
            u,
            v,
            denominator: d,
            subface: 0,
        }
    }
}

/// Refine `mesh` with `refine` (which splits as `split` says and returns the refined mesh with
/// the step's rules, rows over the coarser mesh's vertices) until `gather` finds every
/// triangle's patch, at most `max_steps` times (`<=` [`MAX_ISOLATION_STEPS`]); the last
/// attempt's error is returned if it never does. The steps' rules are composed into
/// [`TriangleIsolation::refinement`].
pub fn isolate_by_refinement(
    mesh: &Mesh,
    split: Split,
    max_steps: usize,
    refine: impl Fn(&Mesh) -> Result<(Mesh, Stencil<f64>), RuntimeError>,
    gather: impl Fn(&Mesh) -> Result<(Vec<TrianglePatch>, Phantoms), RuntimeError>,
) -> Result<TriangleIsolation, RuntimeError> {
    let max_steps = max_steps.min(MAX_ISOLATION_STEPS);
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    let mut child = vec![[0u8; MAX_ISOLATION_STEPS]; mesh.faces()];
    let mut steps = 0;
    let mut refinement = Stencil::identity(mesh.positions.len());
    loop {
        match gather(&current) {
            Ok((patches, phantoms)) => {
                return Ok(TriangleIsolation {
                    mesh: current,
                    patches,
                    phantoms,
                    steps,
                    split,
                    origin,
                    child,
                    refinement,
                })
            }
            Err(e) if steps == max_steps => return Err(e),
            Err(_) => {
                // Triangle f's children are nf .. nf + n - 1.
                let (faces, n) = (current.faces(), split.children());
                origin = (0..n * faces).map(|c| origin[c / n]).collect();
                child = (0..n * faces)
                    .map(|c| {
                        let mut path = child[c / n];
                        path[steps] = (c % n) as u8;
                        path
                    })
                    .collect();
                let (refined, step) = refine(&current)?;
                if step.columns() != current.positions.len()
                    || step.rows() != refined.positions.len()
                {
                    return Err(RuntimeError::Unsupported(format!(
                        "a refinement step's rules map {} points to {}, its meshes have {} and {}",
                        step.columns(),
                        step.rows(),
                        current.positions.len(),
                        refined.positions.len()
                    )));
                }
                refinement = if steps == 0 {
                    step
                } else {
                    refinement.then(&step)
                };
                current = refined;
                steps += 1;
            }
        }
    }
}

/// What the schemes' isolation tests share: the composed stencil against the isolated mesh.
#[cfg(test)]
pub(crate) mod testing {
    use super::*;

    /// A copy of `mesh` (same topology) with every coordinate moved by a pseudo-random amount
    /// in `[-0.25, 0.25)` (splitmix64 of the coordinate's index: deterministic).
    pub(crate) fn deformed(mesh: &Mesh) -> Mesh {
        let noise = |k: u64| {
            let mut z = k.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut out = mesh.clone();
        for (v, p) in out.positions.iter_mut().enumerate() {
            for (c, x) in p.iter_mut().enumerate() {
                *x += 0.5 * noise(3 * v as u64 + c as u64);
            }
        }
        out
    }

    /// `got` equals `want` to `1e-12` relative to the largest coordinate of `input`.
    fn assert_close(what: &str, input: &Mesh, got: &[[f64; 3]], want: &[[f64; 3]]) {
        assert_eq!(got.len(), want.len(), "{what}: point counts");
        let size = input
            .positions
            .iter()
            .flatten()
            .fold(1.0f64, |m, c| m.max(c.abs()));
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            for c in 0..3 {
                assert!(
                    (g[c] - w[c]).abs() <= 1e-12 * size,
                    "{what}: vertex {i}: {g:?} against {w:?}"
                );
            }
        }
    }

    /// `isolate(input)`'s refinement has one row per isolated vertex over the input's vertices,
    /// every row affine (its weights sum to 1), and it gives the isolated positions from the
    /// input's; for a deformed copy of `input` it gives what isolating the copy gives. The
    /// steps taken, for the caller to check that the mesh needed isolation.
    pub(crate) fn check_refinement(
        name: &str,
        input: &Mesh,
        isolate: impl Fn(&Mesh) -> Result<TriangleIsolation, RuntimeError>,
    ) -> usize {
        let iso = isolate(input).unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = &iso.refinement;
        assert_eq!(
            (s.rows(), s.columns()),
            (iso.mesh.positions.len(), input.positions.len()),
            "{name}: rows and columns"
        );
        for i in 0..s.rows() {
            let sum: f64 = s.row(i).1.iter().sum();
            assert!((sum - 1.0).abs() < 1e-12, "{name}: row {i} sums to {sum}");
        }
        assert_close(name, input, &s.apply(&input.positions), &iso.mesh.positions);
        let moved = deformed(input);
        let direct = isolate(&moved).unwrap_or_else(|e| panic!("{name} deformed: {e}"));
        assert_eq!(direct.steps, iso.steps, "{name}: the topology decides");
        assert_close(
            &format!("{name} deformed"),
            &moved,
            &s.apply(&moved.positions),
            &direct.mesh.positions,
        );
        iso.steps
    }
}
