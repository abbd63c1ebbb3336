//! Positions and first derivatives of √3 (two steps as one ternary step) on every region of an
//! interior extraordinary vertex ([`schemes::sqrt3_regions`]) at any rational point:
//! Schaefer–Warren eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the
//! corner, section 4's derivative normalization for the regular basis, and Loop's tangent
//! convention at the vertex itself.
//!
//! **Non-corner region** `r` (triangle `c0, c1, c2`, ternary tile level `L`), at barycentric
//! `x = (u, v)`: the chart point `c = c0 + u (c1 - c0) + v (c2 - c0)`, `y = 3^L c` (level-`L`
//! coordinates), `T` the first tile holding `y`, and
//!
//! ```text
//!   phi(x)      = sum_j psi(y - j) R[j]
//!   d/du phi(x) = 3^L sum_j (D_{c1-c0} psi)(y - j) R[j],   D_w psi = w_1 psi_1 + w_2 psi_2
//!   d/dv phi(x) = 3^L sum_j (D_{c2-c0} psi)(y - j) R[j]
//! ```
//!
//! over the tile's control points `j` (`R[j]` their level-0 rows), `psi_1, psi_2` the regular
//! basis's derivatives along the skew axes ([`sqrt3_regular_basis_kind`]).
//!
//! **Corner region** (region 0, the EV patch of [`crate::sqrt3_patch`]): while
//! `u + v <= 1/3`, `phi(x) = phi(3x) A` and `phi'(x) = 3 phi'(3x) A`; in the outer part the tile
//! formula with `c0 = (0,0)`, axes `(1,0), (0,1)`, `L = 2`.
//!
//! **At `x = 0`** the position is the limit mask (`phi(0) = phi(0) A`, `sum = 1`). The
//! derivative does not exist in the patch's parameters unless `K = 6`: the subdominant
//! eigenvalue of the two-step `A` is `lambda = (2 + 2 cos(2π/K))/9` (Kobbelt 2000; `1/9, 2/9,
//! 0.2946, 1/3, 0.3606, 0.3794` for `K = 3..=8`), not `1/3`, so `phi'(3^-k x) = 3^k phi'(x) A^k`
//! grows or shrinks like `(3 lambda)^-k`. The repo's convention for Loop's vertex
//! ([`crate::triangle_patch::loop_ev_tangents`]) is used instead: the left eigenvectors of the
//! 1-ring block of `A` (`V, E_0..E_{K-1}`; the ring reads only the ring) for `lambda` span the
//! tangent masks, normalized on the reference net `V = 0`, `E_i = (cos 2πi/K, sin 2πi/K)` so
//! that the `u` mask maps it to `E_0` and the `v` mask to `E_1`. They give the tangent plane
//! (the limit surface's normal is their cross product), and at `K = 6`, where the net is the
//! lattice, they are the true derivatives (psi's skew-axis derivatives gathered: tested).
//! Mapping the net to `E_0`, `E_1` is the same as mapping its `E_0, E_1` skew coordinates
//! `(sin((1-i)θ), sin(iθ))/sin θ` to `(1,0)`, `(0,1)` (a linear map of the plane applied to
//! net and targets alike); for `K = 3, 4, 6` those are integers and `lambda` is rational, so
//! the exact path computes the masks exactly that way (f64 and exact agree: tested).
//!
//! The partition of unity holds for every row (positions sum to 1, derivatives to 0).

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::Zero;
use schemes::sqrt3_regions::{Sqrt3Region, Sqrt3Regions};
use schemes::TriangleScheme;

use crate::butterfly_regions::null_space;
use crate::exact_solve::limit_mask;
use crate::regular_patch::StencilKind;
use crate::sqrt3_patch::sqrt3_regular_basis_kind;
use crate::triangle_patch::ring_tangents;
use crate::triangle_system::{TriangleStencils, MAX_BASIS_RATE};
use crate::{Scalar, StencilError};

/// √3's regular basis `psi` and (optionally) its skew-axis derivatives on one grid `1/n`.
#[derive(Clone, Debug)]
pub struct Sqrt3Basis<S> {
    /// The grid rate.
    pub n: u32,
    /// `psi`, `psi_1`, `psi_2` ([`StencilKind`] order); `None` where not solved.
    pub kinds: [Option<TriangleStencils<S>>; 3],
}

fn kind_index(kind: StencilKind) -> usize {
    match kind {
        StencilKind::Position => 0,
        StencilKind::DerivativeU => 1,
        StencilKind::DerivativeV => 2,
    }
}

