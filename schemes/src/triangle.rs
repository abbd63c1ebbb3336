//! Triangle subdivision schemes as data: Loop, the modified butterfly and √3.
//!
//! **The lattice.** A regular triangle mesh is the lattice `Z^2` in *skew* coordinates: the
//! point `(a, b)` sits at `a e_1 + b e_2` with `e_1 = (1, 0)`, `e_2 = (1/2, √3/2)`, and its six
//! neighbours are [`NEIGHBOURS`] `(1,0), (0,1), (-1,1), (-1,0), (0,-1), (1,-1)` in
//! counter-clockwise order. The triangles are `(a,b), (a+1,b), (a,b+1)` ("up") and
//! `(a+1,b), (a,b+1), (a+1,b+1)` ("down"), so the face `(0,0), (1,0), (0,1)` is parameterized
//! barycentrically by the points `(i/n, j/n)`, `i + j <= n` (the convention). The
//! twelve symmetries of the lattice ([`lattice_symmetries`]) are the powers of the rotation by
//! 60 degrees `(a, b) -> (-b, a + b)` and the reflection `(a, b) -> (b, a)`.
//!
//! **Masks.** A uniform scheme with dilation `d` has a mask `s_i`, `i in Z^2`, with
//! `phi(x) = sum_i s_i phi(d x - i)` (Schaefer–Warren eq. (3), in two variables, section 5.1):
//! `s_i` is the weight of the coarse vertex `0` in the fine point at `i / d`. Loop and the
//! butterfly are dyadic (`d = 2`, one step splits each triangle in four). √3 (Kobbelt 2000)
//! rotates the lattice by 30 degrees in one step; two steps are a ternary scheme (`d = 3`)
//! aligned with the original lattice (Schaefer–Warren section 5.1), which is how it is
//! described here ([`TriangleScheme::regular_mask`]).
//!
//! **Irrational weights.** The extraordinary rules of original Loop, the butterfly and √3 use
//! `cos(2π/v)`, which is rational only for `v in {1, 2, 3, 4, 6}` (Niven's theorem). Weights are
//! [`TriangleWeight`]s: an f64 value always, the exact rational where there is one. Warren's
//! weights for Loop (`beta = 3/(8v)`, `3/16` at `v = 3`) are rational at every valence.

use std::collections::BTreeMap;
use std::ops::{Add, Mul, Sub};

use num_rational::Rational64;
use num_traits::{ToPrimitive, Zero};

/// The six neighbours of `(0, 0)` on the triangular lattice, counter-clockwise from `(1, 0)`.
pub const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// A lattice map `(a, b) -> (m[0] a + m[1] b, m[2] a + m[3] b)`.
pub type LatticeMap = [i64; 4];

/// Apply a lattice map to a point.
pub fn apply_map(m: LatticeMap, (a, b): (i64, i64)) -> (i64, i64) {
    (m[0] * a + m[1] * b, m[2] * a + m[3] * b)
}

/// The twelve symmetries of the triangular lattice (the dihedral group D6) in skew
/// coordinates: `R^k` and `R^k F` for the rotation `R (a, b) = (-b, a + b)` by 60 degrees and
/// the reflection `F (a, b) = (b, a)`. The identity comes first.
pub fn lattice_symmetries() -> [LatticeMap; 12] {
    let compose = |p: LatticeMap, q: LatticeMap| -> LatticeMap {
        [
            p[0] * q[0] + p[1] * q[2],
            p[0] * q[1] + p[1] * q[3],
            p[2] * q[0] + p[3] * q[2],
            p[2] * q[1] + p[3] * q[3],
        ]
    };
    let rotation = [0, -1, 1, 1];
    let reflection = [0, 1, 1, 0];
    let mut out = [[1, 0, 0, 1]; 12];
    for k in 1..6 {
        out[k] = compose(rotation, out[k - 1]);
    }
    for k in 0..6 {
        out[6 + k] = compose(out[k], reflection);
    }
    out
}

/// A subdivision weight: always its f64 value, and the exact rational when it is rational.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleWeight {
    /// The exact value, `None` when it is irrational (a `cos(2π j/v)` that is not rational).
    pub exact: Option<Rational64>,
    /// The value in f64 (the nearest double to the exact value when there is one).
    pub value: f64,
}

