//! The `subtess` command line: `tessellate` with `--stats` (DESIGN.md contract), per-face rates
//! from a file, `bench`, and clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn subtess(args: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(args.split_whitespace())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("subtess runs")
}

/// Run `subtess args`, which must succeed (its stderr is the failure message).
fn succeeds(args: &str) -> Output {
    let out = subtess(args);
    assert!(
        out.status.success(),
        "{args}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Run `subtess args`, which must fail; its stderr.
fn fails(args: &str) -> String {
    let out = subtess(args);
    assert!(!out.status.success(), "{args} succeeded");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("subtess-cli-{}-{name}", std::process::id()))
}

fn json(out: &Output) -> serde_json::Value {
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"))
}

#[test]
#[cfg(feature = "catmull-clark")]
fn tessellate_prints_the_stats_contract() {
    let obj = temp("cube.obj");
    let out = succeeds(&format!(
        "tessellate data/cube.obj -o {} --rate 5 --stats",
        obj.display()
    ));
    let stats = json(&out);
    for key in [
        "triangles",
        "vertices",
        "seconds",
        "triangles_per_second",
        "watertight",
        "isolation_seconds",
    ] {
        assert!(stats.get(key).is_some(), "{key} missing: {stats}");
    }
    assert_eq!(stats["watertight"], true);
    // The cube isolates in one step to 24 faces: 24 * 25 dual points; triangles by Euler
    // (a sphere: T = 2V - 4).
    assert_eq!(stats["faces"], 24);
    assert_eq!(stats["vertices"], 24 * 25);
    assert_eq!(stats["triangles"], 2 * 24 * 25 - 4);
    let text = std::fs::read_to_string(&obj).expect("written");
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 600);
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 1196);
    let _ = std::fs::remove_file(obj);
}

#[test]
#[cfg(feature = "catmull-clark")]
fn per_face_rates_from_a_file() {
    let rates = temp("rates.txt");
    // The cube has 6 faces; each becomes 4 after isolation.
    std::fs::write(&rates, "1 2 3\n4 5 24\n").expect("write");
    let obj = temp("rates.obj");
    let out = succeeds(&format!(
        "tessellate data/cube.obj -o {} --rates {} --stats",
        obj.display(),
        rates.display()
    ));
    let stats = json(&out);
    let points: u64 = [1u64, 2, 3, 4, 5, 24].iter().map(|n| 4 * n * n).sum();
    assert_eq!(stats["vertices"], points);
    assert_eq!(stats["watertight"], true);
    assert_eq!(
        (stats["rate_min"].as_u64(), stats["rate_max"].as_u64()),
        (Some(1), Some(24))
    );
    for (text, message) in [
        ("1 2 3 4 5", "5 rates for a mesh of 6 faces"),
        ("1 2 3 4 5 25", "rate 6 is `25`"),
        ("1 2 x 4 5 6", "rate 3 is `x`"),
    ] {
        std::fs::write(&rates, text).expect("write");
        let out = subtess(&format!(
            "tessellate data/cube.obj -o {} --rates {}",
            obj.display(),
            rates.display()
        ));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && stderr.contains(message),
            "{text}: {stderr}"
        );
    }
    let _ = std::fs::remove_file(rates);
    let _ = std::fs::remove_file(obj);
}

/// Every output format from the command line; the format is checked before any work.
#[test]
#[cfg(feature = "catmull-clark")]
fn output_formats_by_extension() {
    for (ext, magic) in [
        ("ply", &b"ply\nformat binary_little_endian 1.0"[..]),
        ("glb", b"glTF"),
        ("gltf", b"{"),
        ("obj", b"# subtess"),
    ] {
        let path = temp(&format!("cube.{ext}"));
        let out = subtess(&format!(
            "tessellate data/cube.obj -o {} --rate 2",
            path.display()
        ));
        assert!(
            out.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&path).expect("written");
        assert!(bytes.starts_with(magic), "{ext}");
        let _ = std::fs::remove_file(path);
    }
    let out = subtess("tessellate /nonexistent.obj -o out.stl");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains(".ply"), "{stderr}");
}