impl<S: Scalar> Sqrt3Basis<S> {
    /// Solve `kinds` of √3's regular basis on the rate-`n` grid
    /// ([`sqrt3_regular_basis_kind`]).
    pub fn new(
        scheme: &TriangleScheme,
        n: u32,
        kinds: &[StencilKind],
    ) -> Result<Self, StencilError> {
        let mut out = Sqrt3Basis {
            n,
            kinds: [None, None, None],
        };
        for &k in kinds {
            out.kinds[kind_index(k)] = Some(sqrt3_regular_basis_kind::<S>(scheme, n, k)?);
        }
        Ok(out)
    }

    fn get(&self, kind: StencilKind) -> Result<&TriangleStencils<S>, StencilError> {
        self.kinds[kind_index(kind)]
            .as_ref()
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!("the regular basis at rate {} lacks {kind:?}", self.n),
            })
    }
}

/// Every region of one valence, its matrices in the field `S`, ready to evaluate.
#[derive(Clone, Debug)]
pub struct Sqrt3RegionStencils<S> {
    /// The regions ([`schemes::sqrt3_regions`]).
    pub regions: Sqrt3Regions,
    /// The corner's `A` in `S`.
    a: Vec<Vec<S>>,
    /// Per region, its tile rows in `S`.
    rows: Vec<Vec<Vec<S>>>,
    /// The limit-position mask at `V` (corner layout).
    pub limit: Vec<S>,
    /// The subdominant eigenvalue of `A` (f64), `(2 + 2 cos(2π/K))/9`.
    pub lambda: f64,
    /// The tangent masks at `V` (corner layout, zero beyond the 1-ring; module docs).
    pub vertex_tangents: [Vec<S>; 2],
}

/// An entry in `S`: the exact rational when there is one, else the f64.
fn entry<S: Scalar>(
    exact: Option<&BigRational>,
    value: f64,
    what: &str,
) -> Result<S, StencilError> {
    match exact {
        Some(r) => Ok(S::from_rational(r)),
        None => S::from_f64(value).ok_or_else(|| StencilError::Irrational {
            what: what.to_owned(),
        }),
    }
}

fn matrix<S: Scalar>(
    exact: Option<&Vec<Vec<BigRational>>>,
    values: &[Vec<f64>],
    what: &str,
) -> Result<Vec<Vec<S>>, StencilError> {
    values
        .iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(|(j, &x)| entry(exact.map(|e| &e[i][j]), x, what))
                .collect()
        })
        .collect()
}

