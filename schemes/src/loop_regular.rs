//! The regular Loop patch in closed form, exactly: the weights of its twelve control points at
//! any rational point, and their first derivatives.
//!
//! A triangle whose three corners have valence 6 is a piece of the quartic box spline
//! (Loop 1987; Schaefer–Warren section 5.1): on it each of the twelve basis functions of the
//! corners' 1-rings is one quartic polynomial. A quartic on a triangle is fixed by its values at
//! the 15 points of the principal lattice of degree 4, `(i/4, j/4)`, `i + j <= 4`, and those
//! are limit positions of vertices of the twice-subdivided net, which Loop's rules give exactly:
//! two steps of the regular rules (vertex `5/8, 1/16 x 6`, edge `3/8, 3/8, 1/8, 1/8`) and the
//! valence-6 limit mask `1/2 V + 1/12 sum E_i` (`chi = 1 / (3 / (8 beta) + v)`, `beta = 1/16`).
//! Interpolating them with the Lagrange basis of that lattice,
//! `L_ijk(l1, l2, l3) = l_i(l1) l_j(l2) l_k(l3)`, `l_i(t) = prod_{m < i} (4t - m) / (m + 1)`,
//! evaluates the patch at any point, exactly. Nothing here solves a system or evaluates a box
//! spline from its definition: the stencil generator (scaling relation) and the test oracle
//! (box-spline recurrence) are the independent methods this agrees with.
//!
//! Coordinates are the skew lattice coordinates of [`crate::triangle`]; the triangle is
//! `(0,0), (1,0), (0,1)` with barycentric `(u, v)` as everywhere in the project.

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::{One, Zero};

use crate::triangle::NEIGHBOURS;

/// The twelve control points of the triangle `(0,0), (1,0), (0,1)`: the union of its corners'
/// 1-rings, sorted (the order of `triangle_local::SubTriangle::points` for an up triangle at
/// the origin).
pub const REGULAR_NET: [(i64, i64); 12] = [
    (-1, 0),
    (-1, 1),
    (-1, 2),
    (0, -1),
    (0, 0),
    (0, 1),
    (0, 2),
    (1, -1),
    (1, 0),
    (1, 1),
    (2, -1),
    (2, 0),
];

/// The degree of the pieces, and so the rate of the interpolation lattice.
const DEGREE: i64 = 4;

fn ratio(p: i64, q: i64) -> BigRational {
    BigRational::new(p.into(), q.into())
}

