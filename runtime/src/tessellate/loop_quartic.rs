//! Loop's regular patch as one quartic polynomial per triangle, for the triangle dual grid's
//! regular faces ([`crate::tessellate::triangle_dual_grid`]) and the tolerance selection's
//! samples of them ([`crate::tessellate::triangle_rates`]).
//!
//! Over a triangle whose three corners have valence 6 Loop's surface is the quartic box spline
//! (Loop 1987; Schaefer–Warren section 5.1): each of the twelve control points' weights is one
//! bivariate polynomial of total degree 4 in the patch parameters `(u, v)`,
//!
//! ```text
//! w_l(u, v) = sum_{a + b <= 4} C[a, b][l] u^a v^b,        l = 0..12,
//! ```
//!
//! so the patch itself is `P(u, v) = sum_{a+b<=4} c_ab u^a v^b` with `c_ab = sum_l C[a,b][l] P_l`.
//! The coefficients come from the closed form of `schemes::loop_regular` (exact values of the
//! twelve weights at the 15 points `(i/4, j/4)` of the principal lattice of degree 4, which fix
//! a quartic): the Vandermonde system of those 15 points is solved once, in f64, for the
//! monomial coefficients. The plan accepts them for a rate only if they reproduce the table's
//! own stencils (position, d/du and d/dv, dual and primal points) to 1e-6, as the quad path
//! accepts its separable factors; otherwise the faces keep their stencils.
//!
//! Per frame and face, the twelve control points are contracted once into the 15 coefficients
//! (x 3 coordinates); then per row of constant `v` into a univariate quartic in `u`,
//! `r_a(v) = sum_b c_ab v^b`, and its `v`-derivative `s_a(v) = sum_b b c_ab v^(b-1)`; every
//! point of the row is then `P = sum_a r_a u^a`, `P_u = sum_a a r_a u^(a-1)`,
//! `P_v = sum_a s_a u^a` by Horner's rule: 10 multiply-adds a coordinate for the position and
//! both derivatives, instead of the stencils' 36.
//!
//! Rounding: the coefficients are contracted from the differences `P_l - P_0`, taken in f64 by
//! [`crate::tessellate::kernel::relative`] (the weights of every `c_ab` but `c_00` sum
//! to zero, and `c_00`'s to one), so the large absolute position enters once, as `P_0` added to
//! `c_00`, and the monomial terms, hence the tangents and normals, carry only the patch's own
//! extent wherever it sits; the output agrees with the stencils' to f32 rounding of the
//! coordinates.
//!
//! The dual grid's points lie on rows of constant `v` in the *face's* parameters (`up(i, j)` at
//! `v = (3j+1)/3n`, `down(i, j)` at `(3j+2)/3n`, the interior primal points at `j/n`), and a
//! patch at face corner `r` sees the face rotated (`crate::scheme::triangle::patch`), so the
//! coefficients are kept in the face's parameters for each of the three corners: the rotation
//! is affine with determinant one, so the face's `P_u x P_v` is the patch's, and the normal is
//! unchanged.

use std::sync::OnceLock;

use num_rational::BigRational;
use num_traits::ToPrimitive;
use schemes::loop_regular::{RegularDerivative, RegularLoopPatch, REGULAR_NET};

use crate::scheme::triangle::patch::{dual_index, primal_in_patch, primal_index};
use crate::tessellate::kernel::Stencils;
use crate::tessellate::lane_stencils::{unit_cross, LANES};

/// Control points of the regular patch.
pub(crate) const POINTS: usize = 12;

/// Monomials `u^a v^b` of total degree at most 4, indexed by [`monomial`].
pub(crate) const MONOMIALS: usize = 15;

/// One regular patch as a quartic in a face's parameters: the coefficient of every monomial
/// ([`monomial`]), per coordinate ([`QuarticBasis::polynomial`]).
pub(crate) type Polynomial = [[f64; 3]; MONOMIALS];

