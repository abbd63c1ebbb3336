//! The versioned binary stencil-table format (documented byte by byte in
//! `docs/table-format.md`).
//!
//! A table holds, for one subdivision scheme, the evaluation stencils of patches next to
//! interior vertices of some valences and boundary vertices of some face counts, on the primal
//! and dual grids of some rates `n`, for positions and both first derivatives. `stencilgen`
//! writes tables with [`encode`]; the runtime reads them with [`Table::parse`], which validates
//! everything (magic, version, endianness, a checksum over every byte but its own, every
//! section's bounds, alignment and shape) before it hands out weights as zero-copy `&[f32]`
//! (or `&[f64]`) slices.
//!
//! ```
//! use table_format::{encode, Feature, PointSet, Precision, SchemeId, SectionKey, StencilKind, Table, TableMeta};
//! let key = SectionKey { kind: StencilKind::Position, points: PointSet::Dual, boundary: false, feature: Feature::None, faces: 4, sector: 0, n: 1 };
//! let meta = TableMeta { scheme: SchemeId::CatmullClark, precision: Precision::F32, corners: false };
//! let bytes = encode(meta, &[(key, 16, vec![1.0 / 16.0; 16])]).expect("valid sections");
//! let aligned = table_format::AlignedBytes::from_slice(&bytes);
//! let table = Table::parse(aligned.as_bytes()).expect("a valid table");
//! assert_eq!(table.weights_f32(&key).expect("present").len(), 16);
//! ```

use std::collections::BTreeMap;
use std::fmt;

use thiserror::Error;

/// The first eight bytes of every table.
pub const MAGIC: [u8; 8] = *b"SUBTESS\0";
/// The format version this crate reads and writes. Version 5 turned the index entry's reserved
/// byte 3 into the patch's sharp feature ([`Feature`]: the dart patches of Catmull–Clark
/// tables) and added the compact region tables' pieces ([`PointSet::RegionBasis`],
/// [`PointSet::RegionRows`]; the butterfly's and √3's grids are expanded from them as Loop's
/// are). Version 4 added the scaling relation's
/// pieces as sections ([`PointSet::CurveBasis`], [`PointSet::VertexMask`],
/// [`PointSet::Subdivision`], [`PointSet::SubPatches`]; for Loop [`PointSet::LoopBasis`],
/// [`PointSet::SubTriangles`], [`PointSet::TriangleRate`]), from which a reader expands the
/// grid stencils; version 3 extended the checksum over the header and the section index (version 2
/// hashed the bytes after the header only, so a changed boundary-mode flag was read as the
/// other mode). Older files are refused.
pub const VERSION: u32 = 5;
/// Size of the fixed header.
pub const HEADER_SIZE: usize = 64;
/// Where the header keeps the checksum (a u64): the one run of bytes [`checksum`] leaves out.
pub const CHECKSUM_OFFSET: usize = 40;
/// Size of one section-index entry.
pub const ENTRY_SIZE: usize = 40;
/// Every section starts at a multiple of this.
pub const SECTION_ALIGN: usize = 64;
/// The largest table file a reader accepts, 4 GiB (the embedded default tables are 1–60 MB). A
/// header declaring more is refused by [`check_header`] before the rest of the file is read.
pub const MAX_FILE_SIZE: u64 = 4 << 30;
/// Written as a little-endian u32 at offset 12: reads back as this only on a little-endian
/// reading of a little-endian file.
pub const ENDIAN_MARK: u32 = 0x0102_0304;

