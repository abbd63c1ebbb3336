//! The true rules, one step at a time, of the families of [`crate::cone_local`] around an
//! interior extraordinary vertex `V`: the modified butterfly's dyadic step and √3's ternary
//! step (two √3 steps). Data only: [`crate::cone_local`] and [`crate::cone_regions`] apply them
//! to build the local matrices and the regions' rows.
//!
//! The rules live here, with the family dispatch ([`ConeRules`]), rather than in the
//! scheme modules ([`crate::butterfly_local`], [`crate::sqrt3_local`]) because the shared
//! row machinery needs them and the scheme modules are built on that machinery: dependencies
//! point from the scheme-specific modules to the shared ones, never back. What the rules are
//! and why they read what they read is in the scheme modules' docs.

use std::collections::BTreeMap;

use crate::cone::{chart_sector, point_name, Weight};
use crate::triangle::{apply_map, lattice_symmetries, TriangleRefinement, NEIGHBOURS};
use crate::triangle_local::{canonical_triangle_point, TrianglePoint};
use crate::{TriangleScheme, TriangleVertexRule, TriangleWeight};

/// The schemes whose extraordinary neighbourhoods are built here, told apart by their rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConeFamily {
    /// The modified butterfly (Zorin, Schröder and Sweldens 1996): interpolatory, dyadic.
    Butterfly,
    /// √3 subdivision (Kobbelt 2000), two √3 steps as one ternary step.
    Sqrt3,
}

impl ConeFamily {
    /// The family whose rules `scheme` has, or why it has none.
    pub fn of(scheme: &TriangleScheme) -> Result<Self, String> {
        if scheme.vertex == TriangleVertexRule::Interpolatory {
            Ok(ConeFamily::Butterfly)
        } else if scheme.vertex == TriangleVertexRule::Sqrt3
            && scheme.refinement == TriangleRefinement::Sqrt3
        {
            Ok(ConeFamily::Sqrt3)
        } else {
            Err(
                "these local matrices are the modified butterfly's (interpolatory rules) or \
                 √3's (Kobbelt 2000: centroids, edge flips)"
                    .to_owned(),
            )
        }
    }

    /// The dilation `λ` of one step: `x -> λx` maps the patch's inner part onto the patch
    /// (2 for the butterfly, 3 for two √3 steps).
    pub fn dilation(self) -> u32 {
        match self {
            ConeFamily::Butterfly => 2,
            ConeFamily::Sqrt3 => 3,
        }
    }

    /// `λ^level`: level-`level` coordinates per level-0 unit.
    pub fn scale(self, level: u32) -> i64 {
        i64::from(self.dilation()).pow(level)
    }
}

/// A linear combination of coarser points making a finer point.
pub(crate) type Combination<T> = Vec<(TrianglePoint, T)>;

/// One step of a family's true rules around `V`, in one number field.
#[derive(Clone, Debug)]
pub(crate) enum ConeRules<T> {
    /// The butterfly's rules ([`ButterflyRules`]; the scheme: [`crate::butterfly_local`]).
    Butterfly(ButterflyRules<T>),
    /// Two √3 steps ([`Sqrt3Rules`]; the scheme: [`crate::sqrt3_local`]).
    Sqrt3(Sqrt3Rules<T>),
}

impl<T: Weight> ConeRules<T> {
    /// The rules of `family` for `scheme` at `valence`; `None` when a weight is irrational in
    /// an exact field, or the scheme lacks the family's refinement.
    pub(crate) fn new(family: ConeFamily, scheme: &TriangleScheme, valence: u32) -> Option<Self> {
        match family {
            ConeFamily::Butterfly => ButterflyRules::new(scheme, valence).map(ConeRules::Butterfly),
            ConeFamily::Sqrt3 => Sqrt3Rules::new(valence).map(ConeRules::Sqrt3),
        }
    }

    /// The valence `K` of `V`.
    pub(crate) fn valence(&self) -> u32 {
        match self {
            ConeRules::Butterfly(r) => r.valence,
            ConeRules::Sqrt3(r) => r.valence,
        }
    }

    /// The level-`(k-1)` combination of the level-`k` point `point`, or the reason the chart
    /// cannot name the stencil.
    pub(crate) fn refine(&self, point: TrianglePoint) -> Result<Combination<T>, String> {
        match self {
            ConeRules::Butterfly(r) => r.refine(point),
            ConeRules::Sqrt3(r) => r.refine(point),
        }
    }
}

