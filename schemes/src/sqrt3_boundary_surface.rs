//! The √3 surface next to a boundary (Kobbelt's boundary rules), evaluated exactly at the
//! points `k/d` by the scaling relation without a system: beside a straight boundary (the
//! half-plane) and on the fan of `K` triangles around a boundary vertex `V`
//! ([`crate::sqrt3_boundary`]'s charts). The offline generator (`stencilgen::sqrt3_strip`) and
//! the runtime's boundary patches both evaluate it here, each with its own copy of the regular
//! basis `psi` on the grid `1/d` ([`RegularBasis`]: solved by the generator, read from the
//! table by the runtime).
//!
//! **Certified levels.** A level-`N` triangle `T` (level-`N` chart coordinates) is regular when
//! `T + int S`, `S = H/2` the support of the regular basis `psi` (within hex norm 2.5, and two
//! and a half rows on either side of a line), misses every point whose rules differ from the
//! interior's: the points within two thirds of a level unit of the boundary and, on a fan,
//! `V`. So `T` is certified when its corners lie [`REGULAR_ROW`] `= 4` units or more from the
//! boundary rays (rows, in the charts of the sectors next to them) and, on a fan, from `V` (hex
//! norm). With `N` the smallest level at which the triangle holding `y = 3^N x` is certified,
//!
//! ```text
//!   phi(x) = sum_j psi(y - j) R_N[j],     d phi / d x_i = 3^N sum_j psi_i(y - j) R_N[j]
//! ```
//!
//! over the level-`N` lattice points `j` named in the fan (Schaefer–Warren eq. (2); `R_N[j]`
//! the level-0 row of point `j` after `N` ternary steps of the true rules, [`BoundaryRows`];
//! `psi_i` the skew-axis derivatives of `psi`). `y` has denominator `d`, so `psi` is needed on
//! the grid `1/d` only. A point off the boundary and off `V` is certified within
//! `log_3(4d) + 1` levels.
//!
//! **On the boundary** the surface is the uniform cubic B-spline of the boundary polygon
//! (`.., E_K, V, E_0, ..` on a fan; the boundary rules are its ternary refinement), and so is its
//! derivative along the boundary. The derivative across the boundary has no finite value
//! there in general: at the midpoint of a boundary edge the local matrix has a cross mode of
//! `0.3722 > 1/3`, so `d phi/d x_2` grows like `x_2^-0.10` towards the line
//! (docs/algorithms/sqrt3.md); the tangent plane there is a direction, a tangent mask:
//! [`BoundarySurface::cross_mask_on_line`] on the half-plane (the fan's rays and `V` are not
//! covered here; `V`'s masks are `stencilgen::sqrt3_fan_tangents`').

use std::collections::{BTreeMap, HashMap};
use std::fmt;

use crate::loop_regular::RegularDerivative;
use crate::sqrt3_boundary::{BoundaryFan, BoundaryRows, FanPoint, V};

/// A stencil over level-0 half-plane points `(a, b)`, `b >= 0`.
pub type StripStencil = BTreeMap<(i64, i64), f64>;

/// A stencil over the level-0 points of a fan.
pub type FanStencil = BTreeMap<FanPoint, f64>;

/// The lowest row of a level-`N` triangle that is certified regular (module docs); also the
/// least hex-norm distance of its corners from a fan's vertex `V`.
pub const REGULAR_ROW: i64 = 4;

/// The regular √3 basis (two steps, one ternary step) and its skew-axis derivatives on one grid
/// `1/d`: the one input of [`BoundarySurface`] that is solved, not ruled.
pub trait RegularBasis {
    /// The grid's denominator `d`: values are given at the points `k/d`.
    fn denominator(&self) -> i64;
    /// The numerators `((lo_1, hi_1), (lo_2, hi_2))` outside of which `what` is zero.
    fn support_box(&self, what: RegularDerivative) -> ((i64, i64), (i64, i64));
    /// `psi` ([`RegularDerivative::Position`]), `psi_1` (`U`) or `psi_2` (`V`) at `k/d`.
    fn value(&self, what: RegularDerivative, k: (i64, i64)) -> f64;
}

