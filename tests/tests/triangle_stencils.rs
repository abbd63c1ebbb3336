//! Regular basis functions of the triangle schemes (Schaefer–Warren section 5.1) on the grid
//! `(1/n) Z^2`, in the skew lattice coordinates of `schemes::triangle`: Loop against the
//! quartic box spline written from its definition (`subtess_tests::box_spline`), the
//! butterfly's interpolation, partition of unity and the twelve lattice symmetries for every
//! scheme, f64 against exact, and the √3 edge-midpoint stencil of the paper's Fig. 4.

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::triangle::{apply_map, lattice_symmetries, TRIANGLE_SCHEME_NAMES};
use schemes::TriangleScheme;
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::triangle_system::{triangle_stencils, TriangleStencils};
use subtess_tests::box_spline::{box_spline, loop_basis};
use subtess_tests::bspline::q;

fn solve<S: stencilgen::Scalar>(name: &str, n: u32, kind: StencilKind) -> TriangleStencils<S> {
    let mask = TriangleScheme::by_name(name)
        .expect("catalogued")
        .regular_mask();
    triangle_stencils::<S>(&mask, n, kind).expect("solvable")
}

fn exact(name: &str, n: u32) -> TriangleStencils<BigRational> {
    solve(name, n, StencilKind::Position)
}

fn bbox_points<S>(s: &TriangleStencils<S>) -> Vec<(i64, i64)> {
    let ((l1, h1), (l2, h2)) = s.bbox;
    (l2..=h2)
        .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
        .collect()
}

#[test]
fn box_spline_reference_is_loops_limit_mask_and_a_partition_of_unity() {
    // Loop's limit position rule at valence 6 (Hoppe et al. 1994, chi = 1/(3/(8 beta) + 6) with
    // beta = 1/16): 1/2 at the vertex, 1/12 at each neighbour.
    assert_eq!(loop_basis(&(q(0, 1), q(0, 1))), q(1, 2));
    for (a, b) in schemes::triangle::NEIGHBOURS {
        assert_eq!(loop_basis(&(q(a, 1), q(b, 1))), q(1, 12), "({a}, {b})");
    }
    for x in [(q(1, 3), q(1, 7)), (q(2, 5), q(-3, 4)), (q(0, 1), q(1, 2))] {
        let mut sum = BigRational::zero();
        for j1 in -3..=3 {
            for j2 in -3..=3 {
                sum += loop_basis(&(&x.0 - q(j1, 1), &x.1 - q(j2, 1)));
            }
        }
        assert_eq!(sum, BigRational::one(), "{x:?}");
    }
}

#[test]
fn sqrt3_vertex_values_are_kobbelts_limit_rule() {
    // Kobbelt (2000): one step maps a vertex p and the average r of its ring to
    // ((1 - alpha) p + alpha r, (p + 2 r)/3) (the new ring is the face centroids), whose left
    // fixed vector gives the limit p + beta (r - p) with beta = 3 alpha / (1 + 3 alpha);
    // alpha_6 = 1/3, so 1/2 at the vertex and 1/12 at each of the six neighbours.
    let alpha = q(1, 3);
    let beta = &alpha * q(3, 1) / (q(1, 1) + &alpha * q(3, 1));
    let s = exact("sqrt3", 1);
    assert_eq!(s.at(0, 0), q(1, 1) - &beta);
    for (a, b) in schemes::triangle::NEIGHBOURS {
        assert_eq!(s.at(a, b), &beta / q(6, 1));
    }
}

#[test]
fn loop_regular_values_are_the_quartic_box_spline() {
    for name in ["loop", "loop-original"] {
        for n in 1..=6 {
            let s = exact(name, n);
            assert_eq!(
                s.bbox,
                (
                    (-2 * i64::from(n), 2 * i64::from(n)),
                    (-2 * i64::from(n), 2 * i64::from(n))
                )
            );
            for (k1, k2) in bbox_points(&s) {
                let x = (q(k1, i64::from(n)), q(k2, i64::from(n)));
                assert_eq!(
                    s.at(k1, k2),
                    loop_basis(&x),
                    "{name} n = {n} at ({k1}, {k2})/{n}"
                );
            }
        }
    }
}

