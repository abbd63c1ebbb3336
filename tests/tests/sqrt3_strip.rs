//! √3 beside a straight boundary, with Kobbelt's boundary rules (`schemes::sqrt3_strip`): the
//! spectrum of the local subdivision matrix at a regular boundary vertex (three triangles),
//! which the strip patches of docs/algorithms/sqrt3.md rely on.

use nalgebra::DMatrix;
use schemes::sqrt3_strip::level1_row;

/// The box of level-0 points `|a| <= 3`, `0 <= b <= 3` around the boundary vertex `(0, 0)` is
/// closed under the ternary step (every level-1 point of the box, at a third of its level-0
/// coordinates, reads only points of the box), so it carries the local matrix `A`.
///
/// * Its largest eigenvalue is 1, simple (a convergent scheme).
/// * The boundary curve is the cubic B-spline, whose derivative at the knot,
///   `(p_{1,0} - p_{-1,0}) / 2`, is a left eigenvector for `1/3` (one ternary step triples the
///   parameter): checked exactly as `t A = t / 3`.
/// * The next eigenvalue equals `1/3` again, with its own eigenvector, and then `1/9` follows: the cross-boundary mode
///   scales like the boundary's tangent, so the surface is C1 at the vertex with a regular
///   (isotropic) characteristic map, the hypothesis the strip's derivatives will rest on.
#[test]
fn the_regular_boundary_vertex_has_a_double_subdominant_third() {
    let r = 3i64;
    let layout: Vec<(i64, i64)> = (0..=r)
        .flat_map(|b| (-r..=r).map(move |a| (a, b)))
        .collect();
    let index = |p: (i64, i64)| layout.iter().position(|&q| q == p);
    let n = layout.len();
    let mut a = DMatrix::<f64>::zeros(n, n);
    for (i, &q) in layout.iter().enumerate() {
        for (p, w) in level1_row(q) {
            let j = index(p).unwrap_or_else(|| panic!("{q:?} reads {p:?} outside the box"));
            a[(i, j)] = w;
        }
    }
    let mut t = DMatrix::<f64>::zeros(1, n);
    t[(0, index((-1, 0)).expect("in the box"))] = -0.5;
    t[(0, index((1, 0)).expect("in the box"))] = 0.5;
    let ta = &t * &a;
    assert!((ta - &t / 3.0).amax() < 1e-15, "the B-spline's derivative");

    let mut moduli: Vec<f64> = a.complex_eigenvalues().iter().map(|z| z.norm()).collect();
    moduli.sort_by(|x, y| y.total_cmp(x));
    println!("moduli of A's eigenvalues: {:?}", &moduli[..8]);
    assert!(
        (moduli[0] - 1.0).abs() < 1e-12 && moduli[1] < 0.99,
        "{moduli:?}"
    );
    for m in &moduli[1..3] {
        assert!((m - 1.0 / 3.0).abs() < 1e-12, "{moduli:?}");
    }
    assert!((moduli[3] - 1.0 / 9.0).abs() < 1e-12, "{moduli:?}");
    // Two independent eigenvectors for 1/3, not a Jordan block (which would put a
    // `k 3^-k` term, a kink, into the cross-boundary derivative).
    let shifted = a.transpose() - DMatrix::<f64>::identity(n, n) / 3.0;
    let mut singular: Vec<f64> = shifted.singular_values().iter().copied().collect();
    singular.sort_by(f64::total_cmp);
    println!("smallest singular values of A - I/3: {:?}", &singular[..3]);
    assert!(singular[1] < 1e-12 && singular[2] > 1e-3, "{singular:?}");
}