impl<T: RegularBasis + ?Sized> RegularBasis for &T {
    fn denominator(&self) -> i64 {
        (**self).denominator()
    }

    fn support_box(&self, what: RegularDerivative) -> ((i64, i64), (i64, i64)) {
        (**self).support_box(what)
    }

    fn value(&self, what: RegularDerivative, k: (i64, i64)) -> f64 {
        (**self).value(what, k)
    }
}

/// Why a point has no stencil here: the message names the point and the reason.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refused(pub String);

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Refused {}

/// Evaluates the surface beside a straight boundary ([`BoundarySurface::strip`]) or on the fan
/// around a boundary vertex ([`BoundarySurface::fan`]) at the points `k/d` (module docs).
#[derive(Clone, Debug)]
pub struct BoundarySurface<B> {
    d: i64,
    basis: B,
    fan: BoundaryFan,
    rows: BoundaryRows,
    /// The half-plane: no vertex is special, so only the rows count.
    strip: bool,
    /// The half-plane's cross masks on its line by `t` in `0..d` (at `(t/d, 0)`; the others
    /// are their translates).
    line_masks: HashMap<i64, StripStencil>,
    /// A fan's half-plane, whose line masks its rays' start from.
    half_plane: Option<Box<BoundarySurface<B>>>,
}

/// The uniform cubic B-spline's four basis functions at `u` in `[0, 1]` (for the points
/// `p_{-1}, p_0, p_1, p_2`), or their derivatives.
fn cubic_b_spline(u: f64, derivative: bool) -> [f64; 4] {
    let v = 1.0 - u;
    if derivative {
        [
            -v * v / 2.0,
            (3.0 * u * u - 4.0 * u) / 2.0,
            (-3.0 * u * u + 2.0 * u + 1.0) / 2.0,
            u * u / 2.0,
        ]
    } else {
        [
            v * v * v / 6.0,
            (3.0 * u * u * u - 6.0 * u * u + 4.0) / 6.0,
            (-3.0 * u * u * u + 3.0 * u * u + 3.0 * u + 1.0) / 6.0,
            u * u * u / 6.0,
        ]
    }
}

fn hex_norm((a, b): (i64, i64)) -> i64 {
    a.abs().max(b.abs()).max((a + b).abs())
}

impl<B: RegularBasis> BoundarySurface<B> {
    /// The half-plane beside a straight boundary, on `basis`'s grid.
    pub fn strip(basis: B) -> Self {
        Self::new(BoundaryFan::new(3), true, basis)
    }

    /// The fan of `faces` (at least one) triangles around a boundary vertex, on `basis`'s grid.
    pub fn fan(faces: u32, basis: B) -> Result<Self, Refused> {
        if faces == 0 {
            return Err(Refused("a boundary vertex without a triangle".to_owned()));
        }
        Ok(Self::new(BoundaryFan::new(faces), false, basis))
    }

    fn new(fan: BoundaryFan, strip: bool, basis: B) -> Self {
        BoundarySurface {
            d: basis.denominator(),
            basis,
            fan,
            rows: BoundaryRows::new(fan),
            strip,
            line_masks: HashMap::new(),
            half_plane: None,
        }
    }

    /// The fan this surface is evaluated on (the fan of three for the half-plane).
    pub fn boundary_fan(&self) -> BoundaryFan {
        self.fan
    }

    /// The grid's denominator `d`.
    pub fn denominator(&self) -> i64 {
        self.d
    }

    /// The half-plane stencil of `what` (position, `d/dx_1`, `d/dx_2`) at `x = k/d` over the
    /// level-0 half-plane points ([`BoundarySurface::strip`]). Refuses `k_2 < 0`, and the
    /// derivative across the line at `k_2 = 0` (unbounded there in general, module docs).
    pub fn half_plane_stencil(
        &mut self,
        k: (i64, i64),
        what: RegularDerivative,
    ) -> Result<StripStencil, Refused> {
        Ok(self
            .stencil(0, k, what)?
            .into_iter()
            .map(|(p, w)| (BoundaryFan::in_sector_zero(p), w))
            .collect())
    }

