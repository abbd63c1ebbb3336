//! The EV-patch stencils that the modified butterfly ([`crate::butterfly_patch`]) and √3
//! ([`crate::sqrt3_patch`]) share, by the grid system and by substitution, over the local
//! matrices of [`schemes::cone_local`] (Schaefer–Warren sections 5.1–5.3).
//!
//! Let `phi(x)` be the row of the `N = 3K + 9` basis functions of the layout at `x = (u, v)` in
//! the patch `u, v >= 0`, `u + v <= 1`, and `λ` the dilation of one step (2 for the butterfly,
//! 3 for two √3 steps). One step of subdivision does not change the surface, so
//!
//! * `phi(x) = phi(λx) A` when `λx` is in the patch again (`u + v <= 1/λ`; Schaefer–Warren
//!   eq. (3));
//! * otherwise `y = λ^L x` (level-`L` skew coordinates) lies in a regular tile `T` of the outer
//!   part, and `phi(x) = sum_j psi(y - j) R_T[j]` over the tile's control points `j`
//!   (eq. (2)), with `psi` the scheme's regular basis function from the uniform system of
//!   [`crate::triangle_system`] (non-polynomial: solved on the grid) and `R_T[j]` the level-0
//!   weights of level-`L` point `j`;
//! * the partition of unity `sum_j phi_j(x) = 1`.
//!
//! At the grid points `(i/n, j/n)`, `i + j <= n`, this is a [`ScalingSystem`] whose classes are
//! the grid points (`x -> λx` maps the grid into itself inside `u + v <= 1/λ`): triangular
//! except at `x = 0`, where `phi(0) = phi(0) A`, `sum phi(0) = 1` gives the limit mask at `V`.
//! `y = λ^L x` has denominator `n`, so `psi` is needed on the rate-`n` grid only.
//! [`ConeSubstitution`] unrolls the same relations at any rational point without forming a
//! system (the independent cross-check).
//!
//! **Irrational weights.** For `K = 5, 7, 8` both schemes' extraordinary weights involve
//! `cos(2π/K)`: only the f64 path serves them (the exact path returns
//! [`StencilError::Irrational`]). The f64 path's relation coefficients are the f64 entries of
//! `A`, carried into the system's rational coefficient rows exactly (every f64 is a dyadic
//! rational), so the solver sees precisely the f64 matrix.

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::cone_local::{ConeFamily, ConeLocalMatrices};
use schemes::TriangleScheme;

