//! Exact evaluation of Loop surfaces: the limit position and the first derivatives `d/du`,
//! `d/dv` of one input triangle at any rational `(u, v)` (barycentric, DESIGN.md: `(0,0)` at the
//! triangle's first vertex, `(1,0)` at its second, `(0,1)` at its third), correct to f64
//! rounding — except the tangent masks at a vertex itself, which are irrational (f64).
//!
//! An independent route to the numbers the Loop table gives (the tests compare them at every
//! tessellation vertex): no stencil system is solved here.
//!
//! 1. **Isolation** as the tessellator does it ([`isolate_loop`]): at most one Loop step. The
//!    refined control points are recomputed exactly (rationals) from the input's f64 positions,
//!    which are exact binary rationals, with the same rules (the one rule function
//!    [`crate::scheme::loop_scheme::refine::loop_stencil`], over `BigRational`); `(u, v)`
//!    descends into the child that holds it (the inverse of
//!    [`crate::scheme::triangle::split::child_to_parent`]).
//! 2. **Patch** of that triangle ([`crate::scheme::triangle::patch`]): control points in the table's
//!    layout (phantoms `a + b - c` included, exactly), the patch parameters
//!    `(u', v') = (w_{r+1}, w_{r+2})` of the child's barycentric weights for a patch at corner
//!    `r`.
//! 3. **Substitution** (Schaefer–Warren section 5.2) with the exact local subdivision matrix
//!    `A` and sub-triangle rows `R_b` of `schemes::triangle_local` (interior or boundary): double
//!    `x = (u', v')` `k` times until `u' + v' > 1/2`, then
//!    `S(x) = w(y) R_b A^k P`, `d/du S(x) = 2^(k+1) (d/du w)(y) R_b A^k P`, `y = 2^(k+1) x`
//!    located in sub-triangle `b`, `w` the regular patch's twelve weights in closed form
//!    ([`schemes::loop_regular`]: two subdivision steps, the limit mask, quartic interpolation).
//!    The middle ("down") sub-triangle is the point reflection of an up triangle, under which
//!    the box spline is symmetric.
//! 4. **At the vertex** (`x = 0`): the limit mask in closed form (interior
//!    `(1 - v chi) V + chi sum E_i`, `chi = 1 / (3 / (8 beta) + v)`; boundary
//!    `(E_0 + 4 V + E_k) / 6`) and the tables' tangent masks (`stencilgen`'s normalization on
//!    the planar reference net): interior `du = (2/v) sum cos(t_i) E_i`,
//!    `dv = (2/v) sum cos(t_i - t_1) E_i`, `t_i = 2 pi i / v`; boundary: the span of the
//!    boundary tangent `E_k - E_0` and the left eigenvector of `A`'s 1-ring block for
//!    `mu_1 = 3/8 + cos(pi/k)/4` (`1/4` at `k = 1`), mapped onto the half-disk net.
//! 5. **Chain rule** back through the rotation and the child map (integer matrices).

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use schemes::loop_regular::{RegularDerivative, RegularLoopPatch, REGULAR_NET};
use schemes::tangent_frame::frame_masks;
use schemes::triangle_local::{TriangleLocalMatrices, SUB_TRIANGLES};
use schemes::TriangleScheme;

use crate::eval::exact_eval::{null_vectors, LimitPoint};
use crate::mesh::topology::Mesh;
use crate::scheme::loop_scheme::isolate::isolate_loop;
use crate::scheme::loop_scheme::refine::{loop_beta, loop_stencil};
use crate::scheme::patch::PatchKind;
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::isolation::TriangleIsolation;
use crate::RuntimeError;

type Point = [BigRational; 3];

/// Position, `d/du`, `d/dv` (patch parameters).
type Derivatives = ([f64; 3], [f64; 3], [f64; 3]);

fn ratio(p: i64, q: i64) -> BigRational {
    BigRational::new(BigInt::from(p), BigInt::from(q))
}

