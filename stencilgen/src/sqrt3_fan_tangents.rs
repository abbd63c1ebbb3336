//! Tangent masks at a boundary vertex of √3 with Kobbelt's boundary rules (the fan of `K`
//! triangles of `schemes::sqrt3_boundary`), from the eigen-structure of its local matrix: what
//! a boundary vertex's normal is made of, where the parametric derivatives vanish or do not
//! exist (docs/algorithms/sqrt3.md, the spectra table).
//!
//! The ball of fan points within three units of `V` (hex norm in their charts) is closed under
//! the ternary step; its local matrix `A` has the boundary curve's tangent `t = (E_0 - E_K)/2`
//! (the cubic B-spline's derivative) as a left eigenvector for `1/3`. The cross mode `c` is the
//! left eigenvector, independent of `t`, of the largest eigenvalue below 1 that has one: `1/9`
//! at `K = 1`, `2/9` at `K = 2`, the second `1/3` at `K = 3`, `0.379` and `0.402` at `K = 4, 5`
//! (there it leads `t`), and at `K >= 6` the leading cross mode of a vertex without a tangent
//! plane (a choice, as Loop's masks at seven or more triangles). The masks are the
//! combinations of `t` and `c` normalized on the planar reference net that puts sector `s`'s
//! point `(a, b)` at `a e_s + b e_{s+1}`, `e_i = (cos i theta, sin i theta)`,
//! `theta = pi / max(K, 2)` (the half-disk; the quarter-disk at `K = 1`), as Loop's
//! (`crate::triangle_boundary`): the `u` mask maps the net to `e_s`, the `v` mask to `e_{s+1}`,
//! so `du x dv` points to the side of the patch `V, E_s, E_{s+1}`.

use nalgebra::DMatrix;
use schemes::sqrt3_boundary::{BoundaryFan, FanPoint, V};
use schemes::tangent_frame::frame_masks;

use crate::ev_tangents::left_null_space;
use crate::StencilError;

/// Tangent masks at the boundary vertex of a fan, over [`Sqrt3FanTangents::layout`].
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3FanTangents {
    /// The ball of fan points within three units of `V`, `V` first.
    pub layout: Vec<FanPoint>,
    /// The eigenvalue of the cross mode `c` (module docs).
    pub across: f64,
    /// The mask in the direction of `E_s` (the patch's `u`).
    pub du: Vec<f64>,
    /// The mask in the direction of `E_{s+1}` (the patch's `v`).
    pub dv: Vec<f64>,
}

/// Weights below this fraction of a mask's largest are rounding, set to zero.
const ROUNDING: f64 = 1e-12;

/// The radius of the smallest ball the local matrix acts on: closed under the step (a level-1
/// point within three level-1 units of `V` reads level-0 points within three units) and
/// holding every point whose basis function reaches `V` (the support of `psi` reaches 2.5).
pub const FAN_RADIUS: i64 = 3;

/// The ball of fan points within `radius` of `V` (hex norm in their charts, `V` first; at least
/// [`FAN_RADIUS`]) and its local matrix (row `i`: the level-1 point at layout point `i`'s
/// coordinates over the layout's level-0 points). A wider ball adds only smaller eigenvalues.
pub fn fan_local_matrix(
    fan: BoundaryFan,
    radius: i64,
) -> Result<(Vec<FanPoint>, DMatrix<f64>), StencilError> {
    let mut layout = vec![V];
    for s in 0..=i64::from(fan.faces) {
        for b in 0..=radius {
            for a in 0..=radius - b {
                if let Some(p) = fan.canonical(s, (a, b)) {
                    if !layout.contains(&p) {
                        layout.push(p);
                    }
                }
            }
        }
    }
    let n = layout.len();
    let mut a = DMatrix::<f64>::zeros(n, n);
    for (i, &q) in layout.iter().enumerate() {
        for (p, w) in fan.level1_row(q) {
            let j =
                layout
                    .iter()
                    .position(|&x| x == p)
                    .ok_or_else(|| StencilError::OutOfDomain {
                        what: format!(
                            "the fan of {}: {q:?} reads {p:?} outside the ball",
                            fan.faces
                        ),
                    })?;
            a[(i, j)] = w;
        }
    }
    Ok((layout, a))
}