#[test]
#[cfg(feature = "catmull-clark")]
fn bench_reports_throughput() {
    let out = succeeds("bench data/cube.obj --refine 2 --rate 4 --threads 1 --frames 3");
    let report = json(&out);
    assert_eq!(report["threads"], 1);
    assert_eq!(report["faces"], 6 * 16);
    // Closed sphere-like surface: T = 2V - 4 with V = 16 points per face.
    assert_eq!(report["triangles"], 2 * 96 * 16 - 4);
    assert!(report["triangles_per_second"]
        .as_f64()
        .is_some_and(|t| t > 0.0));
    assert!(report["isolation_seconds"]
        .as_f64()
        .is_some_and(|t| t >= 0.0));
}

/// `bench --tolerance` chooses the rates again every frame and times the parts: the rates it
/// reports are those `tessellate --tolerance` chooses (the same triangles), and the selection,
/// the plan after it and the evaluation are each part of the frame.
#[test]
#[cfg(feature = "catmull-clark")]
fn bench_with_a_tolerance_plans_every_frame() {
    let out = succeeds("bench data/cube.obj --tolerance 2e-3 --threads 1 --frames 2");
    let report = json(&out);
    let obj = temp("bench_tolerance.obj");
    let once = json(&succeeds(&format!(
        "tessellate data/cube.obj -o {} --tolerance 2e-3 --stats",
        obj.display()
    )));
    let _ = std::fs::remove_file(obj);
    assert_eq!(report["triangles"], once["triangles"]);
    assert_eq!(report["rate_max"], once["rate_max"]);
    assert!(once["rates_seconds"].as_f64().is_some_and(|t| t > 0.0));
    let part = |key: &str| report[key].as_f64().unwrap_or(f64::NAN);
    let whole = part("median_seconds");
    for key in [
        "median_rates_seconds",
        "median_plan_seconds",
        "median_evaluate_seconds",
    ] {
        assert!(part(key) > 0.0 && part(key) < whole, "{key}: {report}");
    }
}

/// `bench --tolerance T --adaptive` tessellates adaptively every frame: the triangles it reports
/// are those `tessellate --method adaptive --triangulate` makes of the same mesh, and it refuses
/// what Lai–Cheng's method cannot take (no tolerance, a triangle scheme).
#[test]
#[cfg(feature = "catmull-clark")]
fn bench_adaptive_tessellates_every_frame() {
    let report = json(&succeeds(
        "bench data/cube.obj --tolerance 2e-3 --adaptive --threads 1 --frames 2",
    ));
    let ply = temp("bench_adaptive.ply");
    let once = json(&succeeds(&format!(
        "tessellate data/cube.obj -o {} --method adaptive --tolerance 2e-3 --triangulate --stats",
        ply.display()
    )));
    let _ = std::fs::remove_file(ply);
    assert_eq!(report["triangles"], once["triangles"], "{report}");
    assert!(
        report["triangles"].as_u64().is_some_and(|t| t > 0),
        "{report}"
    );
    for key in [
        "first_frame_seconds",
        "median_seconds",
        "triangles_per_second",
    ] {
        assert!(
            report[key].as_f64().is_some_and(|x| x > 0.0),
            "{key}: {report}"
        );
    }
    assert!(fails("bench data/cube.obj --adaptive").contains("--tolerance"));
    #[cfg(feature = "loop")]
    assert!(
        fails("bench data/octahedron.obj --scheme loop --tolerance 1e-2 --adaptive")
            .contains("catmull-clark")
    );
}

#[test]
fn bad_input_is_a_clear_error() {
    let bad = temp("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").expect("write");
    for (args, message) in [
        (
            format!("tessellate {} -o x.obj", bad.display()),
            "out of range",
        ),
        (
            "tessellate /nonexistent.obj -o x.obj".to_owned(),
            "/nonexistent.obj",
        ),
        (
            "tessellate data/cube.obj -o x.obj --rate 25".to_owned(),
            "25",
        ),
    ] {
        let out = subtess(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args}");
        assert!(stderr.contains(message), "{args}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args}: {stderr}");
    }
    assert!(!Path::new(env!("CARGO_MANIFEST_DIR")).join("x.obj").exists());
    let _ = std::fs::remove_file(bad);
}

