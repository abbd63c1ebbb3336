//! Limit tangent masks at the extraordinary vertex itself, from the subdominant left
//! eigenvectors of the local subdivision matrix (Halstead, Kass and DeRose; Schaefer–Warren
//! section 5.3 points to the eigen-structure for this).
//!
//! The 1-ring `V, E_1..E_v, F_1..F_v` is invariant under subdivision, so its `(2v+1)`-square
//! block `A_1` of `A` carries the tangent plane: if `w A_1 = lambda w` for the subdominant
//! eigenvalue `lambda`, then `w . P` is a tangent vector of the limit surface at the EV. The
//! eigenvalue pair comes from the Fourier frequencies 1 and v-1; its left eigenspace is spanned
//! by a "cosine" and a "sine" mode. The `u` mask is the cosine mode (its weights on `E_i` vary
//! as `cos(2 pi (i-1)/v)`: the direction of `E_1`), the `v` mask the same rotated by one sector
//! (the direction of `E_2`). The scale is fixed by applying the mask to the planar net
//! `V = 0, E_i = (cos t_i, sin t_i), F_i = E_i + E_{i+1}` and asking for the vector `(1, 0)`:
//! at valence 4 this is the regular net and the masks are exactly the bicubic (or tensor
//! product) derivatives at the corner; at other valences they are tangent *directions* (the
//! patch's parametric derivatives at the EV vanish or diverge with `(2 lambda)^k`).
//! The values are irrational for most valences, so this is f64 only.

use nalgebra::DMatrix;

use crate::extraordinary_patch::LocalMatrices;
use crate::scalar::rational_to_f64;
use crate::StencilError;

/// The subdominant eigenvalue and the `u`, `v` tangent masks at the EV (`K` weights each, zero
/// beyond the 1-ring).
#[derive(Clone, Debug, PartialEq)]
pub struct EvTangents {
    /// The subdominant eigenvalue of `A`.
    pub lambda: f64,
    /// Tangent mask in the direction of `E_1`.
    pub du: Vec<f64>,
    /// Tangent mask in the direction of `E_2`.
    pub dv: Vec<f64>,
}

/// Compute the EV tangent masks of `matrices`.
pub fn ev_tangents(matrices: &LocalMatrices) -> Result<EvTangents, StencilError> {
    let v = matrices.valence as usize;
    let ring = 2 * v + 1;
    let a1 = DMatrix::from_fn(ring, ring, |i, j| rational_to_f64(&matrices.a[i][j]));
    let lambda = a1
        .complex_eigenvalues()
        .iter()
        .filter(|z| (z.norm() - 1.0).abs() > 1e-9)
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    let failure = |what: &str| StencilError::Inconsistent {
        scheme: "extraordinary tangents".to_owned(),
        n: 0,
        detail: format!("valence {v}: {what}"),
    };
    // Left eigenvectors: the null space of A1^T - lambda I.
    let m = a1.transpose() - DMatrix::identity(ring, ring) * lambda;
    let svd = m.svd(false, true);
    let v_t = svd.v_t.ok_or_else(|| failure("SVD without vectors"))?;
    let mut order: Vec<usize> = (0..ring).collect();
    order.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
    let null: Vec<Vec<f64>> = order[..2]
        .iter()
        .map(|&i| v_t.row(i).iter().copied().collect())
        .collect();
    if svd.singular_values[order[1]] > 1e-8 {
        return Err(failure("the subdominant eigenvalue is not a double one"));
    }
    let theta = |i: usize| 2.0 * std::f64::consts::PI * (i as f64) / (v as f64);
    let sine = |w: &[f64]| (0..v).map(|i| w[1 + i] * theta(i).sin()).sum::<f64>();
    let (s0, s1) = (sine(&null[0]), sine(&null[1]));
    let mut du: Vec<f64> = null[0]
        .iter()
        .zip(&null[1])
        .map(|(a, b)| s1 * a - s0 * b)
        .collect();
    // Scale: the planar net E_i = (cos t_i, sin t_i), F_i = E_i + E_{i+1} maps to (1, 0).
    let x = |i: usize| theta(i % v).cos();
    let along_u: f64 = (0..v)
        .map(|i| du[1 + i] * x(i) + du[1 + v + i] * (x(i) + x(i + 1)))
        .sum();
    if along_u.abs() < 1e-12 {
        return Err(failure("the cosine mode vanishes"));
    }
    for w in &mut du {
        *w /= along_u;
    }
    let mut dv = vec![0.0; ring];
    for i in 0..v {
        dv[1 + (i + 1) % v] = du[1 + i];
        dv[1 + v + (i + 1) % v] = du[1 + v + i];
    }
    let k = matrices.size();
    du.resize(k, 0.0);
    dv.resize(k, 0.0);
    Ok(EvTangents { lambda, du, dv })
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::QuadScheme;

    #[test]
    fn catmull_clark_subdominant_eigenvalue_is_the_known_closed_form() {
        // lambda = (5 + cos(2pi/v) + cos(pi/v) sqrt(18 + 2 cos(2pi/v))) / 16 (Stam 1998, eq. 9).
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        for v in 3..=8u32 {
            let t = ev_tangents(&LocalMatrices::new(&cc, v)).expect("tangents");
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
        let t = ev_tangents(&LocalMatrices::new(&cc, 4)).expect("tangents");
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
