//! Stencil tables through the runtime: the embedded default, files written by `stencilgen
//! tables`, and bad files.

use std::process::Command;

use num_rational::BigRational;
use schemes::QuadScheme;
use stencilgen::extraordinary_patch::Neighbourhood;
use stencilgen::regular_patch::StencilKind as Kind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::stencil_set::StencilSetSpec;
use stencilgen::substitution::Substitution;
use stencilgen::table::{build_table, TableSpec};
use subtess::stencil_table::StencilTable;
use subtess::RuntimeError;
use table_format::{PointSet, SectionKey, StencilKind};

fn key(
    kind: StencilKind,
    points: PointSet,
    boundary: bool,
    faces: u32,
    sector: u32,
    n: u32,
) -> SectionKey {
    SectionKey {
        kind,
        points,
        boundary,
        feature: table_format::Feature::None,
        faces,
        sector,
        n,
    }
}

/// Default-table weights agree with exact substitution stencils to f32 rounding (1e-6 relative
/// to the largest weight), at every dual point of a few sections, and sum to 1 / 0.
#[test]
#[cfg(feature = "catmull-clark")]
fn default_table_weights_match_exact_stencils() {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
    let cases = [
        (false, 5, 0, 7),
        (false, 3, 0, 24),
        (true, 3, 1, 5),
        (true, 1, 0, 4),
    ];
    for (boundary, faces, sector, n) in cases {
        let nb = if boundary {
            Neighbourhood::boundary(faces, schemes::BoundaryMode::EdgeOnly)
        } else {
            Neighbourhood::interior(faces)
        };
        let mut exact = Substitution::<BigRational>::new(&cc, nb, sector).expect("substitution");
        for (kind, exact_kind) in [
            (StencilKind::Position, Kind::Position),
            (StencilKind::DerivativeU, Kind::DerivativeU),
        ] {
            let weights = table
                .weights(&key(kind, PointSet::Dual, boundary, faces, sector, n))
                .expect("section");
            let k = weights.len() / (n * n) as usize;
            for j in 0..n {
                for i in 0..n {
                    let row = &weights[((j * n + i) as usize) * k..][..k];
                    let d = 2 * i64::from(n);
                    let u = BigRational::new((2 * i64::from(i) + 1).into(), d.into());
                    let v = BigRational::new((2 * i64::from(j) + 1).into(), d.into());
                    let expected = exact.stencil(&u, &v, exact_kind).expect("stencil");
                    let scale = expected
                        .iter()
                        .map(|w| rational_to_f64(w).abs())
                        .fold(0.0, f64::max);
                    for (w, e) in row.iter().zip(&expected) {
                        let err = (f64::from(*w) - rational_to_f64(e)).abs();
                        assert!(
                            err <= 1e-6 * scale,
                            "{boundary} {faces} {sector} n = {n}: {w} vs {e}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
#[cfg(feature = "catmull-clark")]
fn a_missing_valence_names_what_the_table_has() {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let e = table
        .weights(&key(StencilKind::Position, PointSet::Dual, false, 9, 0, 4))
        .expect_err("no valence 9");
    let text = e.to_string();
    assert!(
        text.contains("valence 9") && text.contains("interior valences 3..=8"),
        "{text}"
    );
    assert!(text.contains("stencilgen tables"), "{text}");
}

/// A folder of one test's own for its files, removed with them when the test ends, passed or
/// not (tests run side by side: one folder each, so none removes another's).
struct Scratch(std::path::PathBuf);

impl Scratch {
    fn new(test: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("subtess-tests-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        Scratch(dir)
    }

    fn path(&self, name: &str) -> std::path::PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A small table written by the generator: `subtess tables info` and the loader read it back.
fn small_table() -> Vec<u8> {
    let mut spec = TableSpec::default_catmull_clark().expect("default spec");
    spec.set = StencilSetSpec {
        valences: vec![3, 4],
        darts: Vec::new(),
        boundary_faces: vec![2],
        boundary_mode: schemes::BoundaryMode::EdgeOnly,
        rates: vec![1, 2, 3],
    };
    build_table(&spec, &|_, _| {}).expect("small table")
}

#[test]
fn generated_files_round_trip_through_subtess() {
    let scratch = Scratch::new("round-trip");
    let path = scratch.path("small.subtess");
    std::fs::write(&path, small_table()).expect("write");
    let table = StencilTable::read(&path).expect("valid table");
    // Compact: 4 patches (valences 3, 4; two sectors of the 2-face boundary vertex) x 5 pieces,
    // 3 rates x 2 curve-basis sections.
    assert_eq!(table.index().entries.len(), 4 * 5 + 3 * 2);
    assert!(table.is_compact());
    let info = Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(["tables", "info"])
        .arg(&path)
        .output()
        .expect("subtess runs");
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success());
    assert!(
        text.contains("interior valences 3..=4, boundary vertices with 2 faces, n = 1..=3"),
        "{text}"
    );
}

/// Bad files: each a clear error from `subtess tables info`, never a panic.
#[test]
fn bad_files_are_clear_errors() {
    let scratch = Scratch::new("bad-files");
    let good = small_table();
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 1;
    // A version this build does not read: the next one.
    let unknown = table_format::VERSION + 1;
    let mut version = good.to_vec();
    version[8..12].copy_from_slice(&unknown.to_le_bytes());
    // A version-2 file (checksum over the bytes after the header only): refused naming its
    // version and the command that regenerates it.
    let mut old = good.to_vec();
    old[8..12].copy_from_slice(&2u32.to_le_bytes());
    let cases: [(&str, Vec<u8>, &str); 6] = [
        (
            "magic.subtess",
            b"PK\x03\x04 not a table".to_vec(),
            "not a subtess stencil table",
        ),
        (
            "version.subtess",
            version,
            &format!("format version {unknown} is not supported"),
        ),
        (
            "v2.subtess",
            old.clone(),
            "format version 2 is not supported",
        ),
        (
            "v2-command.subtess",
            old,
            "regenerate it with this build's `stencilgen tables",
        ),
        ("truncated.subtess", good[..1000].to_vec(), "truncated"),
        ("flipped.subtess", flipped, "checksum"),
    ];
    for (name, bytes, message) in cases {
        let path = scratch.path(name);
        std::fs::write(&path, bytes).expect("write");
        let out = Command::new(env!("CARGO_BIN_EXE_subtess"))
            .args(["tables", "info"])
            .arg(&path)
            .output()
            .expect("runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}");
        assert!(stderr.contains(message), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
    let missing = StencilTable::read(std::path::Path::new("/nonexistent/table.subtess"))
        .expect_err("no file");
    assert!(matches!(missing, RuntimeError::Io { .. }));
}
