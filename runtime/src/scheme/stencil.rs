//! Sparse linear maps between control-point sets: every refinement rule is one (a refined
//! vertex is a fixed combination of coarse ones), and so is a whole isolation, composed step by
//! step. The per-frame path applies the composed map to the *input* control points, so no
//! refinement runs per frame (OpenSubdiv's `Far::StencilTable` plays the same role).
//!
//! Row `i` is `p'_i = sum_k w_k p_{j_k}` over its entries; rows are stored compressed (CSR),
//! their entries sorted by index, no index twice, no zero weight.

use std::ops::{Add, Mul, Sub};

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use rayon::prelude::*;

/// The scalars refinement rules are written in: `f64` for positions and per-frame stencils,
/// [`BigRational`] for exact evaluation. A rule written once over `W` serves both.
pub trait Weight:
    Clone + Zero + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Send + Sync
{
    /// The weight `p / q` (`q != 0`), exact where `Self` can hold it.
    fn ratio(p: i64, q: i64) -> Self;

    /// The weight of a finite `f32` (a sharpness, a fractional weight), exactly: every `f32` is
    /// a dyadic rational.
    fn from_f32(x: f32) -> Self;
}

impl Weight for f64 {
    fn ratio(p: i64, q: i64) -> Self {
        p as f64 / q as f64
    }

    fn from_f32(x: f32) -> Self {
        f64::from(x)
    }
}

impl Weight for BigRational {
    fn ratio(p: i64, q: i64) -> Self {
        BigRational::new(BigInt::from(p), BigInt::from(q))
    }

    fn from_f32(x: f32) -> Self {
        BigRational::from_float(x).unwrap_or_else(BigRational::zero)
    }
}

/// A sparse linear map from `columns` source points to `rows()` target points.
#[derive(Clone, Debug, PartialEq)]
pub struct Stencil<W = f64> {
    offsets: Vec<u32>,
    indices: Vec<u32>,
    weights: Vec<W>,
    columns: usize,
}

impl<W> Stencil<W> {
    /// Number of target points.
    pub fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of source points.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Number of stored weights.
    pub fn entries(&self) -> usize {
        self.indices.len()
    }

    /// Row `i`: its source indices and weights.
    pub fn row(&self, i: usize) -> (&[u32], &[W]) {
        let r = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        (&self.indices[r.clone()], &self.weights[r])
    }
}

impl<W: Weight> Stencil<W> {
    /// The identity on `n` points.
    pub fn identity(n: usize) -> Self {
        Stencil {
            offsets: (0..=n as u32).collect(),
            indices: (0..n as u32).collect(),
            weights: vec![W::ratio(1, 1); n],
            columns: n,
        }
    }

    /// About the heap bytes of its rows (their vectors' capacities).
    pub fn heap_bytes(&self) -> usize {
        self.offsets.capacity() * std::mem::size_of::<u32>()
            + self.indices.capacity() * std::mem::size_of::<u32>()
            + self.weights.capacity() * std::mem::size_of::<W>()
    }

    /// The map of rows `rows` of this one, in that order (a row may repeat).
    pub fn select(&self, rows: &[u32]) -> Self {
        let mut out = Stencil::new(self.columns);
        for &r in rows {
            let (js, ws) = self.row(r as usize);
            out.indices.extend_from_slice(js);
            out.weights.extend_from_slice(ws);
            out.offsets.push(out.indices.len() as u32);
        }
        out
    }

    /// An empty map from `columns` source points; rows follow with [`Stencil::push_row`].
    pub fn new(columns: usize) -> Self {
        Stencil {
            offsets: vec![0],
            indices: Vec::new(),
            weights: Vec::new(),
            columns,
        }
    }

    /// Append a row from `(index, weight)` terms in any order; repeated indices are summed and
    /// zero sums dropped.
    pub fn push_row(&mut self, mut terms: Vec<(u32, W)>) {
        debug_assert!(terms.iter().all(|&(j, _)| (j as usize) < self.columns));
        terms.sort_by_key(|&(j, _)| j);
        let mut last: Option<u32> = None;
        let start = self.indices.len();
        for (j, w) in terms {
            if last == Some(j) {
                let slot = self.weights.len() - 1;
                self.weights[slot] = self.weights[slot].clone() + w;
            } else {
                self.indices.push(j);
                self.weights.push(w);
                last = Some(j);
            }
        }
        // Drop cancelled terms (an exact rule can sum to zero).
        let mut keep = start;
        for k in start..self.indices.len() {
            if !self.weights[k].is_zero() {
                self.indices.swap(keep, k);
                self.weights.swap(keep, k);
                keep += 1;
            }
        }
        self.indices.truncate(keep);
        self.weights.truncate(keep);
        self.offsets.push(self.indices.len() as u32);
    }

