//! Stencils of √3's patch next to an interior extraordinary vertex, two √3 steps at a time
//! (Schaefer–Warren sections 5.1–5.3: the two-step ternary form aligned with the original
//! lattice), by the grid system and by substitution.
//!
//! Let `phi(x)` be the row of the `N = 3K + 9` basis functions of the layout of
//! [`schemes::sqrt3_local`] at `x = (u, v)` in the patch `u, v >= 0`, `u + v <= 1`. Two √3
//! steps do not change the surface, so
//!
//! * `phi(x) = phi(3x) A` when `3x` is in the patch again (`u + v <= 1/3`);
//! * otherwise `y = 3^L x` (`L = 2`, level-`L` skew coordinates) lies in a regular tile `T` of
//!   the outer part, and `phi(x) = sum_j psi(y - j) R_T[j]` over the tile's control points `j`,
//!   with `psi` the regular two-step basis function from the uniform system of
//!   [`crate::triangle_system`] (non-polynomial: solved on the grid) and `R_T[j]` the level-0
//!   weights of level-`L` point `j`;
//! * the partition of unity `sum_j phi_j(x) = 1`.
//!
//! At the grid points `(i/n, j/n)`, `i + j <= n`, this is a [`ScalingSystem`] whose classes are
//! the grid points (`x -> 3x` maps the grid into itself inside `u + v <= 1/3`): triangular
//! except at `x = 0`, where `phi(0) = phi(0) A`, `sum phi(0) = 1` gives the limit mask at `V`
//! (√3 approximates, so it is not a unit row). `y = 9x` has denominator `n`, so `psi` is
//! needed on the rate-`n` grid only. [`Sqrt3Substitution`] unrolls the same relations at any
//! rational point without forming a system (the independent cross-check).
//!
//! **Irrational weights.** For `K = 5, 7, 8` the vertex weight `alpha_K = (4 - 2 cos(2π/K))/9`
//! is irrational: only the f64 path serves them (the exact path returns
//! [`StencilError::Irrational`]). The f64 path's relation coefficients are the f64 entries of
//! `A`, carried into the system's rational coefficient rows exactly (every f64 is a dyadic
//! rational), so the solver sees precisely the f64 matrix.
//!
//! The helpers that read the matrices (`entry`, `rational_a`, the tile sum, the f64 limit
//! mask) repeat those of [`crate::butterfly_patch`] over √3's matrix type (to be shared once
//! the two local-matrix types are one).

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::sqrt3_local::Sqrt3LocalMatrices;
use schemes::TriangleScheme;

use crate::exact_solve::limit_mask;
use crate::regular_patch::StencilKind;
use crate::scaling_system::{NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::triangle_patch::triangle_grid_points;
use crate::triangle_system::{
    triangle_stencils_up_to, TriangleStencils, MAX_BASIS_RATE, MAX_TRIANGLE_RATE,
};
use crate::{Scalar, StencilError};

/// Position stencils at the grid points of the √3 EV patch.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3PatchStencils<S> {
    /// The scheme's name.
    pub scheme: String,
    /// The valence of the vertex at `(0, 0)`.
    pub valence: u32,
    /// The grid denominator: points are `(i/n, j/n)`.
    pub n: u32,
    /// The grid points `(i, j)` (numerators over `n`), in the order asked for.
    pub points: Vec<(i64, i64)>,
    /// `N` weights per point, in the layout order of [`schemes::sqrt3_local`].
    pub stencils: Vec<Vec<S>>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> Sqrt3PatchStencils<S> {
    /// The stencil at `(i/n, j/n)`, if that point was solved for.
    pub fn at(&self, i: i64, j: i64) -> Option<&[S]> {
        let k = self.points.iter().position(|&p| p == (i, j))?;
        Some(&self.stencils[k])
    }
}

/// √3's local matrices at valence `valence`, refusing an exact field when `alpha_K` is
/// irrational (`K = 5, 7, 8`, ...).
pub fn sqrt3_matrices<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
) -> Result<Sqrt3LocalMatrices, StencilError> {
    let m = Sqrt3LocalMatrices::new(scheme, valence)?;
    require_field::<S>(&m)?;
    Ok(m)
}

