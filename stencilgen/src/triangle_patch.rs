//! Stencils of the Loop patch next to an interior extraordinary vertex (Schaefer–Warren
//! sections 5.2–5.3 on the triangular lattice of section 5.1), by the grid system and by
//! substitution, and the limit tangents at the vertex.
//!
//! Let `phi(x)` be the row of the `K = v + 6` basis functions of the layout of
//! [`schemes::triangle_local`] at `x = (u, v)` in the patch `u, v >= 0`, `u + v <= 1`. One step
//! of subdivision does not change the surface, so
//!
//! * `phi(x) = phi(2x) A` when `2x` is in the patch again (`u + v <= 1/2`);
//! * otherwise `y = 2x` (level-1 skew coordinates) lies in a regular sub-triangle `b`, and
//!   `phi(x) = sum_j psi(y - j) R_b[j]` over its twelve level-1 points `j`, with `psi` the
//!   regular (box-spline) basis function of [`crate::triangle_system`];
//! * the partition of unity `sum_j phi_j(x) = 1`.
//!
//! At the grid points `(i/n, j/n)`, `i + j <= n`, this is a [`ScalingSystem`] whose classes are
//! the grid points (`x -> 2x` maps the grid into itself): triangular except at `x = 0`, where
//! `phi(0) = phi(0) A`, `sum phi(0) = 1` is the limit-position mask. [`TriangleSubstitution`]
//! unrolls the same relations at any rational point without forming a system (the independent
//! cross-check). [`loop_ev_tangents`] gives the tangent masks at the vertex from the
//! subdominant left eigenvectors of `A` (f64: they are irrational for most valences).

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::tangent_frame::frame_masks;
use schemes::triangle_local::{TriangleLocalMatrices, TriangleNeighbourhood};
use schemes::TriangleScheme;

use crate::ev_tangents::{left_null_space, subdominant_eigenvalues};
use crate::exact_solve::limit_mask;
use crate::loop_basis::LoopRegularBasis;
use crate::regular_patch::StencilKind;
use crate::scalar::rational_to_f64;
use crate::scaling_system::{NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::triangle_boundary::loop_boundary_tangents;
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::{Scalar, StencilError};

/// A triangle scheme from the catalogue, or an error listing the catalogue.
pub fn triangle_scheme(name: &str) -> Result<TriangleScheme, StencilError> {
    TriangleScheme::by_name(name).ok_or_else(|| StencilError::UnknownScheme {
        name: name.to_owned(),
        known: schemes::triangle::TRIANGLE_SCHEME_NAMES.join(", "),
    })
}

/// Stencils of one kind at the grid points `(i/n, j/n)`, `i + j <= n`, of the Loop EV patch
/// (derivatives: every point but the vertex itself, see [`loop_ev_tangents`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrianglePatchStencils<S> {
    /// The scheme's name.
    pub scheme: String,
    /// The valence of the vertex at `(0, 0)`.
    pub valence: u32,
    /// Grid rate.
    pub n: u32,
    /// Positions, or derivatives along the skew axes `u` (towards `E_0`) and `v` (towards
    /// `E_1`).
    pub kind: StencilKind,
    /// The grid points `(i, j)` (numerators over `n`), `j` outer; without `(0, 0)` for
    /// derivatives.
    pub points: Vec<(i64, i64)>,
    /// `K` weights per point, in the layout order.
    pub stencils: Vec<Vec<S>>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> TrianglePatchStencils<S> {
    /// The stencil at `(i/n, j/n)`, if that is a grid point of the patch.
    pub fn at(&self, i: i64, j: i64) -> Option<&[S]> {
        let k = self.points.iter().position(|&p| p == (i, j))?;
        Some(&self.stencils[k])
    }
}

/// The grid points `(i, j)`, `i + j <= n`, `j` outer.
pub fn triangle_grid_points(n: u32) -> Vec<(i64, i64)> {
    let n = i64::from(n);
    (0..=n)
        .flat_map(|j| (0..=n - j).map(move |i| (i, j)))
        .collect()
}

/// The regular sub-triangle holding `y = (y_1/n, y_2/n)` (level-1 coordinates,
/// `y_1 + y_2 >= n`, inside the level-0 patch): the index into `SUB_TRIANGLES`.
pub fn sub_triangle_of(y: (i64, i64), n: i64) -> usize {
    if y.0 >= n {
        0
    } else if y.1 >= n {
        2
    } else {
        1
    }
}

/// `sum_j psi(y - j) R_b[j]` with `y = Y / d` (level-1 coordinates): the weights of a point of
/// a regular sub-triangle, with `psi` from the exact quartic pieces of [`LoopRegularBasis`].
fn regular_weights<S: Scalar>(
    matrices: &TriangleLocalMatrices,
    basis: &LoopRegularBasis,
    y: (i64, i64),
    d: i64,
) -> Vec<S> {
    let sub = &matrices.sub_triangles[sub_triangle_of(y, d)];
    let mut out = vec![S::zero(); matrices.size()];
    for (&(j1, j2), row) in sub.points.iter().zip(&sub.rows) {
        let psi: S = basis.at(y.0 - d * j1, y.1 - d * j2, d);
        if psi.is_negligible() && S::EXACT {
            continue;
        }
        for (o, r) in out.iter_mut().zip(row) {
            if !r.is_zero() {
                *o = o.clone() + psi.clone() * S::from_rational(r);
            }
        }
    }
    out
}

/// Solve the grid system of the Loop patch around an interior vertex of valence `valence` at
/// rate `n` (`1..=`[`MAX_TRIANGLE_RATE`]), positions.
pub fn triangle_patch_stencils<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    n: u32,
) -> Result<TrianglePatchStencils<S>, StencilError> {
    triangle_patch_stencils_of_kind(scheme, valence, n, StencilKind::Position)
}

