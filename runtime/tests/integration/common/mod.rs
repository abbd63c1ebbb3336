//! Meshes and checks shared by the runtime's integration tests.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use schemes::cone_regions::ConeRegions;
use schemes::crease::INFINITE;
use schemes::triangle_local::{canonical_triangle_point, TrianglePoint};
use schemes::{BoundaryMode, TriangleScheme};
use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use subtess::scheme::catmull_clark::adaptive::LimitQuery;
use subtess::scheme::triangle::cone_chart::ConeChart;
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::scheme::triangle::region_patch::RegionScheme;
use subtess::scheme::triangle::split::{Split, TriangleSplit};
use subtess::stencil_table::StencilTable;
use subtess::tessellate::triangle_dual_grid::TriangleDualGrid;
use subtess::tessellate::GridPlan;

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

/// A cube of side 2 (faces: -z, +z, -y, +x, +y, -x), vertex `i` at the signs of its bits.
pub fn cube() -> Mesh {
    let positions = (0..8)
        .map(|i| {
            let s = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
            [s(0), s(1), s(2)]
        })
        .collect();
    let faces: Vec<Vec<i64>> = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![1, 3, 7, 5],
        vec![3, 2, 6, 7],
        vec![2, 0, 4, 6],
    ];
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a cube")
}

/// The cube with every kind of feature: an infinitely sharp crease loop around the top, a
/// semi-sharp edge, a dart (one sharp edge ending inside), a semi-sharp corner, and, with
/// `hole`, face 2 a hole.
pub fn featured_cube(hole: bool) -> Mesh {
    let mut mesh = cube();
    for (a, b) in [(4, 5), (5, 7), (7, 6), (6, 4)] {
        mesh.set_edge_sharpness(a, b, INFINITE).expect("an edge");
    }
    mesh.set_edge_sharpness(0, 1, 1.5).expect("an edge");
    mesh.set_edge_sharpness(1, 3, INFINITE).expect("an edge");
    mesh.set_vertex_sharpness(2, 2.25).expect("a vertex");
    mesh.holes[2] = hole;
    mesh
}