/// The modified butterfly's rules at one valence, in one number field.
#[derive(Clone, Debug)]
pub(crate) struct ButterflyRules<T> {
    pub(crate) valence: u32,
    /// `(3/4, [s_0, .., s_{K-1}])` at an edge of `V`; `None` at `K = 6` (regular rule).
    extraordinary: Option<(T, Vec<T>)>,
    /// The regular edge rule of the edge `(0,0)-(1,0)`.
    edge: Vec<((i64, i64), T)>,
}

impl<T: Weight> ButterflyRules<T> {
    /// `None` when a weight is irrational in an exact field.
    pub(crate) fn new(scheme: &TriangleScheme, valence: u32) -> Option<Self> {
        let TriangleRefinement::Dyadic {
            edge,
            edge_denominator,
        } = scheme.refinement
        else {
            return None;
        };
        let extraordinary = if valence == 6 {
            None
        } else {
            let (q, s) = scheme.butterfly_extraordinary(valence)?;
            let s: Option<Vec<T>> = s.into_iter().map(T::from_weight).collect();
            Some((T::from_weight(q)?, s?))
        };
        let edge = edge
            .iter()
            .map(|&(o, w)| {
                Some((
                    o,
                    T::from_weight(TriangleWeight::ratio(w, edge_denominator))?,
                ))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(ButterflyRules {
            valence,
            extraordinary,
            edge,
        })
    }

    /// The level-`(k-1)` combination of the level-`k` point `point`, or the reason the chart
    /// cannot name the stencil.
    pub(crate) fn refine(&self, point: TrianglePoint) -> Result<Combination<T>, String> {
        let TrianglePoint::Sector { s, a, b } = point else {
            return Ok(vec![(TrianglePoint::Centre, T::one_weight())]);
        };
        let si = i64::from(s);
        let Some((p, k)) = edge_of(a, b) else {
            return Ok(vec![(
                canonical_triangle_point(self.valence, si, a / 2, b / 2),
                T::one_weight(),
            )]);
        };
        if let (Some((q, weights)), true) = (&self.extraordinary, p == (0, 0) && k == 0) {
            let mut out = vec![(TrianglePoint::Centre, q.clone())];
            out.extend(weights.iter().enumerate().map(|(j, w)| {
                (
                    TrianglePoint::Sector {
                        s: (s + j as u32) % self.valence,
                        a: 1,
                        b: 0,
                    },
                    w.clone(),
                )
            }));
            return Ok(out);
        }
        let map = lattice_symmetries()[k];
        self.edge
            .iter()
            .map(|(o, w)| {
                let o = apply_map(map, *o);
                let q = (p.0 + o.0, p.1 + o.1);
                let sector = chart_sector(q.0, q.1);
                // At K = 6 the cone is the plane and every chart position is right.
                if self.valence != 6 && q != (0, 0) && !(-1..=2).contains(&sector) {
                    return Err(format!(
                        "the stencil of {} reaches chart sector {sector}, past the cut",
                        point_name(point)
                    ));
                }
                Ok((
                    canonical_triangle_point(self.valence, si, q.0, q.1),
                    w.clone(),
                ))
            })
            .collect()
    }
}

/// The level-0 edge `(p, p + R^k (1, 0))` whose new point is the odd level-1 point `(a, b)`.
pub(crate) fn edge_of(a: i64, b: i64) -> Option<((i64, i64), usize)> {
    match (a.rem_euclid(2), b.rem_euclid(2)) {
        (0, 0) => None,
        (1, 0) => Some((((a - 1) / 2, b / 2), 0)),
        (0, 1) => Some(((a / 2, (b - 1) / 2), 1)),
        _ => Some((((a - 1) / 2, (b + 1) / 2), 5)),
    }
}

/// The six neighbours of a half-level point among the half-level points (level-`(k+1)`
/// coordinates), counter-clockwise: the steps of the lattice `a = b (mod 3)` turned by 30
/// degrees.
pub const HALF_LEVEL_STEPS: [(i64, i64); 6] =
    [(1, 1), (-1, 2), (-2, 1), (-1, -1), (1, -2), (2, -1)];

/// √3's rules at one valence, in one number field.
#[derive(Clone, Debug)]
pub(crate) struct Sqrt3Rules<T> {
    pub(crate) valence: u32,
    /// `(1 - alpha_K, alpha_K / K)` at `V`.
    extraordinary: (T, T),
    /// `(1 - alpha_6, alpha_6 / 6) = (2/3, 1/18)` at every other vertex.
    regular: (T, T),
    /// `1/3`, a centroid's weight per corner.
    third: T,
}

impl<T: Weight> Sqrt3Rules<T> {
    /// `None` when `alpha_K` is irrational in an exact field.
    pub(crate) fn new(valence: u32) -> Option<Self> {
        let pair = |v: u32| {
            let (c, b) = TriangleVertexRule::Sqrt3.weights(v);
            Some((T::from_weight(c)?, T::from_weight(b)?))
        };
        Some(Sqrt3Rules {
            valence,
            extraordinary: pair(valence)?,
            regular: pair(6)?,
            third: T::from_weight(TriangleWeight::ratio(1, 3))?,
        })
    }

    /// A vertex rule: `centre` on `p`, `beta` on each of `ring`.
    fn vertex(
        p: TrianglePoint,
        (centre, beta): &(T, T),
        ring: Vec<TrianglePoint>,
    ) -> Combination<T> {
        let mut out = vec![(p, centre.clone())];
        out.extend(ring.into_iter().map(|q| (q, beta.clone())));
        out
    }

    /// The first √3 step: the half-level point `point` (level-`(k+1)` coordinates,
    /// `a = b (mod 3)`) in level-`k` points (level-`k` coordinates).
    fn first(&self, point: TrianglePoint) -> Result<Combination<T>, String> {
        let TrianglePoint::Sector { s, a, b } = point else {
            let ring = (0..self.valence)
                .map(|s| TrianglePoint::Sector { s, a: 1, b: 0 })
                .collect();
            return Ok(Self::vertex(point, &self.extraordinary, ring));
        };
        let s = i64::from(s);
        let at = |x: i64, y: i64| canonical_triangle_point(self.valence, s, x, y);
        if a % 3 == 0 && b % 3 == 0 {
            let (x, y) = (a / 3, b / 3);
            let ring = NEIGHBOURS
                .iter()
                .map(|&(dx, dy)| at(x + dx, y + dy))
                .collect();
            return Ok(Self::vertex(at(x, y), &self.regular, ring));
        }
        if (a - b).rem_euclid(3) != 0 {
            return Err(format!("{} is not a half-level point", point_name(point)));
        }
        // A centroid: the three of its half-level neighbours that are old vertices.
        Ok(HALF_LEVEL_STEPS
            .iter()
            .map(|&(da, db)| (a + da, b + db))
            .filter(|&(x, y)| x.rem_euclid(3) == 0 && y.rem_euclid(3) == 0)
            .map(|(x, y)| (at(x / 3, y / 3), self.third.clone()))
            .collect())
    }

    /// The second √3 step: the level-`(k+1)` point `point` in half-level points (both in
    /// level-`(k+1)` coordinates).
    fn second(&self, point: TrianglePoint) -> Combination<T> {
        let TrianglePoint::Sector { s, a, b } = point else {
            let ring = (0..self.valence)
                .map(|s| TrianglePoint::Sector { s, a: 1, b: 1 })
                .collect();
            return Self::vertex(point, &self.extraordinary, ring);
        };
        let s = i64::from(s);
        let at = |x: i64, y: i64| canonical_triangle_point(self.valence, s, x, y);
        if (a - b).rem_euclid(3) == 0 {
            let ring = HALF_LEVEL_STEPS
                .iter()
                .map(|&(da, db)| at(a + da, b + db))
                .collect();
            return Self::vertex(point, &self.regular, ring);
        }
        // A centroid of a half-level triangle: its three neighbours on the half level.
        NEIGHBOURS
            .iter()
            .map(|&(da, db)| (a + da, b + db))
            .filter(|&(x, y)| (x - y).rem_euclid(3) == 0)
            .map(|(x, y)| (at(x, y), self.third.clone()))
            .collect()
    }

    /// One ternary step (two √3 steps): the level-`(k+1)` point `point` in level-`k` points.
    pub(crate) fn refine(&self, point: TrianglePoint) -> Result<Combination<T>, String> {
        let mut out: BTreeMap<TrianglePoint, T> = BTreeMap::new();
        for (h, w) in self.second(point) {
            for (p, x) in self.first(h)? {
                let e = out.entry(p).or_insert_with(T::zero);
                *e = e.clone() + w.clone() * x;
            }
        }
        Ok(out.into_iter().collect())
    }
}
