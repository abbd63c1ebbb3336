//! A whole set of patch stencils — every neighbourhood, sector, rate and kind a table holds —
//! generated in parallel (rayon; each job is one independent grid solve).

use rayon::prelude::*;
use schemes::{BoundaryMode, QuadScheme};

use crate::extraordinary_patch::Neighbourhood;
use crate::patch_stencils::{patch_stencils, PatchStencils};
use crate::regular_patch::StencilKind;
use crate::{Scalar, StencilError};

/// Which stencils to generate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StencilSetSpec {
    /// Interior valences (e.g. 3..=8).
    pub valences: Vec<u32>,
    /// Valences of darts (interior vertices with one infinitely sharp edge,
    /// [`Neighbourhood::dart`]), every sector of each; empty for none. Only for schemes with
    /// crease (boundary) rules.
    pub darts: Vec<u32>,
    /// Boundary face counts (e.g. 1..=6); empty for none.
    pub boundary_faces: Vec<u32>,
    /// The boundary interpolation mode of the boundary entries.
    pub boundary_mode: BoundaryMode,
    /// Grid rates (e.g. 1..=24).
    pub rates: Vec<u32>,
}

impl StencilSetSpec {
    /// The default table's contents: interior valences 3..=8, darts of valences 3..=8 (every
    /// sector), boundary 1..=6 faces ("edge only"), n = 1..=24.
    pub fn default_catmull_clark() -> Self {
        StencilSetSpec {
            valences: (3..=8).collect(),
            darts: (3..=8).collect(),
            boundary_faces: (1..=6).collect(),
            boundary_mode: BoundaryMode::EdgeOnly,
            rates: (1..=24).collect(),
        }
    }

    /// Every `(neighbourhood, sector)` patch of the set.
    pub fn patches(&self) -> Vec<(Neighbourhood, u32)> {
        let interior = self
            .valences
            .iter()
            .map(|&v| (Neighbourhood::interior(v), 0));
        // Every sector of a dart: sectors `s` and `v - 1 - s` are mirror images, but a mirrored
        // patch reads its control points in another order, so each is stored as it is read.
        let darts = self.darts.iter().flat_map(|&v| {
            let nb = Neighbourhood::dart(v);
            (0..v).map(move |s| (nb, s))
        });
        let boundary = self.boundary_faces.iter().flat_map(|&f| {
            let nb = Neighbourhood::boundary(f, self.boundary_mode);
            (0..f).map(move |s| (nb, s))
        });
        interior.chain(darts).chain(boundary).collect()
    }
}

/// Generate every stencil of `spec` (positions and both derivatives at every primal and dual
/// point), in the order patches x rates x kinds.
pub fn stencil_set<S: Scalar + Send + Sync>(
    scheme: &QuadScheme,
    spec: &StencilSetSpec,
) -> Result<Vec<PatchStencils<S>>, StencilError> {
    stencil_set_with_progress(scheme, spec, &|_, _| {})
}

/// [`stencil_set`], calling `progress(done, total)` (from worker threads) after each grid.
pub fn stencil_set_with_progress<S: Scalar + Send + Sync>(
    scheme: &QuadScheme,
    spec: &StencilSetSpec,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<PatchStencils<S>>, StencilError> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    let jobs: Vec<(Neighbourhood, u32, u32, StencilKind)> = spec
        .patches()
        .into_iter()
        .flat_map(|(nb, s)| {
            spec.rates
                .iter()
                .flat_map(move |&n| StencilKind::ALL.map(|k| (nb, s, n, k)))
        })
        .collect();
    let total = jobs.len();
    jobs.into_par_iter()
        .map(|(nb, s, n, kind)| {
            let result = patch_stencils::<S>(scheme, nb, s, n, kind);
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                total,
            );
            result
        })
        .collect()
}
