//! Catmull–Clark stencils next to a dart (an interior vertex with one infinitely sharp edge,
//! the crease running straight out along sector 0's `+a` axis; `Neighbourhood::dart`):
//!
//! * the grid solve of the scaling relation equals plain substitution (`phi(x) = psi(t) R_b A^k`,
//!   which never forms the system), exactly, at every grid point of every sector;
//! * neighbouring sectors agree on their shared edges, across the crease too (the crease curve
//!   is one curve for both sides, value and derivative along it);
//! * on the crease, the sub-patch beside it is the cubic B-spline of the level-1 crease points,
//!   which are written here by hand from OpenSubdiv's rules (closed form);
//! * the limit mask at the dart is a fixed point of one subdivision step written by hand;
//! * the tangent masks at the dart span an invariant subspace of the one-ring's step.

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::QuadScheme;
use stencilgen::extraordinary_patch::{GridPoint, Neighbourhood};
use stencilgen::patch_stencils::{patch_stencils, PatchStencils};
use stencilgen::regular_patch::StencilKind;
use stencilgen::substitution::Substitution;
use subtess_tests::bspline::{q, uniform_bspline, uniform_bspline_derivative};

mod quad_points;
use quad_points::{add, named};

fn cc() -> QuadScheme {
    QuadScheme::by_name("catmull-clark").expect("catalogued")
}

fn exact(nb: Neighbourhood, sector: u32, n: u32, kind: StencilKind) -> PatchStencils<BigRational> {
    patch_stencils::<BigRational>(&cc(), nb, sector, n, kind).expect("solvable")
}

/// The grid solve equals plain substitution at every grid point (positions and both
/// derivatives; the tangents at the dart itself are irrational and not in the exact grid), for
/// valences 3..=6, every sector, rates 1, 2, 3, 5; each stencil sums to 1 (derivatives: 0).
#[test]
fn dart_grid_solve_equals_substitution() {
    for v in 3..=6 {
        let nb = Neighbourhood::dart(v);
        for sector in 0..v {
            let mut substitution =
                Substitution::<BigRational>::new(&cc(), nb, sector).expect("substitution");
            for n in [1u32, 2, 3, 5] {
                for kind in StencilKind::ALL {
                    let grid = exact(nb, sector, n, kind);
                    let d = 2 * i64::from(n);
                    for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
                        let Some(stencil) = stencil else {
                            assert!((a, b) == (0, 0) && kind != StencilKind::Position);
                            continue;
                        };
                        let expected = substitution
                            .stencil(&q(a, d), &q(b, d), kind)
                            .expect("stencil");
                        assert_eq!(
                            stencil, &expected,
                            "dart {v} sector {sector} n = {n} {kind:?} ({a}, {b})/{d}"
                        );
                        let unit = if kind == StencilKind::Position {
                            BigRational::one()
                        } else {
                            BigRational::zero()
                        };
                        assert_eq!(stencil.iter().sum::<BigRational>(), unit);
                    }
                }
            }
        }
    }
}

/// Sector `s`'s edge `u = 0` is sector `s + 1`'s edge `v = 0` (the edge to `E_{s+2}`), and
/// sector `v - 1`'s edge `u = 0` is sector 0's `v = 0`, the crease: both sides give the same
/// points and the same derivative along the edge. Across the crease this checks that the two
/// sides' sub-patches (reflected from opposite sides) make one curve.
#[test]
fn neighbouring_dart_patches_agree_across_edges_and_the_crease() {
    for v in 3..=6u32 {
        let nb = Neighbourhood::dart(v);
        let n = 4u32;
        let d = 2 * i64::from(n);
        for s in 0..v {
            let t = (s + 1) % v;
            let here = exact(nb, s, n, StencilKind::Position);
            let there = exact(nb, t, n, StencilKind::Position);
            let here_dv = exact(nb, s, n, StencilKind::DerivativeV);
            let there_du = exact(nb, t, n, StencilKind::DerivativeU);
            for x in (0..=d).step_by(2) {
                let (a, b) = (here.at(0, x).expect("grid"), there.at(x, 0).expect("grid"));
                assert_eq!(
                    named(nb, s, a),
                    named(nb, t, b),
                    "dart {v} sectors {s}/{t} at {x}/{d}"
                );
                if x > 0 {
                    let (a, b) = (
                        here_dv.at(0, x).expect("grid"),
                        there_du.at(x, 0).expect("grid"),
                    );
                    assert_eq!(
                        named(nb, s, a),
                        named(nb, t, b),
                        "dart {v} tangents {s}/{t} at {x}/{d}"
                    );
                }
            }
        }
    }
}

