//! What the triangle schemes share: the dyadic and ternary splits, the isolation record, the
//! triangle patches, and (for the butterfly and √3, whose stencils reach beyond the one-ring)
//! the cone charts, lattice walk and region patches. Nothing here imports a scheme's own
//! rules; the isolation that drives the butterfly's and √3's is [`crate::scheme::region_isolate`].

pub mod cone_chart;
pub mod isolation;
pub mod lattice_walk;
pub mod patch;
pub mod region_patch;
pub mod split;