fn exact(p: [f64; 3]) -> Result<Point, RuntimeError> {
    let mut out: Point = std::array::from_fn(|_| BigRational::zero());
    for (o, x) in out.iter_mut().zip(p) {
        *o = BigRational::from_float(x).ok_or_else(|| {
            RuntimeError::Unsupported(format!("a control point coordinate {x} is not finite"))
        })?;
    }
    Ok(out)
}

fn combine(terms: &[(&Point, BigRational)]) -> Point {
    std::array::from_fn(|c| terms.iter().map(|(p, w)| &p[c] * w).sum())
}

fn to_f64(p: &Point) -> [f64; 3] {
    std::array::from_fn(|c| p[c].to_f64().unwrap_or(f64::NAN))
}

/// Evaluates Loop surfaces of one input mesh exactly; isolation and the exact refined control
/// points are computed once.
#[derive(Debug)]
pub struct LoopExactEvaluator {
    input_faces: usize,
    iso: TriangleIsolation,
    /// Exact control points of the isolated mesh, then its phantoms.
    control: Vec<Point>,
    /// The local matrices of every patch kind the isolated mesh has.
    matrices: HashMap<PatchKind, TriangleLocalMatrices>,
    regular: RegularLoopPatch,
}

impl LoopExactEvaluator {
    /// Isolate `mesh` (triangles only) and compute its refined control points exactly.
    pub fn new(mesh: &Mesh) -> Result<Self, RuntimeError> {
        let iso = isolate_loop(mesh)?;
        let mut control = mesh
            .positions
            .iter()
            .map(|&p| exact(p))
            .collect::<Result<Vec<_>, _>>()?;
        if iso.steps == 1 {
            // The rules loop_refine positioned the isolated mesh with, in rationals.
            control = apply_exactly(&loop_stencil::<BigRational>(mesh)?, &control);
        }
        for &[a, b, c] in &iso.phantoms.definitions {
            let (a, b, c) = (
                &control[a as usize],
                &control[b as usize],
                &control[c as usize],
            );
            let p: Point = std::array::from_fn(|i| &a[i] + &b[i] - &c[i]);
            control.push(p);
        }
        let scheme = TriangleScheme::by_name("loop").ok_or_else(|| {
            RuntimeError::Unsupported("the scheme catalogue has no `loop`".to_owned())
        })?;
        let mut matrices = HashMap::new();
        for patch in &iso.patches {
            if matrices.contains_key(&patch.kind) {
                continue;
            }
            let m = if patch.kind.boundary {
                TriangleLocalMatrices::boundary(&scheme, patch.kind.faces, patch.kind.sector)
            } else {
                TriangleLocalMatrices::new(&scheme, patch.kind.faces)
            }
            .map_err(|e| RuntimeError::Unsupported(e.to_string()))?;
            matrices.insert(patch.kind, m);
        }
        Ok(LoopExactEvaluator {
            input_faces: mesh.faces(),
            iso,
            control,
            matrices,
            regular: RegularLoopPatch::new(),
        })
    }

