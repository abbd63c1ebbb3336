//! √3's regions around an extraordinary vertex (every sector-0 triangle whose surface `V`
//! affects, `schemes::sqrt3_regions`) and their position and derivative stencils
//! (`stencilgen::sqrt3_regions`), against numbers that do not come from that code:
//!
//! * brute force: a random net on the explicit `K`-fan, refined by plain √3 mesh operations
//!   (`subtess_tests::sqrt3_fan`); after `2m` steps the limit position of the vertex at the
//!   region's ternary point `(i/3^m, j/3^m)` (Kobbelt's limit rule) is the stencil there;
//! * valence 6: the regular basis `psi` of the uniform system (and its skew-axis derivatives)
//!   gathered on the plane lattice, the vertex tangents included;
//! * derivatives: central differences of position stencils; `psi`'s derivatives: central
//!   differences of `psi` on a finer grid;
//! * the subdominant eigenvalue: Kobbelt's closed form `(2 + 2 cos(2π/K))/9`;
//! * the vertex tangents span the tangent plane: chords from `V` become orthogonal to their
//!   cross product;
//! * partition of unity (eq. (4)); f64 against exact for `K = 3, 4, 6`.

use nalgebra::DMatrix;
use num_rational::BigRational;
use schemes::triangle::{apply_map, lattice_symmetries};
use schemes::triangle_local::TrianglePoint;
use schemes::TriangleScheme;
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::sqrt3_patch::sqrt3_regular_basis_kind;
use stencilgen::sqrt3_regions::{Sqrt3Basis, Sqrt3RegionStencils, Sqrt3RegionSubstitution};
use stencilgen::triangle_system::triangle_stencils;
use subtess_tests::bspline::q;
use subtess_tests::sqrt3_fan::{name, FanMesh};

fn sqrt3() -> TriangleScheme {
    TriangleScheme::by_name("sqrt3").expect("catalogued")
}

fn name_of(p: TrianglePoint) -> (u32, i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0, 0),
        TrianglePoint::Sector { s, a, b } => (s, a, b),
    }
}

