//! Semi-sharp and infinitely sharp features: how sharpness decays from one level to the next,
//! which vertex rule a vertex follows, and the fractional weight that blends two rules when a
//! vertex's rule changes between levels (DeRose, Kass and Truong 1998, "Subdivision surfaces in
//! character animation", section 3; in OpenSubdiv's formulation, `Sdc::Crease`).
//!
//! Sharpness is a non-negative `f32`, as in OpenSubdiv, so that every decision below (is it
//! sharp, did it reach zero) falls the same way as there: `0` is smooth, anything at or above
//! [`INFINITE`] is infinitely sharp, values between are semi-sharp and lose one unit per level.
//! The rules are the same for every scheme; the masks they select are the scheme's.

/// Sharpness at and above which a feature is infinitely sharp (OpenSubdiv's
/// `Crease::SHARPNESS_INFINITE`).
pub const INFINITE: f32 = 10.0;

/// Whether `s` is sharp at all (semi-sharp or infinite).
pub fn is_sharp(s: f32) -> bool {
    s > 0.0
}

/// Whether `s` is infinitely sharp.
pub fn is_infinite(s: f32) -> bool {
    s >= INFINITE
}

/// Whether `s` is sharp but not infinitely so.
pub fn is_semi_sharp(s: f32) -> bool {
    s > 0.0 && s < INFINITE
}

/// How an edge's semi-sharpness decays from one level to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CreaseMethod {
    /// Every semi-sharp value loses one unit per level (OpenSubdiv's `CREASE_UNIFORM`, the
    /// `creasemethod normal` tag).
    #[default]
    Uniform,
    /// Chaikin's rule: a child edge's sharpness is `(3 s + s_avg) / 4 - 1`, `s_avg` the mean
    /// of the other semi-sharp edges at the child's parent vertex, so sharpness varies smoothly
    /// along a crease of varying sharpness (`CREASE_CHAIKIN`, `creasemethod chaikin`).
    Chaikin,
}

/// The rule a vertex point follows (OpenSubdiv's `Crease::Rule`), chosen by the vertex's own
/// sharpness and the number of sharp edges at it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CreaseRule {
    /// No sharp edge: the scheme's smooth rule.
    Smooth,
    /// One sharp edge: the smooth rule for the vertex (the edge is a crease that fades in).
    Dart,
    /// Two sharp edges: the crease (boundary curve) rule along them.
    Crease,
    /// A sharp vertex, or more than two sharp edges: the vertex stays where it is.
    Corner,
}

impl CreaseRule {
    /// The rule of a vertex of sharpness `vertex` whose edges have the sharpness values
    /// `edges`.
    pub fn of(vertex: f32, edges: &[f32]) -> Self {
        if is_sharp(vertex) {
            return CreaseRule::Corner;
        }
        match edges.iter().filter(|&&s| is_sharp(s)).count() {
            0 => CreaseRule::Smooth,
            1 => CreaseRule::Dart,
            2 => CreaseRule::Crease,
            _ => CreaseRule::Corner,
        }
    }

    /// Whether the vertex point uses the smooth mask (smooth and dart vertices).
    pub fn is_smooth(self) -> bool {
        matches!(self, CreaseRule::Smooth | CreaseRule::Dart)
    }
}

