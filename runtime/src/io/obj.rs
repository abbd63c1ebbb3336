//! Wavefront OBJ input: positions, polygonal faces (triangles, quads, n-gons) and
//! OpenSubdiv-style `t` tag lines.
//!
//! Read: `v x y z [w]`, `vt u v [w]`, `f a a/b a/b/c a//c ...` (1-based, or negative = relative
//! to the items read so far; a face's texture coordinates are kept when every corner names
//! one), `t name i/f/s ints... floats... strings...` (OpenSubdiv's `shape_utils`
//! convention; indices in tags are 0-based). Ignored as irrelevant to the surface: `vn`, `vp`,
//! `g`, `o`, `s`, `mtllib`, `usemtl`, `l` and comments. Anything else is an error naming the
//! line, so a file in another dialect is not silently misread.

use std::path::Path;

use schemes::{BoundaryMode, CreaseMethod};

use crate::error::excerpt;
use crate::mesh::face_varying::{FaceVarying, FaceVaryingMode};
use crate::mesh::Mesh;
use crate::{MeshError, RuntimeError};

/// One `t` tag line.
#[derive(Clone, Debug, PartialEq)]
pub struct Tag {
    /// The tag's name (`crease`, `corner`, `interpolateboundary`, `hole`, ...).
    pub name: String,
    /// Its integer arguments.
    pub ints: Vec<i64>,
    /// Its float arguments.
    pub floats: Vec<f64>,
    /// Its string arguments.
    pub strings: Vec<String>,
    /// 1-based line number.
    pub line: usize,
}

/// What an OBJ file says, before any topological check.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Faces as 0-based vertex indices (not yet checked against `positions`).
    pub faces: Vec<Vec<i64>>,
    /// Texture coordinates (`vt`).
    pub uvs: Vec<[f64; 2]>,
    /// Every face's corners as 0-based indices into `uvs` (not yet checked against it), or
    /// empty where the face names none.
    pub face_uvs: Vec<Vec<i64>>,
    /// The 1-based line of each face, for messages.
    pub face_lines: Vec<usize>,
    /// Tag lines.
    pub tags: Vec<Tag>,
}

/// Parse OBJ text.
pub fn parse_obj(text: &str) -> Result<ObjMesh, RuntimeError> {
    let mut mesh = ObjMesh::default();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let err = |message: String| RuntimeError::Obj { line, message };
        match keyword {
            "v" => {
                let coords: Vec<f64> = words
                    .map(|w| {
                        w.parse::<f64>()
                            .map_err(|_| err(format!("`{}` is not a number", excerpt(w))))
                    })
                    .collect::<Result<_, _>>()?;
                if !(3..=4).contains(&coords.len()) {
                    return Err(err(format!(
                        "a vertex needs 3 coordinates, this one has {}",
                        coords.len()
                    )));
                }
                mesh.positions.push([coords[0], coords[1], coords[2]]);
            }
            "vt" => {
                let coords: Vec<f64> = words
                    .map(|w| {
                        w.parse::<f64>()
                            .map_err(|_| err(format!("`{}` is not a number", excerpt(w))))
                    })
                    .collect::<Result<_, _>>()?;
                if !(1..=3).contains(&coords.len()) {
                    return Err(err(format!(
                        "a texture coordinate needs 1 to 3 numbers, this one has {}",
                        coords.len()
                    )));
                }
                mesh.uvs
                    .push([coords[0], coords.get(1).copied().unwrap_or(0.0)]);
            }
            "f" => {
                // 1-based, or negative: relative to the items read so far.
                let index = |word: &str, what: &str, count: usize| {
                    let i: i64 = word.parse().map_err(|_| {
                        err(format!("`{}` is not a {what} reference", excerpt(word)))
                    })?;
                    match i {
                        0 => Err(err(format!("{what} index 0 (OBJ indices start at 1)"))),
                        i if i > 0 => Ok(i - 1),
                        i => Ok(count as i64 + i),
                    }
                };
                let (mut corners, mut uvs) = (Vec::new(), Vec::new());
                for w in words {
                    let mut parts = w.split('/');
                    corners.push(index(
                        parts.next().unwrap_or(""),
                        "vertex",
                        mesh.positions.len(),
                    )?);
                    match parts.next() {
                        Some(t) if !t.is_empty() => {
                            uvs.push(index(t, "texture coordinate", mesh.uvs.len())?)
                        }
                        _ => {}
                    }
                }
                // A face that names texture coordinates at some corners only has none: its
                // surface does not depend on them.
                if uvs.len() != corners.len() {
                    uvs.clear();
                }
                mesh.faces.push(corners);
                mesh.face_uvs.push(uvs);
                mesh.face_lines.push(line);
            }
            "t" => mesh.tags.push(parse_tag(words.collect(), line)?),
            "vn" | "vp" | "g" | "o" | "s" | "mtllib" | "usemtl" | "l" => {}
            other => return Err(err(format!("unknown OBJ statement `{}`", excerpt(other)))),
        }
    }
    Ok(mesh)
}