/// Everything that can be wrong with a table, or with a request to it.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum TableError {
    /// The file does not start with [`MAGIC`].
    #[error("not a subtess stencil table: the file starts with {found:02x?}, not \"SUBTESS\\0\"")]
    BadMagic {
        /// The first bytes found.
        found: Vec<u8>,
    },
    /// A format version this reader does not know: an older one (1 or 2, whose checksums do
    /// not cover the header) or a newer one. The message names both versions and the command
    /// that regenerates the table.
    #[error("stencil table format version {found} is not supported (this build reads version {supported} only): {}", version_advice(.found, .supported))]
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// The endianness mark is wrong.
    #[error("the table's endianness mark reads {found:#010x}, expected {ENDIAN_MARK:#010x} (tables are little-endian)")]
    Endianness {
        /// The mark found.
        found: u32,
    },
    /// The file is shorter than its header says.
    #[error("the table is truncated: {what} needs {needed} bytes, the file has {len}")]
    Truncated {
        /// What did not fit.
        what: String,
        /// Bytes needed.
        needed: u64,
        /// Bytes present.
        len: u64,
    },
    /// The header declares a file larger than [`MAX_FILE_SIZE`].
    #[error("the table's header declares {declared} bytes, more than the {MAX_FILE_SIZE} bytes (4 GiB) a table may have")]
    TooLarge {
        /// The file size in the header.
        declared: u64,
    },
    /// The checksum over every byte but its own (header, index, weights) does not match.
    #[error("the table is corrupt: its checksum over the header, the section index and the weights (every byte but bytes {CHECKSUM_OFFSET}..{}) is {computed:#018x}, not the stored {stored:#018x}", CHECKSUM_OFFSET + 8)]
    Checksum {
        /// The stored checksum.
        stored: u64,
        /// The checksum of the bytes present.
        computed: u64,
    },
    /// A header field holds a value this format does not define.
    #[error("the table's {field} field holds {value}, which this format does not define")]
    BadField {
        /// The field.
        field: &'static str,
        /// Its value.
        value: u64,
    },
    /// A weight is NaN or infinite (behind a valid checksum).
    #[error("section {key} has a weight that is not finite at point {point}; regenerate the table with `stencilgen tables`")]
    NonFinite {
        /// The section.
        key: SectionKey,
        /// The grid point (row) holding it.
        point: usize,
    },
    /// A section lies (partly) outside the file.
    #[error("section {index} ({key}) spans bytes {offset}..{end}, outside the {len}-byte file")]
    SectionOutOfBounds {
        /// Section index.
        index: usize,
        /// The section.
        key: SectionKey,
        /// Start.
        offset: u64,
        /// End.
        end: u64,
        /// File length.
        len: u64,
    },
    /// A section is not aligned for its float type, or overlaps the header or index.
    #[error(
        "section {index} ({key}) at offset {offset} is misaligned or overlaps the header/index"
    )]
    Misaligned {
        /// Section index.
        index: usize,
        /// The section.
        key: SectionKey,
        /// Its offset.
        offset: u64,
    },
    /// A section's byte length disagrees with its shape.
    #[error("section {index} ({key}) has {length} bytes, but {points} points x {width} weights x {precision} bytes = {expected}")]
    WrongShape {
        /// Section index.
        index: usize,
        /// The section.
        key: SectionKey,
        /// Stored length.
        length: u64,
        /// Points (rows).
        points: u32,
        /// Weights per point.
        width: u32,
        /// Bytes per weight.
        precision: u32,
        /// The length the shape implies.
        expected: u64,
    },
    /// A section's point set is for the other kind of patch (triangle point sets in a quad
    /// scheme's table or the reverse; [`PointSet::belongs_to`]).
    #[error("section {key} uses a point set that does not belong to {scheme} patches")]
    WrongPointSet {
        /// The section.
        key: SectionKey,
        /// The table's scheme.
        scheme: &'static str,
    },
    /// Two index entries describe the same section.
    #[error("section {key} appears twice in the index")]
    DuplicateSection {
        /// The section.
        key: SectionKey,
    },
    /// The table has no section for what was asked.
    #[error("this table has no {key}: it covers {coverage}; `stencilgen tables` can generate a table that has it (e.g. with --valences, --boundary, --n)")]
    MissingSection {
        /// What was asked.
        key: SectionKey,
        /// What the table covers.
        coverage: String,
    },
    /// The weights were asked in the other precision.
    #[error("the table stores {stored} weights, not {asked}")]
    PrecisionMismatch {
        /// Stored precision.
        stored: Precision,
        /// Asked precision.
        asked: Precision,
    },
    /// The buffer handed to the reader is not aligned for zero-copy access.
    #[error("the table buffer is not 8-byte aligned; load it with AlignedBytes")]
    UnalignedBuffer,
    /// Sections handed to the writer are inconsistent.
    #[error("cannot encode the table: {0}")]
    Encode(String),
}

/// What to do about a table of another format version: older ones are regenerated, newer ones
/// need the build that wrote them (or are regenerated too).
fn version_advice(found: &u32, supported: &u32) -> &'static str {
    if found < supported {
        "the file was written by an older subtess; regenerate it with this build's \
         `stencilgen tables ... -o FILE` and the options it was made with (docs/table-format.md \
         lists those of the embedded defaults)"
    } else {
        "the file was written by a newer subtess; read it with that build, or regenerate it with \
         this build's `stencilgen tables ... -o FILE`"
    }
}

/// The checksum a table stores at [`CHECKSUM_OFFSET`]: XXH3-64 (seed 0) of every byte of
/// `bytes` but the checksum's own eight, that is of `bytes[..40]` followed by `bytes[48..]`
/// (streamed, no copy). Covering the header and index too (since format version 3) means a
/// changed flag, count or scheme id is refused, not read as another table. `bytes` shorter
/// than the header are hashed as they are (the reader refuses them before asking).
pub fn checksum(bytes: &[u8]) -> u64 {
    let mut hasher = xxhash_rust::xxh3::Xxh3Default::new();
    hasher.update(&bytes[..bytes.len().min(CHECKSUM_OFFSET)]);
    hasher.update(bytes.get(CHECKSUM_OFFSET + 8..).unwrap_or(&[]));
    hasher.digest()
}

/// The scheme a table belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SchemeId {
    /// Catmull–Clark.
    CatmullClark = 1,
    /// Schaefer–Warren's non-polynomial quad scheme.
    SwNonpolyQuad = 2,
    /// Loop with Warren's rational weights (a triangle scheme: triangle point sets).
    Loop = 3,
    /// The modified butterfly (a triangle scheme; `sector` numbers a vertex's regions).
    Butterfly = 4,
    /// √3 subdivision (Kobbelt 2000) as two-step ternary stencils (a triangle scheme; `sector`
    /// numbers a vertex's regions, as for the butterfly).
    Sqrt3 = 5,
}

impl SchemeId {
    /// The catalogue name.
    pub fn name(self) -> &'static str {
        match self {
            SchemeId::CatmullClark => "catmull-clark",
            SchemeId::SwNonpolyQuad => "sw-nonpoly-quad",
            SchemeId::Loop => "loop",
            SchemeId::Butterfly => "butterfly",
            SchemeId::Sqrt3 => "sqrt3",
        }
    }

    /// Whether the scheme subdivides triangles (its sections use the triangle point sets).
    pub fn is_triangle(self) -> bool {
        matches!(self, SchemeId::Loop | SchemeId::Butterfly | SchemeId::Sqrt3)
    }

    /// From the catalogue name.
    pub fn from_name(name: &str) -> Option<Self> {
        [
            SchemeId::CatmullClark,
            SchemeId::SwNonpolyQuad,
            SchemeId::Loop,
            SchemeId::Butterfly,
            SchemeId::Sqrt3,
        ]
        .into_iter()
        .find(|s| s.name() == name)
    }

    fn from_u32(v: u32) -> Option<Self> {
        match v {
            1 => Some(SchemeId::CatmullClark),
            2 => Some(SchemeId::SwNonpolyQuad),
            3 => Some(SchemeId::Loop),
            4 => Some(SchemeId::Butterfly),
            5 => Some(SchemeId::Sqrt3),
            _ => None,
        }
    }
}

