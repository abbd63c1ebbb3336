//! Sharp features through the library facade: creases, corners, darts, semi-sharp edges and
//! holes tessellate into manifold meshes with the boundary loops the holes make, at any rates;
//! the surface of a face next to a feature passes through the limit the rules give.

use std::collections::{HashMap, HashSet};

use proptest::prelude::*;
use schemes::BoundaryMode;
use subtess::{Frame, Mesh, Rates, Scheme, Surface};

use crate::common::{cube, featured_cube};

/// Every directed edge once (a manifold, consistently oriented output), and its boundary
/// loops.
fn manifold_boundary_loops(frame: &Frame) -> usize {
    let mut directed = HashSet::new();
    for t in frame.triangles() {
        for k in 0..3 {
            assert!(
                directed.insert((t[k], t[(k + 1) % 3])),
                "directed edge {:?} twice",
                (t[k], t[(k + 1) % 3])
            );
        }
    }
    let next: HashMap<u32, u32> = directed
        .iter()
        .filter(|&&(a, b)| !directed.contains(&(b, a)))
        .map(|&(a, b)| (a, b))
        .collect();
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
    }
    loops
}

#[test]
#[cfg(feature = "catmull-clark")]
fn every_feature_tessellates_closed_and_a_hole_opens_one_loop() {
    for (hole, loops) in [(false, 0), (true, 1)] {
        let mesh = featured_cube(hole);
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
        assert_eq!(surface.boundary_loops(), loops);
        let mut tessellator = surface.tessellator(&Rates::Uniform(5)).expect("a plan");
        let frame = tessellator
            .evaluate(&mesh.positions_f32())
            .expect("a frame");
        assert_eq!(manifold_boundary_loops(&frame), loops, "hole {hole}");
        assert!(frame.positions().iter().flatten().all(|c| c.is_finite()));
    }
}

/// A pinned vertex on smooth edges is a cone's tip: an output vertex at the vertex itself (the
/// corner rule's limit), whose fan the tessellator closes as a wheel, and whose normal, though
/// the surface has no tangent plane there, is the cone's axis: at a cube's corner, by the
/// cube's symmetry about its diagonal, the diagonal (before, one face's corner normal:
/// `(-1, -1, 5)/sqrt(27)` at rate 1, 1.23 rad off it). Every rate, a closed manifold.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_cone_tip_is_an_output_vertex_with_the_cones_axis_as_normal() {
    let mut mesh = crate::common::cube();
    let tip = 7;
    mesh.set_vertex_sharpness(tip, schemes::crease::INFINITE)
        .expect("a vertex");
    let corner = mesh.positions[tip];
    let axis = corner.map(|c| c / 3f64.sqrt());
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    for n in [1, 2, 5, 8] {
        let mut tessellator = surface.tessellator(&Rates::Uniform(n)).expect("a plan");
        let frame = tessellator
            .evaluate(&mesh.positions_f32())
            .expect("a frame");
        assert_eq!(manifold_boundary_loops(&frame), 0, "rate {n}");
        let at_tip: Vec<usize> = (0..frame.positions().len())
            .filter(|&i| {
                let p = frame.positions()[i];
                (0..3).all(|c| (f64::from(p[c]) - corner[c]).abs() < 1e-6)
            })
            .collect();
        assert_eq!(at_tip.len(), 1, "rate {n}: one output vertex at the tip");
        let normal = frame.normals()[at_tip[0]];
        let cos: f64 = (0..3).map(|c| f64::from(normal[c]) * axis[c]).sum();
        assert!(cos > 1.0 - 1e-6, "rate {n}: normal {normal:?}, cos {cos}");
    }
}

