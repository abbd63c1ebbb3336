//! Triangle meshes in: what `subtess render` draws. OBJ through the one OBJ reader
//! ([`crate::io::obj`], polygons split into fans, `vt` texture coordinates kept), and the two binary formats `subtess
//! tessellate` writes ([`crate::io::mesh_output`]): PLY (ASCII or binary little-endian, any
//! scalar types, `x y z` per vertex, `s t` as texture coordinates when present, a
//! `vertex_indices` list per face) and GLB (glTF 2.0 binary: the first primitive of the first
//! mesh, `POSITION`, optional `TEXCOORD_0`, `indices` or none). Every count is checked against
//! the bytes that must hold it before anything is allocated from it.

use std::collections::HashMap;
use std::path::Path;

use serde_json::Value;

use crate::io::obj::read_obj;
use crate::RuntimeError;

/// Triangles to draw, with texture coordinates where the file has them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Triangles {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as vertex indices, all in range.
    pub triangles: Vec<[u32; 3]>,
    /// One texture coordinate per vertex, if the file has them.
    pub uvs: Option<Vec<[f32; 2]>>,
}

impl Triangles {
    /// Whether every triangle names a vertex there is, and the texture coordinates (if any)
    /// are one per vertex: what drawing the triangles indexes by.
    pub fn check(&self) -> Result<(), String> {
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&v| v as usize >= self.positions.len()))
        {
            return Err(format!(
                "triangle {t:?} names a vertex beyond the {} vertices",
                self.positions.len()
            ));
        }
        match &self.uvs {
            Some(uvs) if uvs.len() != self.positions.len() => Err(format!(
                "{} texture coordinates for {} vertices",
                uvs.len(),
                self.positions.len()
            )),
            _ => Ok(()),
        }
    }
}

/// Read the triangles of an `.obj`, `.ply` or `.glb` file (by extension).
pub fn read_triangles(path: &Path) -> Result<Triangles, RuntimeError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let out = match extension.as_deref() {
        Some("obj") => obj_triangles(path)?,
        Some("ply") => parse_ply(&read(path)?).map_err(|m| bad(path, m))?,
        Some("glb") => parse_glb(&read(path)?).map_err(|m| bad(path, m))?,
        _ => {
            return Err(bad(
                path,
                "reads .obj, .ply and .glb (by extension)".to_string(),
            ))
        }
    };
    out.check().map_err(|reason| bad(path, reason))?;
    Ok(out)
}

fn read(path: &Path) -> Result<Vec<u8>, RuntimeError> {
    std::fs::read(path).map_err(|source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    })
}

fn bad(path: &Path, reason: String) -> RuntimeError {
    RuntimeError::InvalidParameter {
        name: format!("mesh {}", path.display()),
        reason,
    }
}

/// An OBJ file's faces as fans of triangles. Where every face names texture coordinates, each
/// distinct (vertex, texture coordinate) pair of the corners becomes one vertex, so that seams
/// keep both sides' coordinates.
fn obj_triangles(path: &Path) -> Result<Triangles, RuntimeError> {
    let obj = read_obj(path)?;
    let textured = !obj.faces.is_empty() && obj.face_uvs.iter().all(|f| !f.is_empty());
    let mut out = Triangles::default();
    let mut uvs = Vec::new();
    let mut vertex_of: HashMap<(i64, i64), u32> = HashMap::new();
    for (f, face) in obj.faces.iter().enumerate() {
        let mut corners = Vec::with_capacity(face.len());
        for (k, &v) in face.iter().enumerate() {
            let position = usize::try_from(v)
                .ok()
                .and_then(|v| obj.positions.get(v))
                .ok_or_else(|| {
                    bad(
                        path,
                        format!("face {f} names vertex {v}, which is not read"),
                    )
                })?;
            let t = if textured { obj.face_uvs[f][k] } else { -1 };
            let uv = if textured {
                let uv = usize::try_from(t)
                    .ok()
                    .and_then(|t| obj.uvs.get(t))
                    .ok_or_else(|| {
                        bad(
                            path,
                            format!("face {f} names texture coordinate {t}, which is not read"),
                        )
                    })?;
                Some(uv.map(|c| c as f32))
            } else {
                None
            };
            let next = u32::try_from(out.positions.len())
                .map_err(|_| bad(path, "more than 2^32 vertices".to_string()))?;
            let index = *vertex_of.entry((v, t)).or_insert_with(|| {
                out.positions.push(position.map(|c| c as f32));
                uvs.extend(uv);
                next
            });
            corners.push(index);
        }
        for k in 1..corners.len().saturating_sub(1) {
            out.triangles.push([corners[0], corners[k], corners[k + 1]]);
        }
    }
    out.uvs = textured.then_some(uvs);
    Ok(out)
}