/// `--tolerance`: a tighter tolerance never needs fewer triangles; `--view`: a nearer camera
/// never fewer; malformed values are refused by the argument parser.
#[test]
#[cfg(feature = "catmull-clark")]
fn tolerance_and_view_rates() {
    let obj = temp("rates-cube.obj");
    let triangles = |args: &str| -> u64 {
        let out = subtess(&format!(
            "tessellate data/cube.obj -o {} --stats {args}",
            obj.display()
        ));
        assert!(
            out.status.success(),
            "{args}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stats = json(&out);
        assert_eq!(stats["watertight"], true, "{args}");
        stats["triangles"].as_u64().expect("a count")
    };
    let tolerances = ["0.05", "0.01", "0.002"].map(|t| triangles(&format!("--tolerance {t}")));
    assert!(
        tolerances[0] <= tolerances[1] && tolerances[1] <= tolerances[2],
        "{tolerances:?}"
    );
    assert!(tolerances[0] < tolerances[2], "{tolerances:?}");
    let far = triangles("--view 0,0,40,0,0,0,45,1080,8");
    let near = triangles("--view 0,0,4,0,0,0,45,1080,8");
    assert!(far < near, "{far} vs {near}");
    for args in [
        "--view 1,2,3",
        "--tolerance -1",
        "--tolerance 0.01 --rate 3",
    ] {
        let out = subtess(&format!(
            "tessellate data/cube.obj -o {} {args}",
            obj.display()
        ));
        assert!(!out.status.success(), "{args}");
    }
    let _ = std::fs::remove_file(obj);
}

/// `subtess eval` on sharp features, exactly (`eval::exact_eval::feature`): `data/cube_creased.obj`'s
/// top face is bounded by an infinitely sharp crease and its refined points never leave the
/// plane `z = 1` (face points, crease midpoints and crease vertex points of points at `z = 1`),
/// so its limit has `z = 1` exactly, and the top face is symmetric, so its centre is on the z
/// axis; its corner at vertex 4 is the crease's limit `(E_a + 4 V + E_b) / 6 =
/// (-2/3, -2/3, 1)`, correctly rounded; the JSON keeps its keys.
#[test]
fn eval_is_exact_on_sharp_features() {
    let position = |uv: &str| -> Vec<f64> {
        let out = succeeds(&format!(
            "eval data/cube_creased.obj --face 1 --uv {uv} --json"
        ));
        let point = json(&out);
        assert!(point["du"].as_array().is_some_and(|a| a.len() == 3));
        assert!(point["dv"].as_array().is_some_and(|a| a.len() == 3));
        point["position"]
            .as_array()
            .expect("position")
            .iter()
            .filter_map(|x| x.as_f64())
            .collect()
    };
    assert_eq!(position("0,0"), vec![-2.0 / 3.0, -2.0 / 3.0, 1.0]);
    assert_eq!(position("1/2,1/2"), vec![0.0, 0.0, 1.0]);
    assert_eq!(position("1/3,2/7")[2], 1.0);
}

/// `subtess eval` (DESIGN.md contract): JSON `{"position","du","dv"}`; the centre of the cube's
/// top face lies on the cube's z axis (symmetry); bad arguments are clear errors.
#[test]
fn eval_prints_the_limit_point() {
    let out = succeeds("eval data/cube.obj --scheme catmull-clark --face 1 --uv 1/2,1/2 --json");
    let point = json(&out);
    let p: Vec<f64> = point["position"]
        .as_array()
        .expect("position")
        .iter()
        .filter_map(|x| x.as_f64())
        .collect();
    assert_eq!(p.len(), 3);
    assert!(point["du"].as_array().is_some_and(|a| a.len() == 3));
    assert!(point["dv"].as_array().is_some_and(|a| a.len() == 3));
    // data/cube.obj is [-1, 1]^3, face 1 its top (z = 1).
    assert!(
        p[0].abs() < 1e-15 && p[1].abs() < 1e-15 && p[2] > 0.5 && p[2] < 1.0,
        "{p:?}"
    );
    for (args, message) in [
        ("eval data/cube.obj --face 99 --uv 0,0", "99"),
        ("eval data/cube.obj --face 0 --uv 1/0,0", "1/0"),
        ("eval data/cube.obj --face 0 --uv 2,0", "outside"),
        ("eval data/cube.obj --face 0 --uv 0.5", "two rationals"),
        (
            "eval data/cube.obj --scheme loop --face 0 --uv 0,0",
            "triangles",
        ),
        (
            "eval data/cube.obj --scheme butterfly --face 0 --uv 0,0",
            "not implemented",
        ),
        (
            "eval data/cube.obj --scheme sqrt3 --face 0 --uv 0,0",
            "not implemented",
        ),
        (
            "eval data/cube.obj --scheme sw-nonpoly-quad --face 0 --uv 0,0",
            "no table",
        ),
    ] {
        let out = subtess(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && stderr.contains(message),
            "{args}: {stderr}"
        );
    }
}

/// `--bezier`: Espino et al.'s tessellator from the same command, with its own `--stats`.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn bezier_patches_from_the_command_line() {
    let teapot = crate::common::models().join("bezier/teapot.bpt");
    let out_path = temp("teapot.ply");
    let out = succeeds(&format!(
        "tessellate --bezier {} -o {} --test map4p --triangles 3000 --stats",
        teapot.display(),
        out_path.display()
    ));
    let stats = json(&out);
    let triangles = stats["triangles"].as_u64().expect("a count");
    assert!((2700..=3300).contains(&triangles), "{triangles}");
    assert_eq!(
        stats["vertices_discarded"], 0,
        "map tests decide before evaluating"
    );
    assert!(std::fs::read(&out_path)
        .expect("written")
        .starts_with(b"ply"));
    let _ = std::fs::remove_file(out_path);
}

