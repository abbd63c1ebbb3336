//! `stencilgen`: evaluation stencils from the scaling relation, on the command line.
//!
//! `stencilgen curve --scheme NAME --n N [--derivative] [--f64] [--json]` prints the values of
//! a curve scheme's basis function(s) (or their derivatives) on the grid `(1/n) Z`;
//! `stencilgen stencil --scheme S --valence V --u p/q --v p/q [--f64] [--json]` the stencil of
//! the patch next to an extraordinary vertex. See `docs/cli.md` for the JSON layouts.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use num_rational::BigRational;
use schemes::curve::CURVE_SCHEME_NAMES;
use schemes::quad::QUAD_SCHEME_NAMES;
use schemes::{BoundaryMode, CurveScheme, QuadScheme};
use serde_json::{json, Value};
use stencilgen::extraordinary_patch::{canonical, Neighbourhood, OUTER_POINTS};
use stencilgen::rational::parse_rational;
use stencilgen::regular_patch::StencilKind;
use stencilgen::substitution::Substitution;
use stencilgen::{curve_stencils, CurveStencils, Scalar, StencilError};

#[derive(Parser)]
#[command(
    name = "stencilgen",
    version,
    about = "Exact evaluation stencils from subdivision scaling relations"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Basis-function values (or derivatives) of a curve scheme on the grid (1/n)Z.
    Curve {
        /// Scheme name (see `stencilgen schemes`).
        #[arg(long)]
        scheme: String,
        /// Grid rate: values at x = -m, -m + 1/n, ..., m.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(stencilgen::curve_stencils::MAX_RATE)))]
        n: u32,
        /// Tangent masks: values of phi' instead of phi (Schaefer-Warren section 4).
        #[arg(long)]
        derivative: bool,
        /// Solve in f64 (SVD least squares) instead of exact rationals.
        #[arg(long = "f64")]
        float: bool,
        /// Print JSON (exact values as "p/q" strings, f64 values as numbers).
        #[arg(long)]
        json: bool,
    },
    /// Stencil of the patch next to an extraordinary vertex at a rational (u, v).
    Stencil {
        /// Quad scheme name (catmull-clark, sw-nonpoly-quad).
        #[arg(long)]
        scheme: String,
        /// Valence of the (interior) extraordinary vertex at (0, 0).
        #[arg(long, value_parser = clap::value_parser!(u32).range(3..=64), required_unless_present = "boundary", conflicts_with = "boundary")]
        valence: Option<u32>,
        /// The vertex at (0, 0) is a boundary vertex with this many faces.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
        boundary: Option<u32>,
        /// Which of the boundary vertex's patches: 0 has the boundary along u = 0..1, v = 0.
        #[arg(long, default_value_t = 0, requires = "boundary")]
        sector: u32,
        /// A boundary vertex with one face is a pinned corner (OpenSubdiv "edge and corner").
        #[arg(long, requires = "boundary")]
        corners: bool,
        /// u in [0, 1], as p/q.
        #[arg(long, allow_hyphen_values = true)]
        u: String,
        /// v in [0, 1], as p/q.
        #[arg(long, allow_hyphen_values = true)]
        v: String,
        /// Weights in f64 (and the EV's irrational tangent masks).
        #[arg(long = "f64")]
        float: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// List the schemes.
    Schemes,
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), StencilError> {
    match cli.command {
        Command::Schemes => {
            println!("curve schemes (stencilgen curve):");
            for name in CURVE_SCHEME_NAMES {
                if let Some(scheme) = CurveScheme::by_name(name) {
                    println!("  {name:<26} {}", scheme.description);
                }
            }
            println!("quad schemes (stencilgen stencil):");
            for name in QUAD_SCHEME_NAMES {
                if let Some(scheme) = QuadScheme::by_name(name) {
                    println!("  {name:<26} {}", scheme.description);
                }
            }
            Ok(())
        }
        Command::Stencil {
            scheme,
            valence,
            boundary,
            sector,
            corners,
            u,
            v,
            float,
            json,
        } => {
            let scheme =
                QuadScheme::by_name(&scheme).ok_or_else(|| StencilError::UnknownScheme {
                    name: scheme.clone(),
                    known: QUAD_SCHEME_NAMES.join(", "),
                })?;
            let (u, v) = (parse_rational(&u)?, parse_rational(&v)?);
            let mode = if corners {
                BoundaryMode::EdgeAndCorner
            } else {
                BoundaryMode::EdgeOnly
            };
            let nb = match (valence, boundary) {
                (_, Some(faces)) => Neighbourhood::boundary(faces, mode),
                (Some(v), None) => Neighbourhood::interior(v),
                (None, None) => unreachable!("clap requires --valence or --boundary"),
            };
            let out = if float {
                stencil_json::<f64>(&scheme, nb, sector, &u, &v, |x| json!(x))?
            } else {
                stencil_json::<BigRational>(&scheme, nb, sector, &u, &v, |x| json!(x.to_string()))?
            };
            if json {
                println!("{out}");
            } else {
                println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
            }
            Ok(())
        }
        Command::Curve {
            scheme,
            n,
            derivative,
            float,
            json,
        } => {
            let scheme =
                CurveScheme::by_name(&scheme).ok_or_else(|| StencilError::UnknownScheme {
                    name: scheme.clone(),
                    known: CURVE_SCHEME_NAMES.join(", "),
                })?;
            if float {
                let stencils = curve_stencils::<f64>(&scheme, n, derivative)?;
                print(&stencils, json, |v| json!(v));
            } else {
                let stencils = curve_stencils::<BigRational>(&scheme, n, derivative)?;
                print(&stencils, json, |v| json!(v.to_string()));
            }
            Ok(())
        }
    }
}