/// Bytes per stored weight.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Precision {
    /// IEEE binary32.
    F32 = 4,
    /// IEEE binary64.
    F64 = 8,
}

impl fmt::Display for Precision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        })
    }
}

/// What a section's stencils evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StencilKind {
    /// Limit positions.
    Position = 0,
    /// d/du.
    DerivativeU = 1,
    /// d/dv.
    DerivativeV = 2,
}

/// Which grid a section covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PointSet {
    /// `(i/n, j/n)`, `0 <= i, j <= n`, `j` outer: `(n+1)^2` points.
    Primal = 0,
    /// `((2i+1)/2n, (2j+1)/2n)`, `0 <= i, j < n`, `j` outer: `n^2` points.
    Dual = 1,
    /// Triangle patches: `(i/n, j/n)`, `i + j <= n`, `j` outer, `i` inner: `(n+1)(n+2)/2`
    /// points.
    TrianglePrimal = 2,
    /// Triangle patches: the centroids of the `n^2` small triangles, row by row (`j` outer),
    /// each row `up(0,j), down(0,j), up(1,j), .., up(n-1-j, j)`, where `up(i,j)` is the
    /// triangle `(i,j), (i+1,j), (i,j+1)` with centroid `((3i+1)/3n, (3j+1)/3n)` and
    /// `down(i,j)` the triangle `(i+1,j), (i,j+1), (i+1,j+1)` with centroid
    /// `((3i+2)/3n, (3j+2)/3n)`: `2(n-j)-1` points in row `j`, the first `2n-1` being the
    /// zigzag along the edge `v = 0`.
    TriangleDual = 3,
    /// The scaling relation's pieces for tensor-product (quad) schemes, from which a reader
    /// expands the [`PointSet::Primal`] and [`PointSet::Dual`] stencils (docs/table-format.md,
    /// "Compact quad tables"). This one: the regular curve basis `phi(t/n - p)` at `t = 0..=n`
    /// for the four control points `p = -1, 0, 1, 2` of one axis (`n + 1` rows of width 4);
    /// kind [`StencilKind::Position`] holds the values, [`StencilKind::DerivativeU`] the
    /// derivatives in `t/n`. Patch fields 0 (not a patch's section).
    CurveBasis = 4,
    /// One row at `n = 0`: the patch's stencil at its corner vertex, `(0, 0)`: the limit
    /// position mask (kind position) or the tangent masks (d/du, d/dv).
    VertexMask = 5,
    /// The patch's local subdivision matrix `A` at `n = 0`: `K x K`, row `i` the level-1
    /// layout point `i` from the level-0 layout points (`P' = A P`).
    Subdivision = 6,
    /// The patch's three regular sub-patch matrices `R_0, R_1, R_2` at `n = 0`, stacked:
    /// `48 x K`, sub-patches `[1/2,1]x[0,1/2]`, `[1/2,1]^2`, `[0,1/2]x[1/2,1]`, each 16 rows
    /// `(p, q)`, `p, q in -1..=2`, `q` outer.
    SubPatches = 7,
    /// Compact Loop tables (docs/table-format.md, "Compact Loop tables"): the regular basis
    /// (the quartic box spline `psi`, kind position, or its derivative along `u` or `v`) on the
    /// degree-4 lattice, `psi(k_1/4, k_2/4)` for `|k_1|, |k_2| <= h`, `k_2` outer: `width = 2h + 1`
    /// rows of `width` weights, `n = 4` (the lattice's denominator), patch fields 0. Its values
    /// are the quartic (derivatives: cubic) pieces' interpolation data.
    LoopBasis = 8,
    /// A compact Loop table's sub-triangle matrices `R_0, R_1, R_2` of one patch at `n = 0`,
    /// stacked: `36 x K`, sub-triangles next to `E_0`, the middle one, next to `E_1`
    /// (`schemes::triangle_local::SUB_TRIANGLES`), each 12 rows, one per level-1 lattice point
    /// of `schemes::triangle_local::sub_triangle_points` (sorted), the level-0 weights of that
    /// point.
    SubTriangles = 9,
    /// A rate `n` that a compact Loop table covers: no rows (`width` 0), kind position, patch
    /// fields 0. The expanded grids are the rates listed by these sections, so that the index
    /// alone says what the table covers.
    TriangleRate = 10,
    /// Compact region tables (butterfly, √3; docs/table-format.md, "Compact region tables"):
    /// the regular basis on the grid `1/3n` of rate `n` (the key's `n`), by its canonical
    /// values (`schemes::lattice_symmetry`): kind position, `psi` at the wedge points; kind
    /// d/du, `psi_1` at the quarter points; one row of `width` values, patch fields 0. The
    /// reader knows the points' count from the scheme's support and checks it.
    RegionBasis = 11,
    /// A compact region table's tile rows of one region (`faces` the valence, `sector` the
    /// region): `n` rows (the key's `n` is the row count: the region's regular points, in
    /// `schemes::cone_regions::ConeRegion::regular_points` order) of `width` weights (the
    /// region's layout), the level-0 weights of each regular point.
    RegionRows = 12,
}