/// [`triangle_patch_stencils`] for positions or derivatives. A derivative picks up a factor 2
/// per halving (`d/du phi(x) = 2 (d/du phi)(2x) A`, section 4), sums to 0 over the stencil, and
/// is not a grid unknown at the vertex itself (the characteristic map scales by the
/// subdominant eigenvalue there, not 1/2; [`loop_ev_tangents`] gives the tangent directions).
pub fn triangle_patch_stencils_of_kind<S: Scalar>(
    scheme: &TriangleScheme,
    valence: u32,
    n: u32,
    kind: StencilKind,
) -> Result<TrianglePatchStencils<S>, StencilError> {
    if n == 0 || n > MAX_TRIANGLE_RATE {
        return Err(StencilError::RateOutOfRange {
            n,
            max: MAX_TRIANGLE_RATE,
        });
    }
    let matrices = TriangleLocalMatrices::new(scheme, valence)?;
    let basis = LoopRegularBasis::new(scheme, kind)?;
    patch_stencils_at(&matrices, &basis, &triangle_grid_points(n), n)
}

/// The grid system of a Loop patch (any [`TriangleLocalMatrices`]: interior or boundary) at
/// the points `(i/d, j/d)` of `points` (`i, j >= 0`, `i + j <= d`), closed under `x -> 2x`
/// inside the patch, so that every relation `phi(x) = phi(2x) A` has its right-hand side among
/// the unknowns. The primal grid of rate `n` is `d = n`; the dual points (triangle centroids)
/// of rate `n` live on `d = 3n`. Derivatives leave out `(0, 0)` (see
/// [`triangle_patch_stencils_of_kind`]).
pub fn patch_stencils_at<S: Scalar>(
    matrices: &TriangleLocalMatrices,
    basis: &LoopRegularBasis,
    points: &[(i64, i64)],
    d: u32,
) -> Result<TrianglePatchStencils<S>, StencilError> {
    let kind = basis.kind;
    let k = matrices.size();
    let factor = BigRational::from_integer(BigInt::from(kind.doubling_factor()));
    let di = i64::from(d);
    if let Some(p) = points.iter().find(|&&(i, j)| i < 0 || j < 0 || i + j > di) {
        return Err(StencilError::OutOfDomain {
            what: format!(
                "({}/{d}, {}/{d}) is outside the patch u, v >= 0, u + v <= 1",
                p.0, p.1
            ),
        });
    }
    // phi_j(x) = sum_i A[i][j] phi_i(2x).
    let columns: Vec<Vec<(usize, BigRational)>> = (0..k)
        .map(|j| {
            (0..k)
                .filter(|&i| !matrices.a[i][j].is_zero())
                .map(|i| (i, &factor * &matrices.a[i][j]))
                .collect()
        })
        .collect();
    let mut all: Vec<(i64, i64)> = Vec::with_capacity(points.len());
    let mut class_of: HashMap<(i64, i64), u32> = HashMap::new();
    for &p in points {
        let mut p = p;
        loop {
            if p == (0, 0) && kind != StencilKind::Position {
                break;
            }
            if class_of.contains_key(&p) {
                break;
            }
            class_of.insert(p, all.len() as u32);
            all.push(p);
            if 2 * (p.0 + p.1) > di {
                break;
            }
            p = (2 * p.0, 2 * p.1);
        }
    }
    let next: Vec<Option<u32>> = all
        .iter()
        .map(|&(i, j)| (2 * (i + j) <= di).then(|| class_of[&(2 * i, 2 * j)]))
        .collect();
    let mut system = ScalingSystem::<S>::new(next.clone());
    for (c, &(i, j)) in all.iter().enumerate() {
        let constants = match next[c] {
            Some(_) => vec![S::zero(); k],
            None => regular_weights(matrices, basis, (2 * i, 2 * j), di)
                .into_iter()
                .map(|w: S| w * S::from_rational(&factor))
                .collect(),
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
            rhs: if kind == StencilKind::Position {
                BigRational::one()
            } else {
                BigRational::zero()
            },
            label: format!("x = ({i}/{d}, {j}/{d})"),
        });
    }
    let Solution { values, residual } = solve_system::<S>(&system, &matrices.scheme, d)?;
    let wanted: Vec<(i64, i64)> = points
        .iter()
        .copied()
        .filter(|&p| p != (0, 0) || kind == StencilKind::Position)
        .collect();
    let stencils = wanted
        .iter()
        .map(|p| {
            let c = class_of[p] as usize;
            values[c * k..(c + 1) * k].to_vec()
        })
        .collect();
    Ok(TrianglePatchStencils {
        scheme: matrices.scheme.clone(),
        valence: matrices.valence,
        n: d,
        kind,
        points: wanted,
        stencils,
        residual,
    })
}

