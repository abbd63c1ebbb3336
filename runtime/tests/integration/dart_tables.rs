//! Dart patches of the default table (docs/algorithms/extraordinary-stencils.md, "Darts")
//! against feature-adaptive refinement (docs/algorithms/sharp-features.md), an independent
//! route: the table's stencils come from the scaling relation of `Neighbourhood::dart`'s local
//! subdivision matrices, the adaptive ones from refining the mesh itself with the crease rules
//! (`refine.rs`, checked against Pixar's Hbr) until the point lies in a B-spline patch. At every
//! dual point of every face that takes a dart patch, the positions agree to 1e-6 of the mesh's
//! size and the normals to 1e-5 rad.

use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::adaptive::{limit_of, limit_stencils, LimitQuery};
use subtess::scheme::catmull_clark::isolate::isolate;
use subtess::scheme::catmull_clark::refine::refine;
use subtess::scheme::patch::{dual_index_in_patch, table_dart, FacePatch};
use subtess::stencil_table::StencilTable;
use subtess::{Rates, Scheme, Surface};
use table_format::{Feature, PointSet, SectionKey, StencilKind};

type Point = [f64; 3];

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: Point, b: Point) -> Point {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: Point) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn unit(a: Point) -> Point {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The diagonal of the mesh's bounding box.
fn size(mesh: &Mesh) -> f64 {
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        });
    norm(sub(hi, lo))
}

/// The table's dual-grid stencils of `kind` for `patch` at rate `n`, applied at the face's dual
/// point `(i, j)` (its own indices; the table's are the patch's rotation of them).
fn table_at(
    table: &StencilTable,
    mesh: &Mesh,
    patch: &FacePatch,
    kind: StencilKind,
    n: u32,
    (i, j): (usize, usize),
) -> Point {
    let key = SectionKey {
        kind,
        points: PointSet::Dual,
        boundary: patch.kind.boundary,
        feature: patch.kind.feature,
        faces: patch.kind.faces,
        sector: patch.kind.sector,
        n,
    };
    let weights = table.weights(&key).unwrap_or_else(|e| panic!("{key}: {e}"));
    let k = patch.points.len();
    let nu = n as usize;
    let (pi, pj) = dual_index_in_patch(patch.corner, i, j, nu);
    let row = &weights[(pj * nu + pi) * k..][..k];
    let mut p = [0.0; 3];
    for (w, &v) in row.iter().zip(&patch.points) {
        let q = mesh.positions[v as usize];
        for c in 0..3 {
            p[c] += f64::from(*w) * q[c];
        }
    }
    p
}

/// What one comparison covered and the largest differences it met.
#[derive(Debug, Default)]
struct Agreement {
    /// `(valence, sector)` of every dart patch compared.
    kinds: std::collections::BTreeSet<(u32, u32)>,
    /// Faces that took a dart patch, of all faces.
    faces: (usize, usize),
    /// Dual points compared.
    points: usize,
    /// Largest position difference, relative to the mesh's size.
    position: f64,
    /// Largest angle between the normals, radians.
    normal: f64,
}

