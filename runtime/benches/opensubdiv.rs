//! subtess side by side with OpenSubdiv 3.7 (through the `opensubdiv-petite` crate), in one
//! run, the per-frame work **from the input control points** on three meshes, at the same
//! points:
//!
//! * a closed torus of 200 x 100 = 20,000 regular quads (generated here; no extraordinary
//!   vertex: the best case for both), n = 4, 8, 16;
//! * Crane's Spot refined three times (`../shared/models/crane/spot_control_mesh.obj`, 11,712
//!   quads, extraordinary vertices far apart: no isolation), n = 4, 8, 16;
//! * Crane's triangulated Spot (`spot_triangulated.obj`, 5,856 triangles: every face needs
//!   isolation, two Catmull–Clark steps, 70,272 faces), n = 4, 8, 16.
//! * the quad-dominant sword (`../shared/models/odedstein/sword-quad-dominant.obj`, 22,117
//!   quads and 348 triangles: two isolating steps, 358,048 faces, most of them pieces of
//!   regular input quads), n = 4, 8, 16.
//!
//! OpenSubdiv's table for more than [`BATCH_POINTS`] points (the sword at n = 8 and 16, the
//! triangulated Spot at n = 16: one table for the sword's 22.9 M points at n = 8 took the
//! process to 16 GB) is built in batches of consecutive points, one table at a time, each
//! checked and timed (the median of [`BATCH_RUNS`] applications) and dropped; its frame is the
//! sum of the batches' medians, printed as a line of its own beside criterion's groups.
//!
//! The Spot meshes and the sword are skipped, with a message, when `../shared/models` is
//! absent.
//!
//! `scripts/install-opensubdiv-deps.sh && cargo bench -p subtess --features opensubdiv
//! --bench opensubdiv` (the feature builds OpenSubdiv from C++ source; docs/benchmarks.md).
//!
//! The points are subtess's output vertices at uniform rate `n` (their sources: input face,
//! sub-face of a non-quad, exact `(u, v)`), given to OpenSubdiv as Ptex faces and parameters.
//! Every variant is reported as triangles per second with subtess's triangle count.
//!
//! * subtess: `Tessellator::evaluate(&input_points)`, the facade's frame: the isolation's
//!   refinement map (when isolation took steps), then every output vertex's position and unit
//!   normal; the plan (and its triangles, which a frame does not rewrite) built once. One
//!   thread, and two (a two-thread rayon pool installed around the frame).
//! * OpenSubdiv `Far::LimitStencilTable` at the same points, factorized to the input control
//!   points (adaptive refinement to level 10 with Gregory end caps, as the parity test builds
//!   it): built once; per frame its stencils (position, du, dv weights) are applied to the
//!   input points in one tight loop with f32 accumulation, as
//!   `LimitStencilTable::UpdateValues`/`UpdateDerivs` do (the crate exposes the table's arrays
//!   but not those two methods). No normals, no triangles. One thread (OpenSubdiv's CPU path).
//! * OpenSubdiv `Bfr::Surface`, positions only, on the all-quad meshes: the crate exposes only
//!   `Surface::evaluate_position`, which prepares the face's patch points on every call and has
//!   no derivatives, so this is not the same work; shown for reference. Surfaces are
//!   initialized once.
//!
//! `Far::PatchTable` evaluation is not measured: in opensubdiv-petite 0.3.1 the C shim's
//! `PatchTable_EvaluateBasis` is a placeholder (uniform weights, zero derivatives) and
//! `PatchMap_FindPatch` does not return the patch's parameters, so it does not evaluate the
//! surface (checked on the torus at start: positions off by about 5e-4 of the size, derivatives
//! zero).
//!
//! Before timing, OpenSubdiv's positions at every point are checked against subtess's to 1e-5
//! of the mesh's bounding-box diagonal, the normals from OpenSubdiv's derivatives against
//! subtess's to 1e-2 rad (the largest differences are printed: about 1e-5 rad on the torus,
//! up to 6.3e-3 rad next to extraordinary vertices, where OpenSubdiv's end caps approximate), and Bfr's positions (every 97th point) to 1e-5 on the torus (on Spot
//! they are printed: Bfr approximates the patches at extraordinary vertices).
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use opensubdiv_petite::bfr::{Surface as BfrSurface, SurfaceFactory};
use opensubdiv_petite::far;
use subtess::mesh::topology::Mesh;
use subtess::{Rates, Scheme, Surface, VertexSource};

