//! Writing triangle meshes: Wavefront OBJ, binary PLY and glTF 2.0 (`.glb` and `.gltf`).
//!
//! [`write_mesh`] picks the format from the file's extension ([`MeshFormat::from_path`]);
//! `write_obj`, [`write_ply`], [`write_glb`] and [`write_gltf`] write one format each.
//! `docs/cli.md` ("Output formats") describes what each file holds, byte by byte for PLY.
//!
//! | format | positions, normals, triangles | per-vertex source face | source `(u, v)` |
//! |---|---|---|---|
//! | `.obj` | yes | no | no |
//! | `.ply` | yes | `uint face` | `float u v` |
//! | `.glb`, `.gltf` | yes | `_FACE` (FLOAT, when every face `< 2^24`) | `_UV_SOURCE` (VEC2 FLOAT) |
//!
//! The source `(u, v)` of a vertex is the exact rational `u / denominator`, `v / denominator`
//! of its [`VertexSource`]; the files hold the nearest `f32` (correctly rounded while the
//! numerator and denominator are below `2^24`, which every rate of the tables is).
//!
//! Every writer first checks that the mesh is consistent (as many normals and sources as
//! positions, every triangle index in range); a mesh that is not is refused with
//! [`RuntimeError::Io`] of kind [`std::io::ErrorKind::InvalidInput`] naming the problem, before
//! the file is created.

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;
use serde_json::{json, Value};

use crate::io::atomic::write_atomically;
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use crate::RuntimeError;

/// The `generator` written into every file's header or `asset`.
const GENERATOR: &str = concat!("subtess ", env!("CARGO_PKG_VERSION"));

/// `_FACE` is written only while every source face is below this bound: every integer below
/// `2^24` is exact in an `f32` (glTF forbids unsigned int components for custom attributes).
pub const GLTF_FACE_LIMIT: u32 = 1 << 24;

/// An output mesh format, chosen by a file's extension (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront OBJ: `v`, `vn`, `f a//a b//b c//c`.
    Obj,
    /// PLY 1.0, binary little-endian, with each vertex's source face and `(u, v)`.
    Ply,
    /// glTF 2.0 binary: one `.glb` file with a JSON and a BIN chunk.
    Glb,
    /// glTF 2.0 JSON with the buffer embedded as a base64 `data:` URI.
    Gltf,
}

impl MeshFormat {
    /// Every format, in the order error messages list them.
    pub const ALL: [MeshFormat; 4] = [
        MeshFormat::Obj,
        MeshFormat::Ply,
        MeshFormat::Glb,
        MeshFormat::Gltf,
    ];

    /// The file extension, lower case, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Glb => "glb",
            MeshFormat::Gltf => "gltf",
        }
    }

    /// The format `path`'s extension names (case-insensitive), or
    /// [`RuntimeError::Unsupported`] listing the supported extensions. Touches no file, so a
    /// caller can check an output path before doing the work.
    pub fn from_path(path: &Path) -> Result<MeshFormat, RuntimeError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if let Some(format) = MeshFormat::ALL
            .into_iter()
            .find(|f| ext.as_deref() == Some(f.extension()))
        {
            return Ok(format);
        }
        let supported: Vec<String> = MeshFormat::ALL
            .iter()
            .map(|f| format!(".{}", f.extension()))
            .collect();
        let what = match path.extension() {
            Some(e) => format!("output format `.{}`", e.to_string_lossy()),
            None => "an output file without an extension".to_string(),
        };
        Err(RuntimeError::Unsupported(format!(
            "{what} ({}); supported extensions: {}",
            path.display(),
            supported.join(", ")
        )))
    }
}

/// Write `mesh` in the format `path`'s extension names: `.obj`, `.ply`, `.glb` or `.gltf`
/// (case-insensitive). An unknown or missing extension is [`RuntimeError::Unsupported`] and
/// creates no file; I/O failures are [`RuntimeError::Io`] naming `path`.
pub fn write_mesh(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    match MeshFormat::from_path(path)? {
        MeshFormat::Obj => write_obj(mesh, path),
        MeshFormat::Ply => write_ply(mesh, path),
        MeshFormat::Glb => write_glb(mesh, path),
        MeshFormat::Gltf => write_gltf(mesh, path),
    }
}

/// The error constructor for `path`.
fn io_error(path: &Path) -> impl Fn(std::io::Error) -> RuntimeError + '_ {
    move |source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// A consistency problem of `mesh` as an I/O error of kind `InvalidInput` on `path`.
fn invalid(path: &Path, message: String) -> RuntimeError {
    io_error(path)(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        message,
    ))
}