    /// Position and derivatives of input triangle `face` at `(u, v)`, `u, v >= 0`,
    /// `u + v <= 1`.
    pub fn evaluate(
        &self,
        face: usize,
        u: &BigRational,
        v: &BigRational,
    ) -> Result<LimitPoint, RuntimeError> {
        if face >= self.input_faces {
            return Err(RuntimeError::InvalidParameter {
                name: format!("--face {face}"),
                reason: format!("the mesh has {} triangles", self.input_faces),
            });
        }
        if u.is_negative() || v.is_negative() || u + v > BigRational::one() {
            return Err(RuntimeError::InvalidParameter {
                name: format!("--uv {u},{v}"),
                reason: "a triangle's barycentric parameters satisfy u, v >= 0, u + v <= 1"
                    .to_owned(),
            });
        }
        // Descend into the child holding (u, v); `jacobian` maps input (d/du, d/dv) rows.
        let (mut f, mut s, mut t) = (face, u.clone(), v.clone());
        let mut jacobian = [[1i64, 0], [0, 1]];
        if self.iso.steps == 1 {
            let (child, cs, ct, j) = child_of(&s, &t);
            // Triangle f's children are 4f + c (crate::scheme::loop_scheme::refine).
            f = 4 * face + usize::from(child);
            if self.iso.origin.get(f) != Some(&(face as u32)) || self.iso.child[f][0] != child {
                return Err(RuntimeError::Unsupported(format!(
                    "triangle {face}'s child {child} is not where the refinement puts it"
                )));
            }
            (s, t, jacobian) = (cs, ct, j);
        }
        let patch = &self.iso.patches[f];
        // Patch parameters: (w_{r+1}, w_{r+2}) of w = (1 - s - t, s, t).
        let w = [BigRational::one() - &s - &t, s, t];
        let r = patch.corner;
        let (pu, pv) = (w[(r + 1) % 3].clone(), w[(r + 2) % 3].clone());
        let rotation = match r {
            0 => [[1, 0], [0, 1]],
            1 => [[0, 1], [-1, -1]],
            _ => [[-1, -1], [1, 0]],
        };
        // d(patch)/d(input) = rotation * jacobian; rows: d/du' and d/dv' in input terms.
        let chain = mul(rotation, jacobian);
        let matrices = self.matrices.get(&patch.kind).ok_or_else(|| {
            RuntimeError::Unsupported(format!("no local matrices for {:?}", patch.kind))
        })?;
        let points: Vec<&Point> = patch
            .points
            .iter()
            .map(|&c| &self.control[c as usize])
            .collect();
        let (position, du, dv) = if pu.is_zero() && pv.is_zero() {
            at_vertex(matrices, &points)?
        } else {
            self.substitute(matrices, &points, &pu, &pv)
        };
        // d/du_input = chain[0][0] du' + chain[1][0] dv', d/dv_input likewise with column 1.
        let back = |col: usize| -> [f64; 3] {
            std::array::from_fn(|c| chain[0][col] as f64 * du[c] + chain[1][col] as f64 * dv[c])
        };
        Ok(LimitPoint {
            position,
            du: back(0),
            dv: back(1),
        })
    }

