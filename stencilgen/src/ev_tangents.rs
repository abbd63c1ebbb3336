//! Limit tangent masks at the extraordinary vertex itself, from the subdominant left
//! eigenvectors of the local subdivision matrix (Halstead, Kass and DeRose; Schaefer–Warren
//! section 5.3 points to the eigen-structure for this).
//!
//! The 1-ring `V, E_i, F_i` is invariant under subdivision, so its block `A_1` of `A` carries
//! the tangent plane: if `w A_1 = lambda w` for one of the two largest eigenvalues below 1,
//! then `w . P` is a tangent vector of the limit surface at the vertex. (Interior vertices: the
//! double eigenvalue of Fourier frequencies 1 and v-1, a "cosine" and a "sine" mode. Boundary
//! vertices: the boundary curve's tangent, eigenvalue 1/2, and the cross-boundary mode. Darts:
//! two real eigenvalues, distinct except at valence 4, where 1/2 is double; the reference net
//! is the interior one, so a dart's masks are tangent directions spanning its tangent plane.)
//! Which tangent is "d/du" is a choice of normalization; it is fixed on a reference planar net
//! `V = 0, E_i = (cos t_i, sin t_i), F_i = E_i + E_{i+1}` with `t_i = 2 pi (i-1)/v` (interior)
//! or `pi (i-1)/max(f, 2)` (boundary, f faces): the `u` mask of sector `s` maps that net to the
//! unit vector of `E_{s+1}`, the `v` mask to that of `E_{s+2}`. At valence 4, and at a regular
//! boundary vertex (two faces), the net is the regular grid and the masks are exactly the
//! tensor-product derivatives at the corner; elsewhere they are tangent *directions* (the
//! patch's parametric derivatives at the vertex vanish or diverge like `(2 lambda)^k`).
//! The values are irrational for most valences, so this is f64 only.

use nalgebra::DMatrix;

use schemes::tangent_frame::{frame_masks, quad_edge, quad_net};

use crate::extraordinary_patch::LocalMatrices;
use crate::scalar::rational_to_f64;
use crate::StencilError;

/// The largest eigenvalue below 1 and the `u`, `v` tangent masks at the vertex (`K` weights
/// each, zero beyond the 1-ring).
#[derive(Clone, Debug, PartialEq)]
pub struct EvTangents {
    /// The subdominant eigenvalue of `A`.
    pub lambda: f64,
    /// Tangent mask in the direction of `E_1`.
    pub du: Vec<f64>,
    /// Tangent mask in the direction of `E_2`.
    pub dv: Vec<f64>,
}

/// Compute the tangent masks at the vertex of `matrices`' patch.
pub fn ev_tangents(matrices: &LocalMatrices) -> Result<EvTangents, StencilError> {
    let nb = matrices.neighbourhood;
    let (edges, faces) = (nb.edges() as usize, nb.faces as usize);
    let ring = 1 + edges + faces;
    let a1 = DMatrix::from_fn(ring, ring, |i, j| rational_to_f64(&matrices.a[i][j]));
    let failure = |what: &str| StencilError::Inconsistent {
        scheme: "tangents at the extraordinary vertex".to_owned(),
        n: 0,
        detail: format!("{}: {what}", matrices.describe()),
    };
    let (l1, l2) = subdominant_eigenvalues(&a1).map_err(|e| failure(&e))?;
    // Left eigenvectors spanning the tangent plane: the null spaces of A1^T - lambda I.
    let mut basis: Vec<Vec<f64>> = left_null_space(&a1, l1);
    if (l1 - l2).abs() > 1e-9 {
        basis.truncate(1);
        basis.extend(left_null_space(&a1, l2).into_iter().take(1));
    }
    if basis.len() != 2 {
        return Err(failure(
            "the tangent plane is not spanned by two eigenvectors",
        ));
    }
    let boundary = nb.boundary.is_some();
    let edge = |i: usize| quad_edge(boundary, edges, faces, i);
    let net = quad_net(boundary, edges, faces);
    let sector = matrices.sector as usize;
    let [du, dv] = frame_masks(
        [&basis[0], &basis[1]],
        &net,
        [1.0, 1.0],
        [edge(sector), edge(sector + 1)],
        matrices.size(),
    )
    .ok_or_else(|| failure("the eigenvectors do not span the reference net's plane"))?;
    Ok(EvTangents { lambda: l1, du, dv })
}

