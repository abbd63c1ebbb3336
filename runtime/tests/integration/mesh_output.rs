//! Mesh output (OBJ, PLY, GLB, glTF) read back by minimal parsers written here, independent of
//! the writers: every position, normal, index, source face and `(u, v)` must round-trip bit for
//! bit, and the files must have the byte layout the PLY 1.0 and glTF 2.0 specifications require
//! (chunk alignment and padding, accessor bounds, POSITION `min`/`max`).
//!
//! Expected values come from the meshes themselves: a hand-made tetrahedron (chosen values,
//! including `-0.0`, non-dyadic `u/v` and distinct faces) and the dual-grid tessellation of
//! `data/cube.obj`. `(u, v)` are checked against the exact rational: the read `f32` must be the
//! one nearest `u / denominator` (compared with its two neighbours in f64).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use serde_json::Value;
use subtess::io::mesh_output::{write_glb, write_gltf, write_mesh, write_obj, write_ply};
use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::tessellate_uniform;
use subtess::RuntimeError;

// ---------------------------------------------------------------------------------------------
// Meshes and temporary files

/// A tetrahedron with chosen, distinguishable values: no two vertices share a coordinate, a
/// normal or a source, one coordinate is `-0.0`, the parameters are not all dyadic.
fn tetrahedron() -> TriangleMesh {
    let positions = vec![
        [1.0, 1.0, 1.0],
        [1.5, -1.25, -0.0],
        [-1.0, 0.1, -1.0],
        [-1.0, -1.0, 3.3e-7],
    ];
    let normals: Vec<[f32; 3]> = positions
        .iter()
        .map(|p: &[f32; 3]| {
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            [p[0] / l, p[1] / l, p[2] / l]
        })
        .collect();
    let source = |face, u, v, denominator| VertexSource {
        face,
        u,
        v,
        denominator,
        subface: (face % 3) as u8,
    };
    TriangleMesh {
        positions,
        normals,
        sources: vec![
            source(0, 1, 2, 3),
            source(7, 3, 1, 8),
            source(12, 5, 2, 7),
            source(1 << 20, 0, 10, 10),
        ],
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        ..TriangleMesh::default()
    }
}

/// The dual-grid tessellation of the shipped cube at rate 3 (sources with denominator 6).
fn cube() -> TriangleMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
    let obj = read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0;
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (isolated, patches, _) = isolate(&mesh).expect("isolates");
    let (out, _) = tessellate_uniform(&table, &isolated, &patches, 3).expect("tessellates");
    assert!(out.is_watertight());
    assert_eq!(out.positions.len(), patches.len() * 9);
    out
}

/// A fresh path in the system's temporary folder (process id and a counter keep it unique).
fn temp_path(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!(
        "subtess-mesh-output-{}-{n}-{name}",
        std::process::id()
    ))
}

/// Write with `write`, read the bytes back, remove the file.
fn written(
    name: &str,
    mesh: &TriangleMesh,
    write: fn(&TriangleMesh, &Path) -> Result<(), RuntimeError>,
) -> Vec<u8> {
    let path = temp_path(name);
    write(mesh, &path).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
    let bytes = std::fs::read(&path).expect("reads back");
    std::fs::remove_file(&path).expect("removes");
    bytes
}

// ---------------------------------------------------------------------------------------------
// Checks shared by the formats

fn bits3(p: &[f32; 3]) -> [u32; 3] {
    p.map(f32::to_bits)
}

/// `r` is the `f32` nearest `num / den` (ties either way).
fn assert_nearest(r: f32, num: u32, den: u32, what: &str) {
    let q = f64::from(num) / f64::from(den);
    if q == 0.0 {
        assert_eq!(r.to_bits(), 0, "{what}: {r} for 0");
        return;
    }
    assert!(r > 0.0, "{what}: {r} for {num}/{den}");
    let below = f32::from_bits(r.to_bits() - 1);
    let above = f32::from_bits(r.to_bits() + 1);
    let err = (f64::from(r) - q).abs();
    assert!(
        err <= (f64::from(below) - q).abs() && err <= (f64::from(above) - q).abs(),
        "{what}: {r} is not the f32 nearest {num}/{den}"
    );
}

