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

/// A validated stencil table, optionally with a pinned-corner table laid over it: the one-face
/// boundary sections are then read from that one (every other patch is the same whether a
/// mesh pins its corners or not).
#[derive(Debug)]
pub struct StencilTable {
    storage: Storage,
    index: TableIndex,
    corners: Option<Box<StencilTable>>,
}

impl StencilTable {
    /// The embedded default Catmull–Clark table (validated: its checksum is verified too).
    pub fn default_catmull_clark() -> Result<Self, RuntimeError> {
        Self::embedded(tables::default_catmull_clark())
    }

    /// The embedded default Loop table (Warren's weights; validated, checksum included).
    pub fn default_loop() -> Result<Self, RuntimeError> {
        Self::embedded(tables::default_loop())
    }

    /// The embedded default butterfly table (the modified butterfly's regions around interior
    /// vertices of valence 3..=8; validated, checksum included).
    pub fn default_butterfly() -> Result<Self, RuntimeError> {
        Self::embedded(tables::default_butterfly())
    }

    /// The embedded default √3 table (the regions of two √3 steps taken as one ternary step,
    /// around interior vertices of valence 3..=8; validated, checksum included).
    pub fn default_sqrt3() -> Result<Self, RuntimeError> {
        Self::embedded(tables::default_sqrt3())
    }

    fn embedded(bytes: &'static [u8]) -> Result<Self, RuntimeError> {
        let index = TableIndex::parse(bytes)?;
        Ok(StencilTable {
            storage: Storage::Embedded(bytes),
            index,
            corners: None,
        })
    }

    /// The embedded default table for a mesh's boundary rule: for "edge and corner" meshes, the
    /// default table with the embedded pinned-corner table laid over it.
    pub fn default_for(mode: schemes::BoundaryMode) -> Result<Self, RuntimeError> {
        let mut table = Self::default_catmull_clark()?;
        if mode == schemes::BoundaryMode::EdgeAndCorner {
            table.corners = Some(Box::new(Self::embedded(
                tables::default_catmull_clark_corners(),
            )?));
        }
        Ok(table)
    }

    /// Whether one-face boundary vertices are pinned corners in this table (its own header, or
    /// a pinned-corner table laid over it).
    pub fn pins_corners(&self) -> bool {
        self.corners.is_some() || self.index.meta.corners
    }

    /// Validate a table held in memory (copied once into an aligned buffer).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RuntimeError> {
        let bytes = AlignedBytes::from_slice(bytes);
        let index = TableIndex::parse(bytes.as_bytes())?;
        Ok(StencilTable {
            storage: Storage::Owned(bytes),
            index,
            corners: None,
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
            corners: None,
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
        if let (Some(corners), true) = (&self.corners, key.boundary && key.faces == 1) {
            return corners.weights(key);
        }
        Ok(self.index.weights_f32(self.bytes(), key)?)
    }
}

/// Where the triangle tessellator gets its stencils: `points x K` f32 weights, point-major, of
/// one section on a triangle point set ([`table_format::PointSet::TrianglePrimal`], [`table_format::PointSet::TriangleDual`]);
/// a Loop [`StencilTable`], or any other source of the same layout.
pub trait TriangleStencils: Sync {
    /// The weights of `key`, or an error naming what the source covers.
    fn triangle_weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError>;
}

impl TriangleStencils for StencilTable {
    /// Triangle sections of a triangle-scheme (Loop) table; a quad table is refused by name
    /// rather than read at the wrong layout.
    fn triangle_weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError> {
        let scheme = self.index.meta.scheme;
        if !scheme.is_triangle() {
            return Err(RuntimeError::Unsupported(format!(
                "the stencil table is for {}, a quad scheme; triangle meshes need a Loop table",
                scheme.name()
            )));
        }
        self.weights(key)
    }
}