/// An infinitely sharp crease separates the surface: the top face, ringed by the crease
/// loop, depends on its own four vertices only, all at z = 1, so its whole tessellation lies in
/// that plane; moving every other vertex leaves it in place, and nothing rises above it.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_crease_loop_isolates_the_face_inside_it() {
    let mesh = featured_cube(false);
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    let mut tessellator = surface.tessellator(&Rates::Uniform(4)).expect("a plan");
    let mut moved = mesh.positions_f32();
    for p in &mut moved[..4] {
        p[0] *= 1.7;
        p[2] -= 0.9;
    }
    for positions in [mesh.positions_f32(), moved] {
        let frame = tessellator.evaluate(&positions).expect("a frame");
        let mut top = 0;
        for (p, s) in frame.positions().iter().zip(frame.sources()) {
            if s.face == 1 {
                top += 1;
                assert!(
                    (p[2] - 1.0).abs() < 1e-6,
                    "{p:?} of the top face off its plane"
                );
            }
            assert!(p[2] <= 1.0 + 1e-6, "{p:?} above the crease loop");
        }
        assert!(top >= 16, "{top} points on the top face");
    }
}

/// The crease loop around the top is sampled: every output point whose source lies on it (the
/// top face's edges, the side faces' top edges) is on the closed cubic B-spline of the square
/// `(±1, ±1, 1)` (DeRose et al. 1998: an infinitely sharp crease is the B-spline of its
/// vertices), and both sides share those points (the output stays closed).
#[test]
#[cfg(feature = "catmull-clark")]
fn the_crease_is_sampled_on_its_b_spline() {
    let mesh = featured_cube(false);
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    let mut tessellator = surface.tessellator(&Rates::Uniform(6)).expect("a plan");
    let frame = tessellator
        .evaluate(&mesh.positions_f32())
        .expect("a frame");
    assert_eq!(manifold_boundary_loops(&frame), 0);
    let square = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let bspline = |t: f64| {
        let s = 1.0 - t;
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ]
    };
    let curve = |i: usize, t: f64| {
        let b = bspline(t);
        let mut p = [0.0; 2];
        for (a, w) in b.iter().enumerate() {
            let c = square[(i + 3 + a) % 4];
            p[0] += w * c[0];
            p[1] += w * c[1];
        }
        p
    };
    // The nearest point of the curve, by dense sampling refined by ternary search.
    let distance = |q: [f64; 2]| {
        let d = |i: usize, t: f64| {
            let p = curve(i, t);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
        };
        (0..4)
            .map(|i| {
                let t0 = (0..=200)
                    .map(|k| k as f64 / 200.0)
                    .min_by(|&a, &b| d(i, a).total_cmp(&d(i, b)))
                    .unwrap_or(0.0);
                let (mut lo, mut hi) = ((t0 - 0.005).max(0.0), (t0 + 0.005).min(1.0));
                for _ in 0..60 {
                    let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                    if d(i, m1) < d(i, m2) {
                        hi = m2
                    } else {
                        lo = m1
                    }
                }
                d(i, lo)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut on_crease = 0;
    for (p, s) in frame.positions().iter().zip(frame.sources()) {
        let d = s.denominator;
        let crease = match s.face {
            1 => s.u == 0 || s.u == d || s.v == 0 || s.v == d,
            2..=5 => s.v == d,
            _ => false,
        };
        if crease {
            on_crease += 1;
            assert!(
                (p[2] - 1.0).abs() < 1e-6,
                "{p:?} ({s:?}) off the crease plane"
            );
            let e = distance([f64::from(p[0]), f64::from(p[1])]);
            assert!(e < 1e-6, "{p:?} ({s:?}) is {e:e} off the crease's B-spline");
        }
    }
    assert!(on_crease >= 4 * 6, "{on_crease} points on the crease");
}

/// Vertex `(i, j)` (indices taken modulo the sides) of [`wavy_torus`]`(n, m)`.
fn torus_vertex(n: i64, m: i64, i: i64, j: i64) -> usize {
    (i.rem_euclid(n) * m + j.rem_euclid(m)) as usize
}

/// A torus of `n x m` quads (all valence 4), its tube's radius rippled three times around.
fn wavy_torus(n: i64, m: i64) -> Mesh {
    let positions = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| {
                let (a, b) = (
                    std::f64::consts::TAU * i as f64 / n as f64,
                    std::f64::consts::TAU * j as f64 / m as f64,
                );
                let r = 3.0 + b.cos() + 0.1 * (3.0 * a).sin();
                [r * a.cos(), r * a.sin(), b.sin()]
            })
        })
        .collect();
    let at = |i, j| torus_vertex(n, m, i, j) as i64;
    let faces: Vec<Vec<i64>> = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        })
        .collect();
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a torus")
}