/// Quads around the torus's axis and around its tube.
const AROUND: usize = 200;
const TUBE: usize = 100;
const MAJOR_RADIUS: f64 = 1.0;
const MINOR_RADIUS: f64 = 0.4;

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

/// The diagonal of the points' bounding box: the scale of the position tolerance.
fn diagonal(points: &[[f32; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for x in 0..3 {
            lo[x] = lo[x].min(f64::from(p[x]));
            hi[x] = hi[x].max(f64::from(p[x]));
        }
    }
    (0..3).map(|x| (hi[x] - lo[x]).powi(2)).sum::<f64>().sqrt()
}

/// The largest angle between two lists of unit normals, in radians.
fn max_angle(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| {
            let chord = (0..3)
                .map(|x| f64::from(p[x] - q[x]).powi(2))
                .sum::<f64>()
                .sqrt();
            2.0 * (chord / 2.0).min(1.0).asin()
        })
        .fold(0.0, f64::max)
}

/// The most points one OpenSubdiv table is built for. OpenSubdiv's table for the sword at n = 8
/// (22.9 M points) took the process to 16.3 GB; beyond this many points the points are split
/// into consecutive batches of at most this many, one table each, built, checked and timed one
/// after another, and OpenSubdiv's frame is the sum of the batches' median times (the same
/// stencils applied to the same points, a table at a time).
const BATCH_POINTS: usize = 6_000_000;

/// Applications timed per batch (after one untimed) when OpenSubdiv's table is built in batches.
const BATCH_RUNS: usize = 7;

/// The median wall time of `runs` calls of `f`, after one call not timed.
fn median_seconds(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut seconds: Vec<f64> = (0..runs)
        .map(|_| {
            let started = Instant::now();
            f();
            started.elapsed().as_secs_f64()
        })
        .collect();
    seconds.sort_by(f64::total_cmp);
    seconds[runs / 2]
}

/// One mesh of the comparison.
struct Case {
    name: String,
    mesh: Mesh,
}

/// The rates `n` every mesh is compared at.
const RATES: [u32; 3] = [4, 8, 16];

/// The mesh's input faces in OpenSubdiv's terms: vertices per face, face-vertex indices, and
/// every face's first Ptex face (a quad is one Ptex face, an `m`-gon `m`, one per corner).
struct Topology {
    sizes: Vec<u32>,
    indices: Vec<u32>,
    first_ptex: Vec<usize>,
}

impl Topology {
    fn new(mesh: &Mesh) -> Self {
        let faces = mesh.faces();
        let sizes: Vec<u32> = (0..faces).map(|f| mesh.face(f).len() as u32).collect();
        let indices = (0..faces).flat_map(|f| mesh.face(f).to_vec()).collect();
        let mut first_ptex = Vec::with_capacity(faces);
        let mut next = 0;
        for &m in &sizes {
            first_ptex.push(next);
            next += if m == 4 { 1 } else { m as usize };
        }
        Topology {
            sizes,
            indices,
            first_ptex,
        }
    }

    /// The Ptex face and parameters of a subtess output vertex.
    fn ptex(&self, src: &VertexSource) -> (usize, f32, f32) {
        let f = src.face as usize;
        let (u, v) = src.uv();
        let sub = if self.sizes[f] == 4 {
            0
        } else {
            usize::from(src.subface)
        };
        (self.first_ptex[f] + sub, u as f32, v as f32)
    }
}

