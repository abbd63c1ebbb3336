//! The library facade, used only through the crate root's names (`subtess::Mesh`, `Surface`,
//! `Scheme`, `Rates`, `Tessellator`, `Frame`): what a program outside the project sees.
//!
//! The references are independent of the per-frame path: a translated frame must be the
//! translated surface (the stencils sum to one), a deformed frame must equal a *fresh*
//! surface of the deformed mesh refined again step by step (so that no composed map is
//! involved), and the CLI's OBJ output (read back from its text) must hold the same triangles.

use std::path::{Path, PathBuf};
use std::process::Command;

use subtess::{Mesh, Rates, Scheme, Surface};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// A mesh from `../shared/models`.
fn shared(relative: &str) -> Mesh {
    let path = crate::common::models().join(relative);
    Mesh::read_obj(&path).unwrap_or_else(|e| panic!("{relative}: {e}"))
}

/// The diagonal of the bounding box.
fn size(points: &[[f32; 3]]) -> f32 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f32>().sqrt()
}

fn distance(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f32>().sqrt()
}

/// A smooth deformation that moves every control point differently (not affine).
fn deform(points: &[[f32; 3]], scale: f32) -> Vec<[f32; 3]> {
    points
        .iter()
        .map(|p| {
            [
                p[0] + 0.1 * scale * (3.0 * p[1] / scale).sin(),
                p[1] + 0.1 * scale * (2.0 * p[2] / scale).cos(),
                p[2] * 1.2 + 0.05 * scale * (5.0 * p[0] / scale).sin(),
            ]
        })
        .collect()
}

/// Every facade property on one mesh and scheme at rate `n`.
fn check(label: &str, mesh: &Mesh, scheme: Scheme, n: u32) {
    // The reference below refines the positions alone: without texture coordinates it has no
    // seams to split, so neither may the plan under test.
    let mut mesh = mesh.clone();
    mesh.face_varying = None;
    let mesh = &mesh;
    let surface = Surface::new(mesh, scheme).unwrap_or_else(|e| panic!("{label}: {scheme}: {e}"));
    let mut tessellator = surface
        .tessellator(&Rates::Uniform(n))
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let rest = mesh.positions_f32();
    let extent = size(&rest);
    let frame = tessellator.evaluate(&rest).expect("rest frame");
    let (positions, normals, triangles) = (
        frame.positions().to_vec(),
        frame.normals().to_vec(),
        frame.triangles().to_vec(),
    );
    let sources = frame.sources().to_vec();
    assert!(!triangles.is_empty(), "{label}");
    assert_eq!(positions.len(), normals.len(), "{label}");
    assert_eq!(positions.len(), sources.len(), "{label}");
    assert!(
        triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < positions.len()),
        "{label}: a triangle index out of range"
    );
    for (i, n) in normals.iter().enumerate() {
        let length = n.iter().map(|c| c * c).sum::<f32>().sqrt();
        assert!(
            (length - 1.0).abs() < 1e-4,
            "{label}: normal {i} has length {length}"
        );
    }
    for s in &sources {
        assert!(
            (s.face as usize) < mesh.faces(),
            "{label}: source face {}",
            s.face
        );
    }

    // The same positions give the same frame, bit for bit.
    let again = tessellator.evaluate(&rest).expect("again");
    assert_eq!(again.positions(), &positions[..], "{label}: not repeatable");
    assert_eq!(again.normals(), &normals[..], "{label}: not repeatable");

    // Partition of unity: a translated input gives the translated surface.
    let offset = [0.37 * extent, -0.21 * extent, 0.5 * extent];
    let moved: Vec<[f32; 3]> = rest
        .iter()
        .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
        .collect();
    let translated = tessellator.evaluate(&moved).expect("translated");
    let worst = positions
        .iter()
        .zip(translated.positions())
        .map(|(p, q)| distance([p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]], *q))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 1e-5 * extent,
        "{label}: translation off by {worst}"
    );
    let worst_normal = normals
        .iter()
        .zip(translated.normals())
        .map(|(a, b)| distance(*a, *b))
        .fold(0.0f32, f32::max);
    assert!(
        worst_normal < 1e-3,
        "{label}: translated normals off by {worst_normal}"
    );

    // A deformed frame equals a fresh surface of the deformed mesh, refined again: the
    // reference refines the deformed positions step by step in f64 (`Scheme::refine`) as many
    // times as isolation did, so its surface needs no isolation and evaluates the refined
    // positions directly; the frame under test maps the f32 input through the composed map.
    let deformed = deform(&rest, extent);
    let frame = tessellator.evaluate(&deformed).expect("deformed");
    let mut fresh_mesh = mesh.clone();
    fresh_mesh.positions = deformed.iter().map(|p| p.map(f64::from)).collect();
    for _ in 0..surface.isolation_steps() {
        fresh_mesh = scheme.refine(&fresh_mesh).expect("refined");
    }
    let fresh = Surface::new(&fresh_mesh, scheme).expect("fresh surface");
    assert_eq!(
        fresh.isolation_steps(),
        0,
        "{label}: the refined mesh is isolated"
    );
    let mut fresh_tessellator = fresh.tessellator(&Rates::Uniform(n)).expect("fresh plan");
    let reference = fresh_tessellator
        .evaluate(&fresh_mesh.positions_f32())
        .expect("fresh frame");
    assert_eq!(
        reference.triangles(),
        frame.triangles(),
        "{label}: topology"
    );
    let worst = frame
        .positions()
        .iter()
        .zip(reference.positions())
        .map(|(a, b)| distance(*a, *b))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 1e-5 * extent,
        "{label}: deformed frame off a fresh surface by {worst} ({} of the size)",
        worst / extent
    );
    let worst_normal = frame
        .normals()
        .iter()
        .zip(reference.normals())
        .map(|(a, b)| distance(*a, *b))
        .fold(0.0f32, f32::max);
    assert!(
        worst_normal < 1e-3,
        "{label}: deformed normals off by {worst_normal}"
    );

    // The wrong number of points is refused, and so is a NaN.
    assert!(tessellator.evaluate(&rest[1..]).is_err(), "{label}");
    let mut broken = rest.clone();
    broken[0][1] = f32::NAN;
    assert!(tessellator.evaluate(&broken).is_err(), "{label}");
}