/// Refuse a mesh whose arrays disagree or whose triangles index past its vertices.
fn check_consistent(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    let vertices = mesh.positions.len();
    if mesh.normals.len() != vertices || mesh.sources.len() != vertices {
        return Err(invalid(
            path,
            format!(
                "inconsistent mesh: {vertices} positions, {} normals, {} sources",
                mesh.normals.len(),
                mesh.sources.len()
            ),
        ));
    }
    if !mesh.uvs.is_empty() && mesh.uvs.len() != vertices {
        return Err(invalid(
            path,
            format!(
                "inconsistent mesh: {vertices} positions, {} texture coordinates",
                mesh.uvs.len()
            ),
        ));
    }
    // The largest index first (a branch-free pass that vectorizes); the offending triangle is
    // looked for only when there is one.
    match mesh.triangles.as_flattened().iter().copied().max() {
        Some(i) if i as usize >= vertices => {}
        _ => return Ok(()),
    }
    if let Some((t, triangle)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= vertices))
    {
        return Err(invalid(
            path,
            format!("triangle {t} {triangle:?} indexes past the {vertices} vertices"),
        ));
    }
    Ok(())
}

/// The source `(u, v)` as the `f32` nearest `u / denominator`, `v / denominator` (one correctly
/// rounded `f32` division while both are below `2^24`, so exact inputs).
fn source_uv(source: &VertexSource) -> [f32; 2] {
    let exact = |x: u32| x < GLTF_FACE_LIMIT;
    if exact(source.u) && exact(source.v) && exact(source.denominator) {
        let d = source.denominator as f32;
        [source.u as f32 / d, source.v as f32 / d]
    } else {
        let (u, v) = source.uv();
        [u as f32, v as f32]
    }
}

/// Write `mesh` as OBJ (`v`, `vn`, `f a//a b//b c//c`; with texture coordinates also `vt` and
/// `f a/a/a b/b/b c/c/c`).
pub fn write_obj(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    check_consistent(mesh, path)?;
    let io = io_error(path);
    write_atomically(path, |w| {
        writeln!(
            w,
            "# subtess dual-grid tessellation: {} vertices, {} triangles",
            mesh.positions.len(),
            mesh.triangles.len()
        )
        .map_err(&io)?;
        let floats = |tag: &'static [u8]| {
            move |buf: &mut Vec<u8>, xs: &[f32]| {
                let mut number = ryu::Buffer::new();
                buf.extend_from_slice(tag);
                for &x in xs {
                    buf.push(b' ');
                    buf.extend_from_slice(number.format(x).as_bytes());
                }
                buf.push(b'\n');
            }
        };
        let (v, vn, vt) = (floats(b"v"), floats(b"vn"), floats(b"vt"));
        write_lines(w, &mesh.positions, |buf, p| v(buf, p)).map_err(&io)?;
        write_lines(w, &mesh.normals, |buf, n| vn(buf, n)).map_err(&io)?;
        write_lines(w, &mesh.uvs, |buf, t| vt(buf, t)).map_err(&io)?;
        // `f a/a/a ...` with texture coordinates, `f a//a ...` without.
        let middle: &[u8] = if mesh.uvs.is_empty() { b"//" } else { b"/" };
        let last: &[u8] = if mesh.uvs.is_empty() { b"" } else { b"/" };
        write_lines(w, &mesh.triangles, |buf, t| {
            let mut number = itoa::Buffer::new();
            buf.push(b'f');
            for &i in t {
                let i = number.format(u64::from(i) + 1).as_bytes();
                buf.push(b' ');
                buf.extend_from_slice(i);
                buf.extend_from_slice(middle);
                if !last.is_empty() {
                    buf.extend_from_slice(i);
                    buf.extend_from_slice(last);
                }
                buf.extend_from_slice(i);
            }
            buf.push(b'\n');
        })
        .map_err(&io)?;
        Ok(())
    })
}

/// Lines formatted per parallel task in [`write_lines`].
const LINES_PER_TASK: usize = 1 << 14;

/// Write one line per item, formatted by `line` into buffers of [`LINES_PER_TASK`] lines in
/// parallel, a batch of buffers (two per thread) at a time, written in order: the output is the
/// sequential one, and the memory held is a batch, not the file.
fn write_lines<T: Sync>(
    w: &mut impl Write,
    items: &[T],
    line: impl Fn(&mut Vec<u8>, &T) + Sync,
) -> std::io::Result<()> {
    let batch = LINES_PER_TASK * 2 * rayon::current_num_threads().max(1);
    for group in items.chunks(batch) {
        let buffers: Vec<Vec<u8>> = group
            .par_chunks(LINES_PER_TASK)
            .map(|chunk| {
                let mut buf = Vec::with_capacity(48 * chunk.len());
                for item in chunk {
                    line(&mut buf, item);
                }
                buf
            })
            .collect();
        for buf in &buffers {
            w.write_all(buf)?;
        }
    }
    Ok(())
}