/// Sharpness one level down, uniformly: one unit less, zero once it reaches zero, infinite
/// stays infinite.
pub fn decrement(s: f32) -> f32 {
    if !is_sharp(s) {
        0.0
    } else if is_infinite(s) {
        INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

impl CreaseMethod {
    /// The sharpness of the child of an edge of sharpness `s` at one of its end vertices,
    /// whose edges (this one included) have sharpness `around`.
    pub fn child_sharpness(self, s: f32, around: &[f32]) -> f32 {
        if self == CreaseMethod::Uniform || around.len() < 2 {
            return decrement(s);
        }
        if !is_sharp(s) {
            return 0.0;
        }
        if is_infinite(s) {
            return INFINITE;
        }
        let (sum, count) = around
            .iter()
            .filter(|&&e| is_semi_sharp(e))
            .fold((0.0f32, 0u32), |(sum, n), &e| (sum + e, n + 1));
        let blended = if count > 1 {
            // The mean of the *other* semi-sharp edges: this one is among those counted.
            let others = (sum - s) / (count - 1) as f32;
            0.75 * s + 0.25 * others
        } else {
            s
        };
        let child = blended - 1.0;
        if is_sharp(child) {
            child
        } else {
            0.0
        }
    }

    /// The weight of the parent's rule when a vertex of sharpness `vertex` with edges `edges`
    /// changes rule between levels (its child has sharpness `child_vertex` and child edges
    /// `child_edges`, in the same order): the mean sharpness of the features that become smooth,
    /// at most 1. The vertex point is `w * parent rule + (1 - w) * child rule`.
    pub fn fractional_weight(
        self,
        vertex: f32,
        child_vertex: f32,
        edges: &[f32],
        child_edges: &[f32],
    ) -> f32 {
        let (mut sum, mut count) = (0.0f32, 0u32);
        if is_sharp(vertex) && !is_sharp(child_vertex) {
            sum += vertex;
            count += 1;
        }
        for (&p, &c) in edges.iter().zip(child_edges) {
            // Uniformly, an edge vanishes exactly when it is at most 1.
            let fades = match self {
                CreaseMethod::Uniform => is_sharp(p) && p <= 1.0,
                CreaseMethod::Chaikin => is_sharp(p) && !is_sharp(c),
            };
            if fades {
                sum += p;
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f32).min(1.0)
        }
    }
}

/// The two sharp edges of a crease vertex: the first and the last sharp entry of `edges` (a
/// crease has exactly two).
pub fn crease_pair(edges: &[f32]) -> Option<(usize, usize)> {
    let first = edges.iter().position(|&s| is_sharp(s))?;
    let last = edges.iter().rposition(|&s| is_sharp(s))?;
    (first != last).then_some((first, last))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_follow_the_count_of_sharp_edges() {
        assert_eq!(
            CreaseRule::of(0.0, &[0.0, 0.0, 0.0, 0.0]),
            CreaseRule::Smooth
        );
        assert_eq!(CreaseRule::of(0.0, &[2.0, 0.0, 0.0, 0.0]), CreaseRule::Dart);
        assert_eq!(
            CreaseRule::of(0.0, &[2.0, 0.0, 0.5, 0.0]),
            CreaseRule::Crease
        );
        assert_eq!(
            CreaseRule::of(0.0, &[2.0, 1.0, 0.5, 0.0]),
            CreaseRule::Corner
        );
        assert_eq!(CreaseRule::of(0.25, &[0.0; 4]), CreaseRule::Corner);
    }

    #[test]
    fn uniform_sharpness_loses_a_unit_per_level() {
        assert_eq!(decrement(2.5), 1.5);
        assert_eq!(decrement(1.0), 0.0);
        assert_eq!(decrement(0.4), 0.0);
        assert_eq!(decrement(INFINITE), INFINITE);
        assert_eq!(decrement(12.0), INFINITE);
        assert_eq!(CreaseMethod::Uniform.child_sharpness(3.0, &[3.0, 1.0]), 2.0);
    }

    /// Chaikin: a crease of sharpness 3 meeting one of sharpness 1 gives children
    /// `(9 + 1) / 4 - 1 = 1.5` and `(3 + 3) / 4 - 1 = 0.5`; a lone semi-sharp edge decrements.
    #[test]
    fn chaikin_averages_the_other_semi_sharp_edges() {
        let around = [3.0, 0.0, 1.0, 0.0];
        assert_eq!(CreaseMethod::Chaikin.child_sharpness(3.0, &around), 1.5);
        assert_eq!(CreaseMethod::Chaikin.child_sharpness(1.0, &around), 0.5);
        assert_eq!(CreaseMethod::Chaikin.child_sharpness(0.0, &around), 0.0);
        assert_eq!(
            CreaseMethod::Chaikin.child_sharpness(2.0, &[2.0, INFINITE]),
            1.0
        );
    }

    #[test]
    fn the_fractional_weight_is_the_mean_of_what_fades() {
        // Two edges at 0.5 and 0.25 both fade: weight 0.375.
        let w = CreaseMethod::Uniform.fractional_weight(0.0, 0.0, &[0.5, 0.25], &[0.0, 0.0]);
        assert_eq!(w, 0.375);
        // A vertex of sharpness 0.5 fades with an edge of 1: mean 0.75.
        let w = CreaseMethod::Uniform.fractional_weight(0.5, 0.0, &[1.0, 3.0], &[0.0, 2.0]);
        assert_eq!(w, 0.75);
        assert_eq!(crease_pair(&[0.0, 1.0, 0.0, 2.0]), Some((1, 3)));
        assert_eq!(crease_pair(&[0.0, 1.0, 0.0, 0.0]), None);
    }
}
