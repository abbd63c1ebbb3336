//! f64 solution of a residue cycle by a rank-revealing least-squares solve (SVD).
//!
//! Unlike the exact path, this one assembles the block's full system, every scaling relation
//! `x_j - A_j x_{j+1} = 0` of the cycle plus its normalization equations, and solves it in
//! the least-squares sense through the singular value decomposition: the numerical rank tells
//! whether the solution is unique, and the residual whether the system is consistent.
//! (Multiplying the transition matrices together, as the exact path does, would amplify
//! rounding by `2^L` for tangents on a cycle of length `L`.)

use nalgebra::{DMatrix, DVector};

use crate::cycle_block::{CycleBlock, CycleFailure};
use crate::scalar::{rational_to_f64, FLOAT_TOLERANCE};

/// Singular values below this fraction of the largest count as zero.
const RANK_TOLERANCE: f64 = 1e-11;

/// Solve the cycle in f64; values per step, in the block's local order.
pub fn solve_cycle(block: &CycleBlock) -> Result<Vec<Vec<f64>>, CycleFailure> {
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
        let next = (j + 1) % len;
        for (i, row) in block.transitions[j].iter().enumerate() {
            let e = start[j] + i;
            a[(e, start[j] + i)] += 1.0;
            for (l, w) in row {
                a[(e, start[next] + l)] -= rational_to_f64(w);
            }
        }
    }
    for (e, (step, terms, rhs)) in block.normalization.iter().enumerate() {
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
        return Err(CycleFailure::NotUnique { rank, unknowns });
    }
    let x = svd.solve(&b, eps).map_err(|e| CycleFailure::Inconsistent {
        detail: format!("SVD solve failed: {e}"),
    })?;
    let residual = (&a * &x - &b).amax();
    if residual > FLOAT_TOLERANCE {
        return Err(CycleFailure::Inconsistent {
            detail: format!("least-squares residual {residual:e}"),
        });
    }
    Ok((0..len)
        .map(|j| x.as_slice()[start[j]..start[j + 1]].to_vec())
        .collect())
}