/// The source `(u, v)` read back as `f32`s are the nearest to the exact rationals.
fn assert_sources(mesh: &TriangleMesh, faces: Option<&[u32]>, uvs: &[[f32; 2]], what: &str) {
    assert_eq!(uvs.len(), mesh.sources.len(), "{what}: source count");
    for (i, (s, uv)) in mesh.sources.iter().zip(uvs).enumerate() {
        assert_nearest(uv[0], s.u, s.denominator, &format!("{what} vertex {i} u"));
        assert_nearest(uv[1], s.v, s.denominator, &format!("{what} vertex {i} v"));
        if let Some(faces) = faces {
            assert_eq!(faces[i], s.face, "{what} vertex {i} face");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// PLY: a minimal reader for binary little-endian PLY 1.0

#[derive(Debug, PartialEq)]
enum PlyProperty {
    Scalar(String, String),
    List(String, String, String),
}

struct PlyElement {
    name: String,
    count: usize,
    properties: Vec<PlyProperty>,
}

#[derive(Debug, Clone, Copy)]
enum PlyValue {
    F32(f32),
    U32(u32),
}

fn ply_type_size(t: &str) -> usize {
    match t {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        other => panic!("unknown PLY type {other}"),
    }
}

fn ply_read(t: &str, bytes: &[u8], at: &mut usize) -> PlyValue {
    let size = ply_type_size(t);
    let b = &bytes[*at..*at + size];
    *at += size;
    match t {
        "float" | "float32" => PlyValue::F32(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        "uint" | "uint32" => PlyValue::U32(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        "uchar" | "uint8" => PlyValue::U32(u32::from(b[0])),
        other => panic!("this reader does not take {other}"),
    }
}

/// One parsed row of an element: each property's name and values (one for a scalar).
type PlyRow = Vec<(String, Vec<PlyValue>)>;

/// Parsed PLY: comments, elements, and each element's rows.
struct Ply {
    comments: Vec<String>,
    elements: Vec<PlyElement>,
    rows: Vec<Vec<PlyRow>>,
}

fn parse_ply(bytes: &[u8]) -> Ply {
    let end = b"end_header\n";
    let header_len = bytes
        .windows(end.len())
        .position(|w| w == end)
        .expect("end_header")
        + end.len();
    let header = std::str::from_utf8(&bytes[..header_len]).expect("ASCII header");
    let mut lines = header.lines();
    assert_eq!(lines.next(), Some("ply"));
    assert_eq!(lines.next(), Some("format binary_little_endian 1.0"));
    let mut comments = Vec::new();
    let mut elements: Vec<PlyElement> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["comment", ..] => comments.push(line["comment ".len()..].to_string()),
            ["element", name, count] => elements.push(PlyElement {
                name: name.to_string(),
                count: count.parse().expect("element count"),
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => elements
                .last_mut()
                .expect("property after element")
                .properties
                .push(PlyProperty::List(
                    count.to_string(),
                    item.to_string(),
                    name.to_string(),
                )),
            ["property", t, name] => elements
                .last_mut()
                .expect("property after element")
                .properties
                .push(PlyProperty::Scalar(t.to_string(), name.to_string())),
            ["end_header"] => {}
            _ => panic!("unexpected PLY header line {line:?}"),
        }
    }
    let mut at = header_len;
    let mut rows = Vec::new();
    for element in &elements {
        let mut element_rows = Vec::with_capacity(element.count);
        for _ in 0..element.count {
            let mut row = Vec::new();
            for property in &element.properties {
                match property {
                    PlyProperty::Scalar(t, name) => {
                        row.push((name.clone(), vec![ply_read(t, bytes, &mut at)]))
                    }
                    PlyProperty::List(count_type, item, name) => {
                        let PlyValue::U32(n) = ply_read(count_type, bytes, &mut at) else {
                            panic!("list count is not an integer")
                        };
                        let values = (0..n).map(|_| ply_read(item, bytes, &mut at)).collect();
                        row.push((name.clone(), values));
                    }
                }
            }
            element_rows.push(row);
        }
        rows.push(element_rows);
    }
    assert_eq!(at, bytes.len(), "PLY body has trailing or missing bytes");
    Ply {
        comments,
        elements,
        rows,
    }
}

fn f32_of(v: &PlyValue) -> f32 {
    match v {
        PlyValue::F32(x) => *x,
        PlyValue::U32(_) => panic!("expected a float"),
    }
}

fn u32_of(v: &PlyValue) -> u32 {
    match v {
        PlyValue::U32(x) => *x,
        PlyValue::F32(_) => panic!("expected an integer"),
    }
}

fn check_ply(mesh: &TriangleMesh, bytes: &[u8], what: &str) {
    let ply = parse_ply(bytes);
    assert!(
        ply.comments.iter().any(|c| c.contains("subtess")),
        "{what}: no comment names subtess"
    );
    assert_eq!(ply.elements.len(), 2);
    let (vertex, face) = (&ply.elements[0], &ply.elements[1]);
    assert_eq!(
        (vertex.name.as_str(), vertex.count),
        ("vertex", mesh.positions.len())
    );
    assert_eq!(
        (face.name.as_str(), face.count),
        ("face", mesh.triangles.len())
    );
    let scalar = |t: &str, n: &str| PlyProperty::Scalar(t.into(), n.into());
    assert_eq!(
        vertex.properties,
        vec![
            scalar("float", "x"),
            scalar("float", "y"),
            scalar("float", "z"),
            scalar("float", "nx"),
            scalar("float", "ny"),
            scalar("float", "nz"),
            scalar("uint", "face"),
            scalar("float", "u"),
            scalar("float", "v"),
            scalar("uchar", "subface"),
        ]
    );
    assert_eq!(
        face.properties,
        vec![PlyProperty::List(
            "uchar".into(),
            "uint".into(),
            "vertex_indices".into()
        )]
    );
    // The documented record sizes: 37 bytes a vertex, 13 a triangle (parse_ply checked that
    // the body is exactly the header's elements).
    let record: usize = vertex
        .properties
        .iter()
        .map(|p| match p {
            PlyProperty::Scalar(t, _) => ply_type_size(t),
            PlyProperty::List(..) => unreachable!(),
        })
        .sum();
    assert_eq!(record, subtess::io::mesh_output::PLY_VERTEX_BYTES);
    let header_len = bytes.len() - 37 * mesh.positions.len() - 13 * mesh.triangles.len();
    assert!(bytes[..header_len].ends_with(b"end_header\n"));

    let mut faces = Vec::new();
    let mut uvs = Vec::new();
    for (i, row) in ply.rows[0].iter().enumerate() {
        let get = |k: usize| f32_of(&row[k].1[0]);
        let position = [get(0), get(1), get(2)];
        let normal = [get(3), get(4), get(5)];
        assert_eq!(
            bits3(&position),
            bits3(&mesh.positions[i]),
            "{what} position {i}"
        );
        assert_eq!(bits3(&normal), bits3(&mesh.normals[i]), "{what} normal {i}");
        faces.push(u32_of(&row[6].1[0]));
        uvs.push([get(7), get(8)]);
        assert_eq!(
            u32_of(&row[9].1[0]),
            u32::from(mesh.sources[i].subface),
            "{what} subface {i}"
        );
    }
    assert_sources(mesh, Some(&faces), &uvs, what);
    for (t, row) in ply.rows[1].iter().enumerate() {
        let indices: Vec<u32> = row[0].1.iter().map(u32_of).collect();
        assert_eq!(indices, mesh.triangles[t].to_vec(), "{what} triangle {t}");
    }
}

// ---------------------------------------------------------------------------------------------
// glTF: GLB container, base64 data URIs, accessors

fn le_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Split a GLB into its JSON document and BIN chunk, checking header, lengths, chunk types,
/// 4-byte alignment and padding (spaces after the JSON, zeros after the buffer).
fn parse_glb(bytes: &[u8]) -> (Value, Option<Vec<u8>>) {
    assert_eq!(&bytes[0..4], b"glTF", "magic");
    assert_eq!(le_u32(bytes, 4), 2, "version");
    assert_eq!(le_u32(bytes, 8) as usize, bytes.len(), "header length");
    assert_eq!(bytes.len() % 4, 0);
    let json_len = le_u32(bytes, 12) as usize;
    assert_eq!(json_len % 4, 0, "JSON chunk length is a multiple of 4");
    assert_eq!(&bytes[16..20], b"JSON");
    let json = &bytes[20..20 + json_len];
    let text = std::str::from_utf8(json).expect("UTF-8 JSON");
    let trimmed = text.trim_end_matches(' ');
    assert!(json_len - trimmed.len() < 4, "at most 3 padding spaces");
    assert!(
        trimmed.ends_with('}'),
        "JSON ends with its object, then spaces"
    );
    let doc: Value = serde_json::from_str(trimmed).expect("JSON chunk parses");
    let next = 20 + json_len;
    if next == bytes.len() {
        return (doc, None);
    }
    let bin_len = le_u32(bytes, next) as usize;
    assert_eq!(bin_len % 4, 0, "BIN chunk length is a multiple of 4");
    assert_eq!(&bytes[next + 4..next + 8], b"BIN\0");
    assert_eq!(next + 8 + bin_len, bytes.len(), "BIN is the last chunk");
    let bin = bytes[next + 8..].to_vec();
    let declared = doc["buffers"][0]["byteLength"]
        .as_u64()
        .expect("byteLength") as usize;
    assert!(declared <= bin_len && bin_len - declared < 4, "BIN padding");
    assert!(
        bin[declared..].iter().all(|&b| b == 0),
        "BIN padded with zeros"
    );
    (doc, Some(bin[..declared].to_vec()))
}

/// RFC 4648 base64 (standard alphabet, `=` padding), strict.
fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {:?}", char::from(c)),
        }
    };
    let bytes = text.as_bytes();
    assert_eq!(bytes.len() % 4, 0, "base64 length is a multiple of 4");
    let mut out = Vec::new();
    for (k, quad) in bytes.chunks(4).enumerate() {
        let pad = quad.iter().rev().take_while(|&&c| c == b'=').count();
        assert!(
            pad <= 2 && (pad == 0 || k == bytes.len() / 4 - 1),
            "padding"
        );
        let n = quad[..4 - pad]
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &c)| n | value(c) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

#[test]
fn base64_decoder_matches_rfc_4648() {
    for (expected, encoded) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(base64_decode(encoded), expected.as_bytes());
    }
}

/// One accessor resolved through its bufferView to its bytes, with the spec's checks:
/// in-bounds view and accessor, offset aligned to the component size, tight packing.
struct Accessor {
    component_type: u64,
    kind: String,
    count: usize,
    bytes: Vec<u8>,
    target: Option<u64>,
    accessor: Value,
}

fn accessor(doc: &Value, buffer: &[u8], index: u64) -> Accessor {
    let a = &doc["accessors"][index as usize];
    let view = &doc["bufferViews"][a["bufferView"].as_u64().expect("bufferView") as usize];
    assert_eq!(view["buffer"], 0);
    let view_offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let view_len = view["byteLength"].as_u64().expect("view byteLength") as usize;
    assert!(
        view_len >= 1 && view_offset + view_len <= buffer.len(),
        "view in buffer"
    );
    let offset = a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let component_type = a["componentType"].as_u64().expect("componentType");
    let component = match component_type {
        5126 | 5125 => 4,
        other => panic!("unexpected componentType {other}"),
    };
    let kind = a["type"].as_str().expect("type").to_string();
    let components = match kind.as_str() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        other => panic!("unexpected type {other}"),
    };
    let count = a["count"].as_u64().expect("count") as usize;
    assert!(count >= 1);
    let element = component * components;
    if let Some(stride) = view["byteStride"].as_u64() {
        assert_eq!(stride as usize, element);
    }
    assert_eq!((view_offset + offset) % component, 0, "accessor alignment");
    assert!(offset + count * element <= view_len, "accessor in view");
    let start = view_offset + offset;
    Accessor {
        component_type,
        kind,
        count,
        bytes: buffer[start..start + count * element].to_vec(),
        target: view["target"].as_u64(),
        accessor: a.clone(),
    }
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Check a glTF document and its buffer against `mesh`.
fn check_gltf(mesh: &TriangleMesh, doc: &Value, buffer: &[u8], what: &str) {
    assert_eq!(doc["asset"]["version"], "2.0");
    let generator = doc["asset"]["generator"].as_str().expect("generator");
    assert!(
        generator.contains("subtess"),
        "{what}: generator {generator}"
    );
    assert_eq!(doc["scene"], 0);
    assert_eq!(doc["scenes"], serde_json::json!([{ "nodes": [0] }]));
    assert_eq!(doc["nodes"], serde_json::json!([{ "mesh": 0 }]));
    let primitives = doc["meshes"][0]["primitives"]
        .as_array()
        .expect("primitives");
    assert_eq!(doc["meshes"].as_array().map(Vec::len), Some(1));
    assert_eq!(doc["buffers"].as_array().map(Vec::len), Some(1));
    assert_eq!(primitives.len(), 1);
    let primitive = &primitives[0];
    assert_eq!(primitive["mode"], 4, "{what}: TRIANGLES");
    let attributes = primitive["attributes"].as_object().expect("attributes");
    let get = |name: &str| {
        let index = attributes[name].as_u64().expect("attribute index");
        let a = accessor(doc, buffer, index);
        assert_eq!(a.component_type, 5126, "{what} {name}: FLOAT");
        assert_eq!(a.count, mesh.positions.len(), "{what} {name}: count");
        assert_eq!(a.target, Some(34962), "{what} {name}: ARRAY_BUFFER");
        a
    };

    let position = get("POSITION");
    assert_eq!(position.kind, "VEC3");
    let positions = floats(&position.bytes);
    for (i, p) in mesh.positions.iter().enumerate() {
        let read = [positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]];
        assert_eq!(bits3(&read), bits3(p), "{what} position {i}");
    }
    // min and max: the true bounds, compared as f32 values (-0.0 == 0.0).
    for c in 0..3 {
        let lo = mesh
            .positions
            .iter()
            .map(|p| p[c])
            .fold(f32::INFINITY, f32::min);
        let hi = mesh
            .positions
            .iter()
            .map(|p| p[c])
            .fold(f32::NEG_INFINITY, f32::max);
        let min = position.accessor["min"][c].as_f64().expect("min") as f32;
        let max = position.accessor["max"][c].as_f64().expect("max") as f32;
        assert_eq!(
            (min, max),
            (lo, hi),
            "{what} POSITION bounds, component {c}"
        );
    }

    let normal = get("NORMAL");
    assert_eq!(normal.kind, "VEC3");
    let normals = floats(&normal.bytes);
    for (i, n) in mesh.normals.iter().enumerate() {
        let read = [normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]];
        assert_eq!(bits3(&read), bits3(n), "{what} normal {i}");
    }

    let uv = get("_UV_SOURCE");
    assert_eq!(uv.kind, "VEC2");
    let uvs: Vec<[f32; 2]> = floats(&uv.bytes)
        .chunks_exact(2)
        .map(|c| [c[0], c[1]])
        .collect();
    let needs_face = mesh.sources.iter().all(|s| s.face < 1 << 24);
    assert_eq!(
        attributes.contains_key("_FACE"),
        needs_face,
        "{what}: _FACE"
    );
    let faces: Option<Vec<u32>> = needs_face.then(|| {
        let face = get("_FACE");
        assert_eq!(face.kind, "SCALAR");
        floats(&face.bytes)
            .into_iter()
            .map(|f| {
                assert!(
                    f >= 0.0 && f.fract() == 0.0,
                    "{what}: face {f} not an integer"
                );
                f as u32
            })
            .collect()
    });
    assert_sources(mesh, faces.as_deref(), &uvs, what);
    assert_eq!(attributes.len(), 3 + usize::from(needs_face));

    let indices = accessor(doc, buffer, primitive["indices"].as_u64().expect("indices"));
    assert_eq!(indices.component_type, 5125, "{what}: UNSIGNED_INT indices");
    assert_eq!(indices.kind, "SCALAR");
    assert_eq!(indices.target, Some(34963), "{what}: ELEMENT_ARRAY_BUFFER");
    assert_eq!(indices.count, 3 * mesh.triangles.len());
    let read: Vec<u32> = indices
        .bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let expected: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    assert_eq!(read, expected, "{what}: indices");
}

