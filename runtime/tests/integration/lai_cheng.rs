//! Lai–Cheng adaptive tessellation (`subtess::tessellate::lai_cheng`): the error guarantee measured
//! independently of the bound (table stencils at rate 24 and exact evaluation, to the output
//! polygon's own triangles), watertightness by global ids, relative flatness, flat regions.
//!
//! Expected values come from the surfaces themselves (exact evaluation, the f32 tables), from
//! topology (Euler characteristics, edge pairing) or from invariance (scaling by 8 is exact in
//! floating point), never from the code under test.

use std::path::Path;

use crate::common::load;

use num_bigint::BigInt;
use num_rational::BigRational;
use schemes::BoundaryMode;
use subtess::eval::exact_eval::ExactEvaluator;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::adaptive::{limit_stencils, LimitQuery};
use subtess::scheme::catmull_clark::isolate::{isolate_with_origins, Isolation};
use subtess::stencil_table::StencilTable;
use subtess::tessellate::lai_cheng::{
    tessellate_adaptive, AdaptiveMesh, AdaptiveOptions, AdaptivePolygon,
};
use subtess::tessellate::rates::{point_triangle_distance, table_positions};
use subtess::RuntimeError;
use table_format::PointSet;

fn cube() -> Mesh {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj"))
}

/// Crane's Spot, from `../shared/models`.
fn spot() -> Mesh {
    load(&crate::common::models().join("crane/spot_control_mesh.obj"))
}

fn table() -> StencilTable {
    StencilTable::default_catmull_clark().expect("embedded table")
}

fn isolate(mesh: &Mesh) -> Isolation {
    isolate_with_origins(mesh).expect("isolates")
}