fn random_source() -> impl FnMut() -> f64 {
    let mut seed = 0x5851_f42d_4c95_7f2du64;
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

#[test]
fn brute_force_subdivision_on_every_region() {
    // The limit position of the vertex at chart point c0 + (i e1 + j e2)/3^m of region r after
    // 2m √3 steps must equal the region's rate-3^m stencil applied to the region's layout
    // values, K = 3..=8, m = 1, 2.
    let mut random = random_source();
    let mut worst_all = 0f64;
    let bases: Vec<Sqrt3Basis<f64>> = [3u32, 9]
        .iter()
        .map(|&n| Sqrt3Basis::new(&sqrt3(), n, &[StencilKind::Position]).expect("solvable"))
        .collect();
    for k in 3..=8u32 {
        let regions = Sqrt3RegionStencils::<f64>::new(&sqrt3(), k).expect("valid");
        for (m, basis) in [1u32, 2].into_iter().zip(&bases) {
            let unit = 3i64.pow(m);
            let mut mesh = FanMesh::new(k, 8, unit, &mut random);
            let level0 = mesh.by_name();
            let nets: Vec<Vec<f64>> = regions
                .regions
                .regions
                .iter()
                .map(|r| {
                    r.layout
                        .iter()
                        .map(|&p| {
                            let (s, a, b) = name_of(p);
                            let key = name(k, i64::from(s), unit * a, unit * b);
                            mesh.values[level0[&key]].expect("level 0 is complete")
                        })
                        .collect()
                })
                .collect();
            for _ in 0..2 * m {
                mesh = mesh.subdivide();
            }
            let ids = mesh.by_name();
            let (ring, boundary) = mesh.rings();
            for (r, region) in regions.regions.regions.iter().enumerate() {
                let mut worst = 0f64;
                for j in 0..=unit {
                    for i in 0..=unit - j {
                        let w = regions
                            .stencil(r, basis, (i, j), StencilKind::Position)
                            .expect("in the region");
                        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                        let predicted: f64 = w.iter().zip(&nets[r]).map(|(a, b)| a * b).sum();
                        let (x, y) = region.triangle.chart_point(i, j, unit);
                        let id = ids[&name(k, 0, x, y)];
                        let limit = mesh
                            .limit(id, &ring, &boundary)
                            .expect("inside the valid region");
                        worst = worst.max((predicted - limit).abs());
                    }
                }
                assert!(worst < 1e-12, "K = {k} region {r} m = {m}: {worst:e}");
                worst_all = worst_all.max(worst);
            }
        }
    }
    eprintln!("brute force: worst {worst_all:e}");
}

#[test]
fn valence_six_regions_are_psi_on_the_plane() {
    // At K = 6 every region is a face of the regular lattice: the weight of the layout point at
    // p is psi(c - p), and d/du, d/dv are D_{c1-c0} psi, D_{c2-c0} psi (D_w = w_1 psi_1 +
    // w_2 psi_2) with psi, psi_1, psi_2 from the uniform system; at V too (the vertex tangents'
    // convention must give the true derivatives where they exist).
    let mask = sqrt3().regular_mask();
    let regions = Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), 6).expect("valid");
    for n in [1u32, 2, 3, 4] {
        let psi = StencilKind::ALL
            .map(|kind| triangle_stencils::<BigRational>(&mask, n, kind).expect("solvable"));
        let basis = Sqrt3Basis::<BigRational>::new(&sqrt3(), n, &StencilKind::ALL).expect("ok");
        let ni = i64::from(n);
        for (r, region) in regions.regions.regions.iter().enumerate() {
            let plane: Vec<(i64, i64)> = region
                .layout
                .iter()
                .map(|&p| match p {
                    TrianglePoint::Centre => (0, 0),
                    TrianglePoint::Sector { s, a, b } => {
                        apply_map(lattice_symmetries()[s as usize], (a, b))
                    }
                })
                .collect();
            let corners = region.triangle.corners();
            let axes = [
                (corners[1].0 - corners[0].0, corners[1].1 - corners[0].1),
                (corners[2].0 - corners[0].0, corners[2].1 - corners[0].1),
            ];
            for j in 0..=ni {
                for i in 0..=ni - j {
                    let c = region.triangle.chart_point(i, j, ni);
                    for (kind, axis) in [
                        (StencilKind::Position, None),
                        (StencilKind::DerivativeU, Some(axes[0])),
                        (StencilKind::DerivativeV, Some(axes[1])),
                    ] {
                        let got = regions
                            .stencil(r, &basis, (i, j), kind)
                            .expect("in the region");
                        let expected: Vec<BigRational> = plane
                            .iter()
                            .map(|&(a, b)| {
                                let at = (c.0 - ni * a, c.1 - ni * b);
                                match axis {
                                    None => psi[0].at(at.0, at.1),
                                    Some((w1, w2)) => {
                                        q(w1, 1) * psi[1].at(at.0, at.1)
                                            + q(w2, 1) * psi[2].at(at.0, at.1)
                                    }
                                }
                            })
                            .collect();
                        assert_eq!(got, expected, "region {r} {kind:?} ({i}/{n}, {j}/{n})");
                    }
                    for (p, _) in psi[0].stencil_at(c) {
                        assert!(plane.contains(&p), "region {r}: {p:?} not in the layout");
                    }
                }
            }
        }
    }
}

#[test]
fn psi_derivatives_match_central_differences_of_psi() {
    // psi_u at the rate-3 points against (psi(y + h e_1) - psi(y - h e_1)) / 2h, h = 1/12, from
    // psi on the rate-12 grid; the same for psi_v. A wrong factor, axis or sign is O(1).
    let s = sqrt3();
    let fine = sqrt3_regular_basis_kind::<f64>(&s, 12, StencilKind::Position).expect("ok");
    let mut worst = 0f64;
    for (kind, axis) in [
        (StencilKind::DerivativeU, (1, 0)),
        (StencilKind::DerivativeV, (0, 1)),
    ] {
        let d = sqrt3_regular_basis_kind::<f64>(&s, 3, kind).expect("ok");
        for (k1, k2) in d.points() {
            let (y1, y2) = (4 * k1, 4 * k2);
            let fd = (fine.at(y1 + axis.0, y2 + axis.1) - fine.at(y1 - axis.0, y2 - axis.1)) * 6.0;
            worst = worst.max((fd - d.at(k1, k2)).abs());
        }
    }
    eprintln!("psi derivative vs central difference: {worst:e}");
    assert!(worst < 2e-2, "{worst}");
}