    /// Whether the level-`N` triangle with these corners (sector `s`'s chart) is certified
    /// regular: its corners at least [`REGULAR_ROW`] from the boundary rays (and, on a fan,
    /// from `V`), so that `T + int S` misses every point whose rules differ from the interior's.
    fn certified(&self, s: i64, corners: &[(i64, i64); 3]) -> bool {
        if self.strip {
            return corners.iter().all(|c| c.1 >= REGULAR_ROW);
        }
        let last = i64::from(self.fan.faces) - 1;
        corners.iter().all(|&c| {
            hex_norm(c) >= REGULAR_ROW
                && (s != 0 || c.1 >= REGULAR_ROW)
                && (s != last || c.0 >= REGULAR_ROW)
        })
    }

    /// The stencil of `what` (position, `d/du`, `d/dv` along sector `sector`'s chart axes) at
    /// `x = k/d` of that chart, over the fan's level-0 points. On a boundary ray the position
    /// is the boundary's cubic B-spline and the derivative along the ray its derivative; the
    /// derivative across a ray on it, and every derivative at a fan's `V`, are refused
    /// (unbounded or a direction only, module docs).
    pub fn stencil(
        &mut self,
        sector: i64,
        k: (i64, i64),
        what: RegularDerivative,
    ) -> Result<FanStencil, Refused> {
        let d = self.d;
        let refuse = |why: &str| {
            Refused(format!(
                "{what:?} at ({}/{d}, {}/{d}) of sector {sector}: {why}",
                k.0, k.1
            ))
        };
        let at_v = !self.strip && k == (0, 0);
        if let Some((t, along)) = self.on_boundary(sector, k) {
            if at_v && what != RegularDerivative::Position {
                return Err(refuse(
                    "a derivative at the boundary vertex (a tangent mask)",
                ));
            }
            let derivative = match (what, along) {
                (RegularDerivative::Position, _) => None,
                (RegularDerivative::U, Axis::U) => Some(1.0),
                (RegularDerivative::V, Axis::MinusV) => Some(-1.0),
                _ => return Err(refuse("across the boundary on it (unbounded in general)")),
            };
            return Ok(self.boundary_curve(t, derivative));
        }
        // The smallest level at which the triangle holding x is certified regular.
        let (mut level, mut y, mut factor) = (0u32, k, 1.0);
        loop {
            let (a, b) = (y.0.div_euclid(d), y.1.div_euclid(d));
            let (fa, fb) = (y.0.rem_euclid(d), y.1.rem_euclid(d));
            let corners = if fa + fb < d {
                [(a, b), (a + 1, b), (a, b + 1)]
            } else {
                [(a + 1, b), (a + 1, b + 1), (a, b + 1)]
            };
            if self.certified(sector, &corners) {
                break;
            }
            if level >= MAX_LEVEL {
                return Err(refuse(
                    "no certified level (too close to the boundary or V)",
                ));
            }
            level += 1;
            y = (3 * y.0, 3 * y.1);
            factor *= 3.0;
        }
        let ((l1, h1), (l2, h2)) = self.basis.support_box(what);
        let scale = if what == RegularDerivative::Position {
            1.0
        } else {
            factor
        };
        let mut out = FanStencil::new();
        // j with y - d j in the support's box: d j_i in [y_i - h_i, y_i - l_i].
        for j2 in (y.1 - h2).div_euclid(d)..=(y.1 - l2).div_euclid(d) + 1 {
            for j1 in (y.0 - h1).div_euclid(d)..=(y.0 - l1).div_euclid(d) + 1 {
                let w = self.basis.value(what, (y.0 - d * j1, y.1 - d * j2));
                if w == 0.0 {
                    continue;
                }
                let name = self.fan.canonical(sector, (j1, j2)).ok_or_else(|| {
                    refuse(&format!(
                        "level-{level} point ({j1}, {j2}) is outside the fan"
                    ))
                })?;
                for (&p, &r) in self.rows.row(level, name) {
                    *out.entry(p).or_insert(0.0) += scale * w * r;
                }
            }
        }
        out.retain(|_, w| *w != 0.0);
        Ok(out)
    }

