//! subtess side by side with OpenSubdiv 3.7 (through the `opensubdiv-petite` crate), one thread,
//! in one run: a closed torus of 200 x 100 = 20,000 regular quads, per face the `n x n` dual
//! points `((2i+1)/2n, (2j+1)/2n)`, position and both derivatives, n = 4, 8, 16.
//!
//! `scripts/install-opensubdiv-deps.sh && cargo bench -p subtess --features opensubdiv
//! --bench opensubdiv` (the feature builds OpenSubdiv from C++ source; docs/benchmarks.md).
//!
//! Variants, all reported as triangles per second with subtess's triangle count for the points
//! (`DualGrid::triangle_count`, `2 n^2` per face on this mesh):
//!
//! * subtess: `DualGrid::evaluate` (positions and unit normals from the table's position and
//!   tangent stencils) and `DualGrid::connect` (all triangles) per frame; plan built once.
//! * OpenSubdiv `Far::LimitStencilTable`: built once for all points with first derivatives by
//!   `LimitStencilTableFactory`; per frame its stencils (position, du, dv weights) are applied to
//!   the control points in one tight loop with f32 accumulation, as
//!   `LimitStencilTable::UpdateValues`/`UpdateDerivs` do (the crate exposes the table's arrays
//!   but not those two methods). No triangles.
//! * OpenSubdiv `Bfr::Surface`, positions only: the crate exposes only
//!   `Surface::evaluate_position`, which prepares the face's patch points on every call and has
//!   no derivatives, so this is not the same work; it is shown for reference. Surfaces are
//!   initialized once.
//!
//! `Far::PatchTable` evaluation is not measured: in opensubdiv-petite 0.3.1 the C shim's
//! `PatchTable_EvaluateBasis` is a placeholder (uniform weights, zero derivatives) and
//! `PatchMap_FindPatch` does not return the patch's parameters, so it does not evaluate the
//! surface (checked at start: its positions are off by about 5e-4 of the size, 2,000 times the
//! limit stencils' difference to subtess, and its derivatives are zero).
//!
//! Before timing, OpenSubdiv's positions at every point (and Bfr's on a sample of faces) are
//! checked against subtess's to 1e-5 of the torus's size, and the normals from OpenSubdiv's
//! derivatives against subtess's to 1e-4.
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use opensubdiv_petite::bfr::{Surface, SurfaceFactory};
use opensubdiv_petite::far;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::DualGrid;
use subtess::tessellate::GridPlan;

/// Quads around the torus's axis and around its tube.
const AROUND: usize = 200;
const TUBE: usize = 100;
const MAJOR_RADIUS: f64 = 1.0;
const MINOR_RADIUS: f64 = 0.4;
/// The torus's extent (outer diameter): the scale of the position tolerance.
const SIZE: f64 = 2.0 * (MAJOR_RADIUS + MINOR_RADIUS);
const RATES: [usize; 3] = [4, 8, 16];

/// The torus: vertex `(a, b)` at index `b * AROUND + a`, face `(a, b)` at `b * AROUND + a` with
/// corners `(a, b), (a+1, b), (a+1, b+1), (a, b+1)`. The tube radius wobbles a little so that no
/// face is symmetric (a wrong parameter orientation would not go unnoticed).
fn torus() -> (Vec<[f64; 3]>, Vec<Vec<i64>>) {
    let tau = std::f64::consts::TAU;
    let mut positions = Vec::with_capacity(AROUND * TUBE);
    for b in 0..TUBE {
        let phi = tau * b as f64 / TUBE as f64;
        for a in 0..AROUND {
            let theta = tau * a as f64 / AROUND as f64;
            let r = MINOR_RADIUS * (1.0 + 0.05 * (3.0 * theta).sin() * (2.0 * phi).cos());
            let ring = MAJOR_RADIUS + r * phi.cos();
            positions.push([ring * theta.cos(), ring * theta.sin(), r * phi.sin()]);
        }
    }
    let vertex = |a: usize, b: usize| ((b % TUBE) * AROUND + a % AROUND) as i64;
    let faces = (0..TUBE)
        .flat_map(|b| (0..AROUND).map(move |a| (a, b)))
        .map(|(a, b)| {
            vec![
                vertex(a, b),
                vertex(a + 1, b),
                vertex(a + 1, b + 1),
                vertex(a, b + 1),
            ]
        })
        .collect();
    (positions, faces)
}

