//! The one spatial index of the runtime: a uniform grid over a triangle soup answering exact
//! nearest-distance queries, for the error measures of the tessellators (rate selection,
//! Lai–Cheng and Espino et al.'s measured errors).
//!
//! The search is lower-bound driven: the cells around the query are visited ring by ring
//! (Chebyshev shells), and it stops as soon as the best distance found is no larger than the
//! distance from the query to the unvisited part of the grid, so the result equals the
//! brute-force minimum over all triangles.

use crate::mesh::geometry::{point_triangle_distance, Point3};
use crate::mesh::triangle_mesh::TriangleMesh;

/// A uniform grid over a triangle soup answering exact nearest-distance queries.
#[derive(Clone, Debug)]
pub struct TriangleGrid {
    triangles: Vec<[Point3; 3]>,
    lo: Point3,
    cell: f64,
    dims: [usize; 3],
    /// CSR: triangles of cell `k` are `ids[starts[k]..starts[k + 1]]`.
    starts: Vec<usize>,
    ids: Vec<u32>,
}

impl TriangleGrid {
    /// A grid over `triangles` with about two cells per triangle (at most 128 per axis).
    pub fn new(triangles: Vec<[Point3; 3]>) -> TriangleGrid {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for t in &triangles {
            for p in t {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        if triangles.is_empty() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        let extent = (0..3)
            .map(|k| hi[k] - lo[k])
            .fold(0.0, f64::max)
            .max(1e-300);
        let n = triangles.len().max(1) as f64;
        let cell = (extent / (2.0 * n).cbrt()).max(extent / 128.0);
        let mut dims = [1usize; 3];
        for k in 0..3 {
            dims[k] = (((hi[k] - lo[k]) / cell).floor() as usize + 1).clamp(1, 129);
        }
        let mut grid = TriangleGrid {
            triangles,
            lo,
            cell,
            dims,
            starts: Vec::new(),
            ids: Vec::new(),
        };
        let cells = dims[0] * dims[1] * dims[2];
        let mut counts = vec![0usize; cells + 1];
        for t in 0..grid.triangles.len() {
            grid.for_cells_of(t, |c| counts[c + 1] += 1);
        }
        for k in 0..cells {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut ids = vec![0u32; counts[cells]];
        for t in 0..grid.triangles.len() {
            grid.for_cells_of(t, |c| {
                ids[fill[c]] = t as u32;
                fill[c] += 1;
            });
        }
        grid.starts = counts;
        grid.ids = ids;
        grid
    }

    /// A grid over the triangles of `mesh` (its `f32` positions, widened).
    pub fn from_mesh(mesh: &TriangleMesh) -> TriangleGrid {
        let p = |i: u32| {
            let q = mesh.positions[i as usize];
            [f64::from(q[0]), f64::from(q[1]), f64::from(q[2])]
        };
        TriangleGrid::new(
            mesh.triangles
                .iter()
                .map(|t| [p(t[0]), p(t[1]), p(t[2])])
                .collect(),
        )
    }

    fn cell_of(&self, p: Point3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let x = ((p[k] - self.lo[k]) / self.cell).floor();
            c[k] = if x.is_nan() || x < 0.0 {
                0
            } else {
                (x as usize).min(self.dims[k] - 1)
            };
        }
        c
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    fn for_cells_of(&self, t: usize, mut f: impl FnMut(usize)) {
        let tri = self.triangles[t];
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in tri {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let a = self.cell_of(lo);
        let b = self.cell_of(hi);
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f(self.index([x, y, z]));
                }
            }
        }
    }

    /// The distance from `p` to the nearest triangle (infinite for an empty grid): exactly the
    /// minimum of [`point_triangle_distance`] over all triangles.
    pub fn nearest_distance(&self, p: Point3) -> f64 {
        let mut best = f64::INFINITY;
        if self.triangles.is_empty() {
            return best;
        }
        let c = self.cell_of(p);
        let max_ring = self.dims.iter().copied().max().unwrap_or(1);
        for r in 0..=max_ring {
            let lo: Vec<usize> = (0..3).map(|k| c[k].saturating_sub(r)).collect();
            let hi: Vec<usize> = (0..3).map(|k| (c[k] + r).min(self.dims[k] - 1)).collect();
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let ring = x.abs_diff(c[0]).max(y.abs_diff(c[1])).max(z.abs_diff(c[2]));
                        if ring != r {
                            continue;
                        }
                        let k = self.index([x, y, z]);
                        for &t in &self.ids[self.starts[k]..self.starts[k + 1]] {
                            let [a, b, cc] = self.triangles[t as usize];
                            best = best.min(point_triangle_distance(p, &[a, b, cc]));
                        }
                    }
                }
            }
            // A lower bound on the distance to every triangle not seen yet: such a triangle
            // lies entirely outside the visited box, beyond one of its faces that is not a
            // face of the grid.
            let mut bound = f64::INFINITY;
            for k in 0..3 {
                if lo[k] > 0 {
                    let face = self.lo[k] + lo[k] as f64 * self.cell;
                    bound = bound.min((p[k] - face).max(0.0));
                }
                if hi[k] + 1 < self.dims[k] {
                    let face = self.lo[k] + (hi[k] + 1) as f64 * self.cell;
                    bound = bound.min((face - p[k]).max(0.0));
                }
            }
            if best <= bound || bound == f64::INFINITY {
                break;
            }
        }
        best
    }
}