use crate::exact_solve::limit_mask;
use crate::regular_patch::StencilKind;
use crate::scaling_system::{NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::triangle_system::{
    triangle_stencils_up_to, TriangleStencils, MAX_BASIS_RATE, MAX_TRIANGLE_RATE,
};
use crate::{Scalar, StencilError};

/// Position stencils at the grid points of the butterfly's or √3's EV patch.
#[derive(Clone, Debug, PartialEq)]
pub struct ConePatchStencils<S> {
    /// The scheme's name.
    pub scheme: String,
    /// The valence of the vertex at `(0, 0)`.
    pub valence: u32,
    /// The grid denominator: points are `(i/n, j/n)`.
    pub n: u32,
    /// The grid points `(i, j)` (numerators over `n`), in the order asked for.
    pub points: Vec<(i64, i64)>,
    /// `N` weights per point, in the layout order of the local matrices.
    pub stencils: Vec<Vec<S>>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> ConePatchStencils<S> {
    /// The stencil at `(i/n, j/n)`, if that point was solved for.
    pub fn at(&self, i: i64, j: i64) -> Option<&[S]> {
        let k = self.points.iter().position(|&p| p == (i, j))?;
        Some(&self.stencils[k])
    }
}

/// The scheme's local matrices at valence `valence`, refusing an exact field when the weights
/// are irrational (`K = 5, 7, 8`, ...).
pub fn cone_matrices<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
) -> Result<ConeLocalMatrices, StencilError> {
    let m = ConeLocalMatrices::new(scheme, valence)?;
    require_field::<S>(&m)?;
    Ok(m)
}

/// Which weights of `family` at valence `k` are irrational, and why (for error messages).
pub(crate) fn irrational_weights(family: ConeFamily, k: u32) -> String {
    match family {
        ConeFamily::Butterfly => format!(
            "the modified butterfly at valence {k} (its extraordinary edge weights \
             s_j = (1/4 + cos(2 pi j/{k}) + cos(4 pi j/{k})/2)/{k} involve cos(2 pi/{k}), \
             and so do A and the stencils)"
        ),
        ConeFamily::Sqrt3 => format!(
            "sqrt3 at valence {k} (its vertex weight alpha = (4 - 2 cos(2 pi/{k}))/9 \
             involves cos(2 pi/{k}), and so do A and the stencils)"
        ),
    }
}

/// An error unless the field `S` holds the matrices' weights.
pub(crate) fn require_field<S: Scalar>(m: &ConeLocalMatrices) -> Result<(), StencilError> {
    if S::EXACT && !m.is_rational() {
        return Err(StencilError::Irrational {
            what: irrational_weights(m.family, m.valence),
        });
    }
    Ok(())
}

/// Entry `(exact, value)` of a matrix in the field `S`: the exact rational when there is one,
/// else the f64 (`None` only for an exact field without an exact entry).
pub(crate) fn entry<S: Scalar>(exact: Option<&BigRational>, value: f64) -> Option<S> {
    match exact {
        Some(r) => Some(S::from_rational(r)),
        None => S::from_f64(value),
    }
}

/// `A` with rational entries for the system's coefficient rows: exact, or the f64 entries as
/// the dyadic rationals they are.
fn rational_a(m: &ConeLocalMatrices) -> Result<Vec<Vec<BigRational>>, StencilError> {
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

/// `A` in the field `S`.
pub(crate) fn a_in<S: Scalar>(m: &ConeLocalMatrices) -> Result<Vec<Vec<S>>, StencilError> {
    (0..m.size())
        .map(|i| {
            (0..m.size())
                .map(|j| {
                    entry::<S>(m.a_exact.as_ref().map(|a| &a[i][j]), m.a[i][j]).ok_or_else(|| {
                        StencilError::Irrational {
                            what: format!("A at valence {}", m.valence),
                        }
                    })
                })
                .collect()
        })
        .collect()
}

/// `sum_j psi(y - j) R_T[j]` at `y = Y / d` (level-`L` coordinates, in the outer part): the
/// weights of a point of a regular tile, `psi` on the rate-`d` grid (Schaefer–Warren eq. (2)).
fn tile_weights<S: Scalar>(
    m: &ConeLocalMatrices,
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

/// The exactly solved regular basis `exact` rounded into the field `S`.
pub(crate) fn rounded_basis<S: Scalar>(
    exact: TriangleStencils<BigRational>,
) -> TriangleStencils<S> {
    TriangleStencils {
        scheme: exact.scheme,
        n: exact.n,
        kind: exact.kind,
        dilation: exact.dilation,
        hull: exact.hull,
        bbox: exact.bbox,
        values: exact.values.iter().map(S::from_rational).collect(),
        residual: exact.residual,
    }
}

/// The regular (position) basis `psi` of `family`'s scheme on the rate-`d` grid.
pub fn family_regular_basis<S: Scalar>(
    family: ConeFamily,
    scheme: &TriangleScheme,
    d: u32,
) -> Result<TriangleStencils<S>, StencilError> {
    family_regular_basis_kind(family, scheme, d, StencilKind::Position)
}

/// The regular basis `psi` of `family`'s scheme, or one of its skew-axis derivatives
/// (`DerivativeU` is `d psi / d y_1` at fixed `y_2`, normalized by Schaefer–Warren section 4's
/// `sum_j (j_1 - y_1) psi_u(y - j) = 1`, `sum_j (j_2 - y_2) psi_u(y - j) = 0`), on the rate-`d`
/// grid, `d <= `[`MAX_BASIS_RATE`] (the tables' dual points need `3n`).
///
/// Both regular masks are rational at every valence, so `psi` is solved exactly and rounded
/// into `S`, except where [`solves_basis_in_field`] says the field's own solve is faster. The
/// policy is the family's, kept here (not in the scheme modules) because the shared patch and
/// region code needs it and the scheme modules are built on that code.
pub fn family_regular_basis_kind<S: Scalar>(
    family: ConeFamily,
    scheme: &TriangleScheme,
    d: u32,
    kind: StencilKind,
) -> Result<TriangleStencils<S>, StencilError> {
    let mask = scheme.regular_mask();
    if solves_basis_in_field::<S>(family, d) {
        return triangle_stencils_up_to::<S>(&mask, d, kind, MAX_BASIS_RATE);
    }
    let exact = triangle_stencils_up_to::<BigRational>(&mask, d, kind, MAX_BASIS_RATE)?;
    Ok(rounded_basis(exact))
}

/// Whether `family`'s regular basis at rate `d` is solved in the inexact field `S` itself
/// rather than exactly and rounded (an exact field always solves exactly).
///
/// The exact path solves each residue cycle on one support width and substitutes along the
/// trees, while the f64 path factors whole orbits densely. With trees that makes f64 far
/// slower, so the exact path is the default. The butterfly's odd rates are the exception: there
/// every class lies on a cycle, the orbits are the cycles, and the exact arithmetic is what
/// costs (rate 21: 12 s exact against 0.5 s in f64, which agrees within 1e-12; at even rates
/// rate 8 takes 17 s in f64 against 0.04 s exact, rate 24 1.1 s exact; see
/// docs/algorithms/butterfly.md). √3's tables use the rates `3n` (multiples of 3, so the
/// classes form trees hanging off the cycles), where the exact path is the fast one. Measured
/// (ignored test `f64_and_exact_regular_bases_agree_at_the_table_rates` in
/// [`crate::sqrt3_patch`], which also checks agreement within 1e-12): rate 9, 0.07 s exact
/// against 8 s in f64; rate 15, 1 s against 3.6 s; rate 18, 0.9 s against 66 s.
pub fn solves_basis_in_field<S: Scalar>(family: ConeFamily, d: u32) -> bool {
    match family {
        ConeFamily::Butterfly => !S::EXACT && d % 2 == 1,
        ConeFamily::Sqrt3 => false,
    }
}

/// Solve the grid system of the EV patch around an interior vertex of valence `valence` at
/// rate `n` (`1..=`[`MAX_TRIANGLE_RATE`]): positions at `(i/n, j/n)`, `i + j <= n`.
pub fn cone_patch_stencils<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    n: u32,
) -> Result<ConePatchStencils<S>, StencilError> {
    if n == 0 || n > MAX_TRIANGLE_RATE {
        return Err(StencilError::RateOutOfRange {
            n,
            max: MAX_TRIANGLE_RATE,
        });
    }
    let matrices = cone_matrices::<S>(scheme, valence)?;
    let psi = family_regular_basis::<S>(matrices.family, scheme, n)?;
    cone_patch_stencils_at(
        &matrices,
        &psi,
        &crate::triangle_patch::triangle_grid_points(n),
        n,
    )
}

/// The grid system of the EV patch at the points `(i/d, j/d)` of `points` (`i, j >= 0`,
/// `i + j <= d`), closed under `x -> λx` inside `u + v <= 1/λ` (as
/// [`crate::triangle_patch::patch_stencils_at`]); `psi` is the regular basis on the rate-`d`
/// grid with the matrices' dilation (`y = λ^L x` has denominator `d`).
pub fn cone_patch_stencils_at<S: Scalar>(
    matrices: &ConeLocalMatrices,
    psi: &TriangleStencils<S>,
    points: &[(i64, i64)],
    d: u32,
) -> Result<ConePatchStencils<S>, StencilError> {
    require_field::<S>(matrices)?;
    let lambda = matrices.dilation();
    if psi.n != d || psi.dilation != lambda {
        return Err(StencilError::OutOfDomain {
            what: format!(
                "the regular basis is on the rate-{} grid with dilation {}, the points on 1/{d} \
                 with dilation {lambda}",
                psi.n, psi.dilation
            ),
        });
    }
    let l = i64::from(lambda);
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
    // phi_j(x) = sum_i A[i][j] phi_i(λx).
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
            if l * (p.0 + p.1) > di {
                break;
            }
            p = (l * p.0, l * p.1);
        }
    }
    let next: Vec<Option<u32>> = all
        .iter()
        .map(|&(i, j)| (l * (i + j) <= di).then(|| class_of[&(l * i, l * j)]))
        .collect();
    let scale = matrices.family.scale(matrices.tile_level);
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
    Ok(ConePatchStencils {
        scheme: matrices.scheme.clone(),
        valence: matrices.valence,
        n: d,
        points: points.to_vec(),
        stencils,
        residual,
    })
}

