//! The neighbourhood of an extraordinary vertex and one subdivision step on it: the local
//! subdivision matrices live with the scheme data in [`schemes::local_matrices`] (the runtime
//! applies them too); they are re-exported here under their historical path.

pub use schemes::local_matrices::{
    canonical, patch_layout, refine_point, GridPoint, LocalMatrices, Neighbourhood,
    UnsupportedNeighbourhood, OUTER_POINTS, SUB_PATCH_ORIGINS,
};
