//! The mesh layer: polygon and triangle topology (half-edges, fans, boundaries), geometry
//! helpers on `[f64; 3]` points, and the sample locations (face and exact parameters) every
//! tessellator reports. Nothing here knows a subdivision scheme or a file format.

pub mod face_varying;
pub mod geometry;
pub mod source;
#[cfg(test)]
pub(crate) mod test_meshes;
pub mod topology;
pub mod triangle_grid;
pub mod triangle_mesh;
pub mod triangle_topology;
pub(crate) mod watertight;

pub use source::VertexSource;
pub use topology::{Mesh, NONE};
pub use triangle_mesh::TriangleMesh;
