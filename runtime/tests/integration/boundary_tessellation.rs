//! The dual-grid tessellator on meshes with boundary: the surface reaches the limit boundary
//! curve, which for Catmull–Clark's "edge only" rules is the uniform cubic B-spline of the
//! boundary polygon (an independent closed form), and the output's boundary is one closed loop
//! per input boundary loop.

use proptest::prelude::*;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_mesh::TriangleMesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::tessellate;

/// A 3 x 3 grid of quads over `[0,3]^2` with bumpy heights; face `(i, j)` is `3j + i` and runs
/// `u` along `x`, `v` along `y`.
fn grid() -> (Mesh, Vec<[f64; 3]>) {
    let mut positions = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            let h = [0.0, 0.5, -0.25, 0.75, 0.125, -0.5, 0.25, 1.0][(3 * i + 5 * j) % 8];
            positions.push([f64::from(i as u32), f64::from(j as u32), h]);
        }
    }
    let at = |i: i64, j: i64| 4 * j + i;
    let faces: Vec<Vec<i64>> = (0..3)
        .flat_map(|j| {
            (0..3).map(move |i| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        })
        .collect();
    let mesh = Mesh::new(
        positions.clone(),
        &faces,
        &[],
        schemes::BoundaryMode::EdgeOnly,
    )
    .expect("valid grid");
    (mesh, positions)
}

/// The closed uniform cubic B-spline of the boundary loop of [`grid`], at loop parameter `s`
/// (`s = k` is the k-th boundary vertex counter-clockwise from `(0,0)`).
fn boundary_curve(positions: &[[f64; 3]], s: f64) -> [f64; 3] {
    let p = |i: usize, j: usize| positions[4 * j + i];
    let mut ring = Vec::new();
    ring.extend((0..3).map(|k| p(k, 0)));
    ring.extend((0..3).map(|k| p(3, k)));
    ring.extend((0..3).map(|k| p(3 - k, 3)));
    ring.extend((0..3).map(|k| p(0, 3 - k)));
    let k = (s.floor() as usize).min(11);
    let t = s - k as f64;
    let b = [
        (1.0 - t).powi(3) / 6.0,
        (3.0 * t.powi(3) - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t.powi(3) / 6.0,
    ];
    let mut out = [0.0; 3];
    for (m, w) in b.iter().enumerate() {
        let q = ring[(k + 11 + m) % 12];
        for c in 0..3 {
            out[c] += w * q[c];
        }
    }
    out
}

/// Loops formed by directed boundary edges (each vertex with one outgoing edge).
fn boundary_loops(out: &TriangleMesh) -> Vec<Vec<u32>> {
    let edges = out
        .boundary_edges()
        .expect("edge-manifold, consistently oriented");
    let next: std::collections::HashMap<u32, u32> = edges.iter().copied().collect();
    assert_eq!(
        next.len(),
        edges.len(),
        "a boundary vertex with two outgoing edges"
    );
    let mut seen = std::collections::HashSet::new();
    let mut loops = Vec::new();
    for &(a, _) in &edges {
        if seen.contains(&a) {
            continue;
        }
        let mut ring = vec![a];
        seen.insert(a);
        let mut v = next[&a];
        while v != a {
            assert!(seen.insert(v), "boundary edges do not form simple loops");
            ring.push(v);
            v = *next.get(&v).expect("an open boundary chain");
        }
        loops.push(ring);
    }
    loops
}

fn check_grid(rates: &[u32]) {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (mesh, positions) = grid();
    let (isolated, patches, steps) = isolate(&mesh).expect("isolates");
    assert_eq!(steps, 0, "the grid's faces are patches as they are");
    let (out, _) = tessellate(&table, &isolated, &patches, rates).expect("tessellates");
    assert_eq!(out.euler_characteristic(), 1, "a disc");
    let loops = boundary_loops(&out);
    assert_eq!(loops.len(), 1, "one boundary loop");
    // The loop runs through the limit points of the 12 boundary vertices and n - 1 curve points
    // per boundary edge, nothing else.
    let side_rates: u32 = (0..3)
        .map(|k| rates[k] + rates[3 * k + 2] + rates[6 + 2 - k] + rates[3 * (2 - k)])
        .sum();
    assert_eq!(loops[0].len() as u32, 12 + side_rates - 12);
    for &v in &loops[0] {
        let source = out.sources[v as usize];
        let (u, w) = source.uv();
        let f = source.face as usize;
        let (x, y) = ((f % 3) as f64 + u, (f / 3) as f64 + w);
        let s = if y == 0.0 {
            x
        } else if x == 3.0 {
            3.0 + y
        } else if y == 3.0 {
            9.0 - x
        } else {
            assert_eq!(x, 0.0, "a boundary vertex inside the domain");
            12.0 - y
        };
        let expected = boundary_curve(&positions, s % 12.0);
        let got = out.positions[v as usize];
        assert!(
            (0..3).all(|c| (expected[c] - f64::from(got[c])).abs() < 2e-6),
            "loop parameter {s}: {got:?} vs the B-spline's {expected:?}"
        );
        let normal = out.normals[v as usize];
        assert!((normal.iter().map(|c| c * c).sum::<f32>() - 1.0).abs() < 1e-5);
    }
}

#[test]
#[cfg(feature = "catmull-clark")]
fn a_grid_reaches_the_limit_boundary_curve() {
    for n in [1, 2, 3, 8, 24] {
        check_grid(&[n; 9]);
    }
    check_grid(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random per-face rates on the grid: still a disc with one boundary loop on the B-spline.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn random_rates_on_the_grid(rates in proptest::collection::vec(1u32..=24, 9)) {
        check_grid(&rates);
    }
}
