//! Stencil tables as the runtime uses them: the embedded default, or a file, validated once.

use std::path::Path;

use table_format::{AlignedBytes, SectionKey, TableIndex};

use crate::RuntimeError;

/// Where a table's bytes live.
#[derive(Debug)]
enum Storage {
    /// Compiled into the binary.
    Embedded(&'static [u8]),
    /// Read from a file (one copy, into an aligned buffer).
    Owned(AlignedBytes),
}

/// A validated stencil table.
#[derive(Debug)]
pub struct StencilTable {
    storage: Storage,
    index: TableIndex,
}

impl StencilTable {
    /// The embedded default Catmull–Clark table (validated: its checksum is verified too).
    pub fn default_catmull_clark() -> Result<Self, RuntimeError> {
        let bytes = tables::default_catmull_clark();
        let index = TableIndex::parse(bytes)?;
        Ok(StencilTable {
            storage: Storage::Embedded(bytes),
            index,
        })
    }

    /// Validate a table held in memory (copied once into an aligned buffer).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RuntimeError> {
        let bytes = AlignedBytes::from_slice(bytes);
        let index = TableIndex::parse(bytes.as_bytes())?;
        Ok(StencilTable {
            storage: Storage::Owned(bytes),
            index,
        })
    }

    /// Read and validate a table file.
    pub fn read(path: &Path) -> Result<Self, RuntimeError> {
        let bytes = AlignedBytes::read(path).map_err(|source| RuntimeError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let index = TableIndex::parse(bytes.as_bytes())?;
        Ok(StencilTable {
            storage: Storage::Owned(bytes),
            index,
        })
    }

    /// The raw bytes.
    pub fn bytes(&self) -> &[u8] {
        match &self.storage {
            Storage::Embedded(b) => b,
            Storage::Owned(b) => b.as_bytes(),
        }
    }

    /// What the table holds.
    pub fn index(&self) -> &TableIndex {
        &self.index
    }

    /// The f32 weights of one section: `points x K`, point-major (zero-copy).
    pub fn weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError> {
        Ok(self.index.weights_f32(self.bytes(), key)?)
    }
}