/// Bytes of one PLY vertex record: `x y z nx ny nz` (f32), `face` (u32), `u v` (f32),
/// `subface` (u8).
pub const PLY_VERTEX_BYTES: usize = 37;

/// Write `mesh` as binary little-endian PLY 1.0.
///
/// Each vertex is a [`PLY_VERTEX_BYTES`]-byte record `float x y z nx ny nz`, `uint face`,
/// `float u v`, `uchar subface`: position, normal, and the face and parameters it was evaluated
/// at ([`crate::mesh::triangle_mesh::VertexSource`]: the CLI writes the input mesh's faces; `subface`
/// is the sub-face of a non-quad face, 0 for quads); with texture coordinates, 8 more bytes
/// `float s t` follow. Each triangle is
/// `property list uchar uint vertex_indices` (the byte 3, then three `u32`), 13 bytes.
pub fn write_ply(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    check_consistent(mesh, path)?;
    let io = io_error(path);
    write_atomically(path, |w| {
        let header = format!(
            "ply\n\
         format binary_little_endian 1.0\n\
         comment generated by {GENERATOR}: limit positions and normals of a subdivision surface\n\
         comment face u v subface: the source face, its (u, v), the sub-face of a non-quad face\n\
         element vertex {}\n\
         property float x\n\
         property float y\n\
         property float z\n\
         property float nx\n\
         property float ny\n\
         property float nz\n\
         property uint face\n\
         property float u\n\
         property float v\n\
         property uchar subface\n\
         {}\
         element face {}\n\
         property list uchar uint vertex_indices\n\
         end_header\n",
            mesh.positions.len(),
            if mesh.uvs.is_empty() {
                ""
            } else {
                "property float s\nproperty float t\n"
            },
            mesh.triangles.len()
        );
        w.write_all(header.as_bytes()).map_err(&io)?;
        for (i, ((p, n), s)) in mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .zip(&mesh.sources)
            .enumerate()
        {
            let mut record = [0u8; PLY_VERTEX_BYTES + 8];
            let [u, v] = source_uv(s);
            let fields = [p[0], p[1], p[2], n[0], n[1], n[2]];
            for (k, x) in fields.iter().enumerate() {
                record[4 * k..4 * k + 4].copy_from_slice(&x.to_le_bytes());
            }
            record[24..28].copy_from_slice(&s.face.to_le_bytes());
            record[28..32].copy_from_slice(&u.to_le_bytes());
            record[32..36].copy_from_slice(&v.to_le_bytes());
            record[36] = s.subface;
            let size = match mesh.uvs.get(i) {
                Some(t) => {
                    record[37..41].copy_from_slice(&t[0].to_le_bytes());
                    record[41..45].copy_from_slice(&t[1].to_le_bytes());
                    PLY_VERTEX_BYTES + 8
                }
                None => PLY_VERTEX_BYTES,
            };
            w.write_all(&record[..size]).map_err(&io)?;
        }
        for t in &mesh.triangles {
            let mut record = [3u8; 13];
            for (k, i) in t.iter().enumerate() {
                record[1 + 4 * k..5 + 4 * k].copy_from_slice(&i.to_le_bytes());
            }
            w.write_all(&record).map_err(&io)?;
        }
        Ok(())
    })
}

/// glTF `componentType` FLOAT.
const GL_FLOAT: u32 = 5126;
/// glTF `componentType` UNSIGNED_INT.
const GL_UNSIGNED_INT: u32 = 5125;
/// glTF bufferView `target` ARRAY_BUFFER (vertex attributes).
const GL_ARRAY_BUFFER: u32 = 34962;
/// glTF bufferView `target` ELEMENT_ARRAY_BUFFER (indices).
const GL_ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// A glTF document for `mesh`: its JSON (without `buffers[0].uri`) and its one buffer.
struct Gltf {
    json: Value,
    buffer: Vec<u8>,
}