/// The f64 limit mask of `A`: `(A^T - I) l = 0`, `1^T l = 1` in the least-squares sense (the
/// eigenvalue 1 of `A` is simple for a convergent scheme).
pub(crate) fn limit_mask_f64(a: &[Vec<f64>]) -> Result<Vec<f64>, String> {
    let n = a.len();
    let mut lhs = DMatrix::<f64>::zeros(n + 1, n);
    let mut rhs = nalgebra::DVector::<f64>::zeros(n + 1);
    for j in 0..n {
        for i in 0..n {
            lhs[(j, i)] = a[i][j] - if i == j { 1.0 } else { 0.0 };
        }
        lhs[(n, j)] = 1.0;
    }
    rhs[n] = 1.0;
    Ok(lhs
        .svd(true, true)
        .solve(&rhs, 1e-12)
        .map_err(|e| e.to_owned())?
        .iter()
        .copied()
        .collect())
}

/// Evaluates EV-patch stencils by substitution at any rational `(u, v)` whose level-`L` point
/// `λ^L λ^k x` (after the `k` dilations) has a denominator the regular system can be solved at
/// (`<=` [`MAX_TRIANGLE_RATE`]); caches the regular basis per rate.
#[derive(Debug)]
pub struct ConeSubstitution<S> {
    scheme: TriangleScheme,
    /// The local subdivision matrices.
    pub matrices: ConeLocalMatrices,
    bases: HashMap<u32, TriangleStencils<S>>,
}

