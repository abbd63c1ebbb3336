//! The modified butterfly (Zorin, Schröder and Sweldens 1996): one refinement step on closed
//! triangle meshes. Its isolation and region patches are shared with √3
//! ([`crate::scheme::region_isolate`]).

pub mod refine;
