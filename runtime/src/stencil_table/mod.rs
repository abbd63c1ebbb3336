//! Stencil tables as the runtime uses them: the embedded default, or a file, validated once.
//! A compact table's grids are expanded from the scaling relation's pieces when a plan first
//! asks for them (`quad_expansion` for Catmull–Clark, `triangle_expansion` for Loop,
//! `region_expansion` for the butterfly and √3), then kept.

mod quad_expansion;
mod region_expansion;
mod triangle_expansion;

use std::path::Path;
use std::sync::OnceLock;

use table_format::{AlignedBytes, SectionKey, TableIndex};

use crate::RuntimeError;
use quad_expansion::QuadExpansion;
pub(crate) use region_expansion::cone_regions;
pub use region_expansion::RateBasis;
use region_expansion::RegionExpansion;
use triangle_expansion::TriangleExpansion;

/// One patch of a compact table: which vertex (and sharp feature), which sector (its pieces are keyed by these and
/// `n = 0`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct PatchId {
    boundary: bool,
    feature: table_format::Feature,
    faces: u32,
    sector: u32,
}

impl PatchId {
    /// The id as one integer, ordered as the ids are (the fields' order: `boundary`,
    /// `feature`, `faces`, `sector`).
    fn packed(self) -> u128 {
        (u128::from(self.boundary) << 72)
            | (u128::from(self.feature as u8) << 64)
            | (u128::from(self.faces) << 32)
            | u128::from(self.sector)
    }

    /// The patch a section belongs to.
    fn of(key: &SectionKey) -> Self {
        PatchId {
            boundary: key.boundary,
            feature: key.feature,
            faces: key.faces,
            sector: key.sector,
        }
    }
}

/// The expanded grids of one patch, rate and kind: primal then dual, `points x K` f32,
/// point-major.
type Grids = [Box<[f32]>; 2];

/// The largest rate a compact table may cover: the tessellators' largest
/// (`tessellate::dual_grid::MAX_RATE`, `tessellate::triangle_dual_grid::MAX_TRIANGLE_RATE`; a
/// test checks they agree). The file does not bound a compact table's rates as it bounds a
/// grid's (a curve basis is `n + 1` rows, a rate marker none), so this caps what one expansion
/// allocates, `(n + 1)^2 K` weights.
pub(crate) const MAX_COMPACT_RATE: u32 = 64;

/// The scaling-relation pieces of a validated table (its sections other than grids), `None` if
/// it has none. They are f64 only: expanded from f32, the grids would not be the grid layout's
/// to 1 ulp.
fn compact_pieces(index: &TableIndex) -> Result<Option<Vec<&SectionKey>>, RuntimeError> {
    let pieces: Vec<&SectionKey> = index
        .entries
        .iter()
        .map(|e| &e.key)
        .filter(|k| !k.points.is_grid())
        .collect();
    if pieces.is_empty() {
        return Ok(None);
    }
    if index.meta.precision != table_format::Precision::F64 {
        return Err(table_format::TableError::PrecisionMismatch {
            stored: index.meta.precision,
            asked: table_format::Precision::F64,
        }
        .into());
    }
    Ok(Some(pieces))
}

/// The other pieces of the patch whose subdivision matrix is `a` (`width` = `K` weights a row):
/// its sub-patch matrices (`sub`) and its three vertex masks, each present and `K` wide; the
/// error names the piece (`incomplete` words it for the table's scheme).
fn check_patch_pieces(
    index: &TableIndex,
    a: &SectionKey,
    width: u32,
    sub: table_format::PointSet,
    incomplete: impl Fn(String) -> RuntimeError,
) -> Result<(), RuntimeError> {
    use table_format::{PointSet, StencilKind};
    for (kind, points) in [
        (StencilKind::Position, sub),
        (StencilKind::Position, PointSet::VertexMask),
        (StencilKind::DerivativeU, PointSet::VertexMask),
        (StencilKind::DerivativeV, PointSet::VertexMask),
    ] {
        let piece = SectionKey { kind, points, ..*a };
        match index.get(&piece) {
            Some(e) if e.width == width => {}
            Some(_) => return Err(incomplete(format!("{piece} has another width than {a}"))),
            None => return Err(incomplete(format!("{a} has no {piece}"))),
        }
    }
    Ok(())
}

