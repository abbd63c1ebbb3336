//! The one error type of the runtime.

use thiserror::Error;

/// What is wrong with a mesh's topology or geometry; every variant names the face or vertex
/// (0-based, with the OBJ file's 1-based number or line beside it).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    /// No faces.
    #[error("the mesh has no faces")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} (OBJ `v` number {}) has a non-finite coordinate {position:?}", vertex + 1)]
    NonFinite {
        /// 0-based vertex.
        vertex: usize,
        /// Its position.
        position: [f64; 3],
    },
    /// A coordinate's magnitude exceeds [`crate::mesh::topology::MAX_COORDINATE`]: beyond what
    /// `f32` output and its normals hold.
    #[error("vertex {vertex} (OBJ `v` number {}) has a coordinate beyond {limit:e} in magnitude {position:?} (the output is f32: positions and normals must stay finite)", vertex + 1)]
    TooLarge {
        /// 0-based vertex.
        vertex: usize,
        /// Its position.
        position: [f64; 3],
        /// The bound.
        limit: f64,
    },
    /// A face-varying channel (texture coordinates) does not fit its mesh.
    #[error("texture coordinates: {0}")]
    FaceVarying(String),
    /// A face is malformed.
    #[error("face {face} (OBJ line {line}): {reason}")]
    BadFace {
        /// 0-based face.
        face: usize,
        /// 1-based OBJ line (0 when not from a file).
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A face is not yet a table patch: it needs Catmull–Clark isolation steps first.
    #[error("face {face} is not an isolated patch: {reason}")]
    NotIsolated {
        /// 0-based face.
        face: usize,
        /// Why.
        reason: String,
    },
    /// A triangle scheme (Loop) was asked of a mesh with a face that is not a triangle.
    #[error("face {face} has {vertices} vertices; the triangle schemes (loop, butterfly, sqrt3) need a mesh of triangles (triangulate it, or use --scheme catmull-clark)")]
    NotTriangle {
        /// 0-based face.
        face: usize,
        /// Its number of vertices.
        vertices: usize,
    },
    /// A `t` tag line is malformed or names something the mesh lacks.
    #[error("tag `{name}` (OBJ line {line}): {reason}")]
    BadTag {
        /// The tag's name.
        name: String,
        /// 1-based OBJ line.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A tag names an edge the mesh does not have.
    #[error("there is no edge between vertices {a} and {b} (0-based, as tags count)")]
    NoSuchEdge {
        /// 0-based end vertex.
        a: usize,
        /// 0-based end vertex.
        b: usize,
    },
    /// A tag names a vertex the mesh does not have.
    #[error("there is no vertex {vertex} (0-based, as tags count)")]
    NoSuchVertex {
        /// 0-based vertex.
        vertex: usize,
    },
    /// A tag names a face the mesh does not have.
    #[error("there is no face {face} (0-based, as tags count)")]
    NoSuchFace {
        /// 0-based face.
        face: usize,
    },
}

/// Everything the runtime can fail at.
#[derive(Debug, Error)]
pub enum RuntimeError {
    /// A stencil table is invalid, or lacks what was asked of it.
    #[error(transparent)]
    Table(#[from] table_format::TableError),
    /// An OBJ line is malformed (text parsed without a file name).
    #[error("OBJ line {line}: {message}")]
    Obj {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A line of an input file (OBJ, Newell patches, `.bpt`) is malformed.
    #[error("{path}:{line}: {message}")]
    ParseFile {
        /// The file (or a name for text parsed without one).
        path: String,
        /// 1-based line (0 when the problem is not on one line, e.g. an empty file).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The mesh is not one the surface can be built on.
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
    /// A table section's width disagrees with the patch's control-point count.
    #[error("the table's {key} has {table} weights per point, the face's patch has {patch} control points")]
    LayoutMismatch {
        /// The section.
        key: table_format::SectionKey,
        /// Its width.
        table: usize,
        /// The patch's point count.
        patch: usize,
    },
    /// The mesh pins its one-face boundary corners and the table does not, or the reverse.
    #[error("the mesh's boundary rule is {} but the stencil table was made for {}; `stencilgen tables --boundary{}` makes a matching table", if *mesh_corners { "edge and corner" } else { "edge only" }, if *mesh_corners { "edge only" } else { "edge and corner" }, if *mesh_corners { " --corners" } else { "" })]
    BoundaryModeMismatch {
        /// Whether the mesh pins corners.
        mesh_corners: bool,
    },
    /// A scheme's default table was asked for, but this build does not embed it: `subtess` was
    /// built without the scheme's cargo feature ([`crate::Scheme::cargo_feature`]).
    #[error("the {scheme} table is not embedded in this build: enable subtess's cargo feature `{}`, or give a table file (the CLI's --table FILE)", scheme.cargo_feature())]
    NotEmbedded {
        /// The scheme whose table is missing.
        scheme: crate::Scheme,
    },
    /// Something the runtime does not do yet, said plainly.
    #[error("not supported yet: {0}")]
    Unsupported(String),
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// An output (a tessellation, a refinement, an adaptive tessellation) would exceed a
    /// budget (docs/reliability.md): what was estimated, the limit, and how to raise it.
    #[error("{what} would be too large: about {estimate}; the limit is {limit} ({raise})")]
    OverBudget {
        /// The output.
        what: String,
        /// Its estimated size.
        estimate: String,
        /// The limit it exceeds.
        limit: String,
        /// The flag that raises the limit, or why it cannot be raised.
        raise: String,
    },
    /// A parameter is malformed or outside its domain (a rational `u` or `v`, a face, a corner,
    /// a tolerance, a camera, a set of rates).
    #[error("invalid {name}: {reason}")]
    InvalidParameter {
        /// Which parameter, or its text as given.
        name: String,
        /// Its value and what it must be.
        reason: String,
    },
}

/// The most characters of an offending token or line an error message quotes.
pub const EXCERPT_CHARS: usize = 60;

/// `text` as an error message quotes it: whole when it has at most [`EXCERPT_CHARS`]
/// characters, else its first [`EXCERPT_CHARS`] followed by `...` and its length in bytes (a
/// 200 MB token was echoed whole). Every parser's message quotes through here.
pub fn excerpt(text: &str) -> String {
    match text.char_indices().nth(EXCERPT_CHARS) {
        None => text.to_owned(),
        Some((end, _)) => format!("{}... ({} bytes)", &text[..end], text.len()),
    }
}

impl RuntimeError {
    /// An out-of-range tessellator option (a threshold, a resolution, a budget), said in full.
    pub fn invalid_option(reason: String) -> Self {
        RuntimeError::InvalidParameter {
            name: "option".to_owned(),
            reason,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn excerpts_are_short() {
        assert_eq!(excerpt("abc"), "abc");
        let exact = "x".repeat(EXCERPT_CHARS);
        assert_eq!(excerpt(&exact), exact);
        let long = "é".repeat(1_000_000);
        let quoted = excerpt(&long);
        assert!(quoted.starts_with(&"é".repeat(EXCERPT_CHARS)), "{quoted}");
        assert!(quoted.ends_with("... (2000000 bytes)"), "{quoted}");
        assert!(quoted.len() < 2 * EXCERPT_CHARS + 30);
    }
}
