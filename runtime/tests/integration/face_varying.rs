//! Texture coordinates (one face-varying channel): the linear mode against the bilinear
//! interpolation of the corner values, the smooth mode against the positions' own limit
//! surface, closed-form corner values, seam splitting, and the three writers.

use std::path::{Path, PathBuf};
use std::process::Command;

use subtess::io::obj::parse_obj;
use subtess::{FaceVaryingMode, Mesh, Rates, Surface};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

fn mesh_from(text: &str) -> Mesh {
    let obj = parse_obj(text).unwrap_or_else(|e| panic!("{e}"));
    Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0
}

/// The OBJ text of `path` with `vt x y` for every vertex (its own position's x, y), every
/// corner naming its vertex's, and the mode tag `k`.
fn uvs_from_positions(path: &Path, k: u8) -> String {
    let text = std::fs::read_to_string(path).expect("readable");
    let mut out = String::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<&str> = words.collect();
                out += &format!("{line}\nvt {} {}\n", c[0], c[1]);
            }
            Some("f") => {
                let corners: Vec<String> = words
                    .map(|w| {
                        let v = w.split('/').next().expect("a vertex");
                        format!("{v}/{v}")
                    })
                    .collect();
                out += &format!("f {}\n", corners.join(" "));
            }
            _ => out += &format!("{line}\n"),
        }
    }
    out + &format!("t facevaryinginterpolateboundary 1/0/0 {k}\n")
}

/// Under the default mode (OpenSubdiv's `FVAR_LINEAR_ALL`) every output vertex's texture
/// coordinates are the bilinear interpolation of its face's corner values at its `(u, v)`.
#[test]
#[cfg(feature = "catmull-clark")]
fn the_linear_mode_is_bilinear_in_the_corner_values() {
    let text = std::fs::read_to_string(data("cube_uv.obj")).expect("readable");
    let obj = parse_obj(&text).expect("parses");
    let mesh = Mesh::from_obj(&obj).expect("valid").0;
    assert_eq!(
        mesh.face_varying.as_ref().map(|c| c.mode),
        Some(FaceVaryingMode::All)
    );
    let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
    assert!(surface.has_uvs());
    let mut tess = surface.tessellator(&Rates::Uniform(5)).expect("plan");
    let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
    let uvs = frame.uvs().expect("texture coordinates");
    assert_eq!(uvs.len(), frame.positions().len());
    for (uv, s) in uvs.iter().zip(frame.sources()) {
        let corners: Vec<[f64; 2]> = obj.face_uvs[s.face as usize]
            .iter()
            .map(|&t| obj.uvs[t as usize])
            .collect();
        let (u, v) = s.uv();
        let w = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
        for c in 0..2 {
            let expected: f64 = (0..4).map(|k| w[k] * corners[k][c]).sum();
            assert!(
                (f64::from(uv[c]) - expected).abs() < 1e-6,
                "face {} at ({u}, {v}): {uv:?}",
                s.face
            );
        }
    }
}

/// Seam copies of the atlas cube at rate `n`: isolation splits each cube edge into `s = 2^steps`
/// edges of the isolated mesh, each with `n - 1` curve points, and `s - 1` vertices between
/// them (two sectors: one copy each); a cube corner has three sectors (two copies).
fn cube_seam_copies(surface: &Surface, n: u32) -> u32 {
    let s = 1u32 << surface.isolation_steps();
    12 * (s * (n - 1) + (s - 1)) + 8 * 2
}

