//! Output budgets (docs/reliability.md): the size of a tessellation or a refinement is
//! estimated from the plan before anything of that size is allocated, and refused above a
//! limit with a message that gives the estimate and the flag that raises the limit.

use crate::error::RuntimeError;
use crate::scheme::Scheme;

/// The default `--max-triangles`: 200 million triangles, about 16 GB at
/// [`BYTES_PER_TRIANGLE`], so that a 24 GiB machine survives the largest output allowed.
pub const DEFAULT_MAX_TRIANGLES: u64 = 200_000_000;

/// Peak memory per output triangle assumed by the estimates: a dual-grid run (plan, frame,
/// triangle mesh and writer together) peaked at 837 MB for 11,529,598 triangles (a 100 x 100
/// quad grid at rate 24, OBJ or PLY output), 73 bytes per triangle; 80 leaves a margin.
pub const BYTES_PER_TRIANGLE: u64 = 80;

/// The estimated size of an output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputEstimate {
    /// Faces tessellated.
    pub faces: u64,
    /// Output vertices (about).
    pub vertices: u64,
    /// Output triangles (about; an upper estimate).
    pub triangles: u64,
}

impl OutputEstimate {
    /// The dual-grid output of faces with `rates`, quads (Catmull–Clark after isolation) or
    /// triangles (the triangle schemes): a quad face at rate `n` has `n^2` dual points and
    /// `2n^2` triangles with its share of strips and vertex polygons (`2n(n+1)` here, an upper
    /// estimate: a 100 x 100 grid at rate 24 has 11,529,598 triangles for 12,000,000); a
    /// triangle face at most `2n^2` points and `3n^2` triangles (Loop on the octahedron at
    /// rate 8: 171 per face for 192).
    pub fn dual_grid(triangle_faces: bool, rates: impl IntoIterator<Item = u32>) -> Self {
        let mut estimate = OutputEstimate {
            faces: 0,
            vertices: 0,
            triangles: 0,
        };
        for n in rates {
            let face = Self::uniform(triangle_faces, 1, n);
            estimate.faces += 1;
            estimate.vertices = estimate.vertices.saturating_add(face.vertices);
            estimate.triangles = estimate.triangles.saturating_add(face.triangles);
        }
        estimate
    }

    /// [`OutputEstimate::dual_grid`] of `faces` faces all at rate `n`, saturating instead of
    /// wrapping.
    pub fn uniform(triangle_faces: bool, faces: u64, n: u32) -> Self {
        let n = u64::from(n);
        let (vertices, triangles) = if triangle_faces {
            (2 * n * n, 3 * n * n)
        } else {
            (n * n, 2 * n * (n + 1))
        };
        OutputEstimate {
            faces,
            vertices: faces.saturating_mul(vertices),
            triangles: faces.saturating_mul(triangles),
        }
    }

    /// Bytes of memory at [`BYTES_PER_TRIANGLE`].
    pub fn bytes(&self) -> u64 {
        self.triangles.saturating_mul(BYTES_PER_TRIANGLE)
    }

    /// Refuse the estimate when it exceeds `max_triangles` (`what`: the output, e.g. "the
    /// tessellation"), or when its vertices would not fit the `u32` indices of the output.
    pub fn check(&self, what: &str, max_triangles: u64) -> Result<(), RuntimeError> {
        if self.triangles > max_triangles {
            return Err(RuntimeError::OverBudget {
                what: what.to_owned(),
                estimate: self.describe(),
                limit: format!("{max_triangles} triangles"),
                raise: "--max-triangles N raises it".to_owned(),
            });
        }
        if self.vertices > u64::from(u32::MAX) {
            return Err(RuntimeError::OverBudget {
                what: what.to_owned(),
                estimate: self.describe(),
                limit: format!("{} vertices", u32::MAX),
                raise: "output indices are 32-bit".to_owned(),
            });
        }
        Ok(())
    }

