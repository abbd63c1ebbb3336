//! The scheme layer: for every subdivision scheme its refinement rules, the isolation of
//! irregular vertices by refinement, and the patches (which table stencils a face reads, and
//! from which control points). Above the mesh layer and the stencil tables, below the
//! tessellators.

pub mod butterfly;
pub mod catmull_clark;
pub mod loop_scheme;
pub mod patch;
pub mod sqrt3;
pub mod stencil;
pub mod triangle;
