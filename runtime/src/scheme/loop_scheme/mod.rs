//! Loop (with Warren's weights): one refinement step on triangle meshes and the isolation of
//! extraordinary vertices.

pub mod isolate;
pub mod refine;
