//! The one error type of the runtime.

use thiserror::Error;

/// Everything the runtime can fail at.
#[derive(Debug, Error)]
pub enum RuntimeError {
    /// A stencil table is invalid, or lacks what was asked of it.
    #[error(transparent)]
    Table(#[from] table_format::TableError),
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}