/// Every face of the isolated `mesh` that takes a dart patch, at rates `rates`: the table's
/// positions and normals against the adaptive ones.
fn compare(name: &str, mesh: &Mesh, rates: &[u32]) -> Agreement {
    let table = StencilTable::default_for(mesh.boundary).expect("embedded table");
    let (mesh, patches, _) = isolate(mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
    let scale = size(&mesh);
    let mut out = Agreement {
        faces: (0, patches.len()),
        ..Agreement::default()
    };
    for (f, patch) in patches.iter().enumerate() {
        if patch.kind.feature != Feature::Dart {
            assert!(table_dart(&mesh, f).is_none(), "{name}: face {f}");
            continue;
        }
        assert!(!mesh.holes[f]);
        out.faces.0 += 1;
        out.kinds.insert((patch.kind.faces, patch.kind.sector));
        for &n in rates {
            let nu = n as usize;
            let dual: Vec<(usize, usize)> =
                (0..nu).flat_map(|j| (0..nu).map(move |i| (i, j))).collect();
            let queries: Vec<LimitQuery> = dual
                .iter()
                .map(|&(i, j)| LimitQuery {
                    face: f as u32,
                    u: (2 * i + 1) as f64 / (2 * nu) as f64,
                    v: (2 * j + 1) as f64 / (2 * nu) as f64,
                })
                .collect();
            let adaptive = limit_stencils(&mesh, &queries).expect("adaptive stencils");
            for (&ij, stencil) in dual.iter().zip(&adaptive) {
                let [position, du, dv] = limit_of(stencil, &mesh);
                let p = table_at(&table, &mesh, patch, StencilKind::Position, n, ij);
                let tu = table_at(&table, &mesh, patch, StencilKind::DerivativeU, n, ij);
                let tv = table_at(&table, &mesh, patch, StencilKind::DerivativeV, n, ij);
                // The patch's frame is a rotation of the face's: the same normal.
                let (a, b) = (unit(cross(du, dv)), unit(cross(tu, tv)));
                let d = norm(sub(p, position)) / scale;
                let angle = 2.0 * (0.5 * norm(sub(a, b))).asin();
                assert!(
                    d <= 1e-6 && angle <= 1e-5,
                    "{name}: face {f} ({:?}, corner {}), n = {n}, dual point {ij:?}: \
                     table {p:?} vs adaptive {position:?} ({d:e} of the size), normals \
                     {angle:e} rad apart",
                    patch.kind,
                    patch.corner
                );
                out.position = out.position.max(d);
                out.normal = out.normal.max(angle);
                out.points += 1;
            }
        }
    }
    out
}

/// A closed `v`-gonal prism, refined twice, with a dart of valence `v` at the centre of its
/// top face: the refined top face's centre (valence `v`) gets one infinitely sharp edge that
/// runs straight on through the next vertex to the side face's centre, where it ends in a
/// second dart, of valence 4. `mirrored` lists every face the other way round (the same
/// surface, the fans turning the other way).
fn dart_prism(v: usize, mirrored: bool) -> Mesh {
    let angle = |i: usize| std::f64::consts::TAU * i as f64 / v as f64;
    let mut positions: Vec<Point> = (0..v)
        .map(|i| [angle(i).cos(), angle(i).sin(), 1.0])
        .collect();
    positions.extend((0..v).map(|i| [angle(i).cos(), angle(i).sin(), -1.0]));
    let v64 = v as i64;
    let mut faces: Vec<Vec<i64>> = vec![(0..v64).collect(), (v64..2 * v64).rev().collect()];
    for i in 0..v64 {
        let j = (i + 1) % v64;
        faces.push(vec![v64 + i, v64 + j, j, i]);
    }
    if mirrored {
        for f in &mut faces {
            f.reverse();
        }
    }
    let mesh = Mesh::new(positions, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("valid");
    let step = refine(&mesh);
    let mut once = step.mesh;
    // The top face (face 0) is the first face point.
    let centre = step.vertex_points + step.edge_points;
    assert_eq!(once.fan(centre).len(), v);
    let first = once.fan(centre)[0];
    let next = once.head(first) as usize;
    let around = once.fan(next);
    let back = around
        .iter()
        .position(|&h| once.head(h) as usize == centre)
        .expect("an edge back");
    let far = once.head(around[(back + 2) % 4]) as usize;
    once.set_edge_sharpness(centre, next, 10.0).expect("edge");
    once.set_edge_sharpness(next, far, 10.0).expect("edge");
    refine(&once).mesh
}

/// Darts of every table valence (3..=8), in both orientations, at rates 1, 2, 3, 5 and 8: every
/// sector of every dart patch, with the valence-4 darts at the crease's other end.
#[test]
#[cfg(feature = "catmull-clark")]
fn dart_patches_equal_adaptive_refinement_on_prisms() {
    let mut kinds = std::collections::BTreeSet::new();
    let (mut points, mut position, mut normal) = (0, 0f64, 0f64);
    for v in 3..=8 {
        for mirrored in [false, true] {
            let a = compare(
                &format!("prism {v}, mirrored {mirrored}"),
                &dart_prism(v, mirrored),
                &[1, 2, 3, 5, 8],
            );
            let sectors = a.kinds.iter().filter(|k| k.0 == v as u32).count();
            assert_eq!(sectors, v, "prism {v}: sectors {:?}", a.kinds);
            kinds.extend(a.kinds);
            points += a.points;
            position = position.max(a.position);
            normal = normal.max(a.normal);
        }
    }
    eprintln!(
        "{} dart patches, {points} dual points: positions within {position:e} of the size, \
         normals within {normal:e} rad",
        kinds.len()
    );
    // Every sector of every valence the table holds.
    assert_eq!(kinds.len(), (3..=8).sum::<usize>());
}

/// OpenSubdiv's shapes with darts, as given and refined once and twice, rates 1, 2, 4, 7: every face the
/// tables take as a dart patch. As given, `catmark_inf_crease0`'s one dart ends a crease one
/// edge long at a corner, beside a crease and the boundary, so none of its faces is a dart patch
/// (they stay adaptive); one step of refinement puts a straight crease vertex beside it, and
/// its four faces become dart patches. `catmark_cubes_infsharp`'s cubes are isolated by
/// refinement, which does the same for its valence-3 dart.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
#[cfg(feature = "catmull-clark")]
fn dart_patches_equal_adaptive_refinement_on_opensubdiv_shapes() {
    for name in ["catmark_inf_crease0.obj", "catmark_cubes_infsharp.obj"] {
        let path = crate::common::models().join("opensubdiv").join(name);
        let obj = read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
        let mesh = Mesh::from_obj(&obj).unwrap_or_else(|e| panic!("{e}")).0;
        let once = refine(&mesh).mesh;
        let twice = refine(&once).mesh;
        for (level, mesh) in [(0, mesh), (1, once), (2, twice)] {
            let a = compare(name, &mesh, &[1, 2, 4, 7]);
            eprintln!(
                "{name}, level {level}: {} of {} faces dart patches {:?}, {} dual points: \
                 positions within {:e} of the size, normals within {:e} rad",
                a.faces.0, a.faces.1, a.kinds, a.points, a.position, a.normal
            );
            let expected = !(level == 0 && name == "catmark_inf_crease0.obj");
            assert_eq!(!a.kinds.is_empty(), expected, "{name}, level {level}");
        }
    }
}

/// A tessellation through the dart patches stays watertight: every edge of the closed prisms'
/// output is shared by exactly two triangles, at rates 1 and 6.
#[test]
#[cfg(feature = "catmull-clark")]
fn dart_patches_tessellate_watertight() {
    for v in [3, 4, 5, 8] {
        let mesh = dart_prism(v, false);
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("surface");
        for rates in [Rates::Uniform(1), Rates::Uniform(6)] {
            let mut tess = surface.tessellator(&rates).expect("plan");
            let frame = tess.evaluate(&mesh.positions_f32()).expect("frame");
            let mut edges = std::collections::HashMap::new();
            for t in frame.triangles() {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            assert!(
                edges.values().all(|&c| c == 2),
                "prism {v}: an edge not shared by exactly two triangles"
            );
        }
    }
}
