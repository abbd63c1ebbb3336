//! Stencils of quad schemes next to an extraordinary vertex (Schaefer–Warren section 5.2):
//! the grid solve against plain substitution, the regular case against the closed-form
//! bicubic B-spline, and the symmetries and continuity any correct stencil must have.

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::{BivariateMask, CurveScheme, QuadScheme};
use stencilgen::bivariate_system::bivariate_stencils;
use stencilgen::curve_stencils;
use stencilgen::extraordinary_patch::{canonical, patch_layout, GridPoint, Neighbourhood};
use stencilgen::patch_stencils::{patch_stencils, PatchStencils};
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::substitution::Substitution;
use subtess_tests::bspline::{q, uniform_bspline, uniform_bspline_derivative};

fn scheme(name: &str) -> QuadScheme {
    QuadScheme::by_name(name).expect("catalogued")
}

fn exact(s: &QuadScheme, v: u32, n: u32, kind: StencilKind) -> PatchStencils<BigRational> {
    exact_at(s, Neighbourhood::interior(v), 0, n, kind)
}

fn exact_at(
    s: &QuadScheme,
    nb: Neighbourhood,
    sector: u32,
    n: u32,
    kind: StencilKind,
) -> PatchStencils<BigRational> {
    patch_stencils::<BigRational>(s, nb, sector, n, kind).expect("solvable")
}

fn point(a: i64, b: i64, n: u32) -> (BigRational, BigRational) {
    let d = 2 * i64::from(n);
    (q(a, d), q(b, d))
}

/// The grid solve (scaling relation as a system) equals plain substitution
/// `psi(t) R_b A^k` exactly, at every primal and dual point, for positions and both
/// derivatives, every valence 3..=8 and each n of `rates`.
fn grid_solve_equals_substitution(name: &str, rates: &[u32]) {
    let s = scheme(name);
    for v in 3..=8 {
        let mut substitution = Substitution::<BigRational>::new(&s, Neighbourhood::interior(v), 0)
            .expect("substitution");
        for &n in rates {
            for kind in StencilKind::ALL {
                let grid = exact(&s, v, n, kind);
                for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
                    let Some(stencil) = stencil else {
                        assert!((a, b) == (0, 0) && kind != StencilKind::Position);
                        continue;
                    };
                    let (u, w) = point(a, b, n);
                    let expected = substitution
                        .stencil(&u, &w, kind)
                        .expect("substitution stencil");
                    assert_eq!(
                        stencil, &expected,
                        "{name} v = {v} n = {n} {kind:?} at ({u}, {w})"
                    );
                }
            }
        }
    }
}

/// By default the rates below 24; rate 24 (85% of the time, 36 s in the dev profile) runs
/// with `cargo test -p subtess-tests --test quad_stencils -- --ignored`.
const SUBSTITUTION_RATES: [u32; 6] = [1, 2, 3, 5, 7, 12];

#[test]
fn catmull_clark_grid_solve_equals_substitution() {
    grid_solve_equals_substitution("catmull-clark", &SUBSTITUTION_RATES);
}

#[test]
fn sw_nonpoly_quad_grid_solve_equals_substitution() {
    grid_solve_equals_substitution("sw-nonpoly-quad", &SUBSTITUTION_RATES);
}

#[test]
#[ignore = "rate 24 of the grid = substitution check; the rates below run by default"]
fn grid_solve_equals_substitution_at_rate_24() {
    grid_solve_equals_substitution("catmull-clark", &[24]);
    grid_solve_equals_substitution("sw-nonpoly-quad", &[24]);
}

/// Positions of the layout points at valence 4, in sector-0 grid coordinates.
fn regular_positions() -> Vec<(i64, i64)> {
    let mut p = vec![
        (0, 0),
        (1, 0),
        (0, 1),
        (-1, 0),
        (0, -1),
        (1, 1),
        (-1, 1),
        (-1, -1),
        (1, -1),
    ];
    p.extend([(2, -1), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (-1, 2)]);
    p
}