/// At valence 4, where the neighbourhood is the regular grid except for the sharp half-line,
/// the crease over `u in [1/2, 1]` (sector 0, `v = 0`) is the uniform cubic B-spline (closed
/// form, truncated powers) of the level-1 crease points, written here from the rules:
/// `C_0` the dart's smooth vertex point `9/16 V + 3/32 sum E + 1/64 sum F`, `C_1 = (V + E_1)/2`
/// the sharp edge's midpoint, `C_2 = (V + 6 E_1 + P_2)/8` the crease rule at `E_1`,
/// `C_3 = (E_1 + P_2)/2`, with `P_2` the crease's next point `(2, 0)`. Positions and `d/du`
/// (twice the curve's derivative: the sub-patch's parameter runs twice as fast). The same on
/// the other side, sector 3's edge `u = 0` with `d/dv`.
#[test]
fn valence_four_crease_is_the_cubic_bspline_of_the_level_one_crease_points() {
    let nb = Neighbourhood::dart(4);
    let point = |s: u32, a: i64, b: i64| GridPoint::Sector { s, a, b };
    let v = GridPoint::Centre;
    let (e1, p2) = (point(0, 1, 0), point(0, 2, 0));
    let mut c0 = vec![(v, q(9, 16))];
    c0.extend((0..4).map(|s| (point(s, 1, 0), q(3, 32))));
    c0.extend((0..4).map(|s| (point(s, 1, 1), q(1, 64))));
    let polygon = [
        c0,
        vec![(v, q(1, 2)), (e1, q(1, 2))],
        vec![(v, q(1, 8)), (e1, q(6, 8)), (p2, q(1, 8))],
        vec![(e1, q(1, 2)), (p2, q(1, 2))],
    ];
    for n in [2u32, 3, 6] {
        let d = 2 * i64::from(n);
        for (sector, kind) in [
            (0, StencilKind::Position),
            (0, StencilKind::DerivativeU),
            (3, StencilKind::Position),
            (3, StencilKind::DerivativeV),
        ] {
            let grid = exact(nb, sector, n, kind);
            for x in i64::from(n)..=d {
                let at = if sector == 0 {
                    grid.at(x, 0)
                } else {
                    grid.at(0, x)
                };
                let Some(stencil) = at else { continue };
                // The level-1 parameter along the crease, 2u - 1, as x/d.
                let t = q(2 * x - d, d);
                let mut expected = HashMap::new();
                for (k, points) in (-1i64..=2).zip(&polygon) {
                    let y = &t - q(k, 1) + q(2, 1);
                    let w = if kind == StencilKind::Position {
                        uniform_bspline(3, &y)
                    } else {
                        uniform_bspline_derivative(3, &y) * q(2, 1)
                    };
                    for (p, c) in points {
                        add(&mut expected, *p, &w * c);
                    }
                }
                assert_eq!(
                    named(nb, sector, stencil),
                    expected,
                    "sector {sector} n = {n} {kind:?} at {x}/{d}"
                );
            }
        }
    }
}

/// The limit position mask at the dart (the grid's stencil at `(0, 0)`, the left eigenvector
/// of `A` for eigenvalue 1) is a fixed point of one subdivision step of the one-ring written
/// here by hand from the rules (smooth vertex point, smooth edge points, the sharp edge's
/// midpoint, face points): `l . P = l . (S P)` for the one-ring's children `S P`, and it
/// vanishes beyond the one-ring. The same mask in every sector, up to the layout's order.
#[test]
fn dart_limit_mask_is_a_fixed_point_of_the_one_ring_rules() {
    for v in 3..=8u32 {
        let nb = Neighbourhood::dart(v);
        let vv = i64::from(v);
        let ring = 1 + 2 * v as usize;
        let grid = exact(nb, 0, 1, StencilKind::Position);
        let l = grid.at(0, 0).expect("the dart's mask");
        assert!(l[ring..].iter().all(Zero::is_zero), "valence {v}");
        // Slots: 0 the dart, 1..=v the E_i, v+1..=2v the F_i (F_i between E_i and E_{i+1}).
        let e = |i: i64| 1 + (i.rem_euclid(vv)) as usize;
        let f = |i: i64| 1 + v as usize + (i.rem_euclid(vv)) as usize;
        let mut children: Vec<Vec<(usize, BigRational)>> = Vec::new();
        let mut dart = vec![(0, q(4 * vv - 7, 4 * vv))];
        for i in 0..vv {
            dart.push((e(i), q(3, 2 * vv * vv)));
            dart.push((f(i), q(1, 4 * vv * vv)));
        }
        children.push(dart);
        for i in 0..vv {
            if i == 0 {
                children.push(vec![(0, q(1, 2)), (e(0), q(1, 2))]);
            } else {
                children.push(vec![
                    (0, q(3, 8)),
                    (e(i), q(3, 8)),
                    (e(i - 1), q(1, 16)),
                    (e(i + 1), q(1, 16)),
                    (f(i - 1), q(1, 16)),
                    (f(i), q(1, 16)),
                ]);
            }
        }
        for i in 0..vv {
            children.push(
                [0, e(i), f(i), e(i + 1)]
                    .into_iter()
                    .map(|k| (k, q(1, 4)))
                    .collect(),
            );
        }
        // (l S)_j = sum_k l_k S[k][j] must be l_j.
        let mut ls = vec![BigRational::zero(); ring];
        for (k, row) in children.iter().enumerate() {
            for (j, w) in row {
                ls[*j] += &l[k] * w;
            }
        }
        assert_eq!(&ls[..], &l[..ring], "valence {v}");
        for sector in 1..v {
            let other = exact(nb, sector, 1, StencilKind::Position);
            assert_eq!(
                named(nb, sector, other.at(0, 0).expect("mask")),
                named(nb, 0, l),
                "valence {v} sector {sector}"
            );
        }
    }
}

