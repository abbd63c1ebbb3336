//! The Loop patch next to an interior extraordinary vertex of valence 3..=8 (issue 6, step 2;
//! Schaefer–Warren sections 5.2–5.3 on the triangular lattice): the grid system against plain
//! substitution (exactly), valence 6 and the edge shared with the regular neighbour against
//! the quartic box spline written from its definition (`subtess_tests::box_spline`), the
//! mirror symmetry `u <-> v`, continuity with the neighbouring EV patch, partition of unity,
//! f64 against exact, and the tangent masks at the vertex.

use std::collections::BTreeMap;

use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::triangle::{apply_map, lattice_symmetries};
use schemes::triangle_local::{
    triangle_layout, TriangleLocalMatrices, TrianglePoint, TRIANGLE_OUTER_POINTS,
};
use stencilgen::regular_patch::StencilKind;
use stencilgen::scalar::rational_to_f64;
use stencilgen::triangle_patch::{
    loop_ev_tangents, triangle_patch_stencils, triangle_patch_stencils_of_kind, triangle_scheme,
    TrianglePatchStencils, TriangleSubstitution,
};
use stencilgen::triangle_system::triangle_stencils;
use subtess_tests::box_spline::{box_spline, loop_basis};
use subtess_tests::bspline::q;

fn exact(v: u32, n: u32) -> TrianglePatchStencils<BigRational> {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    triangle_patch_stencils::<BigRational>(&loop_, v, n).expect("solvable")
}

/// Unfolded sector-0 lattice positions of the layout points that lie next to the patch:
/// `(layout index, position)`. `E_2` and `E_{v-1}` coincide at valence 3 (both are listed).
fn unfolded_positions(v: u32) -> Vec<(usize, (i64, i64))> {
    let v = v as usize;
    let mut out = vec![
        (0, (0, 0)),
        (1, (1, 0)),
        (2, (0, 1)),
        (1 + (v - 1), (1, -1)),
        (1 + 2 % v, (-1, 1)),
    ];
    if v == 6 {
        out.push((1 + 3, (-1, 0)));
        out.push((1 + 4, (0, -1)));
    }
    for (o, &p) in TRIANGLE_OUTER_POINTS.iter().enumerate() {
        out.push((1 + v + o, p));
    }
    out
}

/// The box-spline weights over the layout at `x` (valid where only the listed points matter).
fn box_spline_weights(v: u32, x: &(BigRational, BigRational)) -> Vec<BigRational> {
    let mut w = vec![BigRational::zero(); v as usize + 6];
    for (i, (a, b)) in unfolded_positions(v) {
        w[i] += loop_basis(&(&x.0 - q(a, 1), &x.1 - q(b, 1)));
    }
    w
}

#[test]
fn grid_system_equals_substitution_exactly() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for v in 3..=8 {
        let mut sub = TriangleSubstitution::<BigRational>::new(&loop_, v).expect("valid");
        for n in [1, 2, 3, 4, 5, 7] {
            let grid = exact(v, n);
            assert_eq!(grid.residual, 0.0);
            for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                let by_substitution = sub
                    .stencil(&q(i, i64::from(n)), &q(j, i64::from(n)))
                    .expect("in the patch");
                assert_eq!(stencil, &by_substitution, "v = {v}, ({i}/{n}, {j}/{n})");
                assert_eq!(
                    by_substitution.iter().sum::<BigRational>(),
                    BigRational::one(),
                    "partition of unity, v = {v}, ({i}/{n}, {j}/{n})"
                );
            }
        }
    }
}

#[test]
fn grid_system_equals_substitution_at_every_rate_up_to_24() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for v in [3, 5, 8] {
        let mut sub = TriangleSubstitution::<BigRational>::new(&loop_, v).expect("valid");
        let rates: Vec<u32> = if v == 5 { (1..=24).collect() } else { vec![24] };
        for n in rates {
            let grid = exact(v, n);
            for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                let by_substitution = sub
                    .stencil(&q(i, i64::from(n)), &q(j, i64::from(n)))
                    .expect("in the patch");
                assert_eq!(stencil, &by_substitution, "v = {v}, ({i}/{n}, {j}/{n})");
            }
        }
    }
}

#[test]
fn valence_six_is_the_quartic_box_spline() {
    for n in 1..=6 {
        let s = exact(6, n);
        for (&(i, j), stencil) in s.points.iter().zip(&s.stencils) {
            let x = (q(i, i64::from(n)), q(j, i64::from(n)));
            assert_eq!(stencil, &box_spline_weights(6, &x), "({i}/{n}, {j}/{n})");
        }
    }
}

