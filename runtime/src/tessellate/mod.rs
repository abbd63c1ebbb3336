//! The tessellators: the dual grid for quads and for triangles (Schaefer and Warren), their
//! rate selection (per face, tolerance, view), Lai and Cheng's error-bounded adaptive method,
//! and Espino et al.'s displacement-map tessellation of Bézier patches; all write a
//! [`crate::mesh::TriangleMesh`].

pub mod bezier;
mod difference_norm;
pub mod dual_grid;
mod kernel;
pub mod lai_cheng;
mod lane_stencils;
mod loop_quartic;
mod mirror_stencils;
pub(crate) mod rate_memory;
pub mod rates;
mod sub_patches;
pub mod triangle_dual_grid;
pub mod triangle_rates;

pub use kernel::GridPlan;
pub(crate) use kernel::{total_bytes, vec_bytes};