/// `--bezier`'s options without `--bezier`, and no input at all, are refused.
#[test]
fn bezier_options_need_bezier_input() {
    for args in [
        "tessellate data/cube.obj -o x.obj --threshold 3",
        "tessellate -o x.obj",
    ] {
        let out = subtess(args);
        assert!(!out.status.success(), "{args}");
    }
}

/// A mesh that pins its corners (`t interpolateboundary 1 0`) tessellates with the embedded
/// tables, no table file needed.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn pinned_corners_work_out_of_the_box() {
    let shape = crate::common::models().join("opensubdiv/catmark_edgecorner.obj");
    let obj = temp("edgecorner.obj");
    let out = succeeds(&format!(
        "tessellate {} -o {} --rate 3 --stats",
        shape.display(),
        obj.display()
    ));
    let stats = json(&out);
    assert!(stats["boundary_loops"].as_u64().is_some_and(|l| l > 0));
    assert!(stats["triangles"].as_u64().is_some_and(|t| t > 0));
    let _ = std::fs::remove_file(obj);
}

/// `--method adaptive` (Lai-Cheng): polygons in OBJ, triangles elsewhere, watertight, the bound
/// under the tolerance; it needs `--tolerance`.
#[test]
#[cfg(feature = "catmull-clark")]
fn adaptive_method_from_the_command_line() {
    let obj = temp("adaptive.obj");
    let out = succeeds(&format!(
        "tessellate data/cube.obj -o {} --method adaptive --tolerance 0.02 --stats",
        obj.display()
    ));
    let stats = json(&out);
    assert_eq!(stats["watertight"], true);
    for key in ["write_seconds", "check_seconds"] {
        assert!(stats[key].as_f64().is_some(), "{key} missing: {stats}");
    }
    assert_eq!(stats["leaves_over_tolerance"], 0);
    assert!(stats["max_bound"].as_f64().is_some_and(|b| b <= 0.02));
    let polygons = stats["polygons"].as_u64().expect("a count");
    let text = std::fs::read_to_string(&obj).expect("written");
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count() as u64,
        polygons
    );
    for args in [
        format!(
            "tessellate data/cube.obj -o {} --method adaptive",
            obj.display()
        ),
        format!("tessellate data/cube.obj -o {} --relative", obj.display()),
    ] {
        let out = subtess(&args);
        assert!(!out.status.success(), "{args}");
    }
    let _ = std::fs::remove_file(obj);
}

