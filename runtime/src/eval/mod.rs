//! Exact evaluation at rational parameters: Catmull–Clark at any face and `(u, v)`, Loop at any
//! triangle and barycentric `(u, v)`.

pub mod exact_eval;
pub mod loop_exact_eval;
