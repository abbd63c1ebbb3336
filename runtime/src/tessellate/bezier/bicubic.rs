//! Bicubic Bézier patches: positions, partial derivatives and unit normals, exact to `f64`.
//!
//! A patch has a 4×4 control net `P[i][j]` stored row by row (`control[4 * i + j]`, the order
//! of the Newell and `.bpt` files, `../shared/models/README.md`). The column index `j` runs
//! along `u`, the row index `i` along `v`:
//!
//! ```text
//! S(u, v) = Σ_i Σ_j B_i(v) B_j(u) P[i][j],   B_k(t) = C(3, k) t^k (1 - t)^(3 - k)
//! ```
//!
//! so `(u, v) = (0, 0)` is `P[0][0]`, `(1, 0)` is `P[0][3]`, `(1, 1)` is `P[3][3]` and `(0, 1)`
//! is `P[3][0]` (the quad-face convention of DESIGN.md). Derivatives are evaluated in hodograph
//! form, on forward differences of the control points, so a collapsed row (four equal points, as
//! in the teapot's lid knob and bottom) has an exactly zero tangent along it; [`BicubicPatch::normal`]
//! then takes the limit normal from the next non-vanishing term of the Taylor expansion of
//! `S_u × S_v` into the patch (first, then second and third derivatives).

pub use crate::mesh::geometry::Point3;
pub(crate) use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};

/// The Bernstein polynomials of degree `n` (0..=3) at `t`; entries past `n` are zero.
///
/// `B^n_k(t) = C(n, k) t^k (1 - t)^(n - k)`. At `t = 0` and `t = 1` the values are exactly
/// `[1, 0, ...]` and `[..., 0, 1]`, so corners evaluate to their control points exactly.
pub fn bernstein(n: usize, t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    match n {
        0 => [1.0, 0.0, 0.0, 0.0],
        1 => [s, t, 0.0, 0.0],
        2 => [s * s, 2.0 * s * t, t * t, 0.0],
        _ => [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t],
    }
}

/// Falling factorial `3! / (3 - k)!` (the factor of the k-th derivative of a cubic).
fn falling(k: usize) -> f64 {
    match k {
        0 => 1.0,
        1 => 3.0,
        2 => 6.0,
        _ => 6.0,
    }
}

/// A bicubic Bézier patch (tensor product of cubic Bernstein polynomials).
#[derive(Clone, Debug, PartialEq)]
pub struct BicubicPatch {
    /// The control net, row by row: `control[4 * i + j] = P[i][j]` (`i` along `v`, `j` along `u`).
    pub control: [Point3; 16],
}

/// A surface point with its first derivatives and unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// `S(u, v)`.
    pub position: Point3,
    /// `∂S/∂u`.
    pub du: Point3,
    /// `∂S/∂v`.
    pub dv: Point3,
    /// The unit normal (direction of `S_u × S_v`, or its limit where that vanishes).
    pub normal: Point3,
}

impl BicubicPatch {
    /// A patch from its 16 control points, row by row.
    pub fn new(control: [Point3; 16]) -> Self {
        BicubicPatch { control }
    }

    /// Control point `P[i][j]` (`i` row along `v`, `j` column along `u`).
    pub fn control_point(&self, i: usize, j: usize) -> Point3 {
        self.control[4 * i + j]
    }

    /// The largest distance of a control point from `P[0][0]` (the patch's scale, used for
    /// relative tolerances).
    pub fn extent(&self) -> f64 {
        self.control
            .iter()
            .map(|&p| norm(sub(p, self.control[0])))
            .fold(0.0, f64::max)
    }

    /// The four control points of side `side` in increasing parameter order: side 0 is `v = 0`
    /// (row 0, along `u`), 1 is `u = 1` (column 3, along `v`), 2 is `v = 1` (row 3, along `u`),
    /// 3 is `u = 0` (column 0, along `v`). The boundary curve of that side is the cubic Bézier
    /// curve of these points alone.
    pub fn side_points(&self, side: usize) -> [Point3; 4] {
        let mut out = [[0.0; 3]; 4];
        for (k, o) in out.iter_mut().enumerate() {
            *o = match side {
                0 => self.control_point(0, k),
                1 => self.control_point(k, 3),
                2 => self.control_point(3, k),
                _ => self.control_point(k, 0),
            };
        }
        out
    }

    /// `S(u, v)`, the tensor-product Bernstein sum.
    pub fn position(&self, u: f64, v: f64) -> Point3 {
        self.partial(u, v, 0, 0)
    }

