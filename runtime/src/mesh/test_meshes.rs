//! Small meshes for the unit tests (the integration tests have their own in `tests/common`).

use schemes::BoundaryMode;

use crate::mesh::topology::Mesh;

/// The octahedron `±x, ±y, ±z` (vertices 0..6 in that order), every vertex of valence 4.
pub fn octahedron() -> Mesh {
    let p = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let f = vec![
        vec![0, 2, 4],
        vec![2, 1, 4],
        vec![1, 3, 4],
        vec![3, 0, 4],
        vec![2, 0, 5],
        vec![1, 2, 5],
        vec![3, 1, 5],
        vec![0, 3, 5],
    ];
    Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("a valid octahedron")
}

/// The unit cube `[0, 1]^3`, vertices `(0,0,0), (1,0,0), (1,1,0), (0,1,0)` and then the same at
/// `z = 1`, faces outward, every vertex of valence 3.
pub fn cube() -> Mesh {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let f = vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ];
    Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("a valid cube")
}

/// The regular tetrahedron, every vertex of valence 3.
pub fn tetrahedron() -> Mesh {
    let p = vec![
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    let f = vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 1], vec![1, 3, 2]];
    Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("a valid tetrahedron")
}

/// The skew lattice `Z^2` wrapped into an `m x m` torus: vertex `(a, b)` (mod `m`) is number
/// `a + m b`, placed at `position(a, b)`; triangles `(a,b),(a+1,b),(a,b+1)` and
/// `(a+1,b),(a+1,b+1),(a,b+1)`, every vertex of valence 6.
pub fn lattice_torus(m: i64, position: impl Fn(i64, i64) -> [f64; 3]) -> Mesh {
    let index = |a: i64, b: i64| a.rem_euclid(m) + m * b.rem_euclid(m);
    let positions = (0..m * m).map(|k| position(k % m, k / m)).collect();
    let mut faces = Vec::new();
    for b in 0..m {
        for a in 0..m {
            faces.push(vec![index(a, b), index(a + 1, b), index(a, b + 1)]);
            faces.push(vec![index(a + 1, b), index(a + 1, b + 1), index(a, b + 1)]);
        }
    }
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid torus")
}

/// A torus of `m x n` quads, every vertex interior of valence 4 (regular), slightly twisted
/// out of its symmetry planes so that no coordinate of a patch is constant.
#[cfg(feature = "catmull-clark")]
pub fn quad_torus(m: usize, n: usize) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..m {
            let (a, b) = (
                std::f64::consts::TAU * i as f64 / m as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            let r = 3.0 + b.cos();
            positions.push([r * a.cos(), r * a.sin(), b.sin() + 0.1 * a.sin()]);
        }
    }
    let at = |i: usize, j: usize| ((j % n) * m + i % m) as i64;
    let faces: Vec<Vec<i64>> = (0..m * n)
        .map(|k| {
            let (i, j) = (k % m, k / m);
            vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
        })
        .collect();
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid torus")
}