/// The rates and patches a compact table covers, and a slot for the grids of each patch, rate
/// and kind (position, d/du, d/dv).
#[derive(Debug)]
struct GridSlots {
    /// Ascending.
    rates: Vec<u32>,
    /// Per rate `n` up to the largest, its index in `rates` (`u32::MAX`: not covered): one
    /// load, not a search. At most [`MAX_COMPACT_RATE`] + 1 entries: every expansion refuses
    /// a rate above it before making its slots.
    rate_index: Vec<u32>,
    /// Ascending, with their control-point counts `K`.
    patches: Vec<(PatchId, u32)>,
    /// The patches' ids packed into one integer each ([`PatchId::packed`]), ascending too.
    packed: Vec<u128>,
    /// `(patch * rates + rate) * 3 + kind`.
    grids: Vec<OnceLock<Grids>>,
}

/// Where a key's grids go in [`GridSlots`].
struct Slot<'s> {
    /// The patch's index among the covered patches.
    patch: usize,
    /// The rate's index among the covered rates.
    rate: usize,
    /// The patch's `K`.
    k: usize,
    /// Its grids, once expanded.
    grids: &'s OnceLock<Grids>,
}

impl GridSlots {
    fn new(mut rates: Vec<u32>, mut patches: Vec<(PatchId, u32)>) -> Self {
        rates.sort_unstable();
        patches.sort_unstable();
        let slots = patches.len() * rates.len() * 3;
        let mut rate_index = vec![u32::MAX; rates.last().map_or(0, |&n| n as usize + 1)];
        for (i, &n) in rates.iter().enumerate() {
            rate_index[n as usize] = i as u32;
        }
        GridSlots {
            packed: patches.iter().map(|p| p.0.packed()).collect(),
            rates,
            rate_index,
            patches,
            grids: (0..slots).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The slot of `key`'s patch, rate and kind, `None` if the table does not cover them.
    fn slot(&self, key: &SectionKey) -> Option<Slot<'_>> {
        let patch = self.packed.binary_search(&PatchId::of(key).packed()).ok()?;
        let rate = match self.rate_index.get(key.n as usize) {
            Some(&i) if i != u32::MAX => i as usize,
            _ => return None,
        };
        Some(Slot {
            patch,
            rate,
            k: self.patches[patch].1 as usize,
            grids: &self.grids[(patch * self.rates.len() + rate) * 3 + key.kind as usize],
        })
    }
}

/// The expansion of a compact table, by patch family.
#[derive(Debug)]
enum Expansion {
    /// Catmull–Clark pieces.
    Quad(QuadExpansion),
    /// Loop pieces.
    Triangle(TriangleExpansion),
    /// Butterfly and √3 pieces.
    Region(RegionExpansion),
}

impl Expansion {
    /// The expansion of a validated table, `None` if it stores grids only.
    fn new(index: &TableIndex) -> Result<Option<Self>, RuntimeError> {
        use table_format::SchemeId;
        Ok(
            if matches!(index.meta.scheme, SchemeId::Butterfly | SchemeId::Sqrt3) {
                RegionExpansion::new(index)?.map(Expansion::Region)
            } else if index.meta.scheme.is_triangle() {
                TriangleExpansion::new(index)?.map(Expansion::Triangle)
            } else {
                QuadExpansion::new(index)?.map(Expansion::Quad)
            },
        )
    }