impl TriangleWeight {
    /// A rational weight.
    pub fn rational(r: Rational64) -> Self {
        TriangleWeight {
            exact: Some(r),
            value: r.to_f64().unwrap_or(f64::NAN),
        }
    }

    /// `p / q` as a weight.
    pub fn ratio(p: i64, q: i64) -> Self {
        Self::rational(Rational64::new(p, q))
    }

    /// `cos(2π j / v)`: exact when the angle is a multiple of π/3 or π/2 (the only rational
    /// values of the cosine at rational multiples of π, by Niven's theorem), f64 otherwise.
    pub fn cos_2pi(j: i64, v: i64) -> Self {
        let r = Rational64::new(j.rem_euclid(v), v);
        let exact = match (*r.numer(), *r.denom()) {
            (0, 1) => Some(Rational64::from_integer(1)),
            (1, 2) => Some(Rational64::from_integer(-1)),
            (1, 4) | (3, 4) => Some(Rational64::zero()),
            (1, 3) | (2, 3) => Some(Rational64::new(-1, 2)),
            (1, 6) | (5, 6) => Some(Rational64::new(1, 2)),
            _ => None,
        };
        match exact {
            Some(e) => Self::rational(e),
            None => TriangleWeight {
                exact: None,
                value: (2.0 * std::f64::consts::PI * j as f64 / v as f64).cos(),
            },
        }
    }

    /// Whether the weight is rational.
    pub fn is_rational(&self) -> bool {
        self.exact.is_some()
    }
}

impl Add for TriangleWeight {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        match (self.exact, o.exact) {
            (Some(a), Some(b)) => Self::rational(a + b),
            _ => TriangleWeight {
                exact: None,
                value: self.value + o.value,
            },
        }
    }
}

impl Sub for TriangleWeight {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        match (self.exact, o.exact) {
            (Some(a), Some(b)) => Self::rational(a - b),
            _ => TriangleWeight {
                exact: None,
                value: self.value - o.value,
            },
        }
    }
}

impl Mul for TriangleWeight {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        match (self.exact, o.exact) {
            (Some(a), Some(b)) => Self::rational(a * b),
            _ => TriangleWeight {
                exact: None,
                value: self.value * o.value,
            },
        }
    }
}

/// The vertex rule of an approximating triangle scheme at valence `v`:
/// `V' = (1 - v beta) V + beta sum E_i`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleVertexRule {
    /// Loop with Warren's weights (Warren, *Subdivision methods for geometric design*, 1995):
    /// `beta = 3/(8v)` for `v > 3`, `beta = 3/16` for `v = 3`; rational at every valence.
    LoopWarren,
    /// Loop's original weights (Loop 1987):
    /// `beta = (1/v) (5/8 - (3/8 + (1/4) cos(2π/v))^2)`; rational only for `v in {3, 4, 6}`.
    LoopOriginal,
    /// √3 (Kobbelt 2000, eq. (2)): `V' = (1 - alpha) V + (alpha / v) sum E_i` with
    /// `alpha = (4 - 2 cos(2π/v)) / 9`; rational only for `v in {3, 4, 6}`.
    Sqrt3,
    /// Interpolatory (the butterfly): `V' = V`.
    Interpolatory,
}

impl TriangleVertexRule {
    /// `(centre, beta)`: the weight of `V` and of each of its `v` neighbours in `V'`.
    pub fn weights(self, valence: u32) -> (TriangleWeight, TriangleWeight) {
        let v = i64::from(valence);
        let one = TriangleWeight::ratio(1, 1);
        let beta = match self {
            TriangleVertexRule::LoopWarren if v == 3 => TriangleWeight::ratio(3, 16),
            TriangleVertexRule::LoopWarren => TriangleWeight::ratio(3, 8 * v),
            TriangleVertexRule::LoopOriginal => {
                let t = TriangleWeight::ratio(3, 8)
                    + TriangleWeight::ratio(1, 4) * TriangleWeight::cos_2pi(1, v);
                (TriangleWeight::ratio(5, 8) - t * t) * TriangleWeight::ratio(1, v)
            }
            TriangleVertexRule::Sqrt3 => {
                let alpha = (TriangleWeight::ratio(4, 1)
                    - TriangleWeight::ratio(2, 1) * TriangleWeight::cos_2pi(1, v))
                    * TriangleWeight::ratio(1, 9);
                alpha * TriangleWeight::ratio(1, v)
            }
            TriangleVertexRule::Interpolatory => TriangleWeight::ratio(0, 1),
        };
        (one - TriangleWeight::ratio(v, 1) * beta, beta)
    }
}