#[test]
fn derivatives_match_central_differences_on_every_region() {
    // x in {(1,1), (2,1), (1,2)}/4 of every region, central differences with h = 1/12 (psi is
    // C^1 with a Hölder derivative: O(h^alpha) agreement, not 1e-12; a wrong factor, axis or
    // sign is O(1)).
    let s = sqrt3();
    let h = 12i64;
    let mut worst = 0f64;
    // psi does not depend on the valence: solved once per denominator the points have.
    let shared: Vec<Sqrt3Basis<f64>> = [4u32, 6, 12]
        .iter()
        .map(|&n| Sqrt3Basis::new(&s, n, &StencilKind::ALL).expect("solvable"))
        .collect();
    for k in 3..=8u32 {
        let mut sub = Sqrt3RegionSubstitution::<f64>::new(&s, k).expect("valid");
        for b in &shared {
            sub.share_basis(b.clone());
        }
        for r in 0..9 {
            for &(i, j) in &[(1i64, 1i64), (2, 1), (1, 2)] {
                let (xu, xv) = (3 * i, 3 * j);
                for (kind, e) in [
                    (StencilKind::DerivativeU, (1, 0)),
                    (StencilKind::DerivativeV, (0, 1)),
                ] {
                    let dv = sub.stencil(r, &q(xu, h), &q(xv, h), kind).expect("ok");
                    assert!(dv.iter().sum::<f64>().abs() < 1e-10, "K = {k} r = {r}");
                    let plus = sub
                        .stencil(r, &q(xu + e.0, h), &q(xv + e.1, h), StencilKind::Position)
                        .expect("ok");
                    let minus = sub
                        .stencil(r, &q(xu - e.0, h), &q(xv - e.1, h), StencilKind::Position)
                        .expect("ok");
                    for ((d, p), m) in dv.iter().zip(&plus).zip(&minus) {
                        worst = worst.max(((p - m) * h as f64 / 2.0 - d).abs());
                    }
                }
            }
        }
    }
    eprintln!("derivatives vs central differences: {worst:e}");
    assert!(worst < 2e-2, "{worst}");
}

#[test]
fn subdominant_eigenvalue_is_kobbelts() {
    // Kobbelt (2000): the double step's subdominant eigenvalue (2 + 2 cos(2 pi/K))/9. It must
    // also dominate every eigenvalue of the whole A but 1 (the premise of the tangents).
    for k in 3..=8u32 {
        let regions = Sqrt3RegionStencils::<f64>::new(&sqrt3(), k).expect("valid");
        let expected = (2.0 + 2.0 * (2.0 * std::f64::consts::PI / f64::from(k)).cos()) / 9.0;
        assert!((regions.lambda - expected).abs() < 1e-12, "K = {k}");
        let m = &regions.regions.corner;
        let n = m.size();
        let a = DMatrix::from_fn(n, n, |i, j| m.a[i][j]);
        let eig = nalgebra::linalg::Schur::try_new(a, 1e-12, 1_000_000)
            .expect("the eigenvalue iteration converges")
            .complex_eigenvalues();
        let mut moduli: Vec<f64> = eig.iter().map(|z| z.norm()).collect();
        moduli.sort_by(|a, b| b.total_cmp(a));
        eprintln!("K = {k}: lambda {expected:.6}, moduli {:?}", &moduli[..6]);
        assert!((moduli[0] - 1.0).abs() < 1e-9, "K = {k}");
        assert!(
            (moduli[1] - expected).abs() < 1e-6,
            "K = {k}: {:?}",
            &moduli[..4]
        );
        assert!(
            (moduli[2] - expected).abs() < 1e-6,
            "K = {k}: {:?}",
            &moduli[..4]
        );
    }
}