    /// `outer ∘ self`: the map that applies `self`, then `outer` (whose columns are `self`'s
    /// rows).
    pub fn then(&self, outer: &Stencil<W>) -> Stencil<W> {
        debug_assert_eq!(outer.columns, self.rows());
        // Each outer row gathers into a dense accumulator over the columns (one per worker),
        // remembering which columns it touched: no sorting of the expanded terms.
        let rows: Vec<Vec<(u32, W)>> = (0..outer.rows())
            .into_par_iter()
            .map_init(
                || {
                    (
                        vec![W::zero(); self.columns],
                        vec![false; self.columns],
                        Vec::new(),
                    )
                },
                |(acc, seen, touched), i| {
                    let (js, ws) = outer.row(i);
                    for (&j, w) in js.iter().zip(ws) {
                        let (ks, vs) = self.row(j as usize);
                        for (&k, v) in ks.iter().zip(vs) {
                            let k = k as usize;
                            if !seen[k] {
                                seen[k] = true;
                                touched.push(k as u32);
                            }
                            acc[k] = acc[k].clone() + w.clone() * v.clone();
                        }
                    }
                    touched.sort_unstable();
                    let row = touched
                        .drain(..)
                        .map(|k| {
                            let k_ = k as usize;
                            seen[k_] = false;
                            (k, std::mem::replace(&mut acc[k_], W::zero()))
                        })
                        .collect();
                    row
                },
            )
            .collect();
        let mut out = Stencil::new(self.columns);
        for row in rows {
            out.push_row(row);
        }
        out
    }
}

impl Stencil<f64> {
    /// Apply to `[f64; 3]` points (the refined positions of a mesh).
    pub fn apply(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; self.rows()];
        self.apply_into(points, &mut out);
        out
    }

    /// Apply to `points` into `out` (`rows()` long), in parallel over rows: the per-frame path
    /// maps a frame's input points, widened to f64, to the isolated control points.
    ///
    /// Why f64 per frame: the refined points keep the input's precision. Rounded to f32, each
    /// would move by up to half an f32 step at its distance from the coordinate origin,
    /// independently of its neighbours, and the small faces of an isolated neighbourhood would
    /// turn that into tangent errors that grow with that distance instead of with their size
    /// (f32 weights would do the same: their sum misses one by about `1e-7`).
    pub fn apply_into(&self, points: &[[f64; 3]], out: &mut [[f64; 3]]) {
        debug_assert_eq!(points.len(), self.columns);
        debug_assert_eq!(out.len(), self.rows());
        out.par_chunks_mut(4096)
            .enumerate()
            .for_each(|(chunk, out)| {
                let first = chunk * 4096;
                for (i, o) in out.iter_mut().enumerate() {
                    let r = self.offsets[first + i] as usize..self.offsets[first + i + 1] as usize;
                    let mut acc = [0.0f64; 3];
                    for (&j, &w) in self.indices[r.clone()].iter().zip(&self.weights[r]) {
                        let p = points[j as usize];
                        acc = [acc[0] + w * p[0], acc[1] + w * p[1], acc[2] + w * p[2]];
                    }
                    *o = acc;
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composition_applies_the_inner_map_first() {
        // inner: midpoints of (0,1) and (1,2); outer: the midpoint of those.
        let mut inner = Stencil::<f64>::new(3);
        inner.push_row(vec![(1, 0.5), (0, 0.5)]);
        inner.push_row(vec![(1, 0.5), (2, 0.5)]);
        let mut outer = Stencil::<f64>::new(2);
        outer.push_row(vec![(0, 0.5), (1, 0.5)]);
        let both = inner.then(&outer);
        assert_eq!(both.row(0), (&[0u32, 1, 2][..], &[0.25, 0.5, 0.25][..]));
        let p = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 8.0, 0.0]];
        assert_eq!(both.apply(&p), outer.apply(&inner.apply(&p)));
    }

    #[test]
    fn repeated_indices_are_summed_and_cancellations_dropped() {
        let mut s = Stencil::<BigRational>::new(3);
        s.push_row(vec![
            (2, BigRational::ratio(1, 3)),
            (0, BigRational::ratio(1, 2)),
            (2, BigRational::ratio(-1, 3)),
            (0, BigRational::ratio(1, 2)),
        ]);
        assert_eq!(s.row(0).0, &[0]);
        assert_eq!(s.row(0).1, &[BigRational::ratio(1, 1)]);
    }
}