/// Build the glTF document: one buffer, one bufferView per attribute and one for the indices
/// (each a multiple of 4 bytes, so every accessor is aligned), one mesh with one primitive
/// (mode 4, TRIANGLES; mode 0, POINTS, without indices for a mesh with vertices but no
/// triangles), one node, one scene. A mesh without vertices gives an empty scene and no buffer
/// (glTF allows no accessor with count 0).
fn build_gltf(mesh: &TriangleMesh, path: &Path) -> Result<Gltf, RuntimeError> {
    check_consistent(mesh, path)?;
    let asset = json!({ "version": "2.0", "generator": GENERATOR });
    if mesh.positions.is_empty() {
        return Ok(Gltf {
            json: json!({ "asset": asset, "scene": 0, "scenes": [{}] }),
            buffer: Vec::new(),
        });
    }
    // POSITION must carry min and max; JSON has no NaN or infinity.
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for (i, p) in mesh.positions.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            return Err(invalid(
                path,
                format!("vertex {i} has a non-finite position {p:?}"),
            ));
        }
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
        }
    }
    let with_face = mesh.sources.iter().all(|s| s.face < GLTF_FACE_LIMIT);

    let mut buffer = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut attributes = serde_json::Map::new();
    // Append one tightly packed bufferView and its accessor; returns the accessor's index.
    let mut add = |bytes: Vec<u8>, target: u32, accessor: Value| -> usize {
        views.push(json!({
            "buffer": 0,
            "byteOffset": buffer.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        let mut accessor = accessor;
        accessor["bufferView"] = json!(views.len() - 1);
        buffer.extend_from_slice(&bytes);
        accessors.push(accessor);
        accessors.len() - 1
    };
    let count = mesh.positions.len();

    let positions = f32_bytes(mesh.positions.iter().flatten().copied());
    let position = add(
        positions,
        GL_ARRAY_BUFFER,
        json!({ "componentType": GL_FLOAT, "count": count, "type": "VEC3",
                "min": min, "max": max }),
    );
    attributes.insert("POSITION".into(), json!(position));
    let normals = f32_bytes(mesh.normals.iter().flatten().copied());
    let normal = add(
        normals,
        GL_ARRAY_BUFFER,
        json!({ "componentType": GL_FLOAT, "count": count, "type": "VEC3" }),
    );
    attributes.insert("NORMAL".into(), json!(normal));
    if !mesh.uvs.is_empty() {
        // glTF's texture origin is the image's top left, OBJ's its bottom left.
        let uvs = f32_bytes(mesh.uvs.iter().flat_map(|t| [t[0], 1.0 - t[1]]));
        let uv = add(
            uvs,
            GL_ARRAY_BUFFER,
            json!({ "componentType": GL_FLOAT, "count": count, "type": "VEC2" }),
        );
        attributes.insert("TEXCOORD_0".into(), json!(uv));
    }
    let uvs = f32_bytes(mesh.sources.iter().flat_map(source_uv));
    let uv = add(
        uvs,
        GL_ARRAY_BUFFER,
        json!({ "componentType": GL_FLOAT, "count": count, "type": "VEC2" }),
    );
    attributes.insert("_UV_SOURCE".into(), json!(uv));
    if with_face {
        let faces = f32_bytes(mesh.sources.iter().map(|s| s.face as f32));
        let face = add(
            faces,
            GL_ARRAY_BUFFER,
            json!({ "componentType": GL_FLOAT, "count": count, "type": "SCALAR" }),
        );
        attributes.insert("_FACE".into(), json!(face));
    }
    let mut primitive = json!({ "attributes": attributes, "mode": 0 });
    if !mesh.triangles.is_empty() {
        let indices: Vec<u8> = mesh
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let index = add(
            indices,
            GL_ELEMENT_ARRAY_BUFFER,
            json!({ "componentType": GL_UNSIGNED_INT, "count": 3 * mesh.triangles.len(),
                    "type": "SCALAR" }),
        );
        primitive["indices"] = json!(index);
        primitive["mode"] = json!(4);
    }
    let json = json!({
        "asset": asset,
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [primitive] }],
        "buffers": [{ "byteLength": buffer.len() }],
        "bufferViews": views,
        "accessors": accessors,
    });
    Ok(Gltf { json, buffer })
}

/// Little-endian bytes of `values`.
fn f32_bytes(values: impl Iterator<Item = f32>) -> Vec<u8> {
    values.flat_map(f32::to_le_bytes).collect()
}

/// Serialize a JSON value (cannot fail for a `Value`; mapped to an I/O error all the same).
fn json_bytes(json: &Value, path: &Path) -> Result<Vec<u8>, RuntimeError> {
    serde_json::to_vec(json).map_err(|e| io_error(path)(std::io::Error::other(e)))
}

