//! Catmull–Clark: one refinement step on polygon meshes and the isolation of extraordinary
//! vertices (every face a table patch with at most one irregular corner).

pub mod adaptive;
pub mod face_varying;
pub mod isolate;
pub mod refine;