/// Values of the twelve basis functions at the 15 lattice points `(i/4, j/4)`, `i + j <= 4`
/// (`[point][control point]`), from two subdivision steps and the limit mask.
fn lattice_values() -> Vec<[BigRational; 12]> {
    // Level-0 values: basis function c is 1 at REGULAR_NET[c], 0 everywhere else (the other
    // control points do not reach this triangle, so zero is as good as any value).
    let level0 = |p: (i64, i64)| -> [BigRational; 12] {
        std::array::from_fn(|c| {
            if REGULAR_NET[c] == p {
                BigRational::one()
            } else {
                BigRational::zero()
            }
        })
    };
    type Level = HashMap<(i64, i64), [BigRational; 12]>;
    let combine = |terms: &[(&[BigRational; 12], BigRational)]| -> [BigRational; 12] {
        std::array::from_fn(|c| terms.iter().map(|(v, w)| &v[c] * w).sum())
    };
    // One regular step: the value at level-(l+1) point y from level-l values `at`. The window
    // only has to hold the 1-rings of what the next step reads.
    let step = |at: &dyn Fn((i64, i64)) -> [BigRational; 12], window: i64| -> Level {
        let mut out = Level::new();
        for y1 in -window..=window + DEGREE {
            for y2 in -window..=window + DEGREE {
                let value = match (y1.rem_euclid(2), y2.rem_euclid(2)) {
                    (0, 0) => {
                        let p = (y1 / 2, y2 / 2);
                        let centre = at(p);
                        let ring: Vec<_> = NEIGHBOURS
                            .iter()
                            .map(|&(a, b)| at((p.0 + a, p.1 + b)))
                            .collect();
                        let mut terms = vec![(&centre, ratio(5, 8))];
                        terms.extend(ring.iter().map(|r| (r, ratio(1, 16))));
                        combine(&terms)
                    }
                    parity => {
                        // The edge from p towards p + e; the opposite vertices p + f, p + g.
                        let (p, e, f, g) = match parity {
                            (1, 0) => (((y1 - 1) / 2, y2 / 2), (1, 0), (0, 1), (1, -1)),
                            (0, 1) => ((y1 / 2, (y2 - 1) / 2), (0, 1), (1, 0), (-1, 1)),
                            _ => (((y1 - 1) / 2, (y2 + 1) / 2), (1, -1), (0, -1), (1, 0)),
                        };
                        let shift = |d: (i64, i64)| at((p.0 + d.0, p.1 + d.1));
                        let (a, b, c, d) = (at(p), shift(e), shift(f), shift(g));
                        combine(&[
                            (&a, ratio(3, 8)),
                            (&b, ratio(3, 8)),
                            (&c, ratio(1, 8)),
                            (&d, ratio(1, 8)),
                        ])
                    }
                };
                out.insert((y1, y2), value);
            }
        }
        out
    };
    let zero: [BigRational; 12] = std::array::from_fn(|_| BigRational::zero());
    let level1 = step(&level0, 3);
    let read1 = |p: (i64, i64)| level1.get(&p).cloned().unwrap_or_else(|| zero.clone());
    let level2 = step(&read1, 2);
    let read2 = |p: (i64, i64)| level2.get(&p).cloned().unwrap_or_else(|| zero.clone());
    let mut out = Vec::new();
    for j in 0..=DEGREE {
        for i in 0..=DEGREE - j {
            let centre = read2((i, j));
            let ring: Vec<_> = NEIGHBOURS
                .iter()
                .map(|&(a, b)| read2((i + a, j + b)))
                .collect();
            let mut terms = vec![(&centre, ratio(1, 2))];
            terms.extend(ring.iter().map(|r| (r, ratio(1, 12))));
            out.push(combine(&terms));
        }
    }
    out
}

/// What to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegularDerivative {
    /// The limit position.
    Position,
    /// `d/du` (along the lattice axis `(1, 0)`).
    U,
    /// `d/dv` (along `(0, 1)`).
    V,
}

/// Exact weights of the regular Loop patch's twelve control points ([`REGULAR_NET`]).
#[derive(Clone, Debug)]
pub struct RegularLoopPatch {
    /// `[lattice point (i, j), j outer][control point]`.
    values: Vec<[BigRational; 12]>,
}

impl Default for RegularLoopPatch {
    fn default() -> Self {
        Self::new()
    }
}

impl RegularLoopPatch {
    /// Subdivide twice and take limits (a few milliseconds, exact).
    pub fn new() -> Self {
        RegularLoopPatch {
            values: lattice_values(),
        }
    }

