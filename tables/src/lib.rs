//! The default stencil tables, embedded: the Catmull–Clark table, its small pinned-corner
//! companion, the Loop table, the butterfly table and the √3 table.
//!
//! The default Catmull–Clark table (interior valences 3..=8, darts of valences 3..=8, boundary
//! vertices with 1..=6 faces "edge only", n = 1..=24) is compact (0.68 MB: the scaling
//! relation's pieces, from which the runtime expands the grids), and so are the Loop table
//! (0.17 MB) and the butterfly and √3 tables (n = 1..=24: 3.4 MB and 2.7 MB, the regular basis
//! per rate and the region matrices). All are generated deterministically by `stencilgen` in this
//! crate's build script rather than kept in the repository and its history, and embedded with
//! `include_bytes!`, aligned for zero-copy reads.
//! `stencilgen tables ... -o FILE` writes the same bytes to a file, and `tests/regenerate.rs`
//! checks that a fresh generation is identical to what is embedded.
//!
//! # Cargo features
//!
//! One per scheme, all four on by default: `catmull-clark` (the Catmull–Clark table and its
//! pinned-corner companion), `loop`, `butterfly` and `sqrt3`. The build script generates, and
//! the crate embeds and exposes a function for, only the tables of the enabled features, so a
//! program that needs only Catmull–Clark links 0.7 MB of tables instead of 7.0 MB and its build
//! skips the triangle tables' generation, about 21 s (docs/benchmarks.md, "Per-scheme cargo
//! features"). `subtess` forwards the same four features.

/// `include_bytes!` gives 1-byte alignment; the table format hands out `&[f32]` views, so the
/// bytes are wrapped in a 64-byte-aligned static.
#[cfg(any(
    feature = "catmull-clark",
    feature = "loop",
    feature = "butterfly",
    feature = "sqrt3"
))]
#[repr(C, align(64))]
struct Aligned<T: ?Sized>(T);

#[cfg(feature = "catmull-clark")]
static CATMULL_CLARK: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(
    env!("OUT_DIR"),
    "/catmull-clark.subtess"
)));

#[cfg(feature = "catmull-clark")]
static CATMULL_CLARK_CORNERS: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(
    env!("OUT_DIR"),
    "/catmull-clark-corners.subtess"
)));

#[cfg(feature = "loop")]
static LOOP: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(env!("OUT_DIR"), "/loop.subtess")));

#[cfg(feature = "butterfly")]
static BUTTERFLY: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(
    env!("OUT_DIR"),
    "/butterfly.subtess"
)));

#[cfg(feature = "sqrt3")]
static SQRT3: &Aligned<[u8]> =
    &Aligned(*include_bytes!(concat!(env!("OUT_DIR"), "/sqrt3.subtess")));

/// The default Catmull–Clark table's bytes (64-byte aligned). Feature `catmull-clark`.
#[cfg(feature = "catmull-clark")]
pub fn default_catmull_clark() -> &'static [u8] {
    &CATMULL_CLARK.0
}

/// The pinned-corner companion table's bytes (64-byte aligned): the one-face boundary vertex in
/// "edge and corner" mode, n = 1..=24 (`stencilgen::table::TableSpec::default_corners`). Laid
/// over the default table for meshes with `interpolateboundary 1`. Feature `catmull-clark`.
#[cfg(feature = "catmull-clark")]
pub fn default_catmull_clark_corners() -> &'static [u8] {
    &CATMULL_CLARK_CORNERS.0
}

/// The default Loop table's bytes (64-byte aligned): interior valences 3..=12 (6 is the
/// regular patch), boundary vertices with 1..=6 triangles (every sector), n = 1..=24,
/// positions and both derivatives, compact: the scaling relation's pieces in f64 (the Loop
/// basis on the lattice `1/4`, the rate markers, per patch `A`, the sub-triangle matrices and
/// the vertex masks), from which the runtime expands the triangle primal and dual grids
/// (docs/table-format.md, "Compact Loop tables";
/// `stencilgen::triangle_table::TriangleTableSpec::default_loop`; 163 KiB, 32.6 MiB as grids).
/// Feature `loop`.
#[cfg(feature = "loop")]
pub fn default_loop() -> &'static [u8] {
    &LOOP.0
}

/// The default butterfly table's bytes (64-byte aligned): the nine regions of interior vertices
/// of valence 3..=8 (region 0 only at valence 6, the regular patch), n = 1..=24, positions and
/// both derivatives, compact: per rate the regular basis on `1/3n` by its canonical values, per
/// valence `A` and the masks at `V`, per region its tile rows, in f64, from which the runtime
/// expands the triangle primal and dual grids (docs/table-format.md, "Compact region tables";
/// `stencilgen::butterfly_table::ButterflyTableSpec::default_butterfly`; 3.2 MiB). Feature
/// `butterfly`.
#[cfg(feature = "butterfly")]
pub fn default_butterfly() -> &'static [u8] {
    &BUTTERFLY.0
}

/// The default √3 table's bytes (64-byte aligned): the nine regions of interior vertices of
/// valence 3..=8 (region 0 only at valence 6, the regular patch) of two √3 steps taken as one
/// ternary step, n = 1..=24, positions and both derivatives, compact as the butterfly's
/// (`stencilgen::sqrt3_table::default_sqrt3_table`; 2.6 MiB). Feature `sqrt3`.
#[cfg(feature = "sqrt3")]
pub fn default_sqrt3() -> &'static [u8] {
    &SQRT3.0
}

#[cfg(test)]
mod tests {
    /// Every embedded table (those of the enabled features), pushed feature by feature: nothing
    /// without any feature, one push with only `loop`, `butterfly` or `sqrt3`.
    #[allow(unused_mut, clippy::vec_init_then_push)]
    fn all() -> Vec<&'static [u8]> {
        let mut all = Vec::new();
        #[cfg(feature = "catmull-clark")]
        all.extend([
            super::default_catmull_clark(),
            super::default_catmull_clark_corners(),
        ]);
        #[cfg(feature = "loop")]
        all.push(super::default_loop());
        #[cfg(feature = "butterfly")]
        all.push(super::default_butterfly());
        #[cfg(feature = "sqrt3")]
        all.push(super::default_sqrt3());
        all
    }

    #[test]
    fn embedded_table_is_aligned_and_starts_with_the_magic() {
        for bytes in all() {
            assert_eq!(bytes.as_ptr() as usize % 64, 0);
            assert_eq!(&bytes[..8], b"SUBTESS\0");
        }
    }

    /// The runtime does not scan the embedded tables for NaN at load (files it does): the
    /// generator's output is checked here once.
    #[test]
    fn embedded_weights_are_finite() {
        for bytes in all() {
            let index = table_format::TableIndex::parse(bytes).expect("valid");
            index.check_finite(bytes).expect("finite");
        }
    }
}
