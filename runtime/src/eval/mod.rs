//! Exact evaluation at rational parameters: Catmull–Clark at any face and `(u, v)`, Loop at any
//! triangle and barycentric `(u, v)`.

pub mod exact_eval;
pub mod loop_exact_eval;

use num_rational::BigRational;
use num_traits::ToPrimitive;

use crate::mesh::face_varying::FaceVaryingMode;
use crate::mesh::Mesh;
use crate::scheme::catmull_clark::adaptive::{limit_stencils, LimitQuery};
use crate::scheme::catmull_clark::face_varying::channel_mesh;
use crate::scheme::catmull_clark::refine::refine;
use crate::scheme::Scheme;
use crate::RuntimeError;

pub use exact_eval::{parse_rational, LimitPoint};

/// The limit position and first derivatives of face `face` of `mesh` under `scheme` at the
/// rational `(u, v)`, in the face's own parameters, rounded once to f64.
///
/// Catmull–Clark: any face; a non-quad face is parameterized by its sub-faces (the quads of
/// its first step), `subface` picks one (docs/algorithms). With sharp features (creases and
/// corners of any sharpness, darts, holes; [`exact_eval::feature`]) the position stays exact: where
/// the descent ends in a B-spline patch (reflected across infinitely sharp edges) or a smooth
/// table patch, derivatives too; at a feature vertex (the point at a corner of the final piece)
/// the position comes from OpenSubdiv's rational limit masks or, at a dart, the exact
/// eigenvector, and the tangents from f64 masks (see [`LimitPoint`]). A hole face (a `hole`
/// tag, or a boundary face under `interpolateboundary 0`) is an error: it has no surface. Loop: barycentric `(u, v)` with
/// `u + v <= 1`, `subface` must be 0. The butterfly and √3 have non-polynomial regular bases;
/// their exact values need the solver at run time and are refused by name.
pub fn limit_point(
    mesh: &Mesh,
    scheme: Scheme,
    face: usize,
    subface: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<LimitPoint, RuntimeError> {
    match scheme {
        Scheme::CatmullClark => exact_eval::evaluate_subface(mesh, face, subface, u, v),
        Scheme::Loop if subface == 0 => {
            loop_exact_eval::LoopExactEvaluator::new(mesh)?.evaluate(face, u, v)
        }
        Scheme::Loop => Err(RuntimeError::InvalidParameter {
            name: "sub-face".to_owned(),
            reason: format!("{subface}: a triangle has no sub-faces (0 only)"),
        }),
        Scheme::Butterfly | Scheme::Sqrt3 => Err(RuntimeError::Unsupported(format!(
            "exact evaluation of {scheme} is not implemented yet (`subtess tessellate --scheme {scheme}` evaluates it from the table)"
        ))),
    }
}

/// The texture coordinates (the mesh's face-varying channel, Catmull–Clark) at the rational
/// `(u, v)` of face `face` (sub-face `subface` of a non-quad face), or `None` when the mesh has
/// none: the bilinear interpolation of the corner values under [`FaceVaryingMode::All`], else
/// the limit of the channel's own mesh ([`channel_mesh`]), exactly and rounded once when it has
/// no sharp feature (no pinned value, crease or hole), by feature-adaptive limit stencils in
/// `f64` otherwise.
pub fn limit_uv(
    mesh: &Mesh,
    face: usize,
    subface: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<Option<[f64; 2]>, RuntimeError> {
    let Some(fvar) = &mesh.face_varying else {
        return Ok(None);
    };
    if face >= mesh.faces() {
        return Err(RuntimeError::InvalidParameter {
            name: "face".to_owned(),
            reason: format!("{face}: the mesh has {} faces", mesh.faces()),
        });
    }
    let sides = mesh.face(face).len();
    if (sides == 4 && subface != 0) || subface >= sides {
        return Err(RuntimeError::InvalidParameter {
            name: "sub-face".to_owned(),
            reason: format!("{subface}: face {face} has {sides} sides"),
        });
    }
    let unit = |x: &BigRational, name: &str| match x.to_f64() {
        Some(f) if (0.0..=1.0).contains(&f) => Ok(f),
        _ => Err(RuntimeError::InvalidParameter {
            name: name.to_owned(),
            reason: format!("{x} is not in [0, 1]"),
        }),
    };
    let (uf, vf) = (unit(u, "u")?, unit(v, "v")?);
    if fvar.mode == FaceVaryingMode::All {
        return Ok(Some(fvar.bilinear(
            mesh.face_halfedges(face),
            subface,
            uf,
            vf,
        )));
    }
    let channel = channel_mesh(mesh, fvar)?;
    if !channel.has_sharp_features() {
        let p = exact_eval::evaluate_subface(&channel, face, subface, u, v)?.position;
        return Ok(Some([p[0], p[1]]));
    }
    // The sub-face of an n-gon is the child its first step makes at that corner.
    let (channel, face) = if sides == 4 {
        (channel, face)
    } else {
        let child = channel.face_offsets[face] as usize + subface;
        (refine(&channel).mesh, child)
    };
    let query = LimitQuery {
        face: face as u32,
        u: uf,
        v: vf,
    };
    let stencil = limit_stencils(&channel, &[query])?;
    let mut out = [0.0; 2];
    for &(vertex, [w, _, _]) in stencil.iter().flatten() {
        let p = channel.positions[vertex as usize];
        out[0] += w * p[0];
        out[1] += w * p[1];
    }
    Ok(Some(out))
}