/// OpenSubdiv's `Far::LimitStencilTable` at `points` (Ptex face, s, t), consecutive points of
/// one Ptex face given as one location array.
fn limit_stencil_table(
    refiner: &far::TopologyRefiner,
    points: &[(usize, f32, f32)],
) -> far::LimitStencilTable {
    let s: Vec<f32> = points.iter().map(|p| p.1).collect();
    let t: Vec<f32> = points.iter().map(|p| p.2).collect();
    let mut locations = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let face = points[start].0;
        let end = start + points[start..].iter().take_while(|p| p.0 == face).count();
        locations.push(far::LocationArray {
            ptex_index: face,
            s: &s[start..end],
            t: &t[start..end],
        });
        start = end;
    }
    let table = far::LimitStencilTable::new(
        refiner,
        &locations,
        None,
        None,
        far::LimitStencilTableOptions::default(),
    )
    .unwrap_or_else(|e| panic!("limit stencil table: {e}"));
    assert_eq!(table.len(), points.len(), "a stencil per point");
    table
}

/// OpenSubdiv's `Bfr::Surface` positions at `points` (crate API: positions only).
fn bfr_points(
    surfaces: &[BfrSurface],
    points: &[(usize, f32, f32)],
    control: &[[f32; 3]],
    out: &mut [[f32; 3]],
) {
    for (o, &(f, u, v)) in out.iter_mut().zip(points) {
        *o = surfaces[f]
            .evaluate_position(u, v, control)
            .unwrap_or_else(|e| panic!("Bfr evaluation: {e:?}"));
    }
}