fn check_glb(mesh: &TriangleMesh, bytes: &[u8], what: &str) -> Value {
    let (doc, bin) = parse_glb(bytes);
    assert!(
        doc["buffers"][0].get("uri").is_none(),
        "GLB buffer has no uri"
    );
    let bin = bin.expect("a BIN chunk");
    check_gltf(mesh, &doc, &bin, what);
    doc
}

/// Check a `.gltf` file; returns its document without the buffer's `uri`, and the buffer.
fn check_gltf_file(mesh: &TriangleMesh, bytes: &[u8], what: &str) -> (Value, Vec<u8>) {
    let mut doc: Value = serde_json::from_slice(bytes).expect("glTF JSON parses");
    let uri = doc["buffers"][0]["uri"].as_str().expect("uri").to_string();
    let data = uri
        .strip_prefix("data:application/octet-stream;base64,")
        .expect("data URI prefix");
    let buffer = base64_decode(data);
    assert_eq!(
        doc["buffers"][0]["byteLength"].as_u64(),
        Some(buffer.len() as u64)
    );
    check_gltf(mesh, &doc, &buffer, what);
    doc["buffers"][0]
        .as_object_mut()
        .expect("buffer")
        .remove("uri");
    (doc, buffer)
}

fn check_obj(mesh: &TriangleMesh, bytes: &[u8], what: &str) {
    let text = std::str::from_utf8(bytes).expect("UTF-8");
    let (mut v, mut vn, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let xyz =
            |w: &[&str]| -> [f32; 3] { [0, 1, 2].map(|k| w[k].parse::<f32>().expect("number")) };
        match words.first() {
            Some(&"v") => v.push(xyz(&words[1..])),
            Some(&"vn") => vn.push(xyz(&words[1..])),
            Some(&"f") => f.push([1, 2, 3].map(|k| {
                let (a, b) = words[k].split_once("//").expect("a//a");
                assert_eq!(a, b);
                a.parse::<u32>().expect("index") - 1
            })),
            _ => {}
        }
    }
    assert_eq!(
        v.iter().map(bits3).collect::<Vec<_>>(),
        mesh.positions.iter().map(bits3).collect::<Vec<_>>(),
        "{what}"
    );
    assert_eq!(
        vn.iter().map(bits3).collect::<Vec<_>>(),
        mesh.normals.iter().map(bits3).collect::<Vec<_>>(),
        "{what}"
    );
    assert_eq!(f, mesh.triangles, "{what}");
}

