//! The numbers of `docs/results.md`: triangles and measured error of tolerance-driven
//! tessellations with per-face rational rates (`1..=24`), per-face powers of two
//! (`1, 2, 4, 8, 16`) and one uniform rate, on closed meshes.
//!
//! `cargo run --release -p subtess --example rate_results` prints the markdown table.
//! Meshes from `../shared/models/` are skipped (and said so) when absent; arguments, if any,
//! keep only the meshes whose names contain one of them.

use std::path::{Path, PathBuf};
use std::time::Instant;

use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::scheme::patch::FacePatch;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::tessellate;
use subtess::tessellate::rates::{
    measure_deviation, tolerance_rates, tolerance_rates_among, ToleranceRates, MAX_SELECTED_RATE,
    POWER_OF_TWO_RATES,
};
use subtess::RuntimeError;

/// Tolerances, as fractions of the bounding-box diagonal of the control mesh.
const TOLERANCES: [f64; 4] = [1e-2, 3e-3, 1e-3, 3e-4];

/// The measurement grid: the table's primal and dual points at this rate (a prime, so that its
/// samples are not those of the selection grid, rate 24, except on the face's edges).
const MEASURE_GRID: u32 = 23;

fn meshes() -> Vec<(&'static str, PathBuf)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../../shared/models");
    vec![
        ("cube (runtime/data)", root.join("data/cube.obj")),
        (
            "catmark_pyramid",
            shared.join("opensubdiv/catmark_pyramid.obj"),
        ),
        ("catmark_torus", shared.join("opensubdiv/catmark_torus.obj")),
        (
            "penguin (odedstein)",
            shared.join("odedstein/penguin_control_mesh.obj"),
        ),
        ("spot (crane)", shared.join("crane/spot_control_mesh.obj")),
    ]
}

struct Row {
    triangles: usize,
    error: f64,
    unmet: usize,
}

fn run(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    rates: &ToleranceRates,
) -> Result<Row, RuntimeError> {
    let (out, _) = tessellate(table, mesh, patches, &rates.rates)?;
    let started = Instant::now();
    let error = measure_deviation(table, mesh, patches, &out, MEASURE_GRID)?;
    if std::env::var_os("RATE_RESULTS_TIMES").is_some() {
        eprintln!(
            "measure {} triangles: {:.2} s",
            out.triangles.len(),
            started.elapsed().as_secs_f64()
        );
    }
    Ok(Row {
        triangles: out.triangles.len(),
        error,
        unmet: rates.unmet.len(),
    })
}

fn main() -> Result<(), RuntimeError> {
    let table = StencilTable::default_catmull_clark()?;
    println!("| mesh (isolated faces) | T / diagonal | rational 1..=24: triangles | error / T | powers of two: triangles | error / T | more triangles | uniform: n | triangles | error / T |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    // Optional arguments: only the meshes whose names contain one of them.
    let only: Vec<String> = std::env::args().skip(1).collect();
    for (name, path) in meshes() {
        if !only.is_empty() && !only.iter().any(|o| name.contains(o.as_str())) {
            continue;
        }
        if !path.exists() {
            eprintln!("skipping {name}: {} is absent", path.display());
            continue;
        }
        let started = Instant::now();
        let (input, warnings) = Mesh::from_obj(&read_obj(&path)?)?;
        if !warnings.is_empty() {
            eprintln!("{name}: {}", warnings.join("; "));
        }
        let (mesh, patches, _) = isolate(&input)?;
        let (mut low, mut high) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in &input.positions {
            for c in 0..3 {
                low[c] = low[c].min(p[c]);
                high[c] = high[c].max(p[c]);
            }
        }
        let diagonal = (0..3)
            .map(|c| (high[c] - low[c]).powi(2))
            .sum::<f64>()
            .sqrt();
        for relative in TOLERANCES {
            let t = relative * diagonal;
            let clock = Instant::now();
            let rational = tolerance_rates(&table, &mesh, &patches, t)?;
            if std::env::var_os("RATE_RESULTS_TIMES").is_some() {
                eprintln!("select: {:.2} s", clock.elapsed().as_secs_f64());
            }
            let powers = tolerance_rates_among(&table, &mesh, &patches, t, &POWER_OF_TWO_RATES)?;
            // The smallest uniform rate meeting T on every face is at least every face's own.
            let start = rational.rates.iter().copied().max().unwrap_or(1);
            let mut uniform = None;
            for n in start..=MAX_SELECTED_RATE {
                let r = tolerance_rates_among(&table, &mesh, &patches, t, &[n])?;
                if r.unmet.is_empty() {
                    uniform = Some((n, r));
                    break;
                }
            }
            let a = run(&table, &mesh, &patches, &rational)?;
            let b = run(&table, &mesh, &patches, &powers)?;
            let mark = |r: &Row| {
                if r.unmet > 0 {
                    format!(" ({} faces unmet)", r.unmet)
                } else {
                    String::new()
                }
            };
            let uniform_cells = match &uniform {
                Some((n, r)) => {
                    let u = run(&table, &mesh, &patches, r)?;
                    format!("{n} | {} | {:.3}", u.triangles, u.error / t)
                }
                None => format!("none <= {MAX_SELECTED_RATE} | | "),
            };
            println!(
                "| {name} ({}) | {relative:.0e} | {}{} | {:.3} | {}{} | {:.3} | {:+.0}% | {uniform_cells} |",
                patches.len(),
                a.triangles,
                mark(&a),
                a.error / t,
                b.triangles,
                mark(&b),
                b.error / t,
                100.0 * (b.triangles as f64 / a.triangles as f64 - 1.0),
            );
        }
        eprintln!("{name}: {:.1} s", started.elapsed().as_secs_f64());
    }
    Ok(())
}
