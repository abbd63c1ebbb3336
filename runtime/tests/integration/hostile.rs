//! Hostile input (issue 20): inputs that used to panic, abort allocating or print zero
//! normals are refused with a message (or handled), never a crash. Each test names the
//! defect it guards.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use subtess::{Mesh, Rates, Scheme, Surface};

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
fn normals_are_unit_at_any_scale() {
    let cube = std::fs::read_to_string(data("cube.obj")).expect("cube.obj");
    let octahedron = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
        f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
    for (name, text, scheme) in [
        ("cube", cube.as_str(), Scheme::CatmullClark),
        ("octahedron", octahedron, Scheme::Loop),
    ] {
        // Half-sides 1e10 and 5e-12: sides 2e10 and 1e-11 for the cube.
        for s in [1.0, 1e10, 5e-12] {
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
