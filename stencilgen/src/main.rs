//! `stencilgen`: evaluation stencils from the scaling relation, on the command line.
//!
//! `stencilgen curve --scheme NAME --n N [--derivative] [--f64] [--json]` prints the values of
//! a curve scheme's basis function(s) (or their derivatives) on the grid `(1/n) Z`; see
//! `docs/cli.md` for the JSON layout.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use num_rational::BigRational;
use schemes::curve::CURVE_SCHEME_NAMES;
use schemes::CurveScheme;
use serde_json::{json, Value};
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
    /// List the curve schemes.
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
            for name in CURVE_SCHEME_NAMES {
                if let Some(scheme) = CurveScheme::by_name(name) {
                    println!("{name:<26} {}", scheme.description);
                }
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
