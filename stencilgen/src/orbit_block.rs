//! The closed sub-system of one orbit, in step-local indices.
//!
//! Write `x_r` for the unknowns of class `r`. The relations read `x_r = A_r x_{next(r)} + c_r`
//! (mask weights in `A_r`, doubled for tangents; known values in `c_r`). Along the orbit's cycle
//! `r_0 -> r_1 -> ... -> r_{L-1} -> r_0` they close on themselves; every tree class hangs off
//! the cycle, or off a terminal class, through its successor. Together with the normalization
//! equations of its classes an orbit is a closed system: nothing outside it enters.

use num_rational::BigRational;

use crate::orbits::Orbit;
use crate::scaling_system::ScalingSystem;

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

/// A relation in step-local indices: `x_i = sum (local unknown of step next, weight) + constant`.
#[derive(Clone, Debug)]
pub struct LocalRelation<S> {
    /// Coefficients on the unknowns of step `next[j]`.
    pub terms: Vec<(usize, BigRational)>,
    /// Known part.
    pub constant: S,
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

/// The equations of one orbit.
///
/// Steps `0..cycle_len` are the cycle in map order (`next[j] = j + 1 mod cycle_len`); the
/// remaining steps are the tree classes, each after the step it maps to (terminal steps have
/// no successor and only constants on their right-hand sides).
#[derive(Clone, Debug)]
pub struct OrbitBlock<S> {
    /// The class of each step.
    pub classes: Vec<u32>,
    /// How many of the first steps form the cycle (0 for a terminal orbit).
    pub cycle_len: usize,
    /// The step holding the successor class, `None` for a terminal step.
    pub next: Vec<Option<usize>>,
    /// Global unknown ids of each step.
    pub steps: Vec<Vec<usize>>,
    /// `relations[j][i]`: the relation of local unknown `i` of step `j`.
    pub relations: Vec<Vec<LocalRelation<S>>>,
    /// The normalization equations of the orbit's classes.
    pub normalization: Vec<LocalNormalization>,
}

impl<S: Clone> OrbitBlock<S> {
    /// Extract the block of `orbit` from `system`. `by_class` is
    /// [`ScalingSystem::unknowns_by_class`]; `normalization_by_class` lists the indices of
    /// each class's normalization rows.
    pub fn new(
        system: &ScalingSystem<S>,
        orbit: &Orbit,
        by_class: &[Vec<usize>],
        normalization_by_class: &[Vec<usize>],
    ) -> Self {
        let classes: Vec<u32> = orbit.cycle.iter().chain(&orbit.tree).copied().collect();
        let mut step_of = std::collections::HashMap::with_capacity(classes.len());
        for (j, &c) in classes.iter().enumerate() {
            step_of.insert(c, j);
        }
        let next: Vec<Option<usize>> = classes
            .iter()
            .map(|&c| {
                system.next[c as usize].map(|s| {
                    *step_of
                        .get(&s)
                        .unwrap_or_else(|| unreachable!("orbits are closed under next"))
                })
            })
            .collect();
        let steps: Vec<Vec<usize>> = classes
            .iter()
            .map(|&c| by_class[c as usize].clone())
            .collect();
        let local = |step: usize, u: usize| -> usize {
            steps[step]
                .binary_search(&u)
                .unwrap_or_else(|_| unreachable!("relations refer to the successor class"))
        };
        let relations = (0..steps.len())
            .map(|j| {
                steps[j]
                    .iter()
                    .map(|&u| {
                        let relation = &system.relations[u];
                        let terms = match next[j] {
                            Some(s) => relation
                                .terms
                                .iter()
                                .map(|(v, w)| (local(s, *v), w.clone()))
                                .collect(),
                            None => Vec::new(),
                        };
                        LocalRelation {
                            terms,
                            constant: relation.constant.clone(),
                        }
                    })
                    .collect()
            })
            .collect();
        let normalization = classes
            .iter()
            .enumerate()
            .flat_map(|(step, &c)| {
                normalization_by_class[c as usize]
                    .iter()
                    .map(move |&e| (step, e))
            })
            .map(|(step, e)| {
                let row = &system.normalization[e];
                LocalNormalization {
                    step,
                    terms: row
                        .terms
                        .iter()
                        .map(|(u, c)| (local(step, *u), c.clone()))
                        .collect(),
                    rhs: row.rhs.clone(),
                }
            })
            .collect();
        OrbitBlock {
            cycle_len: orbit.cycle.len(),
            classes,
            next,
            steps,
            relations,
            normalization,
        }
    }
}
