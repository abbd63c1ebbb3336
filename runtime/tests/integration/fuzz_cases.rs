//! Every input the fuzz targets in `fuzz/` found to crash, time out or run out of memory, kept
//! as a named regression test (`fuzz_case_NN`, in the order found; docs/reliability.md lists
//! them with their causes). Binary inputs are in `runtime/tests/fuzz_cases/`; for the table
//! target they are the bytes the reader got (the target's first byte applied: checksum and
//! declared size mended), found as format version 2 and moved to versions 3, 4 and 5 (the version
//! field and the checksum, which since version 3 covers the header, rewritten; nothing else) so
//! that they still reach the code they broke.

use subtess::StencilTable;

/// The bytes of a kept input.
fn input(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_cases")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A valid table (checksum and declared size right) with a section for `u32::MAX` faces:
/// `coverage()`, which every missing-section message and `tables info` print, overflowed
/// `u32` summing the face counts into ranges (`end + 1`). Now the table is read, and its
/// summary names the count.
#[test]
fn fuzz_case_01() {
    let table = StencilTable::from_bytes(&input("fuzz_case_01.subtess"))
        .expect("a valid table with an odd face count");
    let coverage = table.index().coverage();
    assert!(coverage.contains("4294967295"), "{coverage}");
}

/// A valid checksum over an index entry for triangle primal points at rate `n = u32::MAX`:
/// the point count `(n + 1)(n + 2) / 2` overflowed `u64` (`PointSet::count`), as could
/// `points x width x precision`. Both are now computed without wrapping, and the entry is
/// refused for its shape.
#[test]
fn fuzz_case_02() {
    match StencilTable::from_bytes(&input("fuzz_case_02.subtess")) {
        Err(subtess::RuntimeError::Table(table_format::TableError::WrongShape { key, .. })) => {
            assert_eq!(key.n, u32::MAX)
        }
        other => panic!("{:?}", other.map(|t| t.index().entries.len())),
    }
}