fn require_field<S: Scalar>(m: &Sqrt3LocalMatrices) -> Result<(), StencilError> {
    if S::EXACT && !m.is_rational() {
        return Err(StencilError::Irrational {
            what: format!(
                "sqrt3 at valence {k} (its vertex weight alpha = (4 - 2 cos(2 pi/{k}))/9 \
                 involves cos(2 pi/{k}), and so do A and the stencils)",
                k = m.valence
            ),
        });
    }
    Ok(())
}

/// Entry `(exact, value)` of a matrix in the field `S`: the exact rational when there is one,
/// else the f64 (`None` only for an exact field without an exact entry).
fn entry<S: Scalar>(exact: Option<&BigRational>, value: f64) -> Option<S> {
    match exact {
        Some(r) => Some(S::from_rational(r)),
        None => S::from_f64(value),
    }
}

/// `A` with rational entries for the system's coefficient rows: exact, or the f64 entries as
/// the dyadic rationals they are.
fn rational_a(m: &Sqrt3LocalMatrices) -> Result<Vec<Vec<BigRational>>, StencilError> {
    if let Some(a) = &m.a_exact {
        return Ok(a.clone());
    }
    m.a.iter()
        .map(|row| {
            row.iter()
                .map(|&x| {
                    BigRational::from_float(x).ok_or_else(|| StencilError::Inconsistent {
                        scheme: m.scheme.clone(),
                        n: 0,
                        detail: format!("A has a non-finite entry {x} at valence {}", m.valence),
                    })
                })
                .collect()
        })
        .collect()
}

/// `sum_j psi(y - j) R_T[j]` at `y = Y / d` (level-`L` coordinates, in the outer part): the
/// weights of a point of a regular tile, `psi` on the rate-`d` grid.
fn tile_weights<S: Scalar>(
    m: &Sqrt3LocalMatrices,
    psi: &TriangleStencils<S>,
    y: (i64, i64),
    d: i64,
) -> Result<Vec<S>, StencilError> {
    let tile = m
        .tile_containing(y, d)
        .ok_or_else(|| StencilError::OutOfDomain {
            what: format!(
                "({}/{d}, {}/{d}) (level {}) is in no regular tile of the outer part",
                y.0, y.1, m.tile_level
            ),
        })?;
    let mut out = vec![S::zero(); m.size()];
    for &u in &m.tiles[tile].points {
        let (j1, j2) = m.regular_points[u];
        let w = psi.at(y.0 - d * j1, y.1 - d * j2);
        if w.is_zero() {
            continue;
        }
        for (c, o) in out.iter_mut().enumerate() {
            let r = entry::<S>(
                m.regular_rows_exact.as_ref().map(|rows| &rows[u][c]),
                m.regular_rows[u][c],
            )
            .ok_or_else(|| StencilError::Irrational {
                what: format!("a regular row at valence {}", m.valence),
            })?;
            if !r.is_zero() {
                *o = o.clone() + w.clone() * r;
            }
        }
    }
    Ok(out)
}

/// √3's regular (two-step, ternary) basis function on the rate-`d` grid, in the field `S`.
///
/// The regular mask is rational at every valence, so `psi` is solved exactly and then
/// rounded, as for the butterfly: the exact path solves each residue cycle and substitutes
/// along the trees, the f64 path would factor whole orbits densely.
pub fn sqrt3_regular_basis<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
) -> Result<TriangleStencils<S>, StencilError> {
    sqrt3_regular_basis_kind(scheme, d, StencilKind::Position)
}