#[test]
#[cfg(feature = "catmull-clark")]
fn the_cube_through_the_facade() {
    let cube = Mesh::read_obj(data("cube.obj")).expect("shipped cube");
    for n in [1, 4, 7] {
        check(&format!("cube rate {n}"), &cube, Scheme::CatmullClark, n);
    }
}

#[test]
#[cfg(all(feature = "loop", feature = "butterfly", feature = "sqrt3"))]
fn the_triangle_schemes_through_the_facade() {
    let octahedron = Mesh::read_obj(data("octahedron.obj")).expect("shipped octahedron");
    for scheme in [Scheme::Loop, Scheme::Butterfly, Scheme::Sqrt3] {
        check(&format!("octahedron {scheme}"), &octahedron, scheme, 5);
    }
    // Catmull–Clark on triangles: one step makes quads.
    check(
        "octahedron catmull-clark",
        &octahedron,
        Scheme::CatmullClark,
        3,
    );
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "loop")]
#[cfg(feature = "catmull-clark")]
fn spot_and_a_boundary_mesh_through_the_facade() {
    let spot = shared("crane/spot_control_mesh.obj");
    check("spot control mesh", &spot, Scheme::CatmullClark, 4);
    let spot = shared("crane/spot_triangulated.obj");
    check("spot triangulated, loop", &spot, Scheme::Loop, 3);
    let hand = shared("odedstein/hand_lowres.obj");
    let surface = Surface::new(&hand, Scheme::Loop).expect("hand");
    assert!(surface.boundary_loops() > 0, "the hand has a boundary");
    check("hand (boundary), loop", &hand, Scheme::Loop, 3);
    check(
        "hand (boundary), catmull-clark",
        &hand,
        Scheme::CatmullClark,
        3,
    );
}

#[test]
#[cfg(feature = "catmull-clark")]
fn no_refinement_runs_when_none_is_needed() {
    // The octahedron's vertices all have valence 4: Loop needs isolation, Catmull–Clark of the
    // isolated cube needs none, and a surface with no steps maps the input directly.
    let cube = Mesh::read_obj(data("cube.obj")).expect("cube");
    let once = Scheme::CatmullClark.refine(&cube).expect("refined");
    let surface = Surface::new(&once, Scheme::CatmullClark).expect("surface");
    assert_eq!(surface.isolation_steps(), 0);
    assert_eq!(surface.refinement_weights(), 0);
    let isolated = Surface::new(&cube, Scheme::CatmullClark).expect("surface");
    assert_eq!(isolated.isolation_steps(), 1);
    assert!(isolated.refinement_weights() > 0);
}