// ---------------------------------------------------------------------------------------------
// Tests

#[test]
#[cfg(feature = "catmull-clark")]
fn every_format_round_trips_the_tetrahedron_and_the_tessellated_cube() {
    for (name, mesh) in [("tetrahedron", tetrahedron()), ("cube", cube())] {
        check_ply(
            &mesh,
            &written("m.ply", &mesh, write_ply),
            &format!("{name}.ply"),
        );
        let glb = check_glb(
            &mesh,
            &written("m.glb", &mesh, write_glb),
            &format!("{name}.glb"),
        );
        let (gltf, buffer) = check_gltf_file(
            &mesh,
            &written("m.gltf", &mesh, write_gltf),
            &format!("{name}.gltf"),
        );
        // The .gltf is the .glb's document, with the same buffer.
        assert_eq!(gltf, glb, "{name}: .gltf and .glb documents differ");
        let (_, bin) = parse_glb(&written("m.glb", &mesh, write_glb));
        assert_eq!(Some(buffer), bin, "{name}: .gltf and .glb buffers differ");
        check_obj(
            &mesh,
            &written("m.obj", &mesh, write_obj),
            &format!("{name}.obj"),
        );
    }
}

/// `_FACE` is FLOAT (glTF forbids unsigned int custom attributes): written while every face is
/// below 2^24, where f32 is exact (2^24 - 1 round-trips), left out from 2^24 on. The buffers
/// are then no longer a multiple of 3 bytes, so base64 padding (`=` and `==`) is exercised.
#[test]
fn gltf_face_attribute_only_while_exact() {
    let mut mesh = tetrahedron();
    mesh.sources[2].face = (1 << 24) - 1;
    let doc = check_glb(&mesh, &written("m.glb", &mesh, write_glb), "2^24 - 1");
    assert!(doc["meshes"][0]["primitives"][0]["attributes"]
        .get("_FACE")
        .is_some());

    mesh.sources[2].face = 1 << 24;
    for extra in 0..3 {
        let mut m = mesh.clone();
        for k in 0..extra {
            m.positions.push([k as f32, 2.0, -3.5]);
            m.normals.push([0.0, 0.0, 1.0]);
            m.sources.push(VertexSource {
                face: 3,
                u: 1,
                v: 2,
                denominator: 5,
                subface: 0,
            });
        }
        let doc = check_glb(&m, &written("m.glb", &m, write_glb), "2^24");
        assert!(doc["meshes"][0]["primitives"][0]["attributes"]
            .get("_FACE")
            .is_none());
        let (_, buffer) = check_gltf_file(&m, &written("m.gltf", &m, write_gltf), "2^24 gltf");
        assert_eq!(
            buffer.len(),
            32 * m.positions.len() + 12 * m.triangles.len()
        );
        // The PLY keeps the face whatever its size.
        check_ply(&m, &written("m.ply", &m, write_ply), "2^24 ply");
    }
}