fn parse_tag(words: Vec<&str>, line: usize) -> Result<Tag, RuntimeError> {
    let err = |message: String| RuntimeError::Obj { line, message };
    let (Some(name), Some(counts)) = (words.first(), words.get(1)) else {
        return Err(err(
            "a tag needs a name and counts `ints/floats/strings`".to_owned()
        ));
    };
    let counts: Vec<usize> = counts
        .split('/')
        .map(|c| {
            c.parse()
                .map_err(|_| err(format!("tag counts `{}` are not `i/f/s`", excerpt(counts))))
        })
        .collect::<Result<_, _>>()?;
    let [ni, nf, ns] = counts[..] else {
        return Err(err(format!(
            "tag counts `{}` are not `i/f/s`",
            excerpt(words[1])
        )));
    };
    let args = &words[2..];
    // The counts come from the file: add them without wrapping, and compare the total with
    // the arguments present before anything is sized from it.
    let announced = ni.checked_add(nf).and_then(|n| n.checked_add(ns));
    if announced != Some(args.len()) {
        let announced = announced.map_or_else(|| "more".to_owned(), |n| n.to_string());
        return Err(err(format!(
            "tag `{}` announces {announced} arguments and has {}",
            excerpt(name),
            args.len()
        )));
    }
    let ints = args[..ni]
        .iter()
        .map(|w| {
            w.parse()
                .map_err(|_| err(format!("`{}` is not an integer", excerpt(w))))
        })
        .collect::<Result<_, _>>()?;
    let floats = args[ni..ni + nf]
        .iter()
        .map(|w| {
            w.parse()
                .map_err(|_| err(format!("`{}` is not a number", excerpt(w))))
        })
        .collect::<Result<_, _>>()?;
    let strings = args[ni + nf..].iter().map(|s| (*s).to_owned()).collect();
    Ok(Tag {
        name: (*name).to_owned(),
        ints,
        floats,
        strings,
        line,
    })
}

/// Read and parse an OBJ file.
pub fn read_obj(path: &Path) -> Result<ObjMesh, RuntimeError> {
    let text = std::fs::read_to_string(path).map_err(|source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    })?;
    parse_obj(&text).map_err(|e| match e {
        RuntimeError::Obj { line, message } => RuntimeError::ParseFile {
            path: path.display().to_string(),
            line,
            message,
        },
        other => other,
    })
}

/// Whether a tag with `ints` integer arguments is well formed for `name`, or why not.
fn check_tag(tag: &Tag, ints_per_item: usize, strings: usize) -> Result<usize, MeshError> {
    let bad = |reason: String| MeshError::BadTag {
        name: tag.name.clone(),
        line: tag.line,
        reason,
    };
    if tag.strings.len() < strings {
        return Err(bad(format!("it needs {strings} string argument(s)")));
    }
    if ints_per_item == 0 {
        return Ok(0);
    }
    if tag.ints.is_empty() || tag.ints.len() % ints_per_item != 0 {
        return Err(bad(format!(
            "it needs a multiple of {ints_per_item} integers, it has {}",
            tag.ints.len()
        )));
    }
    let items = tag.ints.len() / ints_per_item;
    // One sharpness for every item, or one each (a hole has none).
    let floats_ok = tag.name == "hole" || tag.floats.len() == 1 || tag.floats.len() == items;
    if !floats_ok {
        return Err(bad(format!(
            "{items} item(s) need 1 or {items} sharpness values, it has {}",
            tag.floats.len()
        )));
    }
    if let Some(&i) = tag.ints.iter().find(|&&i| i < 0) {
        return Err(bad(format!("index {i} is negative")));
    }
    Ok(items)
}

