//! Reading bicubic Bézier patch sets: Newell's "patches + vertices" text format (the 1991
//! `teaset` files: teapot, teacup, teaspoon) and the `.bpt` format, both described in
//! `../shared/models/README.md`.
//!
//! Every malformed input is a [`RuntimeError::ParseFile`] naming the file and the 1-based line.

use std::path::Path;

use super::bicubic::{BicubicPatch, Point3};
use crate::error::excerpt;
use crate::mesh::topology::MAX_COORDINATE;
use crate::RuntimeError;

/// A set of bicubic Bézier patches, in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierPatches {
    /// The patches.
    pub patches: Vec<BicubicPatch>,
}

/// The two supported file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchFormat {
    /// Newell/funet: patch count, `P` lines of 16 comma-separated 1-based indices, vertex count,
    /// `N` lines `x,y,z`.
    Newell,
    /// `.bpt`: patch count, then per patch a `du dv` line and `(du+1)(dv+1)` lines `x y z`.
    Bpt,
}

impl PatchFormat {
    /// `.bpt` (case-insensitive) is [`PatchFormat::Bpt`]; anything else is Newell's format
    /// (its files traditionally have no extension or `.txt`).
    pub fn from_path(path: &Path) -> PatchFormat {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("bpt") => PatchFormat::Bpt,
            _ => PatchFormat::Newell,
        }
    }
}

/// The non-blank lines of `text` with their 1-based line numbers (a trailing `\r` is dropped).
struct Lines<'a> {
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    name: &'a str,
    last: usize,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str, name: &'a str) -> Self {
        Lines {
            inner: text.lines().enumerate(),
            name,
            last: 0,
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> RuntimeError {
        RuntimeError::ParseFile {
            path: self.name.to_string(),
            line,
            message: message.into(),
        }
    }

    /// The next non-blank line, or an error saying what was expected.
    fn expect(&mut self, what: &str) -> Result<(usize, &'a str), RuntimeError> {
        for (k, line) in self.inner.by_ref() {
            let t = line.trim();
            self.last = k + 1;
            if !t.is_empty() {
                return Ok((k + 1, t));
            }
        }
        Err(self.error(
            self.last + 1,
            format!("unexpected end of file: expected {what}"),
        ))
    }

    /// How many lines (blank or not) are left: at most the number of items that may still be
    /// read, so the bound on every preallocation from a count the file declares.
    fn remaining(&self) -> usize {
        self.inner.clone().count()
    }

    /// The next non-blank line, if any.
    fn rest(&mut self) -> Option<(usize, &'a str)> {
        for (k, line) in self.inner.by_ref() {
            let t = line.trim();
            if !t.is_empty() {
                return Some((k + 1, t));
            }
        }
        None
    }

    fn count(&mut self, what: &str) -> Result<(usize, usize), RuntimeError> {
        let (line, t) = self.expect(what)?;
        let n: usize = t
            .parse()
            .map_err(|_| self.error(line, format!("expected {what}, found `{}`", excerpt(t))))?;
        Ok((line, n))
    }

    fn coordinates(
        &self,
        line: usize,
        fields: &[&str],
        separator: &str,
    ) -> Result<Point3, RuntimeError> {
        if fields.len() != 3 {
            return Err(self.error(
                line,
                format!(
                    "expected 3 {separator}-separated coordinates, found {}",
                    fields.len()
                ),
            ));
        }
        let mut p = [0.0; 3];
        for (k, f) in fields.iter().enumerate() {
            let x: f64 = f.trim().parse().map_err(|_| {
                self.error(line, format!("`{}` is not a number", excerpt(f.trim())))
            })?;
            if !x.is_finite() {
                return Err(self.error(
                    line,
                    format!("coordinate `{}` is not finite", excerpt(f.trim())),
                ));
            }
            // The meshes' bound: beyond it the f32 output and its normals overflow.
            if x.abs() > MAX_COORDINATE {
                return Err(self.error(
                    line,
                    format!(
                        "coordinate `{}` is beyond {MAX_COORDINATE:e} (what f32 output and its \
                         normals can hold)",
                        excerpt(f.trim())
                    ),
                ));
            }
            p[k] = x;
        }
        Ok(p)
    }
}

