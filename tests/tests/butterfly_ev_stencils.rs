//! The modified butterfly's patch next to an interior extraordinary vertex of valence 3..=8
//! (Schaefer–Warren sections 5.2–5.3 on the triangular lattice): the grid system against
//! substitution (exactly for K = 3, 4, 6; within 1e-12 in f64 for the irrational K = 5, 7, 8),
//! valence 6 against the regular basis function of the uniform system, interpolation of V, E_0
//! and E_1, partition of unity, the mirror u <-> v, continuity with the neighbouring sector's
//! patch, f64 against exact, and an independent brute-force check: a random net on an explicit
//! K-valent fan mesh subdivided k times with the rules written out here (topological: faces
//! across edges), compared at the dyadic points (i/2^k, j/2^k), which are level-k vertices
//! because the scheme interpolates.

use std::collections::{BTreeMap, HashMap};

use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::butterfly_local::ButterflyLocalMatrices;
use schemes::triangle::apply_map;
use schemes::triangle::lattice_symmetries;
use schemes::triangle_local::TrianglePoint;
use schemes::TriangleScheme;
use stencilgen::butterfly_patch::{
    butterfly_patch_stencils, butterfly_patch_stencils_at, regular_basis, ButterflyPatchStencils,
    ButterflySubstitution,
};
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::triangle_patch::triangle_grid_points;
use stencilgen::triangle_system::triangle_stencils;
use subtess_tests::bspline::q;

fn butterfly() -> TriangleScheme {
    TriangleScheme::by_name("butterfly").expect("catalogued")
}

fn exact(k: u32, n: u32) -> ButterflyPatchStencils<BigRational> {
    butterfly_patch_stencils::<BigRational>(&butterfly(), k, n).expect("solvable")
}

fn float(k: u32, n: u32) -> ButterflyPatchStencils<f64> {
    butterfly_patch_stencils::<f64>(&butterfly(), k, n).expect("solvable")
}

fn layout(k: u32) -> Vec<TrianglePoint> {
    ButterflyLocalMatrices::new(&butterfly(), k)
        .expect("valid")
        .layout
}

#[test]
fn grid_system_equals_substitution_exactly_for_rational_valences() {
    for k in [3, 4, 6] {
        let mut sub = ButterflySubstitution::<BigRational>::new(&butterfly(), k).expect("valid");
        for n in 1..=6 {
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
        let mut sub = ButterflySubstitution::<f64>::new(&butterfly(), k).expect("valid");
        for n in 1..=6 {
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
    for k in [3, 4, 6] {
        for n in [4, 5] {
            let (e, f) = (exact(k, n), float(k, n));
            for (a, b) in e.stencils.iter().flatten().zip(f.stencils.iter().flatten()) {
                assert!((rational_to_f64(a) - b).abs() < 1e-12, "K = {k}, n = {n}");
            }
        }
    }
}

/// The point of the plane where layout point `p` sits at valence 6: `(a, b)` of sector `s` is
/// `R^s (a, b)`, `R` the rotation by 60 degrees.
fn plane_position(p: TrianglePoint) -> (i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0),
        TrianglePoint::Sector { s, a, b } => apply_map(lattice_symmetries()[s as usize], (a, b)),
    }
}

#[test]
fn valence_six_is_the_regular_basis_function() {
    // At valence 6 the patch is a face of the regular lattice: the weight of the control point
    // at p is psi(x - p), psi from the uniform system (triangle_system), which knows nothing of
    // layouts, tiles or A.
    let positions: Vec<(i64, i64)> = layout(6).into_iter().map(plane_position).collect();
    let mask = butterfly().regular_mask();
    for n in 1..=6u32 {
        let psi =
            triangle_stencils::<BigRational>(&mask, n, StencilKind::Position).expect("solvable");
        let s = exact(6, n);
        let ni = i64::from(n);
        for (&(i, j), stencil) in s.points.iter().zip(&s.stencils) {
            let expected: Vec<BigRational> = positions
                .iter()
                .map(|&(a, b)| psi.at(i - ni * a, j - ni * b))
                .collect();
            assert_eq!(stencil, &expected, "({i}/{n}, {j}/{n})");
            // Every lattice point with a nonzero weight there is in the layout.
            for (p, w) in psi.stencil_at((i, j)) {
                assert!(positions.contains(&p), "({i}/{n}, {j}/{n}): {p:?} has {w}");
            }
        }
    }
}

fn unit(size: usize, i: usize) -> Vec<BigRational> {
    let mut e = vec![BigRational::zero(); size];
    e[i] = BigRational::one();
    e
}

#[test]
fn interpolates_v_e0_e1() {
    // The butterfly interpolates: the limit at a vertex is the vertex. V, E_0, E_1 are layout
    // points 0, 1, 2.
    for k in [3, 4, 6] {
        for n in [1, 3, 4] {
            let s = exact(k, n);
            let size = s.stencils[0].len();
            let ni = i64::from(n);
            assert_eq!(
                s.at(0, 0).expect("grid"),
                unit(size, 0).as_slice(),
                "K = {k}"
            );
            assert_eq!(
                s.at(ni, 0).expect("grid"),
                unit(size, 1).as_slice(),
                "K = {k}"
            );
            assert_eq!(
                s.at(0, ni).expect("grid"),
                unit(size, 2).as_slice(),
                "K = {k}"
            );
        }
    }
    for k in 3..=8 {
        let s = float(k, 4);
        for (p, i) in [((0, 0), 0), ((4, 0), 1), ((0, 4), 2)] {
            let w = s.at(p.0, p.1).expect("grid");
            for (c, x) in w.iter().enumerate() {
                let e = if c == i { 1.0 } else { 0.0 };
                assert!((x - e).abs() < 1e-12, "K = {k} at {p:?}: weight {c} = {x}");
            }
        }
    }
}

#[test]
fn partition_of_unity() {
    for k in [3, 4, 6] {
        for n in [2, 5] {
            for w in &exact(k, n).stencils {
                assert!(w.iter().sum::<BigRational>().is_one(), "K = {k}");
            }
        }
    }
    for k in 3..=8 {
        for w in &float(k, 5).stencils {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "K = {k}");
        }
    }
}