/// A surface whose positions were set to a deformed mesh's chooses, at a tolerance, the rates
/// a fresh surface of the deformed mesh chooses, and then makes its frame; with other rates
/// than the undeformed surface's (so the positions did reach the selection: the deformed mesh
/// is twice the size). Points of the
/// wrong number or not finite are refused and change nothing.
fn check_moved_rates(label: &str, mesh: &Mesh, scheme: Scheme, relative: f64) {
    let mut mesh = mesh.clone();
    mesh.face_varying = None;
    let rest = mesh.positions_f32();
    let extent = size(&rest);
    let tolerance = Rates::Tolerance(relative * f64::from(extent));
    let mut surface = Surface::new(&mesh, scheme).expect("surface");
    let adaptive = subtess::AdaptiveOptions {
        tolerance: 1e-3 * f64::from(extent),
        triangulate: true,
        ..Default::default()
    };
    // At rest first: the surface makes and keeps the patch kinds' operators, which the moved
    // surface's adaptive tessellation below reuses, into an output it keeps.
    let mut kept_adaptive = subtess::AdaptiveMesh::default();
    if scheme == Scheme::CatmullClark {
        surface
            .tessellate_adaptive_into(&adaptive, &mut kept_adaptive)
            .expect("adaptive at rest");
        assert!(
            kept_adaptive.polygon_count() > 0,
            "{label}: adaptive at rest"
        );
    }
    let rest_rates = surface
        .tessellator(&tolerance)
        .expect("plan")
        .rates()
        .to_vec();
    // Deformed, and grown to twice the size: the tolerance stays, so the rates must rise.
    let deformed: Vec<[f32; 3]> = deform(&rest, extent)
        .iter()
        .map(|p| p.map(|c| 2.0 * c))
        .collect();
    surface.set_positions(&deformed).expect("moved");
    // This plan fills the buffers the rest plan left to the surface (another size: the rates
    // differ), its sources' among them.
    let (rates, positions, triangles, sources) = {
        let mut tessellator = surface.tessellator(&tolerance).expect("moved plan");
        let rates = tessellator.rates().to_vec();
        let frame = tessellator.evaluate(&deformed).expect("moved frame");
        (
            rates,
            frame.positions().to_vec(),
            frame.triangles().to_vec(),
            frame.sources().to_vec(),
        )
    };

    let mut fresh_mesh = mesh.clone();
    fresh_mesh.positions = deformed.iter().map(|p| p.map(f64::from)).collect();
    let fresh = Surface::new(&fresh_mesh, scheme).expect("fresh surface");
    let mut fresh_tessellator = fresh.tessellator(&tolerance).expect("fresh plan");
    assert_eq!(fresh_tessellator.rates(), &rates[..], "{label}: rates");
    assert_ne!(rest_rates, rates, "{label}: the deformation moves no rate");
    let reference = fresh_tessellator.evaluate(&deformed).expect("fresh frame");
    assert_eq!(reference.triangles(), &triangles[..], "{label}: topology");
    assert_eq!(reference.sources(), &sources[..], "{label}: sources");
    let worst = positions
        .iter()
        .zip(reference.positions())
        .map(|(a, b)| distance(*a, *b))
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-5 * extent, "{label}: frame off by {worst}");

    // Lai–Cheng's adaptive tessellation reads the surface's positions too (with the operators
    // it kept from the rest positions, the fresh surface with its own); into the output kept
    // from the rest tessellation, it is the fresh one's, every list; a refused tessellation
    // leaves it empty.
    if scheme == Scheme::CatmullClark {
        let (moved, _) = surface.tessellate_adaptive(&adaptive).expect("adaptive");
        let (reference, _) = fresh
            .tessellate_adaptive(&adaptive)
            .expect("fresh adaptive");
        surface
            .tessellate_adaptive_into(&adaptive, &mut kept_adaptive)
            .expect("adaptive into the kept output");
        assert!(
            kept_adaptive == reference,
            "{label}: adaptive into a kept output"
        );
        // A coarser tessellation into the same output: its lists shrink, and no entry of
        // the larger one before may be left.
        let coarser = subtess::AdaptiveOptions {
            tolerance: 4.0 * adaptive.tolerance,
            ..adaptive
        };
        let (coarse_reference, _) = fresh.tessellate_adaptive(&coarser).expect("fresh coarser");
        surface
            .tessellate_adaptive_into(&coarser, &mut kept_adaptive)
            .expect("coarser adaptive into the kept output");
        assert!(
            kept_adaptive.polygon_count() < reference.polygon_count()
                && kept_adaptive == coarse_reference,
            "{label}: a coarser adaptive tessellation into a kept output"
        );
        let over = subtess::AdaptiveOptions {
            max_polygons: 10,
            ..adaptive
        };
        assert!(surface
            .tessellate_adaptive_into(&over, &mut kept_adaptive)
            .is_err());
        assert!(
            kept_adaptive == subtess::AdaptiveMesh::default(),
            "{label}: a refused tessellation left polygons"
        );
        assert_eq!(
            moved.triangles(),
            reference.triangles(),
            "{label}: adaptive"
        );
        assert_eq!(
            moved.positions, reference.positions,
            "{label}: adaptive points"
        );
        assert_eq!(
            moved.normals, reference.normals,
            "{label}: adaptive normals"
        );
    }

    assert!(surface.set_positions(&deformed[1..]).is_err(), "{label}");
    let mut broken = rest.clone();
    broken[0][2] = f32::INFINITY;
    assert!(surface.set_positions(&broken).is_err(), "{label}");
    let kept = surface
        .tessellator(&tolerance)
        .expect("plan after refusals");
    assert_eq!(
        kept.rates(),
        &rates[..],
        "{label}: a refusal moved the surface"
    );
    if scheme == Scheme::CatmullClark {
        // Nothing moved since the last selection: the faces the table describes keep their
        // rates unsampled (those sampled by refinement, next to sharp features, never do).
        // (The cube: none of 24; the creased cube: the 20 faces at or next to its creases.)
        let sampled = kept.faces_sampled().expect("a tolerance's count");
        let faces = kept.rates().len();
        let at_rest = if label == "cube" { 0 } else { faces - 1 };
        assert!(
            sampled <= at_rest,
            "{label}: {sampled} of {faces} faces sampled at rest"
        );
    }
}

