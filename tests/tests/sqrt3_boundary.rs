//! √3 next to a boundary vertex, with Kobbelt's boundary rules (`schemes::sqrt3_boundary`):
//! the spectrum of the local subdivision matrix of the fan of `K` triangles, which the
//! boundary patches of docs/algorithms/sqrt3.md rely on.

use nalgebra::DMatrix;
use schemes::sqrt3_boundary::{half_plane_row, BoundaryFan, FanPoint, V};
use stencilgen::sqrt3_fan_tangents::{fan_local_matrix, FAN_RADIUS};

/// The local matrix of the fan of `k` triangles on the ball of radius `r` around `V`
/// (`stencilgen::sqrt3_fan_tangents::fan_local_matrix`: closed under the step, checked there).
fn local_matrix_within(k: u32, r: i64) -> (Vec<FanPoint>, DMatrix<f64>) {
    fan_local_matrix(BoundaryFan::new(k), r).expect("a closed ball")
}

fn local_matrix(k: u32) -> (Vec<FanPoint>, DMatrix<f64>) {
    local_matrix_within(k, FAN_RADIUS)
}

/// The moduli of `a`'s eigenvalues, largest first, by a bounded Schur iteration (a matrix it
/// cannot settle fails the test instead of hanging it).
fn moduli(a: &DMatrix<f64>) -> Vec<f64> {
    let schur = nalgebra::linalg::Schur::try_new(a.clone(), 1e-14, 100_000)
        .expect("the Schur iteration converges");
    let mut m: Vec<f64> = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .collect();
    m.sort_by(|x, y| y.total_cmp(x));
    m
}

/// For every `K = 1..=8`: the largest eigenvalue is 1, simple (a convergent scheme), and the
/// boundary curve's tangent at `V`, `(E_0 - E_K) / 2` (the cubic B-spline's derivative at its
/// knot: the boundary rules are its ternary refinement), is a left eigenvector for `1/3`,
/// exactly; the ball of radius 4 has the same six largest eigenvalues. `--nocapture` prints
/// the spectra that docs/algorithms/sqrt3.md quotes.
#[test]
fn the_boundary_tangent_is_a_left_eigenvector_for_a_third() {
    for k in 1..=8 {
        let (layout, a) = local_matrix(k);
        let index = |p: FanPoint| layout.iter().position(|&q| q == p).expect("in the ball");
        let mut t = DMatrix::<f64>::zeros(1, layout.len());
        t[(0, index((0, 1, 0)))] = 0.5;
        t[(0, index((k, 1, 0)))] = -0.5;
        assert!(((&t * &a) - &t / 3.0).amax() < 1e-15, "K = {k}");
        assert!(index(V) == 0);
        let m = moduli(&a);
        println!("K = {k}: {} points, moduli {:?}", layout.len(), &m[..6]);
        assert!((m[0] - 1.0).abs() < 1e-12 && m[1] < 0.99, "K = {k}: {m:?}");
        // The ball is wide enough: one more ring adds only smaller eigenvalues.
        let (_, wider) = local_matrix_within(k, 4);
        for (x, y) in m.iter().zip(&moduli(&wider)).take(6) {
            assert!((x - y).abs() < 1e-10, "K = {k}: {m:?}");
        }
    }
}

/// At the regular boundary vertex (`K = 3`, the half-plane) the next eigenvalue is `1/3` again,
/// with its own eigenvector (no Jordan block, which would put a `k 3^-k` term, a kink, into the
/// cross-boundary derivative), and `1/9` follows: the cross-boundary mode scales like the
/// boundary's tangent, so the surface is C1 there with an isotropic characteristic map, the
/// hypothesis the strip patches' derivatives rest on.
#[test]
fn the_regular_boundary_vertex_has_a_double_subdominant_third() {
    let (layout, a) = local_matrix(3);
    let m = moduli(&a);
    for x in &m[1..3] {
        assert!((x - 1.0 / 3.0).abs() < 1e-12, "{m:?}");
    }
    assert!((m[3] - 1.0 / 9.0).abs() < 1e-12, "{m:?}");
    let n = layout.len();
    let shifted = a.transpose() - DMatrix::<f64>::identity(n, n) / 3.0;
    let mut singular: Vec<f64> = shifted.singular_values().iter().copied().collect();
    singular.sort_by(f64::total_cmp);
    assert!(singular[1] < 1e-12 && singular[2] > 1e-3, "{singular:?}");
}

/// At the midpoint `(1/2, 0)` of a straight boundary's edge, the fixed point of
/// `y -> 3y - (1, 0)`, the local matrix (row `i`: the level-1 point at layout point `i` plus
/// `(1, 0)`, over the layout's level-0 points; the box `-4..=5` by `0..=4` is closed) has 1
/// simple and the cubic B-spline's derivative at `u = 1/2`, `(-1, -5, 5, 1) / 8` over the
/// boundary points `-1..=2`, as a left eigenvector for `1/3` exactly. `--nocapture` prints
/// the leading moduli, which docs/algorithms/sqrt3.md quotes: a cross mode of `0.3722 > 1/3`
/// there, against `1/3` at a vertex.
#[test]
fn the_boundary_edge_midpoint_spectrum() {
    let layout: Vec<(i64, i64)> = (0..=4)
        .flat_map(|b| (-4..=5).map(move |a| (a, b)))
        .collect();
    let index = |p: (i64, i64)| layout.iter().position(|&q| q == p);
    let n = layout.len();
    let mut a = DMatrix::<f64>::zeros(n, n);
    for (i, &q) in layout.iter().enumerate() {
        for (p, w) in half_plane_row((q.0 + 1, q.1)) {
            let j = index(p).unwrap_or_else(|| panic!("{q:?} reads {p:?} outside the box"));
            a[(i, j)] = w;
        }
    }
    let mut t = DMatrix::<f64>::zeros(1, n);
    for (x, w) in [(-1, -1.0), (0, -5.0), (1, 5.0), (2, 1.0)] {
        t[(0, index((x, 0)).expect("in the box"))] = w / 8.0;
    }
    assert!(((&t * &a) - &t / 3.0).amax() < 1e-15);
    let m = moduli(&a);
    println!("edge midpoint: moduli {:?}", &m[..6]);
    assert!((m[0] - 1.0).abs() < 1e-12 && m[1] < 0.99, "{m:?}");
}