/// [`sqrt3_regular_basis`] or one of its derivatives along the skew axes (`DerivativeU` is
/// `d psi / d y_1` at fixed `y_2`, Schaefer–Warren section 4's normalization
/// `sum_j (j_1 - y_1) psi_u(y - j) = 1`, `sum_j (j_2 - y_2) psi_u(y - j) = 0`), on the rate-`d`
/// grid, `d <= `[`MAX_BASIS_RATE`] (the tables' dual points need `3n`).
///
/// Always solved exactly and rounded: at the tables' rates `3n` (multiples of 3, so the
/// classes form trees hanging off the cycles) the exact path is the fast one, unlike the
/// butterfly's odd rates. Measured (ignored test
/// `f64_and_exact_regular_bases_agree_at_the_table_rates`, which also checks agreement within
/// 1e-12): rate 9, 0.07 s exact against 8 s in f64; rate 15, 1 s against 3.6 s; rate 18,
/// 0.9 s against 66 s.
pub fn sqrt3_regular_basis_kind<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
    kind: StencilKind,
) -> Result<TriangleStencils<S>, StencilError> {
    let mask = scheme.regular_mask();
    let exact = triangle_stencils_up_to::<BigRational>(&mask, d, kind, MAX_BASIS_RATE)?;
    Ok(TriangleStencils {
        scheme: exact.scheme,
        n: exact.n,
        kind: exact.kind,
        dilation: exact.dilation,
        hull: exact.hull,
        bbox: exact.bbox,
        values: exact.values.iter().map(S::from_rational).collect(),
        residual: exact.residual,
    })
}

/// Solve the grid system of the √3 patch around an interior vertex of valence `valence` at
/// rate `n` (`1..=`[`MAX_TRIANGLE_RATE`]): positions at `(i/n, j/n)`, `i + j <= n`.
pub fn sqrt3_patch_stencils<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    n: u32,
) -> Result<Sqrt3PatchStencils<S>, StencilError> {
    if n == 0 || n > MAX_TRIANGLE_RATE {
        return Err(StencilError::RateOutOfRange {
            n,
            max: MAX_TRIANGLE_RATE,
        });
    }
    let matrices = sqrt3_matrices::<S>(scheme, valence)?;
    let psi = sqrt3_regular_basis::<S>(scheme, n)?;
    sqrt3_patch_stencils_at(&matrices, &psi, &triangle_grid_points(n), n)
}