#[test]
#[cfg(feature = "catmull-clark")]
fn moved_positions_choose_a_fresh_surfaces_rates() {
    // The cube's valence-3 corners take an isolating step: the positions go through its map.
    let cube = Mesh::read_obj(data("cube.obj")).expect("cube");
    check_moved_rates("cube", &cube, Scheme::CatmullClark, 1e-3);
    let creased = Mesh::read_obj(data("cube_creased.obj")).expect("creased cube");
    check_moved_rates("creased cube", &creased, Scheme::CatmullClark, 1e-3);
    #[cfg(feature = "loop")]
    {
        let octahedron = Mesh::read_obj(data("octahedron.obj")).expect("octahedron");
        check_moved_rates("octahedron, loop", &octahedron, Scheme::Loop, 1e-3);
    }
}

/// Read an OBJ file's `v` and `f` lines (triangles, `f a b c` or `f a//a ...`).
fn read_triangles(path: &Path) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let text = std::fs::read_to_string(path).expect("output");
    let mut v = Vec::new();
    let mut f = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f32> = words.map(|w| w.parse().expect("coordinate")).collect();
                v.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let i: Vec<u32> = words
                    .map(|w| {
                        w.split('/')
                            .next()
                            .and_then(|x| x.parse().ok())
                            .expect("index")
                    })
                    .collect();
                f.push([i[0] - 1, i[1] - 1, i[2] - 1]);
            }
            _ => {}
        }
    }
    (v, f)
}

#[test]
#[cfg(feature = "catmull-clark")]
fn the_cli_writes_the_frame_the_library_makes() {
    let out = std::env::temp_dir().join(format!("subtess-facade-{}.obj", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_subtess"))
        .args(["tessellate", "data/cube.obj", "--rate", "5", "-o"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (positions, triangles) = read_triangles(&out);
    let _ = std::fs::remove_file(&out);
    let cube = Mesh::read_obj(data("cube.obj")).expect("cube");
    let surface = Surface::new(&cube, Scheme::CatmullClark).expect("surface");
    let mut tessellator = surface.tessellator(&Rates::Uniform(5)).expect("plan");
    let frame = tessellator.evaluate(&cube.positions_f32()).expect("frame");
    assert_eq!(frame.triangles(), &triangles[..]);
    assert_eq!(frame.positions().len(), positions.len());
    for (a, b) in frame.positions().iter().zip(&positions) {
        assert!(distance(*a, *b) < 1e-6, "{a:?} vs {b:?}");
    }
}

#[test]
#[cfg(feature = "loop")]
#[cfg(feature = "catmull-clark")]
fn rates_per_input_face_and_errors() {
    let cube = Mesh::read_obj(data("cube.obj")).expect("cube");
    let surface = Surface::new(&cube, Scheme::CatmullClark).expect("surface");
    let per_face = Rates::PerFace(vec![1, 2, 3, 4, 5, 6]);
    let tessellator = surface.tessellator(&per_face).expect("per-face plan");
    // One step made four quads of every input face; they inherit its rate.
    let mut rates = tessellator.rates().to_vec();
    rates.sort_unstable();
    rates.dedup();
    assert_eq!(rates, [1, 2, 3, 4, 5, 6]);
    for bad in [
        Rates::PerFace(vec![1; 5]),
        Rates::PerFace(vec![0; 6]),
        Rates::Uniform(0),
        Rates::Uniform(99),
    ] {
        assert!(surface.tessellator(&bad).is_err(), "{bad:?}");
    }
    // A table of another scheme is refused by name.
    let table = Scheme::Loop
        .default_table(subtess::BoundaryMode::EdgeOnly)
        .expect("loop table");
    let err = Surface::with_table(&cube, Scheme::CatmullClark, table).expect_err("wrong table");
    assert!(err.to_string().contains("loop"), "{err}");
}