/// How one step refines the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleRefinement {
    /// 1-to-4 split (Loop, butterfly): a new point on every edge by the edge rule.
    Dyadic {
        /// The edge rule on the regular lattice for the edge `(0,0)-(1,0)`: `(offset, weight)`.
        edge: &'static [((i64, i64), i64)],
        /// Common denominator of the edge rule's weights.
        edge_denominator: i64,
    },
    /// √3 (Kobbelt 2000): a new point at every face centroid, old edges flipped; two steps are
    /// a ternary 1-to-9 split aligned with the original lattice.
    Sqrt3,
}

/// Loop's regular edge rule: 3/8 at the ends, 1/8 at the two opposite vertices.
const LOOP_EDGE: [((i64, i64), i64); 4] = [((0, 0), 3), ((1, 0), 3), ((0, 1), 1), ((1, -1), 1)];

/// The butterfly's regular edge rule (Dyn, Levin and Gregory 1990; the modified butterfly of
/// Zorin, Schröder and Sweldens 1996 uses it at regular edges): 1/2 at the ends, 1/8 at the
/// two opposite vertices, -1/16 at the four wing vertices. It is the ten-point rule of Zorin et
/// al. (`1/2 - w, 1/8 + 2w, -1/16 - w, w`) with their tension `w = 0`, which is Dyn–Levin–
/// Gregory's rule (`1/2, 2w, -w`) with their tension `w = 1/16`.
const BUTTERFLY_EDGE: [((i64, i64), i64); 8] = [
    ((0, 0), 8),
    ((1, 0), 8),
    ((0, 1), 2),
    ((1, -1), 2),
    ((-1, 1), -1),
    ((1, 1), -1),
    ((0, -1), -1),
    ((2, -1), -1),
];

/// A uniform mask on the triangular lattice: `phi(x) = sum_i s_i phi(d x - i)`
/// (Schaefer–Warren eq. (3) and section 5.1), in skew coordinates.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LatticeMask {
    /// Name, for messages.
    pub name: String,
    /// The dilation `d` (2 for dyadic schemes, 3 for two steps of √3).
    pub dilation: u32,
    /// The nonzero entries `((i_1, i_2), s_i)`, sorted by index.
    pub weights: Vec<((i64, i64), Rational64)>,
}

impl LatticeMask {
    /// The convex hull of the mask's indices, counter-clockwise, without collinear points.
    /// The support of `phi` is this polygon scaled by `1/(d - 1)` (it is the fixed set of
    /// `S = (S + hull) / d`).
    pub fn hull(&self) -> Vec<(i64, i64)> {
        let mut pts: Vec<(i64, i64)> = self.weights.iter().map(|(i, _)| *i).collect();
        pts.sort_unstable();
        pts.dedup();
        if pts.len() < 3 {
            return pts;
        }
        let cross = |o: (i64, i64), a: (i64, i64), b: (i64, i64)| {
            (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
        };
        let chain = |iter: &mut dyn Iterator<Item = (i64, i64)>| {
            let mut h: Vec<(i64, i64)> = Vec::new();
            for p in iter {
                while h.len() >= 2 && cross(h[h.len() - 2], h[h.len() - 1], p) <= 0 {
                    h.pop();
                }
                h.push(p);
            }
            h.pop();
            h
        };
        let mut lower = chain(&mut pts.iter().copied());
        let upper = chain(&mut pts.iter().rev().copied());
        lower.extend(upper);
        lower
    }

    /// Sum of the entries (`d^2` for a convergent scheme: each coarse point's weights).
    pub fn sum(&self) -> Rational64 {
        self.weights.iter().map(|(_, w)| *w).sum()
    }
}

/// A triangle subdivision scheme, as data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TriangleScheme {
    /// Catalogue name.
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// The vertex rule.
    pub vertex: TriangleVertexRule,
    /// How a step refines the mesh (with the regular edge rule of dyadic schemes).
    pub refinement: TriangleRefinement,
    /// Whether the regular basis function is piecewise polynomial (Loop: the quartic box
    /// spline on the three-direction mesh).
    pub polynomial: bool,
    /// Whether the scheme interpolates its control points.
    pub interpolatory: bool,
}

