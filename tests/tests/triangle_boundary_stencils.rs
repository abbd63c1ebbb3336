//! The Loop patch next to a boundary vertex with `k` triangles (Hoppe et al. 1994 boundary
//! rules; Schaefer–Warren sections 5.2–5.3 on the triangular lattice), by substitution
//! (`stencilgen::triangle_boundary`), against independent references:
//!
//! * `k = 3` (the regular boundary): every sector equals the quartic box spline
//!   (`subtess_tests::box_spline`, from its definition) of the half-plane lattice extended by
//!   the phantom points `P(x, -1) = P(x-1, 0) + P(x, 0) - P(x-1, 1)`, written here;
//! * every `k`: the boundary edges are the uniform cubic B-spline of the boundary polygon
//!   (`subtess_tests::bspline`, truncated powers), the limit mask is the B-spline curve's
//!   `(E_0 + 4V + E_k)/6`, the layout is the documented contract, stencils agree across the
//!   edge shared by neighbouring sectors and under the mirror `s <-> k-1-s`, sum to 1 (0 for
//!   derivatives), and f64 matches exact;
//! * tangents at `V`: the boundary tangent `E_k - E_0` lies in their span, `k = 3` gives the
//!   box spline's derivatives, and the normals just inside the patch converge to `du x dv`
//!   for `k = 1..=5` (and measurably do not for `k >= 6`).

use std::collections::BTreeMap;

use num_rational::BigRational;
use num_traits::{One, Signed, Zero};
use schemes::triangle_local::{TriangleLocalMatrices, TrianglePoint};
use stencilgen::loop_basis::LoopRegularBasis;
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::triangle_boundary::loop_boundary_tangents;
use stencilgen::triangle_patch::{
    patch_stencils_at, triangle_grid_points, triangle_scheme, TriangleSubstitution,
};
use subtess_tests::box_spline::{box_spline, loop_basis};
use subtess_tests::bspline::{q, uniform_bspline, uniform_bspline_derivative};

type Exact = TriangleSubstitution<BigRational>;

fn exact(k: u32, s: u32) -> Exact {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    Exact::boundary(&loop_, k, s).expect("valid boundary patch")
}

/// Switch `sub` to sector `s` of `k` triangles (keeping its cached regular basis).
fn select<S: stencilgen::Scalar>(sub: &mut TriangleSubstitution<S>, k: u32, s: u32) {
    sub.select_boundary_patch(k, s)
        .expect("valid boundary patch");
}

fn float(k: u32, s: u32) -> TriangleSubstitution<f64> {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    TriangleSubstitution::<f64>::boundary(&loop_, k, s).expect("valid boundary patch")
}

fn ray(s: u32, a: i64) -> TrianglePoint {
    TrianglePoint::Sector { s, a, b: 0 }
}

fn inner(s: u32) -> TrianglePoint {
    TrianglePoint::Sector { s, a: 1, b: 1 }
}

/// The grid points `(i/n, j/n)`, `i + j <= n`, of several rates, and a few points whose
/// denominators need several halvings.
fn sample_points() -> Vec<(BigRational, BigRational)> {
    let mut out = Vec::new();
    for n in [1, 2, 3, 4, 5] {
        for j in 0..=n {
            for i in 0..=n - j {
                out.push((q(i, n), q(j, n)));
            }
        }
    }
    for (a, b, n) in [
        (1, 1, 48),
        (1, 0, 48),
        (0, 5, 48),
        (47, 1, 48),
        (3, 7, 40),
        (1, 2, 96),
        (1, 3, 100),
        (30, 2, 77),
        (1, 1, 243),
    ] {
        out.push((q(a, n), q(b, n)));
    }
    out
}

/// A stencil as a map from mesh vertices to nonzero weights.
fn named(layout: &[TrianglePoint], w: &[BigRational]) -> BTreeMap<TrianglePoint, BigRational> {
    layout
        .iter()
        .zip(w)
        .filter(|(_, x)| !x.is_zero())
        .map(|(p, x)| (*p, x.clone()))
        .collect()
}

