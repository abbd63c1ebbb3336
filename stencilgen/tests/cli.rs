//! The `stencilgen` command line: the DESIGN.md contract and its errors.

use std::process::{Command, Output};

/// Run `stencilgen` with a whitespace-separated argument line.
fn stencilgen(args: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stencilgen"))
        .args(args.split_whitespace())
        .output()
        .expect("stencilgen runs")
}

/// The command fails cleanly (an exit status, not a signal or a panic) and says `message`.
fn fails_with(args: &str, message: &str) {
    let out = stencilgen(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(
        out.status.code().is_some(),
        "{args:?} was killed by a signal"
    );
    assert!(stderr.contains(message), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

fn json(args: &str) -> serde_json::Value {
    let out = stencilgen(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

#[test]
fn curve_json_follows_the_contract() {
    let v = json("curve --scheme four-point --n 3 --json");
    assert_eq!(v["scheme"], "four-point");
    assert_eq!(v["n"], 3);
    assert_eq!(v["support"], serde_json::json!([-3, 3]));
    let x = v["x"].as_array().expect("x");
    let values = v["values"].as_array().expect("values");
    assert_eq!(x.len(), 19);
    assert_eq!(values.len(), 19);
    assert_eq!(x[1], "-8/3");
    // Schaefer–Warren section 2: phi(-8/3) = -1/5589, phi(0) = 1.
    assert_eq!(values[1], "-1/5589");
    assert_eq!(values[9], "1");
}

#[test]
fn f64_values_are_numbers_with_a_residual() {
    let v = json("curve --scheme four-point --n 3 --derivative --f64 --json");
    let third = v["values"][10].as_f64().expect("a number");
    assert!((third + 584.0 / 540.0).abs() < 1e-12, "phi'(1/3) = {third}");
    assert!(v["residual"].as_f64().expect("residual") < 1e-12);
}

#[test]
fn vector_schemes_list_their_components() {
    let v = json("curve --scheme nonuniform-cubic-bspline --n 2 --json");
    let functions = v["functions"].as_array().expect("functions");
    assert_eq!(functions.len(), 5);
    assert_eq!(functions[2]["name"], "point0");
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let cases: [(&str, &str); 6] = [
        (
            "curve --scheme loop-de-loop --n 3",
            "unknown scheme `loop-de-loop`",
        ),
        ("curve --scheme four-point --n 0", "0 is not in 1..=1024"),
        (
            "curve --scheme four-point --n three",
            "invalid value 'three'",
        ),
        ("curve --scheme four-point", "--n <N>"),
        ("curve --scheme four-point --n 3 --wat", "--wat"),
        (
            "curve --scheme nonuniform-cubic-bspline --n 3 --derivative",
            "does not map linear data to linear data",
        ),
    ];
    for (args, message) in cases {
        fails_with(args, message);
    }
}

#[test]
fn stencil_json_follows_the_contract() {
    let v = json("stencil --scheme catmull-clark --valence 5 --u 1/3 --v 2/7 --json");
    let weights = v["weights"].as_array().expect("weights");
    assert_eq!(weights.len(), 2 * 5 + 8);
    assert_eq!(v["du"].as_array().expect("du").len(), 18);
    assert_eq!(v["dv"].as_array().expect("dv").len(), 18);
    assert_eq!(v["order"][1], "E1");
    // At the EV the position is the classical limit mask (v^2 V + 4 sum E + sum F)/(v(v+5));
    // exact tangents there are irrational: null, with a note.
    let v = json("stencil --scheme catmull-clark --valence 5 --u 0 --v 0 --json");
    assert_eq!(v["weights"][0], "1/2");
    assert_eq!(v["weights"][1], "2/25");
    assert_eq!(v["weights"][6], "1/50");
    assert!(v["du"].is_null());
    assert!(v["note"].as_str().expect("note").contains("irrational"));
    let v = json("stencil --scheme catmull-clark --valence 5 --u 0 --v 0 --f64 --json");
    assert!(v["du"].as_array().expect("f64 tangents").len() == 18);
}

/// A dart's patches (`--dart --sector S`): at the dart the position is the left eigenvector of
/// `A` (zero beyond the one-ring), the same in every sector; sector 0's crease point at
/// `u = 1` is the crease rule's limit `(V + 4 E_1 + (2, 0)) / 6` of a regular crease vertex
/// (the cubic B-spline of the crease polygon at a knot).
#[test]
fn stencil_at_a_dart() {
    let v = json("stencil --scheme catmull-clark --valence 4 --dart --sector 0 --u 1 --v 0 --json");
    assert_eq!(v["dart"], true);
    assert_eq!(v["weights"][0], "1/6");
    assert_eq!(v["weights"][1], "2/3");
    // O2 = (2, 0), the crease's next point.
    assert_eq!(v["order"][10], "O2");
    assert_eq!(v["weights"][10], "1/6");
    let at_dart = |sector: u32| {
        json(&format!(
            "stencil --scheme catmull-clark --valence 5 --dart --sector {sector} --u 0 --v 0 --json"
        ))
    };
    let (a, b) = (at_dart(0), at_dart(2));
    assert_eq!(a["weights"], b["weights"]);
    let beyond_the_ring = &a["weights"].as_array().expect("weights")[11..];
    assert!(beyond_the_ring.iter().all(|w| w == "0"));
    fails_with(
        "stencil --scheme catmull-clark --valence 5 --sector 1 --u 0 --v 0",
        "--sector needs --boundary or --dart",
    );
    fails_with(
        "stencil --scheme sw-nonpoly-quad --valence 5 --dart --u 0 --v 0",
        "crease",
    );
}

#[test]
fn stencil_bad_input() {
    let cases: [(&str, &str); 4] = [
        (
            "stencil --scheme catmull-clark --valence 5 --u 3/2 --v 0",
            "outside the patch",
        ),
        (
            "stencil --scheme catmull-clark --valence 5 --u 1/0 --v 0",
            "denominator is 0",
        ),
        (
            "stencil --scheme catmull-clark --valence 2 --u 0 --v 0",
            "2 is not in 3..=64",
        ),
        (
            "stencil --scheme no-such-scheme --valence 5 --u 0 --v 0",
            "unknown scheme `no-such-scheme`",
        ),
    ];
    for (args, message) in cases {
        fails_with(args, message);
    }
}

/// Run `tables ARGS -o FILE` (a temporary file named after `name`), which must succeed, and
/// read the table it wrote back.
fn written_table(name: &str, args: &str) -> table_format::TableIndex {
    let path = std::env::temp_dir().join(format!(
        "stencilgen-cli-{name}-{}.subtess",
        std::process::id()
    ));
    let out = stencilgen(&format!("tables {args} -o {}", path.display()));
    assert!(
        out.status.success(),
        "{args}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = table_format::AlignedBytes::read(&path).expect("written");
    let _ = std::fs::remove_file(&path);
    table_format::Table::parse(bytes.as_bytes())
        .expect("valid")
        .into_index()
}

#[test]
fn tables_writes_a_valid_table() {
    let table = written_table("quad", "--valences 3,5 --n 1..2 --precision f64");
    assert_eq!(table.meta.precision, table_format::Precision::F64);
    // Compact: 2 rates x 2 curve-basis sections, 2 interior patches and, by default, the darts
    // of the same valences, every sector (3 + 5), x 5 pieces.
    assert_eq!(table.entries.len(), 2 * 2 + (2 + 8) * 5);
    assert_eq!(
        table.coverage(),
        "interior valences 3, 5, darts of valences 3, 5, no boundary vertices, n = 1..=2"
    );
    // --grids: every grid, 10 patches x 2 rates x 3 kinds x 2 point sets, f32 by default.
    let table = written_table("quad", "--valences 3,5 --n 1..2 --grids");
    assert_eq!(table.meta.precision, table_format::Precision::F32);
    assert_eq!(table.entries.len(), (2 + 8) * 2 * 3 * 2);
    // --darts chooses the darts' valences, or none.
    let table = written_table("quad", "--valences 3,5 --darts 4 --n 1");
    assert_eq!(table.entries.len(), 2 + (2 + 4) * 5);
    let table = written_table("quad", "--valences 3,5 --darts none --n 1");
    assert_eq!(table.entries.len(), 2 + 2 * 5);
    // A scheme without crease rules has no darts unless asked, and then refuses them.
    let table = written_table("quad", "--schemes sw-nonpoly-quad --valences 3 --n 1");
    assert_eq!(table.entries.len(), 2 + 5);
    fails_with(
        "tables --schemes loop --valences 5 --darts 5 --n 1 -o /tmp/x.subtess",
        "darts are implemented for quad schemes only",
    );
    fails_with(
        "tables --valences 3 --n 1 --precision f32 -o /tmp/x.subtess",
        "compact tables store f64",
    );
    fails_with(
        "tables --valences 8..3 -o /tmp/x.subtess",
        "--valences `8..3`",
    );
}

/// `tables --schemes loop` writes a compact table (f64), `--grids` the grids (f32).
#[test]
fn tables_writes_compact_and_grid_loop_tables() {
    let loop_table = "--schemes loop --valences 5 --boundary --boundary-faces 2 --n 1..3";
    let compact = written_table("loop", loop_table);
    assert_eq!(compact.meta.precision, table_format::Precision::F64);
    // 3 basis kinds, 3 rate markers, 3 patches (valence 5, two boundary sectors) x 5 pieces.
    assert_eq!(compact.entries.len(), 3 + 3 + 3 * 5);
    assert_eq!(
        compact.coverage(),
        "interior valences 5, boundary vertices with 2 faces, n = 1..=3"
    );
    let grids = written_table("loop", &format!("{loop_table} --grids"));
    assert_eq!(grids.meta.precision, table_format::Precision::F32);
    // 3 patches x 3 rates x 3 kinds x 2 point sets.
    assert_eq!(grids.entries.len(), 3 * 3 * 3 * 2);
    assert_eq!(grids.coverage(), compact.coverage());
    fails_with(
        "tables --schemes loop --valences 5 --n 1 --precision f32 -o /tmp/x.subtess",
        "compact tables store f64",
    );
}

#[test]
fn triangle_json_lists_the_support_grid() {
    let v = json("triangle --scheme loop --n 2 --json");
    assert_eq!(v["scheme"], "loop");
    assert_eq!(v["dilation"], 2);
    assert_eq!(v["support"].as_array().map(Vec::len), Some(6));
    let points = v["points"].as_array().expect("points");
    let values = v["values"].as_array().expect("values");
    assert_eq!(points.len(), values.len());
    // Hexagon of radius 4 in half steps: 3 * 4 * 5 + 1 = 61 grid points.
    assert_eq!(points.len(), 61);
    let centre = points
        .iter()
        .position(|p| p == &serde_json::json!(["0", "0"]))
        .expect("the origin");
    // Loop's limit position rule at valence 6: 1/2 at the vertex.
    assert_eq!(values[centre], "1/2");
    let f = json("triangle --scheme sqrt3 --n 2 --f64 --json");
    assert!(f["values"][0].is_number());
    assert!(f["residual"].as_f64().expect("residual") < 1e-12);
    fails_with("triangle --scheme loopy --n 2", "unknown scheme `loopy`");
}

#[test]
fn loop_stencil_at_an_extraordinary_vertex() {
    // Loop's limit rule with Warren's beta = 3/40 at valence 5: chi = 1/(3/(8 beta) + 5) = 1/10.
    let v = json("stencil --scheme loop --valence 5 --u 0 --v 0 --json");
    assert_eq!(v["order"].as_array().map(Vec::len), Some(11));
    assert_eq!(v["weights"][0], "1/2");
    assert_eq!(v["weights"][1], "1/10");
    assert_eq!(v["weights"][6], "0");
    assert!(v["du"].is_null() && v["note"].is_string());
    let f = json("stencil --scheme loop --valence 5 --u 0 --v 0 --f64 --json");
    assert_eq!(f["du"].as_array().map(Vec::len), Some(11));
    let away = json("stencil --scheme loop --valence 5 --u 1/3 --v 1/6 --json");
    assert_eq!(away["dv"].as_array().map(Vec::len), Some(11));
    let inner = json("stencil --scheme loop --valence 7 --u 1/3 --v 1/5 --f64 --json");
    let sum: f64 = inner["weights"]
        .as_array()
        .map(|w| w.iter().filter_map(serde_json::Value::as_f64).sum())
        .unwrap_or(0.0);
    assert!((sum - 1.0).abs() < 1e-12);
    fails_with(
        "stencil --scheme loop --valence 5 --u 2/3 --v 2/3",
        "outside the patch",
    );
    fails_with(
        "stencil --scheme loop-original --valence 5 --u 1/3 --v 0",
        "irrational",
    );
    fails_with(
        "stencil --scheme butterfly --valence 5 --u 1/3 --v 0",
        "irrational",
    );
    fails_with(
        "stencil --scheme loop --boundary 3 --valence 5 --u 1/3 --v 0",
        "cannot be used with",
    );
    fails_with(
        "stencil --scheme loop --boundary 2 --sector 2 --u 1/3 --v 0",
        "sectors 0..2",
    );
}

#[test]
fn butterfly_stencil_next_to_an_extraordinary_vertex() {
    // The midpoint of the edge V E_0 is the extraordinary edge rule itself (Zorin, Schroeder,
    // Sweldens 1996): 3/4 V + sum s_j E_j, s_j = (1/4 + cos(2 pi j/K) + cos(4 pi j/K)/2) / K.
    let k = 5;
    let out = json(&format!(
        "stencil --scheme butterfly --valence {k} --u 1/2 --v 0 --f64 --json"
    ));
    let w: Vec<f64> = out["weights"]
        .as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
        .unwrap_or_default();
    assert!((w[0] - 0.75).abs() < 1e-12, "{w:?}");
    for j in 0..k {
        let t = 2.0 * std::f64::consts::PI * j as f64 / k as f64;
        let s = (0.25 + t.cos() + 0.5 * (2.0 * t).cos()) / k as f64;
        assert!((w[1 + j] - s).abs() < 1e-12, "s_{j}: {} vs {s}", w[1 + j]);
    }
    assert!(w[1 + k..].iter().all(|x| x.abs() < 1e-12));
    // Rational at valence 4: exact, and interpolating at the vertex.
    let exact = json("stencil --scheme butterfly --valence 4 --u 0 --v 0 --json");
    assert_eq!(exact["weights"][0], "1");
    // The tangents at the vertex, by hand: the one-ring block of A is closed (the edge points
    // at V read only V and its ring), its Fourier mode 1 has eigenvalue 1/2 with left vectors
    // cos, sin (2 pi j/K) on E_j and 0 at V, right vectors the same on the ring. Normalized
    // (l.r = 1), D_u = (e_E0 - e_V) P puts (2/K) cos(2 pi j/K) on E_j and D_v = (e_E1 - e_V) P
    // puts (2/K) cos(2 pi (j - 1)/K): at K = 4, (1/2, 0, -1/2, 0) and (0, 1/2, 0, -1/2).
    let strings = |key: &str| -> Vec<String> {
        exact[key]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|x| x.as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default()
    };
    let (du, dv) = (strings("du"), strings("dv"));
    assert_eq!(&du[..5], ["0", "1/2", "0", "-1/2", "0"], "{du:?}");
    assert_eq!(&dv[..5], ["0", "0", "1/2", "0", "-1/2"], "{dv:?}");
    assert!(du[5..].iter().chain(&dv[5..]).all(|x| x == "0"));
    let f = json("stencil --scheme butterfly --valence 7 --u 0 --v 0 --f64 --json");
    let floats = |key: &str| -> Vec<f64> {
        f[key]
            .as_array()
            .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
            .unwrap_or_default()
    };
    for j in 0..7 {
        let t = 2.0 * std::f64::consts::PI * j as f64 / 7.0;
        let du = floats("du")[1 + j];
        let dv = floats("dv")[1 + j];
        assert!((du - 2.0 / 7.0 * t.cos()).abs() < 1e-9, "du E_{j}: {du}");
        let t1 = 2.0 * std::f64::consts::PI * (j as f64 - 1.0) / 7.0;
        assert!((dv - 2.0 / 7.0 * t1.cos()).abs() < 1e-9, "dv E_{j}: {dv}");
    }
}

#[test]
fn loop_stencil_next_to_a_boundary_vertex() {
    // At the vertex: the cubic B-spline curve's limit (E_0 + 4 V + E_k) / 6, whatever k is.
    let at = json("stencil --scheme loop --boundary 4 --sector 2 --u 0 --v 0 --json");
    let order: Vec<&str> = at["order"]
        .as_array()
        .map(|o| o.iter().filter_map(serde_json::Value::as_str).collect())
        .unwrap_or_default();
    assert_eq!(&order[..6], ["V", "E0", "E1", "E2", "E3", "E4"]);
    assert_eq!(at["weights"][0], "2/3");
    assert_eq!(at["weights"][1], "1/6");
    assert_eq!(at["weights"][5], "1/6");
    assert_eq!(at["weights"][3], "0");
    assert_eq!(
        (at["faces"].as_u64(), at["sector"].as_u64()),
        (Some(4), Some(2))
    );
    // Along the boundary edge of sector 0 only boundary points count: V, E0 and the point
    // beyond E0 (O1), the cubic B-spline at t = 1/2 between V and E0: 1/48, 23/48, 23/48, 1/48
    // with the fourth point (E_k) at the other end.
    let edge = json("stencil --scheme loop --boundary 2 --sector 0 --u 1/2 --v 0 --json");
    let names: Vec<&str> = edge["order"]
        .as_array()
        .map(|o| o.iter().filter_map(serde_json::Value::as_str).collect())
        .unwrap_or_default();
    let weight = |name: &str| {
        let i = names.iter().position(|n| *n == name).expect("named");
        edge["weights"][i]
            .as_str()
            .map(str::to_owned)
            .unwrap_or_default()
    };
    assert_eq!(weight("V"), "23/48");
    assert_eq!(weight("E0"), "23/48");
    assert_eq!(weight("E2"), "1/48");
    assert_eq!(weight("O1"), "1/48");
    assert_eq!(weight("E1"), "0");
}

/// `stencilgen tables` bounds what it is asked for before making anything: a rate list of
/// four billion entries, valences beyond 64, or a table beyond the format's 4 GiB are refused
/// at once, with nothing written.
#[test]
fn tables_refuse_what_they_cannot_hold() {
    let out =
        std::env::temp_dir().join(format!("stencilgen-budget-{}.subtess", std::process::id()));
    let o = out.display();
    fails_with(
        &format!("tables --n 1..4000000000 -o {o}"),
        "integers in 1..=1024",
    );
    fails_with(
        &format!("tables --valences 3..100000 -o {o}"),
        "integers in 1..=64",
    );
    fails_with(
        &format!("tables --valences 3..64 --n 1..1024 -o {o}"),
        "GiB, more than the format's 4 GiB",
    );
    let long = "9".repeat(100_000);
    let out_put = stencilgen(&format!("tables --n {long} -o {o}"));
    let stderr = String::from_utf8_lossy(&out_put.stderr);
    assert!(
        !out_put.status.success() && stderr.len() < 600,
        "{}",
        stderr.len()
    );
    assert!(!out.exists(), "nothing written");
}

/// `stencil`'s rational `--u`/`--v` are bounded as subtess's `eval` parameters are (issue 20):
/// at most 64 characters, checked before parsing (a 100,000-digit denominator is refused at
/// once, quoted short), and a numerator and denominator of at most 64 bits in lowest terms.
#[test]
fn stencil_rationals_are_bounded() {
    let started = std::time::Instant::now();
    let long = format!("1/1{}", "0".repeat(100_000));
    let out = stencilgen(&format!(
        "stencil --scheme catmull-clark --valence 5 --u {long} --v 0"
    ));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a 100,003-character --u succeeded");
    assert!(stderr.contains("100003 characters"), "{stderr}");
    assert!(stderr.len() < 600, "{} bytes of message", stderr.len());
    assert!(started.elapsed().as_secs() < 5, "{:?}", started.elapsed());
    fails_with(
        "stencil --scheme catmull-clark --valence 5 --u 0 --v 1/36893488147419103232",
        "more than 64 bits",
    );
    // 2^63 is the largest power of two a 64-bit denominator holds.
    let finest =
        json("stencil --scheme catmull-clark --valence 5 --u 1/9223372036854775808 --v 0 --json");
    assert_eq!(finest["u"], "1/9223372036854775808");
}
