//! `stencilgen`: evaluation stencils from the scaling relation, on the command line.
//!
//! `stencilgen curve --scheme NAME --n N [--derivative] [--f64] [--json]` prints the values of
//! a curve scheme's basis function(s) (or their derivatives) on the grid `(1/n) Z`;
//! `stencilgen stencil --scheme S --valence V --u p/q --v p/q [--f64] [--json]` the stencil of
//! the patch next to an extraordinary vertex (quad schemes, Loop, the butterfly and √3); `stencilgen triangle --scheme S --n N` the regular
//! basis function of a triangle scheme on `(1/n) Z^2`. See `docs/cli.md` for the JSON layouts.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};
use schemes::curve::CURVE_SCHEME_NAMES;
use schemes::quad::QUAD_SCHEME_NAMES;
use schemes::sqrt3_boundary::FanPoint;
use schemes::triangle::TRIANGLE_SCHEME_NAMES;
use schemes::{BoundaryMode, CurveScheme, QuadScheme, TriangleScheme};
use serde_json::{json, Value};
use stencilgen::butterfly_regions::ButterflyRegionSubstitution;
use stencilgen::butterfly_table::{build_butterfly_table, ButterflyTableSpec};
use stencilgen::extraordinary_patch::{canonical, Neighbourhood, OUTER_POINTS};
use stencilgen::patch_stencils::{curve_scheme, quad_scheme};
use stencilgen::rational::parse_rational;
use stencilgen::region_table::RegionLayout;
use stencilgen::regular_patch::StencilKind;
use stencilgen::sqrt3_fan_tangents::sqrt3_fan_tangents;
use stencilgen::sqrt3_patch::Sqrt3Substitution;
use stencilgen::sqrt3_regions::Sqrt3RegionSubstitution;
use stencilgen::sqrt3_strip::{self, derivative, FanStencil};
use stencilgen::sqrt3_table::{build_sqrt3_table, Sqrt3TableSpec};
use stencilgen::stencil_set::StencilSetSpec;
use stencilgen::substitution::Substitution;
use stencilgen::table::{build_table, QuadLayout, TableSpec};
use stencilgen::triangle_patch::TriangleSubstitution;
use stencilgen::triangle_system::{triangle_stencils, TriangleStencils, MAX_BASIS_RATE};
use stencilgen::triangle_table::{build_triangle_table, TriangleLayout, TriangleTableSpec};
use stencilgen::{curve_stencils, excerpt, CurveStencils, Scalar, StencilError};
use table_format::Precision;

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
        /// Quad scheme name (catmull-clark, sw-nonpoly-quad), or a triangle scheme: `loop`
        /// (interior and boundary vertices), `butterfly` (interior vertices) or `sqrt3`
        /// (interior vertices; boundary vertices with `--f64`); (u, v) barycentric on the
        /// triangle V, E0, E1.
        #[arg(long)]
        scheme: String,
        /// Valence of the (interior) extraordinary vertex at (0, 0).
        #[arg(long, value_parser = clap::value_parser!(u32).range(3..=64), required_unless_present = "boundary", conflicts_with = "boundary")]
        valence: Option<u32>,
        /// The vertex at (0, 0) is a boundary vertex with this many faces.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
        boundary: Option<u32>,
        /// The interior vertex of --valence is a dart: one infinitely sharp edge, along sector
        /// 0's u axis, the crease continuing straight out (Catmull-Clark).
        #[arg(long, requires = "valence", conflicts_with = "boundary")]
        dart: bool,
        /// Which of the boundary vertex's (or dart's) patches: 0 has the boundary (the
        /// crease) along u = 0..1, v = 0.
        #[arg(long, default_value_t = 0)]
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
    /// Write a versioned binary stencil table (docs/table-format.md).
    Tables {
        /// Schemes, comma separated: quad schemes, `loop`, `butterfly` or `sqrt3` (one file each; with
        /// several, the scheme name is appended to the file stem).
        #[arg(long, default_value = "catmull-clark", value_delimiter = ',')]
        schemes: Vec<String>,
        /// Interior valences: a range `3..8` (inclusive) or a list `3,5,6`.
        #[arg(long, default_value = "3..8")]
        valences: String,
        /// Valences of darts (an interior vertex with one infinitely sharp edge; every sector),
        /// as a range or list, or `none`. Default: the interior valences for a quad scheme with
        /// crease rules (Catmull–Clark), none for the others.
        #[arg(long)]
        darts: Option<String>,
        /// Include boundary vertices (with --boundary-faces faces).
        #[arg(long)]
        boundary: bool,
        /// Face counts of the boundary vertices, as a range or list.
        #[arg(long, default_value = "1..6")]
        boundary_faces: String,
        /// One-face boundary vertices are pinned corners (OpenSubdiv "edge and corner").
        #[arg(long)]
        corners: bool,
        /// Grid rates, as a range or list.
        #[arg(long, default_value = "1..24")]
        n: String,
        /// Stored precision (default: f64 for compact tables, which store only f64; f32 for
        /// grids).
        #[arg(long, value_parser = ["f32", "f64"])]
        precision: Option<String>,
        /// Generate from exact rationals (slower) instead of the f64 path.
        #[arg(long)]
        exact: bool,
        /// Store every grid point's stencil (solved on the grid) instead of the scaling
        /// relation's pieces that the runtime expands (docs/table-format.md): the reference
        /// the compact tables are tested against.
        #[arg(long)]
        grids: bool,
        /// Output file.
        #[arg(short = 'o', long = "output")]
        output: std::path::PathBuf,
    },
    /// Regular basis-function values of a triangle scheme on the grid (1/n)Z^2 (skew lattice
    /// coordinates; Schaefer-Warren section 5.1).
    Triangle {
        /// Triangle scheme name (loop, loop-original, butterfly, sqrt3).
        #[arg(long)]
        scheme: String,
        /// Grid rate: values at the points k/n of the support.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(stencilgen::triangle_system::MAX_TRIANGLE_RATE)))]
        n: u32,
        /// Tangent masks: d/du (along (1,0)) or d/dv (along (0,1)) instead of values.
        #[arg(long, value_parser = ["u", "v"])]
        derivative: Option<String>,
        /// Solve in f64 (SVD least squares) instead of exact rationals.
        #[arg(long = "f64")]
        float: bool,
        /// Print JSON (exact values as "p/q" strings, f64 values as numbers).
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
            println!("triangle schemes (stencilgen triangle):");
            for name in TRIANGLE_SCHEME_NAMES {
                if let Some(scheme) = TriangleScheme::by_name(name) {
                    println!("  {name:<26} {}", scheme.description);
                }
            }
            Ok(())
        }
        Command::Triangle {
            scheme,
            n,
            derivative,
            float,
            json,
        } => {
            let scheme =
                TriangleScheme::by_name(&scheme).ok_or_else(|| StencilError::UnknownScheme {
                    name: scheme.clone(),
                    known: TRIANGLE_SCHEME_NAMES.join(", "),
                })?;
            let kind = match derivative.as_deref() {
                Some("u") => StencilKind::DerivativeU,
                Some("v") => StencilKind::DerivativeV,
                _ => StencilKind::Position,
            };
            let mask = scheme.regular_mask();
            let out = if float {
                let s = triangle_stencils::<f64>(&mask, n, kind)?;
                triangle_json(&s, |v| json!(v))
            } else {
                let s = triangle_stencils::<BigRational>(&mask, n, kind)?;
                triangle_json(&s, |v| json!(v.to_string()))
            };
            if json {
                println!("{out}");
            } else {
                let what = match kind {
                    StencilKind::Position => "phi",
                    StencilKind::DerivativeU => "d/du phi",
                    StencilKind::DerivativeV => "d/dv phi",
                };
                let points = out["points"].as_array().cloned().unwrap_or_default();
                let values = out["values"].as_array().cloned().unwrap_or_default();
                for (p, v) in points.iter().zip(&values) {
                    println!("{what}({}, {}) = {}", text(&p[0]), text(&p[1]), text(v));
                }
            }
            Ok(())
        }
        Command::Tables {
            schemes,
            valences,
            darts,
            boundary,
            boundary_faces,
            corners,
            n,
            precision,
            exact,
            grids,
            output,
        } => {
            let valences = parse_set("--valences", &valences, MAX_TABLE_VALENCE)?;
            // `None`: each scheme's default (below).
            let darts = match darts.as_deref() {
                None => None,
                Some("none") => Some(Vec::new()),
                Some(d) => Some(parse_set("--darts", d, MAX_TABLE_VALENCE)?),
            };
            let mut set = StencilSetSpec {
                darts: darts.clone().unwrap_or_else(|| valences.clone()),
                valences,
                boundary_faces: if boundary {
                    parse_set("--boundary-faces", &boundary_faces, MAX_TABLE_VALENCE)?
                } else {
                    Vec::new()
                },
                boundary_mode: if corners {
                    BoundaryMode::EdgeAndCorner
                } else {
                    BoundaryMode::EdgeOnly
                },
                rates: parse_set("--n", &n, stencilgen::curve_stencils::MAX_RATE)?,
            };
            check_table_size(&set)?;
            let layout = if grids {
                QuadLayout::Grids
            } else {
                QuadLayout::Compact
            };
            let region_layout = if grids {
                RegionLayout::Grids
            } else {
                RegionLayout::Compact
            };
            let precision_of = |compact: bool| match precision.as_deref() {
                Some("f64") => Precision::F64,
                Some(_) => Precision::F32,
                None if compact => Precision::F64,
                None => Precision::F32,
            };
            for name in &schemes {
                let path = if schemes.len() > 1 {
                    with_suffix(&output, name)
                } else {
                    output.clone()
                };
                if let Some(triangle) = TriangleScheme::by_name(name) {
                    if darts.as_ref().is_some_and(|d| !d.is_empty()) {
                        return Err(StencilError::UnsupportedScheme {
                            scheme: name.clone(),
                            reason: "darts are implemented for quad schemes only".to_owned(),
                        });
                    }
                    if corners {
                        return Err(StencilError::UnsupportedScheme {
                            scheme: name.clone(),
                            reason: "pinned corners are implemented for quad schemes only"
                                .to_owned(),
                        });
                    }
                    if exact {
                        return Err(StencilError::UnsupportedScheme {
                            scheme: name.clone(),
                            reason: "triangle tables are generated from the f64 path (the tests check it against exact substitution within 1e-12)".to_owned(),
                        });
                    }
                    let started = std::time::Instant::now();
                    if triangle.name == "butterfly" {
                        if boundary {
                            return Err(StencilError::UnsupportedScheme {
                                scheme: name.clone(),
                                reason: "the butterfly's boundary rules are not implemented"
                                    .to_owned(),
                            });
                        }
                        let spec = ButterflyTableSpec {
                            valences: set.valences.clone(),
                            rates: set.rates.clone(),
                            precision: precision_of(!grids),
                            layout: region_layout,
                        };
                        write_bytes(&path, &build_butterfly_table(&spec)?, started)?;
                        continue;
                    }
                    if triangle.name == "sqrt3" {
                        if boundary {
                            return Err(StencilError::UnsupportedScheme {
                                scheme: name.clone(),
                                reason: "sqrt3's boundary rules are not implemented".to_owned(),
                            });
                        }
                        let spec = Sqrt3TableSpec {
                            valences: set.valences.clone(),
                            rates: set.rates.clone(),
                            precision: precision_of(!grids),
                            layout: region_layout,
                        };
                        write_bytes(&path, &build_sqrt3_table(&spec)?, started)?;
                        continue;
                    }
                    let spec = TriangleTableSpec {
                        scheme: triangle,
                        valences: set.valences.clone(),
                        boundary_faces: set.boundary_faces.clone(),
                        rates: set.rates.clone(),
                        precision: precision_of(!grids),
                        layout: if grids {
                            TriangleLayout::Grids
                        } else {
                            TriangleLayout::Compact
                        },
                    };
                    let bytes = build_triangle_table(&spec)?;
                    write_bytes(&path, &bytes, started)?;
                    continue;
                }
                let scheme = quad_scheme(name)?;
                // A dart's crease takes the scheme's crease (boundary) rules: by default, darts
                // only where the scheme has them.
                set.darts = match &darts {
                    Some(d) => d.clone(),
                    None if scheme.boundary.is_some() => set.valences.clone(),
                    None => Vec::new(),
                };
                write_table(
                    TableSpec {
                        scheme,
                        set: set.clone(),
                        precision: precision_of(layout == QuadLayout::Compact),
                        exact,
                        layout,
                    },
                    &path,
                )?;
            }
            Ok(())
        }
        Command::Stencil {
            scheme,
            valence,
            boundary,
            dart,
            sector,
            corners,
            u,
            v,
            float,
            json,
        } => {
            let (u, v) = (parse_rational(&u)?, parse_rational(&v)?);
            if sector != 0 && boundary.is_none() && !dart {
                return Err(StencilError::UnsupportedScheme {
                    scheme,
                    reason: "--sector needs --boundary or --dart: an interior vertex's patches \
                             are all alike"
                        .to_owned(),
                });
            }
            if let Some(triangle) = TriangleScheme::by_name(&scheme) {
                if dart {
                    return Err(StencilError::UnsupportedScheme {
                        scheme,
                        reason: "darts are implemented for quad schemes only".to_owned(),
                    });
                }
                if corners {
                    return Err(StencilError::UnsupportedScheme {
                        scheme,
                        reason: "pinned corners are implemented for quad schemes only".to_owned(),
                    });
                }
                let patch = match (valence, boundary) {
                    (Some(v), None) => TrianglePatchChoice::Interior(v),
                    (None, Some(faces)) => TrianglePatchChoice::Boundary(faces, sector),
                    _ => {
                        return Err(StencilError::UnsupportedScheme {
                            scheme,
                            reason: "give either --valence V or --boundary FACES [--sector S]"
                                .to_owned(),
                        })
                    }
                };
                let out = if triangle.name == "butterfly" {
                    let TrianglePatchChoice::Interior(valence) = patch else {
                        return Err(StencilError::UnsupportedScheme {
                            scheme,
                            reason: "the butterfly has no boundary rules here; give --valence"
                                .to_owned(),
                        });
                    };
                    if float {
                        butterfly_stencil_json::<f64>(&triangle, valence, &u, &v, |x| json!(x))?
                    } else {
                        butterfly_stencil_json::<BigRational>(&triangle, valence, &u, &v, |x| {
                            json!(x.to_string())
                        })?
                    }
                } else if triangle.name == "sqrt3" {
                    let valence = match patch {
                        TrianglePatchChoice::Interior(valence) => valence,
                        TrianglePatchChoice::Boundary(faces, sector) => {
                            if !float {
                                return Err(StencilError::UnsupportedScheme {
                                    scheme,
                                    reason: "sqrt3's boundary stencils are f64 (a boundary \
                                             triangle's centre has valence 5: alpha_5 is \
                                             irrational); pass --f64"
                                        .to_owned(),
                                });
                            }
                            let out = sqrt3_boundary_stencil_json(faces, sector, &u, &v)?;
                            if json {
                                println!("{out}");
                            } else {
                                println!(
                                    "{}",
                                    serde_json::to_string_pretty(&out).unwrap_or_default()
                                );
                            }
                            return Ok(());
                        }
                    };
                    if float {
                        sqrt3_stencil_json::<f64>(&triangle, valence, &u, &v, |x| json!(x))?
                    } else {
                        sqrt3_stencil_json::<BigRational>(&triangle, valence, &u, &v, |x| {
                            json!(x.to_string())
                        })?
                    }
                } else if float {
                    triangle_stencil_json::<f64>(&triangle, patch, &u, &v, |x| json!(x))?
                } else {
                    triangle_stencil_json::<BigRational>(&triangle, patch, &u, &v, |x| {
                        json!(x.to_string())
                    })?
                };
                if json {
                    println!("{out}");
                } else {
                    println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
                }
                return Ok(());
            }
            let scheme = quad_scheme(&scheme)?;
            let mode = if corners {
                BoundaryMode::EdgeAndCorner
            } else {
                BoundaryMode::EdgeOnly
            };
            let nb = match (valence, boundary) {
                (_, Some(faces)) => Neighbourhood::boundary(faces, mode),
                (Some(v), None) if dart => Neighbourhood::dart(v),
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
            let scheme = curve_scheme(&scheme)?;
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

/// A JSON string's text, or the value's JSON text.
fn text(v: &Value) -> String {
    v.as_str().map_or_else(|| v.to_string(), str::to_owned)
}

/// `{"scheme","n","dilation","derivative","exact","support","points","values"}` for
/// `stencilgen triangle` (docs/cli.md): the support polygon's corners and the grid points in
/// the closed support as `"p/q"` pairs in skew lattice coordinates.
fn triangle_json<S: Scalar>(s: &TriangleStencils<S>, value: impl Fn(&S) -> Value) -> Value {
    let n = i64::from(s.n);
    let d = i64::from(s.dilation) - 1;
    let rational = |p: i64, q: i64| {
        BigRational::new(num_bigint::BigInt::from(p), num_bigint::BigInt::from(q)).to_string()
    };
    let points = s.points();
    let mut out = json!({
        "scheme": s.scheme,
        "n": s.n,
        "dilation": s.dilation,
        "derivative": match s.kind {
            StencilKind::Position => Value::Null,
            StencilKind::DerivativeU => json!("u"),
            StencilKind::DerivativeV => json!("v"),
        },
        "exact": S::EXACT,
        "support": s.hull.iter().map(|&(a, b)| json!([rational(a, d), rational(b, d)])).collect::<Vec<_>>(),
        "points": points.iter().map(|&(a, b)| json!([rational(a, n), rational(b, n)])).collect::<Vec<_>>(),
        "values": points.iter().map(|&(a, b)| value(&s.at(a, b))).collect::<Vec<_>>(),
    });
    if !S::EXACT {
        out["residual"] = json!(s.residual);
    }
    out
}

/// A set of positive integers: `a..b` (inclusive), `a,b,c`, or `a`.
/// The largest valence or boundary face count `stencilgen tables` takes (as `stencil
/// --valence`).
const MAX_TABLE_VALENCE: u32 = 64;

/// A range `a..b` (inclusive) or a list `a,b,c` of integers in `1..=max`; checked before any
/// list is made from it (`--n 1..4000000000` would have been 16 GB of rates).
fn parse_set(flag: &str, text: &str, max: u32) -> Result<Vec<u32>, StencilError> {
    let bad = || StencilError::OutOfDomain {
        what: format!(
            "{flag} `{}` is not a range `a..b` or a list `a,b,c` of integers in 1..={max}",
            excerpt(text)
        ),
    };
    let number = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| (1..=max).contains(&v))
            .ok_or_else(bad)
    };
    let values: Vec<u32> = match text.split_once("..") {
        Some((a, b)) => {
            let (a, b) = (number(a)?, number(b.trim_start_matches('='))?);
            if a > b {
                return Err(bad());
            }
            (a..=b).collect()
        }
        None => text.split(',').map(number).collect::<Result<_, _>>()?,
    };
    Ok(values)
}