/// `mesh` with the edges `crease` infinitely sharp.
fn creased(mut mesh: Mesh, crease: &[(usize, usize)]) -> Mesh {
    for &(a, b) in crease {
        mesh.set_edge_sharpness(a, b, schemes::crease::INFINITE)
            .expect("an edge");
    }
    mesh
}

/// Faces beside a straight infinitely sharp crease take the tensor-product path, their rows
/// beyond the crease replaced by phantom points (`adaptive::phantom_grid`): on a torus crossed
/// by two crease loops every face is separable (the four at the crossing too: four sharp edges
/// pin it, and each face there is a pinned corner's patch, phantoms beyond both sides), and
/// every output point is the feature-adaptive limit at its source (f64 refinement with the
/// crease rules, `adaptive::limit_stencils`, no patch and no table): positions to 1e-6 of the
/// torus's size, the normals of the faces' own points to 1e-5 rad.
#[test]
#[cfg(feature = "catmull-clark")]
fn faces_along_a_straight_crease_are_b_spline_patches_with_phantom_points() {
    let (n, m) = (16, 8);
    let at = |i, j| torus_vertex(n, m, i, j);
    let mut crease = Vec::new();
    for i in 0..n {
        crease.push((at(i, 0), at(i + 1, 0)));
    }
    for j in 0..m {
        crease.push((at(n / 2, j), at(n / 2, j + 1)));
    }
    let mesh = creased(wavy_torus(n, m), &crease);
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    let mut tessellator = surface.tessellator(&Rates::Uniform(5)).expect("a plan");
    assert_eq!(tessellator.separable_faces(), (n * m) as usize);
    let frame = tessellator
        .evaluate(&mesh.positions_f32())
        .expect("a frame");
    // The torus spans 8.2 units.
    assert_on_the_adaptive_limit(&mesh, &frame, 8.2e-6, 1e-5, 0);
}

/// Every output point of `frame` is the feature-adaptive limit of `mesh` at its source (f64
/// refinement with the crease rules, `adaptive::limit_stencils`: no patch, no table) within
/// `position` in each coordinate, and the normals of the faces' own points (not on an edge)
/// within `normal` rad; the output is manifold with `boundary_loops` loops.
#[cfg(feature = "catmull-clark")]
fn assert_on_the_adaptive_limit(
    mesh: &Mesh,
    frame: &Frame,
    position: f64,
    normal: f64,
    boundary_loops: usize,
) {
    use subtess::scheme::catmull_clark::adaptive::{limit_of, limit_stencils, LimitQuery};
    assert_eq!(manifold_boundary_loops(frame), boundary_loops);
    let queries: Vec<LimitQuery> = frame
        .sources()
        .iter()
        .map(|s| {
            let (u, v) = s.uv();
            LimitQuery { face: s.face, u, v }
        })
        .collect();
    let limits = limit_stencils(mesh, &queries).expect("a limit at every source");
    let unit = |d: [f64; 3]| {
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        d.map(|c| c / l)
    };
    let (mut worst_position, mut worst_normal) = (0.0f64, 0.0f64);
    for ((p, normal), (s, stencil)) in frame
        .positions()
        .iter()
        .zip(frame.normals())
        .zip(frame.sources().iter().zip(&limits))
    {
        let [q, du, dv] = limit_of(stencil, mesh);
        let e = (0..3)
            .map(|c| (f64::from(p[c]) - q[c]).abs())
            .fold(0.0, f64::max);
        worst_position = worst_position.max(e);
        let inside = 0 < s.u && s.u < s.denominator && 0 < s.v && s.v < s.denominator;
        if inside {
            let want = unit([
                du[1] * dv[2] - du[2] * dv[1],
                du[2] * dv[0] - du[0] * dv[2],
                du[0] * dv[1] - du[1] * dv[0],
            ]);
            // The angle from the cross product's length (acos loses it near 0).
            let n = normal.map(f64::from);
            let cross = [
                n[1] * want[2] - n[2] * want[1],
                n[2] * want[0] - n[0] * want[2],
                n[0] * want[1] - n[1] * want[0],
            ];
            let dot: f64 = (0..3).map(|c| n[c] * want[c]).sum();
            let a = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2])
                .sqrt()
                .atan2(dot);
            worst_normal = worst_normal.max(a);
        }
    }
    assert!(
        worst_position < position,
        "positions {worst_position:e} from the limit"
    );
    assert!(
        worst_normal < normal,
        "normals {worst_normal:e} rad from the limit"
    );
}