#[test]
fn edge_shared_with_the_regular_neighbour_is_the_box_spline() {
    // On u + v = 1 the patch meets the regular triangle E_0, E_1, (1,1), a box-spline patch.
    for v in 3..=8 {
        for n in [2, 3, 5, 7] {
            let s = exact(v, n);
            let n = i64::from(n);
            for i in 0..=n {
                let stencil = s.at(i, n - i).expect("grid point");
                let x = (q(i, n), q(n - i, n));
                assert_eq!(
                    stencil,
                    box_spline_weights(v, &x),
                    "v = {v}, ({i}/{n}, 1 - {i}/{n})"
                );
            }
        }
    }
}

/// The layout permutation of the reflection `(a, b) -> (b, a)` of sector 0.
fn mirror(v: usize, p: usize) -> usize {
    match p {
        0 => 0,
        p if p <= v => 1 + (v + 2 - p) % v,
        p => 1 + v + (4 - (p - 1 - v)),
    }
}

#[test]
fn mirror_symmetry_u_v() {
    for v in 3..=8u32 {
        let vu = v as usize;
        for n in [3, 5, 7] {
            let s = exact(v, n);
            for &(i, j) in &s.points {
                let a = s.at(i, j).expect("grid point");
                let b = s.at(j, i).expect("grid point");
                for p in 0..a.len() {
                    assert_eq!(a[p], b[mirror(vu, p)], "v = {v} ({i}, {j}) point {p}");
                }
            }
        }
    }
}

#[test]
fn continuous_with_the_neighbouring_extraordinary_patch() {
    // The edge u = 0 (V to E_1) is the edge v = 0 of the patch of sector 1, which is this
    // patch turned by one sector: stencil(0, t) over the mesh = stencil(t, 0) turned.
    for v in 3..=8u32 {
        let layout = triangle_layout(v);
        let turn = |p: TrianglePoint| match p {
            TrianglePoint::Centre => p,
            TrianglePoint::Sector { s, a, b } => TrianglePoint::Sector {
                s: (s + 1) % v,
                a,
                b,
            },
        };
        let as_map = |w: &[BigRational], f: &dyn Fn(TrianglePoint) -> TrianglePoint| {
            let mut m: BTreeMap<TrianglePoint, BigRational> = BTreeMap::new();
            for (p, x) in layout.iter().zip(w) {
                *m.entry(f(*p)).or_insert_with(BigRational::zero) += x;
            }
            m.retain(|_, x| !x.is_zero());
            m
        };
        for n in [2, 3, 5, 7] {
            let s = exact(v, n);
            for t in 0..=i64::from(n) {
                let here = as_map(s.at(0, t).expect("grid"), &|p| p);
                let there = as_map(s.at(t, 0).expect("grid"), &turn);
                assert_eq!(here, there, "v = {v}, t = {t}/{n}");
            }
        }
    }
}

#[test]
fn f64_matches_exact() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for v in [3, 5, 8] {
        let e = exact(v, 5);
        let f = triangle_patch_stencils::<f64>(&loop_, v, 5).expect("solvable");
        for (a, b) in e.stencils.iter().flatten().zip(f.stencils.iter().flatten()) {
            assert!((rational_to_f64(a) - b).abs() < 1e-12);
        }
    }
}

#[test]
fn limit_mask_is_loops_limit_rule() {
    // Loop's limit position (Hoppe et al. 1994): chi = 1 / (3/(8 beta) + v) at each neighbour,
    // 1 - v chi at the vertex, with Warren's beta.
    for v in 3..=8i64 {
        let s = exact(v as u32, 1);
        let beta = if v == 3 { q(3, 16) } else { q(3, 8 * v) };
        let chi = q(1, 1) / (q(3, 8) / beta + q(v, 1));
        let w = s.at(0, 0).expect("vertex");
        assert_eq!(w[0], q(1, 1) - q(v, 1) * &chi, "v = {v}");
        assert!(w[1..=v as usize].iter().all(|x| *x == chi), "v = {v}");
        assert!(w[1 + v as usize..].iter().all(Zero::is_zero), "v = {v}");
    }
}