/// Refuse, before solving anything, a table that would exceed what the format holds
/// ([`table_format::MAX_FILE_SIZE`], 4 GiB): every patch (valence `v` or boundary face count;
/// a dart of valence `v` counts `v` times, one per sector) at every rate `n` has `(n + 1)^2` primal and `n^2` dual points, each with at most
/// `2 v + 8` weights (the Catmull–Clark patch; the triangle schemes' are fewer), for the
/// position and both derivatives, in f64 at most.
fn check_table_size(set: &StencilSetSpec) -> Result<(), StencilError> {
    let dart_sectors = set
        .darts
        .iter()
        .flat_map(|&v| std::iter::repeat(v).take(v as usize));
    let bytes: u128 = set
        .valences
        .iter()
        .copied()
        .chain(dart_sectors)
        .chain(set.boundary_faces.iter().copied())
        .map(|v| {
            set.rates
                .iter()
                .map(|&n| {
                    let n = u128::from(n);
                    ((n + 1) * (n + 1) + n * n) * (2 * u128::from(v) + 8) * 3 * 8
                })
                .sum::<u128>()
        })
        .sum();
    if bytes > u128::from(table_format::MAX_FILE_SIZE) {
        return Err(StencilError::OutOfDomain {
            what: format!(
                "a table of these valences and rates would take up to {:.1} GiB, more than the \
                 format's {} GiB; ask for fewer valences or rates",
                bytes as f64 / f64::from(1u32 << 30),
                table_format::MAX_FILE_SIZE >> 30
            ),
        });
    }
    Ok(())
}