/// Faces along a boundary are B-spline patches with phantom points too (the boundary rules are
/// the crease rules), and so are the one-face corners "edge and corner" pins: on a 5 x 4 grid of
/// quads every face is separable in that mode, all but the four corner faces in "edge only"
/// mode (there a one-face corner takes the crease rule, a table patch), and every output point
/// is the feature-adaptive limit at its source.
#[test]
#[cfg(feature = "catmull-clark")]
fn boundary_faces_and_pinned_corners_are_b_spline_patches_with_phantom_points() {
    let (w, h) = (5i64, 4i64);
    let positions: Vec<[f64; 3]> = (0..=h)
        .flat_map(|j| {
            (0..=w).map(move |i| {
                let (x, y) = (i as f64, j as f64);
                [x, y, 0.3 * (1.3 * x).sin() * (0.9 * y).cos()]
            })
        })
        .collect();
    let at = |i: i64, j: i64| j * (w + 1) + i;
    let faces: Vec<Vec<i64>> = (0..h)
        .flat_map(|j| {
            (0..w).map(move |i| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        })
        .collect();
    for (mode, separable) in [
        (BoundaryMode::EdgeAndCorner, 20),
        (BoundaryMode::EdgeOnly, 16),
    ] {
        let mesh = Mesh::new(positions.clone(), &faces, &[], mode).expect("a grid");
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
        let mut tessellator = surface.tessellator(&Rates::Uniform(5)).expect("a plan");
        assert_eq!(tessellator.separable_faces(), separable, "{mode:?}");
        assert_eq!(tessellator.refined_faces(), 0, "{mode:?}");
        let frame = tessellator
            .evaluate(&mesh.positions_f32())
            .expect("a frame");
        assert_on_the_adaptive_limit(&mesh, &frame, 1e-6 * 6.5, 1e-5, 1);
    }
}

/// An infinitely sharp crease vertex splits its fan into two sectors that subdivide apart, each
/// as a boundary vertex with as many faces: the faces there take the table's boundary patches
/// (`scheme::patch::crease_sector`), not the refinement. A cube whose top face's rim is a crease
/// (after one isolation step, valence-3 corners with sectors of one face on top and two on the
/// sides) and a torus crossed by a rectangular crease loop (valence-4 corners with sectors of
/// one and three faces): no face is refined, and every output point is the feature-adaptive
/// limit at its source.
#[test]
#[cfg(feature = "catmull-clark")]
fn faces_at_crease_vertices_are_boundary_patches_of_their_sectors() {
    use subtess::scheme::catmull_clark::isolate::isolate;
    use subtess::scheme::patch::crease_sector;
    let cube = creased(cube(), &[(4, 5), (5, 7), (7, 6), (6, 4)]);
    let (n, m) = (16, 8);
    let at = |i, j| torus_vertex(n, m, i, j);
    // The rectangle with corners (2, 2) and (6, 5).
    let mut rim = Vec::new();
    for i in 2..6 {
        rim.extend([(at(i, 2), at(i + 1, 2)), (at(i, 5), at(i + 1, 5))]);
    }
    for j in 2..5 {
        rim.extend([(at(2, j), at(2, j + 1)), (at(6, j), at(6, j + 1))]);
    }
    let torus = creased(wavy_torus(n, m), &rim);
    // The cube's 12 faces at its top rim are sector patches: 4 one-face sectors on top, 8 at a
    // two-face sector of a valence-3 corner, which are B-spline patches with phantom points
    // (tensor products); the rest are smooth. The torus's 28 faces at the rectangle are: the 16
    // at its corners table patches (one-face sectors inside, three-face ones outside), the 12
    // along its sides tensor products.
    for (mesh, size, sector_faces, separable) in [(&cube, 2.0, 12, 8), (&torus, 8.2, 28, 112)] {
        let (isolated, _, _) = isolate(mesh).expect("an isolation");
        let sectors = (0..isolated.faces())
            .filter(|&f| crease_sector(&isolated, f).is_some())
            .count();
        assert_eq!(sectors, sector_faces);
        let surface = Surface::new(mesh, Scheme::CatmullClark).expect("a surface");
        let mut tessellator = surface.tessellator(&Rates::Uniform(6)).expect("a plan");
        assert_eq!(tessellator.refined_faces(), 0);
        assert_eq!(tessellator.separable_faces(), separable);
        let frame = tessellator
            .evaluate(&mesh.positions_f32())
            .expect("a frame");
        assert_on_the_adaptive_limit(mesh, &frame, 1e-6 * size, 1e-5, 0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Random per-face rates on the featured cube (with and without its hole), and on a grid
    /// with boundary in both boundary modes and in "none" (boundary faces are holes).
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn random_rates_stay_manifold(rates in proptest::collection::vec(1u32..7, 6), hole in any::<bool>()) {
        let mesh = featured_cube(hole);
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
        let mut tessellator = surface.tessellator(&Rates::PerFace(rates)).expect("a plan");
        let frame = tessellator.evaluate(&mesh.positions_f32()).expect("a frame");
        prop_assert_eq!(manifold_boundary_loops(&frame), usize::from(hole));
    }
}

/// `interpolateboundary 0`: a face at a boundary vertex whose boundary edges are not tagged
/// sharp makes no surface (OpenSubdiv's `VTX_BOUNDARY_NONE`); a 4 x 4 grid keeps its inner
/// 2 x 2 faces, one loop around them.
#[test]
#[cfg(feature = "catmull-clark")]
fn no_boundary_interpolation_drops_the_boundary_faces() {
    let mut text = String::new();
    for j in 0..5 {
        for i in 0..5 {
            text += &format!("v {i} {j} {}\n", (i * j) as f64 * 0.1);
        }
    }
    for j in 0..4 {
        for i in 0..4 {
            let v = j * 5 + i + 1;
            text += &format!("f {} {} {} {}\n", v, v + 1, v + 6, v + 5);
        }
    }
    text += "t interpolateboundary 1/0/0 0\n";
    let obj = subtess::io::obj::parse_obj(&text).expect("valid OBJ");
    let (mesh, warnings) = Mesh::from_obj(&obj).expect("a mesh");
    assert!(warnings.is_empty(), "{warnings:?}");
    let kept: Vec<usize> = (0..16).filter(|&f| !mesh.holes[f]).collect();
    assert_eq!(kept, vec![5, 6, 9, 10]);
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    let mut tessellator = surface.tessellator(&Rates::Uniform(3)).expect("a plan");
    let frame = tessellator
        .evaluate(&mesh.positions_f32())
        .expect("a frame");
    assert_eq!(manifold_boundary_loops(&frame), 1);
}

/// A fin: three quads on one edge, a non-manifold edge OpenSubdiv makes infinitely sharp with
/// pinned corners at its ends. Each sheet is its own patch with its own boundary, and each
/// reaches the shared edge along the same straight segment (a crease between two pinned
/// corners); frames take the input's six vertices.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_non_manifold_fin_splits_into_sheets_meeting_on_the_edge() {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = vec![vec![0, 1, 2, 3], vec![1, 0, 4, 5], vec![0, 1, 6, 7]];
    let mesh = Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("split");
    assert_eq!(mesh.input_vertices(), 8);
    let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
    assert_eq!(surface.input_vertices(), 8);
    let n = 4;
    let mut tessellator = surface.tessellator(&Rates::Uniform(n)).expect("a plan");
    let frame = tessellator
        .evaluate(&mesh.positions_f32())
        .expect("a frame");
    assert_eq!(manifold_boundary_loops(&frame), 3);
    let on_edge = frame
        .positions()
        .iter()
        .filter(|p| p[1].abs() < 1e-6 && p[2].abs() < 1e-6)
        .count();
    // Per sheet: the edge's 2^steps isolated segments, n - 1 curve points each, and their ends.
    let segments = 1usize << surface.isolation_steps();
    assert_eq!(on_edge, 3 * (segments * n as usize + 1));
}
