//! The local subdivision operators of one patch kind in f64: `A`, the sub-patch nets `R_b`,
//! the regular net, the limit mask. Converted once per kind from the exact rationals of
//! [`schemes::local_matrices::LocalMatrices`].

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::ToPrimitive;
use schemes::local_matrices::LocalMatrices;
use schemes::QuadScheme;

use super::bezier_net::{bspline_to_bezier, Net, Point};
use crate::mesh::topology::Mesh;
use crate::scheme::patch::PatchKind;
use crate::RuntimeError;

/// A row-major matrix, dense (for the limit mask's power iteration and the sign test) and by
/// its non-zero entries (for the products).
///
/// Why both: the local subdivision operators are mostly zeros (a new point of `A` draws on at
/// most `2N + 1` of the `2N + 8` old ones), and the products are most of the extraordinary
/// descent's arithmetic. Skipping a zero entry leaves every sum to the bit what the dense
/// product gives for finite points: a running sum starts at `+0`, never becomes `-0` (a sum is
/// `-0` only when both terms are), and `x + (+-0) = x` for any other `x`.
#[derive(Clone, Debug)]
pub(crate) struct Matrix {
    data: Vec<f64>,
    /// Row `r`'s non-zero entries, `(column, weight)` in column order:
    /// `entries[starts[r]..starts[r + 1]]`.
    entries: Vec<(usize, f64)>,
    starts: Vec<usize>,
}

impl Matrix {
    fn from_exact(m: &[Vec<BigRational>]) -> Result<Self, RuntimeError> {
        let cols = m.first().map_or(0, Vec::len);
        let mut data = Vec::with_capacity(m.len() * cols);
        let mut entries = Vec::new();
        let mut starts = vec![0];
        for row in m {
            for (c, x) in row.iter().enumerate() {
                let w = x.to_f64().ok_or_else(|| {
                    RuntimeError::Unsupported(format!("a subdivision weight {x} has no f64 value"))
                })?;
                data.push(w);
                if w != 0.0 {
                    entries.push((c, w));
                }
            }
            starts.push(entries.len());
        }
        Ok(Matrix {
            data,
            entries,
            starts,
        })
    }

    /// Rows.
    fn rows(&self) -> usize {
        self.starts.len() - 1
    }

    /// Row `r`'s non-zero entries.
    fn row(&self, r: usize) -> &[(usize, f64)] {
        self.entries
            .get(self.starts[r]..self.starts[r + 1])
            .unwrap_or(&[])
    }

    /// Row `r` of `M P`.
    fn row_times(&self, r: usize, points: &[Point]) -> Point {
        let mut p = [0.0; 3];
        for &(column, w) in self.row(r) {
            if let Some(q) = points.get(column) {
                for c in 0..3 {
                    p[c] += w * q[c];
                }
            }
        }
        p
    }

    /// `M P` into `out` (its memory kept).
    fn apply_into(&self, points: &[Point], out: &mut Vec<Point>) {
        out.clear();
        out.extend((0..self.rows()).map(|r| self.row_times(r, points)));
    }

    /// `M P` as a 4 x 4 net (`M` has 16 rows).
    fn apply_net(&self, points: &[Point]) -> Net {
        std::array::from_fn(|k| {
            if k < self.rows() {
                self.row_times(k, points)
            } else {
                [0.0; 3]
            }
        })
    }

    /// The distinct rows of `parts` stacked (rows with the same entries once), and per part
    /// the stacked row of each of its rows. Only the sparse product is kept (no dense rows).
    fn stack(parts: &[&Matrix]) -> (Matrix, Vec<Vec<usize>>) {
        let mut stacked = Matrix {
            data: Vec::new(),
            entries: Vec::new(),
            starts: vec![0],
        };
        let mut index: HashMap<Vec<(usize, u64)>, usize> = HashMap::new();
        let mut maps = Vec::with_capacity(parts.len());
        for part in parts {
            let mut map = Vec::with_capacity(part.rows());
            for r in 0..part.rows() {
                let row = part.row(r);
                let key = row.iter().map(|&(c, w)| (c, w.to_bits())).collect();
                let next = stacked.rows();
                let at = *index.entry(key).or_insert(next);
                if at == next {
                    stacked.entries.extend_from_slice(row);
                    stacked.starts.push(stacked.entries.len());
                }
                map.push(at);
            }
            maps.push(map);
        }
        (stacked, maps)
    }
}

