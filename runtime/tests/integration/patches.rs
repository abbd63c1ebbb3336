//! Face patches from the tables against the refinement step (itself checked against Pixar's
//! Hbr): the limit surface of a face equals that of its four children at corresponding
//! parameters, for interior extraordinary vertices and for boundaries.

use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::refine::refine;
use subtess::scheme::patch::{dual_positions, face_patch};
use subtess::stencil_table::StencilTable;

/// A mesh from `../shared/models`.
fn model(relative: &str) -> Mesh {
    let path = crate::common::models().join(relative);
    let obj = read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0
}

/// Child `c` of a quad covers the quarter at corner `c`; its dual point (i, j) at rate n is the
/// parent's dual point at rate 2n returned here.
fn parent_index(c: usize, i: usize, j: usize, n: usize) -> (usize, usize) {
    let last = 2 * n - 1;
    match c {
        0 => (i, j),
        1 => (last - j, i),
        2 => (last - i, last - j),
        _ => (j, last - i),
    }
}

fn check_refinement_invariance(name: &str, mesh: Mesh, table: &StencilTable) {
    // Two steps isolate every extraordinary vertex; a third gives the children.
    let parent = refine(&refine(&mesh).mesh).mesh;
    let children = refine(&parent).mesh;
    let size = {
        let (lo, hi) =
            parent
                .positions
                .iter()
                .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                    (
                        [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                        [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
                    )
                });
        (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
    };
    let mut kinds = std::collections::BTreeSet::new();
    let mut worst = 0f64;
    for n in [1usize, 3, 5, 12] {
        for f in 0..parent.faces() {
            let patch = face_patch(&parent, f).unwrap_or_else(|e| panic!("{name}: {e}"));
            kinds.insert((patch.kind.boundary, patch.kind.faces));
            let coarse =
                dual_positions(table, &parent, &patch, 2 * n as u32).expect("parent positions");
            for c in 0..4 {
                let child = 4 * f + c;
                let patch = face_patch(&children, child).unwrap_or_else(|e| panic!("{name}: {e}"));
                let fine =
                    dual_positions(table, &children, &patch, n as u32).expect("child positions");
                for j in 0..n {
                    for i in 0..n {
                        let (pi, pj) = parent_index(c, i, j, n);
                        let (a, b) = (coarse[pj * 2 * n + pi], fine[j * n + i]);
                        let d = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
                        worst = worst.max(d / size);
                    }
                }
            }
        }
    }
    println!(
        "{name}: patch kinds {kinds:?}, largest parent/child difference {worst:e} of the size"
    );
    assert!(
        worst < 2e-6,
        "{name}: the limit surface changed under refinement by {worst:e}"
    );
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn spot_limit_surface_is_invariant_under_refinement() {
    check_refinement_invariance(
        "spot",
        model("crane/spot_control_mesh.obj"),
        &StencilTable::default_catmull_clark().expect("embedded table"),
    );
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn boundary_limit_surfaces_are_invariant_under_refinement() {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    for name in ["opensubdiv/catmark_flap.obj", "opensubdiv/catmark_tent.obj"] {
        check_refinement_invariance(name, model(name), &table);
    }
}

/// `catmark_edgecorner` pins its corners ("interpolateboundary 1"): the default ("edge only")
/// table is refused for it, and a table made with `--corners` evaluates it.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn pinned_corners_need_a_corner_table() {
    let mesh = model("opensubdiv/catmark_edgecorner.obj");
    let isolated = refine(&refine(&mesh).mesh).mesh;
    let default = StencilTable::default_catmull_clark().expect("embedded table");
    let corner_face = (0..isolated.faces())
        .find(|&f| face_patch(&isolated, f).is_ok_and(|p| p.kind.boundary && p.kind.faces == 1))
        .expect("a corner face");
    let patch = face_patch(&isolated, corner_face).expect("patch");
    let e = dual_positions(&default, &isolated, &patch, 2).expect_err("edge-only table");
    assert!(e.to_string().contains("--corners"), "{e}");
    let mut spec = stencilgen::table::TableSpec::default_catmull_clark().expect("spec");
    spec.set = stencilgen::stencil_set::StencilSetSpec {
        valences: vec![4],
        darts: Vec::new(),
        boundary_faces: vec![1, 2],
        boundary_mode: schemes::BoundaryMode::EdgeAndCorner,
        rates: vec![1, 2, 3, 5, 6, 10, 12, 24],
    };
    let bytes = stencilgen::table::build_table(&spec, &|_, _| {}).expect("corner table");
    let path = std::env::temp_dir().join(format!("subtess-corners-{}.subtess", std::process::id()));
    std::fs::write(&path, bytes).expect("write");
    let table = StencilTable::read(&path).expect("valid");
    check_refinement_invariance("catmark_edgecorner", mesh.clone(), &table);
    let _ = std::fs::remove_file(&path);
    // The embedded pinned-corner table laid over the default one does the same.
    let overlay =
        StencilTable::default_for(schemes::BoundaryMode::EdgeAndCorner).expect("embedded tables");
    assert!(overlay.pins_corners());
    check_refinement_invariance("catmark_edgecorner (embedded corner table)", mesh, &overlay);
}

#[test]
fn unisolated_faces_are_refused() {
    // A single triangle and a quad whose corners are all irregular.
    let p = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let tri = Mesh::new(
        p.clone(),
        &[vec![0, 1, 2]],
        &[],
        schemes::BoundaryMode::EdgeOnly,
    )
    .expect("valid");
    assert!(face_patch(&tri, 0).is_err());
    let quad =
        Mesh::new(p, &[vec![0, 1, 3, 2]], &[], schemes::BoundaryMode::EdgeOnly).expect("valid");
    let e = face_patch(&quad, 0).expect_err("four corners of one face each");
    assert!(e.to_string().contains("irregular"), "{e}");
}
