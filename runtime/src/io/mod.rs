//! Input and output formats: OBJ (with its `t` tags) in, OBJ / PLY / glTF out, and triangle
//! meshes in (OBJ, PLY, GLB) for `subtess render`. Bézier patch input lives with its
//! tessellator ([`crate::tessellate::bezier`]).

pub mod atomic;
pub mod mesh_input;
pub mod mesh_output;
pub mod obj;
