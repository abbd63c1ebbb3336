//! Exact evaluation at rational parameters: Catmull–Clark at any face and `(u, v)`, Loop at any
//! triangle and barycentric `(u, v)`.

pub mod exact_eval;
pub mod loop_exact_eval;

use num_rational::BigRational;

use crate::mesh::Mesh;
use crate::scheme::Scheme;
use crate::RuntimeError;

pub use exact_eval::{parse_rational, LimitPoint};

/// The limit position and first derivatives of face `face` of `mesh` under `scheme` at the
/// rational `(u, v)`, in the face's own parameters, rounded once to f64.
///
/// Catmull–Clark: any face; a non-quad face is parameterized by its sub-faces (the quads of
/// its first step), `subface` picks one (docs/algorithms). Loop: barycentric `(u, v)` with
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
        Scheme::CatmullClark if mesh.has_sharp_features() => Err(RuntimeError::Unsupported(
            "exact evaluation on sharp features (creases, corners, holes); `subtess tessellate` evaluates them (feature-adaptive refinement, f64)".to_owned(),
        )),
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
