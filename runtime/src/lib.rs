//! The subtess runtime: loads stencil tables (never runs the solver) and, as it grows,
//! evaluates and tessellates subdivision surfaces from them.
//!
//! ```
//! let table = runtime::stencil_table::StencilTable::default_catmull_clark().expect("embedded table");
//! assert!(!table.index().entries.is_empty());
//! ```

pub mod bezier;
pub mod butterfly_refine;
pub mod cone_chart;
pub mod dual_grid;
pub mod error;
pub mod exact_eval;
pub mod geometry;
pub mod isolate;
pub mod lai_cheng;
pub mod lattice_walk;
pub mod loop_exact_eval;
pub mod loop_isolate;
pub mod loop_refine;
pub mod mesh_output;
pub mod obj;
pub mod patch;
pub mod rates;
pub mod refine;
pub mod region_isolate;
pub mod region_patch;
pub mod sqrt3_refine;
pub mod stencil_table;
#[cfg(test)]
mod test_meshes;
pub mod topology;
pub mod triangle_dual_grid;
pub mod triangle_isolation;
pub mod triangle_mesh;
pub mod triangle_patch;
pub mod triangle_rates;
pub mod triangle_split;
pub mod triangle_topology;

pub use error::{MeshError, RuntimeError};