fn size(mesh: &Mesh) -> f64 {
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

fn distance_to_polygon(out: &AdaptiveMesh, polygon: &AdaptivePolygon, p: [f64; 3]) -> f64 {
    polygon
        .triangles
        .iter()
        .map(|t| {
            let tri = t.map(|i| out.positions[i as usize]);
            point_triangle_distance(p, &tri)
        })
        .fold(f64::INFINITY, f64::min)
}

fn contains(polygon: &AdaptivePolygon, u: f64, v: f64) -> bool {
    let r = &polygon.region;
    let d = f64::from(r.denominator);
    let (u0, v0, s) = (
        f64::from(r.u0) / d,
        f64::from(r.v0) / d,
        f64::from(r.size) / d,
    );
    let e = 1e-12;
    u >= u0 - e && u <= u0 + s + e && v >= v0 - e && v <= v0 + s + e
}

/// The largest measured `distance / bound` ratio and the largest distance, over the table's
/// primal and dual points at rate 24 of every face, each against every polygon whose parameter
/// square contains it (its own triangles only). Asserts `distance <= bound + slack`.
fn check_with_table(iso: &Isolation, out: &AdaptiveMesh, slack: f64) -> (f64, f64) {
    let table = table();
    let mut by_face: Vec<Vec<AdaptivePolygon>> = vec![Vec::new(); iso.mesh.faces()];
    for p in out.polygons() {
        by_face[p.region.face as usize].push(p);
    }
    let (mut worst_ratio, mut worst): (f64, f64) = (0.0, 0.0);
    for (f, patch) in iso.patches.iter().enumerate() {
        for (set, side, offset) in [(PointSet::Primal, 25, 0.0), (PointSet::Dual, 24, 0.5)] {
            let positions =
                table_positions(&table, &iso.mesh, patch, set, 24).expect("table positions");
            for (k, &s) in positions.iter().enumerate() {
                let (i, j) = (k % side, k / side);
                let (u, v) = ((i as f64 + offset) / 24.0, (j as f64 + offset) / 24.0);
                let mut found = false;
                for polygon in by_face[f].iter().filter(|p| contains(p, u, v)) {
                    found = true;
                    let d = distance_to_polygon(out, polygon, s);
                    assert!(
                        d <= polygon.region.bound + slack,
                        "face {f} at ({u}, {v}): distance {d} > bound {} ({:?})",
                        polygon.region.bound,
                        polygon.region
                    );
                    worst = worst.max(d);
                    if polygon.region.bound > 0.0 {
                        worst_ratio = worst_ratio.max(d / polygon.region.bound);
                    }
                }
                assert!(found, "face {f}: ({u}, {v}) is in no polygon");
            }
        }
    }
    (worst_ratio, worst)
}

fn rational(numerator: u64, denominator: u64) -> BigRational {
    BigRational::new(BigInt::from(numerator), BigInt::from(denominator))
}

/// Exact evaluation at 4 x 4 interior points of every polygon of the faces `faces`: the
/// distance to the polygon's triangles stays within its bound (to f64 rounding).
fn check_exactly(iso: &Isolation, out: &AdaptiveMesh, faces: &[u32], scale: f64) -> f64 {
    let exact = ExactEvaluator::new(&iso.mesh);
    let mut worst: f64 = 0.0;
    for polygon in out.polygons().filter(|p| faces.contains(&p.region.face)) {
        let r = polygon.region;
        let d = u64::from(r.denominator) * 8;
        for a in 0..4u64 {
            for b in 0..4u64 {
                let u = rational(u64::from(r.u0) * 8 + (2 * a + 1) * u64::from(r.size), d);
                let v = rational(u64::from(r.v0) * 8 + (2 * b + 1) * u64::from(r.size), d);
                let s = exact
                    .evaluate(r.face as usize, &u, &v)
                    .expect("exact evaluation")
                    .position;
                let dist = distance_to_polygon(out, &polygon, s);
                assert!(
                    dist <= r.bound + 1e-12 * scale,
                    "face {} at ({u}, {v}): {dist} > {}",
                    r.face,
                    r.bound
                );
                worst = worst.max(dist);
            }
        }
    }
    worst
}

/// Exact evaluation at 8 x 8 interior points of every polygon at an extraordinary vertex of
/// the faces `faces`: asserts the distance to the polygon's triangles is within its bound and
/// returns the largest distance / bound.
fn check_extraordinary_exactly(
    iso: &Isolation,
    out: &AdaptiveMesh,
    faces: &[u32],
    scale: f64,
) -> f64 {
    let exact = ExactEvaluator::new(&iso.mesh);
    let mut worst: f64 = 0.0;
    for polygon in out
        .polygons()
        .filter(|p| p.region.extraordinary && faces.contains(&p.region.face))
    {
        let r = polygon.region;
        let d = u64::from(r.denominator) * 16;
        for a in 0..8u64 {
            for b in 0..8u64 {
                let u = rational(u64::from(r.u0) * 16 + (2 * a + 1) * u64::from(r.size), d);
                let v = rational(u64::from(r.v0) * 16 + (2 * b + 1) * u64::from(r.size), d);
                let s = exact
                    .evaluate(r.face as usize, &u, &v)
                    .expect("exact evaluation")
                    .position;
                let dist = distance_to_polygon(out, &polygon, s);
                assert!(
                    dist <= r.bound + 1e-12 * scale,
                    "face {} at ({u}, {v}): {dist} > {}",
                    r.face,
                    r.bound
                );
                worst = worst.max(dist / r.bound);
            }
        }
    }
    worst
}

fn options(tolerance: f64) -> AdaptiveOptions {
    AdaptiveOptions {
        tolerance,
        ..Default::default()
    }
}

#[test]
#[cfg(feature = "catmull-clark")]
fn the_cube_meets_the_tolerance_everywhere_sampled() {
    let mesh = cube();
    let scale = size(&mesh);
    let iso = isolate(&mesh);
    for t in [0.02 * scale, 0.004 * scale] {
        let (out, stats) =
            tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(t)).expect("ok");
        assert_eq!(stats.leaves_over_tolerance, 0);
        assert!(stats.max_bound <= t);
        let (ratio, worst) = check_with_table(&iso, &out, 2e-6 * scale);
        // Every face of the isolated cube touches a valence-3 vertex: check two exactly.
        let exact = check_exactly(&iso, &out, &[0, 7], scale);
        println!(
            "cube T = {t}: {} polygons, depth {}, measured {worst:.3e} (exact {exact:.3e}), \
             largest measured/bound {ratio:.3}",
            stats.polygons, stats.max_depth
        );
        assert!(worst <= t && exact <= t);
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn spot_meets_the_tolerance_everywhere_sampled() {
    let mesh = spot();
    let scale = size(&mesh);
    let iso = isolate(&mesh);
    let t = 0.002 * scale;
    let (out, stats) =
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(t)).expect("ok");
    assert_eq!(stats.leaves_over_tolerance, 0);
    let (ratio, worst) = check_with_table(&iso, &out, 2e-6 * scale);
    // A face at an extraordinary vertex and a regular one, exactly.
    let ev = out
        .polygons()
        .find(|p| p.region.extraordinary)
        .map_or(0, |p| p.region.face);
    let regular = out
        .polygons()
        .find(|p| p.region.depth > 1 && !p.region.extraordinary)
        .map_or(1, |p| p.region.face);
    let exact = check_exactly(&iso, &out, &[ev, regular], scale);
    println!(
        "spot T = {t}: {} polygons, {} triangles, depth {}, A/U {:.4}, measured {worst:.3e} \
         (exact {exact:.3e}), largest measured/bound {ratio:.3}",
        stats.polygons, stats.triangles, stats.max_depth, stats.au_ratio
    );
    assert!(worst <= t + 2e-6 * scale && exact <= t);
}

/// The extraordinary bound (hull of the Bézier nets of three levels of regular quarters and the
/// innermost layout) on the penguin, whose extraordinary vertices reach valence 8: every
/// polygon of the four faces with the deepest extraordinary squares, exactly at 4 x 4 points,
/// and every face at the table's points, within its polygon's bound.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn the_penguin_meets_the_extraordinary_bound() {
    let mesh = load(&crate::common::models().join("odedstein/penguin_control_mesh.obj"));
    let scale = size(&mesh);
    let iso = isolate(&mesh);
    let t = 0.003 * scale;
    let (out, stats) =
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(t)).expect("ok");
    assert_eq!(stats.leaves_over_tolerance, 0);
    assert!(stats.max_bound <= t);
    let (ratio, worst) = check_with_table(&iso, &out, 2e-6 * scale);
    let mut ev: Vec<(u32, u32)> = out
        .polygons()
        .filter(|p| p.region.extraordinary)
        .map(|p| (p.region.depth, p.region.face))
        .collect();
    ev.sort_unstable_by(|a, b| b.cmp(a));
    let faces: Vec<u32> = ev.iter().take(4).map(|&(_, f)| f).collect();
    assert_eq!(faces.len(), 4, "the penguin has extraordinary vertices");
    let exact = check_exactly(&iso, &out, &faces, scale);
    let ev_ratio = check_extraordinary_exactly(&iso, &out, &faces, scale);
    println!(
        "penguin T = {t}: {} polygons, {} extraordinary, deepest EV square {}, measured \
         {worst:.3e} (exact {exact:.3e}), largest measured/bound {ratio:.3}, at the EV \
         squares (exact, 8 x 8) {ev_ratio:.3}",
        stats.polygons, stats.extraordinary_leaves, ev[0].0
    );
    assert!(worst <= t + 2e-6 * scale && exact <= t);
}