/// Every edge of the atlas cube is a seam: its curve points and the limit points at its
/// vertices are split, the copies share the original's position and normal bits, and the
/// output stays watertight in positions.
#[test]
#[cfg(feature = "catmull-clark")]
fn seams_split_vertices_with_the_same_position_bits() {
    let mesh = Mesh::read_obj(data("cube_uv.obj")).expect("reads");
    let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
    for n in [1u32, 4, 7] {
        let mut tess = surface.tessellator(&Rates::Uniform(n)).expect("plan");
        let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
        let copies = frame.seam_copies();
        assert_eq!(
            copies.len() as u32,
            cube_seam_copies(&surface, n),
            "rate {n}"
        );
        let uvs = frame.uvs().expect("texture coordinates");
        for &[copy, original] in copies {
            let (c, o) = (copy as usize, original as usize);
            assert_eq!(
                frame.positions()[c].map(f32::to_bits),
                frame.positions()[o].map(f32::to_bits)
            );
            assert_eq!(
                frame.normals()[c].map(f32::to_bits),
                frame.normals()[o].map(f32::to_bits)
            );
            assert_ne!(uvs[c], uvs[o], "a copy at rate {n} with its original's uv");
        }
        let out = frame.to_triangle_mesh();
        assert!(out.is_watertight(), "rate {n}");
        // Without the copies mapped back, every seam is an open edge.
        let unwelded = subtess::TriangleMesh {
            seam_copies: Vec::new(),
            ..out
        };
        assert!(!unwelded.is_watertight());
    }
}

/// With texture coordinates equal to the positions' x and y, one per vertex (no seam), the
/// smooth mode (0) applies the positions' own rules: the texture coordinates are the limit
/// positions' x and y, on a mesh with boundary and extraordinary vertices and on one with
/// creases and corners.
#[test]
#[cfg(feature = "catmull-clark")]
fn smooth_texture_coordinates_follow_the_positions_rules() {
    for name in ["disc.obj", "cube_creased.obj"] {
        let mesh = mesh_from(&uvs_from_positions(&data(name), 0));
        let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
        let mut tess = surface.tessellator(&Rates::Uniform(6)).expect("plan");
        let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
        assert!(frame.seam_copies().is_empty(), "{name}");
        let uvs = frame.uvs().expect("texture coordinates");
        let mut worst = 0.0f32;
        for (uv, p) in uvs.iter().zip(frame.positions()) {
            worst = worst.max((uv[0] - p[0]).abs()).max((uv[1] - p[1]).abs());
        }
        assert!(worst < 2e-6, "{name}: texture coordinates off by {worst}");
    }
}

/// One quad, texture coordinates its unit square: at the face's corner the limit is the corner
/// value itself when the mode pins one-face corners (1..=5), and the crease rule's
/// `(E_a + 4 V + E_b) / 6` over the two boundary neighbours (`(1/6, 1/6)`) when smooth (0).
/// Along a side between pinned corners the channel is linear.
#[test]
#[cfg(feature = "catmull-clark")]
fn one_face_corners_are_pinned_by_every_mode_but_none() {
    for mode in FaceVaryingMode::ALL {
        let text = format!(
            "v 0 0 0\nv 2 0 1\nv 2 3 0\nv 0 3 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             f 1/1 2/2 3/3 4/4\nt facevaryinginterpolateboundary 1/0/0 {}\n",
            mode.tag()
        );
        let mesh = mesh_from(&text);
        let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
        let mut tess = surface.tessellator(&Rates::Uniform(4)).expect("plan");
        let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
        let uvs = frame.uvs().expect("texture coordinates");
        let at = |u: f64, v: f64| {
            let i = frame
                .sources()
                .iter()
                .position(|s| s.uv() == (u, v))
                .unwrap_or_else(|| panic!("no vertex at ({u}, {v})"));
            uvs[i]
        };
        let corner = at(0.0, 0.0);
        let expected = if mode == FaceVaryingMode::None {
            [1.0 / 6.0, 1.0 / 6.0]
        } else {
            [0.0, 0.0]
        };
        for c in 0..2 {
            assert!(
                (f64::from(corner[c]) - expected[c]).abs() < 1e-6,
                "{mode:?}: corner {corner:?}"
            );
        }
        if mode != FaceVaryingMode::None {
            let side = at(0.25, 0.0);
            assert!(
                (side[0] - 0.25).abs() < 1e-6 && side[1].abs() < 1e-6,
                "{mode:?}: side {side:?}"
            );
        }
    }
}