/// Evaluates Loop patch stencils (next to an interior vertex, or a boundary vertex with
/// [`TriangleSubstitution::boundary`]) by substitution at any rational `(u, v)`; caches the
/// regular basis per kind.
#[derive(Debug)]
pub struct TriangleSubstitution<S> {
    scheme: TriangleScheme,
    /// The local subdivision matrices.
    pub matrices: TriangleLocalMatrices,
    bases: HashMap<StencilKind, LoopRegularBasis>,
    field: std::marker::PhantomData<S>,
}

impl<S: Scalar> TriangleSubstitution<S> {
    /// Prepare for a Loop scheme around an interior vertex of valence `valence`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(TriangleSubstitution {
            scheme: scheme.clone(),
            matrices: TriangleLocalMatrices::new(scheme, valence)?,
            bases: HashMap::new(),
            field: std::marker::PhantomData,
        })
    }

    /// Prepare for the patch of sector `sector` next to a boundary vertex with `faces`
    /// triangles (Loop's boundary rules, [`TriangleLocalMatrices::boundary`]).
    pub fn boundary(
        scheme: &TriangleScheme,
        faces: u32,
        sector: u32,
    ) -> Result<Self, StencilError> {
        Ok(TriangleSubstitution {
            scheme: scheme.clone(),
            matrices: TriangleLocalMatrices::boundary(scheme, faces, sector)?,
            bases: HashMap::new(),
            field: std::marker::PhantomData,
        })
    }

    /// Switch to another boundary patch, keeping the cached regular basis (it does not depend
    /// on the patch).
    pub fn select_boundary_patch(&mut self, faces: u32, sector: u32) -> Result<(), StencilError> {
        self.matrices = TriangleLocalMatrices::boundary(&self.scheme, faces, sector)?;
        Ok(())
    }

    /// The `K` position weights at `(u, v)`, `u, v >= 0`, `u + v <= 1`: double `x` `k` times
    /// until `u + v > 1/2`, take the regular sub-triangle's weights at `2x`, apply `A` `k` times.
    /// The regular basis comes from its exact quartic pieces ([`LoopRegularBasis`]), so any
    /// denominator works.
    pub fn stencil(&mut self, u: &BigRational, v: &BigRational) -> Result<Vec<S>, StencilError> {
        self.stencil_of_kind(u, v, StencilKind::Position)
    }

    /// [`Self::stencil`] for positions or derivatives along `u` and `v` (a factor 2 per
    /// halving). At the vertex itself the derivative masks are [`loop_ev_tangents`]' tangent
    /// directions, irrational in general: f64 only.
    pub fn stencil_of_kind(
        &mut self,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let (zero, one) = (BigRational::zero(), BigRational::one());
        if *u < zero || *v < zero || u + v > one {
            return Err(StencilError::OutOfDomain {
                what: format!("(u, v) = ({u}, {v}) is outside the patch u, v >= 0, u + v <= 1"),
            });
        }
        if u.is_zero() && v.is_zero() {
            if kind == StencilKind::Position {
                return self.limit_mask();
            }
            let (du, dv) = match self.matrices.neighbourhood {
                TriangleNeighbourhood::Interior { .. } => {
                    let t = loop_ev_tangents(&self.matrices)?;
                    (t.du, t.dv)
                }
                TriangleNeighbourhood::Boundary { .. } => {
                    let t = loop_boundary_tangents(&self.matrices)?;
                    (t.du, t.dv)
                }
            };
            let mask = if kind == StencilKind::DerivativeU {
                du
            } else {
                dv
            };
            return mask
                .into_iter()
                .map(S::from_f64)
                .collect::<Option<Vec<S>>>()
                .ok_or_else(|| StencilError::Irrational {
                    what: format!(
                        "the tangent mask at the vertex (Loop, {:?})",
                        self.matrices.neighbourhood
                    ),
                });
        }
        let half = BigRational::new(BigInt::from(1), BigInt::from(2));
        let two = BigRational::from_integer(BigInt::from(2));
        let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
        while &x + &y <= half {
            x *= &two;
            y *= &two;
            k += 1;
        }
        let (y1, y2) = (&x * &two, &y * &two);
        let d = y1.denom().lcm(y2.denom());
        let numerator = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer())
        };
        let too_big = || StencilError::OutOfDomain {
            what: format!("the denominator of ({u}, {v}) does not fit in 64 bits"),
        };
        let point = (
            numerator(&y1).map_err(|_| too_big())?,
            numerator(&y2).map_err(|_| too_big())?,
        );
        let d = i64::try_from(&d).map_err(|_| too_big())?;
        if !self.bases.contains_key(&kind) {
            let basis = LoopRegularBasis::new(&self.scheme, kind)?;
            self.bases.insert(kind, basis);
        }
        let factor = S::from_rational(&BigRational::from_integer(BigInt::from(
            kind.doubling_factor(),
        )));
        let mut row: Vec<S> = regular_weights(&self.matrices, &self.bases[&kind], point, d)
            .into_iter()
            .map(|w: S| w * factor.clone())
            .collect();
        let size = self.matrices.size();
        for _ in 0..k {
            row = (0..size)
                .map(|j| {
                    row.iter()
                        .zip(&self.matrices.a)
                        .filter(|(_, a)| !a[j].is_zero())
                        .fold(S::zero(), |acc, (w, a)| {
                            acc + w.clone() * S::from_rational(&a[j])
                        })
                        * factor.clone()
                })
                .collect();
        }
        Ok(row)
    }

    /// The limit-position mask at the vertex: `phi(0) = phi(0) A`, `sum phi(0) = 1`, solved
    /// exactly (Loop: `(1 - v chi) V + chi sum E_i`, `chi = 1 / (3 / (8 beta) + v)`, in the
    /// interior; the boundary curve's `(E_0 + 4 V + E_k) / 6` at a boundary vertex).
    pub fn limit_mask(&self) -> Result<Vec<S>, StencilError> {
        let mask = limit_mask(&self.matrices.a).map_err(|e| StencilError::Inconsistent {
            scheme: self.scheme.name.to_owned(),
            n: 1,
            detail: format!("limit mask, {:?}: {e:?}", self.matrices.neighbourhood),
        })?;
        Ok(mask.iter().map(S::from_rational).collect())
    }
}