/// Names of the triangle schemes [`TriangleScheme::by_name`] knows.
pub const TRIANGLE_SCHEME_NAMES: [&str; 4] = ["loop", "loop-original", "butterfly", "sqrt3"];

impl TriangleScheme {
    /// A scheme from the catalogue ([`TRIANGLE_SCHEME_NAMES`]).
    pub fn by_name(name: &str) -> Option<Self> {
        let loop_refinement = TriangleRefinement::Dyadic {
            edge: &LOOP_EDGE,
            edge_denominator: 8,
        };
        match name {
            "loop" => Some(TriangleScheme {
                name: "loop",
                description: "Loop (1987) with Warren's rational weights beta = 3/(8v) (3/16 at v = 3); quartic box spline in regular regions",
                vertex: TriangleVertexRule::LoopWarren,
                refinement: loop_refinement,
                polynomial: true,
                interpolatory: false,
            }),
            "loop-original" => Some(TriangleScheme {
                name: "loop-original",
                description: "Loop (1987) with the original weights (cos 2pi/v: irrational except at v = 3, 4, 6); quartic box spline in regular regions",
                vertex: TriangleVertexRule::LoopOriginal,
                refinement: loop_refinement,
                polynomial: true,
                interpolatory: false,
            }),
            "butterfly" => Some(TriangleScheme {
                name: "butterfly",
                description: "modified butterfly (Zorin, Schroeder, Sweldens 1996), interpolatory, non-polynomial; extraordinary rules use cos 2pi/v",
                vertex: TriangleVertexRule::Interpolatory,
                refinement: TriangleRefinement::Dyadic {
                    edge: &BUTTERFLY_EDGE,
                    edge_denominator: 16,
                },
                polynomial: false,
                interpolatory: true,
            }),
            "sqrt3" => Some(TriangleScheme {
                name: "sqrt3",
                description: "sqrt(3) subdivision (Kobbelt 2000), non-polynomial; solved as its two-step ternary form (Schaefer-Warren section 5.1)",
                vertex: TriangleVertexRule::Sqrt3,
                refinement: TriangleRefinement::Sqrt3,
                polynomial: false,
                interpolatory: false,
            }),
            _ => None,
        }
    }

    /// The dilation of [`Self::regular_mask`]: 2, or 3 for √3's two-step form.
    pub fn dilation(&self) -> u32 {
        match self.refinement {
            TriangleRefinement::Dyadic { .. } => 2,
            TriangleRefinement::Sqrt3 => 3,
        }
    }

    /// The regular mask (all vertices of valence 6), built from the rules.
    ///
    /// Dyadic schemes: `s_{2j}` is the vertex rule's weight of `0` in `V'_j` (the centre weight
    /// at `j = 0`, `beta` at the six neighbours), `s_{2p + e}` the edge rule's weight of `0` in
    /// the point of the edge `(p, p + e)` (the rule for `(0,0)-(1,0)` carried to the edge
    /// directions `(0,1)` and `(-1,1)` by rotations). √3: two steps of Kobbelt's rules
    /// (face point = centroid, vertex rule at valence 6 with `alpha = 1/3`) applied to the
    /// data `delta_0`, read on the lattice `Z^2 / 3`.
    pub fn regular_mask(&self) -> LatticeMask {
        let (centre, beta) = self.vertex.weights(6);
        let rational = |w: TriangleWeight| w.exact.unwrap_or_else(Rational64::zero);
        let mut weights: BTreeMap<(i64, i64), Rational64> = BTreeMap::new();
        match self.refinement {
            TriangleRefinement::Dyadic {
                edge,
                edge_denominator,
            } => {
                *weights.entry((0, 0)).or_default() += rational(centre);
                for (a, b) in NEIGHBOURS {
                    *weights.entry((2 * a, 2 * b)).or_default() += rational(beta);
                }
                // The rotations R^0, R^1, R^2 carry (1, 0) to (1,0), (0,1), (-1,1).
                for map in &lattice_symmetries()[0..3] {
                    let e = apply_map(*map, (1, 0));
                    for &(offset, w) in edge {
                        let o = apply_map(*map, offset);
                        *weights.entry((e.0 - 2 * o.0, e.1 - 2 * o.1)).or_default() +=
                            Rational64::new(w, edge_denominator);
                    }
                }
            }
            TriangleRefinement::Sqrt3 => {
                weights = sqrt3_two_steps(rational(centre), rational(beta));
            }
        }
        LatticeMask {
            name: self.name.to_owned(),
            dilation: self.dilation(),
            weights: weights.into_iter().filter(|(_, w)| !w.is_zero()).collect(),
        }
    }

