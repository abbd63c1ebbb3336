//! Input and output formats: OBJ (with its `t` tags) in, OBJ / PLY / glTF out. Bézier patch
//! input lives with its tessellator ([`crate::tessellate::bezier`]).

pub mod mesh_output;
pub mod obj;