/// The cube's adaptive output is closed (`check_watertight`).
#[test]
#[cfg(feature = "catmull-clark")]
fn the_cube_gives_watertight_polygons_and_triangles() {
    check_watertight("cube", &cube());
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn spot_gives_watertight_polygons_and_triangles() {
    check_watertight("spot", &spot());
}

/// Global ids make the output closed: every polygon edge and every triangle edge is used once
/// in each direction, and the Euler characteristic is the input's.
fn check_watertight(name: &str, mesh: &Mesh) {
    let scale = size(mesh);
    let iso = isolate(mesh);
    for (t, relative) in [(0.05, false), (0.01, false), (0.001, false), (0.02, true)] {
        let opts = AdaptiveOptions {
            tolerance: if relative { t } else { t * scale },
            relative,
            ..Default::default()
        };
        let (out, stats) =
            tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &opts).expect("ok");
        assert!(
            out.is_watertight(),
            "{name} T = {t}: polygons not watertight"
        );
        let triangles = out.to_triangle_mesh();
        assert!(triangles.is_watertight(), "{name} T = {t}: triangles");
        assert_eq!(
            triangles.euler_characteristic(),
            mesh.euler_characteristic(),
            "{name} T = {t}"
        );
        assert_eq!(stats.triangles, triangles.triangles.len());
        // A polygon with m vertices gives m - 2 triangles, over its own vertices (every one
        // used: no point is added inside), whether read in order or one by one.
        let expected: usize = out.polygons().map(|p| p.vertices.len() - 2).sum();
        assert_eq!(stats.triangles, expected);
        assert_eq!(out.polygons().len(), out.polygon_count());
        for (i, p) in out.polygons().enumerate() {
            assert_eq!(out.polygon(i), Some(p), "{name} T = {t}: polygon {i}");
            assert_eq!(p.triangles.len() + 2, p.vertices.len());
            let used: std::collections::BTreeSet<u32> =
                p.triangles.iter().flatten().copied().collect();
            let own: std::collections::BTreeSet<u32> = p.vertices.iter().copied().collect();
            assert_eq!(used, own, "{name} T = {t}: polygon {i}'s triangles");
        }
        assert_eq!(out.polygon(out.polygon_count()), None);
    }
}