/// `--max-depth`: the pinned corner of `cube_creased.obj` is a cone's tip, where the bound
/// shrinks by 0.654 a level (docs/lai-cheng.md): `T = 1e-3` needs more than the default 16
/// levels there, so squares stay over it, and stderr says how many; at 18 none does. Beyond
/// the parameter grid's 24 levels, or 0, is a usage error.
#[test]
#[cfg(feature = "catmull-clark")]
fn adaptive_max_depth_and_the_squares_left_over() {
    let ply = temp("cone.ply");
    let base = format!(
        "tessellate data/cube_creased.obj -o {} --method adaptive --tolerance 1e-3 --stats",
        ply.display()
    );
    let out = succeeds(&base);
    let over = json(&out)["leaves_over_tolerance"]
        .as_u64()
        .expect("a count");
    assert!(over > 0, "the cone's tip at depth 16");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!(
            "warning: {over} squares do not meet the tolerance 0.001 at depth 16"
        )),
        "{stderr}"
    );
    let out = succeeds(&format!("{base} --max-depth 18"));
    assert_eq!(json(&out)["leaves_over_tolerance"], 0);
    assert_eq!(json(&out)["max_depth"], 18);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    for depth in [0, 25] {
        let stderr = fails(&format!("{base} --max-depth {depth}"));
        assert!(stderr.contains("--max-depth"), "{stderr}");
    }
    let _ = std::fs::remove_file(ply);
}

/// A regular octahedron (every vertex valence 4: one Loop step isolates it).
const OCTAHEDRON: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

#[test]
fn eval_evaluates_loop_surfaces_exactly() {
    let mesh = temp("octahedron-eval.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let eval = |uv: &str| {
        let out = succeeds(&format!(
            "eval {} --scheme loop --face 0 --uv {uv} --json",
            mesh.display()
        ));
        let point = json(&out);
        let get = |key: &str| -> Vec<f64> {
            point[key]
                .as_array()
                .map(|a| a.iter().filter_map(|x| x.as_f64()).collect())
                .unwrap_or_default()
        };
        (get("position"), get("du"), get("dv"))
    };
    // Loop's limit rule at valence 4 (Warren: beta = 3/32, chi = 1/(3/(8 beta) + 4) = 1/8):
    // V/2 + (sum of the four neighbours)/8; face 0 = (1,0,0), (0,1,0), (0,0,1), and the
    // neighbours of (1,0,0) are (0,+-1,0), (0,0,+-1), summing to 0.
    let (p, du, dv) = eval("0,0");
    assert_eq!(p, vec![0.5, 0.0, 0.0]);
    // The tangent plane there is x = const: both masks have no x component.
    assert!(du[0].abs() < 1e-15 && dv[0].abs() < 1e-15, "{du:?} {dv:?}");
    // The centre of the face lies on the symmetry axis x = y = z.
    let (c, _, _) = eval("1/3,1/3");
    assert!(
        (c[0] - c[1]).abs() < 1e-15 && (c[1] - c[2]).abs() < 1e-15,
        "{c:?}"
    );
    let _ = std::fs::remove_file(mesh);
}

