//! `TriangleMesh::is_watertight` pairs the inner edges of the faces' grids (quads, or a triangle
//! face's hexagon fans) and of the strips between them by their patterns and groups only the
//! rest (`mesh/watertight/`). The reference is the general check on every
//! directed edge, `boundary_edges` (closed: no directed edge used twice, none without its
//! reverse), on the tessellators' outputs and on those outputs broken in the ways a grid
//! shortcut could miss.

use proptest::prelude::*;
use subtess::{Mesh, Rates, Scheme, Surface, TriangleMesh};

/// The general check: every directed edge once, each with its reverse.
fn closed_by_every_edge(mesh: &TriangleMesh) -> bool {
    mesh.boundary_edges().is_some_and(|b| b.is_empty())
}

fn tessellated(file: &str, rates: Rates) -> TriangleMesh {
    tessellated_by(Scheme::CatmullClark, file, rates)
}

fn tessellated_by(scheme: Scheme, file: &str, rates: Rates) -> TriangleMesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/").to_owned() + file;
    let mesh = Mesh::read_obj(&path).expect("readable");
    let surface = Surface::new(&mesh, scheme).expect("surface");
    let mut tessellator = surface.tessellator(&rates).expect("plan");
    let frame = tessellator.evaluate(&mesh.positions_f32()).expect("frame");
    frame.to_triangle_mesh()
}

/// Both checks agree on `mesh`; returns the answer.
fn agreed(mesh: &TriangleMesh, what: &str) -> bool {
    let expected = closed_by_every_edge(mesh);
    assert_eq!(mesh.is_watertight(), expected, "{what}");
    expected
}

/// `mesh` with a fin on the edge `p q`: two more triangles over it, one each way, to a new
/// vertex (four uses of the edge, closed in themselves).
fn finned(mesh: &TriangleMesh, p: u32, q: u32) -> TriangleMesh {
    let mut mesh = mesh.clone();
    let x = mesh.positions.len() as u32;
    mesh.positions.push([9.0, 9.0, 9.0]);
    mesh.triangles.push([p, q, x]);
    mesh.triangles.push([q, p, x]);
    mesh
}

/// `mesh` with two more triangles on its vertex `v`, to two new vertices, one each way (closed
/// in themselves, and on no edge of the mesh).
#[cfg(feature = "loop")]
fn pinched(mesh: &TriangleMesh, v: u32) -> TriangleMesh {
    let mut mesh = mesh.clone();
    let w = mesh.positions.len() as u32;
    mesh.positions.push([9.0, 9.0, 9.0]);
    mesh.positions.push([9.0, 9.0, 8.0]);
    mesh.triangles.push([v, w, w + 1]);
    mesh.triangles.push([w + 1, w, v]);
    mesh
}

#[test]
#[cfg(feature = "catmull-clark")]
fn tessellations_are_closed_by_both_checks() {
    for n in [1, 2, 3, 8] {
        assert!(agreed(&tessellated("cube.obj", Rates::Uniform(n)), "cube"));
        // Texture seams: vertices split for their coordinates, welded for the check.
        assert!(agreed(
            &tessellated("cube_uv.obj", Rates::Uniform(n)),
            "cube with uvs"
        ));
        assert!(agreed(
            &tessellated("cube_creased.obj", Rates::Uniform(n)),
            "creased"
        ));
    }
    let mixed = Rates::PerFace(vec![1, 2, 3, 5, 8, 13]);
    assert!(agreed(&tessellated("cube.obj", mixed), "mixed rates"));
    // With boundary: not closed, by both.
    assert!(!agreed(&tessellated("disc.obj", Rates::Uniform(4)), "disc"));
}

/// A grid's inner edge used by two more triangles (a fin, closed in itself): four uses of one
/// edge. The grid pairs its own two; only the check of other triangles against the grids'
/// inner edges sees the other two.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_fin_on_a_grid_edge_is_not_closed() {
    let mesh = tessellated("cube.obj", Rates::Uniform(6));
    // The second triangle of the first face's first quad: [a, c, d]; its diagonal a-c is
    // inner to the face's grid.
    let [a, c, _] = mesh.triangles[1];
    assert!(!agreed(&finned(&mesh, a, c), "fin"));
}

