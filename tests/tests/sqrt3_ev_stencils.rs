//! √3's patch next to an interior extraordinary vertex of valence 3..=8, two √3 steps as one
//! ternary step (Schaefer–Warren sections 5.1–5.3): the grid system against substitution
//! (exactly for K = 3, 4, 6; within 1e-12 in f64 for the irrational K = 5, 7, 8), valence 6
//! against the regular basis function of the uniform system, the limit mask at V against
//! Kobbelt's limit rule, partition of unity, the mirror u <-> v, continuity with the
//! neighbouring sector's patch, f64 against exact, and an independent brute-force check: a
//! random net on an explicit K-valent fan mesh refined by plain √3 mesh operations written out
//! here (face centroids, Kobbelt's vertex rule, edge flips), whose vertices' limit positions
//! (Kobbelt's limit rule applied on the refined mesh) must equal the stencils at those
//! vertices' ternary parameters (i/3^m, j/3^m).

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock, PoisonError};

use num_rational::BigRational;
use num_traits::Zero;
use schemes::sqrt3_local::Sqrt3LocalMatrices;
use schemes::triangle_local::TrianglePoint;
use schemes::TriangleScheme;
use stencilgen::scalar::rational_to_f64;
use stencilgen::sqrt3_patch::{
    sqrt3_patch_stencils, sqrt3_patch_stencils_at, sqrt3_regular_basis, Sqrt3PatchStencils,
    Sqrt3Substitution,
};
use stencilgen::triangle_patch::triangle_grid_points;
use stencilgen::triangle_system::TriangleStencils;
use subtess_tests::bspline::q;
use subtess_tests::sqrt3_fan::{alpha, name, FanMesh};

mod common;
use common::{name_of, PatchUnderTest};

fn sqrt3() -> TriangleScheme {
    TriangleScheme::by_name("sqrt3").expect("catalogued")
}

/// √3's regular basis `psi` at rate `n`, solved exactly once per rate for the whole binary
/// (it does not depend on the valence, and the odd rates cost about a second each).
fn basis(n: u32) -> TriangleStencils<BigRational> {
    static CACHE: OnceLock<Mutex<HashMap<u32, TriangleStencils<BigRational>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    let mut cache = cache.lock().unwrap_or_else(PoisonError::into_inner);
    cache
        .entry(n)
        .or_insert_with(|| sqrt3_regular_basis::<BigRational>(&sqrt3(), n).expect("solvable"))
        .clone()
}

fn matrices(k: u32) -> Sqrt3LocalMatrices {
    Sqrt3LocalMatrices::new(&sqrt3(), k).expect("valid")
}

fn exact(k: u32, n: u32) -> Sqrt3PatchStencils<BigRational> {
    sqrt3_patch_stencils_at(&matrices(k), &basis(n), &triangle_grid_points(n), n).expect("solvable")
}

/// [`basis`] rounded to f64.
fn float_basis(n: u32) -> TriangleStencils<f64> {
    let psi = basis(n);
    TriangleStencils {
        values: psi.values.iter().map(rational_to_f64).collect(),
        scheme: psi.scheme,
        n: psi.n,
        kind: psi.kind,
        dilation: psi.dilation,
        hull: psi.hull,
        bbox: psi.bbox,
        residual: psi.residual,
    }
}

fn float(k: u32, n: u32) -> Sqrt3PatchStencils<f64> {
    sqrt3_patch_stencils_at(&matrices(k), &float_basis(n), &triangle_grid_points(n), n)
        .expect("solvable")
}

fn layout(k: u32) -> Vec<TrianglePoint> {
    Sqrt3LocalMatrices::new(&sqrt3(), k).expect("valid").layout
}

/// This scheme's stencils for the checks shared with the other region scheme ([`common`]).
fn under_test() -> PatchUnderTest {
    PatchUnderTest {
        scheme: sqrt3(),
        layout,
        exact,
        float,
        name,
    }
}

#[test]
fn valence_six_is_the_regular_basis_function() {
    common::valence_six_is_the_regular_basis_function(&under_test());
}

#[test]
fn partition_of_unity() {
    common::partition_of_unity(&under_test());
}

#[test]
fn mirror_symmetry_u_v() {
    common::mirror_symmetry_u_v(&under_test());
}