#[test]
#[cfg(feature = "loop")]
fn loop_scheme_takes_view_dependent_rates() {
    let mesh = temp("octahedron-view.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let out_path = temp("octahedron-view.obj.out.obj");
    let stats = |view: &str| {
        let out = succeeds(&format!(
            "tessellate {} -o {} --scheme loop --view {view} --stats",
            mesh.display(),
            out_path.display()
        ));
        json(&out)
    };
    let far = stats("0,0,40,0,0,0,45,1080,8");
    let near = stats("0,0,4,0,0,0,45,1080,8");
    assert_eq!(
        (far["watertight"].clone(), near["watertight"].clone()),
        (true.into(), true.into())
    );
    let count = |s: &serde_json::Value| s["triangles"].as_u64().unwrap_or(0);
    assert!(count(&far) < count(&near), "{far} vs {near}");
    // The nearer camera sees longer edges: higher rates, up to the selection's 24.
    assert!(
        near["rate_max"].as_u64() > far["rate_max"].as_u64(),
        "{far} vs {near}"
    );
    let _ = std::fs::remove_file(mesh);
    let _ = std::fs::remove_file(out_path);
}

#[test]
#[cfg(feature = "loop")]
fn loop_scheme_tessellates_triangles() {
    let mesh = temp("octahedron.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let out_path = temp("octahedron-loop.ply");
    let out = succeeds(&format!(
        "tessellate {} -o {} --scheme loop --rate 3 --stats",
        mesh.display(),
        out_path.display()
    ));
    let stats = json(&out);
    assert_eq!(stats["scheme"], "loop");
    assert!(stats["isolation_seconds"].as_f64().is_some());
    assert_eq!(stats["watertight"], true);
    assert_eq!(stats["isolation_steps"], 1);
    assert_eq!(stats["faces"], 32);
    // Per triangle at rate n: 3n^2 - 3n + 3 triangles (21 at n = 3); a closed surface of genus 0
    // has V = T/2 + 2.
    assert_eq!(stats["triangles"], 32 * 21);
    assert_eq!(stats["vertices"], 32 * 21 / 2 + 2);
    // Per-input-face rates, inherited by the four children of each triangle.
    let rates = temp("octahedron-rates.txt");
    std::fs::write(&rates, "1 2 3 4 5 6 7 8").expect("written");
    let out = succeeds(&format!(
        "tessellate {} -o {} --scheme loop --rates {} --stats",
        mesh.display(),
        out_path.display(),
        rates.display()
    ));
    let stats = json(&out);
    assert_eq!(stats["watertight"], true);
    assert_eq!(
        (stats["rate_min"].clone(), stats["rate_max"].clone()),
        (1.into(), 8.into())
    );
    let bench = succeeds(&format!(
        "bench {} --scheme loop --rate 4 --frames 2",
        mesh.display()
    ));
    let report = json(&bench);
    assert_eq!(report["triangles"], 32 * (3 * 16 - 3 * 4 + 3));
    for path in [mesh, out_path, rates] {
        let _ = std::fs::remove_file(path);
    }
}

/// `subtess tessellate MESH --scheme SCHEME --rate N --stats` for every `N` in 1..=24 (the
/// embedded table's rates): each reports a watertight output of `3N^2 - 3N + 3` triangles per
/// isolated triangle (genus 0: `V = T/2 + 2`); rate 25 is refused by name.
fn every_rate_is_watertight(mesh: &std::path::Path, out_path: &std::path::Path, scheme: &str) {
    for n in 1..=24u64 {
        let stats = json(&succeeds(&format!(
            "tessellate {} -o {} --scheme {scheme} --rate {n} --stats",
            mesh.display(),
            out_path.display()
        )));
        assert_eq!(stats["watertight"], true, "{scheme} at rate {n}");
        let faces = stats["faces"].as_u64().expect("faces");
        let triangles = faces * (3 * n * n - 3 * n + 3);
        assert_eq!(stats["triangles"], triangles, "{scheme} at rate {n}");
        assert_eq!(stats["vertices"], triangles / 2 + 2, "{scheme} at rate {n}");
    }
    let err = fails(&format!(
        "tessellate {} -o {} --scheme {scheme} --rate 25",
        mesh.display(),
        out_path.display()
    ));
    assert!(err.contains("25"), "{err}");
}

#[test]
#[cfg(feature = "butterfly")]
fn butterfly_scheme_tessellates_closed_triangle_meshes() {
    let mesh = temp("octahedron-b.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let out_path = temp("octahedron-butterfly.ply");
    let out = succeeds(&format!(
        "tessellate {} -o {} --scheme butterfly --rate 2 --stats",
        mesh.display(),
        out_path.display()
    ));
    let stats = json(&out);
    assert_eq!(stats["scheme"], "butterfly");
    assert_eq!(stats["watertight"], true);
    assert!(stats["isolation_seconds"]
        .as_f64()
        .is_some_and(|t| t >= 0.0));
    // Neighbouring valence-4 vertices are six edges apart after three steps.
    assert_eq!(stats["isolation_steps"], 3);
    assert_eq!(stats["faces"], 8 * 64);
    // 3n^2 - 3n + 3 triangles per triangle at rate n (9 at n = 2); genus 0: V = T/2 + 2.
    assert_eq!(stats["triangles"], 8 * 64 * 9);
    assert_eq!(stats["vertices"], 8 * 64 * 9 / 2 + 2);
    let bench = succeeds(&format!(
        "bench {} --scheme butterfly --rate 3 --frames 2",
        mesh.display()
    ));
    assert_eq!(json(&bench)["triangles"], 8 * 64 * 21);
    assert!(json(&bench)["isolation_seconds"].as_f64().is_some());
    // Issue 18: the embedded (compact) table covers every rate 1..=24, each one watertight.
    every_rate_is_watertight(&mesh, &out_path, "butterfly");
    // A mesh with a boundary: the butterfly's boundary rules are not implemented.
    let open = temp("open-triangle.obj");
    std::fs::write(&open, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("written");
    let err = fails(&format!(
        "tessellate {} -o {} --scheme butterfly",
        open.display(),
        out_path.display()
    ));
    assert!(err.contains("boundary"), "{err}");
    for path in [mesh, out_path, open] {
        let _ = std::fs::remove_file(path);
    }
}

#[test]
#[cfg(feature = "sqrt3")]
fn sqrt3_scheme_tessellates_triangle_meshes() {
    let mesh = temp("octahedron-s.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let out_path = temp("octahedron-sqrt3.obj");
    let out = succeeds(&format!(
        "tessellate {} -o {} --scheme sqrt3 --rate 3 --stats",
        mesh.display(),
        out_path.display()
    ));
    let stats = json(&out);
    assert_eq!(stats["scheme"], "sqrt3");
    assert!(stats["isolation_seconds"].as_f64().is_some());
    assert_eq!(stats["watertight"], true);
    // Neighbouring valence-4 vertices are nine edges apart after two ternary steps.
    assert_eq!(stats["isolation_steps"], 2);
    assert_eq!(stats["faces"], 8 * 81);
    // 3n^2 - 3n + 3 triangles per triangle at rate n (21 at n = 3); genus 0: V = T/2 + 2.
    assert_eq!(stats["triangles"], 8 * 81 * 21);
    assert_eq!(stats["vertices"], 8 * 81 * 21 / 2 + 2);
    let bench = succeeds(&format!(
        "bench {} --scheme sqrt3 --rate 2 --frames 2",
        mesh.display()
    ));
    assert_eq!(json(&bench)["triangles"], 8 * 81 * 9);
    // Issue 18: the embedded (compact) table covers every rate 1..=24, each one watertight.
    every_rate_is_watertight(&mesh, &out_path, "sqrt3");
    // A mesh with a boundary (one triangle: three corners with one triangle each, three
    // ternary steps apart) tessellates with √3's boundary patches; a tolerance is refused there.
    let open = temp("open-triangle-s.obj");
    std::fs::write(&open, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("written");
    let stats = json(&succeeds(&format!(
        "tessellate {} -o {} --scheme sqrt3 --rate 2 --stats",
        open.display(),
        out_path.display()
    )));
    assert_eq!(stats["boundary_loops"], 1);
    assert_eq!(stats["watertight"], false);
    assert_eq!(stats["isolation_steps"], 3);
    let err = fails(&format!(
        "tessellate {} -o {} --scheme sqrt3 --tolerance 0.01",
        open.display(),
        out_path.display()
    ));
    assert!(err.contains("boundary"), "{err}");
    let info = succeeds("tables info --scheme sqrt3");
    assert!(String::from_utf8_lossy(&info.stdout).contains("sqrt3"));
    for path in [mesh, out_path, open] {
        let _ = std::fs::remove_file(path);
    }
}

#[test]
#[cfg(feature = "loop")]
#[cfg(feature = "catmull-clark")]
fn loop_scheme_errors_name_the_problem() {
    let obj = temp("never.obj");
    // The cube's first face is a quad.
    let err = fails(&format!(
        "tessellate data/cube.obj -o {} --scheme loop",
        obj.display()
    ));
    assert!(err.contains("face 0 has 4 vertices"), "{err}");
    let err = fails(&format!(
        "tessellate data/cube.obj -o {} --scheme sqrt3",
        obj.display()
    ));
    assert!(err.contains("face 0 has 4 vertices"), "{err}");
    let err = fails(&format!(
        "tessellate data/cube.obj -o {} --scheme sw-nonpoly-quad",
        obj.display()
    ));
    assert!(err.contains("no table for this scheme yet"), "{err}");
    assert!(err.contains("sw-nonpoly-quad"), "{err}");
    let out = subtess(&format!(
        "tessellate data/cube.obj -o {} --scheme nonsense",
        obj.display()
    ));
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("nonsense"));
}

/// `--tolerance` with the triangle schemes: a tighter tolerance never needs fewer triangles,
/// the stats report the tolerance and the triangles that cannot meet it (with a warning), and
/// `--method adaptive` is still refused.
#[test]
#[cfg(all(feature = "loop", feature = "butterfly", feature = "sqrt3"))]
fn triangle_schemes_take_a_tolerance() {
    let mesh = temp("octahedron-tolerance.obj");
    std::fs::write(&mesh, OCTAHEDRON).expect("written");
    let out_path = temp("octahedron-tolerance.out.obj");
    let run = |args: &str| {
        subtess(&format!(
            "tessellate {} -o {} --stats {args}",
            mesh.display(),
            out_path.display()
        ))
    };
    let stats = |args: &str| {
        let out = run(args);
        assert!(
            out.status.success(),
            "{args}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        json(&out)
    };
    let mut previous = 0;
    for t in ["0.05", "0.01", "0.002"] {
        let s = stats(&format!("--scheme loop --tolerance {t}"));
        assert_eq!(s["watertight"], true, "{s}");
        assert_eq!(s["tolerance"].as_f64(), t.parse().ok(), "{s}");
        assert_eq!(s["faces_over_tolerance"], 0, "{s}");
        let count = s["triangles"].as_u64().unwrap_or(0);
        assert!(count >= previous, "T = {t}: {count} < {previous}");
        previous = count;
    }
    // 0.002 of a unit octahedron needs more than rate 1 somewhere: 3n^2 - 3n + 3 per triangle.
    assert!(previous > 32 * 3, "{previous}");
    let s = stats("--scheme butterfly --tolerance 0.01");
    assert_eq!(
        (s["scheme"].clone(), s["watertight"].clone()),
        ("butterfly".into(), true.into())
    );
    assert!(s["rate_max"].as_u64().is_some_and(|n| n <= 8), "{s}");
    let s = stats("--scheme sqrt3 --tolerance 0.01");
    assert_eq!(
        (s["scheme"].clone(), s["watertight"].clone()),
        ("sqrt3".into(), true.into())
    );
    assert_eq!(s["faces_over_tolerance"], 0, "{s}");
    assert!(s["rate_max"].as_u64().is_some_and(|n| n <= 8), "{s}");
    // Far below what the table's largest rate reaches: every triangle is reported.
    let out = run("--scheme loop --tolerance 1e-9");
    assert!(out.status.success());
    assert_eq!(json(&out)["faces_over_tolerance"], 32);
    assert!(String::from_utf8_lossy(&out.stderr).contains("do not meet the tolerance"));
    let out = run("--scheme loop --method adaptive --tolerance 0.01");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--method adaptive"));
    for path in [mesh, out_path] {
        let _ = std::fs::remove_file(path);
    }
}

/// `subtess render` draws every format `tessellate` writes, side by side, into the same bytes
/// every time, and refuses sizes and views it cannot draw.
#[test]
#[cfg(feature = "catmull-clark")]
fn render_draws_what_tessellate_writes() {
    let (ply, glb, png, again) = (
        temp("render.ply"),
        temp("render.glb"),
        temp("render.png"),
        temp("render-again.png"),
    );
    for out in [&ply, &glb] {
        succeeds(&format!(
            "tessellate data/cube.obj -o {} --rate 4",
            out.display()
        ));
    }
    for target in [&png, &again] {
        succeeds(&format!(
            "render data/cube.obj {} {} -o {} --size 64x48 --view 20,-10 --wireframe",
            ply.display(),
            glb.display(),
            target.display()
        ));
    }
    let (a, b) = (
        std::fs::read(&png).expect("a PNG"),
        std::fs::read(&again).expect("a PNG"),
    );
    assert_eq!(&a[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(a, b, "the same inputs give the same bytes");
    // Width 3 x 64 = 192, height 48: the IHDR chunk after the signature and its length/type.
    assert_eq!(u32::from_be_bytes([a[16], a[17], a[18], a[19]]), 192);
    assert_eq!(u32::from_be_bytes([a[20], a[21], a[22], a[23]]), 48);
    for path in [&ply, &glb, &png, &again] {
        std::fs::remove_file(path).ok();
    }
    let out = temp("refused.png");
    for (args, message) in [
        ("--size 0x10", "a side of 1..="),
        ("--size 100000x10", "a side of 1..="),
        ("--view 10", "AZ,EL"),
        ("--view 10,20,0.5", "more than 1 radius"),
    ] {
        let err = fails(&format!("render data/cube.obj -o {} {args}", out.display()));
        assert!(err.contains(message), "{args}: {err}");
    }
    let err = fails(&format!("render data/cube_rates.txt -o {}", out.display()));
    assert!(err.contains("reads .obj, .ply and .glb"), "{err}");
    assert!(!out.exists(), "no image for a refused command");
}