/// `dir/name.ext` -> `dir/name-suffix.ext`.
fn with_suffix(path: &std::path::Path, suffix: &str) -> std::path::PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match path.extension() {
        Some(ext) => format!("{stem}-{suffix}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{suffix}"),
    };
    path.with_file_name(name)
}

/// Generate one table with a progress bar on stderr, and write it.
fn write_table(spec: TableSpec, path: &std::path::Path) -> Result<(), StencilError> {
    let started = std::time::Instant::now();
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} grids, {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(format!("{} stencils", spec.scheme.name));
    let bytes = build_table(&spec, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    write_bytes(path, &bytes, started)
}

fn write_bytes(
    path: &std::path::Path,
    bytes: &[u8],
    started: std::time::Instant,
) -> Result<(), StencilError> {
    // All or nothing: a failed write (a full disk) removes the temporary file and never
    // leaves a truncated table under the real name.
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    let partial = std::path::PathBuf::from(partial);
    let written = std::fs::File::create(&partial)
        .and_then(|mut file| {
            std::io::Write::write_all(&mut file, bytes)?;
            file.sync_all()
        })
        .and_then(|()| std::fs::rename(&partial, path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&partial);
        return Err(StencilError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        });
    }
    eprintln!(
        "wrote {} ({} bytes, {:.1} MiB) in {:.1?}",
        path.display(),
        bytes.len(),
        bytes.len() as f64 / (1024.0 * 1024.0),
        started.elapsed()
    );
    Ok(())
}

