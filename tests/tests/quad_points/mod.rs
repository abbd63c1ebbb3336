//! Stencils of quad patches as weights on named points (`GridPoint`s of a neighbourhood's
//! sectors), for the tests that build their expected stencils point by point
//! (`boundary_stencils.rs`, `dart_stencils.rs`).

use std::collections::HashMap;

use num_rational::BigRational;
use num_traits::Zero;
use stencilgen::extraordinary_patch::{GridPoint, Neighbourhood};

/// Weights of a stencil on named points: its nonzero weights, keyed by the patch layout's
/// points (`patch_layout`) of sector `sector`.
pub fn named(
    nb: Neighbourhood,
    sector: u32,
    stencil: &[BigRational],
) -> HashMap<GridPoint, BigRational> {
    stencilgen::extraordinary_patch::patch_layout(nb, sector)
        .into_iter()
        .zip(stencil)
        .filter(|(_, w)| !w.is_zero())
        .map(|(p, w)| (p, w.clone()))
        .collect()
}

/// Add weight `w` on point `p`, dropping the point where its weight cancels to zero.
pub fn add(map: &mut HashMap<GridPoint, BigRational>, p: GridPoint, w: BigRational) {
    let e = map.entry(p).or_insert_with(BigRational::zero);
    *e += w;
    if e.is_zero() {
        map.remove(&p);
    }
}