/// Meshes without triangles, or without vertices, still make valid files (glTF allows no
/// accessor of count 0: points without indices, or an empty scene without a buffer).
#[test]
fn degenerate_meshes_make_valid_files() {
    let mut points = tetrahedron();
    points.triangles.clear();
    let (doc, bin) = parse_glb(&written("points.glb", &points, write_glb));
    let primitive = &doc["meshes"][0]["primitives"][0];
    assert_eq!(primitive["mode"], 0);
    assert!(primitive.get("indices").is_none());
    let bin = bin.expect("BIN chunk");
    let position = accessor(
        &doc,
        &bin,
        primitive["attributes"]["POSITION"]
            .as_u64()
            .expect("POSITION"),
    );
    assert_eq!(position.count, 4);
    check_ply(
        &points,
        &written("points.ply", &points, write_ply),
        "points.ply",
    );

    let empty = TriangleMesh::default();
    let (doc, bin) = parse_glb(&written("empty.glb", &empty, write_glb));
    assert!(bin.is_none());
    assert_eq!(doc["scenes"], serde_json::json!([{}]));
    assert!(doc.get("buffers").is_none() && doc.get("accessors").is_none());
    let doc: Value =
        serde_json::from_slice(&written("empty.gltf", &empty, write_gltf)).expect("parses");
    assert_eq!(doc["asset"]["version"], "2.0");
    check_ply(
        &empty,
        &written("empty.ply", &empty, write_ply),
        "empty.ply",
    );
}