/// Output vertices are limit points at their recorded sources (exact evaluation).
#[test]
#[cfg(feature = "catmull-clark")]
fn vertices_are_limit_points_at_their_sources() {
    let mesh = cube();
    let iso = isolate(&mesh);
    let (out, _) =
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(0.005)).expect("ok");
    let exact = ExactEvaluator::new(&iso.mesh);
    for k in (0..out.positions.len()).step_by(7).take(150) {
        let s = out.sources[k];
        let d = u64::from(s.denominator);
        let p = exact
            .evaluate(
                s.face as usize,
                &rational(u64::from(s.u), d),
                &rational(u64::from(s.v), d),
            )
            .expect("exact")
            .position;
        let e = (0..3)
            .map(|c| (p[c] - out.positions[k][c]).abs())
            .fold(0.0, f64::max);
        assert!(e < 1e-12, "vertex {k} {s:?}: {e}");
    }
}

/// Relative flatness (section 6): every regular leaf's bound is within `T` times its own base
/// quadrilateral's longer diagonal; the result is invariant under scaling (by 8, exact in f64),
/// while absolute flatness is not (and is again with `T` scaled too).
#[test]
#[cfg(feature = "catmull-clark")]
fn relative_flatness_is_scale_invariant_and_bounded_by_the_diagonal() {
    let mesh = cube();
    let mut big = mesh.clone();
    for p in &mut big.positions {
        *p = p.map(|c| 8.0 * c);
    }
    let (iso, iso_big) = (isolate(&mesh), isolate(&big));
    let t = 0.01;
    let relative = AdaptiveOptions {
        tolerance: t,
        relative: true,
        ..Default::default()
    };
    let run = |iso: &Isolation, o: &AdaptiveOptions| {
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, o).expect("ok")
    };
    let (small, s_stats) = run(&iso, &relative);
    let (large, l_stats) = run(&iso_big, &relative);
    assert_eq!(s_stats.polygons, l_stats.polygons);
    assert_eq!(small.positions.len(), large.positions.len());
    for p in small.polygons() {
        assert!(p.region.bound <= p.region.tolerance);
        if !p.region.extraordinary {
            assert!(p.region.bound <= t * p.region.diagonal * (1.0 + 1e-12));
        }
    }
    let (abs_small, _) = run(&iso, &options(0.01));
    let (abs_large, _) = run(&iso_big, &options(0.01));
    assert!(abs_large.polygon_count() > abs_small.polygon_count());
    let (abs_large_scaled, _) = run(&iso_big, &options(0.08));
    assert_eq!(abs_large_scaled.polygon_count(), abs_small.polygon_count());
}

fn grid(n: i64, mode: BoundaryMode) -> Mesh {
    let positions = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| [i as f64, j as f64, 0.5 * i as f64]))
        .collect();
    let faces: Vec<Vec<i64>> = (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| {
                let v = j * (n + 1) + i;
                vec![v, v + 1, v + n + 2, v + n + 1]
            })
        })
        .collect();
    Mesh::new(positions, &faces, &[], mode).expect("valid grid")
}

/// A flat region needs depth 0: a uniform planar grid's limit surface is affine, so every
/// regular face is one polygon however small the tolerance.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_flat_region_needs_depth_zero() {
    let flat = grid(5, BoundaryMode::EdgeAndCorner);
    let iso = isolate(&flat);
    let (out, stats) =
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(1e-9)).expect("ok");
    assert_eq!(stats.max_depth, 0);
    assert_eq!(stats.polygons, iso.mesh.faces());
    // "Edge only": the corner faces are extraordinary (one-face boundary vertices) and are
    // subdivided; every other face is still one polygon.
    let flat = grid(5, BoundaryMode::EdgeOnly);
    let iso = isolate(&flat);
    let (out2, _) =
        tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(1e-6)).expect("ok");
    let mut per_face = vec![0; iso.mesh.faces()];
    for p in out2.polygons() {
        per_face[p.region.face as usize] += 1;
    }
    let single = per_face.iter().filter(|&&c| c == 1).count();
    let corner_faces = iso
        .patches
        .iter()
        .filter(|p| p.kind.boundary && p.kind.faces == 1)
        .count();
    assert_eq!(single, iso.mesh.faces() - corner_faces);
    assert!(out.polygons().all(|p| p.region.depth == 0));
}