/// The subdominant eigenvalue and the tangent masks at the extraordinary vertex of a Loop
/// patch (f64, `K` weights each, zero beyond the 1-ring).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopEvTangents {
    /// The subdominant eigenvalue of `A` (`3/8 + cos(2 pi / v) / 4` for Loop).
    pub lambda: f64,
    /// Tangent mask in the direction of `E_0` (the patch's `u`).
    pub du: Vec<f64>,
    /// Tangent mask in the direction of `E_1` (the patch's `v`).
    pub dv: Vec<f64>,
}

/// Tangent masks at the vertex from the subdominant left eigenvectors of the 1-ring block of
/// `A` (`V, E_0..E_{v-1}`, invariant under subdivision), as [`crate::ev_tangents`] does for
/// quads. The normalization is fixed on the reference net `V = 0`,
/// `E_i = (cos 2 pi i/v, sin 2 pi i/v)`: the `u` mask maps it to `E_0`, the `v` mask to `E_1`.
/// At valence 6 the net is the equilateral lattice and the masks are the box spline's
/// derivatives along the skew axes `(1, 0)` and `(0, 1)` at the vertex.
pub fn loop_ev_tangents(matrices: &TriangleLocalMatrices) -> Result<LoopEvTangents, StencilError> {
    if let TriangleNeighbourhood::Boundary { faces, .. } = matrices.neighbourhood {
        return Err(StencilError::UnsupportedScheme {
            scheme: matrices.scheme.clone(),
            reason: format!("a boundary vertex ({faces} triangles) has no rotational symmetry; its tangents are triangle_boundary::loop_boundary_tangents"),
        });
    }
    let v = matrices.valence as usize;
    let ring = 1 + v;
    let a1 = DMatrix::from_fn(ring, ring, |i, j| rational_to_f64(&matrices.a[i][j]));
    let (lambda, [mut du, mut dv]) =
        ring_tangents(&a1, v).map_err(|what| StencilError::Inconsistent {
            scheme: "tangents at the extraordinary vertex".to_owned(),
            n: 0,
            detail: format!("{} valence {v}: {what}", matrices.scheme),
        })?;
    du.resize(matrices.size(), 0.0);
    dv.resize(matrices.size(), 0.0);
    Ok(LoopEvTangents { lambda, du, dv })
}