impl PointSet {
    /// Number of points of a grid at rate `n`; `u64::MAX` where that does not fit (a primal
    /// grid at `n = u32::MAX`, a rate a file may declare: no table holds it). For the scaling
    /// relation's pieces, see [`PointSet::rows`].
    pub fn count(self, n: u32) -> u64 {
        self.rows(n, 0)
    }

    /// Number of rows of a section of this point set at rate `n` with `width` weights a row:
    /// the grid's points, `n + 1` curve-basis points, one vertex mask, `K = width` rows of `A`,
    /// the 48 rows of the sub-patch matrices, the 36 of the sub-triangle matrices, a square
    /// window of the Loop basis (`width` rows), none for a rate marker, one row of a region
    /// basis, `n` tile rows of a region.
    pub fn rows(self, n: u32, width: u32) -> u64 {
        let n = u128::from(n);
        let count = match self {
            PointSet::Primal => (n + 1) * (n + 1),
            PointSet::Dual | PointSet::TriangleDual => n * n,
            PointSet::TrianglePrimal => (n + 1) * (n + 2) / 2,
            PointSet::CurveBasis => n + 1,
            PointSet::VertexMask => 1,
            PointSet::Subdivision => u128::from(width),
            PointSet::SubPatches => 48,
            PointSet::LoopBasis => u128::from(width),
            PointSet::SubTriangles => 36,
            PointSet::TriangleRate => 0,
            PointSet::RegionBasis => 1,
            PointSet::RegionRows => n,
        };
        u64::try_from(count).unwrap_or(u64::MAX)
    }

    /// Whether the point set belongs to triangle-scheme tables only.
    pub fn is_triangle(self) -> bool {
        matches!(
            self,
            PointSet::TrianglePrimal
                | PointSet::TriangleDual
                | PointSet::LoopBasis
                | PointSet::SubTriangles
                | PointSet::TriangleRate
                | PointSet::RegionBasis
                | PointSet::RegionRows
        )
    }

    /// Whether the point set belongs to quad-scheme tables only. [`PointSet::VertexMask`] and
    /// [`PointSet::Subdivision`] are neither: both families' compact tables store them.
    pub fn is_quad(self) -> bool {
        matches!(
            self,
            PointSet::Primal | PointSet::Dual | PointSet::CurveBasis | PointSet::SubPatches
        )
    }

    /// Whether the point set may appear in a table of `scheme` (triangle point sets in
    /// triangle-scheme tables, quad ones in quad-scheme tables, the shared pieces in both).
    pub fn belongs_to(self, scheme: SchemeId) -> bool {
        if scheme.is_triangle() {
            !self.is_quad()
        } else {
            !self.is_triangle()
        }
    }

    /// Whether the section holds grid stencils (rather than the scaling relation's pieces).
    pub fn is_grid(self) -> bool {
        (self as u8) <= PointSet::TriangleDual as u8
    }

    fn from_u8(v: u8) -> Option<Self> {
        [
            PointSet::Primal,
            PointSet::Dual,
            PointSet::TrianglePrimal,
            PointSet::TriangleDual,
            PointSet::CurveBasis,
            PointSet::VertexMask,
            PointSet::Subdivision,
            PointSet::SubPatches,
            PointSet::LoopBasis,
            PointSet::SubTriangles,
            PointSet::TriangleRate,
            PointSet::RegionBasis,
            PointSet::RegionRows,
        ]
        .into_iter()
        .find(|p| *p as u8 == v)
    }
}

/// The infinitely sharp feature a patch is made for (index entry byte 3). Sharp features are
/// stationary: a patch at one refines into itself, so it has exact stencils like a smooth one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Feature {
    /// None: a smooth interior vertex or a boundary vertex (with its boundary rules).
    None = 0,
    /// A dart: an interior vertex with exactly one infinitely sharp edge, sector 0's `+a` axis
    /// (`V-E_1`), the crease continuing straight out along it
    /// (`schemes::local_matrices::Neighbourhood::dart`). Interior keys only.
    Dart = 1,
}

impl Feature {
    /// The feature of byte value `v`, if the format defines it.
    pub fn from_u8(v: u8) -> Option<Self> {
        [Feature::None, Feature::Dart]
            .into_iter()
            .find(|f| *f as u8 == v)
    }
}

/// Identifies one section: one kind of stencil on one grid of one patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SectionKey {
    /// Position or derivative.
    pub kind: StencilKind,
    /// Primal or dual grid.
    pub points: PointSet,
    /// Whether the patch's corner vertex is a boundary vertex.
    pub boundary: bool,
    /// The sharp feature at the patch's corner vertex ([`Feature::Dart`] only with
    /// `boundary == false`).
    pub feature: Feature,
    /// The vertex's valence (interior) or number of faces (boundary).
    pub faces: u32,
    /// Which of a boundary vertex's patches (0 for interior vertices); for the butterfly, which
    /// of an interior vertex's regions (`schemes::butterfly_regions`).
    pub sector: u32,
    /// Grid rate.
    pub n: u32,
}