#[test]
fn write_mesh_dispatches_on_the_extension_case_insensitively() {
    let mesh = tetrahedron();
    for (ext, magic) in [
        ("obj", &b"# subtess"[..]),
        ("OBJ", b"# subtess"),
        ("ply", b"ply\n"),
        ("Ply", b"ply\n"),
        ("glb", b"glTF"),
        ("GLB", b"glTF"),
        ("gltf", b"{"),
        ("glTF", b"{"),
    ] {
        let path = temp_path(&format!("dispatch.{ext}"));
        write_mesh(&mesh, &path).unwrap_or_else(|e| panic!("{ext}: {e}"));
        let bytes = std::fs::read(&path).expect("reads back");
        std::fs::remove_file(&path).expect("removes");
        assert!(bytes.starts_with(magic), "{ext}");
        match ext.to_ascii_lowercase().as_str() {
            "ply" => check_ply(&mesh, &bytes, ext),
            "glb" => {
                check_glb(&mesh, &bytes, ext);
            }
            "gltf" => {
                check_gltf_file(&mesh, &bytes, ext);
            }
            _ => check_obj(&mesh, &bytes, ext),
        }
    }
}

#[test]
fn unknown_extension_is_unsupported_and_writes_nothing() {
    let mesh = tetrahedron();
    for name in ["out.stl", "out"] {
        let path = temp_path(name);
        match write_mesh(&mesh, &path) {
            Err(RuntimeError::Unsupported(message)) => {
                for ext in [".obj", ".ply", ".glb", ".gltf"] {
                    assert!(message.contains(ext), "{message}");
                }
                assert!(message.contains(&path.display().to_string()), "{message}");
                if name.ends_with(".stl") {
                    assert!(message.contains(".stl"), "{message}");
                }
            }
            other => panic!("{name}: expected Unsupported, got {other:?}"),
        }
        assert!(!path.exists(), "{name} was created");
    }
}