    /// The derivative along the boundary polygon (towards `E_0`; on the half-plane along
    /// `x_1`) at the boundary point of parameter `tau / d`, `V` included: the cubic B-spline's.
    pub fn boundary_tangent(&self, tau: i64) -> FanStencil {
        self.boundary_curve(tau as f64 / self.d as f64, Some(1.0))
    }

    /// Where `k/d` of sector `s`'s chart lies on the boundary: its parameter along the
    /// boundary polygon (`V` at 0, `E_0` at 1, `E_K` at -1; the half-plane's line at `x_1`) and
    /// the chart axis that runs along the boundary there, with its sign.
    fn on_boundary(&self, s: i64, k: (i64, i64)) -> Option<(f64, Axis)> {
        let d = self.d as f64;
        if self.strip {
            return (k.1 == 0).then_some((k.0 as f64 / d, Axis::U));
        }
        let last = i64::from(self.fan.faces) - 1;
        if k == (0, 0) {
            // V, from any sector's chart (its derivatives are refused before the axis counts).
            Some((0.0, Axis::U))
        } else if s == 0 && k.1 == 0 && k.0 >= 0 {
            Some((k.0 as f64 / d, Axis::U))
        } else if s == last && k.0 == 0 && k.1 >= 0 {
            Some((-(k.1 as f64) / d, Axis::MinusV))
        } else {
            None
        }
    }

    /// The boundary's cubic B-spline at parameter `t` (or its derivative along the boundary,
    /// times `sign`), over the fan's boundary points.
    fn boundary_curve(&self, t: f64, derivative: Option<f64>) -> FanStencil {
        let base = t.floor();
        let weights = cubic_b_spline(t - base, derivative.is_some());
        let sign = derivative.unwrap_or(1.0);
        let k = self.fan.faces;
        let point = |i: i64| -> FanPoint {
            if self.strip {
                // The line's points, named in the fan of three (sector 0's chart).
                self.fan.canonical(0, (i, 0)).unwrap_or(V)
            } else if i == 0 {
                V
            } else if i > 0 {
                (0, i, 0)
            } else {
                (k, -i, 0)
            }
        };
        let mut out = FanStencil::new();
        for (m, w) in (-1..=2).zip(weights) {
            if w != 0.0 {
                *out.entry(point(base as i64 + m)).or_insert(0.0) += sign * w;
            }
        }
        out
    }

    /// One level down the half-plane's line: the cross-boundary stencil `D(t, e/3)` from
    /// `v = D(t', e)`, `3t = t' + s`, `t = k/d`: `3 sum_r v[r] R_1[r + (s, 0)]` (translation
    /// invariance along the line). The map triples the constant mode, which a derivative lacks
    /// but rounding puts back; its left eigenvector is the position at `(t, 0)` (the same
    /// relation without the factor 3), so the step removes `(sum) position(t)`.
    fn line_step(&mut self, v: &FanStencil, s: i64, k: i64) -> Result<FanStencil, Refused> {
        let mut out = FanStencil::new();
        for (&p, &w) in v {
            let (a, b) = BoundaryFan::in_sector_zero(p);
            let name = self
                .fan
                .canonical(0, (a + s, b))
                .ok_or_else(|| Refused(format!("({}, {b}) below the boundary", a + s)))?;
            for (&q, &r) in self.rows.row(1, name) {
                *out.entry(q).or_insert(0.0) += 3.0 * w * r;
            }
        }
        let sum: f64 = out.values().sum();
        for (q, w) in self.stencil(0, (k, 0), RegularDerivative::Position)? {
            *out.entry(q).or_insert(0.0) -= sum * w;
        }
        out.retain(|_, w| *w != 0.0);
        Ok(out)
    }