    /// The partial derivative `∂^(a+b) S / ∂u^a ∂v^b` at `(u, v)`, in hodograph form:
    /// `3!/(3-a)! · 3!/(3-b)! · Σ B^(3-b)_i(v) B^(3-a)_j(u) Δ_u^a Δ_v^b P[i][j]` with forward
    /// differences `Δ`; zero when `a > 3` or `b > 3`.
    pub fn partial(&self, u: f64, v: f64, a: usize, b: usize) -> Point3 {
        if a > 3 || b > 3 {
            return [0.0; 3];
        }
        // Forward differences: a times along j (u), b times along i (v).
        let mut net = self.control;
        for level in 0..a {
            for i in 0..4 {
                for j in 0..3 - level {
                    net[4 * i + j] = sub(net[4 * i + j + 1], net[4 * i + j]);
                }
            }
        }
        for level in 0..b {
            for i in 0..3 - level {
                for j in 0..4 - a {
                    net[4 * i + j] = sub(net[4 * (i + 1) + j], net[4 * i + j]);
                }
            }
        }
        let bu = bernstein(3 - a, u);
        let bv = bernstein(3 - b, v);
        let mut out = [0.0; 3];
        for (i, &wv) in bv.iter().enumerate().take(4 - b) {
            let mut row = [0.0; 3];
            for (j, &wu) in bu.iter().enumerate().take(4 - a) {
                row = add(row, scale(wu, net[4 * i + j]));
            }
            out = add(out, scale(wv, row));
        }
        scale(falling(a) * falling(b), out)
    }

    /// Position, first derivatives and unit normal at `(u, v)` ([`BicubicPatch::normal`]).
    pub fn evaluate(&self, u: f64, v: f64) -> SurfacePoint {
        SurfacePoint {
            position: self.position(u, v),
            du: self.partial(u, v, 1, 0),
            dv: self.partial(u, v, 0, 1),
            normal: self.normal(u, v),
        }
    }

    /// The unit normal at `(u, v)`: `S_u × S_v` normalized; where that vanishes (a collapsed
    /// row, or parallel tangents at a corner) the limit of the normal as the point moves into
    /// the patch along `d` (the inward normal of the side, the inward diagonal at a corner,
    /// `(1, 1)` inside). With `S_u(p + εd) = Σ ε^k A_k`, `S_v(p + εd) = Σ ε^k B_k`, the normal
    /// is `Σ ε^n c_n`, `c_n = Σ_{k ≤ n} A_k × B_(n-k)`, and its limit direction is that of the
    /// first `c_n` that does not vanish (n ≤ 3; e.g. `c_1 = S_uv × S_v` on a collapsed `v = 0`
    /// row). The zero vector only if all of these vanish (a patch collapsed to a curve).
    pub fn normal(&self, u: f64, v: f64) -> Point3 {
        let s = self.extent();
        let tol = 1e-24 * s * s;
        let first = cross(self.partial(u, v, 1, 0), self.partial(u, v, 0, 1));
        if norm(first) > tol {
            return crate::mesh::geometry::normalize(first);
        }
        let dir = |t: f64| -> f64 {
            if t <= 0.0 {
                1.0
            } else if t >= 1.0 {
                -1.0
            } else {
                0.0
            }
        };
        let (mut a, mut b) = (dir(u), dir(v));
        if a == 0.0 && b == 0.0 {
            (a, b) = (1.0, 1.0);
        }
        // A_k, B_k: the k-th Taylor coefficients of S_u, S_v along (a, b).
        let binom = [
            [1.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0],
            [1.0, 2.0, 1.0, 0.0],
            [1.0, 3.0, 3.0, 1.0],
        ];
        let fact = [1.0, 1.0, 2.0, 6.0];
        let mut coeff_u = [[0.0; 3]; 4];
        let mut coeff_v = [[0.0; 3]; 4];
        for k in 0..4 {
            for (m, &c) in binom[k].iter().enumerate().take(k + 1) {
                let w = c * a.powi(m as i32) * b.powi((k - m) as i32) / fact[k];
                if w == 0.0 {
                    continue;
                }
                coeff_u[k] = add(coeff_u[k], scale(w, self.partial(u, v, m + 1, k - m)));
                coeff_v[k] = add(coeff_v[k], scale(w, self.partial(u, v, m, k - m + 1)));
            }
        }
        for n in 1..4 {
            let mut c = [0.0; 3];
            for k in 0..=n {
                c = add(c, cross(coeff_u[k], coeff_v[n - k]));
            }
            if norm(c) > tol {
                return scale(1.0 / norm(c), c);
            }
        }
        [0.0; 3]
    }

    /// Whether side `side` is collapsed to a point (its four control points are equal).
    pub fn side_collapsed(&self, side: usize) -> bool {
        let p = self.side_points(side);
        p.iter().all(|&q| q == p[0])
    }
}