impl<S: Scalar> Sqrt3RegionStencils<S> {
    /// Build the regions of √3 at valence `valence` (an exact field only where `alpha_K` is
    /// rational, `K = 3, 4, 6`).
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        let regions = Sqrt3Regions::new(scheme, valence)?;
        if S::EXACT && !regions.is_rational() {
            return Err(StencilError::Irrational {
                what: format!(
                    "sqrt3 at valence {valence} (its vertex weight alpha = (4 - 2 cos(2 pi/\
                     {valence}))/9 involves cos(2 pi/{valence}))"
                ),
            });
        }
        let m = &regions.corner;
        let what = format!("sqrt3 at valence {valence}");
        let a = matrix::<S>(m.a_exact.as_ref(), &m.a, &what)?;
        let rows = regions
            .regions
            .iter()
            .map(|r| matrix::<S>(r.regular_rows_exact.as_ref(), &r.regular_rows, &what))
            .collect::<Result<Vec<_>, _>>()?;
        let failure = |detail: String| StencilError::Inconsistent {
            scheme: scheme.name.to_owned(),
            n: 1,
            detail: format!("valence {valence}: {detail}"),
        };
        let size = m.size();
        let ring = 1 + valence as usize;
        // The layout starts V, E_0..E_{K-1} (sqrt3_layout): the ring block is A's corner.
        let a1 = DMatrix::from_fn(ring, ring, |i, j| m.a[i][j]);
        let (lambda, [du, dv]) = ring_tangents(&a1, valence as usize).map_err(&failure)?;
        let (limit, vertex_tangents) = match &m.a_exact {
            Some(ax) => {
                let limit = limit_mask(ax).map_err(|e| failure(format!("limit mask: {e:?}")))?;
                let t = ring_tangents_exact(ax, valence).map_err(&failure)?;
                let widen = |v: Vec<BigRational>| -> Vec<S> {
                    let mut out: Vec<S> = v.iter().map(S::from_rational).collect();
                    out.resize(size, S::zero());
                    out
                };
                let [tu, tv] = t;
                (
                    limit.iter().map(S::from_rational).collect(),
                    [widen(tu), widen(tv)],
                )
            }
            None => {
                let limit = limit_f64(&m.a).map_err(&failure)?;
                let conv = |v: Vec<f64>| -> Result<Vec<S>, StencilError> {
                    let mut out = v
                        .into_iter()
                        .map(|x| {
                            S::from_f64(x)
                                .ok_or_else(|| StencilError::Irrational { what: what.clone() })
                        })
                        .collect::<Result<Vec<S>, _>>()?;
                    out.resize(size, S::zero());
                    Ok(out)
                };
                (conv(limit)?, [conv(du)?, conv(dv)?])
            }
        };
        Ok(Sqrt3RegionStencils {
            regions,
            a,
            rows,
            limit,
            lambda,
            vertex_tangents,
        })
    }

    /// The region `r`.
    pub fn region(&self, r: usize) -> Result<&Sqrt3Region, StencilError> {
        self.regions
            .regions
            .get(r)
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!(
                    "region {r} of {} at valence {}",
                    self.regions.regions.len(),
                    self.regions.valence
                ),
            })
    }

    /// The `kind` stencil of region `r` at `(u, v) = (i/n, j/n)`, `n = basis.n`, `i, j >= 0`,
    /// `i + j <= n`, over the region's layout (module docs). `basis` must hold `kind`.
    pub fn stencil(
        &self,
        r: usize,
        basis: &Sqrt3Basis<S>,
        point: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let region = self.region(r)?;
        let d = i64::from(basis.n);
        let (i, j) = point;
        if i < 0 || j < 0 || i + j > d {
            return Err(StencilError::OutOfDomain {
                what: format!("({i}/{d}, {j}/{d}) is outside the region u, v >= 0, u + v <= 1"),
            });
        }
        if !region.is_corner() {
            let y = region.triangle.chart_point(i, j, d);
            return self.tile(r, basis, y, kind);
        }
        if (i, j) == (0, 0) {
            return Ok(match kind {
                StencilKind::Position => self.limit.clone(),
                StencilKind::DerivativeU => self.vertex_tangents[0].clone(),
                StencilKind::DerivativeV => self.vertex_tangents[1].clone(),
            });
        }
        let (mut x, mut k) = ((i, j), 0u32);
        while 3 * (x.0 + x.1) <= d {
            x = (3 * x.0, 3 * x.1);
            k += 1;
        }
        let row = self.tile(r, basis, x, kind)?;
        Ok(self.scale_down(row, k, kind))
    }

    /// `phi(x) = phi(3x) A` applied `k` times to the corner row `row` (at `3^k x`): `row A^k`,
    /// times `3^k` for a derivative.
    fn scale_down(&self, mut row: Vec<S>, k: u32, kind: StencilKind) -> Vec<S> {
        let three = S::from_rational(&BigRational::from_integer(BigInt::from(3)));
        for _ in 0..k {
            row = (0..row.len())
                .map(|c| {
                    let sum = row
                        .iter()
                        .zip(&self.a)
                        .filter(|(w, ai)| !w.is_zero() && !ai[c].is_zero())
                        .fold(S::zero(), |acc, (w, ai)| acc + w.clone() * ai[c].clone());
                    // The derivative of phi(3x) A picks up the factor 3.
                    if kind == StencilKind::Position {
                        sum
                    } else {
                        sum * three.clone()
                    }
                })
                .collect();
        }
        row
    }

    /// The tile formula at the chart point `c / n` of region `r` (module docs).
    fn tile(
        &self,
        r: usize,
        basis: &Sqrt3Basis<S>,
        c: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let region = self.region(r)?;
        let d = i64::from(basis.n);
        let scale = 3i64.pow(region.tile_level);
        let y = (scale * c.0, scale * c.1);
        let tile = region
            .tile_containing(y, d)
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!(
                    "({}/{d}, {}/{d}) (level {}) is in no regular tile of region {r}",
                    y.0, y.1, region.tile_level
                ),
            })?;
        let [e1, e2] = region.triangle.axes();
        let axis = match kind {
            StencilKind::Position => None,
            StencilKind::DerivativeU => Some(e1),
            StencilKind::DerivativeV => Some(e2),
        };
        let int = |x: i64| S::from_rational(&BigRational::from_integer(BigInt::from(x)));
        let mut out = vec![S::zero(); region.size()];
        for &u in &region.tiles[tile].points {
            let (j1, j2) = region.regular_points[u];
            let at = (y.0 - d * j1, y.1 - d * j2);
            let w = match axis {
                None => basis.get(StencilKind::Position)?.at(at.0, at.1),
                // D_w psi = w_1 psi_1 + w_2 psi_2, times 3^L for the level-L coordinates.
                Some((w1, w2)) => {
                    let mut w = S::zero();
                    if w1 != 0 {
                        w = w + int(w1 * scale)
                            * basis.get(StencilKind::DerivativeU)?.at(at.0, at.1);
                    }
                    if w2 != 0 {
                        w = w + int(w2 * scale)
                            * basis.get(StencilKind::DerivativeV)?.at(at.0, at.1);
                    }
                    w
                }
            };
            if w.is_zero() {
                continue;
            }
            for (o, rw) in out.iter_mut().zip(&self.rows[r][u]) {
                if !rw.is_zero() {
                    *o = o.clone() + w.clone() * rw.clone();
                }
            }
        }
        Ok(out)
    }
}

