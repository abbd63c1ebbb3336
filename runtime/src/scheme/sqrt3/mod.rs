//! Kobbelt's √3: two steps composed into one ternary refinement of closed triangle meshes. Its
//! isolation and region patches are shared with the butterfly
//! ([`crate::scheme::region_isolate`]).

pub mod refine;
