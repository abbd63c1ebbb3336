//! Solving a [`ScalingSystem`] orbit by orbit, and checking every equation afterwards.

use num_rational::BigRational;

use crate::orbit_block::{BlockFailure, OrbitBlock};
use crate::orbits::orbits;
use crate::scaling_system::ScalingSystem;
use crate::{Scalar, StencilError};

/// The solution of a system and the largest residual over all its equations.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution<S> {
    /// One value per unknown.
    pub values: Vec<S>,
    /// Largest absolute residual over every relation and normalization equation.
    pub residual: f64,
}

/// Solve `system` in the field `S`; `scheme` and `n` only label errors.
pub fn solve_system<S: Scalar>(
    system: &ScalingSystem<S>,
    scheme: &str,
    n: u32,
) -> Result<Solution<S>, StencilError> {
    let by_class = system.unknowns_by_class();
    let mut normalization_by_class = vec![Vec::new(); system.next.len()];
    for (e, row) in system.normalization.iter().enumerate() {
        normalization_by_class[row.class as usize].push(e);
    }
    let mut values: Vec<Option<S>> = vec![None; system.unknowns()];
    for orbit in orbits(&system.next) {
        let block = OrbitBlock::new(system, &orbit, &by_class, &normalization_by_class);
        let solved = S::solve_orbit(&block).map_err(|failure| match failure {
            BlockFailure::Inconsistent { detail } => StencilError::Inconsistent {
                scheme: scheme.to_owned(),
                n,
                detail: format!("orbit with cycle {:?}: {detail}", orbit.cycle),
            },
            BlockFailure::NotUnique { rank, unknowns } => StencilError::NotUnique {
                scheme: scheme.to_owned(),
                n,
                residues: orbit.cycle.clone(),
                rank,
                unknowns,
            },
        })?;
        for (step, step_values) in block.steps.iter().zip(solved) {
            for (&u, value) in step.iter().zip(step_values) {
                values[u] = Some(value);
            }
        }
    }
    let values: Vec<S> = values
        .into_iter()
        .map(|v| v.unwrap_or_else(S::zero))
        .collect();
    let residual = verify(system, &values, scheme, n)?;
    Ok(Solution { values, residual })
}

fn evaluate<S: Scalar>(terms: &[(usize, BigRational)], values: &[S]) -> S {
    terms.iter().fold(S::zero(), |acc, (v, w)| {
        acc + S::from_rational(w) * values[*v].clone()
    })
}

/// Check every equation of the system; the largest absolute residual.
fn verify<S: Scalar>(
    system: &ScalingSystem<S>,
    values: &[S],
    scheme: &str,
    n: u32,
) -> Result<f64, StencilError> {
    let mut worst = 0f64;
    let mut check = |residual: S, what: &dyn Fn() -> String| {
        worst = worst.max(residual.to_f64().abs());
        if residual.is_negligible() {
            Ok(())
        } else {
            Err(StencilError::Inconsistent {
                scheme: scheme.to_owned(),
                n,
                detail: format!("{} is off by {:?}", what(), residual),
            })
        }
    };
    for (u, relation) in system.relations.iter().enumerate() {
        let residual =
            values[u].clone() - evaluate(&relation.terms, values) - relation.constant.clone();
        check(residual, &|| {
            format!("the relation of {}", system.labels[u])
        })?;
    }
    for row in &system.normalization {
        let residual = evaluate(&row.terms, values) - S::from_rational(&row.rhs);
        check(residual, &|| format!("the normalization at {}", row.label))?;
    }
    Ok(worst)
}
