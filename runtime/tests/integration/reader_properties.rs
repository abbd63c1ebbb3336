//! Property tests of the readers (issue 20): what a writer makes of a random input reads back
//! as the same input (OBJ meshes with tags, Newell and `.bpt` patch sets, rates files, stencil
//! tables), and arbitrary text or bytes end in `Ok` or an error, never a panic. The fuzz
//! targets in `fuzz/` run the same readers for minutes; these run in the default test run, in
//! a few seconds (a few hundred cases each).

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use subtess::io::obj::parse_obj;
use subtess::mesh::topology::NONE;
use subtess::tessellate::bezier::bicubic::BicubicPatch;
use subtess::tessellate::rates::{parse_rates, MAX_SELECTED_RATE};
use subtess::{BezierPatches, BoundaryMode, Mesh, RuntimeError, StencilTable};
use table_format::{PointSet, Precision, SchemeId, SectionKey, StencilKind, TableMeta};

/// A coordinate: small integers, binary fractions, or any finite value within the meshes'
/// bound, so that the shortest round-trip form (`{}`) is exercised on all of them.
fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-8i32..=8).prop_map(f64::from),
        (-4096i32..=4096).prop_map(|k| f64::from(k) / 64.0),
        -1e6f64..1e6,
        -1e18f64..=1e18,
    ]
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    [coordinate(), coordinate(), coordinate()]
}

/// How a writer may lay out the same OBJ content.
#[derive(Clone, Debug)]
struct ObjStyle {
    /// `\r\n` line ends instead of `\n`.
    crlf: bool,
    /// A separator between words: a space, a tab or several.
    separator: &'static str,
    /// Faces refer to vertices relative to the count read so far (`-1` is the last).
    relative: bool,
    /// Corners written `v/vt` (one `vt` per vertex), `v//vn`, or plain `v`.
    corners: u8,
    /// Comments and blank lines between statements.
    comments: bool,
}

fn obj_style() -> impl Strategy<Value = ObjStyle> {
    (
        any::<bool>(),
        prop_oneof![Just(" "), Just("\t"), Just("  \t ")],
        any::<bool>(),
        0u8..3,
        any::<bool>(),
    )
        .prop_map(|(crlf, separator, relative, corners, comments)| ObjStyle {
            crlf,
            separator,
            relative,
            corners,
            comments,
        })
}

/// A random grid mesh with tags: `w x h` cells, each a quad or two triangles, every interior
/// edge possibly creased, every interior vertex possibly a corner, faces possibly holes.
#[derive(Clone, Debug)]
struct TaggedMesh {
    positions: Vec<[f64; 3]>,
    faces: Vec<Vec<i64>>,
    /// Creased edges `(a, b)` and their sharpness, in one `crease` tag.
    creases: Vec<(i64, i64, f64)>,
    /// Corner vertices and their sharpness, in one `corner` tag.
    corners: Vec<(i64, f64)>,
    /// Hole faces, in one `hole` tag.
    holes: Vec<i64>,
    /// `interpolateboundary` 1 or 2, or no such tag.
    interpolate: Option<i64>,
}

fn sharpness() -> impl Strategy<Value = f64> {
    prop_oneof![(0u32..=80).prop_map(|k| f64::from(k) / 8.0), 0.0f64..10.0]
}

