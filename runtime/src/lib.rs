//! subtess: exact evaluation and watertight tessellation of subdivision surfaces from
//! precomputed stencil tables (Schaefer and Warren's scaling-relation method).
//!
//! A [`Surface`] is a mesh's topology prepared once for a [`Scheme`]; a [`Tessellator`] is a
//! tessellation planned once at some [`Rates`]; every frame, [`Tessellator::evaluate`] maps the
//! *input* control points to positions and normals, no refinement involved:
//!
//! ```
//! let mesh = subtess::Mesh::read_obj(concat!(env!("CARGO_MANIFEST_DIR"), "/data/cube.obj"))?;
//! let surface = subtess::Surface::new(&mesh, subtess::Scheme::CatmullClark)?;
//! let mut tessellator = surface.tessellator(&subtess::Rates::Uniform(8))?;
//! let mut positions = mesh.positions_f32();
//! positions[0][2] -= 0.5; // animate: move a control point, keep the topology
//! let triangles = tessellator.triangle_count();
//! let frame = tessellator.evaluate(&positions)?; // borrows the tessellator until the next frame
//! assert_eq!(frame.triangles().len(), triangles);
//! assert!(frame.normals().iter().all(|n| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-4));
//! # Ok::<(), subtess::RuntimeError>(())
//! ```
//!
//! Exact evaluation at rational parameters is [`eval::limit_point`]; Lai and Cheng's
//! error-bounded adaptive tessellation is [`Surface::tessellate_adaptive`]; Espino et al.'s
//! Bézier tessellation is [`tessellate_bezier`].
//!
//! The layers, bottom up (docs/architecture.md): [`mesh`] (topology and geometry), [`io`]
//! (OBJ, PLY, glTF), [`stencil_table`] (the validated tables), [`scheme`] (refinement,
//! isolation and patches per scheme), [`tessellate`] (the dual grids, rates, Lai–Cheng,
//! Espino et al.), [`eval`] (exact evaluation), and the facade ([`Surface`]). The layers are
//! public for tools and tests that need one piece; the root names are the stable contract.

pub mod budget;
pub mod error;
pub mod eval;
pub mod io;
pub mod mesh;
mod once;
pub mod render;
pub mod scheme;
pub mod stencil_table;
mod surface;
pub mod tessellate;

pub use budget::{OutputEstimate, DEFAULT_MAX_TRIANGLES};
pub use error::{MeshError, RuntimeError};
pub use eval::exact_eval::{parse_rational, LimitPoint};
pub use io::mesh_output::MeshFormat;
pub use mesh::face_varying::{FaceVarying, FaceVaryingMode};
pub use mesh::triangle_mesh::TriangleMesh;
pub use mesh::{Mesh, VertexSource};
pub use scheme::Scheme;
pub use schemes::BoundaryMode;
pub use stencil_table::StencilTable;
pub use surface::{Frame, Rates, Surface, Tessellator};
pub use tessellate::bezier::{tessellate_bezier, BezierOptions, BezierPatches, BezierStats};
pub use tessellate::lai_cheng::{AdaptiveMesh, AdaptiveOptions, AdaptiveStats};
pub use tessellate::rates::ViewCamera;
