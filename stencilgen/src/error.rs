//! The one error type of `stencilgen`.

use thiserror::Error;

/// Everything that can go wrong while building or solving a scaling-relation system.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StencilError {
    /// The scheme name is not in the catalogue.
    #[error("unknown scheme `{name}`; known schemes: {known}")]
    UnknownScheme {
        /// The name asked for.
        name: String,
        /// The catalogue, comma separated.
        known: String,
    },
    /// The grid rate n is outside what the solver accepts.
    #[error("grid rate n = {n} is out of range: n must be in 1..={max}")]
    RateOutOfRange {
        /// The rate asked for.
        n: u32,
        /// The largest rate accepted.
        max: u32,
    },
    /// Tangent masks were asked of a scheme without linear precision in its parameter, so the
    /// normalization `sum (k - x) phi'(x - k) = 1` (Schaefer–Warren section 4) does not hold.
    #[error("scheme `{scheme}` does not map linear data to linear data in its parameter x, so its tangent masks have no normalization (Schaefer-Warren section 4)")]
    NoLinearPrecision {
        /// The scheme.
        scheme: String,
    },
    /// The scheme cannot be used for what was asked.
    #[error("scheme `{scheme}` cannot be used here: {reason}")]
    UnsupportedScheme {
        /// The scheme.
        scheme: String,
        /// Why.
        reason: String,
    },
    /// The quantity asked for is irrational, so exact mode cannot give it.
    #[error("{what} is irrational; use the f64 mode")]
    Irrational {
        /// What was asked.
        what: String,
    },
    /// A parameter is out of its domain.
    #[error("{what}")]
    OutOfDomain {
        /// What is wrong.
        what: String,
    },
    /// A file could not be written or read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The table writer refused the sections.
    #[error(transparent)]
    Table(#[from] table_format::TableError),
    /// The equations contradict each other: no function satisfies all of them.
    #[error("the scaling-relation system of `{scheme}` at n = {n} is inconsistent: {detail}")]
    Inconsistent {
        /// The scheme.
        scheme: String,
        /// The grid rate.
        n: u32,
        /// Which equation fails and by how much.
        detail: String,
    },
    /// The equations do not determine the values: the solution space has positive dimension.
    #[error("the scaling-relation system of `{scheme}` at n = {n} has no unique solution: the block of residues {residues:?} (mod n) has rank {rank} for {unknowns} unknowns")]
    NotUnique {
        /// The scheme.
        scheme: String,
        /// The grid rate.
        n: u32,
        /// The residues (numerators mod n) of the cycle whose block is rank deficient.
        residues: Vec<u32>,
        /// The rank found.
        rank: usize,
        /// The number of unknowns of the block.
        unknowns: usize,
    },
}

impl From<schemes::local_matrices::UnsupportedNeighbourhood> for StencilError {
    fn from(e: schemes::local_matrices::UnsupportedNeighbourhood) -> Self {
        StencilError::UnsupportedScheme {
            scheme: e.scheme,
            reason: e.reason,
        }
    }
}