fn tagged_mesh() -> impl Strategy<Value = TaggedMesh> {
    (1usize..=4, 1usize..=4)
        .prop_flat_map(|(w, h)| {
            let vertices = (w + 1) * (h + 1);
            (
                Just((w, h)),
                proptest::collection::vec(point(), vertices),
                proptest::collection::vec(any::<bool>(), w * h),
                proptest::collection::vec(proptest::option::of(sharpness()), 2 * w * h + w + h),
                proptest::collection::vec(proptest::option::of(sharpness()), vertices),
                proptest::collection::vec(proptest::bool::weighted(0.15), 2 * w * h),
                proptest::option::of(1i64..=2),
            )
        })
        .prop_map(
            |((w, h), positions, split, crease_at, corner_at, hole_at, interpolate)| {
                let id = |i: usize, j: usize| (j * (w + 1) + i) as i64;
                let mut faces = Vec::new();
                for j in 0..h {
                    for i in 0..w {
                        let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                        if split[j * w + i] {
                            faces.push(vec![a, b, c]);
                            faces.push(vec![a, c, d]);
                        } else {
                            faces.push(vec![a, b, c, d]);
                        }
                    }
                }
                // Interior grid edges: horizontal ones between rows, vertical ones between
                // columns (the triangles' diagonals are interior edges too).
                let mut edges = Vec::new();
                for j in 1..h {
                    for i in 0..w {
                        edges.push((id(i, j), id(i + 1, j)));
                    }
                }
                for j in 0..h {
                    for i in 1..w {
                        edges.push((id(i, j), id(i, j + 1)));
                    }
                }
                for j in 0..h {
                    for i in 0..w {
                        if split[j * w + i] {
                            edges.push((id(i, j), id(i + 1, j + 1)));
                        }
                    }
                }
                let creases = edges
                    .iter()
                    .zip(&crease_at)
                    .filter_map(|(&(a, b), s)| s.map(|s| (a, b, s)))
                    .collect();
                let corners = (1..h)
                    .flat_map(|j| (1..w).map(move |i| (i, j)))
                    .filter_map(|(i, j)| corner_at[j * (w + 1) + i].map(|s| (id(i, j), s)))
                    .collect();
                let holes = (0..faces.len())
                    .filter(|&f| hole_at[f])
                    .map(|f| f as i64)
                    .collect();
                TaggedMesh {
                    positions,
                    faces,
                    creases,
                    corners,
                    holes,
                    interpolate,
                }
            },
        )
}

/// `mesh` as OBJ text, laid out as `style` says.
fn write_obj(mesh: &TaggedMesh, style: &ObjStyle) -> String {
    let end = if style.crlf { "\r\n" } else { "\n" };
    let sep = style.separator;
    let mut out = String::new();
    let line = |text: String, out: &mut String| {
        out.push_str(&text);
        if style.comments {
            out.push_str(" # a comment, f 1 2 3");
            out.push_str(end);
            out.push_str(sep);
        }
        out.push_str(end);
    };
    line(format!("# {} vertices", mesh.positions.len()), &mut out);
    let count = mesh.positions.len() as i64;
    for p in &mesh.positions {
        line(
            format!("v{sep}{}{sep}{}{sep}{}", p[0], p[1], p[2]),
            &mut out,
        );
        match style.corners {
            1 => line(format!("vt{sep}{}{sep}{}", p[0], p[1]), &mut out),
            2 => line(format!("vn{sep}0{sep}0{sep}1"), &mut out),
            _ => {}
        }
    }
    line("g grid".to_owned(), &mut out);
    for face in &mesh.faces {
        let corners: Vec<String> = face
            .iter()
            .map(|&v| {
                let index = if style.relative { v - count } else { v + 1 };
                match style.corners {
                    1 => format!("{index}/{index}"),
                    2 => format!("{index}//{index}"),
                    _ => index.to_string(),
                }
            })
            .collect();
        line(format!("f{sep}{}", corners.join(sep)), &mut out);
    }
    let join = |words: Vec<String>| words.join(sep);
    if !mesh.creases.is_empty() {
        let ints = mesh.creases.iter().flat_map(|&(a, b, _)| [a, b]);
        let floats = mesh.creases.iter().map(|c| c.2.to_string());
        line(
            format!(
                "t{sep}crease{sep}{}/{}/0{sep}{}{sep}{}",
                2 * mesh.creases.len(),
                mesh.creases.len(),
                join(ints.map(|i| i.to_string()).collect()),
                join(floats.collect())
            ),
            &mut out,
        );
    }
    if !mesh.corners.is_empty() {
        let ints = mesh.corners.iter().map(|c| c.0.to_string());
        let floats = mesh.corners.iter().map(|c| c.1.to_string());
        line(
            format!(
                "t{sep}corner{sep}{n}/{n}/0{sep}{}{sep}{}",
                join(ints.collect()),
                join(floats.collect()),
                n = mesh.corners.len()
            ),
            &mut out,
        );
    }
    if !mesh.holes.is_empty() {
        let ints = mesh.holes.iter().map(|f| f.to_string());
        line(
            format!(
                "t{sep}hole{sep}{}/0/0{sep}{}",
                mesh.holes.len(),
                join(ints.collect())
            ),
            &mut out,
        );
    }
    if let Some(rule) = mesh.interpolate {
        line(
            format!("t{sep}interpolateboundary{sep}1/0/0{sep}{rule}"),
            &mut out,
        );
    }
    line(
        format!("t{sep}creasemethod{sep}0/0/1{sep}chaikin"),
        &mut out,
    );
    out
}