/// The test's own naming of fan vertices: `(s, a, b)` with `a, b >= 0` in sector `s`'s chart,
/// normalized to `a >= 1` (the point `(0, b)` of sector `s` is `(b, 0)` of sector `s + 1`), and
/// `V` as `(0, 0, 0)`. The same convention as `TrianglePoint`, written out independently.
fn name(k: u32, s: i64, a: i64, b: i64) -> (u32, i64, i64) {
    assert!(a >= 0 && b >= 0);
    let k = i64::from(k);
    match (a, b) {
        (0, 0) => (0, 0, 0),
        (0, b) => ((s + 1).rem_euclid(k) as u32, b, 0),
        (a, b) => (s.rem_euclid(k) as u32, a, b),
    }
}

fn name_of(p: TrianglePoint) -> (u32, i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0, 0),
        TrianglePoint::Sector { s, a, b } => (s, a, b),
    }
}

#[test]
fn mirror_symmetry_u_v() {
    // Reflecting sector 0 across its bisector, (a, b) -> (b, a), maps sector s to sector -s
    // with its axes swapped; the rules are symmetric, so stencil(i, j) = stencil(j, i) with the
    // layout reflected.
    for k in 3..=8u32 {
        let lay = layout(k);
        let index: HashMap<_, _> = lay
            .iter()
            .enumerate()
            .map(|(i, &p)| (name_of(p), i))
            .collect();
        let mirror: Vec<usize> = lay
            .iter()
            .map(|&p| {
                let (s, a, b) = name_of(p);
                index[&name(k, -i64::from(s), b, a)]
            })
            .collect();
        let check = |a: &[f64], b: &[f64], what: &str| {
            for p in 0..a.len() {
                assert!(
                    (a[p] - b[mirror[p]]).abs() < 1e-12,
                    "K = {k} {what} point {p}"
                );
            }
        };
        let s = float(k, 5);
        for &(i, j) in &s.points {
            check(
                s.at(i, j).expect("grid"),
                s.at(j, i).expect("grid"),
                &format!("({i}, {j})"),
            );
        }
        if matches!(k, 3 | 4) {
            let e = exact(k, 5);
            for &(i, j) in &e.points {
                let (a, b) = (e.at(i, j).expect("grid"), e.at(j, i).expect("grid"));
                for p in 0..a.len() {
                    assert_eq!(a[p], b[mirror[p]], "K = {k} ({i}, {j}) point {p}");
                }
            }
        }
    }
}

