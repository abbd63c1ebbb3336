//! Kobbelt's √3: two steps composed into one ternary refinement of triangle meshes, with
//! Kobbelt's boundary rules. Its isolation and interior region patches are shared with the
//! butterfly ([`crate::scheme::region_isolate`]); the triangles the boundary shapes are its
//! own boundary patches ([`boundary_patch`]), whose grids a plan makes ([`boundary_grids`]).

pub mod boundary_grids;
pub mod boundary_patch;
pub mod refine;
