//! A table face's points two at a time: the point `(i, j)` of a smooth interior patch and its
//! mirror image `(j, i)` across the face's diagonal from one set of sums.
//!
//! The patch around an interior vertex is symmetric under the reflection that swaps its
//! parameters `u` and `v`, which maps its layout onto itself by an involution `sigma`; its
//! stencils follow (the tables hold them exactly so, `f32` for `f32`):
//!
//! ```text
//! w_(j,i)[sigma l] = w_(i,j)[l],   v_(j,i)[sigma l] = u_(i,j)[l],   u_(j,i)[sigma l] = v_(i,j)[l]
//! ```
//!
//! (`w` the position's weights, `u` and `v` the derivatives'). Over the sums `s = q_a + q_b` and
//! differences `d = q_a - q_b` of each pair `b = sigma a` (and the points `q_f` that `sigma`
//! fixes), a point's sum `sum_l w_l q_l` is `E + O` with `E = sum (w_a + w_b)/2 s + sum w_f q_f`
//! and `O = sum (w_a - w_b)/2 d`, and its mirror's is `E - O`: the `K` products of one point
//! serve both. The derivatives pair across: `P_u(i,j) = E_u + O_u` and `P_v(j,i) = E_u - O_u`,
//! `P_v(i,j) = E_v + O_v` and `P_u(j,i) = E_v - O_v`.
//!
//! Why: half of an isolated mesh's faces sum `K = 2N + 8` weights per point and quantity
//! (docs/benchmarks.md); the `n^2 - n` points off the diagonal are most of a face's.

use wide::f32x4;

use crate::scheme::patch::dual_index_in_patch;
use crate::tessellate::kernel::{patch_origin, relative, total_bytes, vec_bytes, Stencils};
use crate::tessellate::lane_stencils::{
    chunk_sums_fixed, unit_cross_x4, LaneSums, LaneWeights, Splat, CHUNK, LANES,
};

/// One group of [`LANES`] points `(i, j)` of the patch with `i >= j`: where they and their
/// mirrors go in the face's order (`u32::MAX`: nowhere, a lane past the face's points or the
/// mirror of a point on the diagonal, which is the point itself).
#[derive(Clone, Debug)]
struct Group {
    at: [u32; LANES],
    mirror_at: [u32; LANES],
}

/// The stencils of one kind of face (table section, face corner, rate) by mirrored pairs.
#[derive(Clone, Debug)]
pub(crate) struct MirrorStencils {
    /// Control points of the patch.
    k: usize,
    /// The basis: the pairs `(a, sigma a)`, `a < sigma a`, then the points `sigma` fixes
    /// (`(f, f)`); the odd sums run over the pairs only.
    even: Vec<(u8, u8)>,
    groups: Vec<Group>,
    /// Per group, the even weights (`even.len()` of them) and the odd (the pairs').
    even_weights: Vec<LaneWeights>,
    odd_weights: Vec<LaneWeights>,
}

/// The patch sizes with a compiled evaluation: `K = 2N + 8` at valences 3, 5 and 6, whose
/// layouts' reflections fix four points (`(K + 4) / 2` even sums, `(K - 4) / 2` odd).
const SIZES: [usize; 3] = [14, 18, 20];

/// The smallest rate paired: below it the groups of four points saved do not pay for the pairs'
/// sums and differences and the points written one by one (at rate 4 the 16 points take three
/// groups instead of four, and the frame took 1.5% more instructions; docs/benchmarks.md).
const MIN_RATE: usize = 5;