#[test]
#[cfg(feature = "catmull-clark")]
fn bad_options_are_refused() {
    let iso = isolate(&cube());
    for o in [
        options(0.0),
        options(f64::NAN),
        AdaptiveOptions {
            max_depth: 99,
            ..options(0.1)
        },
        AdaptiveOptions {
            min_depth: 5,
            max_depth: 4,
            ..options(0.1)
        },
    ] {
        let e = tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &o)
            .expect_err("invalid options");
        assert!(matches!(e, RuntimeError::InvalidParameter { .. }), "{e}");
    }
}

/// The uniform tessellation (min_depth = max_depth) through the same machinery has
/// `faces * 4^depth` polygons: the A/U denominator.
#[test]
#[cfg(feature = "catmull-clark")]
fn uniform_depth_gives_the_uniform_count() {
    let iso = isolate(&cube());
    let o = AdaptiveOptions {
        min_depth: 2,
        max_depth: 2,
        ..options(1.0)
    };
    let (out, stats) = tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &o).expect("ok");
    assert_eq!(out.polygon_count(), iso.mesh.faces() * 16);
    assert_eq!(stats.uniform_polygons, out.polygon_count() as f64);
    assert!(out.polygons().all(|p| p.vertices.len() == 4));
}

/// A tagged OpenSubdiv shape from `../shared/models/opensubdiv`.
fn tagged(name: &str) -> Mesh {
    load(&crate::common::models().join(format!("opensubdiv/{name}.obj")))
}

/// Parameters along a face side: a uniform 1/16 lattice and points closing in on both ends
/// (`2^-k`, `1 - 2^-k`, k = 5..12), where the squares at feature vertices go deep.
fn sample_parameters() -> Vec<f64> {
    let mut t: Vec<f64> = (0..=16).map(|i| f64::from(i) / 16.0).collect();
    for k in 5..=12 {
        let e = 0.5f64.powi(k);
        t.extend([e, 1.0 - e]);
    }
    t
}

/// Dense limit samples of every surface face by the f64 feature-adaptive limit stencils
/// (`adaptive::limit_stencils`, not Lai–Cheng's code), each against every polygon whose square
/// contains it: asserts `distance <= bound + slack`; returns (samples, largest distance,
/// largest distance / bound at hull squares).
fn check_with_limit_stencils(iso: &Isolation, out: &AdaptiveMesh, slack: f64) -> (usize, f64, f64) {
    let mesh = &iso.mesh;
    let mut by_face: Vec<Vec<AdaptivePolygon>> = vec![Vec::new(); mesh.faces()];
    for p in out.polygons() {
        by_face[p.region.face as usize].push(p);
    }
    let ts = sample_parameters();
    let queries: Vec<LimitQuery> = (0..mesh.faces())
        .filter(|&f| !mesh.holes[f])
        .flat_map(|f| {
            let ts = &ts;
            ts.iter().flat_map(move |&u| {
                ts.iter().map(move |&v| LimitQuery {
                    face: f as u32,
                    u,
                    v,
                })
            })
        })
        .collect();
    let stencils = limit_stencils(mesh, &queries).expect("limit stencils");
    let (mut worst, mut worst_ratio): (f64, f64) = (0.0, 0.0);
    for (q, stencil) in queries.iter().zip(&stencils) {
        let mut s = [0.0; 3];
        for &(v, w) in stencil {
            for (x, p) in s.iter_mut().zip(mesh.positions[v as usize]) {
                *x += w[0] * p;
            }
        }
        let mut found = false;
        for polygon in by_face[q.face as usize]
            .iter()
            .filter(|p| contains(p, q.u, q.v))
        {
            found = true;
            let d = distance_to_polygon(out, polygon, s);
            assert!(
                d <= polygon.region.bound + slack,
                "face {} at ({}, {}): distance {d} > bound {} ({:?})",
                q.face,
                q.u,
                q.v,
                polygon.region.bound,
                polygon.region
            );
            worst = worst.max(d);
            if polygon.region.extraordinary && polygon.region.bound > 0.0 {
                worst_ratio = worst_ratio.max(d / polygon.region.bound);
            }
        }
        assert!(found, "face {} ({}, {}) is in no polygon", q.face, q.u, q.v);
    }
    (queries.len(), worst, worst_ratio)
}