/// The tangent masks at an extraordinary vertex of valence `v` from the 1-ring block `a1`
/// (`V, E_0..E_{v-1}`, `(1 + v) x (1 + v)`, invariant under subdivision) of a triangle
/// scheme's local subdivision matrix: the subdominant eigenvalue and the masks (over the ring)
/// spanned by its left eigenvectors, normalized on the reference net `V = 0`,
/// `E_i = (cos 2 pi i/v, sin 2 pi i/v)` so that the `u` mask maps it to `E_0` and the `v` mask
/// to `E_1`. Loop's convention ([`loop_ev_tangents`]), shared with √3's
/// ([`crate::sqrt3_regions`]).
pub(crate) fn ring_tangents(a1: &DMatrix<f64>, v: usize) -> Result<(f64, [Vec<f64>; 2]), String> {
    let (l1, l2) = subdominant_eigenvalues(a1)?;
    let mut basis = left_null_space(a1, l1);
    if (l1 - l2).abs() > 1e-9 {
        basis.truncate(1);
        basis.extend(left_null_space(a1, l2).into_iter().take(1));
    }
    if basis.len() != 2 {
        return Err("the tangent plane is not spanned by two eigenvectors".to_owned());
    }
    let edge = |i: usize| {
        let t = 2.0 * std::f64::consts::PI * (i % v) as f64 / v as f64;
        [t.cos(), t.sin()]
    };
    let net: Vec<(usize, [f64; 2])> = (0..v).map(|i| (1 + i, edge(i))).collect();
    let masks = frame_masks(
        [&basis[0], &basis[1]],
        &net,
        [1.0, 1.0],
        [edge(0), edge(1)],
        basis[0].len(),
    )
    .ok_or_else(|| "the eigenvectors do not span the reference net's plane".to_owned())?;
    Ok((l1, masks))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loop_subdominant_eigenvalue_is_the_closed_form() {
        let loop_ = triangle_scheme("loop").expect("catalogued");
        for v in 3..=8u32 {
            let m = TriangleLocalMatrices::new(&loop_, v).expect("valid");
            let t = loop_ev_tangents(&m).expect("tangents");
            let expected = 0.375 + 0.25 * (2.0 * std::f64::consts::PI / f64::from(v)).cos();
            assert!((t.lambda - expected).abs() < 1e-12, "v = {v}: {}", t.lambda);
        }
    }

    #[test]
    fn points_outside_the_patch_are_errors() {
        let loop_ = triangle_scheme("loop").expect("catalogued");
        let mut s = TriangleSubstitution::<BigRational>::new(&loop_, 5).expect("valid");
        let q = |p: i64, r: i64| BigRational::new(p.into(), r.into());
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        assert!(triangle_patch_stencils::<f64>(&loop_, 5, 0).is_err());
    }
}
