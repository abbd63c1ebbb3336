//! The closed sub-system of one residue orbit.
//!
//! Write `x_r` for the unknowns of residue `r`. The scaling relation reads `x_r = A_r x_{2r}`
//! (residues mod n), where `A_r` holds the mask weights (doubled for tangents). Along the
//! orbit's cycle `r_0 -> r_1 = 2 r_0 -> ... -> r_{L-1} -> r_0` these equations close on
//! themselves; every tree residue hangs off the cycle through its image `2r`. Together with
//! the normalization equations of its residues an orbit is a closed system: nothing outside
//! it enters.

use num_rational::BigRational;

use crate::curve_system::CurveSystem;
use crate::residue_orbits::ResidueOrbit;

/// Why an orbit block has no unique solution.
#[derive(Clone, Debug, PartialEq)]
pub enum BlockFailure {
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

/// The equations of one residue orbit, in step-local indices.
///
/// Steps `0..cycle_len` are the cycle in map order (`next[j] = j + 1 mod cycle_len`); the
/// remaining steps are the tree residues, each after the step it maps to.
#[derive(Clone, Debug)]
pub struct OrbitBlock {
    /// The residue `r_j` of each step.
    pub residues: Vec<u32>,
    /// How many of the first steps form the cycle.
    pub cycle_len: usize,
    /// The step holding residue `2 r_j mod n`.
    pub next: Vec<usize>,
    /// Global unknown ids of each step `j` (residue `r_j`).
    pub steps: Vec<Vec<usize>>,
    /// `transitions[j][i]`: the scaling relation of local unknown `i` of step `j`, as
    /// `(local unknown of step next[j], weight)` pairs.
    pub transitions: Vec<Vec<Vec<(usize, BigRational)>>>,
    /// The normalization equations of the orbit's residues.
    pub normalization: Vec<LocalNormalization>,
}

/// A normalization equation `sum coef * x = rhs` over the unknowns of one step.
#[derive(Clone, Debug)]
pub struct LocalNormalization {
    /// The step whose unknowns it involves.
    pub step: usize,
    /// `(local unknown, coefficient)` pairs.
    pub terms: Vec<(usize, BigRational)>,
    /// Right-hand side.
    pub rhs: BigRational,
}

impl OrbitBlock {
    /// Extract the block of `orbit` from `system`; `by_residue` is
    /// [`CurveSystem::unknowns_by_residue`].
    pub fn new(system: &CurveSystem, orbit: &ResidueOrbit, by_residue: &[Vec<usize>]) -> Self {
        let residues: Vec<u32> = orbit.cycle.iter().chain(&orbit.tree).copied().collect();
        let step_of = |r: u32| residues.iter().position(|&s| s == r);
        let double = |r: u32| ((2 * u64::from(r)) % u64::from(system.n)) as u32;
        let next: Vec<usize> = residues
            .iter()
            .map(|&r| {
                step_of(double(r))
                    .unwrap_or_else(|| unreachable!("orbits are closed under doubling"))
            })
            .collect();
        let steps: Vec<Vec<usize>> = residues
            .iter()
            .map(|&r| by_residue[r as usize].clone())
            .collect();
        let local = |step: usize, u: usize| -> usize {
            steps[step]
                .binary_search(&u)
                .unwrap_or_else(|_| unreachable!("the scaling relation maps residue r to 2r"))
        };
        let transitions = (0..steps.len())
            .map(|j| {
                steps[j]
                    .iter()
                    .map(|&u| {
                        system.scaling[u]
                            .iter()
                            .map(|(v, w)| (local(next[j], *v), w.clone()))
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
                let step = step_of(residue)?;
                let terms = row
                    .terms
                    .iter()
                    .map(|(u, c)| (local(step, *u), c.clone()))
                    .collect();
                Some(LocalNormalization {
                    step,
                    terms,
                    rhs: row.rhs.clone(),
                })
            })
            .collect();
        OrbitBlock {
            cycle_len: orbit.cycle.len(),
            residues,
            next,
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