impl fmt::Display for SectionKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.kind {
            StencilKind::Position => "positions",
            StencilKind::DerivativeU => "d/du",
            StencilKind::DerivativeV => "d/dv",
        };
        let grid = match self.points {
            PointSet::Primal => "primal",
            PointSet::Dual => "dual",
            PointSet::TrianglePrimal => "triangle primal",
            PointSet::TriangleDual => "triangle dual",
            PointSet::CurveBasis => {
                return write!(f, "{kind} of the regular curve basis, n = {}", self.n);
            }
            PointSet::LoopBasis => {
                return write!(f, "{kind} of the Loop basis on the lattice 1/{}", self.n);
            }
            PointSet::TriangleRate => return write!(f, "rate marker n = {}", self.n),
            PointSet::RegionBasis => {
                return write!(
                    f,
                    "{kind} of the regular basis on the grid 1/{}",
                    u64::from(self.n) * 3
                );
            }
            PointSet::RegionRows => {
                return write!(
                    f,
                    "tile rows of region {} of valence {}",
                    self.sector, self.faces
                );
            }
            PointSet::VertexMask => "vertex mask",
            PointSet::Subdivision => "subdivision matrix",
            PointSet::SubPatches => "sub-patch matrices",
            PointSet::SubTriangles => "sub-triangle matrices",
        };
        if !self.points.is_grid() {
            let what = if self.points == PointSet::VertexMask {
                format!("{kind} {grid}")
            } else {
                grid.to_owned()
            };
            return if self.boundary {
                write!(
                    f,
                    "{what} of the boundary vertex with {} faces, sector {}",
                    self.faces, self.sector
                )
            } else if self.feature == Feature::Dart {
                write!(
                    f,
                    "{what} of the dart of valence {}, sector {}",
                    self.faces, self.sector
                )
            } else {
                write!(f, "{what} of valence {}", self.faces)
            };
        }
        if self.boundary {
            write!(
                f,
                "{kind} on the {grid} grid, n = {}, boundary vertex with {} faces, sector {}",
                self.n, self.faces, self.sector
            )
        } else if self.feature == Feature::Dart {
            write!(
                f,
                "{kind} on the {grid} grid, n = {}, dart of valence {}, sector {}",
                self.n, self.faces, self.sector
            )
        } else if self.sector != 0 {
            write!(
                f,
                "{kind} on the {grid} grid, n = {}, valence {}, region {}",
                self.n, self.faces, self.sector
            )
        } else {
            write!(
                f,
                "{kind} on the {grid} grid, n = {}, valence {}",
                self.n, self.faces
            )
        }
    }
}

/// Table-wide metadata.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableMeta {
    /// The scheme.
    pub scheme: SchemeId,
    /// Stored precision.
    pub precision: Precision,
    /// Boundary mode of the boundary sections: a one-face boundary vertex is a pinned corner
    /// (OpenSubdiv "edge and corner") rather than smooth ("edge only").
    pub corners: bool,
}

/// One index entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SectionEntry {
    /// What the section holds.
    pub key: SectionKey,
    /// Rows: grid points.
    pub points: u32,
    /// Weights per point (the patch's control-point count).
    pub width: u32,
    /// Byte offset from the start of the file.
    pub offset: u64,
    /// Byte length.
    pub length: u64,
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// Write a table. Each section is `(key, width, weights)` with `weights.len()` equal to
/// `points(key) * width`, point-major (the `width` weights of a point are contiguous). Sections
/// are written in key order, so the output does not depend on the input order.
pub fn encode(
    meta: TableMeta,
    sections: &[(SectionKey, u32, Vec<f64>)],
) -> Result<Vec<u8>, TableError> {
    let mut sorted: Vec<&(SectionKey, u32, Vec<f64>)> = sections.iter().collect();
    sorted.sort_by_key(|(key, _, _)| *key);
    for pair in sorted.windows(2) {
        if pair[0].0 == pair[1].0 {
            return Err(TableError::DuplicateSection { key: pair[0].0 });
        }
    }
    if let Some((key, _, _)) = sorted
        .iter()
        .find(|(key, _, _)| key.boundary && key.feature != Feature::None)
    {
        return Err(TableError::Encode(format!(
            "{key}: a boundary vertex has no sharp-feature patch (a dart is interior)"
        )));
    }
    if let Some((key, _, _)) = sorted
        .iter()
        .find(|(key, _, _)| !key.points.belongs_to(meta.scheme))
    {
        return Err(TableError::WrongPointSet {
            key: *key,
            scheme: meta.scheme.name(),
        });
    }
    let bytes_per = meta.precision as u64;
    let index_offset = HEADER_SIZE as u64;
    let mut offset = align_up(index_offset + (ENTRY_SIZE * sorted.len()) as u64);
    let mut entries = Vec::with_capacity(sorted.len());
    for (key, width, weights) in &sorted {
        let points = key.points.rows(key.n, *width);
        if weights.len() as u64 != points.saturating_mul(u64::from(*width)) {
            return Err(TableError::Encode(format!(
                "{key}: {} weights for {points} points x {width}",
                weights.len()
            )));
        }
        let length = weights.len() as u64 * bytes_per;
        entries.push(SectionEntry {
            key: *key,
            points: u32::try_from(points)
                .map_err(|_| TableError::Encode(format!("{key}: too many points")))?,
            width: *width,
            offset,
            length,
        });
        offset = align_up(offset + length);
    }
    let file_size = offset;
    let mut out = Vec::with_capacity(file_size as usize);
    out.extend_from_slice(&MAGIC);
    put_u32(&mut out, VERSION);
    put_u32(&mut out, ENDIAN_MARK);
    put_u32(&mut out, HEADER_SIZE as u32);
    put_u32(&mut out, sorted.len() as u32);
    put_u64(&mut out, index_offset);
    put_u64(&mut out, file_size);
    put_u64(&mut out, 0); // checksum, filled in below
    put_u32(&mut out, meta.precision as u32);
    put_u32(&mut out, meta.scheme as u32);
    put_u32(&mut out, u32::from(meta.corners));
    put_u32(&mut out, 0); // reserved
    debug_assert_eq!(out.len(), HEADER_SIZE);
    for e in &entries {
        out.extend_from_slice(&[
            e.key.kind as u8,
            e.key.points as u8,
            u8::from(e.key.boundary),
            e.key.feature as u8,
        ]);
        put_u32(&mut out, e.key.faces);
        put_u32(&mut out, e.key.sector);
        put_u32(&mut out, e.key.n);
        put_u32(&mut out, e.points);
        put_u32(&mut out, e.width);
        put_u64(&mut out, e.offset);
        put_u64(&mut out, e.length);
    }
    for (e, (_, _, weights)) in entries.iter().zip(&sorted) {
        out.resize(e.offset as usize, 0);
        for &w in weights {
            match meta.precision {
                Precision::F32 => out.extend_from_slice(&(w as f32).to_le_bytes()),
                Precision::F64 => out.extend_from_slice(&w.to_le_bytes()),
            }
        }
    }
    out.resize(file_size as usize, 0);
    // Last: the checksum covers every other byte, header and index included.
    let sum = checksum(&out);
    out[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
    Ok(out)
}

fn align_up(x: u64) -> u64 {
    x.div_ceil(SECTION_ALIGN as u64) * SECTION_ALIGN as u64
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    let mut b = [0u8; 4];
    b.copy_from_slice(&bytes[at..at + 4]);
    u32::from_le_bytes(b)
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[at..at + 8]);
    u64::from_le_bytes(b)
}

