//! Measuring a tessellation's error: the largest distance from dense surface samples to the
//! triangle mesh, with an exact point-to-triangle distance and a uniform-grid search that
//! finds the true nearest triangle of the whole mesh (not only of the sample's own patch).
//!
//! The grid is a lower-bound-driven search: the cells around the sample are visited ring by
//! ring (Chebyshev shells), and the search stops as soon as the best distance found is no
//! larger than the distance from the sample to the unvisited part of the grid, so the result
//! equals the brute-force minimum over all triangles.

use super::patch_input::BezierPatches;
pub use crate::mesh::geometry::{
    closest_point_on_segment, closest_point_on_triangle, point_triangle_distance,
};
pub use crate::mesh::triangle_grid::TriangleGrid;
use crate::mesh::triangle_mesh::TriangleMesh;

/// Where the largest distance from the surface to the mesh was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstSample {
    /// The distance.
    pub distance: f64,
    /// The patch.
    pub patch: usize,
    /// Its parameters.
    pub uv: (f64, f64),
}

/// The largest distance from the surface to the mesh, over an `n × n` grid of samples
/// `(i/(n-1), j/(n-1))` on every patch (`n ≥ 2`), each measured exactly to the nearest
/// triangle of the whole mesh ([`TriangleGrid`]).
pub fn max_surface_distance(patches: &BezierPatches, mesh: &TriangleMesh, n: usize) -> f64 {
    worst_sample(patches, mesh, n).distance
}

/// [`max_surface_distance`] with the sample where it occurs.
pub fn worst_sample(patches: &BezierPatches, mesh: &TriangleMesh, n: usize) -> WorstSample {
    let grid = TriangleGrid::from_mesh(mesh);
    let n = n.max(2);
    let mut worst = WorstSample {
        distance: 0.0,
        patch: 0,
        uv: (0.0, 0.0),
    };
    for (k, patch) in patches.patches.iter().enumerate() {
        for j in 0..n {
            for i in 0..n {
                let u = i as f64 / (n - 1) as f64;
                let v = j as f64 / (n - 1) as f64;
                let d = grid.nearest_distance(patch.position(u, v));
                if d > worst.distance {
                    worst = WorstSample {
                        distance: d,
                        patch: k,
                        uv: (u, v),
                    };
                }
            }
        }
    }
    worst
}
