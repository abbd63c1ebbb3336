//! Bézier patch input, bicubic evaluation, displacement maps, edge tests and the adaptive
//! tessellator of Espino et al. (`subtess::tessellate::bezier`). Tests on the Utah teapot and
//! teacup need `../shared/models` and are ignored where it was absent at build time.
//!
//! Where expected numbers come from: the patch counts and the open seams are those of
//! `../shared/models/README.md` (32 / 26 patches; the teapot's open rim, lid edge, handle and
//! spout ends); geometric references (de Casteljau evaluation, finite differences, brute-force
//! distances, the seams found from the raw control rows) are computed here independently of
//! the code under test; the distance cases are worked by hand.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use proptest::prelude::*;
use subtess::mesh::triangle_mesh::TriangleMesh;
use subtess::tessellate::bezier::bicubic::bernstein;
use subtess::tessellate::bezier::displacement_map::{signed_distance, DistanceCase};
use subtess::tessellate::bezier::edge_tests::{map4p_points, map8p_points, map_test};
use subtess::tessellate::bezier::mesh_error::{point_triangle_distance, TriangleGrid};
use subtess::tessellate::bezier::{
    tessellate_bezier, tessellate_bezier_full, BezierOptions, BezierPatches, BicubicPatch,
    DisplacementMap, EdgeTest,
};
use subtess::RuntimeError;

type P3 = [f64; 3];