/// The Loop EV patch's stencil at `(u, v)` (barycentric: `u, v >= 0`, `u + v <= 1`), by
/// substitution: `{"scheme","valence","u","v","exact","order","weights","du","dv"}`. At the
/// vertex itself the tangent masks are irrational in general: `null` in exact mode, with the
/// reason in `"note"`; `--f64` gives them (subdominant eigenvectors).
/// The butterfly's patch next to an interior vertex (region 0 of
/// `stencilgen::butterfly_regions`), by substitution: positions and both derivatives; at the
/// vertex itself the derivatives are the one-sided ones along the patch's edges,
/// `(e_{E_0} - e_V) P` and `(e_{E_1} - e_V) P` (`P` the spectral projector of `A` for 1/2).
fn butterfly_stencil_json<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    u: &BigRational,
    v: &BigRational,
    value: impl Fn(&S) -> Value,
) -> Result<Value, StencilError> {
    let mut substitution = ButterflyRegionSubstitution::<S>::new(scheme, valence)?;
    let mut row = |kind| -> Result<Vec<Value>, StencilError> {
        Ok(substitution
            .stencil(0, u, v, kind)?
            .iter()
            .map(&value)
            .collect())
    };
    let (weights, du, dv) = (
        row(StencilKind::Position)?,
        row(StencilKind::DerivativeU)?,
        row(StencilKind::DerivativeV)?,
    );
    Ok(json!({
        "scheme": scheme.name,
        "valence": valence,
        "boundary": false,
        "u": u.to_string(),
        "v": v.to_string(),
        "exact": S::EXACT,
        "order": substitution.stencils.regions.corner.names(),
        "weights": weights,
        "du": du,
        "dv": dv,
    }))
}

