//! Reproduces the layout of Table 1 of Lai–Cheng (object, A/U/T, polygons, A/U ratio, depth,
//! error, RF) for the cube, Spot and OpenSubdiv's torus at three tolerances each, with the
//! measured error beside the tolerance, and the dual-grid tessellator at the same tolerance.
//! docs/lai-cheng.md quotes its output.
//!
//! ```text
//! cargo run --release -p subtess-runtime --example lai_cheng_table
//! ```
//!
//! Tolerances are absolute, as fractions of each model's bounding-box diagonal. "Measured" is
//! [`runtime::rates::measure_deviation`]: the largest distance from the limit surface, sampled
//! at the table's primal and dual points at rate 24 of every face, to the nearest output
//! triangle. Spot and the torus are skipped with a notice when `../shared/models` is absent.

use std::path::{Path, PathBuf};

use runtime::dual_grid::tessellate;
use runtime::isolate::isolate_with_origins;
use runtime::lai_cheng::{tessellate_adaptive, AdaptiveOptions};
use runtime::obj::read_obj;
use runtime::rates::{measure_deviation, tolerance_rates};
use runtime::stencil_table::StencilTable;
use runtime::topology::Mesh;

fn diagonal(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}

fn main() -> Result<(), runtime::RuntimeError> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = here.join("../../shared/models");
    let models: Vec<(&str, PathBuf)> = vec![
        ("cube", here.join("data/cube.obj")),
        ("Spot", shared.join("crane/spot_control_mesh.obj")),
        (
            "torus (OpenSubdiv)",
            shared.join("opensubdiv/catmark_torus.obj"),
        ),
    ];
    let table = StencilTable::default_catmull_clark()?;
    println!(
        "| Object | A/U/T | polygons | A/U ratio | Depth | Error T (abs) | measured | RF (max bound / diagonal) | dual-grid triangles (measured) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, path) in models {
        if !path.is_file() {
            println!("<!-- skipped {name}: {} is absent -->", path.display());
            continue;
        }
        let (mesh, _) = Mesh::from_obj(&read_obj(&path)?)?;
        let iso = isolate_with_origins(&mesh)?;
        let size = diagonal(&mesh);
        for fraction in [0.01, 0.003, 0.001] {
            let t = fraction * size;
            let options = AdaptiveOptions {
                tolerance: t,
                max_depth: 20,
                ..Default::default()
            };
            let (out, stats) = tessellate_adaptive(&table, &iso.mesh, &iso.patches, &options)?;
            let triangles = out.to_triangle_mesh();
            let measured = measure_deviation(&table, &iso.mesh, &iso.patches, &triangles, 24)?;
            let depth = iso.steps as u32 + stats.uniform_depth;
            let rates = tolerance_rates(&table, &iso.mesh, &iso.patches, t)?;
            let (dual, _) = tessellate(&table, &iso.mesh, &iso.patches, &rates.rates)?;
            let dual_measured = measure_deviation(&table, &iso.mesh, &iso.patches, &dual, 24)?;
            let over = if stats.leaves_over_tolerance > 0 {
                format!(
                    " ({} leaves over T at max depth)",
                    stats.leaves_over_tolerance
                )
            } else {
                String::new()
            };
            println!(
                "| {name} | U | {:.0} | 100.00% | {depth} | | | | |",
                stats.uniform_polygons
            );
            println!(
                "| {name} | A | {} | {:.3}% | {depth} | {t:.3e} ({fraction} x diag){over} | {measured:.3e} | {:.2}% | {} ({dual_measured:.3e}){} |",
                stats.polygons,
                100.0 * stats.polygons as f64 / stats.uniform_polygons,
                100.0 * stats.max_relative_bound,
                dual.triangles.len(),
                if rates.unmet.is_empty() { "" } else { ", some faces unmet at rate 24" },
            );
            println!(
                "| {name} | T | {} | {:.3}% | {depth} | {t:.3e} | {measured:.3e} | {:.2}% | |",
                stats.triangles,
                100.0 * stats.triangles as f64 / stats.uniform_polygons,
                100.0 * stats.max_relative_bound,
            );
            eprintln!(
                "{name} T = {t:.3e}: {} polygons, {} extraordinary leaves, {:.3} s",
                stats.polygons, stats.extraordinary_leaves, stats.seconds
            );
        }
    }
    Ok(())
}