/// A patch file from `../shared/models/bezier`.
fn load(name: &str) -> BezierPatches {
    let path = crate::common::models().join("bezier").join(name);
    BezierPatches::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

// ---------------------------------------------------------------- independent references

fn lerp(a: P3, b: P3, t: f64) -> P3 {
    [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
}

/// De Casteljau on a cubic: three rounds of linear interpolation.
fn casteljau(p: [P3; 4], t: f64) -> P3 {
    let a = [
        lerp(p[0], p[1], t),
        lerp(p[1], p[2], t),
        lerp(p[2], p[3], t),
    ];
    let b = [lerp(a[0], a[1], t), lerp(a[1], a[2], t)];
    lerp(b[0], b[1], t)
}

/// The surface by de Casteljau: each row along u, then the results along v.
fn surface(c: &[P3; 16], u: f64, v: f64) -> P3 {
    let rows: Vec<P3> = (0..4)
        .map(|i| casteljau([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]], u))
        .collect();
    casteljau([rows[0], rows[1], rows[2], rows[3]], v)
}

fn dist(a: P3, b: P3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn len(a: P3) -> f64 {
    dist(a, [0.0; 3])
}

fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A deterministic pseudo-random patch (xorshift), coordinates in [-1, 1].
fn random_patch(seed: u64) -> BicubicPatch {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut c = [[0.0; 3]; 16];
    for (k, p) in c.iter_mut().enumerate() {
        // A wavy grid: keeps the patch regular (non-degenerate) for the derivative checks.
        let (i, j) = ((k / 4) as f64, (k % 4) as f64);
        *p = [j + 0.3 * next(), i + 0.3 * next(), 0.5 * next()];
    }
    BicubicPatch::new(c)
}

// ---------------------------------------------------------------- parsers

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn teapot_in_both_formats_gives_identical_patches_and_teacup_has_26() {
    let (txt, bpt, cup) = (load("teapot.txt"), load("teapot.bpt"), load("teacup.txt"));
    assert_eq!(txt.len(), 32);
    assert_eq!(bpt.len(), 32);
    assert_eq!(txt, bpt, "every control point identical, same order");
    assert_eq!(cup.len(), 26);
    // README: 8 teapot patches have a collapsed row (lid knob 21–24, bottom 29–32).
    let collapsed: Vec<usize> = (0..32)
        .filter(|&p| (0..4).any(|s| txt.patches[p].side_collapsed(s)))
        .map(|p| p + 1)
        .collect();
    assert_eq!(collapsed, vec![21, 22, 23, 24, 29, 30, 31, 32]);
    assert!((0..26).all(|p| (0..4).all(|s| !cup.patches[p].side_collapsed(s))));
}

fn patch_error(r: Result<BezierPatches, RuntimeError>) -> (usize, String) {
    match r {
        Err(RuntimeError::ParseFile {
            path,
            line,
            message,
        }) => {
            assert_eq!(path, "in.txt");
            (line, message)
        }
        other => panic!("expected a ParseFile error, got {other:?}"),
    }
}

#[test]
fn malformed_newell_inputs_are_clear_errors() {
    let idx: String = (1..=16)
        .map(|k| k.to_string())
        .collect::<Vec<_>>()
        .join(",");
    let verts: String = (0..16).map(|k| format!("{k}.0,0,1\n")).collect();
    let good = format!("1\n{idx}\n16\n{verts}");
    assert_eq!(
        BezierPatches::parse_newell(&good, "in.txt")
            .map(|p| p.len())
            .ok(),
        Some(1)
    );
    let cases: Vec<(String, usize, &str)> = vec![
        (String::new(), 1, "unexpected end of file"),
        ("x\n".into(), 1, "the number of patches"),
        ("0\n".into(), 1, "no patches"),
        (format!("1\n1,2,3\n16\n{verts}"), 2, "expected 16"),
        ("1\n3 3\n".to_string(), 2, ".bpt"),
        (
            format!("1\n{}\n16\n{verts}", idx.replace("7", "a")),
            2,
            "`a` is not a vertex index",
        ),
        (
            format!("1\n{}\n16\n{verts}", idx.replacen("1", "0", 1)),
            2,
            "1-based",
        ),
        (
            format!("1\n{}\n16\n{verts}", idx.replace(",16", ",17")),
            2,
            "out of range 1..=16",
        ),
        (format!("1\n{idx}\n16\n1,2\n"), 4, "expected 3"),
        (format!("1\n{idx}\n16\n1,2,nan\n"), 4, "not finite"),
        (format!("1\n{idx}\n16\n1,2,q\n"), 4, "`q` is not a number"),
        (format!("1\n{idx}\n17\n{verts}"), 20, "vertex 17 of 17"),
        (format!("{good}junk\n"), 20, "unexpected content"),
    ];
    for (text, line, needle) in cases {
        let (l, m) = patch_error(BezierPatches::parse_newell(&text, "in.txt"));
        assert_eq!(l, line, "{text:?}: {m}");
        assert!(m.contains(needle), "{text:?}: `{m}` lacks `{needle}`");
    }
    // The Display form names file:line.
    let e = BezierPatches::parse_newell("1\n1,2\n", "in.txt").expect_err("bad");
    assert!(e.to_string().starts_with("in.txt:2: "), "{e}");
}

#[test]
fn malformed_bpt_inputs_are_clear_errors() {
    let pts: String = (0..16).map(|k| format!("{k} 0 1\n")).collect();
    let good = format!("1\n3 3\n{pts}\n");
    assert_eq!(
        BezierPatches::parse_bpt(&good, "in.txt")
            .map(|p| p.len())
            .ok(),
        Some(1)
    );
    let cases: Vec<(String, usize, &str)> = vec![
        ("1\n2 3\n".into(), 2, "not supported"),
        ("1\nx\n".into(), 2, "degree line"),
        (
            format!("1\n3 3\n{}", &pts[..pts.len() - 7]),
            18,
            "control point 16 of 16",
        ),
        (format!("1\n3 3\n1 2\n{pts}"), 3, "expected 3"),
        (format!("2\n3 3\n{pts}"), 19, "patch 2"),
        (format!("{good}9\n"), 20, "unexpected content"),
    ];
    for (text, line, needle) in cases {
        let (l, m) = patch_error(BezierPatches::parse_bpt(&text, "in.txt"));
        assert_eq!(l, line, "{text:?}: {m}");
        assert!(m.contains(needle), "{text:?}: `{m}` lacks `{needle}`");
    }
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let e = BezierPatches::read(Path::new("/nonexistent/teapot.bpt")).expect_err("missing");
    assert!(matches!(e, RuntimeError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/teapot.bpt"));
}

// ---------------------------------------------------------------- bicubic evaluation

#[test]
fn bicubic_matches_de_casteljau_and_finite_differences() {
    for seed in 1..20 {
        let patch = random_patch(seed);
        for &(u, v) in &[(0.0, 0.0), (1.0, 1.0), (0.3, 0.7), (0.5, 0.5), (0.91, 0.05)] {
            let s = patch.position(u, v);
            assert!(
                dist(s, surface(&patch.control, u, v)) < 1e-14,
                "{seed} {u} {v}"
            );
            // First derivatives against central differences of the de Casteljau surface.
            let h = 1e-5;
            let (u0, u1) = ((u - h).max(0.0), (u + h).min(1.0));
            let (v0, v1) = ((v - h).max(0.0), (v + h).min(1.0));
            let fd_u = [0, 1, 2].map(|k| {
                (surface(&patch.control, u1, v)[k] - surface(&patch.control, u0, v)[k]) / (u1 - u0)
            });
            let fd_v = [0, 1, 2].map(|k| {
                (surface(&patch.control, u, v1)[k] - surface(&patch.control, u, v0)[k]) / (v1 - v0)
            });
            let tol = 1e-4 * (1.0 + len(fd_u) + len(fd_v));
            assert!(dist(patch.partial(u, v, 1, 0), fd_u) < tol, "{seed} du");
            assert!(dist(patch.partial(u, v, 0, 1), fd_v) < tol, "{seed} dv");
            let n = patch.normal(u, v);
            assert!((len(n) - 1.0).abs() < 1e-12);
            let c = cross(fd_u, fd_v);
            assert!(dist(n, c.map(|x| x / len(c))) < 1e-4, "{seed} normal");
        }
        // Corners are exactly the corner control points.
        assert_eq!(patch.position(0.0, 0.0), patch.control[0]);
        assert_eq!(patch.position(1.0, 0.0), patch.control[3]);
        assert_eq!(patch.position(1.0, 1.0), patch.control[15]);
        assert_eq!(patch.position(0.0, 1.0), patch.control[12]);
    }
}

#[test]
fn bernstein_basis_is_a_partition_of_unity() {
    for k in 0..=100 {
        let t = k as f64 / 100.0;
        for n in 0..=3 {
            let b = bernstein(n, t);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!(b.iter().all(|&x| x >= 0.0));
        }
        // A patch whose control points all equal X is the point X, with zero derivatives.
        let x = [1.25, -3.5, 0.125];
        let patch = BicubicPatch::new([x; 16]);
        let s = patch.position(t, 1.0 - t);
        assert!(dist(s, x) < 1e-14);
        assert_eq!(patch.partial(t, 0.3, 1, 0), [0.0; 3]);
    }
    // Translation invariance (affine combination): S(P + w) = S(P) + w.
    let p = random_patch(7);
    let w = [3.0, -2.0, 0.5];
    let q = BicubicPatch::new(p.control.map(|c| [c[0] + w[0], c[1] + w[1], c[2] + w[2]]));
    let (a, b) = (p.position(0.37, 0.61), q.position(0.37, 0.61));
    assert!(dist([a[0] + w[0], a[1] + w[1], a[2] + w[2]], b) < 1e-14);
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn degenerate_teapot_patches_have_finite_unit_limit_normals() {
    let teapot = load("teapot.txt");
    for p in [20, 21, 22, 23, 28, 29, 30, 31] {
        let patch = &teapot.patches[p];
        let s = (0..4)
            .find(|&s| patch.side_collapsed(s))
            .expect("collapsed side");
        for k in 0..=16 {
            let t = k as f64 / 16.0;
            let (u, v) = match s {
                0 => (t, 0.0),
                1 => (1.0, t),
                2 => (t, 1.0),
                _ => (0.0, t),
            };
            let n = patch.normal(u, v);
            assert!(
                n.iter().all(|x| x.is_finite()),
                "patch {} at {u},{v}",
                p + 1
            );
            assert!(
                (len(n) - 1.0).abs() < 1e-12,
                "patch {} at {u},{v}: {n:?}",
                p + 1
            );
            // The limit: the plain cross product of de Casteljau differences just inside.
            let e = 1e-4;
            let (ui, vi) = match s {
                0 => (u, e),
                1 => (1.0 - e, v),
                2 => (u, 1.0 - e),
                _ => (e, v),
            };
            let h = 1e-7;
            let c = &patch.control;
            let du = [0, 1, 2].map(|q| {
                (surface(c, (ui + h).min(1.0), vi)[q] - surface(c, (ui - h).max(0.0), vi)[q])
                    / ((ui + h).min(1.0) - (ui - h).max(0.0))
            });
            let dv = [0, 1, 2].map(|q| {
                (surface(c, ui, (vi + h).min(1.0))[q] - surface(c, ui, (vi - h).max(0.0))[q])
                    / ((vi + h).min(1.0) - (vi - h).max(0.0))
            });
            let inside = cross(du, dv);
            let inside = inside.map(|x| x / len(inside));
            assert!(
                dist(n, inside) < 1e-2,
                "patch {} at {u},{v}: {n:?} vs {inside:?}",
                p + 1
            );
        }
    }
}

// ---------------------------------------------------------------- displacement map, tests

#[test]
fn the_three_distance_cases_of_fig_2() {
    // One triangle in z = 0: a point above its interior is S1, at its height.
    let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
    assert_eq!(
        signed_distance(&[t], [0.5, 0.5, 0.3]),
        (0.3, DistanceCase::OneTriangle)
    );
    assert_eq!(
        signed_distance(&[t], [0.5, 0.5, -0.2]),
        (-0.2, DistanceCase::OneTriangle)
    );
    // A convex ridge along the y axis: two triangles sloping down at 45° each side. A point
    // straight above the ridge lies over neither (S2): its distance is to the ridge edge.
    let ridge = [
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, -1.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
    ];
    let (d, case) = signed_distance(&ridge, [0.0, 0.5, 0.4]);
    assert_eq!(case, DistanceCase::NearestEdge);
    assert!((d - 0.4).abs() < 1e-15, "{d}");
    // A concave valley (the ridge upside down): a point above the valley floor but off
    // centre lies over both triangles (S3); the nearer plane is chosen.
    let valley = [
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 1.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
    ];
    let p = [0.1, 0.5, 0.3];
    let (d, case) = signed_distance(&valley, p);
    assert_eq!(case, DistanceCase::SeveralTriangles);
    // Planes x + z = 0 (normal (1,0,1)/√2 or its opposite) and z − x = 0: distances
    // |0.1 + 0.3|/√2 and |0.3 − 0.1|/√2; the nearer is 0.2/√2.
    assert!((d.abs() - 0.2 / 2f64.sqrt()).abs() < 1e-15, "{d}");
}

#[test]
fn map4p_and_map8p_points_follow_eq_2() {
    // Edge (0,0)–(1,0): midpoint (0.5, 0), (ue, ve) = (−0.5, 0).
    let [p3, p4] = map4p_points((0.0, 0.0), (1.0, 0.0));
    assert_eq!(p3, (0.5, -0.5));
    assert_eq!(p4, (0.5, 0.5));
    let p8 = map8p_points((0.0, 0.0), (1.0, 0.0));
    assert_eq!(p8, [(0.0, -0.5), (0.0, 0.5), (1.0, -0.5), (1.0, 0.5)]);
}

#[test]
fn map_tests_compare_differences_with_the_threshold_eq_1_and_3() {
    // A map equal to v (linear, varying across the edge direction u only).
    let (m, n) = (5, 5);
    let values = (0..n)
        .flat_map(|j| (0..m).map(move |_| j as f64 / (n - 1) as f64))
        .collect();
    let map = DisplacementMap {
        m,
        n,
        values,
        cases: [0; 3],
    };
    let (p1, p2) = ((0.25, 0.5), (0.75, 0.5));
    // Along the edge the map is constant: Map2p never splits; across it, d3/d4 differ by
    // 0.25 (half the edge length).
    assert!(!map_test(EdgeTest::Map2p, &map, p1, p2, 0.01));
    assert!(map_test(EdgeTest::Map4p, &map, p1, p2, 0.2));
    assert!(!map_test(EdgeTest::Map4p, &map, p1, p2, 0.3));
    assert!(map_test(EdgeTest::Map8p, &map, p1, p2, 0.2));
    // An edge along v sees the variation in Map2p: |d1 − d12| = 0.25.
    assert!(map_test(
        EdgeTest::Map2p,
        &map,
        (0.5, 0.25),
        (0.5, 0.75),
        0.2
    ));
    assert!(!map_test(
        EdgeTest::Map2p,
        &map,
        (0.5, 0.25),
        (0.5, 0.75),
        0.3
    ));
}

// ---------------------------------------------------------------- error measure

#[test]
fn point_triangle_distance_is_exact_and_the_grid_finds_the_nearest() {
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let d = |p: P3| point_triangle_distance(p, &[t[0], t[1], t[2]]);
    assert!((d([0.2, 0.2, 0.5]) - 0.5).abs() < 1e-15, "over the face");
    assert!(
        (d([-1.0, -1.0, 0.0]) - 2f64.sqrt()).abs() < 1e-15,
        "corner region"
    );
    assert!((d([0.5, -2.0, 0.0]) - 2.0).abs() < 1e-15, "edge region");
    assert!(
        (d([1.0, 1.0, 0.0]) - 0.5f64.sqrt()).abs() < 1e-15,
        "hypotenuse"
    );
    // Random triangles and points: never above a dense barycentric sampling of the triangle,
    // and within the sampling's resolution of it.
    let patch = random_patch(3);
    let tris: Vec<[P3; 3]> = (0..40)
        .map(|k| {
            let f = k as f64 / 40.0;
            [
                patch.position(f, 0.1),
                patch.position(0.9 - 0.5 * f, 0.8),
                patch.position(0.5, f),
            ]
        })
        .collect();
    let grid = TriangleGrid::new(tris.clone());
    for k in 0..200 {
        let f = k as f64 / 200.0;
        let p = [3.0 * f - 1.0, (7.0 * f).sin() * 2.0, (13.0 * f).cos()];
        let brute = tris
            .iter()
            .map(|t| point_triangle_distance(p, &[t[0], t[1], t[2]]))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(grid.nearest_distance(p), brute, "the grid is exact");
        let t = tris[k % tris.len()];
        let exact = point_triangle_distance(p, &[t[0], t[1], t[2]]);
        let mut sampled = f64::INFINITY;
        let s = 60;
        for i in 0..=s {
            for j in 0..=s - i {
                let (a, b) = (i as f64 / s as f64, j as f64 / s as f64);
                let q =
                    [0, 1, 2].map(|c| t[0][c] + a * (t[1][c] - t[0][c]) + b * (t[2][c] - t[0][c]));
                sampled = sampled.min(dist(p, q));
            }
        }
        let edge = dist(t[0], t[1]).max(dist(t[0], t[2])).max(dist(t[1], t[2]));
        assert!(exact <= sampled + 1e-12, "{exact} > {sampled}");
        assert!(sampled - exact <= edge / s as f64, "{exact} vs {sampled}");
    }
}

// ---------------------------------------------------------------- tessellation

/// The open seams expected from the raw control rows (sides whose four control points no
/// other side has, in either order), grouped into loops by shared end points.
fn expected_seams(patches: &BezierPatches) -> Vec<HashSet<(u32, u8)>> {
    let key = |p: &BicubicPatch, s: usize| {
        let pts = p.side_points(s).map(|q| q.map(|x| (x + 0.0).to_bits()));
        let mut rev = pts;
        rev.reverse();
        (pts.min(rev), pts.iter().all(|&q| q == pts[0]))
    };
    let mut count: HashMap<_, usize> = HashMap::new();
    for p in &patches.patches {
        for s in 0..4 {
            *count.entry(key(p, s).0).or_default() += 1;
        }
    }
    let mut open = Vec::new();
    for (k, p) in patches.patches.iter().enumerate() {
        for s in 0..4 {
            let (kk, collapsed) = key(p, s);
            if count[&kk] == 1 && !collapsed {
                let e = p.side_points(s);
                open.push(((k as u32, s as u8), e[0], e[3]));
            }
        }
    }
    // Union of curves sharing an end point.
    let mut group: Vec<usize> = (0..open.len()).collect();
    fn find(g: &mut Vec<usize>, x: usize) -> usize {
        if g[x] != x {
            let r = find(g, g[x]);
            g[x] = r;
        }
        g[x]
    }
    for a in 0..open.len() {
        for b in 0..open.len() {
            let (ea, eb) = (&open[a], &open[b]);
            if ea.1 == eb.1 || ea.1 == eb.2 || ea.2 == eb.1 || ea.2 == eb.2 {
                let (ra, rb) = (find(&mut group, a), find(&mut group, b));
                group[ra] = rb;
            }
        }
    }
    let mut loops: HashMap<usize, HashSet<(u32, u8)>> = HashMap::new();
    for (k, curve) in open.iter().enumerate() {
        let r = find(&mut group, k);
        loops.entry(r).or_default().insert(curve.0);
    }
    loops.into_values().collect()
}

/// The mesh's boundary loops, each as the set of patch sides its vertices lie inside
/// (by their sources), after checking the boundary is consistently oriented.
fn boundary_seams(mesh: &TriangleMesh, d: u32) -> Vec<HashSet<(u32, u8)>> {
    let edges = mesh
        .boundary_edges()
        .expect("no edge used twice in one direction");
    let mut next = HashMap::new();
    for &(a, b) in &edges {
        assert!(
            next.insert(a, b).is_none(),
            "boundary vertex {a} on two loops"
        );
    }
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for &(start, _) in &edges {
        if seen.contains(&start) {
            continue;
        }
        let mut sides = HashSet::new();
        let mut v = start;
        while seen.insert(v) {
            let s = mesh.sources[v as usize];
            assert_eq!(s.denominator, d);
            let on = |x: u32| x == 0 || x == d;
            assert!(
                on(s.u) || on(s.v),
                "boundary vertex {v} inside patch {}",
                s.face
            );
            let side = match (s.u, s.v) {
                (_, 0) if !on(s.u) => Some(0),
                (u, _) if u == d && !on(s.v) => Some(1),
                (_, w) if w == d && !on(s.u) => Some(2),
                (0, _) if !on(s.v) => Some(3),
                _ => None, // a corner
            };
            if let Some(side) = side {
                sides.insert((s.face, side));
            }
            v = next[&v];
        }
        assert_eq!(v, start, "the loop closes");
        out.push(sides);
    }
    out
}

fn check_seams(patches: &BezierPatches, options: &BezierOptions, loops: usize) {
    let t = tessellate_bezier_full(patches, options).unwrap_or_else(|e| panic!("{e}"));
    let expected = expected_seams(patches);
    assert_eq!(expected.len(), loops, "README's open seams");
    let d = 3u32 << options.max_depth;
    let mut got = boundary_seams(&t.mesh, d);
    assert_eq!(got.len(), loops, "{options:?}");
    for e in &expected {
        let k = got
            .iter()
            .position(|g| g == e)
            .unwrap_or_else(|| panic!("{options:?}: seam {e:?} not among {got:?}"));
        got.remove(k);
    }
    // Every normal is a finite unit vector; every vertex is the surface at its source.
    for (k, n) in t.mesh.normals.iter().enumerate() {
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((l - 1.0).abs() < 1e-5, "vertex {k}: normal {n:?}");
    }
    for (k, s) in t.mesh.sources.iter().enumerate().step_by(7) {
        let (u, v) = s.uv();
        let exact = surface(&patches.patches[s.face as usize].control, u, v);
        let p = t.mesh.positions[k].map(f64::from);
        assert!(dist(p, exact) < 1e-6 * (1.0 + len(exact)));
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn teapot_and_teacup_are_watertight_except_their_open_seams() {
    let (teapot, teacup) = (load("teapot.txt"), load("teacup.txt"));
    for test in EdgeTest::ALL {
        for th in [1.0, 0.05, 0.01] {
            let options = BezierOptions {
                test,
                threshold: th,
                error_samples: 0,
                ..Default::default()
            };
            // Teapot (README): rim, lid edge, two handle ends, two spout ends.
            check_seams(&teapot, &options, 6);
            // Teacup: inner bottom hole, outer bottom edge, two handle ends.
            check_seams(&teacup, &options, 4);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Over thresholds, tests and map resolutions the teapot stays watertight where its
    /// patches meet and its boundary is exactly its six open seams.
    #[test]
    #[cfg_attr(not(shared_models), ignore = "needs ../shared/models beside the repository")]
    fn teapot_seams_are_the_same_for_every_threshold(
        log_th in -2.3f64..0.0,
        test in 0usize..4,
        m in 4usize..20,
    ) {
        let teapot = load("teapot.txt");
        let options = BezierOptions {
            test: EdgeTest::ALL[test],
            threshold: 10f64.powf(log_th),
            map_resolution: (m, 16),
            error_samples: 0,
            ..Default::default()
        };
        check_seams(&teapot, &options, 6);
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn map_tests_decide_before_evaluating_and_flat_throws_candidates_away() {
    let teacup = load("teacup.txt");
    for test in EdgeTest::ALL {
        let options = BezierOptions {
            test,
            threshold: 0.01,
            error_samples: 8,
            ..Default::default()
        };
        let (mesh, s) = tessellate_bezier(&teacup, &options).expect("tessellates");
        assert_eq!(s.triangles, mesh.triangles.len());
        assert_eq!(s.vertices, mesh.positions.len());
        assert_eq!(s.vertices_evaluated, s.vertices + s.vertices_discarded);
        if test.uses_map() {
            assert_eq!(s.vertices_discarded, 0, "{test}: one evaluation per vertex");
            assert_eq!(s.evaluations_saved, s.edges_tested - s.edges_split);
            assert_eq!(s.map_evaluations, 26 * 16 * 16);
        } else {
            // Each rejected edge cost one candidate evaluation.
            assert_eq!(s.vertices_discarded, s.edges_tested - s.edges_split);
            assert!(s.vertices_discarded > 0);
        }
        assert!(s.max_error.is_some_and(|e| e > 0.0 && e < 0.1));
        let json = s.to_json();
        for key in [
            "triangles",
            "vertices_evaluated",
            "vertices_discarded",
            "max_error",
            "seconds",
        ] {
            assert!(json.get(key).is_some(), "{key}");
        }
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn a_triangle_budget_searches_the_threshold() {
    let teacup = load("teacup.txt");
    for test in [EdgeTest::Map4p, EdgeTest::Flat] {
        let options = BezierOptions {
            test,
            target_triangles: Some(5000),
            error_samples: 0,
            ..Default::default()
        };
        let (_, s) = tessellate_bezier(&teacup, &options).expect("tessellates");
        assert!(s.triangles.abs_diff(5000) <= 100, "{test}: {}", s.triangles);
        assert!(s.search.is_some_and(|(t, n)| t == 5000 && n > 1));
        // The same threshold without the budget gives the same mesh size.
        let again = BezierOptions {
            test,
            threshold: s.threshold,
            error_samples: 0,
            ..Default::default()
        };
        assert_eq!(
            tessellate_bezier(&teacup, &again).expect("ok").1.triangles,
            s.triangles
        );
    }
}

#[test]
fn bad_options_are_refused_clearly() {
    let patches = BezierPatches {
        patches: vec![random_patch(1)],
    };
    let bad = [
        BezierOptions {
            threshold: -1.0,
            ..Default::default()
        },
        BezierOptions {
            threshold: f64::NAN,
            ..Default::default()
        },
        BezierOptions {
            map_resolution: (1, 16),
            ..Default::default()
        },
        BezierOptions {
            max_depth: 0,
            ..Default::default()
        },
        BezierOptions {
            target_triangles: Some(0),
            ..Default::default()
        },
        BezierOptions {
            threshold: 1e-9,
            max_triangles: 1000,
            ..Default::default()
        },
    ];
    for o in bad {
        let e = tessellate_bezier(&patches, &o).expect_err("refused");
        assert!(matches!(e, RuntimeError::InvalidParameter { .. }), "{e}");
    }
    assert!("MAP4P"
        .parse::<EdgeTest>()
        .is_ok_and(|t| t == EdgeTest::Map4p));
    assert!("map3p".parse::<EdgeTest>().is_err());
}