/// [`MONOMIALS`] padded to a multiple of the vector width.
const MONOMIAL_LANES: usize = 16;

/// The degree of the pieces.
const DEGREE: usize = 4;

/// Lattice coordinates of the regular patch's control points in the table's layout
/// (`schemes::triangle_local::triangle_layout(6)`): `V`, `E_0..E_5` counter-clockwise from the
/// face's corner after `V`, then `O_0..O_4` (`crate::scheme::triangle::patch`).
const TABLE_LAYOUT: [(i64, i64); POINTS] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (0, -1),
    (1, -1),
    (2, -1),
    (2, 0),
    (1, 1),
    (0, 2),
    (-1, 2),
];

/// Index of the monomial `u^a v^b` (`a + b <= 4`): by `a`, then `b`.
const fn monomial(a: usize, b: usize) -> usize {
    // Degrees a' < a hold 5 - a' monomials each.
    a * (2 * DEGREE + 3 - a) / 2 + b
}

/// Monomial coefficients of the twelve weights: `[monomial(a, b)][control point]`.
type Coefficients = [[f64; POINTS]; MONOMIALS];

/// The regular Loop patch's weights as polynomials in a face's parameters, for a patch at each
/// of the three face corners (`by_corner[r]`: `(u', v') = (w_{r+1}, w_{r+2})`, `w = (1-u-v,
/// u, v)`).
#[derive(Clone, Debug)]
pub(crate) struct QuarticBasis {
    by_corner: [Coefficients; 3],
    /// `by_corner` in f32, transposed (`[corner][control point][monomial]`, padded with
    /// zeros), the form the frames read.
    pub(crate) frame: [[[f32; MONOMIAL_LANES]; POINTS]; 3],
}