#[test]
fn grid_system_equals_substitution_exactly() {
    // The grid system of stencilgen::triangle_patch (any TriangleLocalMatrices) against plain
    // substitution, as rationals, positions and both derivatives (the vertex itself only for
    // positions).
    let loop_ = triangle_scheme("loop").expect("catalogued");
    let mut sub = exact(1, 0);
    for kind in KINDS {
        let basis = LoopRegularBasis::new(&loop_, kind).expect("Loop is polynomial");
        for k in 1..=6u32 {
            for s in 0..k {
                select(&mut sub, k, s);
                for n in [1, 2, 3, 5] {
                    let grid = patch_stencils_at::<BigRational>(
                        &sub.matrices,
                        &basis,
                        &triangle_grid_points(n),
                        n,
                    )
                    .expect("solvable");
                    assert_eq!(grid.residual, 0.0);
                    let expected_points =
                        triangle_grid_points(n).len() - usize::from(kind != StencilKind::Position);
                    assert_eq!(grid.points.len(), expected_points);
                    for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                        let (u, v) = (q(i, i64::from(n)), q(j, i64::from(n)));
                        let by_substitution =
                            sub.stencil_of_kind(&u, &v, kind).expect("in the patch");
                        assert_eq!(
                            stencil, &by_substitution,
                            "{kind:?} k = {k}, s = {s}, ({i}/{n}, {j}/{n})"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn layout_is_the_documented_contract() {
    // V, E_0..E_k, then (1,1) of sector s-1 (if s >= 1), (2,0) on ray s, (1,1) of sector s,
    // (2,0) on ray s+1, (1,1) of sector s+1 (if s+1 <= k-1).
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for k in 1..=8u32 {
        for s in 0..k {
            let mut expected = vec![TrianglePoint::Centre];
            expected.extend((0..=k).map(|i| ray(i, 1)));
            if s >= 1 {
                expected.push(inner(s - 1));
            }
            expected.extend([ray(s, 2), inner(s), ray(s + 1, 2)]);
            if s + 1 < k {
                expected.push(inner(s + 1));
            }
            let m = TriangleLocalMatrices::boundary(&loop_, k, s).expect("valid");
            assert_eq!(m.layout, expected, "k = {k}, s = {s}");
        }
    }
}

/// `k = 3`: the mesh is the half-plane `y >= 0` of the lattice (global skew coordinates),
/// `V = 0`, `E_i = R^i (1, 0)` with the rotation `R (a, b) = (-b, a + b)` by 60 degrees.
mod half_plane {
    use super::*;

    pub fn rotate((a, b): (i64, i64), times: u32) -> (i64, i64) {
        (0..times).fold((a, b), |(a, b), _| (-b, a + b))
    }

    /// The global position of a named point (sector `s`'s axes are `R^s (1,0)`, `R^s (0,1)`).
    pub fn position(p: TrianglePoint) -> (i64, i64) {
        match p {
            TrianglePoint::Centre => (0, 0),
            TrianglePoint::Sector { s, a, b } => {
                let (e, f) = (rotate((1, 0), s), rotate((0, 1), s));
                (a * e.0 + b * f.0, a * e.1 + b * f.1)
            }
        }
    }

    /// The mesh point at `p` as layout weights, phantoms `y = -1` expanded; `None` if the
    /// point is neither in the layout nor a phantom of layout points.
    pub fn expand(layout: &[(i64, i64)], p: (i64, i64)) -> Option<Vec<((i64, i64), i64)>> {
        let here = |p: (i64, i64)| layout.contains(&p).then_some(p);
        match p.1 {
            y if y >= 0 => Some(vec![(here(p)?, 1)]),
            -1 => {
                let (x, _) = p;
                Some(vec![
                    (here((x - 1, 0))?, 1),
                    (here((x, 0))?, 1),
                    (here((x - 1, 1))?, -1),
                ])
            }
            _ => None,
        }
    }

    /// `sum_p f(x - p) P(p)` over the lattice points near `x`, as layout weights.
    pub fn weights(
        layout: &[(i64, i64)],
        x: &(BigRational, BigRational),
        f: &dyn Fn(&(BigRational, BigRational)) -> BigRational,
    ) -> Vec<BigRational> {
        let mut w = vec![BigRational::zero(); layout.len()];
        for py in -4..=4 {
            for px in -5..=5 {
                let d = (&x.0 - q(px, 1), &x.1 - q(py, 1));
                // The support of the centred quartic box spline (and of its derivatives) is
                // the hexagon |d_1|, |d_2|, |d_1 + d_2| <= 2, and it vanishes on its boundary.
                let two = q(2, 1);
                if d.0.abs() >= two || d.1.abs() >= two || (&d.0 + &d.1).abs() >= two {
                    continue;
                }
                let value = f(&d);
                if value.is_zero() {
                    continue;
                }
                let terms = expand(layout, (px, py)).unwrap_or_else(|| {
                    panic!("the box spline at ({px}, {py}) reaches beyond the phantom row")
                });
                for (point, c) in terms {
                    let i = layout.iter().position(|&l| l == point).expect("in layout");
                    w[i] += &value * q(c, 1);
                }
            }
        }
        w
    }

    /// The point `(u, v)` of sector `s` in global coordinates.
    pub fn global(s: u32, x: &(BigRational, BigRational)) -> (BigRational, BigRational) {
        let (e, f) = (rotate((1, 0), s), rotate((0, 1), s));
        (
            &x.0 * q(e.0, 1) + &x.1 * q(f.0, 1),
            &x.0 * q(e.1, 1) + &x.1 * q(f.1, 1),
        )
    }
}

#[test]
fn regular_boundary_is_the_box_spline_with_phantoms() {
    let mut sub = exact(3, 0);
    for s in 0..3 {
        select(&mut sub, 3, s);
        let layout: Vec<(i64, i64)> = sub
            .matrices
            .layout
            .iter()
            .map(|&p| half_plane::position(p))
            .collect();
        assert!(layout.iter().all(|p| p.1 >= 0), "sector {s}: {layout:?}");
        for x in sample_points() {
            let got = sub.stencil(&x.0, &x.1).expect("in the patch");
            let expected = half_plane::weights(&layout, &half_plane::global(s, &x), &loop_basis);
            assert_eq!(got, expected, "sector {s}, ({}, {})", x.0, x.1);
        }
    }
}

#[test]
fn regular_boundary_derivatives_are_the_box_spline_differences() {
    // D_xi M_222 = M_{222 - xi}(z) - M_{222 - xi}(z - xi) for a direction xi of the box spline
    // (de Boor et al., Box Splines, (I.28)); the sector's u and v axes are +-xi_j.
    let xi = [(1, 0), (0, 1), (1, -1)];
    // (direction index, sign) of R^i (1, 0): (1,0) = xi_1, (0,1) = xi_2, (-1,1) = -xi_3,
    // (-1,0) = -xi_1.
    let axis = [(0usize, 1i64), (1, 1), (2, -1), (0, -1)];
    let mut sub = exact(3, 0);
    for s in 0..3u32 {
        select(&mut sub, 3, s);
        let layout: Vec<(i64, i64)> = sub
            .matrices
            .layout
            .iter()
            .map(|&p| half_plane::position(p))
            .collect();
        for (kind, (j, sign)) in [
            (StencilKind::DerivativeU, axis[s as usize]),
            (StencilKind::DerivativeV, axis[s as usize + 1]),
        ] {
            let mut c = [2, 2, 2];
            c[j] = 1;
            let d = move |z: &(BigRational, BigRational)| {
                let z = (&z.0 + q(2, 1), z.1.clone());
                let shifted = (&z.0 - q(xi[j].0, 1), &z.1 - q(xi[j].1, 1));
                (box_spline(c, &z) - box_spline(c, &shifted)) * q(sign, 1)
            };
            for n in [1, 2, 3, 5] {
                for jj in 0..=n {
                    for i in 0..=n - jj {
                        if (i, jj) == (0, 0) {
                            continue;
                        }
                        let x = (q(i, n), q(jj, n));
                        let got = sub.stencil_of_kind(&x.0, &x.1, kind).expect("in the patch");
                        let expected = half_plane::weights(&layout, &half_plane::global(s, &x), &d);
                        assert_eq!(got, expected, "{kind:?} sector {s} ({i}/{n}, {jj}/{n})");
                    }
                }
            }
            // At V the f64 tangent masks (eigenvectors, normalized on the half-disk net, which
            // is the lattice at k = 3) are these derivatives too.
            let t = loop_boundary_tangents(&sub.matrices).expect("tangents");
            let mask = if kind == StencilKind::DerivativeU {
                &t.du
            } else {
                &t.dv
            };
            let expected = half_plane::weights(&layout, &(q(0, 1), q(0, 1)), &d);
            for (a, b) in mask.iter().zip(&expected) {
                assert!(
                    (a - rational_to_f64(b)).abs() < 1e-12,
                    "{kind:?} sector {s}: {mask:?} vs {expected:?}"
                );
            }
        }
    }
}

/// The cubic B-spline weights `(c_{-1}, c_0, c_1, c_2)` at `t` of the segment from `c_0` to
/// `c_1`: `B_3(t - j + 2)` with the uniform B-spline `B_3` on `[0, 4]`.
fn cubic(t: &BigRational, derivative: bool) -> [BigRational; 4] {
    let f = |x: BigRational| {
        if derivative {
            uniform_bspline_derivative(3, &x)
        } else {
            uniform_bspline(3, &x)
        }
    };
    [f(t + q(3, 1)), f(t + q(2, 1)), f(t + q(1, 1)), f(t.clone())]
}

#[test]
fn boundary_edges_are_the_cubic_b_spline_of_the_boundary_polygon() {
    // Boundary points are refined by boundary rules only (midpoints; 1/8, 3/4, 1/8): cubic
    // B-spline subdivision. Sector 0's edge v = 0 runs from V to E_0 over E_k, V, E_0, ray 0's
    // (2,0); sector k-1's edge u = 0 from V to E_k over E_0, V, E_k, ray k's (2,0). The
    // derivative along the edge is the curve's derivative (same parameter).
    let mut sub = exact(1, 0);
    for k in 1..=6u32 {
        for (s, first, polygon) in [
            (
                0,
                true,
                [ray(k, 1), TrianglePoint::Centre, ray(0, 1), ray(0, 2)],
            ),
            (
                k - 1,
                false,
                [ray(0, 1), TrianglePoint::Centre, ray(k, 1), ray(k, 2)],
            ),
        ] {
            select(&mut sub, k, s);
            let layout = sub.matrices.layout.clone();
            for n in [1, 2, 3, 5, 7, 8, 16] {
                for i in 0..=n {
                    let t = q(i, n);
                    let (u, v) = if first {
                        (t.clone(), q(0, 1))
                    } else {
                        (q(0, 1), t.clone())
                    };
                    let mut kinds = vec![(StencilKind::Position, false)];
                    if i > 0 {
                        kinds.push(if first {
                            (StencilKind::DerivativeU, true)
                        } else {
                            (StencilKind::DerivativeV, true)
                        });
                    }
                    for (kind, derivative) in kinds {
                        let got = sub.stencil_of_kind(&u, &v, kind).expect("in the patch");
                        let mut expected = BTreeMap::new();
                        for (p, w) in polygon.iter().zip(cubic(&t, derivative)) {
                            if !w.is_zero() {
                                expected.insert(*p, w);
                            }
                        }
                        assert_eq!(
                            named(&layout, &got),
                            expected,
                            "{kind:?} k = {k}, sector {s}, t = {i}/{n}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn limit_mask_is_the_b_spline_curve_limit() {
    let mut sub = exact(1, 0);
    for k in 1..=6u32 {
        for s in 0..k {
            select(&mut sub, k, s);
            let layout = sub.matrices.layout.clone();
            let got = sub.stencil(&q(0, 1), &q(0, 1)).expect("the vertex");
            let expected: BTreeMap<_, _> = [
                (TrianglePoint::Centre, q(2, 3)),
                (ray(0, 1), q(1, 6)),
                (ray(k, 1), q(1, 6)),
            ]
            .into_iter()
            .collect();
            assert_eq!(named(&layout, &got), expected, "k = {k}, s = {s}");
        }
    }
}

const KINDS: [StencilKind; 3] = [
    StencilKind::Position,
    StencilKind::DerivativeU,
    StencilKind::DerivativeV,
];

#[test]
fn partition_of_unity_and_f64_matches_exact() {
    let (mut e, mut f) = (exact(1, 0), float(1, 0));
    for k in 1..=6u32 {
        for s in 0..k {
            select(&mut e, k, s);
            select(&mut f, k, s);
            for n in [1, 2, 3, 5, 7] {
                for j in 0..=n {
                    for i in 0..=n - j {
                        let (u, v) = (q(i, n), q(j, n));
                        for kind in KINDS {
                            if (i, j) == (0, 0) && kind != StencilKind::Position {
                                continue;
                            }
                            let a = e.stencil_of_kind(&u, &v, kind).expect("in the patch");
                            let b = f.stencil_of_kind(&u, &v, kind).expect("in the patch");
                            let sum: BigRational = a.iter().sum();
                            let total = if kind == StencilKind::Position {
                                BigRational::one()
                            } else {
                                BigRational::zero()
                            };
                            assert_eq!(sum, total, "{kind:?} k = {k} s = {s} ({i}/{n}, {j}/{n})");
                            for (x, y) in a.iter().zip(&b) {
                                assert!(
                                    (rational_to_f64(x) - y).abs() <= 1e-12,
                                    "{kind:?} k = {k} s = {s} ({i}/{n}, {j}/{n})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn neighbouring_sectors_agree_on_their_shared_edge() {
    // The edge V-E_{s+1} is u = 0 of sector s and v = 0 of sector s+1, with the same
    // parameter: positions, and the derivative along the edge (d/dv there, d/du here), are
    // the same combination of mesh vertices.
    let (mut a, mut b) = (exact(1, 0), exact(1, 0));
    for k in 2..=6u32 {
        for s in 0..k - 1 {
            select(&mut a, k, s);
            select(&mut b, k, s + 1);
            let (la, lb) = (a.matrices.layout.clone(), b.matrices.layout.clone());
            for n in [2, 3, 5, 7] {
                for i in 0..=n {
                    let t = q(i, n);
                    for (ka, kb) in [
                        (StencilKind::Position, StencilKind::Position),
                        (StencilKind::DerivativeV, StencilKind::DerivativeU),
                    ] {
                        if i == 0 && ka != StencilKind::Position {
                            continue;
                        }
                        let x = a.stencil_of_kind(&q(0, 1), &t, ka).expect("in the patch");
                        let y = b.stencil_of_kind(&t, &q(0, 1), kb).expect("in the patch");
                        assert_eq!(
                            named(&la, &x),
                            named(&lb, &y),
                            "{ka:?} k = {k}, sectors {s}/{}, t = {i}/{n}",
                            s + 1
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn mirror_symmetry_between_sectors_s_and_k_minus_1_minus_s() {
    // The reflection of the wedge swaps E_i and E_{k-i}: (a, b) of sector s' is (b, a) of
    // sector k-1-s', a ray point (a, 0) of ray s' is (a, 0) of ray k-s'; it swaps u and v.
    let (mut a, mut b) = (exact(1, 0), exact(1, 0));
    for k in 1..=6u32 {
        let mirror = |p: TrianglePoint| match p {
            TrianglePoint::Centre => p,
            TrianglePoint::Sector { s, a, b: 0 } => ray(k - s, a),
            TrianglePoint::Sector { s, a, b } => TrianglePoint::Sector {
                s: k - 1 - s,
                a: b,
                b: a,
            },
        };
        for s in 0..k {
            select(&mut a, k, s);
            select(&mut b, k, k - 1 - s);
            let (la, lb) = (a.matrices.layout.clone(), b.matrices.layout.clone());
            for n in [3, 5, 7] {
                for j in 0..=n {
                    for i in 0..=n - j {
                        for (ka, kb) in [
                            (StencilKind::Position, StencilKind::Position),
                            (StencilKind::DerivativeU, StencilKind::DerivativeV),
                        ] {
                            if (i, j) == (0, 0) && ka != StencilKind::Position {
                                continue;
                            }
                            let x = a.stencil_of_kind(&q(i, n), &q(j, n), ka).expect("inside");
                            let y = b.stencil_of_kind(&q(j, n), &q(i, n), kb).expect("inside");
                            let mirrored: BTreeMap<_, _> = named(&la, &x)
                                .into_iter()
                                .map(|(p, w)| (mirror(p), w))
                                .collect();
                            assert_eq!(
                                mirrored,
                                named(&lb, &y),
                                "{ka:?} k = {k}, s = {s}, ({i}/{n}, {j}/{n})"
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn boundary_tangent_lies_in_the_tangent_masks_span() {
    // E_k - E_0 (the boundary curve's tangent at V, up to the factor 1/2) must be a
    // combination alpha du + beta dv; on the half-disk net du, dv map to E_s, E_{s+1}, and
    // E_k - E_0 to (-2, 0), which fixes alpha, beta.
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for k in 1..=8u32 {
        let theta = std::f64::consts::PI / f64::from(k.max(2));
        for s in 0..k {
            let m = TriangleLocalMatrices::boundary(&loop_, k, s).expect("valid");
            let t = loop_boundary_tangents(&m).expect("tangents");
            let (e, f) = (f64::from(s) * theta, f64::from(s + 1) * theta);
            // alpha (cos e, sin e) + beta (cos f, sin f) = image of E_k - E_0.
            let target = [
                (f64::from(k) * theta).cos() - 1.0,
                (f64::from(k) * theta).sin(),
            ];
            let det = e.cos() * f.sin() - e.sin() * f.cos();
            let alpha = (target[0] * f.sin() - target[1] * f.cos()) / det;
            let beta = (e.cos() * target[1] - e.sin() * target[0]) / det;
            for (i, (x, y)) in t.du.iter().zip(&t.dv).enumerate() {
                let expected = if i == 1 {
                    -1.0
                } else if i == 1 + k as usize {
                    1.0
                } else {
                    0.0
                };
                assert!(
                    (alpha * x + beta * y - expected).abs() < 1e-12,
                    "k = {k}, s = {s}, point {i}"
                );
            }
        }
    }
}

#[test]
fn one_triangle_masks_are_the_edges() {
    // k = 1: t = E_1 - E_0 and the cross mode E_0 - 2V + E_1 (the curve's second difference,
    // eigenvalue 1/4); on the quarter-disk net they map to (-1, 1) and (1, 1), so
    // du = (c - t)/2 = E_0 - V and dv = (c + t)/2 = E_1 - V.
    let loop_ = triangle_scheme("loop").expect("catalogued");
    let m = TriangleLocalMatrices::boundary(&loop_, 1, 0).expect("valid");
    let t = loop_boundary_tangents(&m).expect("tangents");
    let expected_du = [-1.0, 1.0, 0.0, 0.0, 0.0, 0.0];
    let expected_dv = [-1.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    for i in 0..6 {
        assert!((t.du[i] - expected_du[i]).abs() < 1e-12, "{:?}", t.du);
        assert!((t.dv[i] - expected_dv[i]).abs() < 1e-12, "{:?}", t.dv);
    }
    assert!((t.across - 0.25).abs() < 1e-15);
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    (dot / (norm(a) * norm(b))).clamp(-1.0, 1.0).acos()
}

/// A non-planar net: the half-disk layout lifted onto `z = 0.4 x^2 - 0.3 y^2 + 0.2 x y`,
/// with a small fixed perturbation per point so no symmetry helps.
fn curved_net(k: u32, layout: &[TrianglePoint]) -> Vec<[f64; 3]> {
    let theta = std::f64::consts::PI / f64::from(k.max(2));
    let dir = |s: u32| [(f64::from(s) * theta).cos(), (f64::from(s) * theta).sin()];
    layout
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = match *p {
                TrianglePoint::Centre => (0.0, 0.0),
                TrianglePoint::Sector { s, a, b } => {
                    let (e, f) = (dir(s), dir(s + 1));
                    let (a, b) = (a as f64, b as f64);
                    (a * e[0] + b * f[0], a * e[1] + b * f[1])
                }
            };
            let wobble = 0.05 * ((i as f64) * 1.7).sin();
            [x, y, 0.4 * x * x - 0.3 * y * y + 0.2 * x * y + wobble]
        })
        .collect()
}

/// For `N = 2^j`: the angle between `du x dv` at `V` and the normal at `(1/N, 1/N)`, and
/// `|cos|` of the angle between that normal and the boundary curve's tangent at `V`,
/// `(E_k - E_0) . P` (a tangent plane at `V` must contain it: the curve lies on the surface).
fn normal_angles(k: u32, s: u32, levels: &[u32]) -> Vec<(f64, f64)> {
    let mut f = float(k, s);
    let net = curved_net(k, &f.matrices.layout);
    let apply = |w: &[f64]| {
        w.iter().zip(&net).fold([0.0; 3], |acc, (w, p)| {
            [acc[0] + w * p[0], acc[1] + w * p[1], acc[2] + w * p[2]]
        })
    };
    let mut normal_at = |u: &BigRational| {
        let du = f
            .stencil_of_kind(u, u, StencilKind::DerivativeU)
            .expect("in the patch");
        let dv = f
            .stencil_of_kind(u, u, StencilKind::DerivativeV)
            .expect("in the patch");
        cross(apply(&du), apply(&dv))
    };
    let at_vertex = normal_at(&q(0, 1));
    let tangent = {
        let (e0, ek) = (net[1], net[1 + k as usize]);
        [ek[0] - e0[0], ek[1] - e0[1], ek[2] - e0[2]]
    };
    levels
        .iter()
        .map(|&j| {
            let u = BigRational::new(1.into(), num_bigint::BigInt::from(2).pow(j));
            let n = normal_at(&u);
            (
                angle(at_vertex, n),
                (std::f64::consts::FRAC_PI_2 - angle(tangent, n))
                    .abs()
                    .sin(),
            )
        })
        .collect()
}

#[test]
fn normals_just_inside_converge_to_the_vertex_normal() {
    // du x dv at V must be the limit of the normals inside (orientation included: a flipped
    // normal would give angles near pi). Measured rate: the ratio of the eigenvalue after the
    // tangent pair (1/2, mu_1) to the smaller of the pair, e.g. (3/8)/(1/2) per halving at
    // k = 4 and 0.452/0.5 at k = 5.
    for k in 1..=5u32 {
        for s in 0..k {
            let a = normal_angles(k, s, &[8, 24]);
            assert!(a[1].0 < 2e-3, "k = {k}, s = {s}: {a:?}");
            assert!(a[1].0 <= a[0].0 / 2.0, "k = {k}, s = {s}: {a:?}");
            assert!(a[1].1 < 2e-3, "k = {k}, s = {s}: {a:?}");
        }
    }
}

#[test]
fn from_seven_triangles_on_the_surface_has_no_tangent_plane_at_the_vertex() {
    // k >= 7: mu_2 = 3/8 + cos(2 pi/k)/4 > 1/2, so the two largest subdominant modes are both
    // cross-boundary modes and the normals inside tend to their plane, which does not contain
    // the boundary curve's tangent: no tangent plane at V (Hoppe's boundary rules are not C1
    // there). Measured here on a generic net, deep inside (N = 2^36).
    for k in 7..=8u32 {
        for s in 0..k {
            let a = normal_angles(k, s, &[24, 36]);
            assert!(a[1].0 > 1e-2, "k = {k}, s = {s}: {a:?}");
            assert!(a[1].1 > 1e-2, "k = {k}, s = {s}: {a:?}");
        }
    }
}

#[test]
#[ignore = "measurement for docs/algorithms/triangle-schemes.md; prints, asserts nothing new"]
fn print_boundary_eigenvalues_and_normal_angles() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for k in 1..=8u32 {
        let m = TriangleLocalMatrices::boundary(&loop_, k, 0).expect("valid");
        let t = loop_boundary_tangents(&m).expect("tangents");
        println!(
            "k = {k}: across = {:.6}, ring eigenvalues = {:.6?}",
            t.across, t.ring_eigenvalues
        );
        for s in 0..k {
            let angles: Vec<String> = normal_angles(k, s, &[4, 8, 12, 16, 24, 36])
                .iter()
                .map(|(a, c)| format!("{a:.1e}/{c:.1e}"))
                .collect();
            println!("  sector {s}: (angle to du x dv)/(|cos| to E_k - E_0) at N = 2^4, 2^8, 2^12, 2^16, 2^24, 2^36: {angles:?}");
        }
    }
}