    /// The grid of `key`, expanded on first use; `None` if the table cannot expand it.
    fn grid<'s>(
        &'s self,
        index: &TableIndex,
        bytes: &[u8],
        key: &SectionKey,
    ) -> Option<Result<&'s [f32], RuntimeError>> {
        match self {
            Expansion::Quad(e) => e.grid(index, bytes, key),
            Expansion::Triangle(e) => e.grid(index, bytes, key),
            Expansion::Region(e) => e.grid(index, bytes, key),
        }
    }
}

/// Where a table's bytes live.
#[derive(Debug)]
enum Storage {
    /// Compiled into the binary.
    Embedded(&'static [u8]),
    /// Read from a file (one copy, into an aligned buffer).
    Owned(AlignedBytes),
}

impl Storage {
    fn as_bytes(&self) -> &[u8] {
        match self {
            Storage::Embedded(b) => b,
            Storage::Owned(b) => b.as_bytes(),
        }
    }
}

/// A validated stencil table, optionally with a pinned-corner table laid over it: the one-face
/// boundary sections are then read from that one (every other patch is the same whether a
/// mesh pins its corners or not).
#[derive(Debug)]
pub struct StencilTable {
    storage: Storage,
    index: TableIndex,
    /// The grids of a compact table, expanded on first use.
    expansion: Option<Expansion>,
    /// Whether the index holds any grid section (a compact table usually holds none: then a
    /// grid request goes to the expansion without a lookup in the index first).
    stores_grids: bool,
    corners: Option<Box<StencilTable>>,
}

/// The bytes of an embedded table, `tables::$function()`, when `subtess`'s cargo feature
/// `$feature` embeds it; else [`RuntimeError::NotEmbedded`] naming the scheme (whose
/// [`crate::Scheme::cargo_feature`] is `$feature`).
macro_rules! embedded_bytes {
    ($feature:literal, $scheme:ident, $function:ident) => {{
        #[cfg(feature = $feature)]
        let bytes: Result<&'static [u8], RuntimeError> = Ok(tables::$function());
        #[cfg(not(feature = $feature))]
        let bytes: Result<&'static [u8], RuntimeError> = Err(RuntimeError::NotEmbedded {
            scheme: crate::Scheme::$scheme,
        });
        bytes
    }};
}

impl StencilTable {
    /// The embedded default Catmull–Clark table (validated: its checksum is verified too);
    /// [`RuntimeError::NotEmbedded`] without the cargo feature `catmull-clark`.
    pub fn default_catmull_clark() -> Result<Self, RuntimeError> {
        Self::embedded(embedded_bytes!(
            "catmull-clark",
            CatmullClark,
            default_catmull_clark
        )?)
    }

    /// The embedded default Loop table (Warren's weights; validated, checksum included);
    /// [`RuntimeError::NotEmbedded`] without the cargo feature `loop`.
    pub fn default_loop() -> Result<Self, RuntimeError> {
        Self::embedded(embedded_bytes!("loop", Loop, default_loop)?)
    }

    /// The embedded default butterfly table (the modified butterfly's regions around interior
    /// vertices of valence 3..=8; validated, checksum included); [`RuntimeError::NotEmbedded`]
    /// without the cargo feature `butterfly`.
    pub fn default_butterfly() -> Result<Self, RuntimeError> {
        Self::embedded(embedded_bytes!("butterfly", Butterfly, default_butterfly)?)
    }

    /// The embedded default √3 table (the regions of two √3 steps taken as one ternary step,
    /// around interior vertices of valence 3..=8; validated, checksum included);
    /// [`RuntimeError::NotEmbedded`] without the cargo feature `sqrt3`.
    pub fn default_sqrt3() -> Result<Self, RuntimeError> {
        Self::embedded(embedded_bytes!("sqrt3", Sqrt3, default_sqrt3)?)
    }

    fn embedded(bytes: &'static [u8]) -> Result<Self, RuntimeError> {
        Self::validated(Storage::Embedded(bytes))
    }