/// `{"weights","du","dv"}` (DESIGN.md / issue contract) plus what they mean: the scheme,
/// valence, point and the control-point order. Tangents that exact arithmetic cannot give
/// (at the EV itself) are `null`, with the reason in `"note"`.
fn stencil_json<S: Scalar>(
    scheme: &QuadScheme,
    nb: Neighbourhood,
    sector: u32,
    u: &BigRational,
    v: &BigRational,
    value: impl Fn(&S) -> Value,
) -> Result<Value, StencilError> {
    let mut substitution = Substitution::<S>::new(scheme, nb, sector)?;
    let weights = substitution.stencil(u, v, StencilKind::Position)?;
    let mut out = json!({
        "scheme": scheme.name,
        "valence": nb.faces,
        "boundary": nb.boundary.is_some(),
        "sector": sector,
        "u": u.to_string(),
        "v": v.to_string(),
        "exact": S::EXACT,
        "order": layout_names(nb, sector),
        "weights": weights.iter().map(&value).collect::<Vec<_>>(),
    });
    for (key, kind) in [
        ("du", StencilKind::DerivativeU),
        ("dv", StencilKind::DerivativeV),
    ] {
        match substitution.stencil(u, v, kind) {
            Ok(mask) => out[key] = mask.iter().map(&value).collect(),
            Err(e @ StencilError::Irrational { .. }) => {
                out[key] = Value::Null;
                out["note"] = json!(e.to_string());
            }
            Err(e) => return Err(e),
        }
    }
    Ok(out)
}

/// Names of the layout's control points: `V`, `E1..`, `F1..`, and the outer points `O1..O7`
/// that exist.
fn layout_names(nb: Neighbourhood, sector: u32) -> Vec<String> {
    let mut names = vec!["V".to_owned()];
    names.extend((1..=nb.edges()).map(|i| format!("E{i}")));
    names.extend((1..=nb.faces).map(|i| format!("F{i}")));
    names.extend(
        OUTER_POINTS
            .iter()
            .enumerate()
            .filter(|(_, &(a, b))| canonical(nb, i64::from(sector), a, b).is_some())
            .map(|(i, _)| format!("O{}", i + 1)),
    );
    names
}

fn print<S: Scalar + std::fmt::Display>(
    stencils: &CurveStencils<S>,
    as_json: bool,
    value: impl Fn(&S) -> Value,
) {
    if as_json {
        println!("{}", to_json(stencils, value));
        return;
    }
    let what = if stencils.derivative { "phi'" } else { "phi" };
    for f in &stencils.functions {
        if stencils.functions.len() > 1 {
            println!("# component {}", f.name);
        }
        for (x, v) in f.grid().iter().zip(&f.values) {
            println!("{what}({x}) = {v}");
        }
    }
    if !S::EXACT {
        println!("# largest residual {:e}", stencils.residual);
    }
}

/// The JSON of DESIGN.md: `{"scheme","n","support","x","values"}` for a uniform scheme; a
/// vector scheme lists its components under `"functions"` with the same fields.
fn to_json<S: Scalar>(stencils: &CurveStencils<S>, value: impl Fn(&S) -> Value) -> Value {
    let function = |f: &stencilgen::BasisFunction<S>| {
        json!({
            "name": f.name,
            "support": [f.support.0, f.support.1],
            "x": f.grid().iter().map(|x| x.to_string()).collect::<Vec<_>>(),
            "values": f.values.iter().map(&value).collect::<Vec<_>>(),
        })
    };
    let mut out = json!({
        "scheme": stencils.scheme,
        "n": stencils.n,
        "derivative": stencils.derivative,
        "exact": S::EXACT,
    });
    if let [single] = stencils.functions.as_slice() {
        for (k, v) in function(single).as_object().into_iter().flatten() {
            if k != "name" {
                out[k] = v.clone();
            }
        }
    } else {
        out["functions"] = stencils.functions.iter().map(function).collect();
    }
    if !S::EXACT {
        out["residual"] = json!(stencils.residual);
    }
    out
}
