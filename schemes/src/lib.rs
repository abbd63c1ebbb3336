//! Subdivision schemes as data: curves, quad schemes and triangle schemes (Loop, butterfly, √3).
//!
//! A subdivision scheme is described here only by the numbers that define it: its masks
//! (the columns of the subdivision matrix S in `p_{j+1} = S p_j`, Schaefer–Warren eq. (1))
//! and, for stationary non-uniform schemes, the finite set of special columns around the
//! non-uniformity. Nothing in this crate solves anything: `stencilgen` turns these data into
//! evaluation stencils through the scaling relation (Schaefer–Warren eq. (3)). One evaluation
//! lives here because the generator and the runtime both make it from a basis they each hold:
//! √3 beside a boundary by certified levels (`sqrt3_boundary_surface`), sums of a given regular
//! basis over rows of the rules.
//!
//! ```
//! use schemes::curve::CurveScheme;
//! let four_point = CurveScheme::by_name("four-point").expect("a catalogued scheme");
//! assert!(four_point.is_uniform());
//! assert!(four_point.reproduces_linear());
//! ```

pub mod bivariate;
pub mod butterfly_local;
pub mod butterfly_regions;
pub mod cone;
pub mod cone_local;
pub mod cone_regions;
pub mod crease;
pub mod curve;
pub mod lattice_symmetry;
pub mod local_matrices;
pub mod loop_regular;
pub mod quad;
pub mod rational;
pub mod sqrt3_boundary;
pub mod sqrt3_boundary_surface;
pub mod sqrt3_local;
pub mod sqrt3_regions;
pub mod tangent_frame;
pub mod triangle;
pub mod triangle_local;

// Crate-private: the families' rules, which the shared cone modules apply (no public items
// of its own; `ConeFamily` and `HALF_LEVEL_STEPS` are re-exported where they were).
mod cone_rules;

pub use bivariate::BivariateMask;
pub use crease::{CreaseMethod, CreaseRule};
pub use curve::{Component, CurveScheme, Term, Translates};
pub use quad::{BoundaryMode, BoundaryRules, QuadScheme, VertexRule};
pub use triangle::{LatticeMask, TriangleScheme, TriangleVertexRule, TriangleWeight};