/// √3's patch next to an interior vertex (two √3 steps as one ternary step): positions by
/// [`Sqrt3Substitution`], d/du and d/dv by region 0 of [`Sqrt3RegionSubstitution`] (the same
/// layout); at `V` itself the derivatives are the tangent masks of Loop's convention
/// (docs/algorithms/sqrt3.md), said in a note.
fn sqrt3_stencil_json<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    u: &BigRational,
    v: &BigRational,
    value: impl Fn(&S) -> Value,
) -> Result<Value, StencilError> {
    let mut substitution = Sqrt3Substitution::<S>::new(scheme, valence)?;
    let weights = substitution.stencil(u, v)?;
    let mut regions = Sqrt3RegionSubstitution::<S>::new(scheme, valence)?;
    let du = regions.stencil(0, u, v, StencilKind::DerivativeU)?;
    let dv = regions.stencil(0, u, v, StencilKind::DerivativeV)?;
    let mut out = json!({
        "scheme": scheme.name,
        "valence": valence,
        "boundary": false,
        "u": u.to_string(),
        "v": v.to_string(),
        "exact": S::EXACT,
        "order": substitution.matrices.names(),
        "weights": weights.iter().map(&value).collect::<Vec<_>>(),
        "du": du.iter().map(&value).collect::<Vec<_>>(),
        "dv": dv.iter().map(&value).collect::<Vec<_>>(),
    });
    if u.is_zero() && v.is_zero() && valence != 6 {
        out["note"] = json!(
            "at the vertex du/dv are tangent masks (subdominant left eigenvectors normalized on \
             the reference net), not derivatives: those exist there only at valence 6"
        );
    }
    Ok(out)
}