/// An inner edge of a strip between two faces' grids (a rung or a diagonal) used by two more
/// triangles: the strip pairs its own two uses; only the test of the other triangles against
/// the strips' inner edges sees the fin.
#[test]
#[cfg(feature = "catmull-clark")]
fn a_fin_on_a_strip_edge_is_not_closed() {
    let clean = tessellated("cube.obj", Rates::Uniform(6));
    // A strip's first quad is `[b_0, a_1, a_0], [b_0, b_1, a_1]`: `b_0 a_1` is a diagonal and
    // `a_1 b_1` a rung (inside the strip, which has two quads at least at this rate). A grid's
    // quads `[a, a + 1, c], [a, c, c - 1]` share their first vertex too, but not `a + 1`.
    let first_strip = (0..clean.triangles.len() - 1)
        .find(|&t| {
            let (x, y) = (clean.triangles[t], clean.triangles[t + 1]);
            x[0] == y[0] && x[1] == y[2]
        })
        .expect("a strip");
    let [b0, a1, _] = clean.triangles[first_strip];
    let [_, b1, _] = clean.triangles[first_strip + 1];
    for (p, q) in [(b0, a1), (a1, b1)] {
        assert!(!agreed(&finned(&clean, p, q), "fin on a strip"));
    }
}

/// Loop's dual grids (hexagon fans in the faces, found as fan blocks), uniform and mixed
/// rates: closed by both checks.
#[test]
#[cfg(feature = "loop")]
fn triangle_tessellations_are_closed_by_both_checks() {
    for n in [1, 2, 3, 4, 8, 13] {
        let mesh = tessellated_by(Scheme::Loop, "octahedron.obj", Rates::Uniform(n));
        assert!(agreed(&mesh, "octahedron"));
    }
    let mixed = Rates::PerFace(vec![1, 3, 4, 5, 8, 13, 2, 6]);
    let mesh = tessellated_by(Scheme::Loop, "octahedron.obj", mixed);
    assert!(agreed(&mesh, "octahedron, mixed rates"));
}

/// A fan block's inner edges, a spoke and a rim between two interior points' hexagons, used
/// by two more triangles: the block pairs its own two uses; only the test of the other
/// triangles against the fan blocks' deep vertices and inner edges sees the fin.
#[test]
#[cfg(feature = "loop")]
fn a_fin_on_a_fan_edge_is_not_closed() {
    let clean = tessellated_by(Scheme::Loop, "octahedron.obj", Rates::Uniform(6));
    // A fan is six triangles `[c, x_r, x_(r+1)]`; the first fan of a face (around its primal
    // point (1, 1)) has the hexagons of (1, 2) and (2, 1) across its rims 0 and 5, inner at
    // this rate.
    let t = (0..clean.triangles.len() - 6)
        .find(|&t| {
            let fan = &clean.triangles[t..t + 6];
            (0..6).all(|r| fan[r][0] == fan[0][0] && fan[r][2] == fan[(r + 1) % 6][1])
        })
        .expect("a fan");
    let [c, x0, x1] = clean.triangles[t];
    for (p, q) in [(c, x0), (x0, x1)] {
        assert!(!agreed(&finned(&clean, p, q), "fin on a fan"));
    }
}

/// A merge strip between two faces' fans (Loop's strips, whatever the two rates): each edge of
/// its first triangles and of one inside it (rungs, row edges paired with the faces' borders,
/// the corner segment, the end rung) used by two more triangles; and a closed pair of
/// triangles on a vertex the strip claims, which leaves the mesh closed (by edges) and sends
/// the check to every edge.
#[test]
#[cfg(feature = "loop")]
fn a_fin_on_a_merge_strip_is_not_closed() {
    for rates in [
        Rates::Uniform(6),
        Rates::PerFace(vec![5, 7, 6, 9, 5, 8, 6, 7]),
    ] {
        let clean = tessellated_by(Scheme::Loop, "octahedron.obj", rates);
        // Consecutive triangles of a strip: the next begins and ends with the first and middle
        // vertices of the last (its row `a` advanced) or with its middle and last.
        let zigzag = |t: usize| {
            let ([x, y, z], next) = (clean.triangles[t], clean.triangles[t + 1]);
            (next[0], next[2]) == (x, y) || (next[0], next[2]) == (y, z)
        };
        // A strip's first triangles (its end rung, the corner segment, the point next to the
        // corner) and one inside it: every edge of them, finned, breaks the mesh.
        let t = (1..clean.triangles.len() - 12)
            .find(|&t| !zigzag(t - 1) && (t..t + 12).all(zigzag))
            .expect("a strip");
        for t in [t, t + 1, t + 2, t + 6] {
            let [x, y, z] = clean.triangles[t];
            for (p, q) in [(x, y), (y, z), (z, x)] {
                assert!(!agreed(&finned(&clean, p, q), "fin on a merge strip"));
            }
        }
        let [_, y, _] = clean.triangles[t + 6];
        assert!(agreed(
            &pinched(&clean, y),
            "two triangles on a strip's vertex"
        ));
    }
}

