//! Reproduces the layout of Table 2 of Espino et al. (triangles T and error E for Map2p,
//! Map4p, Map8p and flat at three triangle budgets) for the Utah teapot and teacup, plus the
//! surface evaluations each test made and saved. docs/espino.md quotes its output.
//!
//! ```text
//! cargo run --release -p subtess --example espino_table [-- --max-depth N --samples N --budgets a,b,c]
//! ```
//!
//! Skips with a notice when `../shared/models` is absent.

use std::path::Path;

use subtess::tessellate::bezier::{
    tessellate_bezier_full, BezierOptions, BezierPatches, EdgeTest, SharedCurves,
};

fn boundary_loops(mesh: &subtess::mesh::triangle_mesh::TriangleMesh) -> Option<usize> {
    let edges = mesh.boundary_edges()?;
    let mut next = std::collections::HashMap::new();
    for &(a, b) in &edges {
        next.insert(a, b);
    }
    let mut seen = std::collections::HashSet::new();
    let mut loops = 0;
    for &(a, _) in &edges {
        if seen.contains(&a) {
            continue;
        }
        loops += 1;
        let mut v = a;
        while seen.insert(v) {
            v = *next.get(&v)?;
        }
    }
    Some(loops)
}

fn main() -> Result<(), subtess::RuntimeError> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|k| args.get(k + 1))
            .cloned()
    };
    let max_depth: u32 = arg("--max-depth")
        .and_then(|s| s.parse().ok())
        .unwrap_or(BezierOptions::default().max_depth);
    let samples: usize = arg("--samples").and_then(|s| s.parse().ok()).unwrap_or(64);
    let budgets: Vec<usize> = arg("--budgets")
        .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or_else(|| vec![20000, 13000, 7500]);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models/bezier");
    if !dir.is_dir() {
        println!(
            "skipping: {} is absent (it ships beside the repository, not in it)",
            dir.display()
        );
        return Ok(());
    }
    println!("Espino et al. Table 2 layout: T = triangles, E = max distance from {samples}x{samples} samples per patch to the mesh");
    println!("map 16x16, max depth {max_depth}, threshold searched per cell for the budget\n");
    let mut header = String::from("| model | budget |");
    let mut rule = String::from("|---|---:|");
    for t in EdgeTest::ALL {
        header += &format!(" {t} T | {t} E |");
        rule += "---:|---:|";
    }
    println!("{header}\n{rule}");
    let mut saved_rows = Vec::new();
    for name in ["teapot.txt", "teacup.txt"] {
        let patches = BezierPatches::read(&dir.join(name))?;
        let open = SharedCurves::new(&patches).open_sides().len();
        for &budget in &budgets {
            let mut row = format!("| {name} | {budget} |");
            for test in EdgeTest::ALL {
                let options = BezierOptions {
                    test,
                    target_triangles: Some(budget),
                    max_depth,
                    error_samples: samples,
                    ..Default::default()
                };
                let t = tessellate_bezier_full(&patches, &options)?;
                let s = &t.stats;
                row += &format!(
                    " {} | {:.5} |",
                    s.triangles,
                    s.max_error.unwrap_or(f64::NAN)
                );
                saved_rows.push(format!(
                    "| {name} | {budget} | {test} | {:.3e} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    s.threshold,
                    s.triangles,
                    s.vertices,
                    s.vertices_evaluated,
                    s.vertices_discarded,
                    s.evaluations_saved,
                    s.edges_capped,
                    boundary_loops(&t.mesh).map_or("inconsistent".to_string(), |l| l.to_string()),
                    open,
                ));
            }
            println!("{row}");
        }
    }
    println!("\nSurface evaluations per cell (decide-first vs compute-then-decide):\n");
    println!("| model | budget | test | th | T | V | evaluated | discarded | saved | capped edges | boundary loops | open sides |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in saved_rows {
        println!("{r}");
    }
    Ok(())
}