/// The edge sharpness of interior edge `(a, b)` in `mesh`, the same on both of its half-edges.
fn edge_sharpness(mesh: &Mesh, a: i64, b: i64) -> Result<f32, TestCaseError> {
    let halfedges = mesh.find_halfedges(a as usize, b as usize);
    prop_assert_eq!(halfedges.len(), 1, "one edge {}-{}", a, b);
    let h = halfedges[0];
    prop_assert!(mesh.twin[h] != NONE, "edge {}-{} is interior", a, b);
    let s = mesh.edge_sharpness[h];
    prop_assert_eq!(mesh.edge_sharpness[mesh.twin[h] as usize], s);
    Ok(s)
}

/// Random patches, and for Newell's format the shared vertex list they index (every control
/// point once, in a random order) with each patch's 1-based indices into it.
fn patch_set() -> impl Strategy<Value = (Vec<[[f64; 3]; 16]>, Vec<usize>)> {
    (1usize..=4)
        .prop_flat_map(|n| {
            (
                proptest::collection::vec(proptest::array::uniform16(point()), n),
                Just(n),
            )
        })
        .prop_flat_map(|(patches, n)| {
            let order: Vec<usize> = (0..16 * n).collect();
            (Just(patches), Just(order).prop_shuffle())
        })
}

fn write_bpt(patches: &[[[f64; 3]; 16]], crlf: bool) -> String {
    let end = if crlf { "\r\n" } else { "\n" };
    let mut out = format!("{}{end}", patches.len());
    for patch in patches {
        out.push_str(&format!("3 3{end}"));
        for p in patch {
            out.push_str(&format!("{} {} {}{end}", p[0], p[1], p[2]));
        }
    }
    out
}

/// Newell's format with the vertices in `order` (`order[k]` is the slot of control point `k`,
/// counting all patches' points in turn).
fn write_newell(patches: &[[[f64; 3]; 16]], order: &[usize], blank_lines: bool) -> String {
    let mut vertices = vec![[0.0; 3]; order.len()];
    let mut out = format!("{}\n", patches.len());
    for (p, patch) in patches.iter().enumerate() {
        let indices: Vec<String> = (0..16)
            .map(|k| {
                let slot = order[16 * p + k];
                vertices[slot] = patch[k];
                (slot + 1).to_string()
            })
            .collect();
        out.push_str(&indices.join(", "));
        out.push('\n');
        if blank_lines {
            out.push_str("  \n");
        }
    }
    out.push_str(&format!("{}\n", vertices.len()));
    for v in &vertices {
        out.push_str(&format!("{},{} , {}\n", v[0], v[1], v[2]));
    }
    out
}

fn to_patches(patches: &[[[f64; 3]; 16]]) -> BezierPatches {
    BezierPatches {
        patches: patches.iter().map(|&c| BicubicPatch::new(c)).collect(),
    }
}

/// A small valid table: a few sections of one scheme, random finite weights.
fn table_sections() -> impl Strategy<Value = (TableMeta, Vec<(SectionKey, u32, Vec<f64>)>)> {
    let meta =
        (any::<bool>(), any::<bool>(), any::<bool>()).prop_map(|(tri, f64s, corners)| TableMeta {
            scheme: if tri {
                SchemeId::Loop
            } else {
                SchemeId::CatmullClark
            },
            precision: if f64s { Precision::F64 } else { Precision::F32 },
            corners,
        });
    let key = (
        0u8..3,
        any::<bool>(),
        any::<bool>(),
        1u32..=8,
        0u32..3,
        1u32..=3,
    );
    (meta, proptest::collection::btree_set(key, 1..=4)).prop_flat_map(|(meta, keys)| {
        let sections: Vec<_> = keys
            .into_iter()
            .map(|(kind, dual, boundary, faces, sector, n)| {
                let points = match (meta.scheme.is_triangle(), dual) {
                    (false, false) => PointSet::Primal,
                    (false, true) => PointSet::Dual,
                    (true, false) => PointSet::TrianglePrimal,
                    (true, true) => PointSet::TriangleDual,
                };
                let kind = [
                    StencilKind::Position,
                    StencilKind::DerivativeU,
                    StencilKind::DerivativeV,
                ][usize::from(kind)];
                let key = SectionKey {
                    kind,
                    points,
                    boundary,
                    feature: table_format::Feature::None,
                    faces,
                    sector,
                    n,
                };
                let width = 2 * faces + 8;
                let count = points.count(n) as usize * width as usize;
                (
                    Just(key),
                    Just(width),
                    proptest::collection::vec(-2.0f64..2.0, count),
                )
            })
            .collect();
        (Just(meta), sections)
    })
}

