//! Quad subdivision schemes: the face, edge and vertex rules of one refinement step.
//!
//! Both schemes here are "vertex/edge/face" schemes on quad meshes, with every rule reading
//! only the 1-ring of the point it makes. Around a vertex `V` of valence `v` with edge
//! neighbours `E_1..E_v` and diagonal neighbours `F_1..F_v` (`F_i` in the face
//! `V, E_i, F_i, E_{i+1}`):
//!
//! * face point: the centroid of the face's four corners;
//! * edge point of edge `(P, Q)`: `e_end (P + Q) + e_side (sum of the other four corners of
//!   the two faces beside the edge)`;
//! * vertex point: `alpha_v V + beta_v sum E_i + gamma_v sum F_i`.
//!
//! In regular regions both are tensor products of a curve scheme ([`QuadScheme::regular_curve`]),
//! which is what the tables use for the regular sub-patches.

use num_rational::Rational64;

/// The vertex rule of a scheme as a function of the valence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexRule {
    /// Catmull–Clark: `V' = (Q + 2R + (v - 3) V) / v`, i.e. `alpha = 1 - 7/(4v)`,
    /// `beta = 3/(2v^2)`, `gamma = 1/(4v^2)`.
    CatmullClark,
    /// The extraordinary rule of `sw-nonpoly-quad` derived in `docs/algorithms/sw-nonpoly-quad.md`:
    /// `alpha = 4/9`, `beta = 4/(9v)`, `gamma = 1/(9v)` (`4/9, 1/9, 1/36` at `v = 4`).
    SwNonpoly,
}

impl VertexRule {
    /// `(alpha, beta, gamma)` at valence `v`: the weights of `V`, of each `E_i`, of each `F_i`.
    pub fn weights(self, valence: u32) -> (Rational64, Rational64, Rational64) {
        let v = i64::from(valence);
        match self {
            VertexRule::CatmullClark => (
                Rational64::new(4 * v - 7, 4 * v),
                Rational64::new(3, 2 * v * v),
                Rational64::new(1, 4 * v * v),
            ),
            VertexRule::SwNonpoly => (
                Rational64::new(4, 9),
                Rational64::new(4, 9 * v),
                Rational64::new(1, 9 * v),
            ),
        }
    }
}

/// What a boundary vertex with a single face does (OpenSubdiv's boundary interpolation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoundaryMode {
    /// "Edge only", OpenSubdiv's default: every boundary vertex, a single face's corner too,
    /// follows the smooth boundary rule.
    EdgeOnly,
    /// "Edge and corner": a boundary vertex with one face (valence 2) is a pinned corner.
    EdgeAndCorner,
}

/// The boundary rules of a scheme: boundary edges are curves of the scheme's boundary curve
/// rule, independent of the interior.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryRules {
    /// Boundary vertex point: `centre * V + end * (the two boundary neighbours)`.
    pub vertex_centre: Rational64,
    /// Weight of each boundary neighbour in a boundary vertex point.
    pub vertex_end: Rational64,
}

/// A quad subdivision scheme, as data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct QuadScheme {
    /// Catalogue name.
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// Weight of each endpoint in an edge point.
    pub edge_end: Rational64,
    /// Weight of each of the four other corners of the two faces beside the edge.
    pub edge_side: Rational64,
    /// The vertex rule.
    pub vertex: VertexRule,
    /// The curve scheme whose tensor product the scheme is in regular regions.
    pub regular_curve: &'static str,
    /// Boundary rules (boundary edge points are always midpoints), if the scheme has them.
    pub boundary: Option<BoundaryRules>,
}

/// Names of the quad schemes [`QuadScheme::by_name`] knows.
pub const QUAD_SCHEME_NAMES: [&str; 2] = ["catmull-clark", "sw-nonpoly-quad"];

impl QuadScheme {
    /// A scheme from the catalogue.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "catmull-clark" => Some(QuadScheme {
                name: "catmull-clark",
                description: "Catmull-Clark (1978), smooth interior rules; bicubic B-spline in regular regions",
                edge_end: Rational64::new(3, 8),
                edge_side: Rational64::new(1, 16),
                vertex: VertexRule::CatmullClark,
                regular_curve: "cubic-bspline",
                // Boundary edges are cubic B-spline curves: (1/8, 3/4, 1/8) and midpoints.
                boundary: Some(BoundaryRules {
                    vertex_centre: Rational64::new(3, 4),
                    vertex_end: Rational64::new(1, 8),
                }),
            }),
            "sw-nonpoly-quad" => Some(QuadScheme {
                name: "sw-nonpoly-quad",
                description: "Schaefer-Warren section 5.4: tensor product of sw-nonpoly, C1 and non-polynomial",
                edge_end: Rational64::new(1, 3),
                edge_side: Rational64::new(1, 12),
                vertex: VertexRule::SwNonpoly,
                regular_curve: "sw-nonpoly",
                boundary: None,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_affine_and_regular_rules_are_tensor_products() {
        for name in QUAD_SCHEME_NAMES {
            let s = QuadScheme::by_name(name).expect("catalogued");
            assert_eq!(
                s.edge_end * 2 + s.edge_side * 4,
                Rational64::from_integer(1),
                "{name}"
            );
            for v in 3..=8 {
                let (a, b, g) = s.vertex.weights(v);
                let v = i64::from(v);
                assert_eq!(
                    a + b * v + g * v,
                    Rational64::from_integer(1),
                    "{name} valence {v}"
                );
            }
        }
        // Tensor products at valence 4: vertex mask = outer product of the curve's even rule
        // (c0, c1, c0); edge mask = outer product of the odd rule (1/2, 1/2) and the even rule.
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        let (c0, c1) = (Rational64::new(1, 8), Rational64::new(6, 8));
        assert_eq!(cc.vertex.weights(4), (c1 * c1, c0 * c1, c0 * c0));
        assert_eq!((cc.edge_end, cc.edge_side), (c1 / 2, c0 / 2));
        let sw = QuadScheme::by_name("sw-nonpoly-quad").expect("catalogued");
        let (c0, c1) = (Rational64::new(1, 6), Rational64::new(2, 3));
        assert_eq!(sw.vertex.weights(4), (c1 * c1, c0 * c1, c0 * c0));
        assert_eq!((sw.edge_end, sw.edge_side), (c1 / 2, c0 / 2));
    }
}