#[test]
fn loop_tangents_are_box_spline_differences() {
    // d/dx_1 M_{222} = M_{122}(x) - M_{122}(x - xi_1) (box-spline derivative formula), and
    // d/dx_2 = M_{212}(x) - M_{212}(x - xi_2); centred by (2, 0).
    for n in 1..=3 {
        let du = solve::<BigRational>("loop", n, StencilKind::DerivativeU);
        let dv = solve::<BigRational>("loop", n, StencilKind::DerivativeV);
        for (k1, k2) in bbox_points(&du) {
            let x = (q(k1, i64::from(n)) + q(2, 1), q(k2, i64::from(n)));
            let x_less = |d: (i64, i64)| (&x.0 - q(d.0, 1), &x.1 - q(d.1, 1));
            let expected_u = box_spline([1, 2, 2], &x) - box_spline([1, 2, 2], &x_less((1, 0)));
            let expected_v = box_spline([2, 1, 2], &x) - box_spline([2, 1, 2], &x_less((0, 1)));
            assert_eq!(du.at(k1, k2), expected_u, "d/du n = {n} at ({k1}, {k2})");
            assert_eq!(dv.at(k1, k2), expected_v, "d/dv n = {n} at ({k1}, {k2})");
        }
    }
}

#[test]
fn butterfly_interpolates_its_control_points() {
    for n in 1..=4 {
        let s = exact("butterfly", n);
        let ni = i64::from(n);
        for (k1, k2) in bbox_points(&s) {
            if k1 % ni == 0 && k2 % ni == 0 {
                let expected = if (k1, k2) == (0, 0) {
                    BigRational::one()
                } else {
                    BigRational::zero()
                };
                assert_eq!(s.at(k1, k2), expected, "n = {n} at ({k1}, {k2})");
            }
        }
    }
}

#[test]
fn partition_of_unity_and_the_twelve_lattice_symmetries_everywhere() {
    for name in TRIANGLE_SCHEME_NAMES {
        for n in [1, 2, 3, 4, 6] {
            let s = exact(name, n);
            let ni = i64::from(n);
            let mut sums = vec![BigRational::zero(); (ni * ni) as usize];
            for (k1, k2) in bbox_points(&s) {
                sums[(k1.rem_euclid(ni) * ni + k2.rem_euclid(ni)) as usize] += s.at(k1, k2);
                for g in lattice_symmetries() {
                    let (m1, m2) = apply_map(g, (k1, k2));
                    assert_eq!(
                        s.at(m1, m2),
                        s.at(k1, k2),
                        "{name} n = {n} {g:?} at ({k1}, {k2})"
                    );
                }
            }
            assert!(sums.iter().all(|x| x.is_one()), "{name} n = {n}: {sums:?}");
        }
    }
}

#[test]
fn f64_is_within_1e_12_of_exact() {
    for name in TRIANGLE_SCHEME_NAMES {
        for n in [2, 3, 5] {
            for kind in StencilKind::ALL {
                let e = solve::<BigRational>(name, n, kind);
                let f = solve::<f64>(name, n, kind);
                assert_eq!(e.bbox, f.bbox);
                for (k1, k2) in bbox_points(&e) {
                    let d = (rational_to_f64(&e.at(k1, k2)) - f.at(k1, k2)).abs();
                    assert!(d < 1e-12, "{name} {kind:?} n = {n} at ({k1}, {k2}): {d:e}");
                }
            }
        }
    }
}

#[test]
fn sqrt3_edge_midpoint_stencil_has_the_papers_normalization_2256() {
    // Schaefer–Warren Fig. 4: the stencil of the midpoint of an edge for sqrt(3), "with an
    // implicit normalization of 2256". Edge (0,0)-(1,0), midpoint (1/2, 0): grid n = 2.
    let s = exact("sqrt3", 2);
    let stencil = s.stencil_at((1, 0));
    let lcm = stencil
        .iter()
        .fold(BigInt::one(), |acc, (_, v)| acc.lcm(v.denom()));
    assert_eq!(lcm, BigInt::from(2256));
    let total: BigRational = stencil.iter().map(|(_, v)| v.clone()).sum();
    assert!(total.is_one());
    // Symmetric under the edge's own symmetries: j -> (1,0) - j and the reflection across the
    // edge's line, (a, b) -> (a + b, -b).
    let weight = |j: (i64, i64)| {
        stencil
            .iter()
            .find(|(i, _)| *i == j)
            .map_or_else(BigRational::zero, |(_, v)| v.clone())
    };
    for (j, v) in &stencil {
        assert_eq!(&weight((1 - j.0, -j.1)), v);
        assert_eq!(&weight((j.0 + j.1, -j.1)), v);
    }
    // Independently of the solver: power iteration of the upsampled matrix (Schaefer–Warren
    // section 3) on v_j = phi((1/2, 0) - j). From phi(x) = sum_i s_i phi(3x - i) and
    // 3 (1/2, 0) = (1/2, 0) + (1, 0): v_j = sum_i s_i v_{3j + i - (1, 0)}.
    let mask = TriangleScheme::by_name("sqrt3")
        .expect("catalogued")
        .regular_mask();
    let r = 4i64;
    let width = (2 * r + 1) as usize;
    let slot = |j: (i64, i64)| {
        (j.0.abs() <= r && j.1.abs() <= r)
            .then(|| ((j.1 + r) as usize) * width + (j.0 + r) as usize)
    };
    let mut v = vec![1.0 / (width * width) as f64; width * width];
    for _ in 0..200 {
        let mut next = vec![0.0; width * width];
        for j1 in -r..=r {
            for j2 in -r..=r {
                let mut acc = 0.0;
                for ((i1, i2), w) in &mask.weights {
                    if let Some(t) = slot((3 * j1 + i1 - 1, 3 * j2 + i2)) {
                        acc += (*w.numer() as f64 / *w.denom() as f64) * v[t];
                    }
                }
                if let Some(t) = slot((j1, j2)) {
                    next[t] = acc;
                }
            }
        }
        let sum: f64 = next.iter().sum();
        v = next.iter().map(|x| x / sum).collect();
    }
    for j1 in -r..=r {
        for j2 in -r..=r {
            let expected = v[slot((j1, j2)).expect("in the window")];
            let got = rational_to_f64(&weight((j1, j2)));
            assert!(
                (got - expected).abs() < 1e-12,
                "({j1}, {j2}): {got} vs {expected}"
            );
        }
    }
}