/// A validated table over borrowed bytes.
#[derive(Clone, Debug)]
pub struct Table<'a> {
    bytes: &'a [u8],
    index: TableIndex,
}

impl<'a> std::ops::Deref for Table<'a> {
    type Target = TableIndex;

    fn deref(&self) -> &TableIndex {
        &self.index
    }
}

impl<'a> Table<'a> {
    /// Validate `bytes` as a table. `bytes` must be 8-byte aligned (see [`AlignedBytes`]) so
    /// that weights can be handed out without copying.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, TableError> {
        Ok(Table {
            bytes,
            index: TableIndex::parse(bytes)?,
        })
    }

    /// The f32 weights of a section: `points x width`, point-major.
    pub fn weights_f32(&self, key: &SectionKey) -> Result<&'a [f32], TableError> {
        self.index.weights_f32(self.bytes, key)
    }

    /// The f64 weights of a section: `points x width`, point-major.
    pub fn weights_f64(&self, key: &SectionKey) -> Result<&'a [f64], TableError> {
        self.index.weights_f64(self.bytes, key)
    }

    /// Total size in bytes.
    pub fn size(&self) -> usize {
        self.bytes.len()
    }

    /// The owned index, to keep beside bytes that outlive this borrow.
    pub fn into_index(self) -> TableIndex {
        self.index
    }
}

/// Everything a validated table says about itself, without its bytes: keep it beside the
/// bytes it was parsed from and pass them back in to read weights.
#[derive(Clone, Debug)]
pub struct TableIndex {
    /// Table-wide metadata.
    pub meta: TableMeta,
    /// The format version read.
    pub version: u32,
    /// The stored checksum (verified).
    pub checksum: u64,
    /// The section index, in file order.
    pub entries: Vec<SectionEntry>,
    lookup: BTreeMap<SectionKey, usize>,
    len: usize,
}

impl TableIndex {
    /// Validate `bytes` as a table (see [`Table::parse`]).
    pub fn parse(bytes: &[u8]) -> Result<Self, TableError> {
        let len = bytes.len() as u64;
        check_header(bytes, len)?;
        let version = u32_at(bytes, 8);
        let count = u32_at(bytes, 20) as u64;
        let index_offset = u64_at(bytes, 24);
        // Before any other field is interpreted: the checksum covers the header and index
        // too, so a changed corners flag, count or scheme id is refused here.
        let stored = u64_at(bytes, CHECKSUM_OFFSET);
        let computed = checksum(bytes);
        if computed != stored {
            return Err(TableError::Checksum { stored, computed });
        }
        let precision = match u32_at(bytes, 48) {
            4 => Precision::F32,
            8 => Precision::F64,
            p => {
                return Err(TableError::BadField {
                    field: "precision",
                    value: u64::from(p),
                })
            }
        };
        let scheme_raw = u32_at(bytes, 52);
        let scheme = SchemeId::from_u32(scheme_raw).ok_or(TableError::BadField {
            field: "scheme",
            value: u64::from(scheme_raw),
        })?;
        let corners = match u32_at(bytes, 56) {
            0 => false,
            1 => true,
            c => {
                return Err(TableError::BadField {
                    field: "boundary mode",
                    value: u64::from(c),
                })
            }
        };
        let index_end = count
            .checked_mul(ENTRY_SIZE as u64)
            .and_then(|x| x.checked_add(index_offset))
            .unwrap_or(u64::MAX);
        if index_offset < HEADER_SIZE as u64 || index_end > len {
            return Err(TableError::Truncated {
                what: format!("the index of {count} sections"),
                needed: index_end,
                len,
            });
        }
        if bytes.as_ptr() as usize % 8 != 0 {
            return Err(TableError::UnalignedBuffer);
        }
        let mut entries = Vec::with_capacity(count as usize);
        let mut lookup = BTreeMap::new();
        for index in 0..count as usize {
            let at = index_offset as usize + index * ENTRY_SIZE;
            let e = &bytes[at..at + ENTRY_SIZE];
            let kind = match e[0] {
                0 => StencilKind::Position,
                1 => StencilKind::DerivativeU,
                2 => StencilKind::DerivativeV,
                k => {
                    return Err(TableError::BadField {
                        field: "section kind",
                        value: u64::from(k),
                    })
                }
            };
            let points = PointSet::from_u8(e[1]).ok_or(TableError::BadField {
                field: "section point set",
                value: u64::from(e[1]),
            })?;
            let boundary = match e[2] {
                0 => false,
                1 => true,
                b => {
                    return Err(TableError::BadField {
                        field: "section boundary flag",
                        value: u64::from(b),
                    })
                }
            };
            // A dart is an interior vertex; a boundary vertex's feature is its boundary.
            let feature = match Feature::from_u8(e[3]) {
                Some(f) if !(boundary && f != Feature::None) => f,
                _ => {
                    return Err(TableError::BadField {
                        field: "section feature",
                        value: u64::from(e[3]),
                    })
                }
            };
            let key = SectionKey {
                kind,
                points,
                boundary,
                feature,
                faces: u32_at(e, 4),
                sector: u32_at(e, 8),
                n: u32_at(e, 12),
            };
            if !points.belongs_to(scheme) {
                return Err(TableError::WrongPointSet {
                    key,
                    scheme: scheme.name(),
                });
            }
            let entry = SectionEntry {
                key,
                points: u32_at(e, 16),
                width: u32_at(e, 20),
                offset: u64_at(e, 24),
                length: u64_at(e, 32),
            };
            let end = entry.offset.saturating_add(entry.length);
            if end > len {
                return Err(TableError::SectionOutOfBounds {
                    index,
                    key,
                    offset: entry.offset,
                    end,
                    len,
                });
            }
            if entry.offset % precision as u64 != 0 || entry.offset < index_end {
                return Err(TableError::Misaligned {
                    index,
                    key,
                    offset: entry.offset,
                });
            }
            // Saturating: the fields are the file's, and a length is at most the file's.
            let expected = u64::from(entry.points)
                .saturating_mul(u64::from(entry.width))
                .saturating_mul(precision as u64);
            if entry.length != expected
                || u64::from(entry.points) != key.points.rows(key.n, entry.width)
            {
                return Err(TableError::WrongShape {
                    index,
                    key,
                    length: entry.length,
                    points: entry.points,
                    width: entry.width,
                    precision: precision as u32,
                    expected,
                });
            }
            if lookup.insert(key, index).is_some() {
                return Err(TableError::DuplicateSection { key });
            }
            entries.push(entry);
        }
        Ok(TableIndex {
            meta: TableMeta {
                scheme,
                precision,
                corners,
            },
            version,
            checksum: stored,
            entries,
            lookup,
            len: bytes.len(),
        })
    }