/// The texture coordinates of `obj` as `mesh`'s face-varying channel, when every face names
/// them; a warning when only some do.
fn face_varying(
    obj: &ObjMesh,
    mesh: &Mesh,
    warnings: &mut Vec<String>,
) -> Result<Option<FaceVarying>, MeshError> {
    let mut mode = FaceVaryingMode::default();
    for tag in obj
        .tags
        .iter()
        .filter(|t| t.name == "facevaryinginterpolateboundary")
    {
        mode = match tag.ints[..] {
            [k] => FaceVaryingMode::from_tag(k),
            _ => None,
        }
        .ok_or_else(|| MeshError::BadTag {
            name: tag.name.clone(),
            line: tag.line,
            reason: format!("{:?} is not one integer 0..=5", tag.ints),
        })?;
    }
    let named = obj.face_uvs.iter().filter(|c| !c.is_empty()).count();
    if named == 0 {
        return Ok(None);
    }
    if named < obj.faces.len() {
        let f = obj.face_uvs.iter().position(|c| c.is_empty()).unwrap_or(0);
        warnings.push(format!(
            "texture coordinates ignored: {named} of {} faces name them (face {f}, OBJ line {}, does not)",
            obj.faces.len(),
            obj.face_lines.get(f).copied().unwrap_or(0)
        ));
        return Ok(None);
    }
    let mut corners = Vec::with_capacity(mesh.face_vertices.len());
    for (f, uvs) in obj.face_uvs.iter().enumerate() {
        for &t in uvs {
            if t < 0 || t as usize >= obj.uvs.len() {
                return Err(MeshError::BadFace {
                    face: f,
                    line: obj.face_lines.get(f).copied().unwrap_or(0),
                    reason: format!(
                        "texture coordinate {} is out of range (the file has {})",
                        t + 1,
                        obj.uvs.len()
                    ),
                });
            }
            corners.push(t as u32);
        }
    }
    FaceVarying::new(mesh.face_vertices.len(), obj.uvs.clone(), corners, mode).map(Some)
}

impl Mesh {
    /// Build from a parsed OBJ file with its tags, as OpenSubdiv's regression reader applies
    /// them: `crease a b .. s ..` (edge sharpness, one value or one per edge), `corner v .. s ..`
    /// (vertex sharpness), `hole f ..`, `interpolateboundary 0|1|2` (none, edge and corner,
    /// edge only: the default), `creasemethod normal|chaikin`, `smoothtriangles
    /// catmark|smooth`. Also returns one warning per tag name it ignores: the hierarchical edits
    /// (`vertexedit`, `edgeedit`, `faceedit`, which OpenSubdiv 3 ignores too) and names it does
    /// not know. Texture coordinates (`vt` named by every corner of every face) become the
    /// mesh's face-varying channel ([`Mesh::face_varying`]) with the mode of
    /// `facevaryinginterpolateboundary k` (0..=5, OpenSubdiv's default 5 when untagged); a file
    /// where only some faces name them gets none, with a warning.
    pub fn from_obj(obj: &ObjMesh) -> Result<(Self, Vec<String>), MeshError> {
        let mut boundary = BoundaryMode::EdgeOnly;
        let mut boundary_none = false;
        let mut unsupported: Vec<(String, usize)> = Vec::new();
        for tag in &obj.tags {
            if tag.name == "interpolateboundary" {
                match tag.ints[..] {
                    [0] => (boundary, boundary_none) = (BoundaryMode::EdgeOnly, true),
                    [1] => (boundary, boundary_none) = (BoundaryMode::EdgeAndCorner, false),
                    [2] => (boundary, boundary_none) = (BoundaryMode::EdgeOnly, false),
                    _ => {
                        return Err(MeshError::BadTag {
                            name: tag.name.clone(),
                            line: tag.line,
                            reason: format!("{:?} is not one integer 0, 1 or 2", tag.ints),
                        })
                    }
                }
            }
        }
        let mut mesh = Mesh::new(obj.positions.clone(), &obj.faces, &obj.face_lines, boundary)?;
        // Boundary edges tagged infinitely sharp by hand: "none" keeps their faces.
        let mut sharp_boundary: Vec<(usize, usize)> = Vec::new();
        for tag in &obj.tags {
            let at = |e: MeshError| MeshError::BadTag {
                name: tag.name.clone(),
                line: tag.line,
                reason: e.to_string(),
            };
            let sharpness = |item: usize| {
                tag.floats
                    .get(item)
                    .or(tag.floats.first())
                    .map_or(0.0, |&s| s as f32)
            };
            match tag.name.as_str() {
                "crease" => {
                    for (item, pair) in tag.ints.chunks(2).take(check_tag(tag, 2, 0)?).enumerate() {
                        let (a, b) = (pair[0] as usize, pair[1] as usize);
                        let s = sharpness(item);
                        mesh.set_edge_sharpness(a, b, s).map_err(at)?;
                        if s >= schemes::crease::INFINITE {
                            sharp_boundary.push((a.min(b), a.max(b)));
                        }
                    }
                }
                "corner" => {
                    for (item, &v) in tag.ints.iter().take(check_tag(tag, 1, 0)?).enumerate() {
                        mesh.set_vertex_sharpness(v as usize, sharpness(item))
                            .map_err(at)?;
                    }
                }
                "hole" => {
                    for &f in tag.ints.iter().take(check_tag(tag, 1, 0)?) {
                        *mesh
                            .holes
                            .get_mut(f as usize)
                            .ok_or(MeshError::NoSuchFace { face: f as usize })
                            .map_err(at)? = true;
                    }
                }
                "creasemethod" | "smoothtriangles" => {
                    check_tag(tag, 0, 1)?;
                    match (tag.name.as_str(), tag.strings[0].as_str()) {
                        ("creasemethod", "normal") => mesh.creasing = CreaseMethod::Uniform,
                        ("creasemethod", "chaikin") => mesh.creasing = CreaseMethod::Chaikin,
                        ("smoothtriangles", "catmark") => mesh.smooth_triangles = false,
                        ("smoothtriangles", "smooth") => mesh.smooth_triangles = true,
                        (name, value) => {
                            return Err(MeshError::BadTag {
                                name: name.to_owned(),
                                line: tag.line,
                                reason: format!("`{}` is not one of its values", excerpt(value)),
                            })
                        }
                    }
                }
                // Read above and in `face_varying`; OpenSubdiv 3 ignores the last.
                "interpolateboundary"
                | "facevaryinginterpolateboundary"
                | "facevaryingpropagatecorners" => {}
                name => match unsupported.iter_mut().find(|(n, _)| n == name) {
                    Some((_, count)) => *count += 1,
                    None => unsupported.push((name.to_owned(), 1)),
                },
            }
        }
        if boundary_none {
            mesh.exclude_boundary_faces(&sharp_boundary);
        }
        let mut warnings: Vec<String> = Vec::new();
        mesh.face_varying = face_varying(obj, &mesh, &mut warnings)?;
        warnings.extend(unsupported.into_iter().map(|(name, count)| {
            format!(
                "tag `{}` ({count} line(s)) is not supported and is ignored",
                excerpt(&name)
            )
        }));
        Ok((mesh, warnings))
    }