impl QuarticBasis {
    /// The coefficients from the closed form (computed once per process: two exact
    /// subdivision steps and a few linear solves, milliseconds), `None` if a solve fails.
    pub(crate) fn get() -> Option<&'static QuarticBasis> {
        static BASIS: OnceLock<Option<QuarticBasis>> = OnceLock::new();
        BASIS.get_or_init(QuarticBasis::new).as_ref()
    }

    fn new() -> Option<Self> {
        let patch = RegularLoopPatch::new();
        // REGULAR_NET's order to the table's.
        let mut net = [0usize; POINTS];
        for (slot, p) in net.iter_mut().zip(TABLE_LAYOUT) {
            *slot = REGULAR_NET.iter().position(|&q| q == p)?;
        }
        // Exact weights at the lattice points (i/4, j/4) of the patch.
        let mut lattice = vec![[0.0f64; POINTS]; MONOMIALS];
        for j in 0..=DEGREE as u32 {
            for i in 0..=DEGREE as u32 - j {
                let ratio = |x: u32| BigRational::new(i64::from(x).into(), 4i64.into());
                let w = patch.weights(&ratio(i), &ratio(j), RegularDerivative::Position);
                let row = &mut lattice[primal_index(DEGREE as u32, i, j)];
                for (out, &l) in row.iter_mut().zip(&net) {
                    *out = w[l].to_f64()?;
                }
            }
        }
        let mut by_corner = [[[0.0; POINTS]; MONOMIALS]; 3];
        for (corner, coefficients) in by_corner.iter_mut().enumerate() {
            // The face's point (i/4, j/4) is the patch's lattice point primal_in_patch(..).
            let mut values = vec![[0.0f64; POINTS]; MONOMIALS];
            for j in 0..=DEGREE as u32 {
                for i in 0..=DEGREE as u32 - j {
                    let (pi, pj) = primal_in_patch(corner, DEGREE as u32, i, j);
                    values[primal_index(DEGREE as u32, i, j)] =
                        lattice[primal_index(DEGREE as u32, pi, pj)];
                }
            }
            *coefficients = interpolate(&values)?;
        }
        let frame = by_corner.map(|c| {
            let mut t = [[0.0f32; MONOMIAL_LANES]; POINTS];
            for (m, row) in c.iter().enumerate() {
                for (l, &x) in row.iter().enumerate() {
                    t[l][m] = x as f32;
                }
            }
            t
        });
        Some(QuarticBasis { by_corner, frame })
    }

    /// The regular patch at face corner `corner` over its twelve control points `control` (the
    /// table's layout) as one quartic in the face's parameters: `c_ab = sum_l C[a, b][l] P_l`.
    pub(crate) fn polynomial(&self, corner: usize, control: &[[f64; 3]]) -> Polynomial {
        let c = &self.by_corner[corner % 3];
        std::array::from_fn(|m| {
            let mut out = [0.0; 3];
            for (&w, q) in c[m].iter().zip(control) {
                for k in 0..3 {
                    out[k] += w * q[k];
                }
            }
            out
        })
    }

    /// Whether the patch-frame polynomials reproduce the table's stencils `dual` and `primal`
    /// of the regular patch at rate `n` (position, d/du, d/dv; every point) to `1e-6`.
    pub(crate) fn reproduces(&self, dual: &Stencils, primal: &Stencils, n: u32) -> bool {
        let c = &self.by_corner[0];
        let nf = f64::from(n);
        let matches = |s: &Stencils, row: usize, (u, v): (f64, f64)| {
            let range = row * POINTS..(row + 1) * POINTS;
            let (Some(wp), Some(wu), Some(wv)) = (
                s.position.get(range.clone()),
                s.du.get(range.clone()),
                s.dv.get(range),
            ) else {
                return false;
            };
            (0..POINTS).all(|l| {
                let [p, du, dv] = weight(c, l, u, v);
                (f64::from(wp[l]) - p).abs() <= 1e-6
                    && (f64::from(wu[l]) - du).abs() <= 1e-6
                    && (f64::from(wv[l]) - dv).abs() <= 1e-6
            })
        };
        if dual.position.len() != (n * n) as usize * POINTS
            || primal.position.len() != ((n + 1) * (n + 2) / 2) as usize * POINTS
        {
            return false;
        }
        (0..n).all(|j| {
            (0..n - j).all(|i| {
                let at = |shift: u32| {
                    (
                        f64::from(3 * i + shift) / (3.0 * nf),
                        f64::from(3 * j + shift) / (3.0 * nf),
                    )
                };
                matches(dual, dual_index(n, i, j, false), at(1))
                    && (i + j + 1 == n || matches(dual, dual_index(n, i, j, true), at(2)))
            })
        }) && (0..=n).all(|j| {
            (0..=n - j).all(|i| {
                matches(
                    primal,
                    primal_index(n, i, j),
                    (f64::from(i) / nf, f64::from(j) / nf),
                )
            })
        })
    }
}

/// `p` on the line `v`: the coefficient of each power `u^a`, its quartic in `v` by Horner's
/// rule. The value at `(u, v)` is [`row_value`] of it, so samples along one row share it.
pub(crate) fn polynomial_row(p: &Polynomial, v: f64) -> [[f64; 3]; DEGREE + 1] {
    std::array::from_fn(|a| {
        let mut row = [0.0; 3];
        for b in (0..=DEGREE - a).rev() {
            for k in 0..3 {
                row[k] = row[k] * v + p[monomial(a, b)][k];
            }
        }
        row
    })
}

/// The quartic in `u` with coefficients `row` ([`polynomial_row`]), by Horner's rule.
pub(crate) fn row_value(row: &[[f64; 3]; DEGREE + 1], u: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for coefficient in row.iter().rev() {
        for k in 0..3 {
            out[k] = out[k] * u + coefficient[k];
        }
    }
    out
}