    /// The index entry of `key`, if the table has it (no error built: [`Self::entry`]'s
    /// message summarizes the whole index).
    pub fn get(&self, key: &SectionKey) -> Option<&SectionEntry> {
        self.lookup.get(key).map(|&i| &self.entries[i])
    }

    /// The index entry of `key`, or which sections the table does have.
    pub fn entry(&self, key: &SectionKey) -> Result<&SectionEntry, TableError> {
        self.lookup
            .get(key)
            .map(|&i| &self.entries[i])
            .ok_or_else(|| TableError::MissingSection {
                key: *key,
                coverage: self.coverage(),
            })
    }

    /// Every weight of every section of `bytes` (the bytes this index was parsed from) is
    /// finite. The checksum only says the bytes are the ones written: a table written with a
    /// NaN or an infinity passes it, and would put NaN into every point it touches. A full
    /// scan (of the order of the checksum's time), so for tables read from files; the
    /// embedded ones come from the build's own generator.
    pub fn check_finite(&self, bytes: &[u8]) -> Result<(), TableError> {
        for entry in &self.entries {
            let bad = match self.meta.precision {
                Precision::F32 => self
                    .weights_f32(bytes, &entry.key)?
                    .iter()
                    .position(|w| !w.is_finite()),
                Precision::F64 => self
                    .weights_f64(bytes, &entry.key)?
                    .iter()
                    .position(|w| !w.is_finite()),
            };
            if let Some(at) = bad {
                return Err(TableError::NonFinite {
                    key: entry.key,
                    point: at / entry.width.max(1) as usize,
                });
            }
        }
        Ok(())
    }

    /// The f32 weights of a section of `bytes` (the bytes this index was parsed from).
    pub fn weights_f32<'b>(
        &self,
        bytes: &'b [u8],
        key: &SectionKey,
    ) -> Result<&'b [f32], TableError> {
        self.weights(bytes, key, Precision::F32)
    }

    /// The f64 weights of a section of `bytes` (the bytes this index was parsed from).
    pub fn weights_f64<'b>(
        &self,
        bytes: &'b [u8],
        key: &SectionKey,
    ) -> Result<&'b [f64], TableError> {
        self.weights(bytes, key, Precision::F64)
    }

    fn weights<'b, T: bytemuck::Pod>(
        &self,
        bytes: &'b [u8],
        key: &SectionKey,
        asked: Precision,
    ) -> Result<&'b [T], TableError> {
        if self.meta.precision != asked {
            return Err(TableError::PrecisionMismatch {
                stored: self.meta.precision,
                asked,
            });
        }
        bytemuck::try_cast_slice(self.section_bytes(bytes, key)?)
            .map_err(|_| TableError::UnalignedBuffer)
    }

    fn section_bytes<'b>(&self, bytes: &'b [u8], key: &SectionKey) -> Result<&'b [u8], TableError> {
        let e = *self.entry(key)?;
        if bytes.len() != self.len {
            return Err(TableError::Encode(
                "weights asked of bytes other than the parsed table's".to_owned(),
            ));
        }
        Ok(&bytes[e.offset as usize..(e.offset + e.length) as usize])
    }

    /// A one-line summary of what the table covers: valences, boundary face counts, rates.
    pub fn coverage(&self) -> String {
        let mut valences = std::collections::BTreeSet::new();
        let mut darts = std::collections::BTreeSet::new();
        let mut boundary = std::collections::BTreeSet::new();
        let mut rates = std::collections::BTreeSet::new();
        for e in &self.entries {
            // The bases and the rate markers belong to no patch; the pieces of a patch to no
            // rate.
            let patchless = matches!(
                e.key.points,
                PointSet::CurveBasis
                    | PointSet::LoopBasis
                    | PointSet::TriangleRate
                    | PointSet::RegionBasis
            );
            if !patchless {
                if e.key.boundary {
                    boundary.insert(e.key.faces);
                } else if e.key.feature == Feature::Dart {
                    darts.insert(e.key.faces);
                } else {
                    valences.insert(e.key.faces);
                }
            }
            if e.key.points.is_grid()
                || matches!(e.key.points, PointSet::CurveBasis | PointSet::TriangleRate)
            {
                rates.insert(e.key.n);
            }
        }
        let interior = if valences.is_empty() {
            "no interior vertices".to_owned()
        } else {
            format!("interior valences {}", ranges(&valences))
        };
        let boundary = if boundary.is_empty() {
            "no boundary vertices".to_owned()
        } else {
            format!("boundary vertices with {} faces", ranges(&boundary))
        };
        // Darts are named only where a table has them (tables before them read as before).
        let darts = if darts.is_empty() {
            String::new()
        } else {
            format!(", darts of valences {}", ranges(&darts))
        };
        format!("{interior}{darts}, {boundary}, n = {}", ranges(&rates))
    }
}