/// Where the point `(u, v)` of sub-face `k` of face `f` of `mesh` lies on the mesh refined
/// once by Catmull–Clark (`subtess::scheme::catmull_clark::refine`, whose children are numbered
/// by the parent's half-edges): sub-face `k` of an n-gon is its child at corner `k`, in the same
/// parameters; a quad's point lies in the child of its quarter, in that child's parameters.
pub fn refined_query(mesh: &Mesh, f: usize, k: usize, u: f64, v: f64) -> LimitQuery {
    let first = mesh.face_halfedges(f).start;
    if mesh.face(f).len() != 4 {
        return LimitQuery {
            face: (first + k) as u32,
            u,
            v,
        };
    }
    let (c, s, t) = match (u > 0.5, v > 0.5) {
        (false, false) => (0, 2.0 * u, 2.0 * v),
        (true, false) => (1, 2.0 * v, 2.0 - 2.0 * u),
        (true, true) => (2, 2.0 - 2.0 * u, 2.0 - 2.0 * v),
        (false, true) => (3, 2.0 - 2.0 * v, 2.0 * u),
    };
    LimitQuery {
        face: (first + c) as u32,
        u: s,
        v: t,
    }
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

/// `../shared/models`, the real meshes beside the repository (or the folder
/// `SUBTESS_SHARED_MODELS` named at build time; `runtime/build.rs`). Tests that read it carry
/// `#[cfg_attr(not(shared_models), ignore = "needs ../shared/models beside the repository")]`:
/// without the folder they are built ignored, so reaching here without it means it went away
/// after the build.
pub fn models() -> PathBuf {
    let dir = PathBuf::from(env!("SUBTESS_MODELS_DIR"));
    assert!(
        dir.is_dir(),
        "{} is absent: it ships beside the repository, not in it. The tests that need it are \
         ignored when it is absent at build time; after adding or removing it, `touch \
         runtime/build.rs` so that they are rebuilt",
        dir.display()
    );
    dir
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
        .filter(|&&h| h != subtess::mesh::topology::NONE)
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

/// The distinct patch kinds `(valence, region)` of an isolated mesh, sorted.
pub fn region_kinds(iso: &TriangleIsolation) -> Vec<(u32, u32)> {
    let mut kinds: Vec<(u32, u32)> = iso
        .patches
        .iter()
        .map(|p| (p.kind.faces, p.kind.sector))
        .collect();
    kinds.sort_unstable();
    kinds.dedup();
    kinds
}

/// A vertex normal of a fine mesh: the area-weighted average of the normals of the triangles
/// around it (their cross products summed).
pub fn ring_normal(mesh: &Mesh, v: usize) -> [f64; 3] {
    let p = &mesh.positions;
    let mut sum = [0.0; 3];
    for h in mesh.fan(v) {
        let (a, b) = (mesh.head(h) as usize, mesh.head(mesh.next(h)) as usize);
        let (e, f) = (
            [0, 1, 2].map(|c| p[a][c] - p[v][c]),
            [0, 1, 2].map(|c| p[b][c] - p[v][c]),
        );
        let n = [
            e[1] * f[2] - e[2] * f[1],
            e[2] * f[0] - e[0] * f[2],
            e[0] * f[1] - e[1] * f[0],
        ];
        sum = [0, 1, 2].map(|c| sum[c] + n[c]);
    }
    let length = sum.iter().map(|c| c * c).sum::<f64>().sqrt();
    sum.map(|c| c / length)
}

/// The vertex one whole-mesh step of `split` puts on the edge `(v, e)` nearest `v`
/// (`subtess::scheme::triangle::split`'s numbering: the midpoint, or the third nearer `v`).
pub fn next_on_edge(split: Split, coarse: &Mesh, v: u32, e: u32) -> u32 {
    let edges = TriangleSplit::new(coarse).edges;
    let i = edges
        .iter()
        .position(|&[a, b]| (a, b) == (v, e) || (a, b) == (e, v))
        .expect("V's edge");
    let n = coarse.positions.len();
    (match split {
        Split::Dyadic => n + i,
        Split::Ternary => n + 2 * i + usize::from(edges[i][0] != v),
    }) as u32
}

/// The gathered layouts of a region scheme are the right vertices, in the right order and
/// rotation: the level-`L` points a region's rows make from its layout (`schemes::cone_regions`,
/// built from the scheme's rules on the cone) equal the vertices that `L` more whole-mesh steps
/// of the runtime put there, named by a cone chart of the refined mesh. For the corner region the
/// rows are `A`'s (level 1, the layout's own points); for the others their tiles' points. Up to
/// three triangles of every patch kind are checked, and every kind at least once.
pub fn check_region_layouts(name: &str, scheme: RegionScheme, iso: &TriangleIsolation) {
    let rules = TriangleScheme::by_name(scheme.name()).expect("catalogued");
    let mut levels = vec![iso.mesh.clone()];
    for _ in 0..2 {
        let next = scheme.refine(&levels[levels.len() - 1]).expect("refines");
        levels.push(next);
    }
    let mut catalogue: HashMap<u32, ConeRegions> = HashMap::new();
    let mut checked = HashMap::new();
    let size = 1.0
        + iso
            .mesh
            .positions
            .iter()
            .flatten()
            .fold(0.0f64, |m, c| m.max(c.abs()));
    for (f, patch) in iso.patches.iter().enumerate() {
        let k = patch.kind.faces;
        let r = patch.kind.sector as usize;
        if *checked.entry((k, r)).or_insert(0) >= 3 {
            continue;
        }
        let regions = catalogue
            .entry(k)
            .or_insert_with(|| ConeRegions::new(&rules, k).expect("regions"));
        let region = &regions.regions[r];
        let (level, points, rows): (usize, Vec<TrianglePoint>, &Vec<Vec<f64>>) = if r == 0 {
            (1, region.layout.clone(), &regions.corner.a)
        } else {
            let points = region
                .regular_points
                .iter()
                .map(|&(a, b)| canonical_triangle_point(k, 0, a, b))
                .collect();
            (region.tile_level as usize, points, &region.regular_rows)
        };
        assert!(
            level < levels.len(),
            "{name}: region {r} at tile level {level}"
        );
        let at = |q: TrianglePoint| {
            let i = region.layout.iter().position(|&p| p == q);
            i.map(|i| patch.points[i]).unwrap_or_else(|| {
                panic!("{name}: region {r} at valence {k} lacks {q:?} in its layout")
            })
        };
        let v = at(TrianglePoint::Centre);
        let mut e = at(TrianglePoint::Sector { s: 0, a: 1, b: 0 });
        for coarse in &levels[..level] {
            e = next_on_edge(scheme.split(), coarse, v, e);
        }
        let refined = &levels[level];
        let radius = points
            .iter()
            .map(|p| match *p {
                TrianglePoint::Centre => 0,
                TrianglePoint::Sector { a, b, .. } => a + b,
            })
            .max()
            .unwrap_or(1);
        let chart = ConeChart::new(refined, v, e, radius).expect("a regular cone around V");
        for (p, row) in points.iter().zip(rows) {
            let w = chart.vertex(*p, 0).expect("within the chart");
            let expect = refined.positions[w as usize];
            let got = row
                .iter()
                .zip(&patch.points)
                .fold([0.0; 3], |acc, (x, &c)| {
                    let q = iso.mesh.positions[c as usize];
                    [0, 1, 2].map(|i| acc[i] + x * q[i])
                });
            for i in 0..3 {
                assert!(
                    (got[i] - expect[i]).abs() < 1e-12 * size,
                    "{name}: triangle {f}, valence {k}, region {r}, point {p:?}: {got:?} != {expect:?}"
                );
            }
        }
        *checked.get_mut(&(k, r)).expect("counted") += 1;
    }
    let mut kinds: Vec<(u32, u32)> = checked.keys().map(|&(k, r)| (k, r as u32)).collect();
    kinds.sort_unstable();
    assert_eq!(
        kinds,
        region_kinds(iso),
        "{name}: every patch kind is checked"
    );
}

/// Per-face `rates` give an oriented manifold with the input's Euler characteristic, whatever
/// the neighbouring rates and patch kinds.
pub fn check_rates_give_a_manifold(
    table: &StencilTable,
    name: &str,
    iso: &TriangleIsolation,
    rates: &[u32],
) {
    let grid = TriangleDualGrid::new(table, &iso.mesh, &iso.patches, rates)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let out = grid.tessellate(&iso.mesh);
    check_topology(&iso.mesh, &out, name);
}

/// The length of the bounding box diagonal of `mesh`.
pub fn diagonal(mesh: &Mesh) -> f64 {
    let (mut low, mut high) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &mesh.positions {
        for c in 0..3 {
            low[c] = low[c].min(p[c]);
            high[c] = high[c].max(p[c]);
        }
    }
    (0..3)
        .map(|c| (high[c] - low[c]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Distance from `p` to the segment `ab`.
pub fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab: Vec<f64> = (0..3).map(|c| b[c] - a[c]).collect();
    let ap: Vec<f64> = (0..3).map(|c| p[c] - a[c]).collect();
    let len2: f64 = ab.iter().map(|x| x * x).sum();
    let t = if len2 > 0.0 {
        (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|c| (ap[c] - t * ab[c]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Distance from `p` to a triangle, written independently of the library's: the distance to
/// the plane when the projection falls inside (same-side tests), else the nearest edge.
pub fn triangle_distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let normal = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let area2 = dot(normal, normal);
    let edges = || {
        (0..3)
            .map(|k| segment_distance(p, t[k], t[(k + 1) % 3]))
            .fold(f64::INFINITY, f64::min)
    };
    if area2 == 0.0 {
        return edges();
    }
    let inside = (0..3).all(|k| {
        let e = sub(t[(k + 1) % 3], t[k]);
        dot(cross(e, sub(p, t[k])), normal) >= 0.0
    });
    if inside {
        dot(sub(p, t[0]), normal).abs() / area2.sqrt()
    } else {
        edges()
    }
}

/// The largest distance from the points to the nearest triangle of `out`, by brute force
/// (every triangle is considered; a bounding-sphere bound only skips the exact test for
/// triangles that cannot be nearer than one already found).
pub fn brute_force_deviation(points: &[[f64; 3]], out: &TriangleMesh) -> f64 {
    let triangles: Vec<[[f64; 3]; 3]> = out
        .triangles
        .iter()
        .map(|t| t.map(|i| out.positions[i as usize].map(f64::from)))
        .collect();
    let spheres: Vec<([f64; 3], f64)> = triangles
        .iter()
        .map(|t| {
            let c = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
            let r = t
                .iter()
                .map(|p| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            (c, r)
        })
        .collect();
    let centre_distance =
        |p: [f64; 3], c: [f64; 3]| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt();
    points
        .iter()
        .map(|&p| {
            // An upper bound first (the farthest point of the nearest sphere), then exact
            // distances for every triangle whose sphere comes nearer than the bound.
            let mut best = spheres
                .iter()
                .map(|&(c, r)| centre_distance(p, c) + r)
                .fold(f64::INFINITY, f64::min);
            for (t, &(c, r)) in triangles.iter().zip(&spheres) {
                if centre_distance(p, c) - r <= best {
                    best = best.min(triangle_distance(p, *t));
                }
            }
            best
        })
        .fold(0.0, f64::max)
}

/// The largest angle between the output's normals and the ring normals of the finer mesh `fine`
/// at the vertices `locate` names for them (`None`: not compared). The shapes are convex around
/// the origin, so every normal must also point outwards.
pub fn worst_normal_angle(
    name: &str,
    out: &TriangleMesh,
    fine: &Mesh,
    locate: impl Fn(&VertexSource) -> Option<u32>,
) -> f64 {
    let mut worst = 0.0f64;
    for ((p, n), s) in out.positions.iter().zip(&out.normals).zip(&out.sources) {
        let n = n.map(f64::from);
        let outwards: f64 = (0..3).map(|c| n[c] * f64::from(p[c])).sum();
        assert!(outwards > 0.0, "{name}: an inward normal at {p:?}");
        if let Some(w) = locate(s) {
            let reference = ring_normal(fine, w as usize);
            let cos: f64 = (0..3).map(|c| n[c] * reference[c]).sum();
            worst = worst.max(cos.clamp(-1.0, 1.0).acos());
        }
    }
    println!("{name}: worst normal angle {worst:.2e} rad");
    worst
}

/// Spot isolated by `scheme` in `steps` steps, at rates 1 and 2 alternating in runs of odd
/// lengths (so that neighbours differ), tessellates to a closed manifold. Needs `../shared`.
pub fn check_spot_at_mixed_rates(scheme: RegionScheme, table: &StencilTable, steps: usize) {
    let m = load(&models().join("crane/spot_triangulated.obj"));
    let iso = subtess::scheme::region_isolate::isolate_regions(&m, scheme)
        .unwrap_or_else(|e| panic!("spot: {e}"));
    assert_eq!(iso.steps, steps);
    let rates: Vec<u32> = (0..iso.mesh.faces())
        .map(|f| 1 + ((f / 7) % 2) as u32)
        .collect();
    check_rates_give_a_manifold(table, "spot", &iso, &rates);
}