/// Valence 4 is the regular case: Catmull–Clark stencils equal the bicubic B-spline
/// `B3(u - p + 2) B3(v - q + 2)` (truncated-power closed form) and its derivatives everywhere.
#[test]
fn catmull_clark_valence_4_is_the_bicubic_bspline() {
    let s = scheme("catmull-clark");
    let positions = regular_positions();
    for n in 1..=8u32 {
        for kind in StencilKind::ALL {
            let grid = exact(&s, 4, n, kind);
            for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
                let Some(stencil) = stencil else { continue };
                let (u, w) = point(a, b, n);
                for (weight, &(p, r)) in stencil.iter().zip(&positions) {
                    let (x, y) = (&u - q(p, 1) + q(2, 1), &w - q(r, 1) + q(2, 1));
                    let expected = match kind {
                        StencilKind::Position => uniform_bspline(3, &x) * uniform_bspline(3, &y),
                        StencilKind::DerivativeU => {
                            uniform_bspline_derivative(3, &x) * uniform_bspline(3, &y)
                        }
                        StencilKind::DerivativeV => {
                            uniform_bspline(3, &x) * uniform_bspline_derivative(3, &y)
                        }
                    };
                    assert_eq!(
                        *weight, expected,
                        "n = {n} {kind:?} at ({u}, {w}) point ({p}, {r})"
                    );
                }
            }
        }
    }
}

/// Valence 4 of sw-nonpoly-quad is the tensor product of the sw-nonpoly curve basis.
#[test]
fn sw_nonpoly_quad_valence_4_is_the_tensor_product() {
    let s = scheme("sw-nonpoly-quad");
    let curve = CurveScheme::by_name("sw-nonpoly").expect("catalogued");
    for n in [1u32, 2, 3, 6] {
        let phi = curve_stencils::<BigRational>(&curve, n, false)
            .expect("curve")
            .functions
            .remove(0);
        let grid = exact(&s, 4, n, StencilKind::Position);
        let ni = i64::from(n);
        for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
            let stencil = stencil.as_ref().expect("positions everywhere");
            if a % 2 == 1 {
                continue; // dual points are off the curve grid 1/n
            }
            for (weight, &(p, r)) in stencil.iter().zip(&regular_positions()) {
                let expected = phi.at(a / 2 - p * ni) * phi.at(b / 2 - r * ni);
                assert_eq!(
                    *weight,
                    expected,
                    "n = {n} at ({a}, {b})/{} point ({p}, {r})",
                    2 * n
                );
            }
        }
    }
}

/// Positions sum to 1, tangents to 0; the limit position at the EV is the classical
/// Catmull–Clark limit mask (v^2 V + 4 sum E + sum F) / (v (v + 5)) (Halstead et al. 1993).
#[test]
fn sums_and_the_limit_mask() {
    for name in ["catmull-clark", "sw-nonpoly-quad"] {
        let s = scheme(name);
        for v in 3..=8u32 {
            for kind in StencilKind::ALL {
                let grid = exact(&s, v, 5, kind);
                let expected = if kind == StencilKind::Position {
                    BigRational::one()
                } else {
                    BigRational::zero()
                };
                for stencil in grid.stencils.iter().flatten() {
                    assert_eq!(
                        stencil.iter().sum::<BigRational>(),
                        expected,
                        "{name} v = {v} {kind:?}"
                    );
                }
            }
        }
    }
    let cc = scheme("catmull-clark");
    for v in 3..=8u32 {
        let grid = exact(&cc, v, 1, StencilKind::Position);
        let mask = grid.at(0, 0).expect("limit mask");
        let vi = i64::from(v);
        let d = vi * (vi + 5);
        for (i, w) in mask.iter().enumerate() {
            let expected = match i {
                0 => q(vi * vi, d),
                i if i <= v as usize => q(4, d),
                i if i <= 2 * v as usize => q(1, d),
                _ => BigRational::zero(),
            };
            assert_eq!(*w, expected, "v = {v} index {i}");
        }
    }
}