    /// Read an OBJ file (with its `t` tags, [`Mesh::from_obj`]) into a mesh; the tags it
    /// ignores are listed by [`Mesh::read_obj_with_warnings`].
    pub fn read_obj(path: impl AsRef<Path>) -> Result<Mesh, RuntimeError> {
        Ok(Self::read_obj_with_warnings(path)?.0)
    }

    /// [`Mesh::read_obj`], and one warning per tag name it ignores.
    pub fn read_obj_with_warnings(
        path: impl AsRef<Path>,
    ) -> Result<(Mesh, Vec<String>), RuntimeError> {
        let obj = read_obj(path.as_ref())?;
        Ok(Mesh::from_obj(&obj)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_faces_tags_and_relative_indices() {
        let text = "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 -1//1\nt crease 2/1/0 0 1 2.5\ng x\n";
        let m = parse_obj(text).expect("valid");
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.faces, vec![vec![0, 1, 2, 3]]);
        assert_eq!(m.tags[0].name, "crease");
        assert_eq!(m.tags[0].ints, vec![0, 1]);
        assert_eq!(m.tags[0].floats, vec![2.5]);
        // One corner names no texture coordinate: the face has none.
        assert_eq!(m.face_uvs, vec![Vec::<i64>::new()]);
    }

    #[test]
    fn reads_texture_coordinates_per_corner() {
        let text =
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0 0\nvt 0.5 1\nf 1/1 2/-2/1 3/3\nf 1 2 3\n";
        let m = parse_obj(text).expect("valid");
        assert_eq!(m.uvs, vec![[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]);
        assert_eq!(m.face_uvs, vec![vec![0, 1, 2], vec![]]);
        for text in ["vt\n", "vt 1 2 3 4\n", "vt x\n"] {
            assert!(parse_obj(text).is_err(), "{text:?}");
        }
    }

    #[test]
    fn bad_lines_name_their_line() {
        for (text, line, message) in [
            ("v 0 0\n", 1, "3 coordinates"),
            ("v 0 0 0\nf 1 x 2\n", 2, "`x`"),
            ("v 0 0 0\nf 0 1 2\n", 2, "index 0"),
            (
                "v 0 0 0\nvt 0 0\nf 1/0 1/1 1/1\n",
                3,
                "texture coordinate index 0",
            ),
            ("\n\nwat 1 2\n", 3, "unknown OBJ statement"),
            ("t crease 2/1/0 0 1\n", 1, "announces 3 arguments"),
            // Counts that wrap `usize` when added (issue 20): an error, not a panic.
            (
                "v 0 0 0\nt crease 18446744073709551615/1/0\n",
                2,
                "announces more arguments and has 0",
            ),
            (
                "t crease 18446744073709551615/18446744073709551615/2 a b\n",
                1,
                "announces more",
            ),
            (
                "t crease 1/18446744073709551615/1 0 x\n",
                1,
                "announces more",
            ),
        ] {
            match parse_obj(text) {
                Err(RuntimeError::Obj {
                    line: l,
                    message: m,
                }) => {
                    assert_eq!(l, line, "{text}");
                    assert!(m.contains(message), "{m}");
                }
                other => panic!("{text}: {other:?}"),
            }
        }
    }
}