    /// The butterfly's edge rule at an edge whose one end `V` has valence `v != 6` and whose
    /// other end is regular (Zorin, Schröder and Sweldens 1996): `(q, [s_0, .., s_{v-1}])`,
    /// the weight of `V` and of its neighbours counter-clockwise from the edge's other end
    /// `s_0`. `v = 3`: `5/12, -1/12, -1/12`; `v = 4`: `3/8, 0, -1/8, 0`; `v >= 5`:
    /// `s_j = (1/4 + cos(2π j/v) + (1/2) cos(4π j/v)) / v`; `q = 3/4`. `None` for other schemes.
    pub fn butterfly_extraordinary(
        &self,
        valence: u32,
    ) -> Option<(TriangleWeight, Vec<TriangleWeight>)> {
        if self.vertex != TriangleVertexRule::Interpolatory {
            return None;
        }
        let v = i64::from(valence);
        let s = match valence {
            3 => vec![
                TriangleWeight::ratio(5, 12),
                TriangleWeight::ratio(-1, 12),
                TriangleWeight::ratio(-1, 12),
            ],
            4 => vec![
                TriangleWeight::ratio(3, 8),
                TriangleWeight::ratio(0, 1),
                TriangleWeight::ratio(-1, 8),
                TriangleWeight::ratio(0, 1),
            ],
            _ => (0..v)
                .map(|j| {
                    (TriangleWeight::ratio(1, 4)
                        + TriangleWeight::cos_2pi(j, v)
                        + TriangleWeight::ratio(1, 2) * TriangleWeight::cos_2pi(2 * j, v))
                        * TriangleWeight::ratio(1, v)
                })
                .collect(),
        };
        Some((TriangleWeight::ratio(3, 4), s))
    }
}

