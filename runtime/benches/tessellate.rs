//! Per-frame tessellation throughput: evaluation of every point (positions and normals) and
//! all connectivity into preallocated buffers; topology, patches and the plan built once. Mesh: Crane's Spot refined to 11,712
//! faces when `../shared/models` exists, else the shipped cube refined to 6,144 faces.
//!
//! `cargo bench -p subtess --bench tessellate`: one and two threads (a rayon pool of
//! each size), rates 4, 8, 16 and mixed.
//!
//! Loop (the triangle dual grid): Crane's triangulated Spot (5,856 triangles, 23,424 after the
//! one isolating Loop step) when `../shared/models` exists, else an icosahedron refined to
//! 5,120 triangles; the same threads and rates.
#![allow(missing_docs)] // criterion_group! generates an undocumented function

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::scheme::catmull_clark::refine::refine;
use subtess::scheme::loop_scheme::isolate::isolate_loop;
use subtess::scheme::loop_scheme::refine::loop_refine;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::DualGrid;
use subtess::tessellate::triangle_dual_grid::TriangleDualGrid;

fn mesh() -> (String, Mesh) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let spot = root.join("../../shared/models/crane/spot_control_mesh.obj");
    let (name, path, steps) = if spot.exists() {
        ("spot", spot, 3)
    } else {
        ("cube", root.join("data/cube.obj"), 5)
    };
    let obj = read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut m = Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0;
    for _ in 0..steps {
        m = refine(&m).mesh;
    }
    (name.to_owned(), m)
}

fn bench(c: &mut Criterion) {
    let table = StencilTable::default_catmull_clark().unwrap_or_else(|e| panic!("{e}"));
    let (name, m) = mesh();
    let (isolated, patches, _) = isolate(&m).unwrap_or_else(|e| panic!("{e}"));
    let mixed: Vec<u32> = (0..patches.len())
        .map(|f| [3, 5, 8, 12, 7, 16][f % 6])
        .collect();
    let control: Vec<[f32; 3]> = isolated
        .positions
        .iter()
        .map(|p| p.map(|c| c as f32))
        .collect();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let mut group = c.benchmark_group(format!(
            "dual grid, {name}, {} faces, {threads} thread(s)",
            patches.len()
        ));
        group.sample_size(20);
        for (label, rates) in [
            ("rate 4", vec![4; patches.len()]),
            ("rate 8", vec![8; patches.len()]),
            ("rate 16", vec![16; patches.len()]),
            ("mixed 3..16", mixed.clone()),
        ] {
            let grid = DualGrid::new(&table, &isolated, &patches, &rates)
                .unwrap_or_else(|e| panic!("{e}"));
            let mut positions = vec![[0.0f32; 3]; grid.vertex_count()];
            let mut normals = positions.clone();
            let mut triangles = vec![[0u32; 3]; grid.triangle_count()];
            group.throughput(Throughput::Elements(grid.triangle_count() as u64));
            group.bench_function(label, |b| {
                pool.install(|| {
                    b.iter(|| {
                        grid.evaluate(&control, &mut positions, &mut normals);
                        grid.connect(&mut triangles);
                    })
                })
            });
        }
        group.finish();
    }
}

/// Spot triangulated, or an icosahedron refined four times by Loop.
fn triangle_mesh() -> (String, Mesh) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let spot = root.join("../../shared/models/crane/spot_triangulated.obj");
    if spot.exists() {
        let obj = read_obj(&spot).unwrap_or_else(|e| panic!("{e}"));
        let m = Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0;
        return ("spot triangulated".to_owned(), m);
    }
    let mut m = common::icosahedron();
    for _ in 0..4 {
        m = loop_refine(&m).unwrap_or_else(|e| panic!("{e}")).mesh;
    }
    ("icosahedron".to_owned(), m)
}

fn bench_loop(c: &mut Criterion) {
    let table = StencilTable::default_loop().unwrap_or_else(|e| panic!("{e}"));
    let (name, m) = triangle_mesh();
    let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{e}"));
    let faces = iso.patches.len();
    let mixed: Vec<u32> = (0..faces).map(|f| [3, 5, 8, 12, 7, 16][f % 6]).collect();
    let control: Vec<[f32; 3]> = iso
        .mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c as f32))
        .collect();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let mut group = c.benchmark_group(format!(
            "loop dual grid, {name}, {faces} triangles, {threads} thread(s)"
        ));
        group.sample_size(20);
        for (label, rates) in [
            ("rate 4", vec![4; faces]),
            ("rate 8", vec![8; faces]),
            ("rate 16", vec![16; faces]),
            ("mixed 3..16", mixed.clone()),
        ] {
            let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates)
                .unwrap_or_else(|e| panic!("{e}"));
            let mut positions = vec![[0.0f32; 3]; grid.vertex_count()];
            let mut normals = positions.clone();
            let mut triangles = vec![[0u32; 3]; grid.triangle_count()];
            group.throughput(Throughput::Elements(grid.triangle_count() as u64));
            group.bench_function(label, |b| {
                pool.install(|| {
                    b.iter(|| {
                        grid.evaluate(&control, &mut positions, &mut normals);
                        grid.connect(&mut triangles);
                    })
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench, bench_loop);
criterion_main!(benches);
