//! subtess: exact evaluation and watertight tessellation of subdivision surfaces from
//! precomputed stencil tables (Schaefer and Warren's scaling-relation method).
//!
//! The layers, bottom up (docs/architecture.md): [`mesh`] (topology and geometry), [`io`]
//! (OBJ, PLY, glTF), [`stencil_table`] (the validated tables), [`scheme`] (refinement,
//! isolation and patches per scheme), [`tessellate`] (the dual grids, rates, Lai–Cheng,
//! Espino et al.) and [`eval`] (exact evaluation).

pub mod error;
pub mod eval;
pub mod io;
pub mod mesh;
pub mod scheme;
pub mod stencil_table;
pub mod tessellate;

pub use error::{MeshError, RuntimeError};
pub use mesh::Mesh;