/// Index permutation of the layout under the reflection u <-> v (sector s -> -s, a <-> b).
fn mirror(v: u32) -> Vec<usize> {
    let nb = Neighbourhood::interior(v);
    let layout = patch_layout(nb, 0);
    let index: HashMap<GridPoint, usize> =
        layout.iter().enumerate().map(|(i, &p)| (p, i)).collect();
    layout
        .iter()
        .map(|p| match *p {
            GridPoint::Centre => 0,
            GridPoint::Sector { s, a, b } => {
                index[&canonical(nb, -i64::from(s), b, a).expect("interior")]
            }
        })
        .collect()
}

/// Swapping u and v mirrors the stencil (and swaps d/du with d/dv).
#[test]
fn swapping_u_and_v_mirrors_the_stencil() {
    for name in ["catmull-clark", "sw-nonpoly-quad"] {
        let s = scheme(name);
        for v in 3..=8u32 {
            let perm = mirror(v);
            let n = 4;
            let pos = exact(&s, v, n, StencilKind::Position);
            let du = exact(&s, v, n, StencilKind::DerivativeU);
            let dv = exact(&s, v, n, StencilKind::DerivativeV);
            for &(a, b) in &pos.points {
                let mirrored = |st: &[BigRational]| {
                    let mut out = vec![BigRational::zero(); st.len()];
                    for (i, w) in st.iter().enumerate() {
                        out[perm[i]] = w.clone();
                    }
                    out
                };
                assert_eq!(
                    pos.at(b, a).map(<[_]>::to_vec),
                    pos.at(a, b).map(mirrored),
                    "{name} v = {v} ({a},{b})"
                );
                assert_eq!(
                    dv.at(b, a).map(<[_]>::to_vec),
                    du.at(a, b).map(mirrored),
                    "{name} v = {v} ({a},{b})"
                );
            }
        }
    }
}

/// A stencil as weights on named grid points; `rotate` shifts sector indices (the same patch
/// one sector further round the vertex).
fn named(v: u32, stencil: &[BigRational], rotate: i64) -> HashMap<GridPoint, BigRational> {
    let nb = Neighbourhood::interior(v);
    patch_layout(nb, 0)
        .into_iter()
        .zip(stencil)
        .filter(|(_, w)| !w.is_zero())
        .map(|(p, w)| {
            let p = match p {
                GridPoint::Centre => p,
                GridPoint::Sector { s, a, b } => {
                    canonical(nb, i64::from(s) + rotate, a, b).expect("interior")
                }
            };
            (p, w.clone())
        })
        .collect()
}

/// Neighbouring patches agree on their shared edges: the EV patch of sector 0 at (0, t) and
/// that of sector 1 at (t, 0) (edge V-E_2; d/dv of one is d/du of the other), and the EV patch
/// at (1, t) and the regular patch beyond u = 1 at (0, t).
#[test]
fn neighbouring_patches_agree_along_shared_edges() {
    for name in ["catmull-clark", "sw-nonpoly-quad"] {
        let s = scheme(name);
        let curve = CurveScheme::by_name(s.regular_curve).expect("catalogued");
        for v in 3..=8u32 {
            let n = 6u32;
            let nn = 2 * i64::from(n);
            let pos = exact(&s, v, n, StencilKind::Position);
            let du = exact(&s, v, n, StencilKind::DerivativeU);
            let dv = exact(&s, v, n, StencilKind::DerivativeV);
            for t in (2..=nn).step_by(2) {
                let here = named(v, pos.at(0, t).expect("grid"), 0);
                let there = named(v, pos.at(t, 0).expect("grid"), 1);
                assert_eq!(here, there, "{name} v = {v} edge V-E2 at t = {t}/{nn}");
                let here = named(v, dv.at(0, t).expect("grid"), 0);
                let there = named(v, du.at(t, 0).expect("grid"), 1);
                assert_eq!(
                    here, there,
                    "{name} v = {v} d/dv along V-E2 at t = {t}/{nn}"
                );
            }
            // Regular patch on the cell [1,2] x [0,1] of sector 0, at its u = 0 edge.
            let phi = curve_stencils::<BigRational>(&curve, n, false)
                .expect("curve")
                .functions
                .remove(0);
            let ni = i64::from(n);
            for t in 0..=ni {
                let mut regular: HashMap<GridPoint, BigRational> = HashMap::new();
                for qq in -1..=2 {
                    for p in -1..=2 {
                        let w = phi.at(-p * ni) * phi.at(t - qq * ni);
                        if !w.is_zero() {
                            let point = canonical(Neighbourhood::interior(v), 0, 1 + p, qq)
                                .expect("interior");
                            *regular.entry(point).or_insert_with(BigRational::zero) += w;
                        }
                    }
                }
                let ev = named(v, pos.at(nn, 2 * t).expect("grid"), 0);
                assert_eq!(ev, regular, "{name} v = {v} edge u = 1 at v = {t}/{n}");
            }
        }
    }
}