#[test]
fn unwritable_paths_are_io_errors_naming_the_path() {
    let mesh = tetrahedron();
    let missing = temp_path("no-such-folder");
    let folder = temp_path("folder.glb");
    std::fs::create_dir(&folder).expect("creates a folder");
    for ext in ["obj", "ply", "glb", "gltf"] {
        let path = missing.join(format!("out.{ext}"));
        match write_mesh(&mesh, &path) {
            Err(RuntimeError::Io { path: p, source }) => {
                assert_eq!(p, path.display().to_string());
                assert_eq!(source.kind(), std::io::ErrorKind::NotFound, "{ext}");
            }
            other => panic!("{ext}: expected Io, got {other:?}"),
        }
    }
    // A folder where the file should go.
    match write_mesh(&mesh, &folder) {
        Err(RuntimeError::Io { path, .. }) => assert_eq!(path, folder.display().to_string()),
        other => panic!("expected Io, got {other:?}"),
    }
    std::fs::remove_dir(&folder).expect("removes the folder");
}

#[test]
fn inconsistent_meshes_are_refused_before_writing() {
    let mut bad_index = tetrahedron();
    bad_index.triangles[2][1] = 4;
    let mut short_normals = tetrahedron();
    short_normals.normals.pop();
    let mut short_sources = tetrahedron();
    short_sources.sources.pop();
    for (name, mesh) in [
        ("index", bad_index),
        ("normals", short_normals),
        ("sources", short_sources),
    ] {
        for ext in ["obj", "ply", "glb", "gltf"] {
            let path = temp_path(&format!("bad-{name}.{ext}"));
            match write_mesh(&mesh, &path) {
                Err(RuntimeError::Io { source, .. }) => {
                    assert_eq!(
                        source.kind(),
                        std::io::ErrorKind::InvalidInput,
                        "{name} {ext}"
                    )
                }
                other => panic!("{name} {ext}: expected InvalidInput, got {other:?}"),
            }
            assert!(!path.exists(), "{name} {ext}: file created");
        }
    }
}

#[test]
fn non_finite_positions_are_refused_by_gltf() {
    let mut mesh = tetrahedron();
    mesh.positions[1][2] = f32::NAN;
    for ext in ["glb", "gltf"] {
        let path = temp_path(&format!("nan.{ext}"));
        match write_mesh(&mesh, &path) {
            Err(RuntimeError::Io { source, .. }) => {
                assert_eq!(source.kind(), std::io::ErrorKind::InvalidInput);
                assert!(source.to_string().contains("vertex 1"), "{source}");
            }
            other => panic!("{ext}: expected InvalidInput, got {other:?}"),
        }
    }
}
