//! `stencilgen stencil --scheme sqrt3`: √3's patch next to an interior extraordinary vertex,
//! on the command line (docs/cli.md).

use std::process::{Command, Output};

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::One;

fn stencilgen(args: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stencilgen"))
        .args(args.split_whitespace())
        .output()
        .expect("stencilgen runs")
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

fn fails_with(args: &str, message: &str) {
    let out = stencilgen(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(out.status.code().is_some(), "{args:?} was killed");
    assert!(stderr.contains(message), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
        .unwrap_or_default()
}

fn rationals(v: &serde_json::Value) -> Vec<BigRational> {
    v.as_array()
        .map(|a| {
            a.iter()
                .filter_map(serde_json::Value::as_str)
                .map(|s| s.parse::<BigRational>().expect("p/q"))
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn sqrt3_limit_position_is_kobbelts_rule() {
    // Kobbelt (2000): V_inf = (1 - b) V + (b/K) sum E_s with b = 3 a / (1 + 3 a),
    // a = (4 - 2 cos(2 pi/K))/9.
    let k = 5;
    let out = json(&format!(
        "stencil --scheme sqrt3 --valence {k} --u 0 --v 0 --f64 --json"
    ));
    assert_eq!(out["order"].as_array().map(Vec::len), Some(3 * k + 9));
    assert_eq!(out["order"][0], "V");
    assert_eq!(out["order"][1], "(1,0)_0");
    let w = numbers(&out["weights"]);
    let a = (4.0 - 2.0 * (2.0 * std::f64::consts::PI / k as f64).cos()) / 9.0;
    let b = 3.0 * a / (1.0 + 3.0 * a);
    assert!((w[0] - (1.0 - b)).abs() < 1e-12, "{w:?}");
    for x in &w[1..=k] {
        assert!((x - b / k as f64).abs() < 1e-12, "{w:?}");
    }
    assert!(w[k + 1..].iter().all(|x| x.abs() < 1e-12));
    // At V the derivative rows are tangent masks (a note says so): they sum to 0.
    assert!(out["note"].is_string());
    assert!(numbers(&out["du"]).iter().sum::<f64>().abs() < 1e-12);
    // Valence 4: a = 4/9, b = 4/7.
    let exact = json("stencil --scheme sqrt3 --valence 4 --u 0 --v 0 --json");
    assert_eq!(exact["weights"][0], "3/7");
    assert_eq!(exact["weights"][1], "1/7");
    assert_eq!(exact["weights"][5], "0");
}

#[test]
fn sqrt3_edge_midpoint_at_valence_six_has_the_papers_normalization_2256() {
    // Schaefer–Warren Fig. 4: the stencil at the midpoint of an edge of the regular mesh has
    // the implicit normalization 2256. At valence 6 the EV patch is a regular face.
    let out = json("stencil --scheme sqrt3 --valence 6 --u 1/2 --v 0 --json");
    let w = rationals(&out["weights"]);
    let lcm = w.iter().fold(BigInt::one(), |acc, x| acc.lcm(x.denom()));
    assert_eq!(lcm, BigInt::from(2256));
    assert_eq!(w.iter().sum::<BigRational>(), BigRational::one());
}

#[test]
fn sqrt3_errors() {
    fails_with(
        "stencil --scheme sqrt3 --valence 5 --u 1/3 --v 0",
        "irrational",
    );
    fails_with(
        "stencil --scheme sqrt3 --boundary 3 --u 1/3 --v 0",
        "pass --f64",
    );
    fails_with(
        "stencil --scheme sqrt3 --boundary 2 --sector 2 --u 1/3 --v 0 --f64",
        "sectors 0..2",
    );
    fails_with(
        "stencil --scheme sqrt3 --valence 4 --u 2/3 --v 2/3",
        "outside the patch",
    );
}

#[test]
fn sqrt3_derivatives_are_central_differences_of_positions() {
    // d/du at (1/2, 1/4), K = 5, against (p(u + h) - p(u - h)) / 2h of the CLI's own positions,
    // h = 1/12 (psi is C^1 with a Hölder derivative: about 1e-2, a wrong factor is O(1)).
    let at = |u: &str, v: &str| {
        json(&format!(
            "stencil --scheme sqrt3 --valence 5 --u {u} --v {v} --f64 --json"
        ))
    };
    let mid = at("1/2", "1/4");
    let du = numbers(&mid["du"]);
    assert!(du.iter().sum::<f64>().abs() < 1e-10);
    let (plus, minus) = (
        numbers(&at("7/12", "1/4")["weights"]),
        numbers(&at("5/12", "1/4")["weights"]),
    );
    for ((d, p), m) in du.iter().zip(&plus).zip(&minus) {
        assert!((d - (p - m) * 6.0).abs() < 2e-2, "{d} vs {}", (p - m) * 6.0);
    }
}

/// Next to a boundary vertex (Kobbelt's boundary rules, `--boundary F --sector S`, f64): on the
/// boundary edge `v = 0` of sector 0 the position is the uniform cubic B-spline of the boundary
/// polygon `E_F, V, E_0, (2,0)_0` (closed form: `(1, 23, 23, 1) / 48` at `u = 1/2`, `(1, 4, 1) / 6`
/// at `V`), the derivative along the edge its derivative `(-1, -5, 5, 1) / 8`, and the
/// derivative across it is refused with a note; at `V` the derivatives are tangent masks (a
/// note says so; they sum to 0); inside, positions sum to 1 and derivatives to 0.
#[test]
fn sqrt3_boundary_stencils_are_the_b_spline_on_the_boundary() {
    let out = json("stencil --scheme sqrt3 --boundary 2 --sector 0 --u 1/2 --v 0 --f64 --json");
    let order = out["order"].as_array().expect("order").clone();
    let weight = |name: [i64; 3], key: &str| -> f64 {
        let i = order
            .iter()
            .position(|p| {
                p.as_array()
                    .map(|a| a.iter().map(|x| x.as_i64()).collect::<Vec<_>>())
                    == Some(name.iter().map(|&x| Some(x)).collect())
            })
            .unwrap_or_else(|| panic!("{name:?} in {order:?}"));
        out[key][i].as_f64().expect("a number")
    };
    for (name, w, dw) in [
        ([2, 1, 0], 1.0, -1.0),
        ([0, 0, 0], 23.0, -5.0),
        ([0, 1, 0], 23.0, 5.0),
        ([0, 2, 0], 1.0, 1.0),
    ] {
        assert!(
            (weight(name, "weights") - w / 48.0).abs() < 1e-15,
            "{name:?}"
        );
        assert!((weight(name, "du") - dw / 8.0).abs() < 1e-15, "{name:?}");
    }
    assert!(out["dv"].is_null() && out["note"].as_str().is_some_and(|n| n.contains("across")));
    let vertex = json("stencil --scheme sqrt3 --boundary 4 --sector 2 --u 0 --v 0 --f64 --json");
    assert!(vertex["note"]
        .as_str()
        .is_some_and(|n| n.contains("tangent masks")));
    assert!(numbers(&vertex["du"]).iter().sum::<f64>().abs() < 1e-12);
    let w: Vec<f64> = numbers(&vertex["weights"])
        .into_iter()
        .filter(|&x| x != 0.0)
        .collect();
    assert_eq!(w.len(), 3);
    let mut sorted = w.clone();
    sorted.sort_by(f64::total_cmp);
    for (x, want) in sorted.iter().zip([1.0 / 6.0, 1.0 / 6.0, 4.0 / 6.0]) {
        assert!((x - want).abs() < 1e-15, "{w:?}");
    }
    let inside =
        json("stencil --scheme sqrt3 --boundary 5 --sector 4 --u 1/4 --v 1/3 --f64 --json");
    let sum = |key: &str| numbers(&inside[key]).iter().sum::<f64>();
    assert!((sum("weights") - 1.0).abs() < 1e-12);
    assert!(sum("du").abs() < 1e-10 && sum("dv").abs() < 1e-10);
}