fn compare(c: &mut Criterion, two_threads: &rayon::ThreadPool, case: &Case) {
    let mesh = &case.mesh;
    let control = mesh.positions_f32();
    let size = diagonal(&control);
    let topology = Topology::new(mesh);
    let all_quads = topology.sizes.iter().all(|&m| m == 4);

    let started = Instant::now();
    let surface = Surface::new(mesh, Scheme::CatmullClark).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "{}: {} input faces, {} isolation steps, {} faces, refinement map {} weights ({:.2} s)",
        case.name,
        mesh.faces(),
        surface.isolation_steps(),
        surface.faces(),
        surface.refinement_weights(),
        started.elapsed().as_secs_f64()
    );

    // OpenSubdiv: the same vertices and faces, adaptively refined as the parity test does.
    let descriptor =
        far::TopologyDescriptor::new(control.len(), &topology.sizes, &topology.indices)
            .unwrap_or_else(|e| panic!("topology descriptor: {e}"));
    let mut refiner = far::TopologyRefiner::new(descriptor, far::TopologyRefinerOptions::default())
        .unwrap_or_else(|e| panic!("topology refiner: {e}"));
    refiner.refine_adaptive(
        far::AdaptiveRefinementOptions {
            isolation_level: 10,
            ..far::AdaptiveRefinementOptions::default()
        },
        &[],
    );
    if case.name == "torus" {
        check_patch_table(&refiner, &control, size);
    }
    // Bfr's factory reads its (unrefined) refiner until it is dropped; declared before it, the
    // refiner outlives it.
    let bfr_refiner = far::TopologyRefiner::new(descriptor, far::TopologyRefinerOptions::default())
        .unwrap_or_else(|e| panic!("topology refiner: {e}"));
    let factory = SurfaceFactory::new(&bfr_refiner, 2, 6)
        .unwrap_or_else(|e| panic!("Bfr surface factory: {e}"));
    let surfaces: Vec<BfrSurface> = if all_quads {
        (0..mesh.faces())
            .map(|f| {
                factory
                    .init_vertex_surface(opensubdiv_petite::Index::from(f))
                    .unwrap_or_else(|e| panic!("Bfr surface of face {f}: {e:?}"))
            })
            .collect()
    } else {
        Vec::new()
    };

    for n in RATES {
        let mut tessellator = surface
            .tessellator(&Rates::Uniform(n))
            .unwrap_or_else(|e| panic!("{e}"));
        let triangles = tessellator.triangle_count();
        let frame = tessellator
            .evaluate(&control)
            .unwrap_or_else(|e| panic!("{e}"));
        let points: Vec<(usize, f32, f32)> =
            frame.sources().iter().map(|s| topology.ptex(s)).collect();
        let (ours_p, ours_n) = (frame.positions().to_vec(), frame.normals().to_vec());
        eprintln!(
            "{}, n = {n}: {} points, {triangles} triangles, {} of {} faces separable",
            case.name,
            points.len(),
            tessellator.separable_faces(),
            surface.faces()
        );

        // OpenSubdiv's table in batches of consecutive points where one table for all of them
        // would not fit in memory; each batch is built, checked and timed, then dropped.
        let batches = points.len().div_ceil(BATCH_POINTS);
        let mut position_error = 0.0f64;
        let mut normal_error = 0.0f64;
        let mut build_seconds = 0.0;
        let mut weights = 0usize;
        let mut batch_seconds = Vec::with_capacity(batches);
        let mut single = None;
        for batch in 0..batches {
            let range = batch * points.len() / batches..(batch + 1) * points.len() / batches;
            let started = Instant::now();
            let limit = limit_stencil_table(&refiner, &points[range.clone()]);
            build_seconds += started.elapsed().as_secs_f64();
            weights += limit.weights().len();
            let stencils = LimitStencils::new(&limit);
            let mut osd_p = vec![[0.0f32; 3]; range.len()];
            let mut osd_du = osd_p.clone();
            let mut osd_dv = osd_p.clone();
            stencils.apply(&control, &mut osd_p, &mut osd_du, &mut osd_dv);
            let osd_n: Vec<[f32; 3]> = osd_du
                .iter()
                .zip(&osd_dv)
                .map(|(&u, &v)| unit_normal(u, v))
                .collect();
            position_error =
                position_error.max(max_difference(&osd_p, &ours_p[range.clone()]) / size);
            normal_error = normal_error.max(max_angle(&osd_n, &ours_n[range.clone()]));
            if batches == 1 {
                single = Some((limit, osd_p, osd_du, osd_dv));
            } else {
                batch_seconds.push(median_seconds(BATCH_RUNS, || {
                    stencils.apply(&control, &mut osd_p, &mut osd_du, &mut osd_dv)
                }));
            }
        }
        eprintln!(
            "{}, n = {n}: OpenSubdiv LimitStencilTable built in {build_seconds:.2} s, {batches} \
             batch(es) ({:.1} weights per point and quantity)",
            case.name,
            weights as f64 / points.len() as f64
        );
        let mut bfr_error = 0.0f64;
        if all_quads {
            let sample: Vec<(usize, f32, f32)> = points.iter().copied().step_by(97).collect();
            let ours: Vec<[f32; 3]> = ours_p.iter().copied().step_by(97).collect();
            let mut bfr = vec![[0.0f32; 3]; sample.len()];
            bfr_points(&surfaces, &sample, &control, &mut bfr);
            bfr_error = max_difference(&bfr, &ours) / size;
        }
        eprintln!(
            "{}, n = {n}: largest differences to subtess: LimitStencilTable positions \
             {position_error:.1e} of the diagonal, normals {normal_error:.1e} rad; Bfr \
             positions {bfr_error:.1e}",
            case.name
        );
        assert!(position_error < 1e-5, "LimitStencilTable positions differ");
        // Next to extraordinary vertices OpenSubdiv's level-10 end caps approximate the
        // tangents (6.3e-3 rad on the triangulated Spot, whose isolated faces all touch one).
        assert!(normal_error < 1e-2, "LimitStencilTable normals differ");
        // Bfr approximates irregular patches (at extraordinary vertices) at the factory's
        // approximation level (2 here): checked on the torus, only printed on Spot (1e-5 to
        // 1e-4 of the diagonal there).
        if case.name == "torus" {
            assert!(bfr_error < 1e-5, "Bfr positions differ");
        }
        if batches > 1 {
            let seconds: f64 = batch_seconds.iter().sum();
            eprintln!(
                "{}, n = {n}: OpenSubdiv LimitStencilTable (P, du, dv), 1 thread, {batches} \
                 batches: {:.2} ms a frame (the sum of each batch's median of {BATCH_RUNS} \
                 applications), {:.1} M triangles/s",
                case.name,
                seconds * 1e3,
                triangles as f64 / seconds / 1e6
            );
        }
        drop((ours_p, ours_n));

        let mut group = c.benchmark_group(format!(
            "{}, n = {n}, {} points, {triangles} triangles",
            case.name,
            points.len()
        ));
        group.sample_size(10);
        group.sampling_mode(SamplingMode::Flat);
        group.warm_up_time(Duration::from_secs(2));
        group.measurement_time(Duration::from_secs(5));
        group.throughput(Throughput::Elements(triangles as u64));
        group.bench_function("subtess Tessellator::evaluate, 1 thread", |b| {
            b.iter(|| tessellator.evaluate(&control).map(|f| f.positions().len()))
        });
        group.bench_function("subtess Tessellator::evaluate, 2 threads", |b| {
            b.iter(|| {
                two_threads.install(|| tessellator.evaluate(&control).map(|f| f.positions().len()))
            })
        });
        if let Some((limit, mut osd_p, mut osd_du, mut osd_dv)) = single {
            let stencils = LimitStencils::new(&limit);
            group.bench_function("OpenSubdiv LimitStencilTable (P, du, dv), 1 thread", |b| {
                b.iter(|| stencils.apply(&control, &mut osd_p, &mut osd_du, &mut osd_dv))
            });
            if all_quads {
                group.bench_function(
                    "OpenSubdiv Bfr::Surface (P only, crate API), 1 thread",
                    |b| b.iter(|| bfr_points(&surfaces, &points, &control, &mut osd_p)),
                );
            }
        }
        group.finish();
    }
}

