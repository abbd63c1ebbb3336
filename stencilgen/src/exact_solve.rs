//! Exact solution of an orbit over the rationals.
//!
//! On the cycle, substituting the relations `x_j = A_j x_{j+1} + c_j` into each other gives
//! `x_j = P_j x_0 + q_j` with `P_L = I, q_L = 0`, `P_j = A_j P_{j+1}`, `q_j = A_j q_{j+1} + c_j`;
//! the relation of step 0 closes the loop as `(P_0 - I) x_0 = -q_0`. For a uniform scheme `x_0`
//! is a fixed vector of the product of the cycle's matrices (Schaefer–Warren section 3: a
//! dominant left eigenvector of the upsampled subdivision matrix). Each normalization equation
//! of cycle step `j` becomes `(c^T P_j) x_0 = rhs - c^T q_j`. This reduced system has only
//! `|x_0|` unknowns (one support width), however long the cycle, and it is equivalent to the
//! cycle's full system: the eliminated equations hold by construction. Gauss–Jordan
//! elimination over Q decides consistency and uniqueness; tree classes then follow by
//! substitution, `x_r = A_r x_{next(r)} + c_r`. The normalization equations of tree classes
//! determine nothing; the caller verifies them.

use num_rational::BigRational;
use num_traits::{One, Zero};

use crate::orbit_block::{BlockFailure, LocalNormalization, LocalRelation, OrbitBlock};

type Dense = Vec<Vec<BigRational>>;

/// Solve the orbit exactly; values per step, in the block's local order.
pub fn solve_orbit(block: &OrbitBlock<BigRational>) -> Result<Vec<Vec<BigRational>>, BlockFailure> {
    let len = block.cycle_len;
    let mut values: Vec<Vec<BigRational>> = Vec::with_capacity(block.steps.len());
    if len > 0 {
        let width = block.steps[0].len();
        // affine[j] = (P_j, q_j); (P_len, q_len) = (I, 0).
        let mut affine: Vec<(Dense, Vec<BigRational>)> = vec![(Vec::new(), Vec::new()); len];
        let mut next: (Dense, Vec<BigRational>) =
            (identity(width), vec![BigRational::zero(); width]);
        for j in (0..len).rev() {
            let p = apply(&block.relations[j], &next.0, width);
            let q = block.relations[j]
                .iter()
                .map(|r| combine(r, &next.1))
                .collect();
            affine[j] = (p, q);
            next = affine[j].clone();
        }
        let (p0, q0) = &affine[0];
        let mut rows: Vec<(Vec<BigRational>, BigRational)> = Vec::new();
        for (i, row) in p0.iter().enumerate() {
            let mut r = row.clone();
            r[i] -= BigRational::one();
            rows.push((r, -q0[i].clone()));
        }
        for LocalNormalization { step, terms, rhs } in
            block.normalization.iter().filter(|e| e.step < len)
        {
            let (p, q) = &affine[*step];
            let mut r = vec![BigRational::zero(); width];
            let mut b = rhs.clone();
            for (l, c) in terms {
                for (o, x) in r.iter_mut().zip(&p[*l]) {
                    *o += c * x;
                }
                b -= c * &q[*l];
            }
            rows.push((r, b));
        }
        let x0 = solve_dense(rows, width)?;
        for (p, q) in &affine {
            values.push(p.iter().zip(q).map(|(row, c)| dot(row, &x0) + c).collect());
        }
    }
    for j in len..block.steps.len() {
        let step = match block.next[j] {
            Some(s) => block.relations[j]
                .iter()
                .map(|r| combine(r, &values[s]))
                .collect(),
            None => block.relations[j]
                .iter()
                .map(|r| r.constant.clone())
                .collect(),
        };
        values.push(step);
    }
    Ok(values)
}

/// `sum w x[l] + constant` for one relation.
fn combine(relation: &LocalRelation<BigRational>, x: &[BigRational]) -> BigRational {
    relation
        .terms
        .iter()
        .fold(relation.constant.clone(), |acc, (l, w)| acc + w * &x[*l])
}

/// `A P` for a sparse `A` (the relations' terms) and a dense `P` of `width` columns.
fn apply(a: &[LocalRelation<BigRational>], p: &Dense, width: usize) -> Dense {
    a.iter()
        .map(|row| {
            let mut out = vec![BigRational::zero(); width];
            for (l, w) in &row.terms {
                for (o, x) in out.iter_mut().zip(&p[*l]) {
                    if !x.is_zero() {
                        *o += w * x;
                    }
                }
            }
            out
        })
        .collect()
}

fn identity(n: usize) -> Dense {
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    if i == j {
                        BigRational::one()
                    } else {
                        BigRational::zero()
                    }
                })
                .collect()
        })
        .collect()
}

fn dot(a: &[BigRational], b: &[BigRational]) -> BigRational {
    a.iter()
        .zip(b)
        .filter(|(x, y)| !x.is_zero() && !y.is_zero())
        .fold(BigRational::zero(), |acc, (x, y)| acc + x * y)
}

