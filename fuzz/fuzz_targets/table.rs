//! The stencil-table reader (`StencilTable::from_bytes`: header, index, checksum, every weight
//! finite), then a few sections' weights read back. The first byte chooses what the target
//! mends before reading the rest as a table, so that mutations get past the checks a random
//! change almost never passes: bit 0 writes the checksum (`table_format::checksum`: xxh3 of
//! every byte but its own, header included since format version 3) into the header, bit 1
//! writes the length as the declared file size (first, since the checksum covers it). A
//! compact table's grids (quad, Loop, butterfly or √3) are expanded too (`StencilTable::weights`
//! on grid keys), for up to two patches (regions) at its rates up to 8.

#![no_main]

use libfuzzer_sys::fuzz_target;
use subtess::StencilTable;
use table_format::{PointSet, Precision, SectionKey, StencilKind, CHECKSUM_OFFSET, HEADER_SIZE};

/// Where the header keeps the declared file size (docs/table-format.md).
const FILE_SIZE_AT: usize = 32;

fuzz_target!(|data: &[u8]| {
    let [mode, rest @ ..] = data else {
        return;
    };
    let mut bytes = rest.to_vec();
    if bytes.len() >= HEADER_SIZE {
        if mode & 2 != 0 {
            let len = bytes.len() as u64;
            bytes[FILE_SIZE_AT..FILE_SIZE_AT + 8].copy_from_slice(&len.to_le_bytes());
        }
        if mode & 1 != 0 {
            let sum = table_format::checksum(&bytes);
            bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
        }
    }
    let Ok(table) = StencilTable::from_bytes(&bytes) else {
        return;
    };
    let index = table.index();
    let _ = index.coverage();
    for entry in index.entries.iter().take(8) {
        let expected = u64::from(entry.points) * u64::from(entry.width);
        match index.meta.precision {
            Precision::F32 => {
                let weights = table
                    .weights(&entry.key)
                    .expect("an indexed f32 section reads");
                assert_eq!(weights.len() as u64, expected);
                assert!(weights.iter().all(|w| w.is_finite()));
            }
            Precision::F64 => {
                let weights = index
                    .weights_f64(table.bytes(), &entry.key)
                    .expect("an indexed f64 section reads");
                assert_eq!(weights.len() as u64, expected);
                assert!(weights.iter().all(|w| w.is_finite()));
            }
        }
    }
    if !table.is_compact() {
        return;
    }
    // Quad tables list their rates by curve-basis sections, compact triangle tables by rate
    // markers.
    let rates: Vec<u32> = index
        .entries
        .iter()
        .filter(|e| {
            matches!(e.key.points, PointSet::CurveBasis | PointSet::TriangleRate) && e.key.n <= 8
        })
        .map(|e| e.key.n)
        .collect();
    let grids = if index.meta.scheme.is_triangle() {
        [PointSet::TrianglePrimal, PointSet::TriangleDual]
    } else {
        [PointSet::Primal, PointSet::Dual]
    };
    // A quad or Loop patch is named by its subdivision matrix; a butterfly or √3 region by its
    // rows (whose `n` is a point count, replaced by the rate below).
    let regions = index
        .entries
        .iter()
        .any(|e| e.key.points == PointSet::RegionRows);
    let patch_piece = if regions {
        PointSet::RegionRows
    } else {
        PointSet::Subdivision
    };
    let patches = index
        .entries
        .iter()
        .filter(|e| e.key.points == patch_piece)
        .take(2);
    for patch in patches {
        for &n in &rates {
            for points in grids {
                let key = SectionKey {
                    kind: StencilKind::DerivativeU,
                    points,
                    n,
                    ..patch.key
                };
                // Loading checked every quad and Loop piece; a region's rows and a rate's basis
                // are checked against the region geometry when first expanded, so there a
                // mutated table may be refused here (an error, never a panic).
                let weights = match table.weights(&key) {
                    Ok(weights) => weights,
                    Err(_) if regions => continue,
                    Err(e) => panic!("a covered grid does not expand: {e}"),
                };
                assert_eq!(
                    weights.len() as u64,
                    points.count(n) * u64::from(patch.width)
                );
            }
        }
    }
});