/// The grid system of the √3 patch at the points `(i/d, j/d)` of `points` (`i, j >= 0`,
/// `i + j <= d`), closed under `x -> 3x` inside `u + v <= 1/3`; `psi` is the regular basis on
/// the rate-`d` grid (`y = 9x` has denominator `d`).
pub fn sqrt3_patch_stencils_at<S: Scalar>(
    matrices: &Sqrt3LocalMatrices,
    psi: &TriangleStencils<S>,
    points: &[(i64, i64)],
    d: u32,
) -> Result<Sqrt3PatchStencils<S>, StencilError> {
    require_field::<S>(matrices)?;
    if psi.n != d || psi.dilation != 3 {
        return Err(StencilError::OutOfDomain {
            what: format!(
                "the regular basis is on the rate-{} grid with dilation {}, the points on 1/{d} \
                 with dilation 3",
                psi.n, psi.dilation
            ),
        });
    }
    let k = matrices.size();
    let di = i64::from(d);
    if let Some(p) = points.iter().find(|&&(i, j)| i < 0 || j < 0 || i + j > di) {
        return Err(StencilError::OutOfDomain {
            what: format!(
                "({}/{d}, {}/{d}) is outside the patch u, v >= 0, u + v <= 1",
                p.0, p.1
            ),
        });
    }
    let a = rational_a(matrices)?;
    // phi_j(x) = sum_i A[i][j] phi_i(3x).
    let columns: Vec<Vec<(usize, BigRational)>> = (0..k)
        .map(|j| {
            (0..k)
                .filter(|&i| !a[i][j].is_zero())
                .map(|i| (i, a[i][j].clone()))
                .collect()
        })
        .collect();
    let mut all: Vec<(i64, i64)> = Vec::with_capacity(points.len());
    let mut class_of: HashMap<(i64, i64), u32> = HashMap::new();
    for &p in points {
        let mut p = p;
        while !class_of.contains_key(&p) {
            class_of.insert(p, all.len() as u32);
            all.push(p);
            if 3 * (p.0 + p.1) > di {
                break;
            }
            p = (3 * p.0, 3 * p.1);
        }
    }
    let next: Vec<Option<u32>> = all
        .iter()
        .map(|&(i, j)| (3 * (i + j) <= di).then(|| class_of[&(3 * i, 3 * j)]))
        .collect();
    let scale = 3i64.pow(matrices.tile_level);
    let mut system = ScalingSystem::<S>::new(next.clone());
    for (c, &(i, j)) in all.iter().enumerate() {
        let constants = match next[c] {
            Some(_) => vec![S::zero(); k],
            None => tile_weights(matrices, psi, (scale * i, scale * j), di)?,
        };
        for (col, constant) in constants.into_iter().enumerate() {
            let terms: SparseRow = match next[c] {
                Some(target) => {
                    let base = target as usize * k;
                    columns[col]
                        .iter()
                        .map(|(r, w)| (base + r, w.clone()))
                        .collect()
                }
                None => Vec::new(),
            };
            system.push_unknown(
                c as u32,
                Relation { terms, constant },
                format!("phi_{col}({i}/{d}, {j}/{d})"),
            );
        }
        system.normalization.push(NormalizationRow {
            class: c as u32,
            terms: (c * k..(c + 1) * k)
                .map(|u| (u, BigRational::one()))
                .collect(),
            rhs: BigRational::one(),
            label: format!("x = ({i}/{d}, {j}/{d})"),
        });
    }
    let Solution { values, residual } = solve_system::<S>(&system, &matrices.scheme, d)?;
    let stencils = points
        .iter()
        .map(|p| {
            let c = class_of[p] as usize;
            values[c * k..(c + 1) * k].to_vec()
        })
        .collect();
    Ok(Sqrt3PatchStencils {
        scheme: matrices.scheme.clone(),
        valence: matrices.valence,
        n: d,
        points: points.to_vec(),
        stencils,
        residual,
    })
}

/// Evaluates √3 EV-patch stencils by substitution at any rational `(u, v)` whose level-`L`
/// point `9 * 3^k x` (after the triplings) has a denominator the regular system can be solved
/// at (`<=` [`MAX_TRIANGLE_RATE`]); caches the regular basis per rate.
#[derive(Debug)]
pub struct Sqrt3Substitution<S> {
    scheme: TriangleScheme,
    /// The local subdivision matrices.
    pub matrices: Sqrt3LocalMatrices,
    bases: HashMap<u32, TriangleStencils<S>>,
}