/// Weight of control point `l` and its two derivatives at `(u, v)`, from coefficients `c`.
fn weight(c: &Coefficients, l: usize, u: f64, v: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for a in 0..=DEGREE {
        for b in 0..=DEGREE - a {
            let x = c[monomial(a, b)][l];
            let power = |t: f64, e: usize| if e == 0 { 1.0 } else { t.powi(e as i32) };
            out[0] += x * power(u, a) * power(v, b);
            if a > 0 {
                out[1] += x * a as f64 * power(u, a - 1) * power(v, b);
            }
            if b > 0 {
                out[2] += x * b as f64 * power(u, a) * power(v, b - 1);
            }
        }
    }
    out
}

/// The monomial coefficients of the quartics taking `values[primal_index(4, i, j)]` at
/// `(i/4, j/4)`: the Vandermonde system of the principal lattice (unisolvent for quartics),
/// by Gaussian elimination with partial pivoting; `None` if it is singular.
fn interpolate(values: &[[f64; POINTS]]) -> Option<Coefficients> {
    let mut a = [[0.0f64; MONOMIALS]; MONOMIALS];
    let mut rhs = [[0.0f64; POINTS]; MONOMIALS];
    for j in 0..=DEGREE {
        for i in 0..=DEGREE - j {
            let p = primal_index(DEGREE as u32, i as u32, j as u32);
            let (u, v) = (i as f64 / 4.0, j as f64 / 4.0);
            for x in 0..=DEGREE {
                for y in 0..=DEGREE - x {
                    a[p][monomial(x, y)] = u.powi(x as i32) * v.powi(y as i32);
                }
            }
            rhs[p] = *values.get(p)?;
        }
    }
    for col in 0..MONOMIALS {
        let pivot =
            (col..MONOMIALS).max_by(|&r, &s| a[r][col].abs().total_cmp(&a[s][col].abs()))?;
        if a[pivot][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, pivot);
        rhs.swap(col, pivot);
        for row in 0..MONOMIALS {
            if row == col {
                continue;
            }
            let factor = a[row][col] / a[col][col];
            if factor == 0.0 {
                continue;
            }
            let (pivot_row, pivot_rhs) = (a[col], rhs[col]);
            for (x, p) in a[row].iter_mut().zip(&pivot_row).skip(col) {
                *x -= factor * p;
            }
            for (x, p) in rhs[row].iter_mut().zip(&pivot_rhs) {
                *x -= factor * p;
            }
        }
    }
    let mut out = [[0.0; POINTS]; MONOMIALS];
    for (m, row) in out.iter_mut().enumerate() {
        for l in 0..POINTS {
            row[l] = rhs[m][l] / a[m][m];
        }
    }
    Some(out)
}

/// One face's quartic, per coordinate: `c[a][b]` the coefficient of `u^a v^b` (zero for
/// `a + b > 4`).
type FaceQuartic = [[[f32; 3]; DEGREE + 1]; DEGREE + 1];

/// `sum_l C[., .][l] (P_l - P_0)` for every monomial at once (`[coordinate][monomial]`).
///
/// Not inlined for the reason of [`row_points`]: inlined into [`contract`], whose result is
/// read coordinate by coordinate, it was compiled to scalar arithmetic.
#[inline(never)]
fn monomial_sums(
    frame: &[[f32; MONOMIAL_LANES]; POINTS],
    local: &[[f32; 3]; POINTS],
) -> [[f32; MONOMIAL_LANES]; 3] {
    let mut sums = [[0.0f32; MONOMIAL_LANES]; 3];
    // `P_0 - P_0` is zero.
    for (w, p) in frame.iter().zip(local).skip(1) {
        for x in 0..3 {
            for m in 0..MONOMIAL_LANES {
                sums[x][m] += w[m] * p[x];
            }
        }
    }
    sums
}