/// √3's patch `sector` next to a boundary vertex with `faces` triangles (Kobbelt's boundary
/// rules), f64, by [`sqrt3_strip::fan`] on the grid of the point's common denominator
/// (at most [`MAX_BASIS_RATE`]): positions everywhere, `du`/`dv` off the boundary, the
/// tangent masks of [`sqrt3_fan_tangents`] at `V` (with a note), and `null` with a note
/// across a boundary ray on it (unbounded there in general).
/// Control points are named `[sector, a, b]` in `schemes::sqrt3_boundary`'s charts.
fn sqrt3_boundary_stencil_json(
    faces: u32,
    sector: u32,
    u: &BigRational,
    v: &BigRational,
) -> Result<Value, StencilError> {
    let outside = |what: String| StencilError::OutOfDomain { what };
    if faces == 0 || sector >= faces {
        return Err(outside(format!(
            "sector {sector}: a boundary vertex with {faces} triangles has sectors 0..{faces}"
        )));
    }
    if u.is_negative() || v.is_negative() || u + v > BigRational::one() {
        return Err(outside(format!("({u}, {v}) is outside the patch")));
    }
    let d = u.denom().lcm(v.denom());
    let d = u32::try_from(&d)
        .ok()
        .filter(|&d| d <= MAX_BASIS_RATE)
        .ok_or_else(|| {
            outside(format!(
                "({u}, {v}): the common denominator {d} is above {MAX_BASIS_RATE}"
            ))
        })?;
    let numerator = |x: &BigRational| -> Result<i64, StencilError> {
        i64::try_from(&(x * BigRational::from_integer(BigInt::from(d))).to_integer())
            .map_err(|_| outside(format!("({u}, {v})")))
    };
    let k = (numerator(u)?, numerator(v)?);
    let mut evaluator = sqrt3_strip::fan(faces, d)?;
    let s = i64::from(sector);
    let weights = evaluator.stencil(s, k, derivative(StencilKind::Position))?;
    let mut notes = Vec::new();
    let mut derivative = |kind: StencilKind| match evaluator.stencil(s, k, derivative(kind)) {
        Ok(stencil) => Some(stencil),
        Err(e) => {
            notes.push(e.to_string());
            None
        }
    };
    let (du, dv) = if k == (0, 0) {
        // At V the derivatives are the tangent masks (docs/algorithms/sqrt3.md).
        let masks = sqrt3_fan_tangents(faces, sector)?;
        let stencil = |w: &[f64]| -> FanStencil {
            masks
                .layout
                .iter()
                .zip(w)
                .filter(|(_, &x)| x != 0.0)
                .map(|(&p, &x)| (p, x))
                .collect()
        };
        notes.push(format!(
            "at the boundary vertex du/dv are tangent masks (the boundary tangent and the cross \
             mode of eigenvalue {:.6}, normalized on the half-disk net), not derivatives",
            masks.across
        ));
        (Some(stencil(&masks.du)), Some(stencil(&masks.dv)))
    } else {
        (
            derivative(StencilKind::DerivativeU),
            derivative(StencilKind::DerivativeV),
        )
    };
    let mut order: Vec<FanPoint> = weights.keys().copied().collect();
    for stencil in [&du, &dv].into_iter().flatten() {
        order.extend(stencil.keys().copied());
    }
    order.sort_unstable();
    order.dedup();
    let row = |stencil: &FanStencil| -> Vec<f64> {
        order
            .iter()
            .map(|p| stencil.get(p).copied().unwrap_or(0.0))
            .collect()
    };
    let mut out = json!({
        "scheme": "sqrt3",
        "boundary": true,
        "faces": faces,
        "sector": sector,
        "u": u.to_string(),
        "v": v.to_string(),
        "exact": false,
        "order": order.iter().map(|p| json!([p.0, p.1, p.2])).collect::<Vec<_>>(),
        "weights": row(&weights),
        "du": du.as_ref().map(row),
        "dv": dv.as_ref().map(row),
    });
    if !notes.is_empty() {
        out["note"] = json!(notes.join("; "));
    }
    Ok(out)
}

