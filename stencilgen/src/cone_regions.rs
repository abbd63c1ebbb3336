//! Positions and first derivatives of the modified butterfly or √3 on every region of an
//! interior extraordinary vertex ([`schemes::cone_regions`]) at any rational point:
//! Schaefer–Warren eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the
//! corner, and section 4's derivative normalization for the regular basis. The two schemes
//! differ only in the dilation `λ` (2, 3) and in their masks at `V` itself
//! ([`crate::butterfly_regions`], [`crate::sqrt3_regions`]).
//!
//! **Non-corner region** `r` (triangle `c0, c1, c2`, tile level `L`), at barycentric
//! `x = (u, v)`: the chart point `c = c0 + u (c1 - c0) + v (c2 - c0)`, `y = λ^L c` (level-`L`
//! coordinates), `T` the first tile holding `y`, and
//!
//! ```text
//!   phi(x)      = sum_j psi(y - j) R[j]
//!   d/du phi(x) = λ^L sum_j (D_{c1-c0} psi)(y - j) R[j],   D_w psi = w_1 psi_1 + w_2 psi_2
//!   d/dv phi(x) = λ^L sum_j (D_{c2-c0} psi)(y - j) R[j]
//! ```
//!
//! over the tile's control points `j` (`R[j]` their level-0 rows), `psi_1, psi_2` the regular
//! basis's derivatives along the skew axes ([`family_regular_basis_kind`]).
//!
//! **Corner region** (region 0, the EV patch): while `u + v <= 1/λ`, `phi(x) = phi(λx) A` and
//! `phi'(x) = λ phi'(λx) A`; in the outer part the tile formula above with `c0 = (0,0)`, axes
//! `(1,0), (0,1)`. At `x = 0` itself the position is the limit mask and the derivatives are
//! the scheme's [`VertexMasks`].
//!
//! The partition of unity holds for every row (positions sum to 1, derivatives to 0).

use std::collections::HashMap;

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::Zero;
use schemes::cone_local::ConeFamily;
use schemes::cone_regions::{ConeRegion, ConeRegions};
use schemes::TriangleScheme;

use crate::cone_patch::{entry, family_regular_basis_kind, irrational_weights};
// The masks at V are built with the rest of the regions; `VertexMasks` keeps its path here.
use crate::cone_vertex::vertex_masks;
pub use crate::cone_vertex::VertexMasks;
use crate::region_table::RegionStencilSet;
use crate::regular_patch::StencilKind;
use crate::triangle_system::{TriangleStencils, MAX_BASIS_RATE};
use crate::{Scalar, StencilError};

/// The family of `scheme`'s rules, or [`StencilError::UnsupportedScheme`].
fn family_of(scheme: &TriangleScheme) -> Result<ConeFamily, StencilError> {
    ConeFamily::of(scheme).map_err(|reason| StencilError::UnsupportedScheme {
        scheme: scheme.name.to_owned(),
        reason,
    })
}

/// The regular basis `psi` and (optionally) its skew-axis derivatives on one grid `1/n`.
#[derive(Clone, Debug)]
pub struct RegionBasis<S> {
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

impl<S: Scalar> RegionBasis<S> {
    /// Solve `kinds` of the scheme's regular basis on the rate-`n` grid
    /// ([`family_regular_basis_kind`]).
    pub fn new(
        scheme: &TriangleScheme,
        n: u32,
        kinds: &[StencilKind],
    ) -> Result<Self, StencilError> {
        let family = family_of(scheme)?;
        let mut out = RegionBasis {
            n,
            kinds: [None, None, None],
        };
        for &k in kinds {
            out.kinds[kind_index(k)] = Some(family_regular_basis_kind::<S>(family, scheme, n, k)?);
        }
        Ok(out)
    }

    pub(crate) fn get(&self, kind: StencilKind) -> Result<&TriangleStencils<S>, StencilError> {
        self.kinds[kind_index(kind)]
            .as_ref()
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!("the regular basis at rate {} lacks {kind:?}", self.n),
            })
    }
}

