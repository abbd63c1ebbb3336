//! Real meshes from `../shared/models` (every test here is ignored where that folder was absent
//! at build time): every OpenSubdiv shape is read and accepted, and the
//! Catmull–Clark refinement reproduces Pixar's Hbr reference refinements and Crane's Spot.

use crate::common::models;

use std::path::{Path, PathBuf};

use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::scheme::catmull_clark::refine::refine;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::tessellate;

fn load(path: &Path) -> (Mesh, Vec<String>) {
    let obj = read_obj(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every OpenSubdiv regression shape parses and its topology validates, the deliberately
/// non-manifold `nonman_*` shapes included (faces that repeat a vertex too); a shape refused
/// would print its message and fail.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn every_opensubdiv_shape_is_accepted() {
    let dir = models();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir.join("opensubdiv"))
        .expect("readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    entries.sort();
    assert!(entries.len() >= 50);
    let (mut accepted, mut refused) = (0, 0);
    for path in entries {
        let obj = read_obj(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        match Mesh::from_obj(&obj) {
            Ok((mesh, warnings)) => {
                accepted += 1;
                let refined = refine(&mesh).mesh;
                assert_eq!(
                    refined.euler_characteristic(),
                    mesh.euler_characteristic(),
                    "{}",
                    path.display()
                );
                for w in warnings {
                    println!(
                        "{}: {w}",
                        path.file_name()
                            .map(|n| n.to_string_lossy())
                            .unwrap_or_default()
                    );
                }
            }
            Err(e) => {
                refused += 1;
                let name = path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                println!("{name}: refused: {e}");
            }
        }
    }
    println!("{accepted} accepted, {refused} refused");
    assert_eq!(refused, 0, "every shape is accepted");
    assert!(accepted >= 57, "only {accepted} shapes accepted");
}

/// Every shape the topology accepts tessellates (rate 3, and mixed rates 1..5) into a closed,
/// consistently oriented surface or, with boundary, one with boundary edges; the Euler
/// characteristic is the input's. Shapes that pin their corners use the embedded corner table. Shapes are refused, with the reason, only
/// when isolation fails.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn every_accepted_opensubdiv_shape_tessellates_watertight() {
    let dir = models();
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir.join("opensubdiv"))
        .expect("readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    entries.sort();
    // Shapes that pin their one-face corners get the embedded pinned-corner table laid over
    // the default one.
    let corner_table =
        StencilTable::default_for(schemes::BoundaryMode::EdgeAndCorner).expect("embedded tables");
    let (mut tessellated, mut corners, mut refused) = (0, 0, Vec::new());
    for path in entries {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let obj = read_obj(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let Ok((mesh, _)) = Mesh::from_obj(&obj) else {
            continue;
        };
        let (isolated, patches, _) = match isolate(&mesh) {
            Ok(x) => x,
            Err(e) => {
                refused.push(format!("{name}: {e}"));
                continue;
            }
        };
        let table = if mesh.boundary == schemes::BoundaryMode::EdgeAndCorner {
            corners += 1;
            &corner_table
        } else {
            &table
        };
        let mixed = (0..patches.len()).map(|f| 1 + (f as u32 * 7) % 5).collect();
        for rates in [vec![3; patches.len()], mixed] {
            let out = match tessellate(table, &isolated, &patches, &rates) {
                Ok((out, _)) => out,
                Err(e @ subtess::RuntimeError::Table(_)) => {
                    refused.push(format!("{name}: {e}"));
                    break;
                }
                Err(e) => panic!("{name}: {e}"),
            };
            if mesh.boundary_loops() == 0 {
                assert!(out.is_watertight(), "{name}: not watertight");
            } else {
                let edges = out
                    .boundary_edges()
                    .unwrap_or_else(|| panic!("{name}: non-manifold output"));
                assert!(!edges.is_empty(), "{name}: lost its boundary");
            }
            assert_eq!(
                out.euler_characteristic(),
                mesh.euler_characteristic(),
                "{name}"
            );
        }
        tessellated += 1;
    }
    for r in &refused {
        println!("refused: {r}");
    }
    tessellated -= refused.len();
    println!(
        "{tessellated} shapes tessellated ({corners} with pinned corners), {} refused",
        refused.len()
    );
    assert!(refused.is_empty(), "refused: {refused:?}");
    assert!(tessellated >= 57, "only {tessellated} shapes tessellated");
}

/// `catmark_nonman_quadpole8`'s quads repeat their pole vertex (`a b v v`): each has a
/// degenerate edge from `v` to itself, non-manifold in OpenSubdiv, so infinitely sharp between
/// two pinned copies of `v`. Closed forms the output must meet: the limit curve of an
/// infinitely sharp edge between two pinned points at one position is that point, so the
/// surface's boundary around the pole collapses onto `v = (0, -1, 0)`; the outer boundary is
/// the cubic B-spline of the outer ring, whose control points all have `y = -0.7836`, so it
/// stays in that plane. Every output boundary vertex is on one of the two, both are present,
/// and there are two boundary loops.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn doubled_corners_close_the_surface_at_their_vertex() {
    let (mesh, _) = load(&models().join("opensubdiv/catmark_nonman_quadpole8.obj"));
    assert_eq!(mesh.boundary_loops(), 2);
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (isolated, patches, _) = isolate(&mesh).expect("isolates");
    for rate in [1, 2, 5, 8] {
        let (out, _) = tessellate(&table, &isolated, &patches, &vec![rate; patches.len()])
            .expect("tessellates");
        let edges = out.boundary_edges().expect("manifold output");
        let (mut at_pole, mut on_rim) = (0, 0);
        for &(a, _) in &edges {
            let p = out.positions[a as usize];
            let to_pole = (p[0].powi(2) + (p[1] + 1.0).powi(2) + p[2].powi(2)).sqrt();
            if to_pole < 1e-6 {
                at_pole += 1;
            } else {
                assert!(
                    (p[1] + 0.7836).abs() < 1e-6,
                    "rate {rate}: boundary vertex {p:?} neither at the pole nor on the rim"
                );
                on_rim += 1;
            }
        }
        assert!(
            at_pole >= 8 && on_rim >= 8,
            "rate {rate}: {at_pole} at the pole, {on_rim} on the rim"
        );
        assert_eq!(out.euler_characteristic(), mesh.euler_characteristic());
    }
}

/// The largest distance from each point of `reference` to the nearest point of `ours`, relative
/// to the reference's bounding-box diagonal.
fn point_set_distance(ours: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in reference {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let diagonal = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt();
    let nearest = |q: &[f64; 3]| {
        ours.iter()
            .map(|p| (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>())
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    };
    reference.iter().map(nearest).fold(0.0, f64::max) / diagonal
}

/// Pixar Hbr's reference refinements (`<name>_level<N>.obj` = N + 1 uniform steps) as point
/// sets, to 1e-5 of the model size, for every reference shape: creases (semi-sharp and
/// infinite), corners, darts and both boundary modes, all with their tags.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn refinement_reproduces_hbr_reference() {
    let dir = models();
    let mut names: Vec<String> = std::fs::read_dir(dir.join("opensubdiv_hbr_reference"))
        .expect("readable")
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.ends_with(".obj"))
        .collect();
    names.sort();
    let mut compared = 0;
    for name in names {
        let Some((shape, level)) = name.trim_end_matches(".obj").rsplit_once("_level") else {
            continue;
        };
        let level: usize = level.parse().expect("level number");
        let (mut mesh, warnings) = load(&dir.join("opensubdiv").join(format!("{shape}.obj")));
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        for _ in 0..=level {
            mesh = refine(&mesh).mesh;
        }
        let (reference, _) = load(&dir.join("opensubdiv_hbr_reference").join(&name));
        assert_eq!(
            mesh.positions.len(),
            reference.positions.len(),
            "{name}: vertex count"
        );
        assert_eq!(mesh.faces(), reference.faces(), "{name}: face count");
        let d = point_set_distance(&mesh.positions, &reference.positions);
        assert!(d < 1e-5, "{name}: points differ by {d:e} of the model size");
        compared += 1;
    }
    println!("{compared} reference refinements reproduced");
    assert_eq!(compared, 51, "every reference refinement is compared");
}

/// Crane's `spot_quadrangulated.obj` is two Catmull–Clark steps of `spot_control_mesh.obj`.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn refinement_reproduces_spot() {
    let dir = models();
    let (control, _) = load(&dir.join("crane/spot_control_mesh.obj"));
    let (reference, _) = load(&dir.join("crane/spot_quadrangulated.obj"));
    let twice = refine(&refine(&control).mesh).mesh;
    assert_eq!(twice.positions.len(), reference.positions.len());
    let d = point_set_distance(&twice.positions, &reference.positions);
    assert!(d < 1e-5, "spot differs by {d:e} of its size");
    assert_eq!(twice.euler_characteristic(), 2);
}