/// A vertex polygon (Loop's output ends with them, fanned at the limit point of each primal
/// vertex): a fin on a spoke or a rim breaks the mesh; a closed pair of triangles on its centre
/// leaves it closed (by edges), the spokes then checked edge by edge.
#[test]
#[cfg(feature = "loop")]
fn a_fin_on_a_vertex_polygon_is_not_closed() {
    let clean = tessellated_by(Scheme::Loop, "octahedron.obj", Rates::Uniform(5));
    // The last polygon: the triangles at the end around one centre.
    let centre = clean.triangles[clean.triangles.len() - 1][0];
    let m = clean
        .triangles
        .iter()
        .rev()
        .take_while(|t| t[0] == centre)
        .count();
    let fan = &clean.triangles[clean.triangles.len() - m..];
    let closed_fan = (0..m).all(|r| fan[r][2] == fan[(r + 1) % m][1]);
    assert!(m >= 3 && closed_fan, "{fan:?}");
    let [c, x0, x1] = fan[0];
    for (p, q) in [(c, x0), (x0, c), (x0, x1)] {
        assert!(!agreed(&finned(&clean, p, q), "fin on a vertex polygon"));
    }
    assert!(agreed(
        &pinched(&clean, c),
        "two triangles on a polygon's centre"
    ));
}

/// Tessellations long enough that the grid scan runs in pieces (65,536 triangles and more
/// each), a face's grid cut between two of them, with and without texture seams (whose grids go
/// to the general check, from every piece): closed by both checks, and broken by both where a
/// piece ends.
#[test]
#[cfg(feature = "catmull-clark")]
fn tessellations_scanned_in_pieces_agree() {
    for file in ["cube.obj", "cube_uv.obj"] {
        let mesh = tessellated(file, Rates::Uniform(64));
        assert!(
            mesh.triangles.len() > 2 * 65_536,
            "{}",
            mesh.triangles.len()
        );
        assert!(agreed(&mesh, file));
        for t in [65_535, 65_536, 65_537, 131_071, 131_072] {
            let mut removed = mesh.clone();
            removed.triangles.remove(t);
            assert!(!agreed(&removed, file));
            let mut reversed = mesh.clone();
            reversed.triangles[t].swap(1, 2);
            assert!(!agreed(&reversed, file));
        }
    }
}

/// `mesh` with its triangle `pick` (modulo the count) removed (`how` 0), reversed (1),
/// duplicated (2) or moved to other vertices (3).
fn broken(mut mesh: TriangleMesh, pick: usize, how: u8) -> TriangleMesh {
    let t = pick % mesh.triangles.len();
    match how {
        0 => {
            mesh.triangles.remove(t);
        }
        1 => mesh.triangles[t].swap(1, 2),
        2 => {
            let copy = mesh.triangles[t];
            mesh.triangles.push(copy);
        }
        _ => {
            let v = mesh.positions.len() as u32;
            mesh.triangles[t][0] = (mesh.triangles[t][0] + 1) % v;
        }
    }
    mesh
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// One triangle removed, reversed, duplicated or moved to other vertices, with and without
    /// texture seams: both checks say the same.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn broken_tessellations_agree(
        rate in 2u32..13,
        pick in 0usize..10_000,
        how in 0u8..4,
        seams in any::<bool>(),
    ) {
        let file = if seams { "cube_uv.obj" } else { "cube.obj" };
        let mesh = tessellated(file, Rates::Uniform(rate));
        agreed(&broken(mesh, pick, how), "broken");
    }

    /// The same breakages of Loop's dual grids, whose faces' fans the check pairs in place.
    #[test]
    #[cfg(feature = "loop")]
    fn broken_triangle_tessellations_agree(
        rate in 2u32..13,
        pick in 0usize..10_000,
        how in 0u8..4,
    ) {
        let mesh = tessellated_by(Scheme::Loop, "octahedron.obj", Rates::Uniform(rate));
        agreed(&broken(mesh, pick, how), "broken");
    }
}