/// The f64 path agrees with the exact one within 1e-12.
#[test]
fn f64_agrees_with_exact() {
    for name in ["catmull-clark", "sw-nonpoly-quad"] {
        let s = scheme(name);
        for v in 3..=8u32 {
            for n in [1u32, 3, 7, 12] {
                for kind in StencilKind::ALL {
                    let e = exact(&s, v, n, kind);
                    let f = patch_stencils::<f64>(&s, Neighbourhood::interior(v), 0, n, kind)
                        .expect("f64");
                    assert!(
                        f.residual < 1e-12,
                        "{name} v = {v} n = {n}: residual {}",
                        f.residual
                    );
                    for (se, sf) in e.stencils.iter().zip(&f.stencils) {
                        let (Some(se), Some(sf)) = (se, sf) else {
                            continue;
                        };
                        for (a, b) in se.iter().zip(sf) {
                            assert!(
                                (rational_to_f64(a) - b).abs() < 1e-12,
                                "{name} v = {v} n = {n} {kind:?}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// The bivariate system solved directly in 2D equals the tensor product of the curve
/// solution, values and both derivatives.
#[test]
fn bivariate_system_equals_tensor_product_of_curves() {
    for name in ["cubic-bspline", "sw-nonpoly", "quadratic-bspline"] {
        let curve = CurveScheme::by_name(name).expect("catalogued");
        let mask = BivariateMask::tensor(&curve).expect("uniform");
        for n in 1..=5u32 {
            let phi = curve_stencils::<BigRational>(&curve, n, false)
                .expect("curve")
                .functions
                .remove(0);
            let dphi = curve_stencils::<BigRational>(&curve, n, true)
                .expect("curve")
                .functions
                .remove(0);
            for kind in StencilKind::ALL {
                let grid = bivariate_stencils::<BigRational>(&mask, n, kind).expect("bivariate");
                let ni = i64::from(n);
                let ((lx, hx), (ly, hy)) = grid.support;
                for k2 in ly * ni..=hy * ni {
                    for k1 in lx * ni..=hx * ni {
                        let expected = match kind {
                            StencilKind::Position => phi.at(k1) * phi.at(k2),
                            StencilKind::DerivativeU => dphi.at(k1) * phi.at(k2),
                            StencilKind::DerivativeV => phi.at(k1) * dphi.at(k2),
                        };
                        assert_eq!(
                            grid.at(k1, k2),
                            expected,
                            "{name} n = {n} {kind:?} ({k1}, {k2})/{n}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn substitution_reaches_rationals_off_every_grid() {
    // (1/7, 2/9) is on no grid the tables use; positions still sum to one and equal the grid
    // solve at n = 63 (the lcm of 7 and 9).
    let s = scheme("catmull-clark");
    let mut substitution =
        Substitution::<BigRational>::new(&s, Neighbourhood::interior(5), 0).expect("substitution");
    let (u, w) = (q(1, 7), q(2, 9));
    let stencil = substitution
        .stencil(&u, &w, StencilKind::Position)
        .expect("stencil");
    assert_eq!(stencil.iter().sum::<BigRational>(), BigRational::one());
    let grid = exact(&s, 5, 63, StencilKind::Position);
    assert_eq!(grid.at(18, 28).expect("grid point"), stencil.as_slice());
}

/// sw-nonpoly-quad is C1 at valences 3..=8 by the eigen-analysis of its local subdivision
/// matrix (docs/algorithms/sw-nonpoly-quad.md): 1 is simple, the subdominant eigenvalue is
/// double and equals the closed form (T + sqrt(T^2 - 1/6))/2, T = 7/12 + cos(2 pi/v)/6, of the
/// Fourier blocks, and every other eigenvalue is smaller in modulus. Its limit mask is
/// 9/25 V + 12/(25v) sum E + 4/(25v) sum F.
#[test]
fn sw_nonpoly_quad_eigen_structure_and_limit_mask() {
    let s = scheme("sw-nonpoly-quad");
    for v in 3..=8u32 {
        let m =
            stencilgen::extraordinary_patch::LocalMatrices::new(&s, Neighbourhood::interior(v), 0)
                .expect("valid");
        let k = m.size();
        let a = nalgebra::DMatrix::from_fn(k, k, |i, j| rational_to_f64(&m.a[i][j]));
        // A bounded Schur iteration: a matrix it cannot settle fails the test instead of hanging it.
        let schur = nalgebra::linalg::Schur::try_new(a, 1e-14, 100_000)
            .expect("Schur decomposition converges");
        let mut moduli: Vec<f64> = schur
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .collect();
        moduli.sort_by(|x, y| y.total_cmp(x));
        let t = 7.0 / 12.0 + (2.0 * std::f64::consts::PI / f64::from(v)).cos() / 6.0;
        let lambda = (t + (t * t - 1.0 / 6.0).sqrt()) / 2.0;
        assert!(
            (moduli[0] - 1.0).abs() < 1e-12 && moduli[1] < 1.0 - 1e-9,
            "v = {v}: {moduli:?}"
        );
        assert!(
            (moduli[1] - lambda).abs() < 1e-9 && (moduli[2] - lambda).abs() < 1e-9,
            "v = {v}: {moduli:?}"
        );
        assert!(moduli[3] < lambda - 1e-3, "v = {v}: {moduli:?}");
        let mask = exact(&s, v, 1, StencilKind::Position);
        let mask = mask.at(0, 0).expect("limit mask");
        let vi = i64::from(v);
        for (i, w) in mask.iter().enumerate() {
            let expected = match i {
                0 => q(9, 25),
                i if i <= v as usize => q(12, 25 * vi),
                i if i <= 2 * v as usize => q(4, 25 * vi),
                _ => BigRational::zero(),
            };
            assert_eq!(*w, expected, "v = {v} index {i}");
        }
    }
}

/// The characteristic map (the patch evaluated on the subdominant right eigenvectors of `A`)
/// is regular and injective for both schemes at valences 3..=8, checked on the primal grid at
/// n = 16: every grid triangle has the same orientation, and, normalized so that the images of
/// the edges V-E_1 and V-E_2 lie on the rays at angles 0 and 2 pi/v, the whole patch stays in
/// that wedge — so by the rotational symmetry the v sectors do not overlap (Reif's criterion,
/// with the eigenvalue test above).
#[test]
fn characteristic_maps_are_regular_and_injective() {
    for name in ["catmull-clark", "sw-nonpoly-quad"] {
        let s = scheme(name);
        for v in 3..=8u32 {
            let m = stencilgen::extraordinary_patch::LocalMatrices::new(
                &s,
                Neighbourhood::interior(v),
                0,
            )
            .expect("valid");
            let k = m.size();
            let a = nalgebra::DMatrix::from_fn(k, k, |i, j| rational_to_f64(&m.a[i][j]));
            // The subdominant eigenvalue, from the invariant 1-ring block (the full K x K matrix has
            // defective outer blocks, on which nalgebra's Schur iteration does not settle).
            let lambda = stencilgen::ev_tangents::ev_tangents(&m)
                .expect("tangents")
                .lambda;
            // Right eigenvectors: the null space of A - lambda I.
            let svd = (a - nalgebra::DMatrix::identity(k, k) * lambda).svd(false, true);
            let v_t = svd.v_t.expect("vectors");
            let mut order: Vec<usize> = (0..k).collect();
            order.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
            assert!(
                svd.singular_values[order[1]] < 1e-9,
                "{name} v = {v}: not a double eigenvalue"
            );
            let net: Vec<[f64; 2]> = (0..k)
                .map(|j| [v_t[(order[0], j)], v_t[(order[1], j)]])
                .collect();
            let n = 16u32;
            let grid =
                patch_stencils::<f64>(&s, Neighbourhood::interior(v), 0, n, StencilKind::Position)
                    .expect("f64");
            let eval = |i: i64, j: i64| -> [f64; 2] {
                let w = grid.at(2 * i, 2 * j).expect("primal point");
                w.iter().zip(&net).fold([0.0, 0.0], |acc, (w, p)| {
                    [acc[0] + w * p[0], acc[1] + w * p[1]]
                })
            };
            let ni = i64::from(n);
            // Normalize: S(1,0) -> (1, 0), S(0,1) -> (cos t, sin t).
            let theta = 2.0 * std::f64::consts::PI / f64::from(v);
            let (e1, e2) = (eval(ni, 0), eval(0, ni));
            let det = e1[0] * e2[1] - e1[1] * e2[0];
            assert!(det.abs() > 1e-12, "{name} v = {v}: degenerate edge images");
            let target = [[1.0, theta.cos()], [0.0, theta.sin()]];
            let inv = [[e2[1] / det, -e2[0] / det], [-e1[1] / det, e1[0] / det]];
            let map = |p: [f64; 2]| -> [f64; 2] {
                let c = [
                    inv[0][0] * p[0] + inv[0][1] * p[1],
                    inv[1][0] * p[0] + inv[1][1] * p[1],
                ];
                [
                    target[0][0] * c[0] + target[0][1] * c[1],
                    target[1][0] * c[0] + target[1][1] * c[1],
                ]
            };
            let points: Vec<Vec<[f64; 2]>> = (0..=ni)
                .map(|j| (0..=ni).map(|i| map(eval(i, j))).collect())
                .collect();
            let angle = |p: [f64; 2]| p[1].atan2(p[0]);
            for t in 1..=ni {
                let (on_u, on_v) = (points[0][t as usize], points[t as usize][0]);
                assert!(
                    angle(on_u).abs() < 1e-9,
                    "{name} v = {v}: edge V-E1 leaves its ray"
                );
                assert!(
                    (angle(on_v) - theta).abs() < 1e-9,
                    "{name} v = {v}: edge V-E2 leaves its ray"
                );
            }
            let mut sign = 0.0f64;
            for j in 0..ni as usize {
                for i in 0..ni as usize {
                    let (p00, p10, p11, p01) = (
                        points[j][i],
                        points[j][i + 1],
                        points[j + 1][i + 1],
                        points[j + 1][i],
                    );
                    for (a, b, c) in [(p00, p10, p11), (p00, p11, p01)] {
                        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                        if sign == 0.0 {
                            sign = area.signum();
                        }
                        assert!(area * sign > 0.0, "{name} v = {v}: folded cell ({i}, {j})");
                    }
                    if (i, j) != (0, 0) {
                        let t = angle(p00);
                        assert!(
                            (-1e-9..=theta + 1e-9).contains(&t),
                            "{name} v = {v}: ({i}, {j}) leaves the wedge"
                        );
                    }
                }
            }
        }
    }
}