/// The f64 tangent masks at the dart (`ev_tangents`) span a left invariant subspace of the
/// one-ring block `A_1` of `A` (residual below 1e-14 after projecting `x A_1` onto their span),
/// the subspace of the two largest eigenvalues below 1: the restriction's trace is at most
/// `2 lambda`, and exactly 1 at valence 4, where `lambda = 1/2` is double.
#[test]
fn dart_tangents_span_the_subdominant_invariant_subspace() {
    use num_traits::ToPrimitive;
    use stencilgen::ev_tangents::ev_tangents;
    use stencilgen::extraordinary_patch::LocalMatrices;
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for v in 3..=8u32 {
        for sector in 0..v {
            let m = LocalMatrices::new(&cc(), Neighbourhood::dart(v), sector).expect("valid");
            let ring = 1 + 2 * v as usize;
            let t = ev_tangents(&m).expect("tangents");
            let (du, dv) = (&t.du[..ring], &t.dv[..ring]);
            assert!(t.du[ring..].iter().chain(&t.dv[ring..]).all(|w| *w == 0.0));
            let times_a1 = |x: &[f64]| -> Vec<f64> {
                (0..ring)
                    .map(|j| {
                        (0..ring)
                            .map(|i| x[i] * m.a[i][j].to_f64().expect("finite"))
                            .sum()
                    })
                    .collect()
            };
            // An orthonormal basis of the span.
            let e1: Vec<f64> = du.iter().map(|x| x / dot(du, du).sqrt()).collect();
            let along = dot(dv, &e1);
            let w: Vec<f64> = dv.iter().zip(&e1).map(|(x, e)| x - along * e).collect();
            let e2: Vec<f64> = w.iter().map(|x| x / dot(&w, &w).sqrt()).collect();
            let mut trace = 0.0;
            for (k, x) in [&e1, &e2].into_iter().enumerate() {
                let y = times_a1(x);
                let (a, b) = (dot(&y, &e1), dot(&y, &e2));
                trace += [a, b][k];
                let residual = y
                    .iter()
                    .zip(e1.iter().zip(&e2))
                    .map(|(y, (p, q))| (y - a * p - b * q).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(residual < 1e-14, "dart {v} sector {sector}: {residual:e}");
            }
            assert!(t.lambda > 0.0 && t.lambda < 1.0, "dart {v}");
            assert!(trace <= 2.0 * t.lambda + 1e-12, "dart {v} sector {sector}");
            if v == 4 {
                assert!((t.lambda - 0.5).abs() < 1e-12 && (trace - 1.0).abs() < 1e-12);
            }
        }
    }
}

/// The dart patches of the default table (`stencilgen::table::default_table()`, the bytes
/// `subtess` embeds: `tables/tests/regenerate.rs`), read back through the table format: for every
/// valence 3..=8 and every sector, the stored pieces give by plain substitution,
/// `phi(x) = psi(2^k x - o_b) R_b A^(k-1)` with `psi` the bicubic B-spline from truncated powers
/// (`uniform_bspline`, not `stencilgen`'s basis), the position stencils that exact substitution
/// on freshly built rational matrices gives, at the primal and dual points of rate 4, to 1e-12;
/// the stored limit mask is the exact one at `(0, 0)`. A wrong feature byte, sector or valence
/// in the keys, or a corrupted piece, would fail here.
#[test]
fn default_table_dart_pieces_give_the_exact_stencils() {
    use table_format::{Feature, PointSet, SectionKey, StencilKind as Kind, Table};
    let bytes = stencilgen::table::default_table().expect("the default table");
    let aligned = table_format::AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    let piece = |v: u32, sector: u32, kind: Kind, points: PointSet| -> Vec<f64> {
        let key = SectionKey {
            kind,
            points,
            boundary: false,
            feature: Feature::Dart,
            faces: v,
            sector,
            n: 0,
        };
        table
            .weights_f64(&key)
            .unwrap_or_else(|e| panic!("{key}: {e}"))
            .to_vec()
    };
    let to_f64 = |x: &BigRational| -> f64 {
        use num_traits::ToPrimitive;
        x.to_f64().expect("finite")
    };
    // psi's 16 weights at t in [0,1]^2, (p, q) in -1..=2, q outer: B_3(t - p + 2) per axis.
    let psi = |t: [&BigRational; 2]| -> Vec<f64> {
        let axis = |t: &BigRational| -> Vec<f64> {
            (-1..=2)
                .map(|p| to_f64(&uniform_bspline(3, &(t - q(p, 1) + q(2, 1)))))
                .collect()
        };
        let (wu, wv) = (axis(t[0]), axis(t[1]));
        wv.iter()
            .flat_map(|b| wu.iter().map(move |a| a * b))
            .collect()
    };
    let mut compared = 0;
    for v in 3..=8u32 {
        let k = 2 * v as usize + 8;
        for sector in 0..v {
            let a = piece(v, sector, Kind::Position, PointSet::Subdivision);
            let r = piece(v, sector, Kind::Position, PointSet::SubPatches);
            let mask = piece(v, sector, Kind::Position, PointSet::VertexMask);
            assert_eq!((a.len(), r.len(), mask.len()), (k * k, 48 * k, k));
            let mut exact = Substitution::<BigRational>::new(&cc(), Neighbourhood::dart(v), sector)
                .expect("substitution");
            let limit = exact
                .stencil(&q(0, 1), &q(0, 1), StencilKind::Position)
                .expect("limit");
            for (stored, want) in mask.iter().zip(&limit) {
                assert!(
                    (stored - to_f64(want)).abs() <= 1e-15,
                    "dart {v} sector {sector}"
                );
            }
            // Rate 4: primal points (i/4, j/4) and dual points ((2i+1)/8, (2j+1)/8), on 1/8.
            let points = (0..=8i64)
                .flat_map(|b| (0..=8i64).map(move |a| (a, b)))
                .filter(|&(a, b)| (a % 2 == 0 && b % 2 == 0) || (a % 2 == 1 && b % 2 == 1))
                .filter(|&p| p != (0, 0));
            for (a_, b_) in points {
                let (mut x, mut y, mut levels) = (q(a_, 8), q(b_, 8), 0);
                while x <= q(1, 2) && y <= q(1, 2) {
                    x *= q(2, 1);
                    y *= q(2, 1);
                    levels += 1;
                }
                // (x, y) in [0,1]^2 minus [0,1/2]^2: sub-patch b at level 1, local 2x - o_b.
                let (tx, ty) = (&x * q(2, 1), &y * q(2, 1));
                let (b, origin) = match (tx >= q(1, 1), ty >= q(1, 1)) {
                    (true, false) => (0, (1, 0)),
                    (true, true) => (1, (1, 1)),
                    _ => (2, (0, 1)),
                };
                let t = [&tx - q(origin.0, 1), &ty - q(origin.1, 1)];
                let w = psi([&t[0], &t[1]]);
                let mut stencil = vec![0.0; k];
                for (row, wr) in w.iter().enumerate() {
                    for (s, rv) in stencil.iter_mut().zip(&r[(16 * b + row) * k..][..k]) {
                        *s += wr * rv;
                    }
                }
                for _ in 0..levels {
                    stencil = (0..k)
                        .map(|j| (0..k).map(|i| stencil[i] * a[i * k + j]).sum())
                        .collect();
                }
                let want = exact
                    .stencil(&q(a_, 8), &q(b_, 8), StencilKind::Position)
                    .expect("stencil");
                for (i, (s, w)) in stencil.iter().zip(&want).enumerate() {
                    assert!(
                        (s - to_f64(w)).abs() <= 1e-12,
                        "dart {v} sector {sector} at ({a_}, {b_})/8, weight {i}: {s} from the \
                         table, {w} exact"
                    );
                }
                compared += 1;
            }
        }
    }
    // 33 patches x (24 primal + 16 dual points).
    assert_eq!(compared, 33 * 40);
}