    /// Substitution away from the vertex (module docs, step 3).
    fn substitute(
        &self,
        matrices: &TriangleLocalMatrices,
        points: &[&Point],
        u: &BigRational,
        v: &BigRational,
    ) -> Derivatives {
        let half = ratio(1, 2);
        let two = ratio(2, 1);
        let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
        while &x + &y <= half {
            x *= &two;
            y *= &two;
            k += 1;
        }
        // Level-1 point y = 2x in sector coordinates, its sub-triangle and local coordinates.
        let (y1, y2) = (&x * &two, &y * &two);
        let one = BigRational::one();
        let b = if y1 >= one {
            0
        } else if y2 >= one {
            2
        } else {
            1
        };
        let sub = &matrices.sub_triangles[b];
        let corner = SUB_TRIANGLES[b][0];
        // Up triangles are REGULAR_NET translated; the down one is its point reflection
        // through (1/2, 1/2) (p -> (1,1) - p), where derivatives change sign.
        let down = b == 1;
        let local = if down {
            (&one - &y1, &one - &y2)
        } else {
            (&y1 - ratio(corner.0, 1), &y2 - ratio(corner.1, 1))
        };
        let net_of = |q: (i64, i64)| {
            if down {
                (1 - q.0, 1 - q.1)
            } else {
                (q.0 - corner.0, q.1 - corner.1)
            }
        };
        let sign: i64 = if down { -1 } else { 1 };
        let size = matrices.size();
        let row = |what: RegularDerivative| -> Vec<BigRational> {
            let w = self.regular.weights(&local.0, &local.1, what);
            let mut out = vec![BigRational::zero(); size];
            for (&q, r) in sub.points.iter().zip(&sub.rows) {
                let Some(i) = REGULAR_NET.iter().position(|&p| p == net_of(q)) else {
                    continue;
                };
                if w[i].is_zero() {
                    continue;
                }
                for (o, a) in out.iter_mut().zip(r) {
                    if !a.is_zero() {
                        *o += &w[i] * a;
                    }
                }
            }
            // phi(x) = phi(2x) A, k times.
            for _ in 0..k {
                out = (0..size)
                    .map(|j| {
                        out.iter()
                            .zip(&matrices.a)
                            .filter(|(w, a)| !w.is_zero() && !a[j].is_zero())
                            .map(|(w, a)| w * &a[j])
                            .sum()
                    })
                    .collect();
            }
            out
        };
        let apply = |weights: &[BigRational], factor: &BigRational| -> [f64; 3] {
            let terms: Vec<(&Point, BigRational)> = points
                .iter()
                .zip(weights)
                .filter(|(_, w)| !w.is_zero())
                .map(|(p, w)| (*p, w * factor))
                .collect();
            to_f64(&combine(&terms))
        };
        // Each halving and the step to level 1 double a derivative.
        let factor = BigRational::from_integer(BigInt::from(sign) << (k + 1));
        (
            apply(&row(RegularDerivative::Position), &one),
            apply(&row(RegularDerivative::U), &factor),
            apply(&row(RegularDerivative::V), &factor),
        )
    }
}