/// Every region of one valence, its matrices in the field `S`, ready to evaluate.
#[derive(Clone, Debug)]
pub struct ConeRegionStencils<S> {
    /// The regions ([`schemes::cone_regions`]).
    pub regions: ConeRegions,
    /// The corner's `A` in `S`.
    a: Vec<Vec<S>>,
    /// Per region, its tile rows in `S`.
    rows: Vec<Vec<Vec<S>>>,
    /// The limit-position mask at `V` (corner layout).
    pub limit: Vec<S>,
    /// The subdominant eigenvalue of `A` (f64, [`VertexMasks::lambda`]).
    pub lambda: f64,
    /// The tangent masks at `V` (corner layout; [`crate::butterfly_regions`],
    /// [`crate::sqrt3_regions`]).
    pub vertex_tangents: [Vec<S>; 2],
}

/// A matrix in `S`, entry by entry ([`entry`]): exact where `exact` is given, else the f64
/// `values`; `what` names it in the error of an exact field without exact entries.
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
                .map(|(j, &x)| {
                    entry(exact.map(|e| &e[i][j]), x).ok_or_else(|| StencilError::Irrational {
                        what: what.to_owned(),
                    })
                })
                .collect()
        })
        .collect()
}

impl<S: Scalar> ConeRegionStencils<S> {
    /// Build the regions of the modified butterfly or √3 at valence `valence` (an exact field
    /// only where the weights are rational, `K = 3, 4, 6`).
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        let regions = ConeRegions::new(scheme, valence)?;
        let family = regions.corner.family;
        if S::EXACT && !regions.is_rational() {
            return Err(StencilError::Irrational {
                what: irrational_weights(family, valence),
            });
        }
        let m = &regions.corner;
        let what = format!("{} at valence {valence}", scheme.name);
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
        let VertexMasks {
            limit,
            lambda,
            tangents,
        } = vertex_masks::<S>(family, m, &failure, &what)?;
        Ok(ConeRegionStencils {
            regions,
            a,
            rows,
            limit,
            lambda,
            vertex_tangents: tangents,
        })
    }

    /// The region `r`.
    pub fn region(&self, r: usize) -> Result<&ConeRegion, StencilError> {
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
        basis: &RegionBasis<S>,
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
        let l = i64::from(self.regions.corner.dilation());
        let (mut x, mut k) = ((i, j), 0u32);
        while l * (x.0 + x.1) <= d {
            x = (l * x.0, l * x.1);
            k += 1;
        }
        let row = self.tile(r, basis, x, kind)?;
        Ok(self.scale_down(row, k, kind))
    }

    /// `phi(x) = phi(λx) A` applied `k` times to the corner row `row` (at `λ^k x`): `row A^k`,
    /// times `λ^k` for a derivative.
    fn scale_down(&self, mut row: Vec<S>, k: u32, kind: StencilKind) -> Vec<S> {
        let lambda = S::from_rational(&BigRational::from_integer(BigInt::from(
            self.regions.corner.dilation(),
        )));
        for _ in 0..k {
            row = (0..row.len())
                .map(|c| {
                    let sum = row
                        .iter()
                        .zip(&self.a)
                        .filter(|(w, ai)| !w.is_zero() && !ai[c].is_zero())
                        .fold(S::zero(), |acc, (w, ai)| acc + w.clone() * ai[c].clone());
                    // The derivative of phi(λx) A picks up the factor λ.
                    if kind == StencilKind::Position {
                        sum
                    } else {
                        sum * lambda.clone()
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
        basis: &RegionBasis<S>,
        c: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let region = self.region(r)?;
        let d = i64::from(basis.n);
        let scale = self.regions.corner.family.scale(region.tile_level);
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
                // D_w psi = w_1 psi_1 + w_2 psi_2, times λ^L for the level-L coordinates.
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

impl ConeRegionStencils<f64> {
    /// What a compact region table stores of this valence
    /// ([`crate::region_table::build_compact_region_table`]): the corner's width, every
    /// region's width, and `A`, the masks at `V` (limit, d/du, d/dv) and every region's tile
    /// rows (one per regular point, in [`ConeRegion::regular_points`] order), row-major, as
    /// [`Self::stencil`] uses them.
    pub fn compact_pieces(&self) -> (usize, Vec<usize>, crate::region_table::ValencePieces) {
        let flat = |m: &Vec<Vec<f64>>| m.iter().flatten().copied().collect::<Vec<f64>>();
        (
            self.a.len(),
            self.regions.regions.iter().map(ConeRegion::size).collect(),
            (
                flat(&self.a),
                [
                    self.limit.clone(),
                    self.vertex_tangents[0].clone(),
                    self.vertex_tangents[1].clone(),
                ],
                self.rows.iter().map(flat).collect(),
            ),
        )
    }
}

impl RegionStencilSet for ConeRegionStencils<f64> {
    type Basis = RegionBasis<f64>;

    fn valence(&self) -> u32 {
        self.regions.valence
    }

    fn region_count(&self) -> usize {
        self.regions.regions.len()
    }

    fn width(&self, r: usize) -> Result<usize, StencilError> {
        Ok(self.region(r)?.size())
    }

    fn stencil(
        &self,
        r: usize,
        basis: &Self::Basis,
        point: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<f64>, StencilError> {
        ConeRegionStencils::stencil(self, r, basis, point, kind)
    }
}

/// Evaluates every region at any rational point, caching the regular basis per rate and kind.
#[derive(Debug)]
pub struct ConeRegionSubstitution<S> {
    scheme: TriangleScheme,
    /// The regions and their matrices.
    pub stencils: ConeRegionStencils<S>,
    bases: HashMap<u32, RegionBasis<S>>,
}

impl<S: Scalar> ConeRegionSubstitution<S> {
    /// Prepare for valence `valence`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(ConeRegionSubstitution {
            scheme: scheme.clone(),
            stencils: ConeRegionStencils::new(scheme, valence)?,
            bases: HashMap::new(),
        })
    }

    /// Hand over a solved basis (it does not depend on the valence), so that several
    /// valences solve it once.
    pub fn share_basis(&mut self, basis: RegionBasis<S>) {
        self.bases.insert(basis.n, basis);
    }

    /// The `kind` stencil of region `r` at `(u, v)`, `u, v >= 0`, `u + v <= 1`. In √3's corner
    /// the point is first tripled out of `u + v <= 1/3` (`phi(x) = phi(3x) A`); the common
    /// denominator of the point then evaluated must be at most [`MAX_BASIS_RATE`] (the
    /// regular basis is solved on that grid: for the butterfly, rates with large odd parts
    /// take minutes).
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
        let family = self.stencils.regions.corner.family;
        let (mut u, mut v, mut k) = (u.clone(), v.clone(), 0u32);
        // √3's corner points gain a factor 3 in the denominator per level, so they are tripled
        // out first; the butterfly's are evaluated on their own grid, whose bases at odd rates
        // are solved in f64 directly (so its f64 stencils keep those bases' last bits).
        if family == ConeFamily::Sqrt3 && corner && !(u.is_zero() && v.is_zero()) {
            let lambda = BigRational::from_integer(BigInt::from(family.dilation()));
            let inner = lambda.recip();
            while &u + &v <= inner {
                u *= &lambda;
                v *= &lambda;
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
            let entry = self.bases.entry(rate).or_insert(RegionBasis {
                n: rate,
                kinds: [None, None, None],
            });
            let slot = &mut entry.kinds[kind_index(kind)];
            if slot.is_none() {
                *slot = Some(family_regular_basis_kind::<S>(
                    self.stencils.regions.corner.family,
                    &self.scheme,
                    rate,
                    kind,
                )?);
            }
        }
        let empty = RegionBasis {
            n: rate,
            kinds: [None, None, None],
        };
        let basis = self.bases.get(&rate).unwrap_or(&empty);
        self.stencils.stencil(r, basis, point, kind)
    }
}
