//! f64 solution of an orbit by a rank-revealing least-squares solve (SVD).
//!
//! For an orbit with a cycle, unlike the exact path, this one assembles the orbit's whole
//! system, every relation `x_r - A_r x_{next(r)} = c_r` plus every normalization equation of its
//! classes, and solves it in the least-squares sense through the singular value decomposition:
//! the numerical rank tells whether the solution is unique, and the residual whether the
//! system is consistent. Substituting along a long residue tree, as the exact path does, would
//! amplify rounding by up to `2^d` for tangents at depth `d` (each derivative relation doubles
//! its weights). An orbit that ends in a terminal class (a point next to an extraordinary
//! vertex whose doubles leave the patch after a few steps) is triangular with known values at
//! its root and short trees: it is solved by substitution.

use nalgebra::{DMatrix, DVector};

use crate::orbit_block::{BlockFailure, LocalNormalization, OrbitBlock};
use crate::rational::rational_to_f64;

/// Largest residual an f64 solution may leave in any equation and still count as a solution.
pub const FLOAT_TOLERANCE: f64 = 1e-9;

/// Singular values below this fraction of the largest count as zero.
const RANK_TOLERANCE: f64 = 1e-11;

/// At most this many passes of iterative refinement.
const REFINEMENT_PASSES: usize = 4;

/// Solve the orbit in f64; values per step, in the block's local order.
pub fn solve_orbit(block: &OrbitBlock<f64>) -> Result<Vec<Vec<f64>>, BlockFailure> {
    if block.cycle_len == 0 {
        return Ok(substitute(block));
    }
    let len = block.steps.len();
    let mut start = vec![0usize; len + 1];
    for j in 0..len {
        start[j + 1] = start[j] + block.steps[j].len();
    }
    let unknowns = start[len];
    let equations = unknowns + block.normalization.len();
    let mut a = DMatrix::<f64>::zeros(equations, unknowns);
    let mut b = DVector::<f64>::zeros(equations);
    for j in 0..len {
        for (i, relation) in block.relations[j].iter().enumerate() {
            let e = start[j] + i;
            a[(e, start[j] + i)] += 1.0;
            b[e] = relation.constant;
            if let Some(next) = block.next[j] {
                for (l, w) in &relation.terms {
                    a[(e, start[next] + l)] -= rational_to_f64(w);
                }
            }
        }
    }
    for (e, LocalNormalization { step, terms, rhs }) in block.normalization.iter().enumerate() {
        let e = unknowns + e;
        for (l, c) in terms {
            a[(e, start[*step] + l)] += rational_to_f64(c);
        }
        b[e] = rational_to_f64(rhs);
    }
    let svd = a.clone().svd(true, true);
    let largest = svd.singular_values.max();
    let eps = RANK_TOLERANCE * largest;
    let rank = svd.rank(eps);
    if rank < unknowns {
        return Err(BlockFailure::NotUnique { rank, unknowns });
    }
    let solve = |rhs: &DVector<f64>| {
        svd.solve(rhs, eps).map_err(|e| BlockFailure::Inconsistent {
            detail: format!("SVD solve failed: {e}"),
        })
    };
    let mut x = solve(&b)?;
    let mut residual = (&a * &x - &b).amax();
    // nalgebra's bidiagonal QR iteration stops at a loose criterion: on well-conditioned blocks
    // (singular values in [0.1, 10]) its factors can be off by 1e-10. Iterative refinement
    // with the same factors removes that: each pass multiplies the error by about
    // cond(A) * (factorization error).
    for _ in 0..REFINEMENT_PASSES {
        let correction = solve(&(&b - &a * &x))?;
        let refined = &x + correction;
        let refined_residual = (&a * &refined - &b).amax();
        if refined_residual >= residual {
            break;
        }
        x = refined;
        residual = refined_residual;
    }
    if residual > FLOAT_TOLERANCE {
        return Err(BlockFailure::Inconsistent {
            detail: format!("least-squares residual {residual:e}"),
        });
    }
    Ok((0..len)
        .map(|j| x.as_slice()[start[j]..start[j + 1]].to_vec())
        .collect())
}

/// Values of a terminal orbit, step by step from its root.
fn substitute(block: &OrbitBlock<f64>) -> Vec<Vec<f64>> {
    let mut values: Vec<Vec<f64>> = Vec::with_capacity(block.steps.len());
    for (j, relations) in block.relations.iter().enumerate() {
        let step = relations
            .iter()
            .map(|r| {
                let known = block.next[j].map_or(&[][..], |s| values[s].as_slice());
                r.terms.iter().fold(r.constant, |acc, (l, w)| {
                    acc + rational_to_f64(w) * known[*l]
                })
            })
            .collect();
        values.push(step);
    }
    values
}
