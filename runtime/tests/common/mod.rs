//! Meshes and checks shared by the runtime's integration tests.
// Each test binary uses its own subset.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use runtime::obj::read_obj;
use runtime::topology::Mesh;
use runtime::triangle_mesh::TriangleMesh;
use schemes::BoundaryMode;

pub fn mesh(positions: Vec<[f64; 3]>, faces: &[[i64; 3]]) -> Mesh {
    let faces: Vec<Vec<i64>> = faces.iter().map(|f| f.to_vec()).collect();
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid test mesh")
}

pub fn tetrahedron() -> Mesh {
    mesh(
        vec![
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ],
        &[[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
    )
}

pub fn octahedron() -> Mesh {
    let p = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    mesh(
        p,
        &[
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
    )
}

pub fn icosahedron() -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let p = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    mesh(
        p,
        &[
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ],
    )
}

/// A torus of `m x n` lattice cells, each split into two triangles the same way: every vertex
/// interior of valence 6 (regular).
pub fn torus(m: usize, n: usize) -> Mesh {
    let (big, small) = (3.0, 1.0);
    let mut p = Vec::new();
    for j in 0..n {
        for i in 0..m {
            let (a, b) = (
                std::f64::consts::TAU * i as f64 / m as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            let r = big + small * b.cos();
            p.push([r * a.cos(), r * a.sin(), small * b.sin()]);
        }
    }
    let at = |i: usize, j: usize| ((j % n) * m + i % m) as i64;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..m {
            faces.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            faces.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh(p, &faces)
}

pub fn models() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!(
            "skipping: {} is absent (it ships beside the repository, not in it)",
            dir.display()
        );
        None
    }
}

pub fn load(path: &Path) -> Mesh {
    let obj = read_obj(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Mesh::from_obj(&obj)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// The output is an oriented manifold with the input's Euler characteristic and boundary loops.
pub fn check_topology(input: &Mesh, out: &TriangleMesh, label: &str) {
    let triangles: Vec<Vec<i64>> = out
        .triangles
        .iter()
        .map(|t| t.iter().map(|&v| i64::from(v)).collect())
        .collect();
    let positions = out.positions.iter().map(|p| p.map(f64::from)).collect();
    let surface = Mesh::new(positions, &triangles, &[], BoundaryMode::EdgeOnly)
        .unwrap_or_else(|e| panic!("{label}: the output is not an oriented manifold: {e}"));
    let used = surface
        .vertex_halfedge
        .iter()
        .filter(|&&h| h != runtime::topology::NONE)
        .count();
    assert_eq!(used, out.positions.len(), "{label}: unused output vertices");
    assert_eq!(
        surface.euler_characteristic(),
        input.euler_characteristic(),
        "{label}: Euler characteristic"
    );
    assert_eq!(
        surface.boundary_loops(),
        input.boundary_loops(),
        "{label}: boundary loops"
    );
    assert_eq!(
        out.is_watertight(),
        input.boundary_loops() == 0,
        "{label}: watertight"
    );
}