/// Write `mesh` as a glTF 2.0 binary (`.glb`).
///
/// One buffer in the BIN chunk, in this order: `POSITION` (VEC3 FLOAT, with `min`/`max`),
/// `NORMAL` (VEC3 FLOAT), with texture coordinates `TEXCOORD_0` (VEC2 FLOAT, `(s, 1 - t)`:
/// glTF's origin is the image's top left), `_UV_SOURCE` (VEC2 FLOAT: the source `(u, v)`),
/// `_FACE` (SCALAR FLOAT: the source face, written only while every face is below
/// [`GLTF_FACE_LIMIT`], where `f32` holds it exactly; glTF forbids unsigned int components for
/// custom attributes), then the indices (SCALAR UNSIGNED_INT). One bufferView each (`target` 34962 for attributes,
/// 34963 for indices), one mesh with one TRIANGLES primitive, one node, one scene;
/// `asset.generator` is `subtess VERSION`. The JSON chunk is padded with spaces and the BIN
/// chunk with zeros to multiples of 4 bytes. A file of 4 GiB or more (about 100 million
/// triangles) cannot be a GLB and is refused.
pub fn write_glb(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    let gltf = build_gltf(mesh, path)?;
    let mut json = json_bytes(&gltf.json, path)?;
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = gltf.buffer;
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let to_u32 = |n: usize| {
        u32::try_from(n).map_err(|_| {
            invalid(
                path,
                format!("{n} bytes do not fit a GLB (4 GiB at most); write .ply or .obj"),
            )
        })
    };
    let total = to_u32(total)?;
    let io = io_error(path);
    write_atomically(path, |w| {
        w.write_all(b"glTF").map_err(&io)?;
        w.write_all(&2u32.to_le_bytes()).map_err(&io)?;
        w.write_all(&total.to_le_bytes()).map_err(&io)?;
        w.write_all(&to_u32(json.len())?.to_le_bytes())
            .map_err(&io)?;
        w.write_all(b"JSON").map_err(&io)?;
        w.write_all(&json).map_err(&io)?;
        if !bin.is_empty() {
            w.write_all(&to_u32(bin.len())?.to_le_bytes())
                .map_err(&io)?;
            w.write_all(b"BIN\0").map_err(&io)?;
            w.write_all(&bin).map_err(&io)?;
        }
        Ok(())
    })
}

/// Write `mesh` as glTF 2.0 JSON (`.gltf`): the same document as [`write_glb`], with the buffer
/// embedded in `buffers[0].uri` as `data:application/octet-stream;base64,...` (standard
/// alphabet, `=` padding).
pub fn write_gltf(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    let mut gltf = build_gltf(mesh, path)?;
    if !gltf.buffer.is_empty() {
        gltf.json["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64(&gltf.buffer)
        ));
    }
    let json = json_bytes(&gltf.json, path)?;
    write_atomically(path, |w| w.write_all(&json).map_err(io_error(path)))
}

/// Base64 (RFC 4648 section 4: standard alphabet, `=` padding).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * k) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{base64, check_consistent, TriangleMesh, VertexSource};
    use std::path::Path;

    /// A triangle naming a vertex past the end is refused, named, wherever it is (the first one
    /// when there are several); a mesh within its vertices, or with no triangles, passes.
    #[test]
    fn triangles_past_the_vertices_are_refused() {
        let mesh = |triangles: Vec<[u32; 3]>| TriangleMesh {
            positions: vec![[0.0; 3]; 4],
            normals: vec![[0.0; 3]; 4],
            sources: vec![VertexSource::default(); 4],
            triangles,
            ..TriangleMesh::default()
        };
        let path = Path::new("out.ply");
        assert!(check_consistent(&mesh(vec![[0, 1, 2], [0, 2, 3]]), path).is_ok());
        assert!(check_consistent(&mesh(Vec::new()), path).is_ok());
        for (triangles, named) in [
            (vec![[0, 1, 4], [0, 2, 3]], "triangle 0 [0, 1, 4]"),
            (
                vec![[0, 1, 2], [9, 2, 3], [0, 5, 1]],
                "triangle 1 [9, 2, 3]",
            ),
            (
                vec![[0, 1, 2], [0, 2, u32::MAX]],
                "triangle 1 [0, 2, 4294967295]",
            ),
        ] {
            let error = check_consistent(&mesh(triangles), path)
                .expect_err("refused")
                .to_string();
            assert!(error.contains(named), "{error}");
            assert!(error.contains("indexes past the 4 vertices"), "{error}");
        }
    }

    /// The test vectors of RFC 4648 section 10.
    #[test]
    fn base64_matches_rfc_4648() {
        for (input, expected) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), expected);
        }
    }
}