/// Two regular √3 steps of the data `delta_0` (Kobbelt 2000): the ternary mask.
///
/// Positions are kept in units of `1/3`: the coarse lattice is `3 Z^2`, the lattice after one
/// step is `L_1 = {(a, b) : a = b (mod 3)}` (the old points and the centroids of the old
/// triangles, a lattice rotated by 30 degrees with spacing `1/√3`), and after two steps all of
/// `Z^2`. The centroid of a triangle of one level is the new point whose three corners are its
/// neighbours at distance (spacing / √3): for the coarse level the `L_1` steps
/// `±(1,1), ±(-1,2), ±(-2,1)`, for `L_1` the unit steps [`NEIGHBOURS`].
fn sqrt3_two_steps(centre: Rational64, beta: Rational64) -> BTreeMap<(i64, i64), Rational64> {
    let l1_steps: [(i64, i64); 6] = [(1, 1), (-1, 2), (-2, 1), (-1, -1), (1, -2), (2, -1)];
    let coarse_steps: Vec<(i64, i64)> = NEIGHBOURS.iter().map(|&(a, b)| (3 * a, 3 * b)).collect();
    let step = |data: &BTreeMap<(i64, i64), Rational64>,
                old: &dyn Fn((i64, i64)) -> bool,
                old_steps: &[(i64, i64)],
                centroid_steps: &[(i64, i64)]| {
        let at = |p: (i64, i64)| data.get(&p).copied().unwrap_or_else(Rational64::zero);
        let mut candidates: Vec<(i64, i64)> = Vec::new();
        for &p in data.keys() {
            candidates.push(p);
            for d in old_steps.iter().chain(centroid_steps) {
                candidates.push((p.0 + d.0, p.1 + d.1));
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        let mut out = BTreeMap::new();
        for p in candidates {
            let value = if old(p) {
                old_steps.iter().fold(centre * at(p), |acc, d| {
                    acc + beta * at((p.0 + d.0, p.1 + d.1))
                })
            } else {
                centroid_steps
                    .iter()
                    .map(|d| (p.0 + d.0, p.1 + d.1))
                    .filter(|&q| old(q))
                    .fold(Rational64::zero(), |acc, q| {
                        acc + at(q) * Rational64::new(1, 3)
                    })
            };
            if !value.is_zero() {
                out.insert(p, value);
            }
        }
        out
    };
    let delta = BTreeMap::from([((0, 0), Rational64::from_integer(1))]);
    let coarse = |p: (i64, i64)| p.0.rem_euclid(3) == 0 && p.1.rem_euclid(3) == 0;
    let in_l1 = |p: (i64, i64)| (p.0 - p.1).rem_euclid(3) == 0;
    let level1 = step(&delta, &coarse, &coarse_steps, &l1_steps);
    step(&level1, &in_l1, &l1_steps, &NEIGHBOURS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetries_are_twelve_distinct_lattice_automorphisms() {
        let maps = lattice_symmetries();
        for (i, m) in maps.iter().enumerate() {
            assert_eq!((m[0] * m[3] - m[1] * m[2]).abs(), 1);
            let mut image: Vec<_> = NEIGHBOURS.iter().map(|&p| apply_map(*m, p)).collect();
            image.sort_unstable();
            let mut n = NEIGHBOURS.to_vec();
            n.sort_unstable();
            assert_eq!(image, n, "map {i} permutes the neighbours");
            assert!(maps[..i].iter().all(|o| o != m), "map {i} repeats");
        }
    }

    #[test]
    fn vertex_rules_are_affine_and_rational_where_cos_is() {
        for v in 3..=12u32 {
            for rule in [
                TriangleVertexRule::LoopWarren,
                TriangleVertexRule::LoopOriginal,
                TriangleVertexRule::Sqrt3,
            ] {
                let (c, b) = rule.weights(v);
                assert!((c.value + f64::from(v) * b.value - 1.0).abs() < 1e-15);
                let rational = rule == TriangleVertexRule::LoopWarren || matches!(v, 3 | 4 | 6);
                assert_eq!(b.is_rational(), rational, "{rule:?} v = {v}");
            }
        }
        // Warren (1995): 3/16 at v = 3, 3/(8v) above; Loop's original agrees at v = 3 and 6.
        assert_eq!(
            TriangleVertexRule::LoopWarren.weights(3).1.exact,
            Some(Rational64::new(3, 16))
        );
        assert_eq!(
            TriangleVertexRule::LoopOriginal.weights(3).1.exact,
            Some(Rational64::new(3, 16))
        );
        assert_eq!(
            TriangleVertexRule::LoopOriginal.weights(6).1.exact,
            Some(Rational64::new(1, 16))
        );
        // Kobbelt (2000): alpha_6 = (4 - 1)/9 = 1/3, so beta = 1/18.
        assert_eq!(
            TriangleVertexRule::Sqrt3.weights(6).1.exact,
            Some(Rational64::new(1, 18))
        );
    }

    #[test]
    fn regular_masks_sum_to_d_squared_and_are_symmetric() {
        for name in TRIANGLE_SCHEME_NAMES {
            let s = TriangleScheme::by_name(name).expect("catalogued");
            let mask = s.regular_mask();
            let d = i64::from(mask.dilation);
            assert_eq!(mask.sum(), Rational64::from_integer(d * d), "{name}");
            let lookup: BTreeMap<_, _> = mask.weights.iter().copied().collect();
            for m in lattice_symmetries() {
                for (i, w) in &mask.weights {
                    assert_eq!(lookup.get(&apply_map(m, *i)), Some(w), "{name} {m:?}");
                }
            }
        }
    }

    #[test]
    fn butterfly_extraordinary_rules_sum_to_one() {
        let b = TriangleScheme::by_name("butterfly").expect("catalogued");
        for v in 3..=8u32 {
            let (q, s) = b.butterfly_extraordinary(v).expect("butterfly");
            let sum = s.iter().fold(q, |acc, w| acc + *w);
            assert!((sum.value - 1.0).abs() < 1e-14, "v = {v}");
            assert_eq!(sum.is_rational(), matches!(v, 3 | 4 | 6), "v = {v}");
        }
    }
}