/// The face's polynomial from its control points `local = P_l - P_0` (table order, relative
/// to `origin = P_0`) and the coefficients `frame` of its patch corner (`frame[l][monomial(a,
/// b)]`): `c_ab = sum_l C[a,b][l] (P_l - P_0)`, plus `P_0` in `c_00`; control point by control
/// point, all monomials at once (lanes).
fn contract(
    frame: &[[f32; MONOMIAL_LANES]; POINTS],
    local: &[[f32; 3]; POINTS],
    origin: [f32; 3],
) -> FaceQuartic {
    let sums = monomial_sums(frame, local);
    let mut c = [[[0.0f32; 3]; DEGREE + 1]; DEGREE + 1];
    for a in 0..=DEGREE {
        for b in 0..=DEGREE - a {
            for x in 0..3 {
                c[a][b][x] = sums[x][monomial(a, b)];
            }
        }
    }
    for x in 0..3 {
        c[0][0][x] += origin[x];
    }
    c
}

/// `LANES` rows of constant `v` (one per lane): the quartic in `u`, `r_a(v) = sum_b c_ab v^b`
/// (`p[a][x]`), and the `v`-derivative's restriction `s_a(v) = sum_b b c_ab v^(b-1)`
/// (`dv[a][x]`, cubic in `u`: `c_40` has no `v`).
struct RowChunk {
    p: [[[f32; LANES]; 3]; DEGREE + 1],
    dv: [[[f32; LANES]; 3]; DEGREE],
}

impl RowChunk {
    /// The rows at `v[k]`, by Horner's rule in `v` (not inlined, as [`row_points`]).
    #[inline(never)]
    fn new(c: &FaceQuartic, v: &[f32; LANES]) -> Self {
        let mut chunk = RowChunk {
            p: [[[0.0f32; LANES]; 3]; DEGREE + 1],
            dv: [[[0.0f32; LANES]; 3]; DEGREE],
        };
        // One call per power of `u`, each with its degree in `v` known, so that every Horner
        // loop is unrolled.
        chunk.rows::<0, 4>(c, v);
        chunk.rows::<1, 3>(c, v);
        chunk.rows::<2, 2>(c, v);
        chunk.rows::<3, 1>(c, v);
        chunk.rows::<4, 0>(c, v);
        chunk
    }

    /// `r_A(v)` and `s_A(v)`, `TOP = 4 - A` the degree of `r_A` in `v`.
    #[inline(always)]
    fn rows<const A: usize, const TOP: usize>(&mut self, c: &FaceQuartic, v: &[f32; LANES]) {
        for x in 0..3 {
            let mut r = [c[A][TOP][x]; LANES];
            for b in (0..TOP).rev() {
                for k in 0..LANES {
                    r[k] = r[k] * v[k] + c[A][b][x];
                }
            }
            self.p[A][x] = r;
            if let Some(dv) = self.dv.get_mut(A) {
                let mut s = [TOP as f32 * c[A][TOP][x]; LANES];
                for b in (1..TOP).rev() {
                    let w = b as f32 * c[A][b][x];
                    for k in 0..LANES {
                        s[k] = s[k] * v[k] + w;
                    }
                }
                dv[x] = s;
            }
        }
    }

    /// Position, d/du and d/dv of every row at its own parameter `u[k]` (lane `k`), by
    /// Horner's rule in `u`: `P = sum_a r_a u^a`, `P_u = sum_a (a+1) r_(a+1) u^a`,
    /// `P_v = sum_a s_a u^a`.
    #[inline(always)]
    // `x` indexes the row coefficients and the three quantities of `out` in step.
    #[allow(clippy::needless_range_loop)]
    fn point(&self, u: &[f32; LANES], out: &mut Sums) {
        for x in 0..3 {
            let mut q = self.p[DEGREE][x];
            for a in (0..DEGREE).rev() {
                for k in 0..LANES {
                    q[k] = q[k] * u[k] + self.p[a][x][k];
                }
            }
            out[0][x] = q;
            // The u-derivative's coefficients (a + 1) r_(a+1), made where they are used.
            let du = |a: usize, k: usize| (a + 1) as f32 * self.p[a + 1][x][k];
            let mut q: [f32; LANES] = std::array::from_fn(|k| du(DEGREE - 1, k));
            let mut r = self.dv[DEGREE - 1][x];
            for a in (0..DEGREE - 1).rev() {
                for k in 0..LANES {
                    q[k] = q[k] * u[k] + du(a, k);
                    r[k] = r[k] * u[k] + self.dv[a][x][k];
                }
            }
            out[1][x] = q;
            out[2][x] = r;
        }
    }
}