impl<S: Scalar> ConeSubstitution<S> {
    /// Prepare for the scheme around an interior vertex of valence `valence` (an exact field
    /// only where the weights are rational).
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(ConeSubstitution {
            scheme: scheme.clone(),
            matrices: cone_matrices::<S>(scheme, valence)?,
            bases: HashMap::new(),
        })
    }

    /// Hand over the regular basis at one rate (it does not depend on the valence), so that
    /// substitutions at several valences, or a grid system and a substitution, solve it once.
    /// `psi` must be the scheme's position basis, with the matrices' dilation; an error
    /// otherwise.
    pub fn share_basis(&mut self, psi: TriangleStencils<S>) -> Result<(), StencilError> {
        if psi.dilation != self.matrices.dilation()
            || psi.kind != StencilKind::Position
            || psi.scheme != self.scheme.name
        {
            return Err(StencilError::UnsupportedScheme {
                scheme: psi.scheme,
                reason: format!(
                    "the basis handed to a {} substitution must be its position basis",
                    self.scheme.name
                ),
            });
        }
        self.bases.insert(psi.n, psi);
        Ok(())
    }

    /// The `N` position weights at `(u, v)`, `u, v >= 0`, `u + v <= 1`: dilate `x` `k` times
    /// until `u + v > 1/λ`, take the regular tile's weights at `λ^L x`, apply `A` `k` times
    /// (`phi(x) = phi(λx) A`). At `(0, 0)`: [`Self::limit_mask`].
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
        let lambda = BigRational::from_integer(BigInt::from(self.matrices.dilation()));
        let inner = lambda.recip();
        let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
        while &x + &y <= inner {
            x *= &lambda;
            y *= &lambda;
            k += 1;
        }
        let scale = BigRational::from_integer(BigInt::from(
            self.matrices.family.scale(self.matrices.tile_level),
        ));
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
            let basis = family_regular_basis::<S>(self.matrices.family, &self.scheme, rate)?;
            self.bases.insert(rate, basis);
        }
        let mut row = tile_weights(&self.matrices, &self.bases[&rate], point, i64::from(rate))?;
        let a = a_in::<S>(&self.matrices)?;
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

    /// The limit-position mask at the vertex: the left fixed vector `phi(0) = phi(0) A` with
    /// `sum phi(0) = 1`, exactly when `A` is rational, else by an f64 least-squares solve
    /// (`limit_mask_f64`).
    pub fn limit_mask(&self) -> Result<Vec<S>, StencilError> {
        let m = &self.matrices;
        let failure = |detail: String| StencilError::Inconsistent {
            scheme: self.scheme.name.to_owned(),
            n: 1,
            detail: format!("limit mask at valence {}: {detail}", m.valence),
        };
        if let Some(a) = &m.a_exact {
            let mask = limit_mask(a).map_err(|e| failure(format!("{e:?}")))?;
            return Ok(mask.iter().map(S::from_rational).collect());
        }
        let w = limit_mask_f64(&m.a).map_err(failure)?;
        w.iter()
            .map(|&x| S::from_f64(x))
            .collect::<Option<Vec<S>>>()
            .ok_or_else(|| StencilError::Irrational {
                what: format!("the limit mask at valence {}", m.valence),
            })
    }
}