#[test]
fn valence_six_tangents_are_the_box_spline_derivatives() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    let m = TriangleLocalMatrices::new(&loop_, 6).expect("valid");
    let t = loop_ev_tangents(&m).expect("tangents");
    let mask = loop_.regular_mask();
    for (kind, got) in [
        (StencilKind::DerivativeU, &t.du),
        (StencilKind::DerivativeV, &t.dv),
    ] {
        let d = triangle_stencils::<BigRational>(&mask, 1, kind).expect("solvable");
        for (i, (a, b)) in unfolded_positions(6).into_iter().take(7) {
            // The weight of the point at j in the derivative at 0 is phi'(0 - j).
            let expected = rational_to_f64(&d.at(-a, -b));
            assert!(
                (got[i] - expected).abs() < 1e-12,
                "{kind:?} point {i}: {} vs {expected}",
                got[i]
            );
        }
    }
    // The rotations carry the masks into each other: the u mask turned by 60 degrees is v's.
    let r = lattice_symmetries()[1];
    assert_eq!(apply_map(r, (1, 0)), (0, 1));
    for k in 0..6 {
        assert!((t.du[1 + k] - t.dv[1 + (k + 1) % 6]).abs() < 1e-12);
    }
}

fn exact_kind(v: u32, n: u32, kind: StencilKind) -> TrianglePatchStencils<BigRational> {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    triangle_patch_stencils_of_kind::<BigRational>(&loop_, v, n, kind).expect("solvable")
}

const DERIVATIVES: [StencilKind; 2] = [StencilKind::DerivativeU, StencilKind::DerivativeV];

#[test]
fn derivative_grid_equals_substitution_and_sums_to_zero() {
    let loop_ = triangle_scheme("loop").expect("catalogued");
    for v in 3..=8 {
        let mut sub = TriangleSubstitution::<BigRational>::new(&loop_, v).expect("valid");
        for kind in DERIVATIVES {
            for n in [1, 2, 3, 5, 7] {
                let grid = exact_kind(v, n, kind);
                assert!(!grid.points.contains(&(0, 0)));
                for (&(i, j), stencil) in grid.points.iter().zip(&grid.stencils) {
                    let by_substitution = sub
                        .stencil_of_kind(&q(i, i64::from(n)), &q(j, i64::from(n)), kind)
                        .expect("in the patch");
                    assert_eq!(
                        stencil, &by_substitution,
                        "{kind:?} v = {v}, ({i}/{n}, {j}/{n})"
                    );
                    assert!(stencil.iter().sum::<BigRational>().is_zero());
                }
            }
        }
        // At the vertex exact mode refuses (irrational in general).
        assert!(sub
            .stencil_of_kind(&q(0, 1), &q(0, 1), StencilKind::DerivativeU)
            .is_err());
    }
}

#[test]
fn valence_six_derivatives_are_the_box_spline_differences() {
    // d/du M_222(z) = M_122(z) - M_122(z - xi_1), d/dv = M_212(z) - M_212(z - xi_2),
    // z = x - p + (2, 0) for the control point at p.
    for n in 1..=4 {
        for kind in DERIVATIVES {
            let s = exact_kind(6, n, kind);
            for (&(i, j), stencil) in s.points.iter().zip(&s.stencils) {
                let mut expected = vec![BigRational::zero(); 12];
                for (k, (a, b)) in unfolded_positions(6) {
                    let z = (
                        q(i, i64::from(n)) - q(a - 2, 1),
                        q(j, i64::from(n)) - q(b, 1),
                    );
                    let (c, d) = match kind {
                        StencilKind::DerivativeU => ([1, 2, 2], (1, 0)),
                        _ => ([2, 1, 2], (0, 1)),
                    };
                    expected[k] +=
                        box_spline(c, &z) - box_spline(c, &(&z.0 - q(d.0, 1), &z.1 - q(d.1, 1)));
                }
                assert_eq!(stencil, &expected, "{kind:?} ({i}/{n}, {j}/{n})");
            }
        }
    }
}

#[test]
fn derivative_mirror_symmetry() {
    for v in [3, 5, 8u32] {
        let du = exact_kind(v, 5, StencilKind::DerivativeU);
        let dv = exact_kind(v, 5, StencilKind::DerivativeV);
        for &(i, j) in &du.points {
            let a = du.at(i, j).expect("grid point");
            let b = dv.at(j, i).expect("grid point");
            for p in 0..a.len() {
                assert_eq!(
                    a[p],
                    b[mirror(v as usize, p)],
                    "v = {v} ({i}, {j}) point {p}"
                );
            }
        }
    }
}