/// Position, d/du and d/dv of `LANES` points: `[quantity][coordinate][lane]`.
type Sums = [[[f32; LANES]; 3]; 3];

/// Where a row's points go: `count` points `u = params[first + 3t]`, written to
/// `positions[at + stride t]`.
#[derive(Clone, Copy, Debug, Default)]
struct RowLayout {
    first: usize,
    count: usize,
    at: usize,
    stride: usize,
}

/// Row `k` of constant `v = k / 3n` of a face at rate `n` ([`evaluate_face`]); `count` 0 for
/// the rows that hold no point of the face's own.
fn row_layout(n: usize, k: usize) -> RowLayout {
    let j = k / 3;
    if k >= 3 * n || j >= n {
        return RowLayout::default();
    }
    // Face row j starts at dual_index(n, 0, j, false) = j (2n - j).
    let start = j * (2 * n - j);
    let (first, count, at, stride) = match k % 3 {
        1 => (1, n - j, start, 2),
        2 => (2, n - j - 1, start + 1, 2),
        // Interior points of row j >= 1 follow those of rows 1..j.
        _ if j >= 1 && j + 1 < n => (3, n - j - 1, n * n + (j - 1) * (n - 1) - (j - 1) * j / 2, 1),
        _ => (0, 0, 0, 0),
    };
    RowLayout {
        first,
        count,
        at,
        stride,
    }
}

/// The points `t = 0..count` of the rows of `chunk` (one per lane; the `t`-th at `u[t]`).
///
/// Why a function of its own, not inlined: where the sums are transposed into points right
/// after (`[x, y, z]` a point), the compiler's vectorizer groups the arithmetic by coordinate
/// instead of by lane, shuffling every step; made apart and stored whole, each step is one
/// vector operation for the four rows.
#[inline(never)]
fn row_points(chunk: &RowChunk, u: &[[f32; LANES]], out: &mut [Sums]) {
    for (out, u) in out.iter_mut().zip(u) {
        chunk.point(u, out);
    }
}