    /// The cross-boundary tangent mask at `(k/d, 0)` on the half-plane's line
    /// ([`BoundarySurface::strip`]): the direction the derivatives `D(t, e)` across the line
    /// take as `e -> 0` (they grow without bound where a cross mode outgrows the tangent's
    /// `1/3`, as at an edge's midpoint, and converge where it does not, as at a vertex),
    /// normalized with the line's own tangent so that on the flat lattice (point `(a, b)` at
    /// `(a, b)`) it maps to `(0, 1)`, the `x_2` axis, as a derivative would. So `du` (the
    /// B-spline's derivative) and this mask span the surface's tangent plane there.
    ///
    /// The derivatives above the line relate level to level, `D(t, e/3) = 3 sum_r D(t', e)[r]
    /// R_1[r + (s, 0)]` with `3t = t' + s` (translation invariance along the line); on the
    /// grid `1/d` the numerators follow `t -> 3t mod d` into a cycle. Starting from the exact
    /// derivative at `(t_p, 1/d)` above the cycle's first point, the cycle is walked backwards
    /// level by level, renormalized every turn, until a turn changes the normalized mask by at
    /// most 1e-12 of its largest weight; the points before the cycle follow by the same step.
    pub fn cross_mask_on_line(&mut self, k: i64) -> Result<StripStencil, Refused> {
        let (base, t) = (k.div_euclid(self.d), k.rem_euclid(self.d));
        let mask = match self.line_masks.get(&t) {
            Some(mask) => mask.clone(),
            None => {
                let mask = self.walk_the_line(t)?;
                self.line_masks.insert(t, mask.clone());
                mask
            }
        };
        // Translation invariance along the line: the mask at k is the one at t moved.
        Ok(mask
            .into_iter()
            .map(|((a, b), w)| ((a + base, b), w))
            .collect())
    }

    /// [`BoundarySurface::cross_mask_on_line`] at `(k/d, 0)`, walked (uncached).
    fn walk_the_line(&mut self, k: i64) -> Result<StripStencil, Refused> {
        let d = self.d;
        let unsettled = || {
            Refused(format!(
                "the cross-boundary direction at ({k}/{d}, 0) did not settle"
            ))
        };
        if !self.strip {
            return Err(Refused(
                "the cross-boundary mask on the line is the half-plane's".to_owned(),
            ));
        }
        let (base, start_t) = (k.div_euclid(d), k.rem_euclid(d));
        // The orbit t -> 3t mod d with each step's shift, until a numerator repeats.
        let mut orbit: Vec<(i64, i64)> = Vec::new();
        let mut t = start_t;
        let start = loop {
            if let Some(i) = orbit.iter().position(|&(u, _)| u == t) {
                break i;
            }
            orbit.push((t, (3 * t).div_euclid(d)));
            t = (3 * t).rem_euclid(d);
        };
        let normalized = |v: FanStencil| -> FanStencil {
            let largest = v.values().fold(0.0f64, |m, w| m.max(w.abs()));
            v.into_iter().map(|(p, w)| (p, w / largest)).collect()
        };
        let cycle: Vec<(i64, i64)> = orbit[start..].to_vec();
        let mut v = normalized(self.stencil(0, (cycle[0].0, 1), RegularDerivative::V)?);
        let mut levels = 0;
        loop {
            let before = v.clone();
            for &(u, s) in cycle.iter().rev() {
                v = self.line_step(&v, s, u)?;
                levels += 1;
            }
            v = normalized(v);
            let change = v
                .keys()
                .chain(before.keys())
                .map(|p| {
                    (v.get(p).copied().unwrap_or(0.0) - before.get(p).copied().unwrap_or(0.0)).abs()
                })
                .fold(0.0f64, f64::max);
            if change <= SETTLED {
                break;
            }
            if levels > MAX_LINE_LEVELS {
                return Err(unsettled());
            }
        }
        for &(u, s) in orbit[..start].iter().rev() {
            v = self.line_step(&v, s, u)?;
        }
        // Frame: the flat lattice's image of v is (g_1, g_2); the line's tangent maps it to
        // (1, 0); so (v - g_1 tangent) / g_2 maps it to (0, 1).
        let image = v.iter().fold([0.0, 0.0], |acc, (&p, &w)| {
            let (a, b) = BoundaryFan::in_sector_zero(p);
            [acc[0] + w * a as f64, acc[1] + w * b as f64]
        });
        if image[1].abs() < 1e-12 {
            return Err(unsettled());
        }
        let tangent = self.stencil(0, (start_t, 0), RegularDerivative::U)?;
        let mut mask = v;
        for (p, w) in tangent {
            *mask.entry(p).or_insert(0.0) -= image[0] * w;
        }
        Ok(mask
            .into_iter()
            .filter(|&(_, w)| w != 0.0)
            .map(|(p, w)| {
                let (a, b) = BoundaryFan::in_sector_zero(p);
                ((a + base, b), w / image[1])
            })
            .collect())
    }
}

