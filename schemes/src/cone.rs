//! What every scheme's neighbourhood of an interior extraordinary vertex shares on the
//! `K`-valent cone of [`crate::triangle_local`] (Schaefer–Warren sections 5.2–5.3): the layout
//! ball around the patch `V, E_0, E_1`, its order, point names, the separating-axis test on
//! which the regular-tile and region tests rest, and the number fields the local matrices are
//! built in. Used by [`crate::butterfly_local`], [`crate::butterfly_regions`],
//! [`crate::sqrt3_local`] and [`crate::sqrt3_regions`], so the conventions cannot drift apart.

use std::collections::{HashMap, VecDeque};
use std::ops::{Add, Mul};

use num_bigint::BigInt;
use num_rational::{BigRational, Rational64};
use num_traits::Zero;

use crate::triangle::NEIGHBOURS;
use crate::triangle_local::{canonical_triangle_point, TrianglePoint};
use crate::TriangleWeight;

/// The graph distance from `{V, E_0, E_1}` that every layout reaches: the smallest that works
/// for the butterfly and for √3 (why: [`crate::butterfly_local`], [`crate::sqrt3_local`]).
pub const LAYOUT_RADIUS: u32 = 2;

/// The graph-distance ball of radius `radius` around `{V, E_0, E_1}` on the cone, ordered by
/// ring (distance from `V`), then sector, then `b`.
pub(crate) fn layout_ball(valence: u32, radius: u32) -> Vec<TrianglePoint> {
    let neighbours = |p: TrianglePoint| -> Vec<TrianglePoint> {
        match p {
            TrianglePoint::Centre => (0..valence)
                .map(|s| TrianglePoint::Sector { s, a: 1, b: 0 })
                .collect(),
            TrianglePoint::Sector { s, a, b } => NEIGHBOURS
                .iter()
                .map(|&(da, db)| canonical_triangle_point(valence, i64::from(s), a + da, b + db))
                .collect(),
        }
    };
    let mut distance: HashMap<TrianglePoint, u32> = HashMap::new();
    let mut queue = VecDeque::new();
    for p in [
        TrianglePoint::Centre,
        TrianglePoint::Sector { s: 0, a: 1, b: 0 },
        TrianglePoint::Sector {
            s: 1 % valence,
            a: 1,
            b: 0,
        },
    ] {
        distance.insert(p, 0);
        queue.push_back(p);
    }
    while let Some(p) = queue.pop_front() {
        let d = distance[&p];
        if d == radius {
            continue;
        }
        for q in neighbours(p) {
            if let std::collections::hash_map::Entry::Vacant(e) = distance.entry(q) {
                e.insert(d + 1);
                queue.push_back(q);
            }
        }
    }
    let mut points: Vec<TrianglePoint> = distance.into_keys().collect();
    points.sort_by_key(|&p| layout_key(p));
    points
}

/// The order of every butterfly layout (the EV patch's and each region's,
/// [`crate::butterfly_regions`]): `V` first, then by ring `a + b`, then sector, then `b`.
pub fn layout_key(p: TrianglePoint) -> (i64, i64, i64) {
    match p {
        TrianglePoint::Centre => (0, 0, 0),
        TrianglePoint::Sector { s, a, b } => (a + b, i64::from(s), b),
    }
}

/// Names of layout points: `V`, or `(a,b)_s`.
pub fn point_name(p: TrianglePoint) -> String {
    match p {
        TrianglePoint::Centre => "V".to_owned(),
        TrianglePoint::Sector { s, a, b } => format!("({a},{b})_{s}"),
    }
}

/// The number of 60-degree chart sectors, counter-clockwise from `(1, 0)`, between the chart's
/// first sector and the lattice point `(a, b) != (0, 0)`: `0` for `a >= 1, b >= 0`, `1` for the
/// next wedge, `-1` for the one clockwise, ... in `-2..=3` (the chart's cut is the ray at 180
/// degrees, sector 3). The rotation is the one [`canonical_triangle_point`] applies.
pub fn chart_sector(a: i64, b: i64) -> i64 {
    let (mut a, mut b, mut s) = (a, b, 0);
    while !(a >= 1 && b >= 0) {
        if a == 0 && b == 0 {
            return 0;
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a + b);
        } else {
            (s, a, b) = (s + 1, a + b, -a);
        }
    }
    s
}

/// The number fields the matrices are built in: f64 and exact rationals.
pub(crate) trait Weight: Clone + Zero + Add<Output = Self> + Mul<Output = Self> {
    /// The weight in this field, `None` if it is irrational and the field exact.
    fn from_weight(w: TriangleWeight) -> Option<Self>;
    /// `1`.
    fn one_weight() -> Self;
}

impl Weight for f64 {
    fn from_weight(w: TriangleWeight) -> Option<Self> {
        Some(w.value)
    }
    fn one_weight() -> Self {
        1.0
    }
}

impl Weight for BigRational {
    fn from_weight(w: TriangleWeight) -> Option<Self> {
        w.exact.map(big)
    }
    fn one_weight() -> Self {
        BigRational::from_integer(BigInt::from(1))
    }
}

pub(crate) fn big(r: Rational64) -> BigRational {
    BigRational::new(BigInt::from(*r.numer()), BigInt::from(*r.denom()))
}

/// The interiors of two convex polygons (counter-clockwise, skew coordinates) meet: no edge of
/// either separates them (the separating-axis test; affine coordinates keep separation).
pub(crate) fn interiors_meet(p: &[(i64, i64)], q: &[(i64, i64)]) -> bool {
    let separated_by = |poly: &[(i64, i64)]| {
        (0..poly.len()).any(|e| {
            let (a, b) = (poly[e], poly[(e + 1) % poly.len()]);
            let f = |x: &(i64, i64)| (b.0 - a.0) * (x.1 - a.1) - (b.1 - a.1) * (x.0 - a.0);
            let lo_p = p.iter().map(f).min().unwrap_or(0);
            let hi_p = p.iter().map(f).max().unwrap_or(0);
            let lo_q = q.iter().map(f).min().unwrap_or(0);
            let hi_q = q.iter().map(f).max().unwrap_or(0);
            hi_p <= lo_q || hi_q <= lo_p
        })
    };
    !separated_by(p) && !separated_by(q)
}