    /// "F faces, V vertices, T triangles, B GB".
    fn describe(&self) -> String {
        format!(
            "{} faces, {} vertices, {} triangles, {:.1} GB at {BYTES_PER_TRIANGLE} bytes per triangle",
            self.faces,
            self.vertices,
            self.triangles,
            self.bytes() as f64 / 1e9
        )
    }
}

/// Faces after `steps` refinement steps of `scheme` (as [`Scheme::refine`] takes them) of a
/// mesh whose faces have `face_sizes` vertices: Catmull–Clark's first step makes `k` quads of
/// a `k`-gon and each later one 4 of a quad; Loop and the butterfly make 4 triangles of one;
/// a √3 step (two √3 refinements) makes 9. Saturates instead of wrapping.
pub fn refined_faces(
    scheme: Scheme,
    face_sizes: impl IntoIterator<Item = usize>,
    steps: u32,
) -> u64 {
    let (faces, corners) = face_sizes.into_iter().fold((0u64, 0u64), |(f, c), k| {
        (f + 1, c.saturating_add(k as u64))
    });
    match (scheme, steps) {
        (_, 0) => faces,
        (Scheme::CatmullClark, _) => corners.saturating_mul(4u64.saturating_pow(steps - 1)),
        (Scheme::Sqrt3, _) => faces.saturating_mul(9u64.saturating_pow(steps)),
        (Scheme::Loop | Scheme::Butterfly, _) => faces.saturating_mul(4u64.saturating_pow(steps)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimates bound the counts measured (numbers from `subtess tessellate --stats`:
    /// the cube at rates 1, 2, 4 has 44, 188, 764 triangles; Loop on the octahedron at rates
    /// 1, 2, 4, 8 has 96, 288, 1248, 5472).
    #[test]
    fn estimates_bound_measured_counts() {
        for (n, measured) in [(1, 44), (2, 188), (4, 764)] {
            let e = OutputEstimate::dual_grid(false, std::iter::repeat_n(n, 24));
            assert!(
                e.triangles >= measured && e.triangles <= 3 * measured,
                "{e:?}"
            );
            assert_eq!(e.vertices, 24 * u64::from(n * n));
        }
        for (n, measured) in [(1, 96), (2, 288), (4, 1248), (8, 5472)] {
            let e = OutputEstimate::dual_grid(true, std::iter::repeat_n(n, 32));
            assert!(
                e.triangles >= measured && e.triangles <= 3 * measured,
                "{e:?}"
            );
        }
    }

    #[test]
    fn over_the_limit_is_refused_with_the_estimate_and_the_flag() {
        let e = OutputEstimate::dual_grid(false, [24; 6]);
        assert!(e.check("the tessellation", 7200).is_ok());
        let message = e
            .check("the tessellation", 7199)
            .expect_err("over")
            .to_string();
        assert!(message.contains("7200 triangles"), "{message}");
        assert!(message.contains("--max-triangles"), "{message}");
        let huge = OutputEstimate::dual_grid(false, std::iter::repeat_n(24, 10_000_000));
        let message = huge
            .check("it", u64::MAX)
            .expect_err("over u32")
            .to_string();
        assert!(message.contains("32-bit"), "{message}");
    }

    #[test]
    fn refined_face_counts() {
        // A cube: 6 quads, 24 after one step, 6 * 4^6 after six.
        assert_eq!(refined_faces(Scheme::CatmullClark, [4; 6], 1), 24);
        assert_eq!(refined_faces(Scheme::CatmullClark, [4; 6], 6), 6 * 4096);
        // A triangle and a pentagon: 3 + 5 quads after one step.
        assert_eq!(refined_faces(Scheme::CatmullClark, [3, 5], 2), 32);
        assert_eq!(refined_faces(Scheme::Loop, [3; 8], 3), 8 * 64);
        assert_eq!(refined_faces(Scheme::Sqrt3, [3; 8], 2), 8 * 81);
        assert_eq!(refined_faces(Scheme::Sqrt3, [3; 8], 60), u64::MAX);
    }
}