/// The two largest eigenvalues of `a1` whose modulus is not 1 (real parts), by a bounded
/// Schur iteration so that a matrix it cannot settle is an error, not a hang.
pub(crate) fn subdominant_eigenvalues(a1: &DMatrix<f64>) -> Result<(f64, f64), String> {
    let schur = nalgebra::linalg::Schur::try_new(a1.clone(), 1e-14, 100_000)
        .ok_or_else(|| "the eigenvalue iteration did not converge".to_owned())?;
    let mut eigenvalues: Vec<f64> = schur
        .complex_eigenvalues()
        .iter()
        .filter(|z| (z.norm() - 1.0).abs() > 1e-9)
        .map(|z| z.re)
        .collect();
    eigenvalues.sort_by(|x, y| y.total_cmp(x));
    match eigenvalues.as_slice() {
        [l1, l2, ..] => Ok((*l1, *l2)),
        _ => Err("no pair of subdominant eigenvalues".to_owned()),
    }
}

/// An orthonormal basis of the left null space of `a - lambda I` (singular values below 1e-8).
pub(crate) fn left_null_space(a: &DMatrix<f64>, lambda: f64) -> Vec<Vec<f64>> {
    let n = a.nrows();
    let m = a.transpose() - DMatrix::identity(n, n) * lambda;
    let svd = m.svd(false, true);
    let Some(v_t) = svd.v_t else {
        return Vec::new();
    };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
    order
        .into_iter()
        .take_while(|&i| svd.singular_values[i] < 1e-8)
        .map(|i| v_t.row(i).iter().copied().collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extraordinary_patch::Neighbourhood;
    use schemes::QuadScheme;

    #[test]
    fn catmull_clark_subdominant_eigenvalue_is_the_known_closed_form() {
        // lambda = (5 + cos(2pi/v) + cos(pi/v) sqrt(18 + 2 cos(2pi/v))) / 16 (Stam 1998, eq. 9).
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        for v in 3..=8u32 {
            let t = ev_tangents(
                &LocalMatrices::new(&cc, Neighbourhood::interior(v), 0).expect("valid"),
            )
            .expect("tangents");
            let c = (2.0 * std::f64::consts::PI / f64::from(v)).cos();
            let h = (std::f64::consts::PI / f64::from(v)).cos();
            let expected = (5.0 + c + h * (18.0 + 2.0 * c).sqrt()) / 16.0;
            assert!(
                (t.lambda - expected).abs() < 1e-12,
                "v = {v}: {} vs {expected}",
                t.lambda
            );
        }
    }

    #[test]
    fn valence_four_masks_are_the_bicubic_corner_derivatives() {
        // d/du of the bicubic at a corner: (1/2)(E_1 - E_3) x (1/6, 4/6, 1/6) across.
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        let t =
            ev_tangents(&LocalMatrices::new(&cc, Neighbourhood::interior(4), 0).expect("valid"))
                .expect("tangents");
        let expected = [
            0.0,
            1.0 / 3.0,
            0.0,
            -1.0 / 3.0,
            0.0,
            1.0 / 12.0,
            -1.0 / 12.0,
            -1.0 / 12.0,
            1.0 / 12.0,
        ];
        for (i, e) in expected.iter().enumerate() {
            assert!((t.du[i] - e).abs() < 1e-12, "du[{i}] = {} vs {e}", t.du[i]);
        }
        assert!((t.dv[2] - 1.0 / 3.0).abs() < 1e-12 && (t.dv[4] + 1.0 / 3.0).abs() < 1e-12);
    }
}