/// `1..=6, 8` style summary of a set of integers.
fn ranges(set: &std::collections::BTreeSet<u32>) -> String {
    let mut parts = Vec::new();
    let mut iter = set.iter().copied().peekable();
    while let Some(start) = iter.next() {
        let mut end = start;
        // `u32::MAX` (a field a file may hold) has no successor: checked, not wrapped.
        while end
            .checked_add(1)
            .is_some_and(|next| iter.peek() == Some(&next))
        {
            end += 1;
            iter.next();
        }
        parts.push(if end > start {
            format!("{start}..={end}")
        } else {
            start.to_string()
        });
    }
    parts.join(", ")
}

/// Check a table's fixed-size header: `head` is the file's first [`HEADER_SIZE`] bytes (or all
/// of them, if it has fewer) and `len` the file's length. Checks the magic, the version, the
/// endianness mark, the header size, and the file size the header declares against `len` and
/// [`MAX_FILE_SIZE`]. A reader calls it before reading the rest, so that a file of absurd size
/// (a 100 GB sparse file given as a table) is refused without being read.
pub fn check_header(head: &[u8], len: u64) -> Result<(), TableError> {
    if head.len() < MAGIC.len() || head[..MAGIC.len()] != MAGIC {
        return Err(TableError::BadMagic {
            found: head[..head.len().min(MAGIC.len())].to_vec(),
        });
    }
    if head.len() < HEADER_SIZE {
        return Err(TableError::Truncated {
            what: "the header".to_owned(),
            needed: HEADER_SIZE as u64,
            len,
        });
    }
    let version = u32_at(head, 8);
    if version != VERSION {
        return Err(TableError::UnsupportedVersion {
            found: version,
            supported: VERSION,
        });
    }
    let mark = u32_at(head, 12);
    if mark != ENDIAN_MARK {
        return Err(TableError::Endianness { found: mark });
    }
    let header_size = u32_at(head, 16);
    if header_size as usize != HEADER_SIZE {
        return Err(TableError::BadField {
            field: "header size",
            value: u64::from(header_size),
        });
    }
    let file_size = u64_at(head, 32);
    if file_size > MAX_FILE_SIZE {
        return Err(TableError::TooLarge {
            declared: file_size,
        });
    }
    if file_size > len {
        return Err(TableError::Truncated {
            what: "the file size in the header".to_owned(),
            needed: file_size,
            len,
        });
    }
    if file_size < len {
        return Err(TableError::BadField {
            field: "file size",
            value: file_size,
        });
    }
    Ok(())
}

/// An owned, 8-byte-aligned byte buffer, so that a table read from a file (one copy) can be
/// parsed and viewed without further copies.
#[derive(Clone, Debug, Default)]
pub struct AlignedBytes {
    words: Vec<u64>,
    len: usize,
}

impl AlignedBytes {
    /// Copy `bytes` into an aligned buffer.
    pub fn from_slice(bytes: &[u8]) -> Self {
        let mut words = vec![0u64; bytes.len().div_ceil(8)];
        bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..bytes.len()].copy_from_slice(bytes);
        AlignedBytes {
            words,
            len: bytes.len(),
        }
    }

    /// Read a file straight into an aligned buffer.
    pub fn read(path: &std::path::Path) -> std::io::Result<Self> {
        use std::io::Read;
        let mut file = std::fs::File::open(path)?;
        let len = usize::try_from(file.metadata()?.len()).unwrap_or(usize::MAX);
        let mut words = vec![0u64; len.div_ceil(8)];
        file.read_exact(&mut bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..len])?;
        Ok(AlignedBytes { words, len })
    }

    /// Read exactly `len` bytes from `reader` into an aligned buffer (a table reader reads the
    /// header first, checks it with [`check_header`], then passes the header chained with the
    /// rest of the file).
    pub fn read_from(mut reader: impl std::io::Read, len: usize) -> std::io::Result<Self> {
        let mut words = vec![0u64; len.div_ceil(8)];
        reader.read_exact(&mut bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..len])?;
        Ok(AlignedBytes { words, len })
    }

    /// The bytes.
    pub fn as_bytes(&self) -> &[u8] {
        &bytemuck::cast_slice::<u64, u8>(&self.words)[..self.len]
    }
}

#[cfg(test)]
mod tests;