/// A PLY scalar type: its size in bytes and whether it is an integer.
fn ply_type(name: &str) -> Option<(usize, bool)> {
    Some(match name {
        "char" | "uchar" | "int8" | "uint8" => (1, true),
        "short" | "ushort" | "int16" | "uint16" => (2, true),
        "int" | "uint" | "int32" | "uint32" => (4, true),
        "float" | "float32" => (4, false),
        "double" | "float64" => (8, false),
        _ => return None,
    })
}

enum Property {
    Scalar(String, String),
    List(String, String, String),
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// The values of a PLY body, ASCII or binary little-endian, read one at a time.
enum Body<'a> {
    Ascii(std::str::SplitAsciiWhitespace<'a>),
    Binary(&'a [u8]),
}

impl Body<'_> {
    fn next(&mut self, kind: &str) -> Result<f64, String> {
        match self {
            Body::Ascii(words) => words
                .next()
                .ok_or("the body ends early")?
                .parse::<f64>()
                .map_err(|e| format!("a {kind} value: {e}")),
            Body::Binary(bytes) => {
                let (size, _) = ply_type(kind).ok_or(format!("unknown type {kind}"))?;
                if bytes.len() < size {
                    return Err("the body ends early".to_string());
                }
                let (head, rest) = bytes.split_at(size);
                *bytes = rest;
                let mut b = [0u8; 8];
                b[..size].copy_from_slice(head);
                Ok(match kind {
                    "char" | "int8" => f64::from(b[0] as i8),
                    "uchar" | "uint8" => f64::from(b[0]),
                    "short" | "int16" => f64::from(i16::from_le_bytes([b[0], b[1]])),
                    "ushort" | "uint16" => f64::from(u16::from_le_bytes([b[0], b[1]])),
                    "int" | "int32" => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    "uint" | "uint32" => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    "float" | "float32" => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    _ => f64::from_le_bytes(b),
                })
            }
        }
    }

    /// A lower bound on the values left: what an element's count is checked against.
    fn left(&self) -> usize {
        match self {
            Body::Ascii(words) => words.clone().size_hint().1.unwrap_or(usize::MAX),
            Body::Binary(bytes) => bytes.len(),
        }
    }
}

fn parse_ply(bytes: &[u8]) -> Result<Triangles, String> {
    let end = b"end_header";
    let header_end = bytes
        .windows(end.len())
        .position(|w| w == end)
        .ok_or("not a PLY file: no end_header")?;
    let header = std::str::from_utf8(&bytes[..header_end]).map_err(|_| "a header not in ASCII")?;
    let mut body_start = header_end + end.len();
    body_start += bytes[body_start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len() - body_start, |k| k + 1);
    let mut lines = header.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err("not a PLY file: no `ply` line".to_string());
    }
    let mut ascii = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", "ascii", _] => ascii = Some(true),
            ["format", "binary_little_endian", _] => ascii = Some(false),
            ["format", other, _] => return Err(format!("format {other} is not read")),
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("element {name} count {count:?}"))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => elements
                .last_mut()
                .ok_or("a property before any element")?
                .properties
                .push(Property::List(
                    count.to_string(),
                    item.to_string(),
                    name.to_string(),
                )),
            ["property", kind, name] => elements
                .last_mut()
                .ok_or("a property before any element")?
                .properties
                .push(Property::Scalar(kind.to_string(), name.to_string())),
            _ => {}
        }
    }
    for element in &elements {
        for property in &element.properties {
            let kinds = match property {
                Property::Scalar(kind, _) => vec![kind],
                Property::List(count, item, _) => vec![count, item],
            };
            if let Some(kind) = kinds.into_iter().find(|k| ply_type(k).is_none()) {
                return Err(format!("property type {kind} is not a PLY type"));
            }
        }
    }
    let mut body = match ascii {
        Some(true) => Body::Ascii(
            std::str::from_utf8(&bytes[body_start..])
                .map_err(|_| "an ASCII body that is not ASCII")?
                .split_ascii_whitespace(),
        ),
        Some(false) => Body::Binary(&bytes[body_start..]),
        None => return Err("no format line".to_string()),
    };
    let mut out = Triangles::default();
    let mut uvs = Vec::new();
    for element in &elements {
        // Every row holds at least one value (one byte): a count beyond that is a lie.
        if element.count > body.left() {
            return Err(format!(
                "element {} claims {} rows, more than the body holds",
                element.name, element.count
            ));
        }
        for _ in 0..element.count {
            let (mut p, mut uv) = ([0.0f32; 3], [None::<f32>; 2]);
            for property in &element.properties {
                match property {
                    Property::Scalar(kind, name) => {
                        let x = body.next(kind)? as f32;
                        match name.as_str() {
                            "x" => p[0] = x,
                            "y" => p[1] = x,
                            "z" => p[2] = x,
                            "s" | "texture_u" => uv[0] = Some(x),
                            "t" | "texture_v" => uv[1] = Some(x),
                            _ => {}
                        }
                    }
                    Property::List(count, item, name) => {
                        let n = body.next(count)?;
                        if !(0.0..=1e6).contains(&n) {
                            return Err(format!("a list of {n} items"));
                        }
                        let mut polygon = Vec::with_capacity((n as usize).min(body.left()));
                        for _ in 0..n as usize {
                            polygon.push(body.next(item)?);
                        }
                        if element.name == "face"
                            && (name == "vertex_indices" || name == "vertex_index")
                        {
                            let index = |x: f64| {
                                (x >= 0.0 && x <= f64::from(u32::MAX) && x.fract() == 0.0)
                                    .then_some(x as u32)
                                    .ok_or(format!("vertex index {x}"))
                            };
                            for k in 1..polygon.len().saturating_sub(1) {
                                out.triangles.push([
                                    index(polygon[0])?,
                                    index(polygon[k])?,
                                    index(polygon[k + 1])?,
                                ]);
                            }
                        }
                    }
                }
            }
            if element.name == "vertex" {
                out.positions.push(p);
                if let [Some(s), Some(t)] = uv {
                    uvs.push([s, t]);
                }
            }
        }
    }
    if !uvs.is_empty() && uvs.len() == out.positions.len() {
        out.uvs = Some(uvs);
    }
    Ok(out)
}