/// The tangent masks of sector `sector` at the boundary vertex with `faces` triangles (module
/// docs).
pub fn sqrt3_fan_tangents(faces: u32, sector: u32) -> Result<Sqrt3FanTangents, StencilError> {
    let failure = |what: &str| StencilError::Inconsistent {
        scheme: "sqrt3 tangents at a boundary vertex".to_owned(),
        n: 0,
        detail: format!("{faces} triangles, sector {sector}: {what}"),
    };
    if faces == 0 || sector >= faces {
        return Err(StencilError::OutOfDomain {
            what: format!("sector {sector} of a boundary vertex with {faces} triangles"),
        });
    }
    let fan = BoundaryFan::new(faces);
    let (layout, a) = fan_local_matrix(fan, FAN_RADIUS)?;
    let n = layout.len();
    let index = |p: FanPoint| layout.iter().position(|&q| q == p);
    let mut t = vec![0.0; n];
    t[index((0, 1, 0)).ok_or_else(|| failure("E_0 is not in the ball"))?] = 0.5;
    t[index((faces, 1, 0)).ok_or_else(|| failure("E_K is not in the ball"))?] = -0.5;
    let schur = nalgebra::linalg::Schur::try_new(a.clone(), 1e-14, 100_000)
        .ok_or_else(|| failure("the eigenvalue iteration did not converge"))?;
    let mut values: Vec<f64> = schur
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.im.abs() < 1e-9 && z.re < 1.0 - 1e-9)
        .map(|z| z.re)
        .collect();
    values.sort_by(|x, y| y.total_cmp(x));
    values.dedup_by(|x, y| (*x - *y).abs() < 1e-9);
    let t_norm2: f64 = t.iter().map(|x| x * x).sum();
    let (across, c) = values
        .iter()
        .find_map(|&lambda| {
            left_null_space(&a, lambda)
                .into_iter()
                .map(|w| {
                    let along: f64 = w.iter().zip(&t).map(|(x, y)| x * y).sum::<f64>() / t_norm2;
                    w.iter()
                        .zip(&t)
                        .map(|(x, y)| x - along * y)
                        .collect::<Vec<f64>>()
                })
                .find(|c| c.iter().map(|x| x * x).sum::<f64>() > 1e-12)
                .map(|c| (lambda, c))
        })
        .ok_or_else(|| failure("no cross-boundary eigenvector"))?;
    let theta = std::f64::consts::PI / f64::from(faces.max(2));
    let e = |i: u32| {
        let x = theta * f64::from(i);
        [x.cos(), x.sin()]
    };
    let net: Vec<(usize, [f64; 2])> = layout
        .iter()
        .enumerate()
        .map(|(i, &(s, a, b))| {
            let (p, q) = (e(s), e(s + 1));
            (
                i,
                [
                    a as f64 * p[0] + b as f64 * q[0],
                    a as f64 * p[1] + b as f64 * q[1],
                ],
            )
        })
        .collect();
    let [mut du, mut dv] =
        frame_masks([&t, &c], &net, [1.0, 1.0], [e(sector), e(sector + 1)], n)
            .ok_or_else(|| failure("the tangent and cross modes do not span the net's plane"))?;
    // The SVD's eigenvectors carry rounding (about 1e-16) on points the modes do not read.
    for mask in [&mut du, &mut dv] {
        let largest = mask.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for x in mask.iter_mut() {
            if x.abs() <= ROUNDING * largest {
                *x = 0.0;
            }
        }
    }
    Ok(Sqrt3FanTangents {
        layout,
        across,
        du,
        dv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two closed forms: with one triangle (`K = 1`) the cross mode is the boundary curve's
    /// second difference `E_0 - 2V + E_K` (its boundary rows give `(3, -6, 3) / 27`, a ninth of
    /// it), eigenvalue `1/9`; at the regular boundary (`K = 3`) the `u` mask of sector 0 is the
    /// boundary tangent itself, since on the lattice net `t` maps to `e_0` exactly.
    #[test]
    fn cross_modes_and_the_regular_boundary() {
        let one = sqrt3_fan_tangents(1, 0).expect("tangents");
        assert!((one.across - 1.0 / 9.0).abs() < 1e-9, "{}", one.across);
        let m = sqrt3_fan_tangents(3, 0).expect("tangents");
        for (i, &p) in m.layout.iter().enumerate() {
            let want = match p {
                (0, 1, 0) => 0.5,
                (3, 1, 0) => -0.5,
                _ => 0.0,
            };
            assert!((m.du[i] - want).abs() < 1e-12, "{p:?}: {}", m.du[i]);
        }
        assert!(sqrt3_fan_tangents(2, 2).is_err());
    }
}
