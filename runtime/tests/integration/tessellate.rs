//! The dual-grid tessellator on closed meshes: watertight, manifold, the input's Euler
//! characteristic, vertices on the limit surface, normals facing out.

use std::path::Path;

use proptest::prelude::*;
use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::scheme::patch::dual_positions;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::dual_grid::{tessellate, tessellate_uniform};
use subtess::tessellate::GridPlan;

fn load(path: &Path) -> Mesh {
    let obj = read_obj(path).unwrap_or_else(|e| panic!("{e}"));
    Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0
}

fn check(name: &str, mesh: &Mesh, convex: bool) {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (isolated, patches, _) = isolate(mesh).expect("isolates");
    for n in 1..=5u32 {
        let (out, _) = tessellate_uniform(&table, &isolated, &patches, n).expect("tessellates");
        assert!(out.is_watertight(), "{name} n = {n}: not watertight");
        assert_eq!(
            out.euler_characteristic(),
            mesh.euler_characteristic(),
            "{name} n = {n}"
        );
        // Every vertex is the limit surface at its (face, u, v).
        let nn = (n * n) as usize;
        for (f, patch) in patches.iter().enumerate() {
            let expected =
                dual_positions(&table, &isolated, patch, n).expect("reference evaluation");
            for (i, p) in expected.iter().enumerate() {
                let q = out.positions[f * nn + i];
                assert!(
                    (0..3).all(|c| (p[c] - f64::from(q[c])).abs() < 1e-5),
                    "{name} n = {n} face {f}: {p:?} vs {q:?}"
                );
                let source = out.sources[f * nn + i];
                assert_eq!(source.face as usize, f);
                let (u, v) = source.uv();
                let (ei, ej) = ((i as u32 % n) as f64, (i as u32 / n) as f64);
                assert_eq!(
                    (u, v),
                    (
                        (2.0 * ei + 1.0) / (2.0 * n as f64),
                        (2.0 * ej + 1.0) / (2.0 * n as f64)
                    )
                );
            }
        }
        if convex {
            let centre = out
                .positions
                .iter()
                .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
            let centre = centre.map(|c| c / out.positions.len() as f32);
            for (p, normal) in out.positions.iter().zip(&out.normals) {
                let outward: f32 = (0..3).map(|c| (p[c] - centre[c]) * normal[c]).sum();
                assert!(outward > 0.0, "{name} n = {n}: a normal points inwards");
            }
        }
    }
}