    /// A table over bytes whose index is valid (and, for files, whose weights are finite).
    fn validated(storage: Storage) -> Result<Self, RuntimeError> {
        let bytes = storage.as_bytes();
        let index = TableIndex::parse(bytes)?;
        if matches!(storage, Storage::Owned(_)) {
            index.check_finite(bytes)?;
        }
        Ok(StencilTable {
            expansion: Expansion::new(&index)?,
            stores_grids: index.entries.iter().any(|e| e.key.points.is_grid()),
            storage,
            index,
            corners: None,
        })
    }

    /// The embedded default table for a mesh's boundary rule: for "edge and corner" meshes, the
    /// default table with the embedded pinned-corner table laid over it.
    /// [`RuntimeError::NotEmbedded`] without the cargo feature `catmull-clark`.
    pub fn default_for(mode: schemes::BoundaryMode) -> Result<Self, RuntimeError> {
        let mut table = Self::default_catmull_clark()?;
        if mode == schemes::BoundaryMode::EdgeAndCorner {
            table.corners = Some(Box::new(Self::embedded(embedded_bytes!(
                "catmull-clark",
                CatmullClark,
                default_catmull_clark_corners
            )?)?));
        }
        Ok(table)
    }

    /// Whether one-face boundary vertices are pinned corners in this table (its own header, or
    /// a pinned-corner table laid over it).
    pub fn pins_corners(&self) -> bool {
        self.corners.is_some() || self.index.meta.corners
    }

    /// Validate a table held in memory (copied once into an aligned buffer), every weight
    /// finite included.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RuntimeError> {
        Self::validated(Storage::Owned(AlignedBytes::from_slice(bytes)))
    }

    /// Read and validate a table file. The fixed-size header is read and checked first
    /// ([`table_format::check_header`]: magic, version, the declared size against the file's
    /// length and [`table_format::MAX_FILE_SIZE`]); only then is the rest read, then every
    /// weight checked to be finite ([`table_format::TableIndex::check_finite`]).
    pub fn read(path: &Path) -> Result<Self, RuntimeError> {
        use std::io::Read;
        let io = |source| RuntimeError::Io {
            path: path.display().to_string(),
            source,
        };
        let mut file = std::fs::File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let mut head = Vec::with_capacity(table_format::HEADER_SIZE);
        file.by_ref()
            .take(table_format::HEADER_SIZE as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        table_format::check_header(&head, len)?;
        // At most MAX_FILE_SIZE (4 GiB), checked above.
        let len = usize::try_from(len)
            .map_err(|_| table_format::TableError::TooLarge { declared: len })?;
        let bytes = AlignedBytes::read_from(head.as_slice().chain(file), len).map_err(io)?;
        Self::validated(Storage::Owned(bytes))
    }

    /// The raw bytes.
    pub fn bytes(&self) -> &[u8] {
        self.storage.as_bytes()
    }

    /// What the table holds.
    pub fn index(&self) -> &TableIndex {
        &self.index
    }

    /// Whether the table stores the scaling relation's pieces and expands its grids
    /// (docs/table-format.md, "Compact quad tables" and "Compact Loop tables").
    pub fn is_compact(&self) -> bool {
        self.expansion.is_some()
    }

    /// The f32 weights of one section: `points x K`, point-major. Zero-copy for a table that
    /// stores its grids; for a compact one, expanded on the first request (both grids of the
    /// key's patch, rate and kind: about 0.2 ms for a Catmull–Clark patch at rate 24, 2 ms for
    /// a Loop one, docs/benchmarks.md) and kept for the table's lifetime.
    pub fn weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError> {
        if let (Some(corners), true) = (&self.corners, key.boundary && key.faces == 1) {
            return corners.weights(key);
        }
        match &self.expansion {
            Some(expansion)
                if (key.points.is_grid() && !self.stores_grids)
                    || self.index.get(key).is_none() =>
            {
                expansion
                    .grid(&self.index, self.bytes(), key)
                    .unwrap_or_else(|| {
                        Err(table_format::TableError::MissingSection {
                            key: *key,
                            coverage: self.index.coverage(),
                        }
                        .into())
                    })
            }
            _ => Ok(self.index.weights_f32(self.bytes(), key)?),
        }
    }
}

