//! Per-frame tessellation throughput through the library facade, **from the input control
//! points**: `Surface::new` (isolation) and `Surface::tessellator` (the plan: table lookups,
//! separable factors, connectivity and triangles) run once; every frame is
//! `Tessellator::evaluate(&input_positions)`: the isolation's refinement stencils (when it took
//! steps), then every output vertex's position and unit normal.
//!
//! `cargo bench -p subtess --bench tessellate`: one and two threads (a rayon pool of each
//! size), rates 4, 8, 16 and mixed, on
//! * Catmull–Clark, no isolation needed: Crane's Spot refined three times (11,712 faces) when
//!   `../shared/models` exists, else the shipped cube refined five times (6,144 faces);
//! * Catmull–Clark, isolation needed: Spot triangulated (5,856 triangles: one step, 17,568
//!   quads; this group needs `../shared/models`);
//! * Loop: Spot triangulated (one isolating step, 23,424 triangles), else an icosahedron
//!   refined four times by Loop.
//!
//! Group "watertightness check": `TriangleMesh::is_watertight` on Spot's control mesh at rate
//! 16 (1,508,326 triangles; the cube refined three times without `../shared/models`) and on
//! Loop's triangulated Spot at rate 8 (4,005,504 triangles; the icosahedron refined four times
//! without), beside the general check on every directed edge (`boundary_edges`) and the frame
//! it checks.
#![allow(missing_docs)] // criterion_group! generates an undocumented function

// The integration tests' meshes; the benchmark uses a few of them.
#[allow(dead_code)]
#[path = "../tests/integration/common/mod.rs"]
mod common;

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use subtess::{Mesh, Rates, Scheme, Surface, Tessellator};

fn shared(relative: &str) -> Option<Mesh> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/models")
        .join(relative);
    if !path.exists() {
        eprintln!("SKIPPED: {} is absent", path.display());
        return None;
    }
    Some(Mesh::read_obj(&path).unwrap_or_else(|e| panic!("{e}")))
}

fn refined(mut mesh: Mesh, scheme: Scheme, steps: usize) -> Mesh {
    for _ in 0..steps {
        mesh = scheme.refine(&mesh).unwrap_or_else(|e| panic!("{e}"));
    }
    mesh
}

/// A rayon pool of `threads` threads, for the groups of one and two threads.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// One frame from the input control points; its vertex count keeps it from being optimized away.
fn frame(tessellator: &mut Tessellator<'_>, control: &[[f32; 3]]) -> usize {
    tessellator
        .evaluate(control)
        .map(|f| f.positions().len())
        .unwrap_or(0)
}

/// The meshes: (group label, mesh, scheme).
fn cases() -> Vec<(String, Mesh, Scheme)> {
    let mut cases = Vec::new();
    let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
    match shared("crane/spot_control_mesh.obj") {
        Some(spot) => cases.push((
            "dual grid, spot refined 3x (no isolation)".to_owned(),
            refined(spot, Scheme::CatmullClark, 3),
            Scheme::CatmullClark,
        )),
        None => cases.push((
            "dual grid, cube refined 5x (no isolation)".to_owned(),
            refined(
                Mesh::read_obj(&cube).unwrap_or_else(|e| panic!("{e}")),
                Scheme::CatmullClark,
                5,
            ),
            Scheme::CatmullClark,
        )),
    }
    match shared("crane/spot_triangulated.obj") {
        Some(spot) => {
            cases.push((
                "dual grid, spot triangulated (one isolating step)".to_owned(),
                spot.clone(),
                Scheme::CatmullClark,
            ));
            cases.push((
                "loop dual grid, spot triangulated".to_owned(),
                spot,
                Scheme::Loop,
            ));
        }
        None => cases.push((
            "loop dual grid, icosahedron refined 4x".to_owned(),
            refined(common::icosahedron(), Scheme::Loop, 4),
            Scheme::Loop,
        )),
    }
    cases
}

fn bench(c: &mut Criterion) {
    for (name, mesh, scheme) in cases() {
        let surface = Surface::new(&mesh, scheme).unwrap_or_else(|e| panic!("{name}: {e}"));
        let control = mesh.positions_f32();
        let mixed: Vec<u32> = (0..mesh.faces())
            .map(|f| [3, 5, 8, 12, 7, 16][f % 6])
            .collect();
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut group = c.benchmark_group(format!(
                "{name}, {} faces, {threads} thread(s)",
                surface.faces()
            ));
            group.sample_size(20);
            for (label, rates) in [
                ("rate 4", Rates::Uniform(4)),
                ("rate 8", Rates::Uniform(8)),
                ("rate 16", Rates::Uniform(16)),
                ("mixed 3..16", Rates::PerFace(mixed.clone())),
            ] {
                let mut tessellator = pool
                    .install(|| surface.tessellator(&rates))
                    .unwrap_or_else(|e| panic!("{e}"));
                group.throughput(Throughput::Elements(tessellator.triangle_count() as u64));
                group.bench_function(label, |b| {
                    pool.install(|| b.iter(|| frame(&mut tessellator, &control)))
                });
            }
            group.finish();
        }
    }
}

/// The watertightness check against the frame it checks, one and two threads: a quad dual
/// grid and Loop's.
fn check(c: &mut Criterion) {
    let quads = shared("crane/spot_control_mesh.obj").unwrap_or_else(|| {
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let cube = Mesh::read_obj(&cube).unwrap_or_else(|e| panic!("{e}"));
        refined(cube, Scheme::CatmullClark, 3)
    });
    let triangles = shared("crane/spot_triangulated.obj")
        .unwrap_or_else(|| refined(common::icosahedron(), Scheme::Loop, 4));
    for (mesh, scheme, rate) in [
        (quads, Scheme::CatmullClark, 16),
        (triangles, Scheme::Loop, 8),
    ] {
        let surface = Surface::new(&mesh, scheme).unwrap_or_else(|e| panic!("{e}"));
        let control = mesh.positions_f32();
        let mut tessellator = surface
            .tessellator(&Rates::Uniform(rate))
            .unwrap_or_else(|e| panic!("{e}"));
        let output = tessellator
            .evaluate(&control)
            .unwrap_or_else(|e| panic!("{e}"))
            .to_triangle_mesh();
        assert!(output.is_watertight());
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut group = c.benchmark_group(format!(
                "watertightness check, {scheme:?} rate {rate}, {} triangles, {threads} thread(s)",
                output.triangles.len()
            ));
            group.sample_size(10);
            group.throughput(Throughput::Elements(output.triangles.len() as u64));
            group.bench_function("is_watertight", |b| {
                pool.install(|| b.iter(|| output.is_watertight()))
            });
            group.bench_function("general check (boundary_edges)", |b| {
                pool.install(|| b.iter(|| output.boundary_edges().map(|e| e.len())))
            });
            group.bench_function("the frame (evaluate)", |b| {
                pool.install(|| b.iter(|| frame(&mut tessellator, &control)))
            });
            group.finish();
        }
    }
}

criterion_group!(benches, bench, check);
criterion_main!(benches);