/// The dual parameters of one face at rate `n`, row by row (`j` outer), as subtess orders its
/// output vertices: `(s, t)` arrays.
fn dual_parameters(n: usize) -> (Vec<f32>, Vec<f32>) {
    let d = (2 * n) as f32;
    (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .map(|(i, j)| ((2 * i + 1) as f32 / d, (2 * j + 1) as f32 / d))
        .unzip()
}

/// OpenSubdiv's limit stencils (position, du, dv) applied to `control`: what
/// `LimitStencilTable::UpdateValues` and `UpdateDerivs` compute, fused into one pass.
struct LimitStencils<'a> {
    sizes: &'a [i32],
    offsets: &'a [opensubdiv_petite::Index],
    indices: &'a [opensubdiv_petite::Index],
    weights: &'a [f32],
    du: &'a [f32],
    dv: &'a [f32],
}

impl<'a> LimitStencils<'a> {
    fn new(table: &'a far::LimitStencilTable) -> Self {
        let s = LimitStencils {
            sizes: table.sizes(),
            offsets: table.offsets(),
            indices: table.control_indices(),
            weights: table.weights(),
            du: table.du_weights(),
            dv: table.dv_weights(),
        };
        assert_eq!(s.sizes.len(), s.offsets.len());
        assert_eq!(s.weights.len(), s.indices.len());
        assert_eq!(s.du.len(), s.indices.len());
        assert_eq!(s.dv.len(), s.indices.len());
        s
    }

    fn apply(
        &self,
        control: &[[f32; 3]],
        out_p: &mut [[f32; 3]],
        out_du: &mut [[f32; 3]],
        out_dv: &mut [[f32; 3]],
    ) {
        for (k, (&size, &offset)) in self.sizes.iter().zip(self.offsets).enumerate() {
            let range = offset.0 as usize..offset.0 as usize + size as usize;
            let mut p = [0.0f32; 3];
            let mut du = [0.0f32; 3];
            let mut dv = [0.0f32; 3];
            for (((&index, &w), &wu), &wv) in self.indices[range.clone()]
                .iter()
                .zip(&self.weights[range.clone()])
                .zip(&self.du[range.clone()])
                .zip(&self.dv[range])
            {
                let c = control[index.0 as usize];
                for x in 0..3 {
                    p[x] += w * c[x];
                    du[x] += wu * c[x];
                    dv[x] += wv * c[x];
                }
            }
            out_p[k] = p;
            out_du[k] = du;
            out_dv[k] = dv;
        }
    }
}

fn unit_normal(du: [f32; 3], dv: [f32; 3]) -> [f32; 3] {
    let c = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    c.map(|x| x / l)
}

fn max_difference(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |x| f64::from((p[x] - q[x]).abs())))
        .fold(0.0, f64::max)
}

/// OpenSubdiv's `Bfr::Surface` positions of one face at the parameters `(s, t)` (crate API).
fn bfr_face(surface: &Surface, s: &[f32], t: &[f32], control: &[[f32; 3]], out: &mut [[f32; 3]]) {
    for ((o, &u), &v) in out.iter_mut().zip(s).zip(t) {
        *o = surface
            .evaluate_position(u, v, control)
            .unwrap_or_else(|e| panic!("Bfr evaluation: {e:?}"));
    }
}