impl<B: RegularBasis + Clone> BoundarySurface<B> {
    /// The cross-boundary tangent mask at the boundary point of parameter `tau / d` along the
    /// boundary polygon (`V` at 0, `E_0` at `d`, `E_K` at `-d`; on the half-plane the line's
    /// `x_1`), over the fan's level-0 points: the direction into the surface that, with the
    /// derivative along the boundary, spans the tangent plane there (module docs). Oriented so
    /// that (along the boundary towards `E_0`, this mask) turns counter-clockwise like the
    /// charts' axes; scaled so that its largest weight is 1 on a fan (the half-plane's is
    /// [`BoundarySurface::cross_mask_on_line`]'s).
    ///
    /// * On the half-plane: [`BoundarySurface::cross_mask_on_line`].
    /// * On a fan's ray: the ray is the half-plane's line far from `V`, so the mask at
    ///   `3^m tau` (the first `m` that puts it and its support [`FAR`] units or more from `V`)
    ///   is the half-plane's there; walked back `m` levels by the fan's rows
    ///   (`M_{l-1} = sum_q M_l[q] R_1[q]`, the relation [`BoundarySurface::cross_mask_on_line`]
    ///   walks on the line, without its translation), the constant mode removed at each level.
    /// * At `V`: [`BoundarySurface::cross_mask_at_vertex`].
    pub fn cross_mask(&mut self, tau: i64) -> Result<FanStencil, Refused> {
        if self.strip {
            let line = self.cross_mask_on_line(tau)?;
            return line
                .into_iter()
                .map(|(p, w)| {
                    self.fan
                        .canonical(0, p)
                        .map(|name| (name, w))
                        .ok_or_else(|| Refused(format!("{p:?} is below the line")))
                })
                .collect();
        }
        if tau == 0 {
            return self.cross_mask_at_vertex();
        }
        let d = self.d;
        let last = i64::from(self.fan.faces) - 1;
        // Half-plane point (x, y), x along the boundary parameter, as a point of the ray's
        // sector chart: sector 0 takes it as is; sector K - 1 runs the boundary along (0, -1)
        // with the surface on the side of (1, -1), its 60-degree turn.
        let on_ray = |fan: &BoundaryFan, (x, y): (i64, i64)| -> Option<FanPoint> {
            if tau > 0 {
                (x >= 1).then(|| fan.canonical(0, (x, y))).flatten()
            } else {
                (x <= -1)
                    .then(|| fan.canonical(last, (y, -x - y)))
                    .flatten()
            }
        };
        let basis = &self.basis;
        let strip = self
            .half_plane
            .get_or_insert_with(|| Box::new(BoundarySurface::strip(basis.clone())));
        let (mut level, mut far) = (0u32, tau);
        let mut mask = loop {
            if far.abs() >= FAR * d {
                let line = strip.cross_mask_on_line(far)?;
                let named: Option<FanStencil> = line
                    .iter()
                    .map(|(&p, &w)| on_ray(&self.fan, p).map(|name| (name, w)))
                    .collect();
                if let Some(named) = named {
                    break named;
                }
            }
            if level >= MAX_LEVEL {
                return Err(Refused(format!(
                    "the cross-boundary mask at {tau}/{d} on a ray: no level puts it beside a \
                     straight boundary"
                )));
            }
            level += 1;
            far *= 3;
        };
        for l in (0..level).rev() {
            let mut back = FanStencil::new();
            for (&q, &w) in &mask {
                for (&p, &r) in self.rows.row(1, q) {
                    *back.entry(p).or_insert(0.0) += w * r;
                }
            }
            // The rows are affine, so the sum stays 0 but for rounding, which the step would
            // triple: remove it with the boundary curve's position there.
            let sum: f64 = back.values().sum();
            let here = (3i64.pow(l) * tau) as f64 / d as f64;
            for (p, w) in self.boundary_curve(here, None) {
                *back.entry(p).or_insert(0.0) -= sum * w;
            }
            mask = normalized(back);
        }
        mask.retain(|_, w| *w != 0.0);
        Ok(mask)
    }
}

