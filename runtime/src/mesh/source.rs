//! Where a tessellator's output vertex lies on the surface: a face and exact rational
//! parameters.

/// Where an output vertex was evaluated: face `face` at `(u / denominator, v / denominator)` in
/// that face's own parameters (DESIGN.md conventions). Dual points at rate `n` have denominator
/// `2n`, points on the boundary curve `n`. As the tessellator makes them, `face` is a face of the
/// mesh it was given (the isolated mesh); [`crate::scheme::catmull_clark::isolate::Isolation::input_source`] turns them
/// into the input mesh's faces, where a non-quad face is parameterized by its sub-faces (the
/// quads of its first Catmull–Clark step, `subface` = the corner they hold). On Loop meshes
/// (`crate::tessellate::triangle_dual_grid`) `(u, v)` are the triangle's barycentric parameters: centroids
/// of the small triangles at rate `n` have denominator `3n`, primal points `n`, and
/// [`crate::scheme::triangle::isolation::TriangleIsolation::input_source`] maps them to the input triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VertexSource {
    /// The face (of the mesh that was tessellated).
    pub face: u32,
    /// Numerator of `u`.
    pub u: u32,
    /// Numerator of `v`.
    pub v: u32,
    /// The common denominator of `u` and `v`.
    pub denominator: u32,
    /// For a non-quad input face, which sub-face `(u, v)` is in (0 otherwise).
    pub subface: u8,
}

impl VertexSource {
    /// `(u, v)` as floating-point numbers.
    pub fn uv(&self) -> (f64, f64) {
        let d = f64::from(self.denominator);
        (f64::from(self.u) / d, f64::from(self.v) / d)
    }
}