fn bench(c: &mut Criterion) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .unwrap_or_else(|e| panic!("one-thread rayon pool: {e}"));

    let (positions, faces) = torus();
    let face_count = faces.len();
    let control: Vec<[f32; 3]> = positions.iter().map(|p| p.map(|c| c as f32)).collect();
    // subtess's plans take f64 control points (`GridPlan::evaluate`): the same f32 values.
    let control64: Vec<[f64; 3]> = control.iter().map(|p| p.map(f64::from)).collect();

    // subtess: topology, patches (the torus is regular: no refinement step).
    let table = StencilTable::default_catmull_clark().unwrap_or_else(|e| panic!("{e}"));
    let mesh = Mesh::new(
        positions.clone(),
        &faces,
        &[],
        schemes::BoundaryMode::EdgeOnly,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let (isolated, patches, steps) = isolate(&mesh).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(steps, 0, "the torus is all regular quads");
    assert_eq!(isolated.positions.len(), control.len());

    // OpenSubdiv: the same vertices and faces.
    let vertices_per_face = vec![4u32; face_count];
    let face_vertices: Vec<u32> = faces.iter().flatten().map(|&v| v as u32).collect();
    let descriptor =
        far::TopologyDescriptor::new(control.len(), &vertices_per_face, &face_vertices)
            .unwrap_or_else(|e| panic!("topology descriptor: {e}"));
    let mut refiner = far::TopologyRefiner::new(descriptor, far::TopologyRefinerOptions::default())
        .unwrap_or_else(|e| panic!("topology refiner: {e}"));
    refiner.refine_adaptive(far::AdaptiveRefinementOptions::default(), &[]);
    // Bfr's factory reads its (unrefined) refiner until it is dropped; declared before it, the
    // refiner outlives it. A quad's ptex face is the face itself: ptex index = face index.
    let bfr_refiner = far::TopologyRefiner::new(descriptor, far::TopologyRefinerOptions::default())
        .unwrap_or_else(|e| panic!("topology refiner: {e}"));
    let factory = SurfaceFactory::new(&bfr_refiner, 2, 6)
        .unwrap_or_else(|e| panic!("Bfr surface factory: {e}"));
    let surfaces: Vec<Surface> = (0..face_count)
        .map(|f| {
            factory
                .init_vertex_surface(opensubdiv_petite::Index::from(f))
                .unwrap_or_else(|e| panic!("Bfr surface of face {f}: {e:?}"))
        })
        .collect();
    check_patch_table(&refiner, &control);

    for n in RATES {
        let (s, t) = dual_parameters(n);
        let points = face_count * n * n;

        let grid = DualGrid::new(&table, &isolated, &patches, &vec![n as u32; face_count])
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(grid.vertex_count(), points, "closed mesh: dual points only");
        eprintln!(
            "n = {n}: subtess plan: {} of {face_count} faces separable (tensor product), \
             {} triangles",
            grid.separable_faces(),
            grid.triangle_count()
        );
        let mut positions = vec![[0.0f32; 3]; points];
        let mut normals = positions.clone();
        let mut triangles = vec![[0u32; 3]; grid.triangle_count()];
        grid.evaluate(&control64, &mut positions, &mut normals);

        let locations: Vec<far::LocationArray> = (0..face_count)
            .map(|f| far::LocationArray {
                ptex_index: f,
                s: &s,
                t: &t,
            })
            .collect();
        let started = Instant::now();
        let limit = far::LimitStencilTable::new(
            &refiner,
            &locations,
            None,
            None,
            far::LimitStencilTableOptions::default(),
        )
        .unwrap_or_else(|e| panic!("limit stencil table: {e}"));
        eprintln!(
            "n = {n}: OpenSubdiv LimitStencilTable for {points} points built in {:.2} s \
             ({} weights per quantity)",
            started.elapsed().as_secs_f64(),
            limit.weights().len()
        );
        assert_eq!(limit.len(), points);
        let stencils = LimitStencils::new(&limit);
        let mut osd_p = vec![[0.0f32; 3]; points];
        let mut osd_du = osd_p.clone();
        let mut osd_dv = osd_p.clone();
        stencils.apply(&control, &mut osd_p, &mut osd_du, &mut osd_dv);

        let position_error = max_difference(&osd_p, &positions) / SIZE;
        let osd_normals: Vec<[f32; 3]> = osd_du
            .iter()
            .zip(&osd_dv)
            .map(|(&u, &v)| unit_normal(u, v))
            .collect();
        let normal_error = max_difference(&osd_normals, &normals);
        let mut bfr_p = vec![[0.0f32; 3]; n * n];
        let mut bfr_error = 0.0f64;
        for f in (0..face_count).step_by(97) {
            bfr_face(&surfaces[f], &s, &t, &control, &mut bfr_p);
            let ours = &positions[f * n * n..(f + 1) * n * n];
            bfr_error = bfr_error.max(max_difference(&bfr_p, ours) / SIZE);
        }
        eprintln!(
            "n = {n}: largest differences to subtess: LimitStencilTable positions {position_error:.1e} \
             of the size, normals {normal_error:.1e}; Bfr positions {bfr_error:.1e} of the size"
        );
        assert!(position_error < 1e-5, "LimitStencilTable positions differ");
        assert!(normal_error < 1e-4, "LimitStencilTable normals differ");
        assert!(bfr_error < 1e-5, "Bfr positions differ");

        let mut group = c.benchmark_group(format!(
            "torus {face_count} quads, n = {n}, {points} points, 1 thread"
        ));
        group.sample_size(10);
        group.sampling_mode(SamplingMode::Flat);
        group.warm_up_time(Duration::from_secs(2));
        group.measurement_time(Duration::from_secs(5));
        group.throughput(Throughput::Elements(grid.triangle_count() as u64));
        group.bench_function("subtess dual grid (evaluate + connect)", |b| {
            b.iter(|| {
                grid.evaluate(&control64, &mut positions, &mut normals);
                grid.connect(&mut triangles);
            })
        });
        group.bench_function("OpenSubdiv LimitStencilTable (P, du, dv)", |b| {
            b.iter(|| stencils.apply(&control, &mut osd_p, &mut osd_du, &mut osd_dv))
        });
        group.bench_function("OpenSubdiv Bfr::Surface (P only, crate API)", |b| {
            b.iter(|| {
                for (surface, out) in surfaces.iter().zip(osd_p.chunks_exact_mut(n * n)) {
                    bfr_face(surface, &s, &t, &control, out);
                }
            })
        });
        group.finish();
    }
}