fn subtess(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(args)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "subtess {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The CLI writes texture coordinates in every format: OBJ `vt` (one per `v`), PLY `s t`,
/// and a glTF that a standard parser loads with `TEXCOORD_0` as long as `POSITION`; `--stats`
/// reports the seam vertices and watertightness in positions.
#[test]
#[cfg(feature = "catmull-clark")]
fn every_writer_carries_texture_coordinates() {
    let dir = std::env::temp_dir().join(format!("subtess-uv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let input = data("cube_uv.obj");
    let input = input.to_str().expect("utf-8 path");
    let obj = dir.join("cube.obj");
    let stats = subtess(&[
        "tessellate",
        input,
        "-o",
        obj.to_str().expect("utf-8"),
        "--rate",
        "3",
        "--stats",
    ]);
    let stats: serde_json::Value = serde_json::from_str(&stats).expect("JSON");
    assert_eq!(stats["uvs"], true);
    assert_eq!(stats["watertight"], true);
    let mesh = Mesh::read_obj(data("cube_uv.obj")).expect("reads");
    let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
    assert_eq!(stats["seam_vertices"], cube_seam_copies(&surface, 3));
    let text = std::fs::read_to_string(&obj).expect("written");
    let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("vt "), count("v "));
    let corners_name_their_uv = |l: &str| {
        l.split_whitespace().skip(1).all(|c| {
            let p: Vec<&str> = c.split('/').collect();
            p.len() == 3 && p[0] == p[1] && p[1] == p[2]
        })
    };
    assert!(text
        .lines()
        .filter(|l| l.starts_with("f "))
        .all(corners_name_their_uv));

    let ply = dir.join("cube.ply");
    subtess(&[
        "tessellate",
        input,
        "-o",
        ply.to_str().expect("utf-8"),
        "--rate",
        "3",
    ]);
    let bytes = std::fs::read(&ply).expect("written");
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]).into_owned();
    assert!(header.contains("property float s\nproperty float t\nelement face"));

    let glb = dir.join("cube.glb");
    subtess(&[
        "tessellate",
        input,
        "-o",
        glb.to_str().expect("utf-8"),
        "--rate",
        "3",
    ]);
    let bytes = std::fs::read(&glb).expect("written");
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("glTF: {e}"));
    let primitive = gltf
        .meshes()
        .next()
        .and_then(|m| m.primitives().next())
        .expect("a primitive");
    let count_of = |semantic: gltf::Semantic| {
        primitive
            .get(&semantic)
            .map(|a| a.count())
            .unwrap_or_else(|| panic!("no {semantic:?}"))
    };
    assert_eq!(
        count_of(gltf::Semantic::TexCoords(0)),
        count_of(gltf::Semantic::Positions)
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `eval`'s texture coordinates (`subtess::eval::limit_uv`: exact rationals where the channel
/// has no sharp feature, one adaptive query otherwise) agree with the tessellation's at the
/// sources of its vertices, in every mode, on the atlas cube and on the disc with texture
/// coordinates from its positions (where the exact limit's x, y are the reference).
#[test]
#[cfg(feature = "catmull-clark")]
fn eval_gives_the_texture_coordinates_of_the_tessellation() {
    use num_bigint::BigInt;
    use num_rational::BigRational;
    let cube = std::fs::read_to_string(data("cube_uv.obj")).expect("readable");
    for mode in FaceVaryingMode::ALL {
        for (label, text) in [
            (
                "cube",
                format!(
                    "{cube}\nt facevaryinginterpolateboundary 1/0/0 {}\n",
                    mode.tag()
                ),
            ),
            ("disc", uvs_from_positions(&data("disc.obj"), mode.tag())),
        ] {
            let mesh = mesh_from(&text);
            let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
            let mut tess = surface.tessellator(&Rates::Uniform(3)).expect("plan");
            let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
            let uvs = frame.uvs().expect("texture coordinates");
            for (i, s) in frame.sources().iter().enumerate().step_by(13) {
                let d = BigInt::from(s.denominator);
                let (u, v) = (
                    BigRational::new(BigInt::from(s.u), d.clone()),
                    BigRational::new(BigInt::from(s.v), d),
                );
                let face = s.face as usize;
                let uv = subtess::eval::limit_uv(&mesh, face, usize::from(s.subface), &u, &v)
                    .expect("evaluates")
                    .expect("texture coordinates");
                let off = (uv[0] - f64::from(uvs[i][0]))
                    .abs()
                    .max((uv[1] - f64::from(uvs[i][1])).abs());
                assert!(
                    off < 2e-6,
                    "{label} {mode:?} vertex {i}: {uv:?} vs {:?}",
                    uvs[i]
                );
            }
        }
    }
}

/// Seams add limit points at vertices the positions alone would not sample: on the atlas cube,
/// every corner (a smooth extraordinary vertex of valence 3) gets three. By the cube's
/// symmetry the limit point lies on the diagonal through the corner and the normal is the
/// diagonal's direction.
#[test]
#[cfg(feature = "catmull-clark")]
fn seam_limit_points_at_extraordinary_vertices_are_exact() {
    let mesh = Mesh::read_obj(data("cube_uv.obj")).expect("reads");
    let surface = Surface::new(&mesh, subtess::Scheme::CatmullClark).expect("surface");
    let mut tess = surface.tessellator(&Rates::Uniform(4)).expect("plan");
    let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
    let mut corners = 0;
    for ((s, p), n) in frame
        .sources()
        .iter()
        .zip(frame.positions())
        .zip(frame.normals())
    {
        let (u, v) = s.uv();
        if !(u == 0.0 || u == 1.0) || !(v == 0.0 || v == 1.0) {
            continue;
        }
        corners += 1;
        let diagonal = p.map(|c| c.signum() / 3f32.sqrt());
        let off_axis = p
            .iter()
            .map(|c| (c.abs() - p[0].abs()).abs())
            .fold(0.0, f32::max);
        assert!(off_axis < 1e-6, "corner limit {p:?} off the diagonal");
        for c in 0..3 {
            assert!((n[c] - diagonal[c]).abs() < 1e-6, "normal {n:?} at {p:?}");
        }
    }
    // 8 corners, three faces each.
    assert_eq!(corners, 24);
}

/// `--no-uvs` drops the texture coordinates: no `vt`, no seam vertices, and the output of the
/// mesh without them.
#[test]
#[cfg(feature = "catmull-clark")]
fn no_uvs_drops_the_texture_coordinates() {
    let dir = std::env::temp_dir().join(format!("subtess-no-uv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let input = data("cube_uv.obj");
    let plain = data("cube.obj");
    let (with, without) = (dir.join("with.obj"), dir.join("without.obj"));
    let stats = subtess(&[
        "tessellate",
        input.to_str().expect("utf-8"),
        "-o",
        with.to_str().expect("utf-8"),
        "--no-uvs",
        "--stats",
    ]);
    let stats: serde_json::Value = serde_json::from_str(&stats).expect("JSON");
    assert_eq!(stats["uvs"], false);
    assert_eq!(stats["seam_vertices"], 0);
    subtess(&[
        "tessellate",
        plain.to_str().expect("utf-8"),
        "-o",
        without.to_str().expect("utf-8"),
    ]);
    let body = |p: &Path| {
        let text = std::fs::read_to_string(p).expect("written");
        text.lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    assert_eq!(body(&with), body(&without));
    std::fs::remove_dir_all(&dir).ok();
}

/// `eval::limit_uv` refuses parameters outside the face, as `limit_point` does.
#[test]
fn limit_uv_refuses_parameters_outside_the_face() {
    use num_bigint::BigInt;
    use num_rational::BigRational;
    let mesh = Mesh::read_obj(data("cube_uv.obj")).expect("reads");
    let half = BigRational::new(BigInt::from(1), BigInt::from(2));
    let outside = BigRational::new(BigInt::from(3), BigInt::from(2));
    assert!(subtess::eval::limit_uv(&mesh, 0, 0, &half, &half).is_ok());
    assert!(subtess::eval::limit_uv(&mesh, 0, 0, &outside, &half).is_err());
    assert!(subtess::eval::limit_uv(&mesh, 0, 0, &half, &-half.clone()).is_err());
}
