//! Properties every EV patch of the modified butterfly and of √3 must have, written once and
//! checked the same way for both (`butterfly_ev_stencils.rs`, `sqrt3_ev_stencils.rs`): valence 6
//! against the regular basis function of the uniform system, partition of unity, the mirror
//! `u <-> v`, and continuity with the neighbouring sector's patch. The expected values come
//! from the uniform system (`triangle_system`, which knows nothing of layouts, tiles or `A`)
//! and from the symmetries of the rules; each scheme hands in its own stencils and its own
//! test-side naming of cone points (its brute-force fan's `name`).

use std::collections::{BTreeMap, HashMap};

use num_rational::BigRational;
use num_traits::One;
use schemes::triangle::{apply_map, lattice_symmetries};
use schemes::triangle_local::TrianglePoint;
use schemes::TriangleScheme;
use stencilgen::cone_patch::{cone_patch_stencils, ConePatchStencils};
use stencilgen::regular_patch::StencilKind;
use stencilgen::triangle_system::triangle_stencils;

/// One scheme's EV-patch stencils as the shared checks read them.
pub struct PatchUnderTest {
    /// The catalogued scheme.
    pub scheme: TriangleScheme,
    /// The layout at valence `K`.
    pub layout: fn(u32) -> Vec<TrianglePoint>,
    /// The exact grid stencils at valence `K`, rate `n`.
    pub exact: fn(u32, u32) -> ConePatchStencils<BigRational>,
    /// The f64 grid stencils at valence `K`, rate `n`.
    pub float: fn(u32, u32) -> ConePatchStencils<f64>,
    /// The test's own naming of cone points: `(s, a, b)` in sector `s`'s chart, canonical.
    pub name: fn(u32, i64, i64, i64) -> (u32, i64, i64),
}

/// `(s, a, b)` of a layout point, `V` as `(0, 0, 0)`.
pub fn name_of(p: TrianglePoint) -> (u32, i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0, 0),
        TrianglePoint::Sector { s, a, b } => (s, a, b),
    }
}

/// The point of the plane where layout point `p` sits at valence 6: `(a, b)` of sector `s` is
/// `R^s (a, b)`, `R` the rotation by 60 degrees.
pub fn plane_position(p: TrianglePoint) -> (i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0),
        TrianglePoint::Sector { s, a, b } => apply_map(lattice_symmetries()[s as usize], (a, b)),
    }
}

/// At valence 6 the patch is a face of the regular lattice: the weight of the control point
/// at `p` is `psi(x - p)`, `psi` from the uniform system (through the public entry point,
/// which solves `psi` itself), and every lattice point with a nonzero weight is in the layout.
pub fn valence_six_is_the_regular_basis_function(t: &PatchUnderTest) {
    let positions: Vec<(i64, i64)> = (t.layout)(6).into_iter().map(plane_position).collect();
    let mask = t.scheme.regular_mask();
    for n in 1..=6u32 {
        let psi =
            triangle_stencils::<BigRational>(&mask, n, StencilKind::Position).expect("solvable");
        let s = cone_patch_stencils::<BigRational>(&t.scheme, 6, n).expect("solvable");
        let ni = i64::from(n);
        for (&(i, j), stencil) in s.points.iter().zip(&s.stencils) {
            let expected: Vec<BigRational> = positions
                .iter()
                .map(|&(a, b)| psi.at(i - ni * a, j - ni * b))
                .collect();
            assert_eq!(stencil, &expected, "({i}/{n}, {j}/{n})");
            for (p, w) in psi.stencil_at((i, j)) {
                assert!(positions.contains(&p), "({i}/{n}, {j}/{n}): {p:?} has {w}");
            }
        }
    }
}

/// Every stencil sums to 1: exactly at `K = 3, 4, 6`, within 1e-12 in f64 at `K = 3..=8`.
pub fn partition_of_unity(t: &PatchUnderTest) {
    for k in [3, 4, 6] {
        for n in [2, 5] {
            for w in &(t.exact)(k, n).stencils {
                assert!(w.iter().sum::<BigRational>().is_one(), "K = {k}");
            }
        }
    }
    for k in 3..=8 {
        for w in &(t.float)(k, 5).stencils {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "K = {k}");
        }
    }
}

/// Reflecting sector 0 across its bisector, `(a, b) -> (b, a)`, maps sector `s` to sector `-s`
/// with its axes swapped; the rules are symmetric, so `stencil(i, j) = stencil(j, i)` with the
/// layout reflected (within 1e-12 in f64 at `K = 3..=8`, exactly at `K = 3, 4`).
pub fn mirror_symmetry_u_v(t: &PatchUnderTest) {
    for k in 3..=8u32 {
        let lay = (t.layout)(k);
        let index: HashMap<_, _> = lay
            .iter()
            .enumerate()
            .map(|(i, &p)| (name_of(p), i))
            .collect();
        let mirror: Vec<usize> = lay
            .iter()
            .map(|&p| {
                let (s, a, b) = name_of(p);
                index[&(t.name)(k, -i64::from(s), b, a)]
            })
            .collect();
        let s = (t.float)(k, 5);
        for &(i, j) in &s.points {
            let (a, b) = (s.at(i, j).expect("grid"), s.at(j, i).expect("grid"));
            for p in 0..a.len() {
                assert!(
                    (a[p] - b[mirror[p]]).abs() < 1e-12,
                    "K = {k} ({i}, {j}) point {p}"
                );
            }
        }
        if matches!(k, 3 | 4) {
            let e = (t.exact)(k, 5);
            for &(i, j) in &e.points {
                let (a, b) = (e.at(i, j).expect("grid"), e.at(j, i).expect("grid"));
                for p in 0..a.len() {
                    assert_eq!(a[p], b[mirror[p]], "K = {k} ({i}, {j}) point {p}");
                }
            }
        }
    }
}

/// The edge `u = 0` (`V` to `E_1`) is the edge `v = 0` of sector 1's patch, which is this
/// patch turned by one sector: `stencil(0, t)` over the mesh = `stencil(t, 0)` turned.
pub fn continuous_with_the_neighbouring_sector(t: &PatchUnderTest) {
    for k in 3..=8u32 {
        let lay = (t.layout)(k);
        let as_map = |w: &[f64], turn: u32| {
            let mut m: BTreeMap<(u32, i64, i64), f64> = BTreeMap::new();
            for (p, x) in lay.iter().zip(w) {
                let (s, a, b) = name_of(*p);
                let key = if (a, b) == (0, 0) {
                    (0, 0, 0)
                } else {
                    ((s + turn) % k, a, b)
                };
                *m.entry(key).or_insert(0.0) += x;
            }
            m
        };
        for n in [3, 5, 6] {
            let s = (t.float)(k, n);
            for u in 0..=i64::from(n) {
                let here = as_map(s.at(0, u).expect("grid"), 0);
                let there = as_map(s.at(u, 0).expect("grid"), 1);
                for key in here.keys().chain(there.keys()) {
                    let (a, b) = (
                        here.get(key).copied().unwrap_or(0.0),
                        there.get(key).copied().unwrap_or(0.0),
                    );
                    assert!(
                        (a - b).abs() < 1e-12,
                        "K = {k}, t = {u}/{n}, {key:?}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