#[test]
fn loop_quartic_pieces_equal_the_box_spline_at_denominators_beyond_the_grids() {
    // LoopRegularBasis interpolates the rate-4 grid; the box spline comes from its definition.
    // Denominators 3n of the dual points up to n = 24, and odd ones no grid here was solved at.
    let scheme = TriangleScheme::by_name("loop").expect("catalogued");
    let basis = stencilgen::loop_basis::LoopRegularBasis::new(&scheme, StencilKind::Position)
        .expect("polynomial");
    let du = stencilgen::loop_basis::LoopRegularBasis::new(&scheme, StencilKind::DerivativeU)
        .expect("polynomial");
    let mut checked = 0;
    for d in [29i64, 48, 72] {
        // A sparse sweep of the support [-2, 2]^2 (every 7th numerator, offset per row).
        for k2 in (-2 * d..=2 * d).step_by(7) {
            for k1 in (-2 * d + (k2.rem_euclid(5))..=2 * d).step_by(11) {
                let x = (q(k1, d), q(k2, d));
                let value: BigRational = basis.at(k1, k2, d);
                assert_eq!(value, loop_basis(&x), "psi at ({k1}, {k2})/{d}");
                let shifted = (&x.0 + q(2, 1), x.1.clone());
                let expected_u = box_spline([1, 2, 2], &shifted)
                    - box_spline([1, 2, 2], &(&shifted.0 - q(1, 1), shifted.1.clone()));
                let slope: BigRational = du.at(k1, k2, d);
                assert_eq!(slope, expected_u, "d/du psi at ({k1}, {k2})/{d}");
                let float: f64 = basis.at(k1, k2, d);
                assert!((float - rational_to_f64(&value)).abs() < 1e-14);
                checked += 1;
            }
        }
    }
    assert!(checked > 300, "{checked} points");
}

#[test]
fn regular_loop_patch_from_subdivision_is_the_box_spline() {
    // schemes::loop_regular interpolates limit points of two subdivision steps; the oracle is
    // the box spline from its definition: the weight of net point p at x is psi(x - p).
    use schemes::loop_regular::{RegularDerivative, RegularLoopPatch, REGULAR_NET};
    let patch = RegularLoopPatch::new();
    for (nu, nv, d) in [
        (0, 0, 1),
        (1, 0, 3),
        (1, 1, 3),
        (2, 5, 9),
        (7, 3, 17),
        (10, 31, 72),
        (1, 70, 72),
    ] {
        let (u, v) = (q(nu, d), q(nv, d));
        let w = patch.weights(&u, &v, RegularDerivative::Position);
        let du = patch.weights(&u, &v, RegularDerivative::U);
        let dv = patch.weights(&u, &v, RegularDerivative::V);
        for (c, &(p1, p2)) in REGULAR_NET.iter().enumerate() {
            let x = (&u - q(p1, 1), &v - q(p2, 1));
            assert_eq!(w[c], loop_basis(&x), "({nu}, {nv})/{d}, point {c}");
            // Box-spline derivative formula, centred by (2, 0) as in loop_tangents_are_...
            let s = (&x.0 + q(2, 1), x.1.clone());
            let less = |e: (i64, i64)| (&s.0 - q(e.0, 1), &s.1 - q(e.1, 1));
            let eu = box_spline([1, 2, 2], &s) - box_spline([1, 2, 2], &less((1, 0)));
            let ev = box_spline([2, 1, 2], &s) - box_spline([2, 1, 2], &less((0, 1)));
            assert_eq!(du[c], eu, "d/du ({nu}, {nv})/{d}, point {c}");
            assert_eq!(dv[c], ev, "d/dv ({nu}, {nv})/{d}, point {c}");
        }
    }
}