/// The crate's `Far::PatchTable` evaluation (`PatchMap::find_patch` + `evaluate_point`) is not
/// benchmarked: print how far it is from the limit surface at the face centres (the limit
/// stencils', which agree with subtess).
fn check_patch_table(refiner: &far::TopologyRefiner, control: &[[f32; 3]]) {
    let Ok(patches) = far::PatchTable::new(refiner, None) else {
        eprintln!("Far::PatchTable: the crate could not build it");
        return;
    };
    let Some(map) = far::PatchMap::new(&patches) else {
        eprintln!("Far::PatchMap: the crate could not build it");
        return;
    };
    let faces: Vec<usize> = (0..AROUND * TUBE).step_by(101).collect();
    let half = [0.5f32];
    let locations: Vec<far::LocationArray> = faces
        .iter()
        .map(|&f| far::LocationArray {
            ptex_index: f,
            s: &half,
            t: &half,
        })
        .collect();
    let limit = far::LimitStencilTable::new(
        refiner,
        &locations,
        None,
        None,
        far::LimitStencilTableOptions::default(),
    )
    .unwrap_or_else(|e| panic!("limit stencil table: {e}"));
    let mut expected = vec![[0.0f32; 3]; faces.len()];
    let (mut du, mut dv) = (expected.clone(), expected.clone());
    LimitStencils::new(&limit).apply(control, &mut expected, &mut du, &mut dv);
    let mut worst = 0.0f64;
    let mut largest_derivative = 0.0f32;
    for (&f, e) in faces.iter().zip(&expected) {
        let Some((patch, u, v)) = map.find_patch(f, 0.5, 0.5) else {
            eprintln!("Far::PatchMap: no patch found for face {f}");
            return;
        };
        let Some(result) = patches.evaluate_point(patch, u, v, control) else {
            eprintln!("Far::PatchTable: evaluate_point failed for face {f}");
            return;
        };
        worst = worst.max(max_difference(&[result.point], &[*e]) / SIZE);
        let derivatives = result.du.iter().chain(&result.dv);
        largest_derivative = derivatives.fold(largest_derivative, |m, x| m.max(x.abs()));
    }
    eprintln!(
        "Far::PatchTable + PatchMap (crate API, not benchmarked): at face centres, positions \
         differ from the limit surface by up to {worst:.1e} of the size, largest derivative \
         component {largest_derivative:.1e}"
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