/// Where the triangle tessellator gets its stencils: `points x K` f32 weights, point-major, of
/// one section on a triangle point set ([`table_format::PointSet::TrianglePrimal`], [`table_format::PointSet::TriangleDual`]);
/// a Loop [`StencilTable`], or any other source of the same layout.
pub trait TriangleStencils: Sync {
    /// The weights of `key`, or an error naming what the source covers.
    fn triangle_weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError>;
}

impl StencilTable {
    /// The regular basis of a compact √3 (or butterfly) table at rate `n`, on the grid `1/3n`:
    /// what √3's boundary patches are evaluated from
    /// (`crate::scheme::sqrt3::boundary_grids`). Refused, naming the table, for a
    /// table that stores grids only or lacks the rate.
    pub fn regular_basis(&self, n: u32) -> Result<&RateBasis, RuntimeError> {
        let missing = || {
            RuntimeError::Unsupported(format!(
                "the {} table has no regular basis at rate {n} (boundary patches are evaluated \
                 from a compact table's basis: regenerate it with stencilgen tables)",
                self.index.meta.scheme.name()
            ))
        };
        match &self.expansion {
            Some(Expansion::Region(e)) => e
                .regular_basis(&self.index, self.bytes(), n)
                .unwrap_or_else(|| Err(missing())),
            _ => Err(missing()),
        }
    }
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

// The test starts from the embedded Catmull–Clark table's header.
#[cfg(all(test, feature = "catmull-clark"))]
mod tests {
    use super::*;

    /// A sparse file of `len` bytes (no disk used) that starts with `head`.
    fn sparse(name: &str, head: &[u8], len: u64) -> std::path::PathBuf {
        use std::io::Write;
        let path =
            std::env::temp_dir().join(format!("subtess-table-{}-{name}", std::process::id()));
        let mut file = std::fs::File::create(&path).expect("temp file");
        file.write_all(head).expect("header");
        file.set_len(len).expect("sparse length");
        path
    }

    /// Issue 20: a 100 GiB sparse file given as a table is refused from its 64-byte header
    /// (before the fix the reader allocated the file's whole length first).
    #[test]
    fn absurd_files_are_refused_from_the_header() {
        let huge = 100u64 << 30;
        let real = tables::default_catmull_clark();
        let head = &real[..table_format::HEADER_SIZE];
        // A real header on a file of another length.
        let path = sparse("mismatch", head, huge);
        let e = StencilTable::read(&path).expect_err("length disagrees with the header");
        std::fs::remove_file(&path).ok();
        assert!(e.to_string().contains("file size"), "{e}");
        // A header that declares the absurd length itself.
        let mut declared = head.to_vec();
        declared[32..40].copy_from_slice(&huge.to_le_bytes());
        let path = sparse("declared", &declared, huge);
        let e = StencilTable::read(&path).expect_err("over the limit");
        std::fs::remove_file(&path).ok();
        assert!(e.to_string().contains("4 GiB"), "{e}");
        // Not a table at all.
        let path = sparse("zeros", &[], huge);
        let e = StencilTable::read(&path).expect_err("no magic");
        std::fs::remove_file(&path).ok();
        assert!(e.to_string().contains("not a subtess stencil table"), "{e}");
        // A real table still reads.
        let path = sparse("real", real, real.len() as u64);
        let table = StencilTable::read(&path).expect("a valid table");
        std::fs::remove_file(&path).ok();
        assert_eq!(table.bytes(), real);
    }
}