fn le_u32(bytes: &[u8], at: usize) -> Result<u32, String> {
    bytes
        .get(at..at + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or_else(|| "the file ends early".to_string())
}

fn parse_glb(bytes: &[u8]) -> Result<Triangles, String> {
    if bytes.get(..4) != Some(b"glTF") {
        return Err("not a GLB file (no glTF magic)".to_string());
    }
    if le_u32(bytes, 4)? != 2 {
        return Err("not glTF 2.0".to_string());
    }
    let json_len = le_u32(bytes, 12)? as usize;
    if bytes.get(16..20) != Some(b"JSON") {
        return Err("the first chunk is not JSON".to_string());
    }
    let json = bytes
        .get(20..20 + json_len)
        .ok_or("the JSON chunk runs past the end")?;
    let doc: Value = serde_json::from_slice(json).map_err(|e| format!("JSON chunk: {e}"))?;
    let bin_at = (20 + json_len).next_multiple_of(4);
    let bin = match bytes.get(bin_at..bin_at + 8) {
        Some(head) if &head[4..8] == b"BIN\0" => {
            let len = le_u32(head, 0)? as usize;
            bytes
                .get(bin_at + 8..bin_at + 8 + len)
                .ok_or("the BIN chunk runs past the end")?
        }
        _ => &[][..],
    };
    let primitive = &doc["meshes"][0]["primitives"][0];
    let position = primitive["attributes"]["POSITION"]
        .as_u64()
        .ok_or("no POSITION in the first primitive")?;
    let positions = accessor(&doc, bin, position, 3)?;
    let positions: Vec<[f32; 3]> = positions
        .chunks_exact(3)
        .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
        .collect();
    let uvs = match primitive["attributes"]["TEXCOORD_0"].as_u64() {
        Some(a) => Some(
            accessor(&doc, bin, a, 2)?
                .chunks_exact(2)
                .map(|c| [c[0] as f32, c[1] as f32])
                .collect(),
        ),
        None => None,
    };
    let indices: Vec<u32> = match primitive["indices"].as_u64() {
        Some(a) => accessor(&doc, bin, a, 1)?
            .into_iter()
            .map(|x| x as u32)
            .collect(),
        None => (0..u32::try_from(positions.len()).map_err(|_| "too many vertices")?).collect(),
    };
    let triangles = indices
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    Ok(Triangles {
        positions,
        triangles,
        uvs,
    })
}

/// The values of accessor `index` (`width` components each), from the BIN chunk.
fn accessor(doc: &Value, bin: &[u8], index: u64, width: usize) -> Result<Vec<f64>, String> {
    let a = &doc["accessors"][index as usize];
    let view = &doc["bufferViews"][a["bufferView"]
        .as_u64()
        .ok_or("an accessor without a bufferView")? as usize];
    let count = a["count"].as_u64().ok_or("an accessor without a count")? as usize;
    let (size, read): (usize, fn(&[u8]) -> f64) = match a["componentType"].as_u64() {
        Some(5126) => (4, |b| {
            f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        }),
        Some(5125) => (4, |b| {
            f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        }),
        Some(5123) => (2, |b| f64::from(u16::from_le_bytes([b[0], b[1]]))),
        Some(5121) => (1, |b| f64::from(b[0])),
        other => return Err(format!("component type {other:?} is not read")),
    };
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"]
        .as_u64()
        .map_or(size * width, |s| s as usize);
    let needed = count
        .checked_sub(1)
        .map_or(Some(0), |last| {
            last.checked_mul(stride)?.checked_add(size * width)
        })
        .and_then(|n| n.checked_add(start))
        .ok_or("an accessor too large")?;
    if needed > bin.len() {
        return Err(format!(
            "an accessor of {count} elements needs {needed} bytes, the BIN chunk has {}",
            bin.len()
        ));
    }
    let mut out = Vec::with_capacity(count * width);
    for i in 0..count {
        for c in 0..width {
            let at = start + i * stride + c * size;
            out.push(read(&bin[at..at + size]));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_ply_with_texture_coordinates_and_a_quad() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
                    property float z\nproperty float s\nproperty float t\nelement face 1\n\
                    property list uchar int vertex_indices\nend_header\n\
                    0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";
        let t = parse_ply(text.as_bytes()).expect("parses");
        assert_eq!(t.positions.len(), 4);
        assert_eq!(t.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(t.uvs.expect("uvs")[2], [1.0, 1.0]);
    }

    /// The shipped textured cube: every edge a seam, so each face's four corners are their own
    /// vertices (24), with the coordinates of the file.
    #[test]
    fn obj_texture_coordinates_split_vertices_at_seams() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube_uv.obj");
        let t = read_triangles(&path).expect("reads");
        assert_eq!(t.positions.len(), 24);
        assert_eq!(t.triangles.len(), 12);
        let uvs = t.uvs.expect("texture coordinates");
        assert_eq!(uvs.len(), 24);
        assert!((uvs[0][0] - 0.02).abs() < 1e-6 && (uvs[0][1] - 0.02).abs() < 1e-6);
        let plain = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let t = read_triangles(&plain).expect("reads");
        assert_eq!((t.positions.len(), t.triangles.len(), t.uvs), (8, 12, None));
    }

    #[test]
    fn a_ply_count_beyond_the_body_is_refused() {
        let text = "ply\nformat binary_little_endian 1.0\nelement vertex 10000000000\n\
                    property float x\nend_header\n\0\0\0\0";
        let e = parse_ply(text.as_bytes()).expect_err("refused");
        assert!(e.contains("more than the body holds"), "{e}");
    }

    #[test]
    fn a_glb_accessor_beyond_the_buffer_is_refused() {
        let json = br#"{"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[{"bufferView":0,"count":1000000,"componentType":5126,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":12}]}"#;
        let mut bytes = b"glTF".to_vec();
        bytes.extend(2u32.to_le_bytes());
        let padded = json.len().next_multiple_of(4);
        bytes.extend(((12 + 8 + padded + 8 + 12) as u32).to_le_bytes());
        bytes.extend((padded as u32).to_le_bytes());
        bytes.extend(b"JSON");
        bytes.extend(json);
        bytes.resize(20 + padded, b' ');
        bytes.extend(12u32.to_le_bytes());
        bytes.extend(b"BIN\0");
        bytes.extend([0u8; 12]);
        let e = parse_glb(&bytes).expect_err("refused");
        assert!(e.contains("needs"), "{e}");
    }
}