/// Every point of a regular face at rate `n` in the face's own order (its dual points, then its
/// interior primal points, [`crate::tessellate::triangle_dual_grid`]): `params[k] = k / 3n`,
/// `k = 0..=3n`.
///
/// Rows of constant `v` are `v = k / 3n`: `k = 3j + 1` holds the ups of face row `j`
/// (`up(i, j)` at `u = (3i+1)/3n`), `3j + 2` its downs (`(3i+2)/3n`; ups and downs interleave
/// in the output, `up, down, .., up`), `3j` the interior primal points `(i/n, j/n)`, `i >= 1`.
/// The rows' polynomials are made `LANES` at a time (`LANES` consecutive rows, one a lane), and
/// their points too: the `t`-th point of every row of the chunk together, each lane at its own
/// `u` (the rows of a chunk differ in length by at most two points, so few lanes idle).
/// `local` holds the control points relative to the first, `origin` ([`contract`]).
pub(crate) fn evaluate_face(
    frame: &[[f32; MONOMIAL_LANES]; POINTS],
    local: &[[f32; 3]; POINTS],
    origin: [f32; 3],
    n: usize,
    params: &[f32],
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let c = contract(frame, local, origin);
    // The points of a chunk's rows are made BLOCK at a time (buffers small enough to cost
    // nothing to clear per face).
    let mut u = [[0.0f32; LANES]; BLOCK];
    let mut sums = [[[[0.0f32; LANES]; 3]; 3]; BLOCK];
    let mut k0 = 1;
    while k0 < 3 * n {
        let v: [f32; LANES] = std::array::from_fn(|k| params[(k0 + k).min(3 * n)]);
        let chunk = RowChunk::new(&c, &v);
        let rows: [RowLayout; LANES] = std::array::from_fn(|k| row_layout(n, k0 + k));
        let longest = rows.iter().map(|r| r.count).max().unwrap_or(0);
        for t0 in (0..longest).step_by(BLOCK) {
            let m = BLOCK.min(longest - t0);
            for (t, u) in (t0..).zip(&mut u[..m]) {
                // A shorter row repeats its last parameter (evaluated, not written).
                *u = rows.map(|r| params[r.first + 3 * t.min(r.count.saturating_sub(1))]);
            }
            row_points(&chunk, &u[..m], &mut sums[..m]);
            // Where point t of every row goes, advanced by the rows' strides.
            let mut at = rows.map(|r| r.at + r.stride * t0);
            for (t, [p, du, dv]) in (t0..).zip(&sums[..m]) {
                let normal = unit_cross(*du, *dv);
                for k in 0..LANES {
                    if t < rows[k].count {
                        positions[at[k]] = [p[0][k], p[1][k], p[2][k]];
                        normals[at[k]] = normal[k];
                    }
                    at[k] += rows[k].stride;
                }
            }
        }
        k0 += LANES;
    }
}

/// Points of every row of a chunk made by one call of [`row_points`].
const BLOCK: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monomials_are_numbered_densely() {
        let mut at = 0;
        for a in 0..=DEGREE {
            for b in 0..=DEGREE - a {
                assert_eq!(monomial(a, b), at);
                at += 1;
            }
        }
        assert_eq!(at, MONOMIALS);
    }

    /// The polynomials are the closed form's weights at points off the interpolation lattice,
    /// derivatives included (`schemes::loop_regular`, exact), in every corner's rotation.
    #[test]
    fn the_quartics_are_the_closed_form_at_any_point() {
        let basis = QuarticBasis::get().expect("the closed form interpolates");
        let patch = RegularLoopPatch::new();
        let net: Vec<usize> = TABLE_LAYOUT
            .iter()
            .map(|p| {
                REGULAR_NET
                    .iter()
                    .position(|q| q == p)
                    .expect("a net point")
            })
            .collect();
        for (i, j) in [(1, 1), (3, 5), (7, 2), (0, 10), (4, 4)] {
            let r = |x: i64| BigRational::new(x.into(), 13.into());
            let (u, v) = (r(i), r(j));
            let exact = [
                RegularDerivative::Position,
                RegularDerivative::U,
                RegularDerivative::V,
            ]
            .map(|what| patch.weights(&u, &v, what));
            for l in 0..POINTS {
                let got = weight(&basis.by_corner[0], l, i as f64 / 13.0, j as f64 / 13.0);
                for k in 0..3 {
                    let want = exact[k][net[l]].to_f64().expect("finite");
                    assert!((got[k] - want).abs() < 1e-12, "({i}, {j}) l {l} k {k}");
                }
            }
            // Corner r: the face point (u, v) is the patch point (w_{r+1}, w_{r+2}).
            for corner in 1..3 {
                let (uf, vf) = (i as f64 / 13.0, j as f64 / 13.0);
                let w = [1.0 - uf - vf, uf, vf];
                let (pu, pv) = (w[(corner + 1) % 3], w[(corner + 2) % 3]);
                for l in 0..POINTS {
                    let face = weight(&basis.by_corner[corner], l, uf, vf)[0];
                    let patch = weight(&basis.by_corner[0], l, pu, pv)[0];
                    assert!((face - patch).abs() < 1e-12, "corner {corner}");
                }
            }
        }
    }
}