/// Lines made of the words the OBJ reader knows, so that random text gets past the first
/// keyword: vertices, faces (absolute, relative, with texture coordinates), tags with right
/// and wrong counts, huge and odd numbers.
fn obj_soup() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        Just("v"),
        Just("f"),
        Just("vt"),
        Just("t"),
        Just("crease"),
        Just("corner"),
        Just("hole"),
        Just("interpolateboundary"),
        Just("creasemethod"),
        Just("chaikin"),
        Just("1"),
        Just("2"),
        Just("3"),
        Just("4"),
        Just("-1"),
        Just("0"),
        Just("1/1"),
        Just("2//2"),
        Just("1/1/0"),
        Just("2/1/0"),
        Just("0/0/1"),
        Just("18446744073709551615/1/0"),
        Just("-9223372036854775808"),
        Just("1e308"),
        Just("nan"),
        Just("0.5"),
        Just("#"),
    ];
    let line = proptest::collection::vec(word, 0..8).prop_map(|w| w.join(" "));
    proptest::collection::vec(line, 0..24).prop_map(|lines| lines.join("\n"))
}

/// Lines of numbers, commas and degree lines, for the Bézier readers.
fn patch_soup() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        Just("1"),
        Just("2"),
        Just("3"),
        Just("16"),
        Just("0"),
        Just("3 3"),
        Just(","),
        Just("1,2,3"),
        Just("0.5"),
        Just("-2e18"),
        Just("inf"),
        Just("18446744073709551616"),
        Just("10000000000"),
    ];
    let line = proptest::collection::vec(word, 0..17).prop_map(|w| w.join(" "));
    proptest::collection::vec(line, 0..40).prop_map(|lines| lines.join("\n"))
}

