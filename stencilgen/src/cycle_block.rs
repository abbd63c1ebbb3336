//! The closed sub-system of one residue cycle.
//!
//! Along a cycle `r_0 -> r_1 = 2 r_0 -> ... -> r_{L-1} -> r_0 (mod n)` the scaling relation
//! reads `x_j = A_j x_{j+1}` (indices mod L), where `x_j` are the unknowns of residue `r_j`
//! and `A_j` holds the (doubled, for tangents) mask weights. Together with the normalization
//! equations of these residues it is a closed system: nothing outside the cycle enters it.

use num_rational::BigRational;

use crate::curve_system::CurveSystem;

/// Why a cycle block has no unique solution.
#[derive(Clone, Debug, PartialEq)]
pub enum CycleFailure {
    /// The equations contradict each other.
    Inconsistent {
        /// What failed, and by how much.
        detail: String,
    },
    /// The equations leave a positive-dimensional solution space.
    NotUnique {
        /// The rank found.
        rank: usize,
        /// The number of unknowns of the block.
        unknowns: usize,
    },
}

/// The equations of one residue cycle, in step-local indices.
#[derive(Clone, Debug)]
pub struct CycleBlock {
    /// The residues `r_j` of the cycle.
    pub residues: Vec<u32>,
    /// Global unknown ids of each step `j` (residue `r_j`).
    pub steps: Vec<Vec<usize>>,
    /// `transitions[j][i]`: the scaling relation of local unknown `i` of step `j`, as
    /// `(local unknown of step j + 1, weight)` pairs.
    pub transitions: Vec<Vec<Vec<(usize, BigRational)>>>,
    /// Normalization equations `(step, [(local unknown, coef)], rhs)`.
    pub normalization: Vec<(usize, Vec<(usize, BigRational)>, BigRational)>,
}

impl CycleBlock {
    /// Extract the block of `cycle` from `system`; `by_residue` is
    /// [`CurveSystem::unknowns_by_residue`].
    pub fn new(system: &CurveSystem, cycle: &[u32], by_residue: &[Vec<usize>]) -> Self {
        let steps: Vec<Vec<usize>> = cycle
            .iter()
            .map(|&r| by_residue[r as usize].clone())
            .collect();
        let local = |step: usize, u: usize| -> usize {
            steps[step]
                .binary_search(&u)
                .unwrap_or_else(|_| unreachable!("scaling relation leaves its residue cycle"))
        };
        let len = steps.len();
        let transitions = (0..len)
            .map(|j| {
                steps[j]
                    .iter()
                    .map(|&u| {
                        system.scaling[u]
                            .iter()
                            .map(|(v, w)| (local((j + 1) % len, *v), w.clone()))
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let n = i64::from(system.n);
        let normalization = system
            .normalization
            .iter()
            .filter_map(|row| {
                let residue = row.numerator.rem_euclid(n) as u32;
                let step = cycle.iter().position(|&r| r == residue)?;
                let terms = row
                    .terms
                    .iter()
                    .map(|(u, c)| (local(step, *u), c.clone()))
                    .collect();
                Some((step, terms, row.rhs.clone()))
            })
            .collect();
        CycleBlock {
            residues: cycle.to_vec(),
            steps,
            transitions,
            normalization,
        }
    }

    /// Total number of unknowns in the block.
    pub fn unknowns(&self) -> usize {
        self.steps.iter().map(Vec::len).sum()
    }
}