impl BezierPatches {
    /// Read a patch file, choosing the format by extension ([`PatchFormat::from_path`]).
    pub fn read(path: &Path) -> Result<BezierPatches, RuntimeError> {
        let text = std::fs::read_to_string(path).map_err(|source| RuntimeError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let name = path.display().to_string();
        match PatchFormat::from_path(path) {
            PatchFormat::Newell => BezierPatches::parse_newell(&text, &name),
            PatchFormat::Bpt => BezierPatches::parse_bpt(&text, &name),
        }
    }

    /// Parse Newell's "patches + vertices" format; `name` is used in error messages.
    pub fn parse_newell(text: &str, name: &str) -> Result<BezierPatches, RuntimeError> {
        let mut lines = Lines::new(text, name);
        let (count_line, count) = lines.count("the number of patches")?;
        if count == 0 {
            return Err(lines.error(count_line, "the file declares no patches"));
        }
        // One line per patch: a count larger than the lines left cannot be met, and is not
        // trusted with an allocation (the loop below reports the short file).
        let mut indices = Vec::with_capacity(count.min(lines.remaining()));
        for p in 0..count {
            let (line, t) = lines.expect(&format!("patch {} of {count}", p + 1))?;
            let fields: Vec<&str> = t.split(',').collect();
            if fields.len() != 16 {
                let hint = if fields.len() == 2 || t.split_whitespace().count() == 2 {
                    " (a `du dv` line: is this a .bpt file?)"
                } else {
                    ""
                };
                return Err(lines.error(
                    line,
                    format!(
                        "patch {}: expected 16 comma-separated vertex indices, found {}{hint}",
                        p + 1,
                        fields.len()
                    ),
                ));
            }
            let mut row = [0usize; 16];
            for (k, f) in fields.iter().enumerate() {
                let f = f.trim();
                let i: usize = f.parse().map_err(|_| {
                    lines.error(
                        line,
                        format!("patch {}: `{}` is not a vertex index", p + 1, excerpt(f)),
                    )
                })?;
                if i == 0 {
                    return Err(lines.error(
                        line,
                        format!("patch {}: vertex index 0 (indices are 1-based)", p + 1),
                    ));
                }
                row[k] = i;
            }
            indices.push((line, row));
        }
        let (vertex_line, vertices) = lines.count("the number of vertices")?;
        if vertices == 0 {
            return Err(lines.error(vertex_line, "the file declares no vertices"));
        }
        let mut points = Vec::with_capacity(vertices.min(lines.remaining()));
        for v in 0..vertices {
            let (line, t) = lines.expect(&format!("vertex {} of {vertices}", v + 1))?;
            let fields: Vec<&str> = t.split(',').collect();
            points.push(lines.coordinates(line, &fields, "comma")?);
        }
        if let Some((line, t)) = lines.rest() {
            return Err(lines.error(
                line,
                format!(
                    "unexpected content after the {vertices} vertices: `{}`",
                    excerpt(t)
                ),
            ));
        }
        let mut patches = Vec::with_capacity(indices.len());
        for (p, (line, row)) in indices.iter().enumerate() {
            let mut control = [[0.0; 3]; 16];
            for (c, &i) in control.iter_mut().zip(row) {
                *c = *points.get(i - 1).ok_or_else(|| {
                    lines.error(
                        *line,
                        format!(
                            "patch {}: vertex index {i} is out of range 1..={vertices}",
                            p + 1
                        ),
                    )
                })?;
            }
            patches.push(BicubicPatch::new(control));
        }
        Ok(BezierPatches { patches })
    }

    /// Parse the `.bpt` format (only bicubic patches, `3 3`); `name` is used in error messages.
    pub fn parse_bpt(text: &str, name: &str) -> Result<BezierPatches, RuntimeError> {
        let mut lines = Lines::new(text, name);
        let (count_line, count) = lines.count("the number of patches")?;
        if count == 0 {
            return Err(lines.error(count_line, "the file declares no patches"));
        }
        // 17 lines per patch (`du dv` and 16 points) bound what the rest of the file can hold.
        let mut patches = Vec::with_capacity(count.min(lines.remaining() / 17));
        for p in 0..count {
            let (line, t) = lines.expect(&format!("the degree line `du dv` of patch {}", p + 1))?;
            let degrees: Vec<&str> = t.split_whitespace().collect();
            let parsed: Option<Vec<usize>> = degrees.iter().map(|d| d.parse().ok()).collect();
            match parsed.as_deref() {
                Some([3, 3]) => {}
                Some([du, dv]) => {
                    return Err(lines.error(
                        line,
                        format!(
                            "patch {}: degrees {du} {dv} are not supported (only bicubic patches, `3 3`)",
                            p + 1
                        ),
                    ))
                }
                _ => {
                    return Err(lines.error(
                        line,
                        format!("patch {}: expected the degree line `du dv`, found `{}`", p + 1, excerpt(t)),
                    ))
                }
            }
            let mut control = [[0.0; 3]; 16];
            for (k, c) in control.iter_mut().enumerate() {
                let (line, t) =
                    lines.expect(&format!("control point {} of 16 of patch {}", k + 1, p + 1))?;
                let fields: Vec<&str> = t.split_whitespace().collect();
                *c = lines.coordinates(line, &fields, "space")?;
            }
            patches.push(BicubicPatch::new(control));
        }
        if let Some((line, t)) = lines.rest() {
            return Err(lines.error(
                line,
                format!(
                    "unexpected content after the {count} patches: `{}`",
                    excerpt(t)
                ),
            ));
        }
        Ok(BezierPatches { patches })
    }

    /// The number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Whether there are no patches.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The axis-aligned bounding box of all control points (`(min, max)`; it contains the
    /// surface by the convex-hull property).
    pub fn bounding_box(&self) -> (Point3, Point3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.patches {
            for c in &p.control {
                for k in 0..3 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
        }
        (lo, hi)
    }

    /// The length of the bounding box's diagonal.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        super::bicubic::norm(super::bicubic::sub(hi, lo))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The message of a parse error, which must name `line`.
    fn error_at(result: Result<BezierPatches, RuntimeError>, line: usize) -> String {
        match result {
            Err(RuntimeError::ParseFile {
                line: l, message, ..
            }) => {
                assert_eq!(l, line, "{message}");
                message
            }
            other => panic!("expected a parse error at line {line}: {other:?}"),
        }
    }

    /// Issue 20: a declared count of 10^10 (1.3 TB of patches) is refused when the data runs
    /// out, without allocating for the count first (before the fix this aborted allocating).
    #[test]
    fn huge_declared_counts_do_not_preallocate() {
        let one_patch = "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n";
        let m = error_at(
            BezierPatches::parse_newell(&format!("10000000000\n{one_patch}"), "t"),
            3,
        );
        assert!(m.contains("patch 2 of 10000000000"), "{m}");
        let m = error_at(
            BezierPatches::parse_newell(&format!("1\n{one_patch}10000000000\n1,2,3\n"), "t"),
            5,
        );
        assert!(m.contains("vertex 2 of 10000000000"), "{m}");
        let m = error_at(BezierPatches::parse_bpt("10000000000\n3 3\n", "t.bpt"), 3);
        assert!(m.contains("control point 1 of 16 of patch 1"), "{m}");
        // A count beyond u64: not a number of patches at all.
        let m = error_at(
            BezierPatches::parse_bpt("99999999999999999999999\n", "t.bpt"),
            1,
        );
        assert!(m.contains("expected the number of patches"), "{m}");
    }

    /// Coordinates beyond the meshes' bound (1e18) are refused naming the line, as in meshes:
    /// their f32 output and normals would overflow.
    #[test]
    fn coordinates_beyond_the_bound_are_refused() {
        let points = |x: &str| {
            let mut text = String::from("1\n3 3\n");
            for k in 0..16 {
                let first = if k == 5 { x.to_string() } else { k.to_string() };
                text.push_str(&format!("{first} 0 0\n"));
            }
            text
        };
        let m = error_at(BezierPatches::parse_bpt(&points("2e18"), "t.bpt"), 8);
        assert!(m.contains("beyond 1e18"), "{m}");
        assert!(BezierPatches::parse_bpt(&points("1e18"), "t.bpt").is_ok());
    }
}