    /// The twelve weights (or their derivatives) at `(u, v)` of the triangle
    /// `(0,0), (1,0), (0,1)`. Points outside it get the polynomial's continuation (callers
    /// keep `u, v >= 0`, `u + v <= 1`).
    pub fn weights(
        &self,
        u: &BigRational,
        v: &BigRational,
        what: RegularDerivative,
    ) -> [BigRational; 12] {
        let lambda = [BigRational::one() - u - v, u.clone(), v.clone()];
        // l_i(t) and its derivative for i = 0..=4 at each barycentric coordinate.
        let four = ratio(DEGREE, 1);
        let factors: Vec<([BigRational; 5], [BigRational; 5])> = lambda
            .iter()
            .map(|t| {
                let mut value: [BigRational; 5] = std::array::from_fn(|_| BigRational::one());
                let mut slope: [BigRational; 5] = std::array::from_fn(|_| BigRational::zero());
                for i in 1..=DEGREE as usize {
                    let m = ratio(i as i64 - 1, 1);
                    let scale = ratio(1, i as i64);
                    let linear = (&four * t - &m) * &scale;
                    slope[i] = &slope[i - 1] * &linear + &value[i - 1] * &four * &scale;
                    value[i] = &value[i - 1] * &linear;
                }
                (value, slope)
            })
            .collect();
        let mut out: [BigRational; 12] = std::array::from_fn(|_| BigRational::zero());
        let mut point = 0;
        for j in 0..=DEGREE as usize {
            for i in 0..=DEGREE as usize - j {
                let k = DEGREE as usize - i - j;
                // The lattice point (i/4, j/4) has barycentric (k, i, j) / 4.
                let (f1, f2, f3) = (&factors[0], &factors[1], &factors[2]);
                let basis = match what {
                    RegularDerivative::Position => &f1.0[k] * &f2.0[i] * &f3.0[j],
                    // d/du moves l2 up and l1 down; d/dv moves l3 up and l1 down.
                    RegularDerivative::U => {
                        &f1.0[k] * &f2.1[i] * &f3.0[j] - &f1.1[k] * &f2.0[i] * &f3.0[j]
                    }
                    RegularDerivative::V => {
                        &f1.0[k] * &f2.0[i] * &f3.1[j] - &f1.1[k] * &f2.0[i] * &f3.0[j]
                    }
                };
                if !basis.is_zero() {
                    for (o, value) in out.iter_mut().zip(&self.values[point]) {
                        *o += value * &basis;
                    }
                }
                point += 1;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_of_unity_and_linear_precision() {
        // Loop reproduces linear functions: sum w = 1, sum w p = (u, v) (Loop's limit of a
        // planar lattice net is the plane itself).
        let patch = RegularLoopPatch::new();
        for (u, v) in [(0, 0), (1, 0), (0, 1), (1, 3), (2, 5), (7, 11)] {
            let (u, v) = (ratio(u, 13), ratio(v, 13));
            let w = patch.weights(&u, &v, RegularDerivative::Position);
            assert_eq!(w.iter().sum::<BigRational>(), BigRational::one());
            let x: BigRational = w
                .iter()
                .zip(REGULAR_NET)
                .map(|(w, p)| w * ratio(p.0, 1))
                .sum();
            let y: BigRational = w
                .iter()
                .zip(REGULAR_NET)
                .map(|(w, p)| w * ratio(p.1, 1))
                .sum();
            assert_eq!((x, y), (u.clone(), v.clone()));
            let du = patch.weights(&u, &v, RegularDerivative::U);
            let dv = patch.weights(&u, &v, RegularDerivative::V);
            assert!(du.iter().sum::<BigRational>().is_zero());
            let dx: BigRational = du
                .iter()
                .zip(REGULAR_NET)
                .map(|(w, p)| w * ratio(p.0, 1))
                .sum();
            let dy: BigRational = dv
                .iter()
                .zip(REGULAR_NET)
                .map(|(w, p)| w * ratio(p.1, 1))
                .sum();
            assert_eq!((dx, dy), (BigRational::one(), BigRational::one()));
        }
    }

    #[test]
    fn corner_is_the_valence_six_limit_mask() {
        let w = RegularLoopPatch::new().weights(
            &BigRational::zero(),
            &BigRational::zero(),
            RegularDerivative::Position,
        );
        for (weight, p) in w.iter().zip(REGULAR_NET) {
            let expected = match p {
                (0, 0) => ratio(1, 2),
                p if NEIGHBOURS.contains(&p) => ratio(1, 12),
                _ => BigRational::zero(),
            };
            assert_eq!(*weight, expected, "{p:?}");
        }
    }
}
