//! The tangent masks at a vertex, normalized on a reference net: the one statement of the
//! convention the tables (`stencilgen`) and exact evaluation (`subtess`) share.
//!
//! At an extraordinary or boundary vertex the parametric derivatives vanish or diverge, so the
//! tables store tangent *masks* instead: two left eigenvectors `w_0`, `w_1` of the local
//! subdivision matrix spanning the tangent plane (the subdominant ones inside, the boundary
//! tangent and the cross mode on a boundary). Only the plane they span is geometric; their
//! lengths and directions are a convention, fixed here: on the planar *reference net* of the
//! vertex's ring (`V = 0`, the neighbours on the unit circle, face points their sums), the `u`
//! mask maps the net to the sector's first edge neighbour and the `v` mask to its second. With
//! `g_i` the image of `w_i` on the net, the masks are `c_0 s_0 w_0 + c_1 s_1 w_1` where
//! `[g_0 g_1] c = target` (Cramer's rule) and `s_i` a per-vector scale (exact evaluation below
//! the top level divides each eigen-component by `(2 lambda_i)^L`).
//!
//! Each scheme builds its own net (the angles, in its own arithmetic, so that the tables stay
//! byte for byte what they were); this module does the rest.

/// Neighbour `i` (modulo `edges`) of a quad vertex's reference net: on the unit circle at
/// `i` times `2 pi / faces` inside, `pi / max(faces, 2)` on a boundary (whose `faces + 1` edge
/// neighbours then span a half-turn).
pub fn quad_edge(boundary: bool, edges: usize, faces: usize, i: usize) -> [f64; 2] {
    let step = if boundary {
        std::f64::consts::PI / faces.max(2) as f64
    } else {
        2.0 * std::f64::consts::PI / faces as f64
    };
    let t = step * ((i % edges) as f64);
    [t.cos(), t.sin()]
}

/// The reference net of a quad vertex's ring `V, E_1..E_edges, F_1..F_faces` (layout indices
/// `0`, `1..=edges`, then the faces): `V = 0`, the edge neighbours at [`quad_edge`], each face
/// point the sum of its two edge neighbours.
pub fn quad_net(boundary: bool, edges: usize, faces: usize) -> Vec<(usize, [f64; 2])> {
    let edge = |i| quad_edge(boundary, edges, faces, i);
    (0..edges)
        .map(|i| (1 + i, edge(i)))
        .chain((0..faces).map(|i| {
            let (e, f) = (edge(i), edge(i + 1));
            (1 + edges + i, [e[0] + f[0], e[1] + f[1]])
        }))
        .collect()
}

/// The image `sum_j w[j] net[j]` of a mask on a reference net given as `(index, point)` pairs,
/// summed in the net's order.
pub fn net_image(w: &[f64], net: &[(usize, [f64; 2])]) -> [f64; 2] {
    net.iter().fold([0.0, 0.0], |acc, &(j, p)| {
        [acc[0] + w[j] * p[0], acc[1] + w[j] * p[1]]
    })
}

/// The combinations of `basis[0]` and `basis[1]` (scaled by `scales`) whose images on `net` are
/// `targets[0]` (the `u` mask) and `targets[1]` (the `v` mask), each padded with zeros to
/// `size`; `None` when the basis' images do not span the plane (|det| <= 1e-12, or NaN).
pub fn frame_masks(
    basis: [&[f64]; 2],
    net: &[(usize, [f64; 2])],
    scales: [f64; 2],
    targets: [[f64; 2]; 2],
    size: usize,
) -> Option<[Vec<f64>; 2]> {
    let (g0, g1) = (net_image(basis[0], net), net_image(basis[1], net));
    let det = g0[0] * g1[1] - g0[1] * g1[0];
    if det.is_nan() || det.abs() <= 1e-12 {
        return None;
    }
    let mask = |target: [f64; 2]| -> Vec<f64> {
        let c0 = scales[0] * (target[0] * g1[1] - target[1] * g1[0]) / det;
        let c1 = scales[1] * (g0[0] * target[1] - g0[1] * target[0]) / det;
        let mut m: Vec<f64> = basis[0]
            .iter()
            .zip(basis[1])
            .map(|(a, b)| c0 * a + c1 * b)
            .collect();
        m.resize(size.max(m.len()), 0.0);
        m
    };
    Some([mask(targets[0]), mask(targets[1])])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the valence-4 net (E_i at 0, 90, 180, 270 degrees) any two independent masks combine
    /// into masks whose images are the targets, exactly.
    #[test]
    fn masks_map_the_net_to_their_targets() {
        let edge = |i: usize| {
            let t = std::f64::consts::FRAC_PI_2 * (i % 4) as f64;
            [t.cos(), t.sin()]
        };
        // Ring V, E_1..E_4: the net holds the edge neighbours.
        let net: Vec<(usize, [f64; 2])> = (0..4).map(|i| (1 + i, edge(i))).collect();
        // Two independent masks (not the answer): E_1 + E_2 and E_2 - E_4.
        let w0 = [0.0, 1.0, 1.0, 0.0, 0.0];
        let w1 = [0.0, 0.0, 1.0, 0.0, -1.0];
        let [du, dv] = frame_masks([&w0, &w1], &net, [1.0, 1.0], [edge(0), edge(1)], 7)
            .expect("they span the plane");
        assert_eq!((du.len(), dv.len()), (7, 7));
        for (mask, target) in [(&du, edge(0)), (&dv, edge(1))] {
            let image = net_image(mask, &net);
            assert!((image[0] - target[0]).abs() < 1e-15 && (image[1] - target[1]).abs() < 1e-15);
        }
        // A scale multiplies its eigen-component.
        let [scaled, _] =
            frame_masks([&w0, &w1], &net, [2.0, 2.0], [edge(0), edge(1)], 5).expect("spans");
        for (a, b) in scaled.iter().zip(&du) {
            assert!((a - 2.0 * b).abs() < 1e-15);
        }
        // Parallel images span nothing.
        assert!(frame_masks([&w0, &w0], &net, [1.0, 1.0], [edge(0), edge(1)], 5).is_none());
    }
}