/// Which Loop patch `stencilgen stencil` prints.
#[derive(Clone, Copy, Debug)]
enum TrianglePatchChoice {
    /// Next to an interior vertex of this valence.
    Interior(u32),
    /// Sector `.1` next to a boundary vertex with `.0` triangles.
    Boundary(u32, u32),
}

fn triangle_stencil_json<S: Scalar>(
    scheme: &TriangleScheme,
    patch: TrianglePatchChoice,
    u: &BigRational,
    v: &BigRational,
    value: impl Fn(&S) -> Value,
) -> Result<Value, StencilError> {
    let mut substitution = match patch {
        TrianglePatchChoice::Interior(valence) => TriangleSubstitution::<S>::new(scheme, valence)?,
        TrianglePatchChoice::Boundary(faces, sector) => {
            TriangleSubstitution::<S>::boundary(scheme, faces, sector)?
        }
    };
    let weights = substitution.stencil(u, v)?;
    let mut out = json!({
        "scheme": scheme.name,
        "u": u.to_string(),
        "v": v.to_string(),
        "exact": S::EXACT,
        "order": substitution.matrices.names(),
        "weights": weights.iter().map(&value).collect::<Vec<_>>(),
    });
    match patch {
        TrianglePatchChoice::Interior(valence) => {
            out["valence"] = json!(valence);
            out["boundary"] = json!(false);
        }
        TrianglePatchChoice::Boundary(faces, sector) => {
            out["faces"] = json!(faces);
            out["sector"] = json!(sector);
            out["boundary"] = json!(true);
        }
    }
    for (key, kind) in [
        ("du", StencilKind::DerivativeU),
        ("dv", StencilKind::DerivativeV),
    ] {
        match substitution.stencil_of_kind(u, v, kind) {
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
        "dart": nb.dart,
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