/// The table's contract points for rate `n`: the primal grid and the centroids in zigzag rows,
/// written out from docs/table-format.md.
fn contract_points(n: u32) -> [Vec<(BigRational, BigRational)>; 2] {
    let ni = i64::from(n);
    let mut dual = Vec::new();
    for j in 0..ni {
        for i in 0..ni - j {
            dual.push((q(3 * i + 1, 3 * ni), q(3 * j + 1, 3 * ni)));
            if i + j + 2 <= ni {
                dual.push((q(3 * i + 2, 3 * ni), q(3 * j + 2, 3 * ni)));
            }
        }
    }
    let primal = (0..=ni)
        .flat_map(|j| (0..=ni - j).map(move |i| (q(i, ni), q(j, ni))))
        .collect();
    [primal, dual]
}

#[test]
fn loop_table_sections_are_the_substitution_stencils_at_the_contract_points() {
    // The table's f64 grid system (on 1/3n for the centroids) against exact substitution,
    // point by point in the documented order, interior and boundary patches.
    use stencilgen::triangle_boundary::loop_boundary_tangents;
    use stencilgen::triangle_table::{build_triangle_table, TriangleLayout, TriangleTableSpec};
    use table_format::{AlignedBytes, PointSet, Precision, SectionKey, StencilKind as Kind, Table};
    let loop_ = triangle_scheme("loop").expect("catalogued");
    let rates = [1u32, 2, 5];
    let spec = TriangleTableSpec {
        scheme: loop_.clone(),
        valences: vec![3, 7],
        boundary_faces: vec![2],
        rates: rates.to_vec(),
        precision: Precision::F64,
        layout: TriangleLayout::Grids,
    };
    let bytes = AlignedBytes::from_slice(&build_triangle_table(&spec).expect("builds"));
    let table = Table::parse(bytes.as_bytes()).expect("valid");
    type Evaluator = Box<dyn FnMut(&BigRational, &BigRational, StencilKind) -> Vec<BigRational>>;
    // (boundary, faces, sector), exact substitution, the tangent masks at the vertex.
    type Case = ((bool, u32, u32), Evaluator, (Vec<f64>, Vec<f64>));
    let mut patches: Vec<Case> = Vec::new();
    for v in [3u32, 7] {
        let mut sub = TriangleSubstitution::<BigRational>::new(&loop_, v).expect("valid");
        let t = loop_ev_tangents(&sub.matrices).expect("tangents");
        let eval: Evaluator =
            Box::new(move |x, y, kind| sub.stencil_of_kind(x, y, kind).expect("inside"));
        patches.push(((false, v, 0), eval, (t.du, t.dv)));
    }
    for sector in 0..2 {
        let m = TriangleLocalMatrices::boundary(&loop_, 2, sector).expect("valid");
        let t = loop_boundary_tangents(&m).expect("tangents");
        let mut sub =
            TriangleSubstitution::<BigRational>::boundary(&loop_, 2, sector).expect("valid");
        let eval: Evaluator =
            Box::new(move |x, y, kind| sub.stencil_of_kind(x, y, kind).expect("inside"));
        patches.push(((true, 2, sector), eval, (t.du, t.dv)));
    }
    for ((boundary, faces, sector), mut eval, (du, dv)) in patches {
        for n in rates {
            let [primal, dual] = contract_points(n);
            for (kind, stencil_kind) in [
                (Kind::Position, StencilKind::Position),
                (Kind::DerivativeU, StencilKind::DerivativeU),
                (Kind::DerivativeV, StencilKind::DerivativeV),
            ] {
                for (points, set) in [
                    (&primal, PointSet::TrianglePrimal),
                    (&dual, PointSet::TriangleDual),
                ] {
                    let key = SectionKey {
                        kind,
                        points: set,
                        boundary,
                        feature: table_format::Feature::None,
                        faces,
                        sector,
                        n,
                    };
                    let w = table.weights_f64(&key).expect("present");
                    let k = w.len() / points.len();
                    assert_eq!(w.len(), points.len() * k);
                    for (p, (x, y)) in points.iter().enumerate() {
                        let row = &w[p * k..(p + 1) * k];
                        if x.is_zero() && y.is_zero() && kind != Kind::Position {
                            let t = if kind == Kind::DerivativeU { &du } else { &dv };
                            assert_eq!(row, t.as_slice());
                            continue;
                        }
                        let exact = eval(x, y, stencil_kind);
                        assert_eq!(exact.len(), k);
                        for (a, b) in row.iter().zip(&exact) {
                            assert!((a - rational_to_f64(b)).abs() < 1e-12, "{key} point {p}");
                        }
                    }
                }
            }
        }
    }
}