/// Boundary loops of the output: directed polygon edges without their reverse, followed.
fn output_boundary_loops(out: &AdaptiveMesh) -> usize {
    use std::collections::{HashMap, HashSet};
    let mut directed = HashSet::new();
    for p in out.polygons() {
        let n = p.vertices.len();
        for k in 0..n {
            directed.insert((p.vertices[k], p.vertices[(k + 1) % n]));
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            assert!(
                next.insert(a, b).is_none(),
                "vertex {a} starts two rim edges"
            );
        }
    }
    let mut seen = HashSet::new();
    let mut loops = 0;
    for &start in next.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let mut v = start;
        while seen.insert(v) {
            v = next[&v];
        }
        assert_eq!(v, start, "a rim that does not close");
    }
    loops
}

/// Lai–Cheng on tagged OpenSubdiv shapes (semi-sharp and infinitely sharp creases, corners,
/// holes, boundary modes, darts: `catmark_cubes_infsharp`'s faces at its dart take the dart
/// table patches, checked here against the adaptive limit stencils): every dense limit sample within its polygon's bound and the
/// tolerance, no leaf over the tolerance, polygons and triangles closed on closed shapes, and
/// the surface's boundary loops (holes included) and Euler characteristic kept.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn tagged_shapes_meet_the_tolerance() {
    for name in [
        "catmark_cube_creases0",
        "catmark_cube_creases1",
        "catmark_cube_corner0",
        "catmark_cube_corner4",
        "catmark_hole_test1",
        "catmark_hole_test2",
        "catmark_single_crease",
        "catmark_edgecorner",
        "catmark_cubes_infsharp",
    ] {
        let mesh = tagged(name);
        let scale = size(&mesh);
        let iso = isolate(&mesh);
        for fraction in [0.01, 0.003] {
            let t = fraction * scale;
            let (out, stats) =
                tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &options(t)).expect(name);
            assert_eq!(stats.leaves_over_tolerance, 0, "{name} T = {t}");
            let (samples, worst, hull_ratio) = check_with_limit_stencils(&iso, &out, 1e-9 * scale);
            assert!(worst <= t, "{name}: {worst} > {t}");
            let triangles = out.to_triangle_mesh();
            let loops = mesh.boundary_loops();
            if loops == 0 {
                assert!(out.is_watertight(), "{name} T = {t}: polygons");
                assert!(triangles.is_watertight(), "{name} T = {t}: triangles");
            }
            assert_eq!(output_boundary_loops(&out), loops, "{name} T = {t}");
            assert_eq!(
                triangles.euler_characteristic(),
                mesh.euler_characteristic(),
                "{name} T = {t}"
            );
            eprintln!(
                "| {name} | {fraction} | {t:.3e} | {:.3e} | {samples} | {worst:.3e} | {:.3} | {hull_ratio:.3} | {} | {} | {} | {} | {loops} |",
                stats.max_bound,
                worst / t,
                stats.polygons,
                stats.triangles,
                stats.extraordinary_leaves,
                stats.max_depth,
            );
        }
    }
}

/// Relative flatness on a tagged shape: every leaf within `tolerance` times its diagonal (the
/// whole face's for sphere-bounded squares), the dense samples within their bounds, closed.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn relative_flatness_on_a_tagged_shape() {
    let mesh = tagged("catmark_cube_creases1");
    let iso = isolate(&mesh);
    let opts = AdaptiveOptions {
        tolerance: 0.02,
        relative: true,
        ..Default::default()
    };
    let (out, stats) = tessellate_adaptive(&table(), &iso.mesh, &iso.patches, &opts).expect("ok");
    assert_eq!(stats.leaves_over_tolerance, 0);
    for p in out.polygons() {
        assert!(p.region.bound <= p.region.tolerance, "{:?}", p.region);
        assert!(p.region.diagonal > 0.0, "{:?}", p.region);
    }
    check_with_limit_stencils(&iso, &out, 1e-9 * size(&mesh));
    assert!(out.is_watertight() && out.to_triangle_mesh().is_watertight());
}