#[test]
fn continuous_with_the_neighbouring_sector() {
    common::continuous_with_the_neighbouring_sector(&under_test());
}

#[test]
fn grid_system_equals_substitution_exactly_for_rational_valences() {
    for k in [3, 4, 6] {
        let mut sub = Sqrt3Substitution::<BigRational>::new(&sqrt3(), k).expect("valid");
        for n in 1..=6 {
            sub.share_basis(basis(n)).expect("sqrt3's basis");
            let grid = exact(k, n);
            assert_eq!(grid.residual, 0.0);
            for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                let by_substitution = sub
                    .stencil(&q(i, i64::from(n)), &q(j, i64::from(n)))
                    .expect("in the patch");
                assert_eq!(stencil, &by_substitution, "K = {k}, ({i}/{n}, {j}/{n})");
            }
        }
    }
}

#[test]
fn grid_system_equals_substitution_in_f64_for_every_valence() {
    for k in 3..=8 {
        let mut sub = Sqrt3Substitution::<f64>::new(&sqrt3(), k).expect("valid");
        for n in [1, 2, 3, 4, 6, 9] {
            sub.share_basis(float_basis(n)).expect("sqrt3's basis");
            let grid = float(k, n);
            assert!(grid.residual < 1e-12, "K = {k} n = {n}: {}", grid.residual);
            for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                let by_substitution = sub
                    .stencil(&q(i, i64::from(n)), &q(j, i64::from(n)))
                    .expect("in the patch");
                for (a, b) in stencil.iter().zip(&by_substitution) {
                    assert!(
                        (a - b).abs() < 1e-12,
                        "K = {k}, ({i}/{n}, {j}/{n}): {a} vs {b}"
                    );
                }
            }
        }
    }
}

#[test]
fn f64_matches_exact_where_exact_exists() {
    // Through the public entry point (which solves psi itself, exactly, and rounds it).
    for k in [3, 4, 6] {
        for n in [4, 6] {
            let e = sqrt3_patch_stencils::<BigRational>(&sqrt3(), k, n).expect("solvable");
            let f = sqrt3_patch_stencils::<f64>(&sqrt3(), k, n).expect("solvable");
            assert_eq!(e.points, f.points);
            for (a, b) in e.stencils.iter().flatten().zip(f.stencils.iter().flatten()) {
                assert!((rational_to_f64(a) - b).abs() < 1e-12, "K = {k}, n = {n}");
            }
        }
    }
}

#[test]
fn limit_mask_at_v_is_kobbelts_limit_rule() {
    // Kobbelt (2000): one step maps V and the average R of its ring to
    // ((1 - a) V + a R, (V + 2 R)/3) (the new ring is the K centroids), whose left fixed vector
    // gives V_inf = (1 - b) V + b R, b = 3a / (1 + 3a): 1 - b at V, b/K at each E_s, 0 beyond.
    for k in 3..=8u32 {
        let kk = k as usize;
        let a = alpha(kk);
        let b = 3.0 * a / (1.0 + 3.0 * a);
        let s = float(k, 3);
        let w = s.at(0, 0).expect("grid");
        assert!((w[0] - (1.0 - b)).abs() < 1e-12, "K = {k}: {}", w[0]);
        for (c, x) in w.iter().enumerate().skip(1) {
            let e = if c <= kk { b / f64::from(k) } else { 0.0 };
            assert!((x - e).abs() < 1e-12, "K = {k}, point {c}: {x} vs {e}");
        }
    }
    // Exactly where alpha is rational: 5/9, 4/9, 1/3 (cos(2 pi/K) = -1/2, 0, 1/2).
    for (k, a) in [(3u32, q(5, 9)), (4, q(4, 9)), (6, q(1, 3))] {
        let b = &a * q(3, 1) / (q(1, 1) + &a * q(3, 1));
        let w = exact(k, 2);
        let w = w.at(0, 0).expect("grid");
        assert_eq!(w[0], q(1, 1) - &b, "K = {k}");
        for (c, x) in w.iter().enumerate().skip(1) {
            let e = if c <= k as usize {
                &b / q(i64::from(k), 1)
            } else {
                BigRational::zero()
            };
            assert_eq!(x, &e, "K = {k}, point {c}");
        }
    }
}