impl MirrorStencils {
    /// Its vectors' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        total_bytes([
            vec_bytes(&self.even),
            vec_bytes(&self.groups),
            vec_bytes(&self.even_weights),
            vec_bytes(&self.odd_weights),
        ])
    }

    /// The pairs of a patch's dual stencils `s` at rate `n` (`k` weights a row, the patch's own
    /// grid order) for a face whose corner `corner` is the patch's vertex, or `None` where the
    /// stencils are not mirror images under an involution of the layout fixing four points
    /// (bit for bit), or `k` is not one of [`SIZES`].
    pub(crate) fn new(s: &Stencils, k: usize, n: usize, corner: usize) -> Option<Self> {
        if !SIZES.contains(&k) || n < MIN_RATE {
            return None;
        }
        fn row(w: &[f32], k: usize, n: usize, (i, j): (usize, usize)) -> Option<&[f32]> {
            w.get((j * n + i) * k..(j * n + i + 1) * k)
        }
        let row = |w, i, j| row(w, k, n, (i, j));
        // sigma from the pair of points (1, 0) and (0, 1): each weight found once.
        let (a, b) = (row(s.position, 1, 0)?, row(s.position, 0, 1)?);
        let mut sigma = vec![0usize; k];
        for (l, w) in a.iter().enumerate() {
            let mut found = (0..k).filter(|&m| b[m] == *w);
            sigma[l] = found.next()?;
            if found.next().is_some() {
                return None;
            }
        }
        let fixed = (0..k).filter(|&l| sigma[l] == l).count();
        if fixed != 4 || (0..k).any(|l| sigma[sigma[l]] != l) {
            return None;
        }
        for j in 0..n {
            for i in 0..n {
                let (p, q) = (row(s.position, i, j)?, row(s.position, j, i)?);
                let (pu, pv) = (row(s.du, i, j)?, row(s.dv, i, j)?);
                let (qu, qv) = (row(s.du, j, i)?, row(s.dv, j, i)?);
                for l in 0..k {
                    let m = sigma[l];
                    if q[m] != p[l] || qv[m] != pu[l] || qu[m] != pv[l] {
                        return None;
                    }
                }
            }
        }
        let mut even: Vec<(u8, u8)> = (0..k)
            .filter(|&l| l < sigma[l])
            .map(|l| (l as u8, sigma[l] as u8))
            .collect();
        let pairs = even.len();
        even.extend(
            (0..k)
                .filter(|&l| l == sigma[l])
                .map(|l| (l as u8, l as u8)),
        );
        // Face order of every patch point.
        let mut face_at = vec![0u32; n * n];
        for t in 0..n * n {
            let (pi, pj) = dual_index_in_patch(corner, t % n, t / n, n);
            *face_at.get_mut(pj * n + pi)? = t as u32;
        }
        // The points below the diagonal (i > j), then the diagonal's, LANES a group; the last
        // group's unused lanes repeat its last point (evaluated, not written).
        let points: Vec<(usize, usize)> = (0..n)
            .flat_map(|j| (j + 1..n).map(move |i| (i, j)))
            .chain((0..n).map(|i| (i, i)))
            .collect();
        let mut groups = Vec::new();
        let (mut even_weights, mut odd_weights) = (Vec::new(), Vec::new());
        for chunk in points.chunks(LANES) {
            let point = |lane: usize| chunk[lane.min(chunk.len() - 1)];
            let mut group = Group {
                at: [u32::MAX; LANES],
                mirror_at: [u32::MAX; LANES],
            };
            for (lane, &(i, j)) in chunk.iter().enumerate() {
                group.at[lane] = face_at[j * n + i];
                if i != j {
                    group.mirror_at[lane] = face_at[i * n + j];
                }
            }
            let lane_rows = |w| -> Option<Vec<&[f32]>> {
                (0..LANES)
                    .map(|lane| {
                        let (i, j) = point(lane);
                        row(w, i, j)
                    })
                    .collect()
            };
            let rows = [lane_rows(s.position)?, lane_rows(s.du)?, lane_rows(s.dv)?];
            let weight = |a: usize, b: usize, odd: bool| -> LaneWeights {
                std::array::from_fn(|quantity| {
                    let r = &rows[quantity];
                    f32x4::new(std::array::from_fn(|lane| match (odd, a == b) {
                        (true, _) => (r[lane][a] - r[lane][b]) * 0.5,
                        (false, true) => r[lane][a],
                        (false, false) => (r[lane][a] + r[lane][b]) * 0.5,
                    }))
                })
            };
            for (e, &(a, b)) in even.iter().enumerate() {
                let (a, b) = (usize::from(a), usize::from(b));
                even_weights.push(weight(a, b, false));
                if e < pairs {
                    odd_weights.push(weight(a, b, true));
                }
            }
            groups.push(group);
        }
        Some(MirrorStencils {
            k,
            even,
            groups,
            even_weights,
            odd_weights,
        })
    }

    /// Every point of the face whose patch's control points are the vertices `points` of
    /// `control` (made [`relative`] to the first), into `positions`, `normals` in the face's
    /// order; nothing if they are not `K`.
    pub(crate) fn evaluate_patch(
        &self,
        points: &[u32],
        control: &[[f64; 3]],
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        if points.len() != self.k {
            return;
        }
        let origin = patch_origin(points, control);
        let q = |l: u8| relative(control[points[usize::from(l)] as usize], origin);
        let out = (positions, normals);
        match self.k {
            14 => self.evaluate_fixed::<14, 9, 5>(q, origin, out),
            18 => self.evaluate_fixed::<18, 11, 7>(q, origin, out),
            20 => self.evaluate_fixed::<20, 12, 8>(q, origin, out),
            _ => {}
        }
    }

    /// [`MirrorStencils::evaluate_patch`] with `K` control points, `M` even sums, `P` odd.
    #[inline(always)]
    fn evaluate_fixed<const K: usize, const M: usize, const P: usize>(
        &self,
        q: impl Fn(u8) -> [f32; 3],
        origin: [f64; 3],
        (positions, normals): (&mut [[f32; 3]], &mut [[f32; 3]]),
    ) {
        if self.even.len() != M {
            return;
        }
        let q: [[f32; 3]; K] = std::array::from_fn(|l| q(l as u8));
        let even: [Splat; M] = std::array::from_fn(|e| {
            let (a, b) = self.even[e];
            let (qa, qb) = (q[usize::from(a)], q[usize::from(b)]);
            std::array::from_fn(|c| f32x4::splat(if a == b { qa[c] } else { qa[c] + qb[c] }))
        });
        let odd: [Splat; P] = std::array::from_fn(|e| {
            let (a, b) = self.even[e];
            let (qa, qb) = (q[usize::from(a)], q[usize::from(b)]);
            std::array::from_fn(|c| f32x4::splat(qa[c] - qb[c]))
        });
        let origin = origin.map(|c| c as f32);
        let mut even_sums: [LaneSums; CHUNK] = [[[f32x4::ZERO; 3]; 3]; CHUNK];
        let mut odd_sums: [LaneSums; CHUNK] = [[[f32x4::ZERO; 3]; 3]; CHUNK];
        let chunks = self
            .groups
            .chunks(CHUNK)
            .zip(self.even_weights.chunks(M * CHUNK))
            .zip(self.odd_weights.chunks(P * CHUNK));
        for ((groups, even_weights), odd_weights) in chunks {
            chunk_sums_fixed::<M>(even_weights, &even, origin, &mut even_sums);
            chunk_sums_fixed::<P>(odd_weights, &odd, [0.0; 3], &mut odd_sums);
            for ((group, e), o) in groups.iter().zip(&even_sums).zip(&odd_sums) {
                // Quantity x (position, d/du, d/dv) of the points, E + O, and of their mirrors,
                // E - O, where d/du and d/dv trade places.
                let point = |x: usize| -> [f32x4; 3] { std::array::from_fn(|c| e[x][c] + o[x][c]) };
                let mirror =
                    |x: usize| -> [f32x4; 3] { std::array::from_fn(|c| e[x][c] - o[x][c]) };
                let normal = unit_cross_x4(point(1), point(2));
                write(&group.at, point(0), normal, positions, normals);
                let normal = unit_cross_x4(mirror(2), mirror(1));
                write(&group.mirror_at, mirror(0), normal, positions, normals);
            }
        }
    }
}

/// The points `[x, y, z]` (a point per lane) of `p` and `n` to `positions[at[lane]]` and
/// `normals[at[lane]]`, lanes at `u32::MAX` left out.
#[inline(always)]
fn write(
    at: &[u32; LANES],
    p: [f32x4; 3],
    n: [f32x4; 3],
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let point = |v: [f32x4; 3]| f32x4::transpose([v[0], v[1], v[2], f32x4::ZERO]);
    let (p, n) = (point(p), point(n));
    for ((&t, p), n) in at.iter().zip(p).zip(n) {
        if let (Some(to_p), Some(to_n)) =
            (positions.get_mut(t as usize), normals.get_mut(t as usize))
        {
            let (p, n) = (p.to_array(), n.to_array());
            *to_p = [p[0], p[1], p[2]];
            *to_n = [n[0], n[1], n[2]];
        }
    }
}