/// The limit-position mask of a local subdivision matrix `A` (`K x K`, rows the level-1
/// points): the left fixed vector `l A = l` with `sum l = 1`, solved exactly.
pub fn limit_mask(a: &[Vec<BigRational>]) -> Result<Vec<BigRational>, BlockFailure> {
    let size = a.len();
    let mut rows: Vec<(Vec<BigRational>, BigRational)> = (0..size)
        .map(|j| {
            let mut row: Vec<BigRational> = (0..size).map(|i| a[i][j].clone()).collect();
            row[j] -= BigRational::one();
            (row, BigRational::zero())
        })
        .collect();
    rows.push((vec![BigRational::one(); size], BigRational::one()));
    solve_dense(rows, size)
}

/// Gauss–Jordan elimination of an overdetermined system `rows = [(a_i, b_i)]` in `width`
/// unknowns: the unique solution, or why there is none.
pub fn solve_dense(
    mut rows: Vec<(Vec<BigRational>, BigRational)>,
    width: usize,
) -> Result<Vec<BigRational>, BlockFailure> {
    let mut rank = 0;
    let mut pivots = Vec::new();
    for col in 0..width {
        let Some(p) = (rank..rows.len()).find(|&i| !rows[i].0[col].is_zero()) else {
            continue;
        };
        rows.swap(rank, p);
        let inv = rows[rank].0[col].recip();
        for x in rows[rank].0.iter_mut() {
            *x *= &inv;
        }
        rows[rank].1 *= &inv;
        let (pivot_row, pivot_rhs) = rows[rank].clone();
        for (i, (a, b)) in rows.iter_mut().enumerate() {
            if i == rank || a[col].is_zero() {
                continue;
            }
            let f = a[col].clone();
            for (x, y) in a.iter_mut().zip(&pivot_row) {
                if !y.is_zero() {
                    *x -= &f * y;
                }
            }
            *b -= &f * &pivot_rhs;
        }
        pivots.push(col);
        rank += 1;
    }
    if let Some((i, (_, b))) = rows
        .iter()
        .enumerate()
        .skip(rank)
        .find(|(_, (_, b))| !b.is_zero())
    {
        return Err(BlockFailure::Inconsistent {
            detail: format!("after elimination equation {i} reads 0 = {b}"),
        });
    }
    if rank < width {
        return Err(BlockFailure::NotUnique {
            rank,
            unknowns: width,
        });
    }
    let mut x = vec![BigRational::zero(); width];
    for (i, &col) in pivots.iter().enumerate() {
        x[col] = rows[i].1.clone();
    }
    Ok(x)
}

/// A basis of the right null space of the dense rational matrix `m` (`rows x width`).
pub(crate) fn null_space(mut m: Vec<Vec<BigRational>>, width: usize) -> Vec<Vec<BigRational>> {
    let mut pivots = Vec::new();
    let mut rank = 0;
    for col in 0..width {
        let Some(p) = (rank..m.len()).find(|&i| !m[i][col].is_zero()) else {
            continue;
        };
        m.swap(rank, p);
        let inv = m[rank][col].recip();
        for x in m[rank].iter_mut() {
            *x *= &inv;
        }
        let pivot = m[rank].clone();
        for (i, row) in m.iter_mut().enumerate() {
            if i == rank || row[col].is_zero() {
                continue;
            }
            let f = row[col].clone();
            for (x, y) in row.iter_mut().zip(&pivot) {
                if !y.is_zero() {
                    *x -= &f * y;
                }
            }
        }
        pivots.push(col);
        rank += 1;
    }
    (0..width)
        .filter(|c| !pivots.contains(c))
        .map(|free| {
            let mut v = vec![BigRational::zero(); width];
            v[free] = BigRational::one();
            for (i, &p) in pivots.iter().enumerate() {
                v[p] = -m[i][free].clone();
            }
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;

    fn q(n: i64, d: i64) -> BigRational {
        BigRational::new(BigInt::from(n), BigInt::from(d))
    }

    #[test]
    fn null_space_of_a_rank_one_matrix() {
        let q = |x: i64| BigRational::from_integer(BigInt::from(x));
        // [1 2 3] has the null space spanned by (-2, 1, 0), (-3, 0, 1).
        let ns = null_space(vec![vec![q(1), q(2), q(3)]], 3);
        assert_eq!(ns, vec![vec![q(-2), q(1), q(0)], vec![q(-3), q(0), q(1)]]);
    }

    #[test]
    fn dense_solver_reports_rank_and_consistency() {
        // x + y = 1, x - y = 0, 2x = 1: consistent and unique.
        let rows = vec![
            (vec![q(1, 1), q(1, 1)], q(1, 1)),
            (vec![q(1, 1), q(-1, 1)], q(0, 1)),
            (vec![q(2, 1), q(0, 1)], q(1, 1)),
        ];
        assert_eq!(solve_dense(rows, 2), Ok(vec![q(1, 2), q(1, 2)]));
        // x + y = 1 alone: rank 1 of 2.
        let rows = vec![(vec![q(1, 1), q(1, 1)], q(1, 1))];
        assert_eq!(
            solve_dense(rows, 2),
            Err(BlockFailure::NotUnique {
                rank: 1,
                unknowns: 2
            })
        );
        // x = 1, x = 2.
        let rows = vec![(vec![q(1, 1)], q(1, 1)), (vec![q(1, 1)], q(2, 1))];
        assert!(matches!(
            solve_dense(rows, 1),
            Err(BlockFailure::Inconsistent { .. })
        ));
    }
}
