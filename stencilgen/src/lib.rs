//! Evaluation stencils from the scaling relation (Schaefer and Warren, "Exact evaluation of
//! limits and tangents for non-polynomial subdivision schemes").
//!
//! A convergent stationary subdivision scheme has basis functions that satisfy the scaling
//! relation `phi(x) = sum_i s_i phi(2x - i)` (eq. (3)) at *every* x, not only at dyadic points.
//! Written at every point of the grid `(1/n) Z` inside the support, together with the partition
//! of unity `sum_i phi(x - i) = 1` (eq. (4)), it is a linear system whose solution is the exact
//! value of the basis functions on that grid: the evaluation stencils. Differentiating gives
//! the tangent masks (section 4).
//!
//! The system relates `phi` at `x` only to `phi` at `2x - i`, so it splits along the orbits of
//! the residues `r -> 2r (mod n)` ([`orbits::orbits`]). Only the cycle of each orbit is a real
//! linear solve; every other residue follows by substitution. The exact path solves each cycle
//! over the rationals ([`exact_solve`]), the f64 path by an SVD least-squares solve
//! ([`float_solve`]); both share everything else through [`Scalar`].
//!
//! ```
//! use num_rational::BigRational;
//! use schemes::CurveScheme;
//! let scheme = CurveScheme::by_name("four-point").expect("catalogued");
//! let stencils = stencilgen::curve_stencils::<BigRational>(&scheme, 3, false).expect("solvable");
//! // Schaefer–Warren section 2: phi(1/3) = 4240/5589.
//! assert_eq!(stencils.functions[0].at(1).to_string(), "4240/5589");
//! ```

pub mod bivariate_system;
pub mod butterfly_patch;
pub mod butterfly_regions;
pub mod butterfly_table;
pub mod cone_patch;
pub mod cone_regions;
// Crate-private: the families' masks at the vertex, which the shared cone_regions builds
// (its one public item, `VertexMasks`, is re-exported there).
mod cone_vertex;
pub mod curve_stencils;
pub mod curve_system;
pub mod error;
pub mod ev_tangents;
pub mod exact_solve;
pub mod extraordinary_patch;
pub mod float_solve;
pub mod loop_basis;
pub mod orbit_block;
pub mod orbits;
pub mod patch_stencils;
pub mod rational;
pub mod region_basis;
pub mod region_table;
pub mod regular_patch;
pub mod scalar;
pub mod scaling_system;
pub mod solve;
pub mod sqrt3_fan_tangents;
pub mod sqrt3_patch;
pub mod sqrt3_regions;
pub mod sqrt3_strip;
pub mod sqrt3_table;
pub mod stencil_set;
pub mod substitution;
pub mod table;
pub mod triangle_boundary;
pub mod triangle_patch;
pub mod triangle_system;
pub mod triangle_table;

pub use curve_stencils::{curve_stencils, BasisFunction, CurveStencils};
pub use error::StencilError;
pub use scalar::Scalar;

/// The most characters of an offending argument a message quotes.
pub const EXCERPT_CHARS: usize = 60;

/// `text` as a message quotes it: whole when it has at most [`EXCERPT_CHARS`] characters,
/// else its first [`EXCERPT_CHARS`] followed by `...` and its length in bytes (a
/// million-character argument is not echoed back).
pub fn excerpt(text: &str) -> String {
    match text.char_indices().nth(EXCERPT_CHARS) {
        Some((at, _)) => format!("{}... ({} bytes)", &text[..at], text.len()),
        None => text.to_owned(),
    }
}