/// One patch kind's operators.
#[derive(Clone, Debug)]
pub(crate) struct Operators {
    /// Control points `K`.
    pub(crate) size: usize,
    /// The rows of `A` (K x K; `P_{k+1} = A P_k` is the layout one level down, around the
    /// same vertex) and of the `R_b` (16 x K: B-spline nets of the sub-patches
    /// `[1/2,1]x[0,1/2]`, `[1/2,1]^2`, `[0,1/2]x[1/2,1]`) stacked, each distinct row once: a
    /// level's next layout and its three nets share most of their points (every point of
    /// level `k + 1` that two of them hold), so one product makes them all, each row the
    /// arithmetic its own matrix would do.
    level: Matrix,
    /// Per row of `A`, its row of `level`.
    a_rows: Vec<usize>,
    /// Per sub-patch and net point, its row of `level`.
    net_rows: [[usize; 16]; 3],
    /// The B-spline net of a regular patch (phantom points included), else `None`.
    pub(crate) regular: Option<Matrix>,
    /// The limit mask `l` (`l A = l`, `sum l = 1`): the position at the vertex.
    pub(crate) limit: Vec<f64>,
    /// Whether every entry of `A` and every subdivision rule is non-negative, which puts the
    /// patch over `[0, 2^-k]^2` inside the convex hull of `A^k P` (the extraordinary bound).
    pub(crate) nonnegative: bool,
}

impl Operators {
    /// Build the operators of `kind` for a mesh with `mesh`'s boundary rule.
    pub(crate) fn new(mesh: &Mesh, kind: PatchKind) -> Result<Self, RuntimeError> {
        let scheme = QuadScheme::by_name("catmull-clark")
            .ok_or_else(|| RuntimeError::Unsupported("catmull-clark is not catalogued".into()))?;
        let nb = kind.neighbourhood(mesh.boundary);
        let exact = LocalMatrices::new(&scheme, nb, kind.sector)
            .map_err(|e| RuntimeError::Unsupported(e.to_string()))?;
        let a = Matrix::from_exact(&exact.a)?;
        let sub_patches = [
            Matrix::from_exact(&exact.sub_patches[0])?,
            Matrix::from_exact(&exact.sub_patches[1])?,
            Matrix::from_exact(&exact.sub_patches[2])?,
        ];
        let (level, maps) = Matrix::stack(&[&a, &sub_patches[0], &sub_patches[1], &sub_patches[2]]);
        let net = |b: usize| -> Result<[usize; 16], RuntimeError> {
            maps[b + 1].as_slice().try_into().map_err(|_| {
                RuntimeError::Unsupported(format!("a sub-patch of {kind:?} without 16 points"))
            })
        };
        let net_rows = [net(0)?, net(1)?, net(2)?];
        let a_rows = maps[0].clone();
        let regular = match exact.regular_net() {
            Some(n) => Some(Matrix::from_exact(&n)?),
            None => None,
        };
        let size = exact.size();
        // Power iteration for the left eigenvector of eigenvalue 1; the others are below 0.7
        // for Catmull–Clark, so 200 steps leave far less than f64 rounding.
        let mut limit = vec![0.0; size];
        limit[0] = 1.0;
        for _ in 0..200 {
            let mut next = vec![0.0; size];
            for (r, &l) in limit.iter().enumerate() {
                for (c, x) in next.iter_mut().enumerate() {
                    *x += l * a.data[r * size + c];
                }
            }
            let sum: f64 = next.iter().sum();
            limit = next.iter().map(|x| x / sum).collect();
        }
        let nonnegative = a.data.iter().all(|&x| x >= 0.0);
        Ok(Operators {
            size,
            level,
            a_rows,
            net_rows,
            regular,
            limit,
            nonnegative,
        })
    }

    /// The layout `A P` one level down from the layout `points` into `next`, and the Bézier
    /// nets of the three regular quarters of `points`' own square (`R_b P`, to Bézier form)
    /// into `nets`, from one product (into `rows`).
    pub(crate) fn level(
        &self,
        points: &[Point],
        rows: &mut Vec<Point>,
        next: &mut Vec<Point>,
        nets: &mut [Net; 3],
    ) {
        self.level.apply_into(points, rows);
        // Every stacked row index is below the stacked rows' count (`Matrix::stack`).
        next.clear();
        next.extend(self.a_rows.iter().map(|&r| rows[r]));
        for (net, indices) in nets.iter_mut().zip(&self.net_rows) {
            let mut spline = [[0.0; 3]; 16];
            for (p, &r) in spline.iter_mut().zip(indices) {
                *p = rows[r];
            }
            *net = bspline_to_bezier(&spline);
        }
    }

    /// The Bézier net of the whole (regular) patch.
    pub(crate) fn regular_patch(&self, points: &[Point]) -> Option<Net> {
        self.regular
            .as_ref()
            .map(|r| bspline_to_bezier(&r.apply_net(points)))
    }

    /// The limit position at the patch vertex.
    pub(crate) fn vertex_position(&self, points: &[Point]) -> Point {
        let mut p = [0.0; 3];
        for (w, q) in self.limit.iter().zip(points) {
            for c in 0..3 {
                p[c] += w * q[c];
            }
        }
        p
    }
}
