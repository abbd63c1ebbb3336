//! Catmull–Clark stencils next to boundary vertices ("edge only" and "edge and corner"):
//! the boundary curve is the cubic B-spline of the boundary polygon, regular boundary and
//! corner patches are bicubic with phantom points, and the grid solve equals substitution.

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::{BoundaryMode, QuadScheme};
use stencilgen::ev_tangents::ev_tangents;
use stencilgen::extraordinary_patch::{canonical, GridPoint, LocalMatrices, Neighbourhood};
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

/// Every boundary neighbourhood the tables cover: 1..=6 faces, both modes where they differ.
fn neighbourhoods() -> Vec<Neighbourhood> {
    let mut all = vec![Neighbourhood::boundary(1, BoundaryMode::EdgeAndCorner)];
    all.extend((1..=6).map(|f| Neighbourhood::boundary(f, BoundaryMode::EdgeOnly)));
    all
}

/// Position `(a, b)` of sector `s` as existing points, extrapolating linearly across the
/// boundary (the phantom-point construction of regular boundary and corner patches).
fn with_phantom(nb: Neighbourhood, s: i64, a: i64, b: i64) -> Vec<(GridPoint, BigRational)> {
    if let Some(p) = canonical(nb, s, a, b) {
        return vec![(p, BigRational::one())];
    }
    // Sector 0's boundary is its line b = 0; the last sector's is its line a = 0.
    let (near, far) = if s == 0 && b < 0 {
        ((a, b + 1), (a, b + 2))
    } else {
        ((a + 1, b), (a + 2, b))
    };
    let mut out: Vec<(GridPoint, BigRational)> = with_phantom(nb, s, near.0, near.1)
        .into_iter()
        .map(|(p, w)| (p, w * q(2, 1)))
        .collect();
    out.extend(
        with_phantom(nb, s, far.0, far.1)
            .into_iter()
            .map(|(p, w)| (p, -w)),
    );
    out
}

/// The bicubic B-spline patch on the 4x4 net around the cell [0,1]^2 of `sector`, with phantom
/// points beyond the boundary, at (u, v): weights on named points.
fn bicubic(
    nb: Neighbourhood,
    sector: u32,
    u: &BigRational,
    v: &BigRational,
    kind: StencilKind,
) -> HashMap<GridPoint, BigRational> {
    let mut out = HashMap::new();
    for qq in -1..=2i64 {
        for p in -1..=2i64 {
            let (x, y) = (u - q(p, 1) + q(2, 1), v - q(qq, 1) + q(2, 1));
            let w = match kind {
                StencilKind::Position => uniform_bspline(3, &x) * uniform_bspline(3, &y),
                StencilKind::DerivativeU => {
                    uniform_bspline_derivative(3, &x) * uniform_bspline(3, &y)
                }
                StencilKind::DerivativeV => {
                    uniform_bspline(3, &x) * uniform_bspline_derivative(3, &y)
                }
            };
            if w.is_zero() {
                continue;
            }
            for (point, c) in with_phantom(nb, i64::from(sector), p, qq) {
                add(&mut out, point, &w * c);
            }
        }
    }
    out
}

/// A regular boundary vertex (two faces) and a pinned corner (one face, "edge and corner"):
/// every patch is the bicubic B-spline with phantom points, everywhere (closed form).
#[test]
fn regular_boundary_and_corner_patches_are_bicubic_with_phantoms() {
    let cases = [
        (Neighbourhood::boundary(2, BoundaryMode::EdgeOnly), 0),
        (Neighbourhood::boundary(2, BoundaryMode::EdgeOnly), 1),
        (Neighbourhood::boundary(1, BoundaryMode::EdgeAndCorner), 0),
    ];
    for (nb, sector) in cases {
        for n in [1u32, 2, 3, 4, 6] {
            for kind in StencilKind::ALL {
                let grid = exact(nb, sector, n, kind);
                for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
                    let Some(stencil) = stencil else { continue };
                    let (u, v) = (q(a, 2 * i64::from(n)), q(b, 2 * i64::from(n)));
                    assert_eq!(
                        named(nb, sector, stencil),
                        bicubic(nb, sector, &u, &v, kind),
                        "{nb:?} sector {sector} n = {n} {kind:?} at ({u}, {v})"
                    );
                }
            }
        }
    }
}