/// Every reader on `text`: an error or a value, never a panic (the caller's test fails if one
/// panics). What the Bézier readers accept has patches and finite coordinates.
fn read_everything(text: &str) {
    if let Ok(obj) = parse_obj(text) {
        let _ = Mesh::from_obj(&obj);
    }
    for patches in [
        BezierPatches::parse_newell(text, "soup.txt"),
        BezierPatches::parse_bpt(text, "soup.bpt"),
    ]
    .into_iter()
    .flatten()
    {
        assert!(!patches.is_empty() && patches.diagonal().is_finite());
    }
    if let Ok(rates) = parse_rates(text, 3) {
        assert_eq!(rates.len(), 3);
    }
    let _ = subtess::parse_rational(text);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// A random grid of quads and triangles with crease, corner, hole, interpolateboundary and
    /// creasemethod tags, written in any layout, reads back as the same positions (bit for
    /// bit), faces and tags, and the mesh built from it carries them.
    #[test]
    fn obj_meshes_with_tags_round_trip(mesh in tagged_mesh(), style in obj_style()) {
        let text = write_obj(&mesh, &style);
        let obj = parse_obj(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&obj.positions, &mesh.positions);
        prop_assert_eq!(&obj.faces, &mesh.faces);
        let uvs = if style.corners == 1 { mesh.faces.clone() } else { vec![vec![]; mesh.faces.len()] };
        prop_assert_eq!(&obj.face_uvs, &uvs);
        let crease = obj.tags.iter().find(|t| t.name == "crease");
        if let Some(tag) = crease {
            let ints: Vec<i64> = mesh.creases.iter().flat_map(|&(a, b, _)| [a, b]).collect();
            let floats: Vec<f64> = mesh.creases.iter().map(|c| c.2).collect();
            prop_assert_eq!((&tag.ints, &tag.floats), (&ints, &floats));
        }
        prop_assert_eq!(crease.is_some(), !mesh.creases.is_empty());

        let (built, warnings) = Mesh::from_obj(&obj).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert!(warnings.is_empty(), "{:?}", warnings);
        prop_assert_eq!(&built.positions, &mesh.positions);
        prop_assert_eq!(built.faces(), mesh.faces.len());
        for (f, face) in mesh.faces.iter().enumerate() {
            let read: Vec<i64> = built.face(f).iter().map(|&v| i64::from(v)).collect();
            prop_assert_eq!(&read, face);
        }
        for &(a, b, s) in &mesh.creases {
            prop_assert_eq!(edge_sharpness(&built, a, b)?, s as f32);
        }
        for &(v, s) in &mesh.corners {
            prop_assert_eq!(built.vertex_sharpness[v as usize], s as f32);
        }
        for f in 0..mesh.faces.len() {
            prop_assert_eq!(built.holes[f], mesh.holes.contains(&(f as i64)), "face {}", f);
        }
        let rule = if mesh.interpolate == Some(1) { BoundaryMode::EdgeAndCorner } else { BoundaryMode::EdgeOnly };
        prop_assert_eq!(built.boundary, rule);
        prop_assert_eq!(built.creasing, schemes::CreaseMethod::Chaikin);
        // Untagged interior edges stay smooth.
        let sharp_interior = (0..built.twin.len())
            .filter(|&h| built.twin[h] != NONE && built.edge_sharpness[h] > 0.0)
            .count();
        prop_assert_eq!(sharp_interior, mesh.creases.iter().filter(|c| c.2 > 0.0).count() * 2);
    }

    /// Random bicubic patch sets written as `.bpt` and in Newell's format (shared vertex list
    /// in a random order, `, ` and `,` separators, blank lines) read back as the same patches.
    #[test]
    fn bezier_patches_round_trip((patches, order) in patch_set(), crlf in any::<bool>(), blank in any::<bool>()) {
        let expected = to_patches(&patches);
        let bpt = write_bpt(&patches, crlf);
        let read = BezierPatches::parse_bpt(&bpt, "random.bpt").map_err(|e| TestCaseError::fail(format!("{e}\n{bpt}")))?;
        prop_assert_eq!(&read, &expected);
        let newell = write_newell(&patches, &order, blank);
        let read = BezierPatches::parse_newell(&newell, "random.txt").map_err(|e| TestCaseError::fail(format!("{e}\n{newell}")))?;
        prop_assert_eq!(&read, &expected);
        // Each format is refused by the other reader, naming a line.
        let refused = |r: Result<BezierPatches, RuntimeError>| matches!(r, Err(RuntimeError::ParseFile { line, .. }) if line >= 1);
        prop_assert!(refused(BezierPatches::parse_newell(&bpt, "random.bpt")));
        prop_assert!(refused(BezierPatches::parse_bpt(&newell, "random.txt")));
    }

    /// Random rates written with any whitespace read back as the same rates; one rate fewer or
    /// more, or one out of range, is an error at its line.
    #[test]
    fn rates_round_trip(
        rates in proptest::collection::vec(1u32..=MAX_SELECTED_RATE, 0..60),
        separators in proptest::collection::vec(prop_oneof![Just(" "), Just("\n"), Just("\t"), Just("\r\n"), Just("  ")], 61),
        bad in prop_oneof![Just("0"), Just("25"), Just("-3"), Just("1.5"), Just("x"), Just("4294967296")],
    ) {
        let text: String = rates.iter().zip(&separators).map(|(r, s)| format!("{s}{r}")).collect::<String>() + separators[60];
        prop_assert_eq!(parse_rates(&text, rates.len()).map_err(|e| TestCaseError::fail(e.to_string()))?, rates.clone());
        let lines_before = |k: usize| text_before(&rates, &separators, k).matches('\n').count() + 1;
        if !rates.is_empty() {
            prop_assert!(parse_rates(&text, rates.len() - 1).is_err());
            // Replace the last rate by a bad token: the error names its number and line.
            let k = rates.len() - 1;
            let replaced = format!("{}{}{}{}", text_before(&rates, &separators, k), separators[k], bad, separators[60]);
            match parse_rates(&replaced, rates.len()) {
                Err(RuntimeError::ParseFile { line, message, .. }) => {
                    prop_assert_eq!(line, lines_before(k) + separators[k].matches('\n').count());
                    let expected = format!("rate {} is `{}`", k + 1, bad);
                    prop_assert!(message.contains(&expected), "{}", message);
                }
                other => prop_assert!(false, "{:?}", other),
            }
        }
        prop_assert!(parse_rates(&text, rates.len() + 1).is_err());
    }

    /// Random valid tables (sections of random shapes, f32 or f64, either scheme kind) read
    /// back with the same index and weights (f32 ones rounded once).
    #[test]
    fn tables_round_trip((meta, sections) in table_sections()) {
        let bytes = table_format::encode(meta, &sections).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let table = StencilTable::from_bytes(&bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(table.index().meta, meta);
        prop_assert_eq!(table.index().entries.len(), sections.len());
        for (key, width, weights) in &sections {
            let entry = table.index().entry(key).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(entry.width, *width);
            match meta.precision {
                Precision::F32 => {
                    let read = table.weights(key).map_err(|e| TestCaseError::fail(e.to_string()))?;
                    let expected: Vec<f32> = weights.iter().map(|&w| w as f32).collect();
                    prop_assert_eq!(read, &expected[..]);
                }
                Precision::F64 => {
                    let read = table.index().weights_f64(table.bytes(), key).map_err(|e| TestCaseError::fail(e.to_string()))?;
                    prop_assert_eq!(read, &weights[..]);
                }
            }
        }
    }

    /// Any byte changed in a valid table is refused: by the field checks `check_header` makes
    /// before the file is read (magic, version, endianness mark, header size, file size), and
    /// every other byte, header and index included, by the checksum (format version 3 covers
    /// every byte but its own: docs/reliability.md).
    #[test]
    fn changed_tables_are_refused((meta, sections) in table_sections(), at in any::<prop::sample::Index>(), xor in 1u8..=255) {
        let mut bytes = table_format::encode(meta, &sections).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let at = at.index(bytes.len());
        bytes[at] ^= xor;
        let read = StencilTable::from_bytes(&bytes);
        let by_field_check = matches!(at, 0..=19 | 32..=39);
        let refused = match &read {
            Err(RuntimeError::Table(table_format::TableError::Checksum { .. })) => !by_field_check,
            Err(RuntimeError::Table(_)) => by_field_check,
            _ => false,
        };
        prop_assert!(refused, "byte {} changed: {:?}", at, read.map(|t| t.index().entries.len()));
    }
}

/// The rates text up to (not including) the separator before rate `k`.
fn text_before(rates: &[u32], separators: &[&str], k: usize) -> String {
    rates[..k]
        .iter()
        .zip(separators)
        .map(|(r, s)| format!("{s}{r}"))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Arbitrary text, through every reader: no panic.
    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        read_everything(&text);
    }

    /// Arbitrary bytes (as the lossy text a reader could be handed), through every reader, and
    /// as a table: no panic.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        read_everything(&String::from_utf8_lossy(&bytes));
        let _ = StencilTable::from_bytes(&bytes);
        let mut table = b"SUBTESS\0".to_vec();
        table.extend_from_slice(&bytes);
        let _ = StencilTable::from_bytes(&table);
    }

    /// Lines of OBJ words (keywords, tags with right and wrong counts, huge and odd numbers):
    /// no panic, and what parses has faces within the vertices read or is refused by the mesh.
    #[test]
    fn obj_word_soup_never_panics(text in obj_soup()) {
        read_everything(&text);
        if let Ok(obj) = parse_obj(&text) {
            if let Ok((mesh, _)) = Mesh::from_obj(&obj) {
                let vertices = mesh.positions.len();
                for f in 0..mesh.faces() {
                    prop_assert!(mesh.face(f).iter().all(|&v| (v as usize) < vertices));
                }
            }
        }
    }

    /// Lines of numbers and commas, for the Bézier readers: no panic.
    #[test]
    fn patch_word_soup_never_panics(text in patch_soup()) {
        read_everything(&text);
    }
}
