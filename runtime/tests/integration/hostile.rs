//! Hostile input (issue 20): inputs that used to panic, abort allocating or print zero
//! normals are refused with a message (or handled), never a crash. Each test names the
//! defect it guards.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use subtess::{Mesh, Rates, RuntimeError, Scheme, Surface};

fn subtess(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("subtess runs")
}

/// Run `subtess args`, which must fail cleanly (status 1, no panic); its stderr.
fn refused(args: &[&str]) -> String {
    let out = subtess(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    stderr
}

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("subtess-hostile-{}-{name}", std::process::id()))
}

fn write(name: &str, text: &str) -> PathBuf {
    let path = temp(name);
    std::fs::write(&path, text).expect("temp file");
    path
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// A tag whose argument count wraps `usize` when added panicked in the OBJ reader.
#[test]
fn tag_counts_that_wrap_are_refused() {
    let cube = std::fs::read_to_string(data("cube.obj")).expect("cube.obj");
    let path = write(
        "wrap.obj",
        &format!("{cube}t crease 18446744073709551615/1/0\n"),
    );
    let out = temp("wrap-out.obj");
    let stderr = refused(&[
        "tessellate",
        path.to_str().expect("a UTF-8 path"),
        "-o",
        out.to_str().expect("a UTF-8 path"),
    ]);
    std::fs::remove_file(&path).ok();
    assert!(stderr.contains("wrap.obj:17:"), "{stderr}");
    assert!(stderr.contains("announces more arguments"), "{stderr}");
    assert!(!out.exists());
}

/// A Newell or `.bpt` patch count of 10^10 aborted allocating 1.3 TB before reading a patch.
#[test]
fn huge_patch_counts_are_refused_without_allocating() {
    let newell = write(
        "huge-count",
        "10000000000\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n",
    );
    let bpt = write("huge-count.bpt", "10000000000\n3 3\n0 0 0\n");
    let out = temp("huge-count-out.obj");
    for (path, expected) in [
        (&newell, "patch 2 of 10000000000"),
        (&bpt, "control point 2"),
    ] {
        let stderr = refused(&[
            "tessellate",
            "--bezier",
            path.to_str().expect("a UTF-8 path"),
            "-o",
            out.to_str().expect("a UTF-8 path"),
        ]);
        std::fs::remove_file(path).ok();
        assert!(stderr.contains("unexpected end of file"), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
    }
}

/// A 100 GiB sparse file given as a table was read whole (into 100 GiB of memory) before its
/// magic was checked; now its 64-byte header is read first.
#[test]
fn absurd_table_files_are_refused_from_the_header() {
    let path = temp("sparse.subtess");
    let file = std::fs::File::create(&path).expect("temp file");
    file.set_len(100 << 30).expect("a sparse file");
    drop(file);
    let stderr = refused(&["tables", "info", path.to_str().expect("a UTF-8 path")]);
    assert!(stderr.contains("not a subtess stencil table"), "{stderr}");
    let stderr = refused(&[
        "bench",
        data("cube.obj").to_str().expect("a UTF-8 path"),
        "--table",
        path.to_str().expect("a UTF-8 path"),
        "--frames",
        "1",
    ]);
    std::fs::remove_file(&path).ok();
    assert!(stderr.contains("not a subtess stencil table"), "{stderr}");
}

/// `subtess tables info | head -1` panicked on the broken pipe (exit 134). The reader here
/// closes the pipe before `subtess` has loaded and verified its table, so every line it
/// prints meets a closed pipe.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_closed_pipe_ends_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(["tables", "info"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("subtess runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("subtess ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(stderr.is_empty(), "{stderr}");
}

/// `bench --threads 20000` started 20,000 threads; the limit is 256.
#[test]
#[cfg(feature = "catmull-clark")]
fn thread_counts_are_capped() {
    let cube = data("cube.obj");
    for threads in ["20000", "257", "0"] {
        let stderr = refused_usage(&[
            "bench",
            cube.to_str().expect("a UTF-8 path"),
            "--threads",
            threads,
        ]);
        assert!(stderr.contains("--threads"), "{stderr}");
        assert!(stderr.contains("1..=256"), "{stderr}");
    }
    let out = subtess(&[
        "bench",
        cube.to_str().expect("a UTF-8 path"),
        "--threads",
        "2",
        "--frames",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Run `subtess args`, which must be refused as a usage error (clap's status 2); its stderr.
fn refused_usage(args: &[&str]) -> String {
    let out = subtess(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    stderr
}

/// `text` with every vertex's coordinates multiplied by `s`.
fn scaled_obj(text: &str, s: f64) -> String {
    text.lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(coords) => {
                let c: Vec<f64> = coords
                    .split_whitespace()
                    .map(|x| x.parse::<f64>().expect("a coordinate") * s)
                    .collect();
                format!("v {:e} {:e} {:e}\n", c[0], c[1], c[2])
            }
            None => format!("{line}\n"),
        })
        .collect()
}

/// A cube of side 2e10 or 1e-11 got every normal `0 0 0`: the squared length of the tangents'
/// cross product overflowed or underflowed `f32`. Catmull–Clark on `data/cube.obj`, and Loop on
/// an octahedron, scaled.
#[test]
#[cfg(feature = "loop")]
#[cfg(feature = "catmull-clark")]
fn normals_are_unit_at_any_scale() {
    let cube = std::fs::read_to_string(data("cube.obj")).expect("cube.obj");
    let octahedron = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
        f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
    for (name, text, scheme) in [
        ("cube", cube.as_str(), Scheme::CatmullClark),
        ("octahedron", octahedron, Scheme::Loop),
    ] {
        // Half-sides 1e10 and 5e-12: sides 2e10 and 1e-11 for the cube; 1e18 puts its
        // vertices at the largest magnitude accepted (`MAX_COORDINATE`).
        for s in [1.0, 1e10, 5e-12, 1e18] {
            let path = write(&format!("{name}-{s}.obj"), &scaled_obj(text, s));
            let mesh = Mesh::read_obj(&path).expect("a valid mesh");
            std::fs::remove_file(&path).ok();
            let surface = Surface::new(&mesh, scheme).expect("a surface");
            let mut tessellator = surface.tessellator(&Rates::Uniform(2)).expect("a plan");
            let frame = tessellator
                .evaluate(&mesh.positions_f32())
                .expect("a frame");
            assert!(!frame.normals().is_empty());
            for (n, p) in frame.normals().iter().zip(frame.positions()) {
                let length = n.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>().sqrt();
                assert!(
                    (length - 1.0).abs() < 1e-5,
                    "{name} scaled by {s}: normal {n:?} at {p:?}"
                );
                // Outward on these convex, origin-centred shapes.
                let outward: f64 = n.iter().zip(p).map(|(&a, &b)| f64::from(a * b)).sum();
                assert!(outward > 0.0, "{name} scaled by {s}: normal {n:?} at {p:?}");
            }
        }
    }
}

/// A 1M-quad grid at `--rate 24`, `bench --refine 6` and large √3 refinements aborted
/// allocating gigabytes: the output was never estimated. Now the plan's estimate (and, for
/// `bench --refine`, the face count after refinement) is refused above `--max-triangles`
/// (200 million by default) before anything of its size is allocated.
#[test]
#[cfg(feature = "catmull-clark")]
fn outputs_over_the_triangle_budget_are_refused() {
    let cube = data("cube.obj");
    let cube = cube.to_str().expect("a UTF-8 path");
    let out = temp("budget-out.obj");
    let out = out.to_str().expect("a UTF-8 path");
    // Isolation splits the cube's 6 faces into 24: at rate 24, 24 * 2 * 24 * 25 = 28800
    // triangles estimated (27,644 made).
    let stderr = refused(&[
        "tessellate",
        cube,
        "--rate",
        "24",
        "--max-triangles",
        "28000",
        "-o",
        out,
    ]);
    assert!(stderr.contains("28800 triangles"), "{stderr}");
    assert!(stderr.contains("--max-triangles N raises it"), "{stderr}");
    assert!(!Path::new(out).exists());
    let made = subtess(&[
        "tessellate",
        cube,
        "--rate",
        "24",
        "--max-triangles",
        "28800",
        "-o",
        out,
    ]);
    assert!(made.status.success(), "{made:?}");
    std::fs::remove_file(out).ok();
    // The default budget: √3 on the octahedron refined 6 times (two √3 steps each) has
    // 8 * 9^6 = 4,251,528 faces, about 816 million triangles at rate 8.
    let stderr = refused(&[
        "bench",
        data("octahedron.obj").to_str().expect("a UTF-8 path"),
        "--scheme",
        "sqrt3",
        "--refine",
        "6",
        "--rate",
        "8",
        "--frames",
        "1",
    ]);
    assert!(
        stderr.contains("4251528 faces after refinement"),
        "{stderr}"
    );
    assert!(
        stderr.contains("the limit is 200000000 triangles"),
        "{stderr}"
    );
    // Catmull–Clark: 6 * 4^6 = 24576 faces, 29,491,200 triangles at rate 24.
    let stderr = refused(&[
        "bench",
        cube,
        "--refine",
        "6",
        "--rate",
        "24",
        "--max-triangles",
        "1000000",
        "--frames",
        "1",
    ]);
    assert!(stderr.contains("29491200 triangles"), "{stderr}");
    // The library refuses before planning, with the same error.
    let mesh = Mesh::read_obj(data("cube.obj")).expect("cube.obj");
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    assert!(matches!(
        surface.tessellator_within(&Rates::Uniform(24), 28000),
        Err(RuntimeError::OverBudget { .. })
    ));
    assert!(surface
        .tessellator_within(&Rates::Uniform(24), 28800)
        .is_ok());
}

/// `--method adaptive --tolerance 1e-7` on a cube grew to 4.5 GB and aborted: the squares
/// were split down to depth 16 whatever their number. Now the polygons are counted as they
/// are made, and the run fails at `--max-polygons` (20 million by default) naming the
/// tolerance it could not meet.
#[test]
#[cfg(feature = "catmull-clark")]
fn adaptive_tessellation_stops_at_its_polygon_cap() {
    let out = temp("adaptive-cap.obj");
    let stderr = refused(&[
        "tessellate",
        data("cube.obj").to_str().expect("a UTF-8 path"),
        "--method",
        "adaptive",
        "--tolerance",
        "1e-7",
        "--max-polygons",
        "10000",
        "-o",
        out.to_str().expect("a UTF-8 path"),
    ]);
    assert!(stderr.contains("distance tolerance 0.0000001"), "{stderr}");
    assert!(stderr.contains("the limit is 10000 polygons"), "{stderr}");
    assert!(stderr.contains("--max-polygons N raises it"), "{stderr}");
    assert!(!out.exists());
}

/// Coordinates near 1e308 reached an `unreachable!` in refinement (the refined positions
/// overflowed to infinity), and above 3.4e38 the f32 output was `inf`, written with exit 0.
/// Now every coordinate must be at most `MAX_COORDINATE` = 1e18 in magnitude, checked when
/// the mesh is read, the vertex named.
#[test]
fn positions_beyond_f32_are_refused() {
    let cube = std::fs::read_to_string(data("cube.obj")).expect("cube.obj");
    let out = temp("far-out.obj");
    for s in [2e18, 1e30, 1e300, 1.7e308] {
        let path = write(&format!("far-{s:e}.obj"), &scaled_obj(&cube, s));
        for scheme in ["catmull-clark", "loop"] {
            let stderr = refused(&[
                "tessellate",
                path.to_str().expect("a UTF-8 path"),
                "--scheme",
                scheme,
                "-o",
                out.to_str().expect("a UTF-8 path"),
            ]);
            assert!(stderr.contains("vertex 0 (OBJ `v` number 1)"), "{stderr}");
            assert!(stderr.contains("beyond 1e18"), "{stderr}");
            assert!(!out.exists());
        }
        let stderr = refused(&[
            "bench",
            path.to_str().expect("a UTF-8 path"),
            "--refine",
            "2",
            "--frames",
            "1",
        ]);
        assert!(stderr.contains("beyond 1e18"), "{stderr}");
        std::fs::remove_file(&path).ok();
    }
}

/// `subtess eval --uv 1/2^k` with a million digits took over a minute (this test takes 100,000, under the
/// 128 KiB a command-line argument may have) (big integers parse
/// in time quadratic in their digits). Now a parameter has at most 64 characters and a
/// numerator and denominator of at most 64 bits.
#[test]
fn eval_rationals_are_bounded() {
    let cube = data("cube.obj");
    let cube = cube.to_str().expect("a UTF-8 path");
    let huge = format!("1/1{},0", "0".repeat(100_000));
    let started = std::time::Instant::now();
    let stderr = refused(&["eval", cube, "--face", "0", "--uv", &huge]);
    assert!(started.elapsed().as_secs() < 20);
    assert!(stderr.contains("a parameter is at most 64"), "{stderr}");
    assert!(stderr.len() < 400, "{stderr}");
    // 2^64 = 18446744073709551616 has 65 bits; 2^63 is taken.
    let stderr = refused(&[
        "eval",
        cube,
        "--face",
        "0",
        "--uv",
        "1/18446744073709551616,0",
    ]);
    assert!(stderr.contains("more than 64 bits"), "{stderr}");
    let out = subtess(&[
        "eval",
        cube,
        "--face",
        "0",
        "--uv",
        "1/9223372036854775808,1/3",
    ]);
    assert!(out.status.success(), "{out:?}");
}

/// Error messages echoed a whole 200 MB token. Now the OBJ reader, the Bézier readers and the
/// rates file quote at most `EXCERPT_CHARS` = 60 characters of it, then `...` and its length.
#[test]
#[cfg(feature = "catmull-clark")]
fn long_tokens_are_quoted_short() {
    let token = "x".repeat(1_000_000);
    let cube = std::fs::read_to_string(data("cube.obj")).expect("cube.obj");
    let obj = write("long-token.obj", &format!("v 1 2 {token}\n{cube}"));
    let newell = write("long-token", &format!("1\n{token}{}\n", ",1".repeat(15)));
    let rates = write("long-token-rates.txt", &format!("1 2 3 {token} 5 6\n"));
    let out = temp("long-token-out.obj");
    let out = out.to_str().expect("a UTF-8 path");
    let cube_path = data("cube.obj");
    let runs: [Vec<&str>; 3] = [
        vec!["tessellate", obj.to_str().expect("a UTF-8 path"), "-o", out],
        vec![
            "tessellate",
            "--bezier",
            newell.to_str().expect("a UTF-8 path"),
            "-o",
            out,
        ],
        vec![
            "tessellate",
            cube_path.to_str().expect("a UTF-8 path"),
            "--rates",
            rates.to_str().expect("a UTF-8 path"),
            "-o",
            out,
        ],
    ];
    for args in &runs {
        let stderr = refused(args);
        assert!(stderr.len() < 600, "{args:?}: {} bytes", stderr.len());
        assert!(
            stderr.contains(&format!("{}... (1000000 bytes)", &token[..60])),
            "{args:?}: {stderr}"
        );
    }
    for path in [obj, newell, rates] {
        std::fs::remove_file(path).ok();
    }
}

/// A table written with a NaN weight has a valid checksum: `tables info` said "verified" and
/// the surface came out NaN. Files are now scanned for non-finite weights.
#[test]
fn tables_with_non_finite_weights_are_refused() {
    use table_format::{encode, Precision, SchemeId, SectionKey, StencilKind, TableMeta};
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let key = SectionKey {
        kind: StencilKind::Position,
        points: table_format::PointSet::Dual,
        boundary: false,
        feature: table_format::Feature::None,
        faces: 3,
        sector: 0,
        n: 1,
    };
    let mut weights = vec![0.0; 14];
    weights[3] = f64::NAN;
    let bytes = encode(meta, &[(key, 14, weights)]).expect("written");
    let path = temp("nan.subtess");
    std::fs::write(&path, bytes).expect("temp file");
    let stderr = refused(&["tables", "info", path.to_str().expect("a UTF-8 path")]);
    std::fs::remove_file(&path).ok();
    assert!(stderr.contains("not finite"), "{stderr}");
}

/// A user table whose section does not fit the face's patch (13 weights per point where the
/// valence-3 patch has 14 control points) used to be bypassed: the faces went to the adaptive
/// refinement as if the table lacked the section, and the run succeeded on other stencils
/// than the ones asked for. Only an absent section sends a face there now.
#[test]
fn a_table_section_that_does_not_fit_its_patch_is_refused_not_bypassed() {
    use table_format::{encode, Precision, SchemeId, SectionKey, StencilKind, TableMeta};
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let (n, width) = (2, 13);
    let points = table_format::PointSet::Dual.count(n) as usize;
    let sections: Vec<_> = [
        StencilKind::Position,
        StencilKind::DerivativeU,
        StencilKind::DerivativeV,
    ]
    .into_iter()
    .map(|kind| {
        let key = SectionKey {
            kind,
            points: table_format::PointSet::Dual,
            boundary: false,
            feature: table_format::Feature::None,
            faces: 3,
            sector: 0,
            n,
        };
        (
            key,
            width,
            vec![1.0 / f64::from(width); points * width as usize],
        )
    })
    .collect();
    let bytes = encode(meta, &sections).expect("written");
    let table = temp("narrow.subtess");
    std::fs::write(&table, bytes).expect("temp file");
    let out = temp("narrow.obj");
    let stderr = refused(&[
        "tessellate",
        data("cube.obj").to_str().expect("a UTF-8 path"),
        "-o",
        out.to_str().expect("a UTF-8 path"),
        "--table",
        table.to_str().expect("a UTF-8 path"),
        "--rate",
        "2",
    ]);
    std::fs::remove_file(&table).ok();
    std::fs::remove_file(&out).ok();
    assert!(
        stderr.contains("13 weights per point") && stderr.contains("14 control points"),
        "{stderr}"
    );
}