/// Evaluates every region at any rational point, caching the regular basis per rate and kind.
#[derive(Debug)]
pub struct Sqrt3RegionSubstitution<S> {
    scheme: TriangleScheme,
    /// The regions and their matrices.
    pub stencils: Sqrt3RegionStencils<S>,
    bases: HashMap<u32, Sqrt3Basis<S>>,
}

impl<S: Scalar> Sqrt3RegionSubstitution<S> {
    /// Prepare for valence `valence`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(Sqrt3RegionSubstitution {
            scheme: scheme.clone(),
            stencils: Sqrt3RegionStencils::new(scheme, valence)?,
            bases: HashMap::new(),
        })
    }

    /// Hand over a solved basis (it does not depend on the valence), so that several
    /// valences solve it once.
    pub fn share_basis(&mut self, basis: Sqrt3Basis<S>) {
        self.bases.insert(basis.n, basis);
    }

    /// The `kind` stencil of region `r` at `(u, v)`, `u, v >= 0`, `u + v <= 1`. In the corner
    /// the point is first tripled out of `u + v <= 1/3` (`phi(x) = phi(3x) A`); the common
    /// denominator of the point then evaluated must be at most [`MAX_BASIS_RATE`] (the
    /// regular basis is solved on that grid).
    pub fn stencil(
        &mut self,
        r: usize,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let (zero, one) = (
            BigRational::zero(),
            BigRational::from_integer(BigInt::from(1)),
        );
        if *u < zero || *v < zero || u + v > one {
            return Err(StencilError::OutOfDomain {
                what: format!("(u, v) = ({u}, {v}) is outside the region u, v >= 0, u + v <= 1"),
            });
        }
        let corner = self.stencils.region(r)?.is_corner();
        let (mut u, mut v, mut k) = (u.clone(), v.clone(), 0u32);
        if corner && !(u.is_zero() && v.is_zero()) {
            let third = BigRational::new(BigInt::from(1), BigInt::from(3));
            let three = BigRational::from_integer(BigInt::from(3));
            while &u + &v <= third {
                u *= &three;
                v *= &three;
                k += 1;
            }
        }
        let row = self.stencil_on_grid(r, &u, &v, kind)?;
        Ok(self.stencils.scale_down(row, k, kind))
    }

    /// [`Self::stencil`] on the grid of the point's own denominator.
    fn stencil_on_grid(
        &mut self,
        r: usize,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let d = u.denom().lcm(v.denom());
        let rate = u32::try_from(&d)
            .ok()
            .filter(|&x| x <= MAX_BASIS_RATE)
            .ok_or_else(|| StencilError::RateOutOfRange {
                n: u32::try_from(&d).unwrap_or(u32::MAX),
                max: MAX_BASIS_RATE,
            })?;
        let num = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer()).map_err(|_| {
                StencilError::OutOfDomain {
                    what: format!("{t} does not fit the grid"),
                }
            })
        };
        let point = (num(u)?, num(v)?);
        let needs_basis = point != (0, 0) || !self.stencils.region(r)?.is_corner();
        if needs_basis {
            let entry = self.bases.entry(rate).or_insert(Sqrt3Basis {
                n: rate,
                kinds: [None, None, None],
            });
            let slot = &mut entry.kinds[kind_index(kind)];
            if slot.is_none() {
                *slot = Some(sqrt3_regular_basis_kind::<S>(&self.scheme, rate, kind)?);
            }
        }
        let empty = Sqrt3Basis {
            n: rate,
            kinds: [None, None, None],
        };
        let basis = self.bases.get(&rate).unwrap_or(&empty);
        self.stencils.stencil(r, basis, point, kind)
    }
}