/// A mesh from `../shared/models`, refined `steps` times, or `None` (with a message) where the
/// folder is absent.
fn shared_mesh(relative: &str, steps: usize) -> Option<Mesh> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/models")
        .join(relative);
    if !path.exists() {
        eprintln!(
            "SKIPPED: {} is absent (../shared/models beside the repository)",
            path.display()
        );
        return None;
    }
    let mut mesh = Mesh::read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    for _ in 0..steps {
        mesh = subtess::scheme::catmull_clark::refine::refine(&mesh).mesh;
    }
    Some(mesh)
}

fn bench(c: &mut Criterion) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .unwrap_or_else(|e| panic!("one-thread rayon pool: {e}"));
    let two_threads = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap_or_else(|e| panic!("two-thread rayon pool: {e}"));

    let (positions, faces) = torus();
    let torus = Mesh::new(positions, &faces, &[], schemes::BoundaryMode::EdgeOnly)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut cases = vec![Case {
        name: "torus".to_owned(),
        mesh: torus,
    }];
    let shared = [
        (
            "crane/spot_control_mesh.obj",
            3,
            "Spot refined 3x (no isolation)",
        ),
        (
            "crane/spot_triangulated.obj",
            0,
            "Spot triangulated (isolation)",
        ),
        (
            "odedstein/sword-quad-dominant.obj",
            0,
            "sword, quad-dominant (isolation)",
        ),
    ];
    for (path, steps, name) in shared {
        if let Some(mesh) = shared_mesh(path, steps) {
            cases.push(Case {
                name: name.to_owned(),
                mesh,
            });
        }
    }
    for case in &cases {
        compare(c, &two_threads, case);
    }
}

/// The crate's `Far::PatchTable` evaluation (`PatchMap::find_patch` + `evaluate_point`) is not
/// benchmarked: print how far it is from the limit surface at the face centres (the limit
/// stencils', which agree with subtess).
fn check_patch_table(refiner: &far::TopologyRefiner, control: &[[f32; 3]], size: f64) {
    let Ok(patches) = far::PatchTable::new(refiner, None) else {
        eprintln!("Far::PatchTable: the crate could not build it");
        return;
    };
    let Some(map) = far::PatchMap::new(&patches) else {
        eprintln!("Far::PatchMap: the crate could not build it");
        return;
    };
    let faces: Vec<usize> = (0..AROUND * TUBE).step_by(101).collect();
    let centres: Vec<(usize, f32, f32)> = faces.iter().map(|&f| (f, 0.5, 0.5)).collect();
    let limit = limit_stencil_table(refiner, &centres);
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
        worst = worst.max(max_difference(&[result.point], &[*e]) / size);
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