impl<B: RegularBasis> BoundarySurface<B> {
    /// The cross-boundary tangent mask at a fan's vertex `V` (`K != 3`; the half-plane's is
    /// [`BoundarySurface::cross_mask_on_line`] at 0): the left eigenvector `c` of the ternary
    /// step on the ball of points within three units of `V` (closed under the step) for the
    /// largest eigenvalue below 1 whose eigenvector is independent of the boundary tangent
    /// `t = (E_0 - E_K)/2` (docs/algorithms/sqrt3.md, the spectra table), by power iteration:
    /// at `K >= 4` that mode leads `t`'s `1/3`; at `K = 1, 2` (`1/9`, `2/9`) `t` is deflated
    /// with its right eigenvector, itself iterated. The constant mode (left: the limit mask
    /// `(E_K + 4V + E_0)/6`, right: the ones) is removed at every step. Oriented on the
    /// half-disk net (sector `s`'s `(a, b)` at `a e_s + b e_{s+1}`, `e_i` at angle
    /// `i pi / max(K, 2)`) so that it points into the surface from the boundary tangent.
    pub fn cross_mask_at_vertex(&mut self) -> Result<FanStencil, Refused> {
        if self.strip {
            return Err(Refused(
                "the half-plane's vertex mask is cross_mask_on_line(0)".to_owned(),
            ));
        }
        let k = self.fan.faces;
        let mut ball: Vec<FanPoint> =
            std::iter::once(V)
                .chain((0..=k).flat_map(|s| {
                    (1..=3i64).flat_map(move |a| (0..=3 - a).map(move |b| (s, a, b)))
                }))
                .filter(|&(s, a, b)| self.fan.canonical(i64::from(s), (a, b)) == Some((s, a, b)))
                .collect();
        ball.sort_unstable();
        let slot = |p: &FanPoint| ball.binary_search(p).ok();
        let refuse = |why: String| Refused(format!("the vertex mask of the fan of {k}: {why}"));
        // A[q][p]: the step's rows of the ball's points over the ball.
        let mut a = vec![vec![0.0; ball.len()]; ball.len()];
        for (i, &q) in ball.iter().enumerate() {
            for (&p, &w) in self.rows.row(1, q) {
                let j = slot(&p).ok_or_else(|| refuse(format!("{p:?} leaves the ball")))?;
                a[i][j] = w;
            }
        }
        let limit: Vec<f64> = ball
            .iter()
            .map(|p| {
                self.boundary_curve(0.0, None)
                    .get(p)
                    .copied()
                    .unwrap_or(0.0)
            })
            .collect();
        let unit = |p: FanPoint| -> Vec<f64> { ball.iter().map(|&q| f64::from(q == p)).collect() };
        let (e0, ek) = (unit((0, 1, 0)), unit((k, 1, 0)));
        let tangent: Vec<f64> = e0.iter().zip(&ek).map(|(x, y)| (x - y) / 2.0).collect();
        let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
        let scaled = |x: Vec<f64>| -> Vec<f64> {
            let m = x.iter().fold(0.0f64, |m, w| m.max(w.abs()));
            x.into_iter().map(|w| w / m).collect()
        };
        let settle =
            |mut x: Vec<f64>, step: &dyn Fn(&[f64]) -> Vec<f64>| -> Result<Vec<f64>, Refused> {
                for _ in 0..MAX_LINE_LEVELS {
                    let next = scaled(step(&x));
                    let change = next
                        .iter()
                        .zip(&x)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    x = next;
                    if change <= SETTLED {
                        return Ok(x);
                    }
                }
                Err(refuse("the power iteration did not settle".to_owned()))
            };
        // Right eigenvector of t's 1/3 (K = 1, 2): A r, less its constant part (l . r) 1.
        let deflate = if k <= 2 {
            let right = settle(
                e0.iter().zip(&ek).map(|(x, y)| x - y).collect(),
                &|r: &[f64]| {
                    let ar: Vec<f64> = a.iter().map(|row| dot(row, r)).collect();
                    let c = dot(&limit, &ar);
                    ar.into_iter().map(|x| x - c).collect()
                },
            )?;
            let norm = dot(&tangent, &right);
            if norm.abs() < 1e-12 {
                return Err(refuse(
                    "the tangent's right eigenvector is degenerate".to_owned(),
                ));
            }
            Some((right, norm))
        } else {
            None
        };
        // Left iteration from a point inside the middle sector, less the limit mask.
        let inside = ball
            .iter()
            .position(|&p| p == (k.saturating_sub(1) / 2, 1, 1))
            .ok_or_else(|| refuse("no interior point in the ball".to_owned()))?;
        let start: Vec<f64> = (0..ball.len())
            .map(|j| f64::from(j == inside) - limit[j])
            .collect();
        let mask = settle(start, &|m: &[f64]| {
            let mut next: Vec<f64> = (0..ball.len())
                .map(|j| m.iter().zip(&a).map(|(w, row)| w * row[j]).sum())
                .collect();
            let constant: f64 = next.iter().sum();
            for (x, l) in next.iter_mut().zip(&limit) {
                *x -= constant * l;
            }
            if let Some((right, norm)) = &deflate {
                let c = dot(&next, right) / norm;
                for (x, t) in next.iter_mut().zip(&tangent) {
                    *x -= c * t;
                }
            }
            next
        })?;
        // Orientation on the half-disk net: the image of c to the left of t's.
        let theta = std::f64::consts::PI / f64::from(k.max(2));
        let at = |&(s, a, b): &FanPoint| -> [f64; 2] {
            let e = |i: u32| [(f64::from(i) * theta).cos(), (f64::from(i) * theta).sin()];
            let (x, y) = (e(s), e(s + 1));
            [
                a as f64 * x[0] + b as f64 * y[0],
                a as f64 * x[1] + b as f64 * y[1],
            ]
        };
        let image = |w: &[f64]| {
            ball.iter().zip(w).fold([0.0, 0.0], |acc, (p, &x)| {
                let q = at(p);
                [acc[0] + x * q[0], acc[1] + x * q[1]]
            })
        };
        let (t, c) = (image(&tangent), image(&mask));
        let turn = t[0] * c[1] - t[1] * c[0];
        if turn.abs() < 1e-9 {
            return Err(refuse(
                "the cross mode is parallel to the tangent on the net".to_owned(),
            ));
        }
        let sign = turn.signum();
        Ok(ball
            .iter()
            .zip(mask)
            .filter(|(_, w)| *w != 0.0)
            .map(|(&p, w)| (p, sign * w))
            .collect())
    }
}