impl<S: Scalar> Sqrt3Substitution<S> {
    /// Prepare for √3 around an interior vertex of valence `valence` (an exact field only
    /// where `alpha_K` is rational).
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(Sqrt3Substitution {
            scheme: scheme.clone(),
            matrices: sqrt3_matrices::<S>(scheme, valence)?,
            bases: HashMap::new(),
        })
    }

    /// Hand over the regular basis at one rate (it does not depend on the valence), so that
    /// substitutions at several valences, or a grid system and a substitution, solve it once.
    /// `psi` must be √3's ternary basis ([`sqrt3_regular_basis`]); an error otherwise.
    pub fn share_basis(&mut self, psi: TriangleStencils<S>) -> Result<(), StencilError> {
        if psi.dilation != 3 || psi.kind != StencilKind::Position || psi.scheme != self.scheme.name
        {
            return Err(StencilError::UnsupportedScheme {
                scheme: psi.scheme,
                reason: "the basis handed to a sqrt3 substitution must be sqrt3's position basis"
                    .to_owned(),
            });
        }
        self.bases.insert(psi.n, psi);
        Ok(())
    }

    /// The `N` position weights at `(u, v)`, `u, v >= 0`, `u + v <= 1`: triple `x` `k` times
    /// until `u + v > 1/3`, take the regular tile's weights at `9x`, apply `A` `k` times
    /// (`phi(x) = phi(3x) A`). At `(0, 0)`: [`Self::limit_mask`].
    pub fn stencil(&mut self, u: &BigRational, v: &BigRational) -> Result<Vec<S>, StencilError> {
        let (zero, one) = (BigRational::zero(), BigRational::one());
        if *u < zero || *v < zero || u + v > one {
            return Err(StencilError::OutOfDomain {
                what: format!("(u, v) = ({u}, {v}) is outside the patch u, v >= 0, u + v <= 1"),
            });
        }
        if u.is_zero() && v.is_zero() {
            return self.limit_mask();
        }
        let third = BigRational::new(BigInt::from(1), BigInt::from(3));
        let three = BigRational::from_integer(BigInt::from(3));
        let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
        while &x + &y <= third {
            x *= &three;
            y *= &three;
            k += 1;
        }
        let scale = BigRational::from_integer(BigInt::from(3i64.pow(self.matrices.tile_level)));
        let (y1, y2) = (&x * &scale, &y * &scale);
        let d = y1.denom().lcm(y2.denom());
        let too_big = || StencilError::RateOutOfRange {
            n: u32::try_from(&d).unwrap_or(u32::MAX),
            max: MAX_TRIANGLE_RATE,
        };
        let rate = u32::try_from(&d)
            .ok()
            .filter(|&r| r <= MAX_TRIANGLE_RATE)
            .ok_or_else(too_big)?;
        let numerator = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer())
                .map_err(|_| too_big())
        };
        let point = (numerator(&y1)?, numerator(&y2)?);
        if !self.bases.contains_key(&rate) {
            let basis = sqrt3_regular_basis::<S>(&self.scheme, rate)?;
            self.bases.insert(rate, basis);
        }
        let mut row = tile_weights(&self.matrices, &self.bases[&rate], point, i64::from(rate))?;
        let a = self.a()?;
        for _ in 0..k {
            row = (0..row.len())
                .map(|j| {
                    row.iter()
                        .zip(&a)
                        .filter(|(w, ai)| !w.is_zero() && !ai[j].is_zero())
                        .fold(S::zero(), |acc, (w, ai)| acc + w.clone() * ai[j].clone())
                })
                .collect();
        }
        Ok(row)
    }

    /// `A` in the field `S`.
    fn a(&self) -> Result<Vec<Vec<S>>, StencilError> {
        let m = &self.matrices;
        (0..m.size())
            .map(|i| {
                (0..m.size())
                    .map(|j| {
                        entry::<S>(m.a_exact.as_ref().map(|a| &a[i][j]), m.a[i][j]).ok_or_else(
                            || StencilError::Irrational {
                                what: format!("A at valence {}", m.valence),
                            },
                        )
                    })
                    .collect()
            })
            .collect()
    }

    /// The limit-position mask at the vertex: the left fixed vector `phi(0) = phi(0) A` with
    /// `sum phi(0) = 1`, exactly when `A` is rational, else by an f64 least-squares solve
    /// (the eigenvalue 1 of `A` is simple for a convergent scheme).
    pub fn limit_mask(&self) -> Result<Vec<S>, StencilError> {
        let m = &self.matrices;
        let size = m.size();
        let failure = |detail: String| StencilError::Inconsistent {
            scheme: self.scheme.name.to_owned(),
            n: 1,
            detail: format!("limit mask at valence {}: {detail}", m.valence),
        };
        if let Some(a) = &m.a_exact {
            let mask = limit_mask(a).map_err(|e| failure(format!("{e:?}")))?;
            return Ok(mask.iter().map(S::from_rational).collect());
        }
        // (A^T - I) w = 0 and 1^T w = 1, in the least-squares sense.
        let mut lhs = DMatrix::<f64>::zeros(size + 1, size);
        let mut rhs = nalgebra::DVector::<f64>::zeros(size + 1);
        for j in 0..size {
            for i in 0..size {
                lhs[(j, i)] = m.a[i][j] - if i == j { 1.0 } else { 0.0 };
            }
            lhs[(size, j)] = 1.0;
        }
        rhs[size] = 1.0;
        let w = lhs
            .svd(true, true)
            .solve(&rhs, 1e-12)
            .map_err(|e| failure(e.to_owned()))?;
        w.iter()
            .map(|&x| S::from_f64(x))
            .collect::<Option<Vec<S>>>()
            .ok_or_else(|| StencilError::Irrational {
                what: format!("the limit mask at valence {}", m.valence),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle_system::triangle_stencils;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
    }

    #[test]
    fn exact_mode_refuses_irrational_valences_and_names_the_cosine() {
        for k in [5, 7, 8] {
            let e = sqrt3_patch_stencils::<BigRational>(&sqrt3(), k, 2).expect_err("irrational");
            assert!(matches!(e, StencilError::Irrational { .. }));
            assert!(e.to_string().contains(&format!("cos(2 pi/{k})")), "{e}");
            assert!(Sqrt3Substitution::<BigRational>::new(&sqrt3(), k).is_err());
        }
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 2).is_ok());
    }

    #[test]
    fn points_outside_the_patch_and_bad_rates_are_errors() {
        let mut s = Sqrt3Substitution::<BigRational>::new(&sqrt3(), 4).expect("valid");
        let q = |p: i64, r: i64| BigRational::new(p.into(), r.into());
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        // 9 * 20/53 has denominator 53 > 24: the regular system is not solved there.
        assert!(matches!(
            s.stencil(&q(20, 53), &q(0, 1)),
            Err(StencilError::RateOutOfRange { n: 53, .. })
        ));
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 0).is_err());
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 25).is_err());
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        let loop_basis =
            triangle_stencils::<BigRational>(&loop_.regular_mask(), 2, StencilKind::Position)
                .expect("solvable");
        assert!(s.share_basis(loop_basis).is_err());
        assert!(matches!(
            sqrt3_patch_stencils::<f64>(&loop_, 5, 2),
            Err(StencilError::UnsupportedScheme { .. })
        ));
    }

    #[test]
    #[ignore = "timing sweep (a few minutes): exact against f64 solves of psi and its derivatives at rates 3..=15"]
    fn f64_and_exact_regular_bases_agree_at_the_table_rates() {
        let scheme = sqrt3();
        let mask = scheme.regular_mask();
        for d in (3..=15).step_by(3) {
            for kind in StencilKind::ALL {
                let t0 = std::time::Instant::now();
                let e = triangle_stencils_up_to::<BigRational>(&mask, d, kind, MAX_BASIS_RATE)
                    .expect("exact");
                let te = t0.elapsed().as_secs_f64();
                let t1 = std::time::Instant::now();
                let f =
                    triangle_stencils_up_to::<f64>(&mask, d, kind, MAX_BASIS_RATE).expect("f64");
                let tf = t1.elapsed().as_secs_f64();
                let worst = e
                    .values
                    .iter()
                    .zip(&f.values)
                    .map(|(a, b)| (crate::Scalar::to_f64(a) - b).abs())
                    .fold(0.0, f64::max);
                eprintln!("rate {d} {kind:?}: exact {te:.2} s, f64 {tf:.2} s, |diff| {worst:e}");
                assert!(worst < 1e-12, "rate {d} {kind:?}: {worst}");
            }
        }
    }
}