#[test]
fn continuous_with_the_neighbouring_sector() {
    // The edge u = 0 (V to E_1) is the edge v = 0 of sector 1's patch, which is this patch
    // turned by one sector: stencil(0, t) over the mesh = stencil(t, 0) turned.
    for k in 3..=8u32 {
        let lay = layout(k);
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
            let s = float(k, n);
            for t in 0..=i64::from(n) {
                let here = as_map(s.at(0, t).expect("grid"), 0);
                let there = as_map(s.at(t, 0).expect("grid"), 1);
                for key in here.keys().chain(there.keys()) {
                    let (a, b) = (
                        here.get(key).copied().unwrap_or(0.0),
                        there.get(key).copied().unwrap_or(0.0),
                    );
                    assert!(
                        (a - b).abs() < 1e-12,
                        "K = {k}, t = {t}/{n}, {key:?}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

/// A face of [`FanMesh`]: corner ids (counter-clockwise), its sector, the corners' chart
/// coordinates in that sector (used only to name the new vertices).
type Face = ([usize; 3], i64, [(i64, i64); 3]);

/// An explicit triangle mesh: the K-valent fan of radius `R` around V, subdivided by the
/// butterfly's rules applied topologically (edge -> its two faces -> opposite and wing
/// vertices), with no lattice charts and no library code.
struct FanMesh {
    valence: u32,
    /// Values of the vertices; `None` where the stencil ran off the finite mesh.
    values: Vec<Option<f64>>,
    /// The vertex of each name.
    by_name: HashMap<(u32, i64, i64), usize>,
    /// Faces: corners (ids, counter-clockwise), the sector and the corners' chart coordinates.
    faces: Vec<Face>,
}

/// The modified butterfly's extraordinary weights (Zorin, Schröder, Sweldens 1996, written
/// from the paper): K = 3: 5/12, -1/12, -1/12; K = 4: 3/8, 0, -1/8, 0; K >= 5:
/// (1/4 + cos(2πj/K) + cos(4πj/K)/2)/K; 3/4 at the vertex.
fn zss_weights(k: u32) -> Vec<f64> {
    match k {
        3 => vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0],
        4 => vec![3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0],
        _ => (0..k)
            .map(|j| {
                let t = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(k);
                (0.25 + t.cos() + 0.5 * (2.0 * t).cos()) / f64::from(k)
            })
            .collect(),
    }
}

impl FanMesh {
    fn new(k: u32, radius: i64, value: &mut dyn FnMut() -> f64) -> Self {
        let mut mesh = FanMesh {
            valence: k,
            values: Vec::new(),
            by_name: HashMap::new(),
            faces: Vec::new(),
        };
        for s in 0..i64::from(k) {
            for b in 0..radius {
                for a in 0..radius - b {
                    let up = [(a, b), (a + 1, b), (a, b + 1)];
                    mesh.add_face(s, up, value);
                    if a + b + 2 <= radius {
                        mesh.add_face(s, [(a + 1, b), (a + 1, b + 1), (a, b + 1)], value);
                    }
                }
            }
        }
        mesh
    }

    fn vertex(&mut self, key: (u32, i64, i64), value: &mut dyn FnMut() -> Option<f64>) -> usize {
        if let Some(&v) = self.by_name.get(&key) {
            return v;
        }
        self.values.push(value());
        self.by_name.insert(key, self.values.len() - 1);
        self.values.len() - 1
    }

    fn add_face(&mut self, s: i64, chart: [(i64, i64); 3], value: &mut dyn FnMut() -> f64) {
        let k = self.valence;
        let ids = chart.map(|(a, b)| self.vertex(name(k, s, a, b), &mut || Some(value())));
        self.faces.push((ids, s, chart));
    }

    /// One step of the modified butterfly.
    fn subdivide(&self) -> FanMesh {
        let k = self.valence;
        // Edge (min, max) -> the third corners of its faces.
        let mut opposite: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (ids, _, _) in &self.faces {
            for e in 0..3 {
                let (p, q, o) = (ids[e], ids[(e + 1) % 3], ids[(e + 2) % 3]);
                opposite.entry((p.min(q), p.max(q))).or_default().push(o);
            }
        }
        let across = |p: usize, q: usize, not: usize| -> Option<usize> {
            opposite
                .get(&(p.min(q), p.max(q)))?
                .iter()
                .copied()
                .find(|&o| o != not)
        };
        let centre = self.by_name[&(0, 0, 0)];
        let weights = zss_weights(k);
        let edge_value = |p: usize, q: usize| -> Option<f64> {
            let val = |v: usize| self.values[v];
            if k != 6 && (p == centre || q == centre) {
                let other = if p == centre { q } else { p };
                let (s, _, _) = *self.by_name.iter().find(|(_, &v)| v == other)?.0;
                let mut sum = 0.75 * val(centre)?;
                for (j, w) in weights.iter().enumerate() {
                    let e = self.by_name[&((s + j as u32) % k, 1, 0)];
                    sum += w * val(e)?;
                }
                return Some(sum);
            }
            let ops = opposite.get(&(p.min(q), p.max(q)))?;
            if ops.len() != 2 {
                return None;
            }
            let mut sum = 0.5 * (val(p)? + val(q)?) + 0.125 * (val(ops[0])? + val(ops[1])?);
            for &o in ops {
                for (x, y) in [(p, o), (q, o)] {
                    let third = if x == p { q } else { p };
                    sum -= val(across(x, y, third)?)? / 16.0;
                }
            }
            Some(sum)
        };
        let mut fine = FanMesh {
            valence: k,
            values: Vec::new(),
            by_name: HashMap::new(),
            faces: Vec::new(),
        };
        for (ids, s, chart) in &self.faces {
            let doubled = chart.map(|(a, b)| (2 * a, 2 * b));
            let corner: Vec<usize> = (0..3)
                .map(|c| {
                    let (a, b) = doubled[c];
                    fine.vertex(name(k, *s, a, b), &mut || self.values[ids[c]])
                })
                .collect();
            let mid: Vec<usize> = (0..3)
                .map(|e| {
                    let (c, d) = (e, (e + 1) % 3);
                    let (a, b) = (chart[c].0 + chart[d].0, chart[c].1 + chart[d].1);
                    fine.vertex(name(k, *s, a, b), &mut || edge_value(ids[c], ids[d]))
                })
                .collect();
            let m = |x: usize| {
                (
                    mid[x],
                    (
                        chart[x].0 + chart[(x + 1) % 3].0,
                        chart[x].1 + chart[(x + 1) % 3].1,
                    ),
                )
            };
            let c = |x: usize| (corner[x], doubled[x]);
            for tri in [
                [c(0), m(0), m(2)],
                [m(0), c(1), m(1)],
                [m(2), m(1), c(2)],
                [m(0), m(1), m(2)],
            ] {
                fine.faces.push((tri.map(|t| t.0), *s, tri.map(|t| t.1)));
            }
        }
        fine
    }
}

#[test]
fn brute_force_subdivision_at_dyadic_points() {
    // A random net on the fan of radius 6 (every vertex random, also those outside the layout:
    // a layout too small would show), subdivided k = 3 and 4 times; the limit at the dyadic
    // point (i/2^k, j/2^k) is the level-k vertex there (the scheme interpolates), and the grid
    // stencil at rate 2^k applied to the layout's values must give it.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 3..=8u32 {
        let mut mesh = FanMesh::new(k, 6, &mut random);
        let lay = layout(k);
        let net: Vec<f64> = lay
            .iter()
            .map(|&p| mesh.values[mesh.by_name[&name_of(p)]].expect("level 0 is complete"))
            .collect();
        for level in 1..=4u32 {
            mesh = mesh.subdivide();
            if level < 3 {
                continue;
            }
            let n = 1u32 << level;
            let s = float(k, n);
            let mut worst = 0f64;
            for (&(i, j), w) in s.points.iter().zip(&s.stencils) {
                let predicted: f64 = w.iter().zip(&net).map(|(a, b)| a * b).sum();
                let id = mesh.by_name[&name(k, 0, i, j)];
                let subdivided = mesh.values[id].expect("inside the valid region");
                worst = worst.max((predicted - subdivided).abs());
            }
            assert!(worst < 1e-12, "K = {k}, level {level}: off by {worst:e}");
        }
    }
}

#[test]
#[ignore = "slow sweep: every rate 7..=24 for K = 3, 5, 8 (minutes: the regular basis at odd rates such as 23 takes 20 s exactly)"]
fn grid_system_equals_substitution_at_every_rate_up_to_24() {
    let b = butterfly();
    let matrices: Vec<ButterflyLocalMatrices> = [3, 5, 8]
        .iter()
        .map(|&k| ButterflyLocalMatrices::new(&b, k).expect("valid"))
        .collect();
    let mut subs: Vec<ButterflySubstitution<f64>> = [3, 5, 8]
        .iter()
        .map(|&k| ButterflySubstitution::new(&b, k).expect("valid"))
        .collect();
    for n in 7..=24u32 {
        // psi does not depend on the valence: one solve per rate for the three grids.
        let psi = regular_basis::<f64>(&b, n).expect("solvable");
        let points = triangle_grid_points(n);
        for (m, sub) in matrices.iter().zip(subs.iter_mut()) {
            let grid = butterfly_patch_stencils_at(m, &psi, &points, n).expect("solvable");
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