/// A stencil scaled so that its largest weight is 1 in magnitude.
fn normalized(v: FanStencil) -> FanStencil {
    let largest = v.values().fold(0.0f64, |m, w| m.max(w.abs()));
    v.into_iter().map(|(p, w)| (p, w / largest)).collect()
}

/// How far from `V` (in level units, along the ray) a fan's ray is the half-plane's line for
/// [`BoundarySurface::cross_mask`]: the line's masks reach about five units on either side.
pub const FAR: i64 = 9;

/// How much one turn of a cycle may change the normalized mask of
/// [`BoundarySurface::cross_mask_on_line`] (relative to its largest weight) when it stops.
const SETTLED: f64 = 1e-12;

/// Levels walked at most by [`BoundarySurface::cross_mask_on_line`]: at an edge's midpoint
/// the rest shrinks by `(1/3) / 0.3722 = 0.896` a level, which reaches [`SETTLED`] within 300.
const MAX_LINE_LEVELS: usize = 5000;

/// A chart axis along the boundary, with its direction relative to the boundary polygon's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Axis {
    U,
    MinusV,
}

/// Levels tried at most before a point is refused as too close to the boundary or `V` (a
/// grid point off them is certified within `log_3(4 d) + 1` levels).
const MAX_LEVEL: u32 = 12;