/// Along sector 0's boundary edge v = 0 every boundary vertex gives the cubic B-spline of the
/// boundary polygon E_{f+1}, V, E_1, (2, 0) (with V doubled as 2V - E_1 beyond a pinned corner).
#[test]
fn the_boundary_is_the_cubic_bspline_of_the_boundary_polygon() {
    for nb in neighbourhoods() {
        let before = if nb.is_corner() {
            with_phantom(nb, 0, -1, 0)
        } else {
            vec![(
                GridPoint::Sector {
                    s: nb.faces,
                    a: 1,
                    b: 0,
                },
                BigRational::one(),
            )]
        };
        let one = |p: GridPoint| vec![(p, BigRational::one())];
        let polygon = [
            before,
            one(GridPoint::Centre),
            one(GridPoint::Sector { s: 0, a: 1, b: 0 }),
            one(GridPoint::Sector { s: 0, a: 2, b: 0 }),
        ];
        let n = 6u32;
        for kind in [StencilKind::Position, StencilKind::DerivativeU] {
            let grid = exact(nb, 0, n, kind);
            for a in 0..=2 * i64::from(n) {
                let Some(stencil) = grid.at(a, 0) else {
                    continue;
                };
                let t = q(a, 2 * i64::from(n));
                let mut expected = HashMap::new();
                for (k, points) in (-1i64..=2).zip(&polygon) {
                    let x = &t - q(k, 1) + q(2, 1);
                    let w = match kind {
                        StencilKind::Position => uniform_bspline(3, &x),
                        _ => uniform_bspline_derivative(3, &x),
                    };
                    for (p, c) in points {
                        add(&mut expected, *p, &w * c);
                    }
                }
                assert_eq!(
                    named(nb, 0, stencil),
                    expected,
                    "{nb:?} {kind:?} at u = {t}"
                );
            }
        }
    }
}

/// The grid solve equals plain substitution at every grid point, every boundary
/// neighbourhood, every sector.
#[test]
fn boundary_grid_solve_equals_substitution() {
    for nb in neighbourhoods() {
        for sector in 0..nb.faces {
            let mut substitution =
                Substitution::<BigRational>::new(&cc(), nb, sector).expect("substitution");
            for n in [1u32, 2, 3, 5, 12] {
                for kind in StencilKind::ALL {
                    let grid = exact(nb, sector, n, kind);
                    for (&(a, b), stencil) in grid.points.iter().zip(&grid.stencils) {
                        let Some(stencil) = stencil else { continue };
                        let d = 2 * i64::from(n);
                        let expected = substitution
                            .stencil(&q(a, d), &q(b, d), kind)
                            .expect("stencil");
                        assert_eq!(
                            stencil, &expected,
                            "{nb:?} sector {sector} n = {n} {kind:?} ({a}, {b})/{d}"
                        );
                        let sum: BigRational = stencil.iter().sum();
                        let unit = if kind == StencilKind::Position {
                            BigRational::one()
                        } else {
                            BigRational::zero()
                        };
                        assert_eq!(sum, unit);
                    }
                }
            }
        }
    }
}

/// Patches of neighbouring sectors agree on their shared edge V-E_{s+2}.
#[test]
fn neighbouring_boundary_patches_agree() {
    for nb in neighbourhoods().into_iter().filter(|nb| nb.faces >= 2) {
        let n = 4u32;
        let d = 2 * i64::from(n);
        for s in 0..nb.faces - 1 {
            let here = exact(nb, s, n, StencilKind::Position);
            let there = exact(nb, s + 1, n, StencilKind::Position);
            let here_dv = exact(nb, s, n, StencilKind::DerivativeV);
            let there_du = exact(nb, s + 1, n, StencilKind::DerivativeU);
            for t in (0..=d).step_by(2) {
                let (a, b) = (here.at(0, t).expect("grid"), there.at(t, 0).expect("grid"));
                assert_eq!(
                    named(nb, s, a),
                    named(nb, s + 1, b),
                    "{nb:?} sectors {s}/{} at {t}/{d}",
                    s + 1
                );
                if t > 0 {
                    let (a, b) = (
                        here_dv.at(0, t).expect("grid"),
                        there_du.at(t, 0).expect("grid"),
                    );
                    assert_eq!(
                        named(nb, s, a),
                        named(nb, s + 1, b),
                        "{nb:?} tangents {s}/{} at {t}/{d}",
                        s + 1
                    );
                }
            }
        }
    }
}

/// At a regular boundary vertex the tangent masks are the bicubic ones with phantoms:
/// d/du = (E_1 - E_3)/2 along the boundary and d/dv = (F_2 - E_3)/6 + 2(E_2 - V)/3 + (F_1 - E_1)/6.
#[test]
fn regular_boundary_vertex_tangents() {
    let m = LocalMatrices::new(&cc(), Neighbourhood::boundary(2, BoundaryMode::EdgeOnly), 0)
        .expect("valid");
    let t = ev_tangents(&m).expect("tangents");
    // Layout: V, E1, E2, E3, F1, F2, then outer points.
    let du = [0.0, 0.5, 0.0, -0.5, 0.0, 0.0];
    let dv = [
        -2.0 / 3.0,
        -1.0 / 6.0,
        2.0 / 3.0,
        -1.0 / 6.0,
        1.0 / 6.0,
        1.0 / 6.0,
    ];
    for i in 0..6 {
        assert!((t.du[i] - du[i]).abs() < 1e-12, "du[{i}] = {}", t.du[i]);
        assert!((t.dv[i] - dv[i]).abs() < 1e-12, "dv[{i}] = {}", t.dv[i]);
    }
}