/// `a * b` for 2 x 2 integer matrices.
fn mul(a: [[i64; 2]; 2], b: [[i64; 2]; 2]) -> [[i64; 2]; 2] {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

/// The child of a Loop step holding parent point `(u, v)`, the child's own `(s, t)`, and
/// `d(s, t)/d(u, v)` (the inverse of [`crate::scheme::triangle::split::child_to_parent`]).
fn child_of(u: &BigRational, v: &BigRational) -> (u8, BigRational, BigRational, [[i64; 2]; 2]) {
    let (one, two, half) = (BigRational::one(), ratio(2, 1), ratio(1, 2));
    let w0 = &one - u - v;
    if w0 >= half {
        (0, u * &two, v * &two, [[2, 0], [0, 2]])
    } else if *u >= half {
        (1, v * &two, &w0 * &two, [[0, 2], [-2, -2]])
    } else if *v >= half {
        (2, &w0 * &two, u * &two, [[-2, -2], [2, 0]])
    } else {
        (3, (u + v) * &two - &one, &one - u * &two, [[2, 2], [-2, 0]])
    }
}

/// `stencil` applied to exact points: row `i` gives `sum w p_j` over its entries.
fn apply_exactly(stencil: &Stencil<BigRational>, p: &[Point]) -> Vec<Point> {
    (0..stencil.rows())
        .map(|i| {
            let (js, ws) = stencil.row(i);
            std::array::from_fn(|c| js.iter().zip(ws).map(|(&j, w)| w * &p[j as usize][c]).sum())
        })
        .collect()
}

/// Limit position (exact) and tangent masks (f64) at the patch vertex (module docs, step 4).
fn at_vertex(
    matrices: &TriangleLocalMatrices,
    points: &[&Point],
) -> Result<Derivatives, RuntimeError> {
    use schemes::triangle_local::TriangleNeighbourhood;
    let f = |p: &Point| to_f64(p);
    let (position, du, dv) = match matrices.neighbourhood {
        TriangleNeighbourhood::Interior { valence } => {
            let v = i64::from(valence);
            let beta: BigRational = loop_beta(valence as usize);
            let chi =
                BigRational::one() / (ratio(3, 8) / &beta + BigRational::from_integer(v.into()));
            let mut terms = vec![(
                points[0],
                BigRational::one() - &chi * BigRational::from_integer(v.into()),
            )];
            terms.extend((1..=valence as usize).map(|i| (points[i], chi.clone())));
            let angle = |i: usize| 2.0 * std::f64::consts::PI * i as f64 / f64::from(valence);
            let mask = |shift: usize| -> Vec<f64> {
                let mut m = vec![0.0; 1 + valence as usize];
                for i in 0..valence as usize {
                    m[1 + i] = 2.0 / f64::from(valence) * (angle(i) - angle(shift)).cos();
                }
                m
            };
            (combine(&terms), mask(0), mask(1))
        }
        TriangleNeighbourhood::Boundary { faces, sector } => {
            let k = faces as usize;
            let terms = [
                (points[1], ratio(1, 6)),
                (points[0], ratio(2, 3)),
                (points[1 + k], ratio(1, 6)),
            ];
            let (du, dv) = boundary_tangents(matrices, k, sector as usize)?;
            (combine(&terms), du, dv)
        }
    };
    let apply = |mask: &[f64]| -> [f64; 3] {
        let mut out = [0.0; 3];
        for (w, p) in mask.iter().zip(points) {
            let p = f(p);
            for c in 0..3 {
                out[c] += w * p[c];
            }
        }
        out
    };
    Ok((f(&position), apply(&du), apply(&dv)))
}

/// The tangent masks at a boundary vertex over `V, E_0..E_k` (module docs, step 4).
fn boundary_tangents(
    matrices: &TriangleLocalMatrices,
    k: usize,
    sector: usize,
) -> Result<(Vec<f64>, Vec<f64>), RuntimeError> {
    let ring = k + 2;
    let a: Vec<Vec<f64>> = (0..ring)
        .map(|i| {
            (0..ring)
                .map(|j| matrices.a[i][j].to_f64().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let mu = if k == 1 {
        0.25
    } else {
        0.375 + 0.25 * (std::f64::consts::PI / k as f64).cos()
    };
    // Left eigenvectors: null vectors of (A^T - mu I); two of them at k = 3 (t is one).
    let count = if k == 3 { 2 } else { 1 };
    let system: Vec<Vec<f64>> = (0..ring)
        .map(|j| {
            (0..ring)
                .map(|i| a[i][j] - if i == j { mu } else { 0.0 })
                .collect()
        })
        .collect();
    let mut t = vec![0.0; ring];
    t[1] = -1.0;
    t[1 + k] = 1.0;
    let t_norm2 = 2.0;
    let norm2 = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
    let c = null_vectors(system, count)
        .into_iter()
        .map(|w| {
            let along: f64 = w.iter().zip(&t).map(|(a, b)| a * b).sum::<f64>() / t_norm2;
            w.iter()
                .zip(&t)
                .map(|(a, b)| a - along * b)
                .collect::<Vec<f64>>()
        })
        .max_by(|x, y| norm2(x).total_cmp(&norm2(y)))
        .filter(|c| norm2(c) > 1e-12)
        .ok_or_else(|| {
            RuntimeError::Unsupported(format!(
                "no cross-boundary eigenvector at a boundary vertex with {k} triangles"
            ))
        })?;
    let step = std::f64::consts::PI / k.max(2) as f64;
    let edge = |i: usize| [(step * i as f64).cos(), (step * i as f64).sin()];
    let net: Vec<(usize, [f64; 2])> = (0..=k).map(|i| (1 + i, edge(i))).collect();
    let [du, dv] = frame_masks(
        [&t, &c],
        &net,
        [1.0, 1.0],
        [edge(sector), edge(sector + 1)],
        t.len(),
    )
    .ok_or_else(|| {
        RuntimeError::Unsupported(format!(
            "the tangent and cross modes at a boundary vertex with {k} triangles do not span the reference net's plane"
        ))
    })?;
    Ok((du, dv))
}