#[test]
fn vertex_tangents_span_the_tangent_plane() {
    // A random net in R^3; n = (du x dv) at V. The chord from V to the surface point at
    // (t, 0), (0, t), (t, t) must become orthogonal to n: |chord . n| / |chord| shrinks as
    // t = 3^-k shrinks, geometrically (a wrong mask leaves it O(1)).
    let mut random = random_source();
    for k in 3..=8u32 {
        let mut sub = Sqrt3RegionSubstitution::<f64>::new(&sqrt3(), k).expect("valid");
        let size = sub.stencils.region(0).expect("corner").size();
        let net: Vec<[f64; 3]> = (0..size).map(|_| [random(), random(), random()]).collect();
        let apply = |w: &[f64]| {
            w.iter().zip(&net).fold([0.0; 3], |acc, (x, p)| {
                [acc[0] + x * p[0], acc[1] + x * p[1], acc[2] + x * p[2]]
            })
        };
        let zero = q(0, 1);
        let du = apply(
            &sub.stencil(0, &zero, &zero, StencilKind::DerivativeU)
                .expect("ok"),
        );
        let dv = apply(
            &sub.stencil(0, &zero, &zero, StencilKind::DerivativeV)
                .expect("ok"),
        );
        let normal = [
            du[1] * dv[2] - du[2] * dv[1],
            du[2] * dv[0] - du[0] * dv[2],
            du[0] * dv[1] - du[1] * dv[0],
        ];
        let norm = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        let p0 = apply(
            &sub.stencil(0, &zero, &zero, StencilKind::Position)
                .expect("ok"),
        );
        for dir in [(1i64, 0i64), (0, 1), (1, 1)] {
            let mut angles = Vec::new();
            for den in [9i64, 27, 81, 243] {
                let p = apply(
                    &sub.stencil(0, &q(dir.0, den), &q(dir.1, den), StencilKind::Position)
                        .expect("ok"),
                );
                let chord = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
                let len = chord.iter().map(|x| x * x).sum::<f64>().sqrt();
                let dot: f64 = chord.iter().zip(&normal).map(|(a, b)| a * b).sum();
                angles.push((dot / (len * norm)).abs());
            }
            eprintln!("K = {k} {dir:?}: {angles:?}");
            // Measured decay per tripling: about lambda_3 / lambda (0.59 at K = 8, the slowest).
            assert!(
                angles.windows(2).all(|w| w[1] < 0.7 * w[0]) && angles[3] < 0.25 * angles[0],
                "K = {k} {dir:?}: {angles:?}"
            );
        }
    }
}

#[test]
fn f64_matches_exact_on_every_region() {
    for k in [3u32, 4, 6] {
        let e = Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), k).expect("exact");
        let f = Sqrt3RegionStencils::<f64>::new(&sqrt3(), k).expect("f64");
        for n in [3u32, 6] {
            let be = Sqrt3Basis::<BigRational>::new(&sqrt3(), n, &StencilKind::ALL).expect("ok");
            let bf = Sqrt3Basis::<f64>::new(&sqrt3(), n, &StencilKind::ALL).expect("ok");
            let ni = i64::from(n);
            for r in 0..9 {
                for kind in StencilKind::ALL {
                    for j in 0..=ni {
                        for i in 0..=ni - j {
                            let a = e.stencil(r, &be, (i, j), kind).expect("exact");
                            let b = f.stencil(r, &bf, (i, j), kind).expect("f64");
                            let sum: BigRational = a.iter().sum();
                            let unit = if kind == StencilKind::Position { 1 } else { 0 };
                            assert_eq!(sum, q(unit, 1), "K = {k} r = {r} {kind:?}");
                            for (x, y) in a.iter().zip(&b) {
                                assert!(
                                    (rational_to_f64(x) - y).abs() < 1e-12,
                                    "K = {k} r = {r} {kind:?} ({i}/{n}, {j}/{n})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