/// The f64 limit mask: `(A^T - I) l = 0`, `1^T l = 1` in the least-squares sense (the
/// eigenvalue 1 is simple).
fn limit_f64(a: &[Vec<f64>]) -> Result<Vec<f64>, String> {
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

/// Loop's vertex tangent convention (module docs) exactly, over the 1-ring of the rational
/// `A` (`K = 3, 4, 6`): `lambda = (2 + 2 cos(2π/K))/9` (Kobbelt's double-step eigenvalue; a
/// two-dimensional left eigenspace is required, not assumed), the reference net in `E_0, E_1`
/// skew coordinates (integers there), targets `(1, 0)` and `(0, 1)`.
fn ring_tangents_exact(
    a: &[Vec<BigRational>],
    valence: u32,
) -> Result<[Vec<BigRational>; 2], String> {
    let k = valence as usize;
    let ring = 1 + k;
    let q = |p: i64, r: i64| BigRational::new(BigInt::from(p), BigInt::from(r));
    let cos = match valence {
        3 => q(-1, 2),
        4 => q(0, 1),
        6 => q(1, 2),
        _ => return Err(format!("cos(2 pi/{valence}) is irrational")),
    };
    let lambda = (q(2, 1) + q(2, 1) * cos) / q(9, 1);
    // Left eigenvectors: the right null space of B^T - lambda I.
    let shifted: Vec<Vec<BigRational>> = (0..ring)
        .map(|i| {
            (0..ring)
                .map(|j| {
                    let x = a[j][i].clone();
                    if i == j {
                        x - &lambda
                    } else {
                        x
                    }
                })
                .collect()
        })
        .collect();
    let basis = null_space(shifted, ring);
    if basis.len() != 2 {
        return Err(format!(
            "lambda = {lambda} has {} left eigenvectors on the 1-ring, not 2",
            basis.len()
        ));
    }
    let theta = 2.0 * std::f64::consts::PI / f64::from(valence);
    let net: Vec<(i64, i64)> = (0..k)
        .map(|i| {
            let t = i as f64 * theta;
            let x = (theta - t).sin() / theta.sin();
            let y = t.sin() / theta.sin();
            (x.round() as i64, y.round() as i64)
        })
        .collect();
    let image = |w: &[BigRational]| {
        net.iter()
            .enumerate()
            .fold((q(0, 1), q(0, 1)), |(x, y), (i, &(n1, n2))| {
                (x + &w[1 + i] * q(n1, 1), y + &w[1 + i] * q(n2, 1))
            })
    };
    let (g0, g1) = (image(&basis[0]), image(&basis[1]));
    let det = &g0.0 * &g1.1 - &g0.1 * &g1.0;
    if det.is_zero() {
        return Err("the eigenvectors do not span the reference net's plane".to_owned());
    }
    let mask = |t: (BigRational, BigRational)| -> Vec<BigRational> {
        let c0 = (&t.0 * &g1.1 - &t.1 * &g1.0) / &det;
        let c1 = (&g0.0 * &t.1 - &g0.1 * &t.0) / &det;
        basis[0]
            .iter()
            .zip(&basis[1])
            .map(|(a, b)| &c0 * a + &c1 * b)
            .collect()
    };
    Ok([mask((q(1, 1), q(0, 1))), mask((q(0, 1), q(1, 1)))])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
    }

    #[test]
    fn exact_refuses_irrational_valences() {
        assert!(Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), 5).is_err());
        assert!(Sqrt3RegionStencils::<f64>::new(&sqrt3(), 5).is_ok());
    }

    #[test]
    fn vertex_tangents_exact_equal_f64_and_sum_to_zero() {
        // The exact normalization (skew net) and Loop's (cos/sin net) are the same convention.
        for k in [3u32, 4, 6] {
            let e = Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), k).expect("exact");
            let f = Sqrt3RegionStencils::<f64>::new(&sqrt3(), k).expect("f64");
            for (te, tf) in e.vertex_tangents.iter().zip(&f.vertex_tangents) {
                assert!(te.iter().sum::<BigRational>().is_zero(), "K = {k}");
                for (a, b) in te.iter().zip(tf) {
                    assert!((crate::Scalar::to_f64(a) - b).abs() < 1e-12, "K = {k}");
                }
            }
        }
    }
}