#[test]
#[cfg(feature = "catmull-clark")]
fn the_shipped_cube_tessellates_watertight() {
    let mesh = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj"));
    check("cube", &mesh, true);
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn spot_tessellates_watertight() {
    check("spot", &spot(), false);
}

/// Crane's Spot, from `../shared/models`.
fn spot() -> Mesh {
    load(&crate::common::models().join("crane/spot_control_mesh.obj"))
}

/// Rates from `seed` (any of `1..=max_rate`, not only powers of two) tessellate `mesh`
/// watertight, manifold and with its Euler characteristic.
fn check_random_rates(mesh: &Mesh, seed: &[u32], max_rate: u32) -> Result<(), TestCaseError> {
    static TABLE: std::sync::OnceLock<StencilTable> = std::sync::OnceLock::new();
    let table =
        TABLE.get_or_init(|| StencilTable::default_catmull_clark().expect("embedded table"));
    let (isolated, patches, _) = isolate(mesh).expect("isolates");
    let rates: Vec<u32> = (0..patches.len())
        .map(|f| 1 + (seed[f % seed.len()] - 1) % max_rate)
        .collect();
    let (out, _) = tessellate(table, &isolated, &patches, &rates).expect("tessellates");
    prop_assert!(out.is_watertight());
    prop_assert_eq!(out.euler_characteristic(), mesh.euler_characteristic());
    prop_assert_eq!(
        out.positions.len(),
        rates.iter().map(|&n| (n * n) as usize).sum::<usize>()
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Random per-face rates, any of 1..=24, on the cube.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn random_per_face_rates_stay_watertight(seed in proptest::collection::vec(1u32..=24, 64)) {
        let cube = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj"));
        check_random_rates(&cube, &seed, 24)?;
    }
}

proptest! {
    // Spot's 2,928 faces at up to rate 6 cost more than the cube; as many Spot cases as when
    // the cube's test drew Spot too in half of its 16.
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Random per-face rates, any of 1..=6, on Spot.
    #[test]
    #[cfg_attr(not(shared_models), ignore = "needs ../shared/models beside the repository")]
    #[cfg(feature = "catmull-clark")]
    fn random_per_face_rates_on_spot_stay_watertight(seed in proptest::collection::vec(1u32..=24, 64)) {
        check_random_rates(&spot(), &seed, 6)?;
    }
}

/// On a refined cube every face away from the eight valence-3 corners is regular and takes the
/// tensor-product path, whose factors are recovered from (and checked against) the table.
#[test]
#[cfg(feature = "catmull-clark")]
fn regular_faces_are_evaluated_as_tensor_products() {
    let mesh = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj"));
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (isolated, patches, _) = isolate(&mesh).expect("isolates");
    let irregular = patches.iter().filter(|p| p.kind.faces != 4).count();
    for n in [1, 2, 7, 24] {
        let grid = subtess::tessellate::dual_grid::DualGrid::new(
            &table,
            &isolated,
            &patches,
            &vec![n; patches.len()],
        )
        .expect("plans");
        assert_eq!(grid.separable_faces(), patches.len() - irregular, "n = {n}");
    }
}

/// The uniform cubic B-spline basis and its derivative at `t` (closed form).
fn cubic_bspline(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ],
        [
            -s * s / 2.0,
            (3.0 * t * t - 4.0 * t) / 2.0,
            (-3.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
    )
}

/// A torus of 12 x 8 quads has only valence-4 vertices: every face is a bicubic B-spline patch
/// over the 4 x 4 grid of its neighbours (the closed form, independent of the tables), and every
/// output vertex and normal must be that patch at the vertex's (face, u, v), at any rate.
#[test]
#[cfg(feature = "catmull-clark")]
fn valence_4_regions_reproduce_the_bicubic_b_spline() {
    let (m, k) = (12usize, 8usize);
    let point = |i: usize, j: usize| {
        let (a, b) = (
            std::f64::consts::TAU * (i % m) as f64 / m as f64,
            std::f64::consts::TAU * (j % k) as f64 / k as f64,
        );
        // Bumps so that no two patches are congruent.
        let r = 1.0 + 0.1 * ((3 * i + 7 * j) % 5) as f64;
        [
            (3.0 + r * b.cos()) * a.cos(),
            (3.0 + r * b.cos()) * a.sin(),
            r * b.sin(),
        ]
    };
    let positions: Vec<[f64; 3]> = (0..k)
        .flat_map(|j| (0..m).map(move |i| point(i, j)))
        .collect();
    let index = |i: usize, j: usize| ((j % k) * m + (i % m)) as i64;
    let faces: Vec<Vec<i64>> = (0..k)
        .flat_map(|j| {
            (0..m).map(move |i| {
                vec![
                    index(i, j),
                    index(i + 1, j),
                    index(i + 1, j + 1),
                    index(i, j + 1),
                ]
            })
        })
        .collect();
    let mesh = Mesh::new(
        positions.clone(),
        &faces,
        &[],
        schemes::BoundaryMode::EdgeOnly,
    )
    .expect("valid torus");
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let (isolated, patches, steps) = isolate(&mesh).expect("isolates");
    assert_eq!(steps, 0);
    for rates in [
        vec![1; m * k],
        vec![6; m * k],
        (0..m * k).map(|f| 1 + (f as u32 * 5) % 24).collect(),
    ] {
        let (out, _) = tessellate(&table, &isolated, &patches, &rates).expect("tessellates");
        assert!(out.is_watertight());
        assert_eq!(out.euler_characteristic(), 0);
        for (v, source) in out.sources.iter().enumerate() {
            let f = source.face as usize;
            let (fi, fj) = (f % m, f / m);
            let (u, w) = source.uv();
            let ((bu, du), (bv, dv)) = (cubic_bspline(u), cubic_bspline(w));
            let mut p = [0.0; 3];
            let mut tu = [0.0; 3];
            let mut tv = [0.0; 3];
            for a in 0..4 {
                for b in 0..4 {
                    let q = positions[index(fi + m + a - 1, fj + k + b - 1) as usize];
                    for c in 0..3 {
                        p[c] += bu[a] * bv[b] * q[c];
                        tu[c] += du[a] * bv[b] * q[c];
                        tv[c] += bu[a] * dv[b] * q[c];
                    }
                }
            }
            let got = out.positions[v];
            assert!(
                (0..3).all(|c| (p[c] - f64::from(got[c])).abs() < 1e-5),
                "face {f} at ({u}, {w}): {got:?} vs {p:?}"
            );
            let n = [
                tu[1] * tv[2] - tu[2] * tv[1],
                tu[2] * tv[0] - tu[0] * tv[2],
                tu[0] * tv[1] - tu[1] * tv[0],
            ];
            let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            let normal = out.normals[v];
            assert!(
                (0..3).all(|c| (n[c] / length - f64::from(normal[c])).abs() < 1e-4),
                "normal of face {f} at ({u}, {w})"
            );
        }
    }
}

/// Every output vertex is the exact limit surface (`exact_eval`, evaluated on the *input* mesh)
/// at the source the tessellator reports for it, mapped back through isolation to the input
/// face's own parameters (or an n-gon's sub-face): positions to f32 accuracy, normals to 1e-4.
#[test]
#[cfg(feature = "catmull-clark")]
fn output_vertices_are_exact_evaluation_at_their_input_sources() {
    // A pyramid with a pentagonal base (an n-gon) and a boundary: five triangles around the apex
    // with one removed.
    let mut p: Vec<[f64; 3]> = (0..5)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 5.0;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    p.push([0.1, 0.2, 1.3]);
    let faces: Vec<Vec<i64>> = vec![
        vec![4, 3, 2, 1, 0],
        vec![0, 1, 5],
        vec![1, 2, 5],
        vec![2, 3, 5],
        vec![3, 4, 5],
    ];
    let open_pyramid = Mesh::new(p, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("valid");
    let cube = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj"));
    check_exact_at_input_sources("cube", &cube, 1);
    check_exact_at_input_sources("open pyramid", &open_pyramid, 1);
}

/// Spot's output vertices (every 37th) are the exact limit surface at their input sources.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn spots_output_vertices_are_exact_evaluation_at_their_input_sources() {
    check_exact_at_input_sources("spot", &spot(), 37);
}

/// Every `stride`-th output vertex of `mesh` at mixed rates against exact evaluation at its
/// input source.
fn check_exact_at_input_sources(name: &str, mesh: &Mesh, stride: usize) {
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use subtess::eval::exact_eval::ExactEvaluator;
    use subtess::scheme::catmull_clark::isolate::isolate_with_origins;
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    {
        let iso = isolate_with_origins(mesh).expect("isolates");
        let rates: Vec<u32> = (0..iso.patches.len())
            .map(|f| 1 + (f as u32 * 3) % 5)
            .collect();
        let (out, _) = tessellate(&table, &iso.mesh, &iso.patches, &rates).expect("tessellates");
        let exact = ExactEvaluator::new(mesh);
        let size = out
            .positions
            .iter()
            .flatten()
            .fold(0.0f32, |m, c| m.max(c.abs()));
        for v in (0..out.positions.len()).step_by(stride) {
            let s = iso.input_source(out.sources[v]);
            let r = |x: u32| BigRational::new(BigInt::from(x), BigInt::from(s.denominator));
            let point = exact
                .evaluate_subface(s.face as usize, usize::from(s.subface), &r(s.u), &r(s.v))
                .unwrap_or_else(|e| panic!("{name} vertex {v}: {e}"));
            let got = out.positions[v];
            assert!(
                (0..3).all(|c| (point.position[c] - f64::from(got[c])).abs() < 2e-6 * f64::from(size)),
                "{name} vertex {v} at {s:?}: {got:?} vs exact {:?}",
                point.position
            );
            let n = [
                point.du[1] * point.dv[2] - point.du[2] * point.dv[1],
                point.du[2] * point.dv[0] - point.du[0] * point.dv[2],
                point.du[0] * point.dv[1] - point.du[1] * point.dv[0],
            ];
            let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            let normal = out.normals[v];
            assert!(
                (0..3).all(|c| (n[c] / length - f64::from(normal[c])).abs() < 1e-4),
                "{name} vertex {v} at {s:?}: normal {normal:?} vs exact {n:?}"
            );
        }
    }
}