fn random_source() -> impl FnMut() -> f64 {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Refine a random fan `2 m` times and compare the limit positions of the vertices at the
/// patch's ternary points `(i/3^m, j/3^m)` with `stencil(i, j)` applied to the layout's values;
/// the largest difference.
fn brute_force(k: u32, m: u32, stencil: &mut dyn FnMut(i64, i64) -> Vec<f64>) -> f64 {
    let unit = 3i64.pow(m);
    let mut random = random_source();
    let mut mesh = FanMesh::new(k, 6, unit, &mut random);
    let level0 = mesh.by_name();
    let net: Vec<f64> = layout(k)
        .iter()
        .map(|&p| {
            let (s, a, b) = name_of(p);
            let key = name(k, i64::from(s), unit * a, unit * b);
            mesh.values[level0[&key]].expect("level 0 is complete")
        })
        .collect();
    for _ in 0..2 * m {
        mesh = mesh.subdivide();
    }
    let ids = mesh.by_name();
    let (ring, boundary) = mesh.rings();
    let mut worst = 0f64;
    for (i, j) in triangle_grid_points(unit as u32) {
        let id = ids[&name(k, 0, i, j)];
        let limit = mesh
            .limit(id, &ring, &boundary)
            .expect("inside the valid region");
        let predicted: f64 = stencil(i, j).iter().zip(&net).map(|(a, b)| a * b).sum();
        worst = worst.max((predicted - limit).abs());
    }
    worst
}

#[test]
fn brute_force_subdivision_at_ternary_points() {
    // A random net on the fan of radius 6 (every vertex random, also those outside the layout:
    // a layout too small would show), refined by two and four √3 steps; the limit position of
    // the vertex at (i/3^m, j/3^m) must be the grid stencil at rate 3^m applied to the net.
    for k in 3..=8u32 {
        for m in [1, 2] {
            let s = float(k, 3u32.pow(m));
            let worst = brute_force(k, m, &mut |i, j| s.at(i, j).expect("grid").to_vec());
            assert!(worst < 1e-12, "K = {k}, m = {m}: off by {worst:e}");
        }
    }
}

#[test]
fn brute_force_six_steps_by_substitution() {
    // Six √3 steps: the points (i/27, j/27), past the grid systems' rate 24, by substitution.
    for k in [3, 5] {
        let mut sub = Sqrt3Substitution::<f64>::new(&sqrt3(), k).expect("valid");
        let worst = brute_force(k, 3, &mut |i, j| {
            sub.stencil(&q(i, 27), &q(j, 27)).expect("in the patch")
        });
        assert!(worst < 1e-12, "K = {k}: off by {worst:e}");
    }
}

#[test]
#[ignore = "slow sweep: every rate 7..=24 for K = 3, 5, 8"]
fn grid_system_equals_substitution_at_every_rate_up_to_24() {
    let scheme = sqrt3();
    let valences = [3, 5, 8];
    let matrices: Vec<Sqrt3LocalMatrices> = valences
        .iter()
        .map(|&k| Sqrt3LocalMatrices::new(&scheme, k).expect("valid"))
        .collect();
    let mut subs: Vec<Sqrt3Substitution<f64>> = valences
        .iter()
        .map(|&k| Sqrt3Substitution::new(&scheme, k).expect("valid"))
        .collect();
    for n in 7..=24u32 {
        // psi does not depend on the valence: one solve per rate for the three grids.
        let psi = sqrt3_regular_basis::<f64>(&scheme, n).expect("solvable");
        let points = triangle_grid_points(n);
        for (m, sub) in matrices.iter().zip(subs.iter_mut()) {
            sub.share_basis(psi.clone()).expect("sqrt3's basis");
            let grid = sqrt3_patch_stencils_at(m, &psi, &points, n).expect("solvable");
            for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                let by_substitution = sub
                    .stencil(&q(i, i64::from(n)), &q(j, i64::from(n)))
                    .expect("in the patch");
                for (a, c) in stencil.iter().zip(&by_substitution) {
                    assert!(
                        (a - c).abs() < 1e-12,
                        "K = {}, ({i}/{n}, {j}/{n})",
                        m.valence
                    );
                }
            }
        }
    }
}
