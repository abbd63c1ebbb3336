//! Butterfly meshes end to end: isolation, the region patches and their layouts, and (with the
//! butterfly table) the tessellation.

mod common;

use std::collections::HashMap;

use runtime::butterfly_isolate::isolate_butterfly;
use runtime::butterfly_refine::butterfly_refine;
use runtime::cone_chart::ConeChart;
use runtime::topology::Mesh;
use runtime::triangle_isolation::TriangleIsolation;
use schemes::butterfly_regions::ButterflyRegions;
use schemes::triangle_local::{canonical_triangle_point, TrianglePoint};
use schemes::TriangleScheme;

use common::{icosahedron, load, models, octahedron, tetrahedron, torus};

fn regions_of(iso: &TriangleIsolation) -> Vec<(u32, u32)> {
    let mut kinds: Vec<(u32, u32)> = iso
        .patches
        .iter()
        .map(|p| (p.kind.faces, p.kind.sector))
        .collect();
    kinds.sort_unstable();
    kinds.dedup();
    kinds
}

#[test]
fn isolation_separates_the_extraordinary_vertices() {
    let cases: Vec<(&str, Mesh)> = vec![
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
        ("torus", torus(12, 12)),
    ];
    for (name, m) in cases {
        let iso = isolate_butterfly(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        println!(
            "{name}: {} steps, {} triangles, patches {:?}",
            iso.steps,
            iso.mesh.faces(),
            regions_of(&iso)
        );
    }
}

#[test]
fn spot_isolates() {
    let Some(dir) = models() else { return };
    let m = load(&dir.join("crane/spot_triangulated.obj"));
    let iso = isolate_butterfly(&m).unwrap_or_else(|e| panic!("spot: {e}"));
    println!(
        "spot: {} steps, {} triangles, {} kinds",
        iso.steps,
        iso.mesh.faces(),
        regions_of(&iso).len()
    );
}

/// The gathered layouts are the right vertices, in the right order and rotation: the level-`L`
/// points a region's rows make from its layout (`schemes::butterfly_regions`, built from the
/// scheme's rules on the cone) equal the vertices that `L` more whole-mesh butterfly steps of
/// the runtime put there, named by a cone chart of the refined mesh. For the corner region the
/// rows are `A`'s (level 1, the layout's own points); for the others their tiles' points.
fn check_layouts_against_refinement(name: &str, iso: &TriangleIsolation) {
    let scheme = TriangleScheme::by_name("butterfly").expect("catalogued");
    let mut levels = vec![(iso.mesh.clone(), Vec::new())];
    for _ in 0..2 {
        let r = butterfly_refine(&levels[levels.len() - 1].0).expect("refines");
        levels.push((r.mesh, r.edges));
    }
    let mut catalogue: HashMap<u32, ButterflyRegions> = HashMap::new();
    let mut checked = HashMap::new();
    for (f, patch) in iso.patches.iter().enumerate() {
        let k = patch.kind.faces;
        let r = patch.kind.sector as usize;
        if *checked.entry((k, r)).or_insert(0) >= 3 {
            continue;
        }
        let regions = catalogue
            .entry(k)
            .or_insert_with(|| ButterflyRegions::new(&scheme, k).expect("regions"));
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
        if level >= levels.len() {
            continue;
        }
        let at = |q: TrianglePoint| {
            let i = region.layout.iter().position(|&p| p == q);
            i.map(|i| patch.points[i]).unwrap_or_else(|| {
                panic!("{name}: region {r} at valence {k} lacks {q:?} in its layout")
            })
        };
        let v = at(TrianglePoint::Centre);
        let mut e = at(TrianglePoint::Sector { s: 0, a: 1, b: 0 });
        for l in 1..=level {
            let (previous, edges) = (&levels[l - 1].0, &levels[l].1);
            let i = edges
                .iter()
                .position(|&[a, b]| (a, b) == (v, e) || (a, b) == (e, v))
                .expect("V's edge");
            e = (previous.positions.len() + i) as u32;
        }
        let refined = &levels[level].0;
        let radius = points
            .iter()
            .map(|p| match *p {
                TrianglePoint::Centre => 0,
                TrianglePoint::Sector { a, b, .. } => a + b,
            })
            .max()
            .unwrap_or(1);
        let chart = ConeChart::new(refined, v, e, radius).expect("a regular cone around V");
        let scale = 1.0
            + iso
                .mesh
                .positions
                .iter()
                .flatten()
                .fold(0.0f64, |m, c| m.max(c.abs()));
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
                    (got[i] - expect[i]).abs() < 1e-12 * scale,
                    "{name}: triangle {f}, valence {k}, region {r}, point {p:?}: {got:?} != {expect:?}"
                );
            }
        }
        *checked.get_mut(&(k, r)).expect("counted") += 1;
    }
    for ((k, r), n) in &checked {
        assert!(*n > 0, "{name}: valence {k} region {r} unchecked");
    }
}

#[test]
fn gathered_layouts_match_whole_mesh_refinement() {
    for (name, m) in [
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
    ] {
        let iso = isolate_butterfly(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_layouts_against_refinement(name, &iso);
    }
}

#[test]
#[ignore]
fn time_spot_isolation() {
    let Some(dir) = models() else { return };
    let m = load(&dir.join("crane/spot_triangulated.obj"));
    let t = std::time::Instant::now();
    let iso = isolate_butterfly(&m).unwrap_or_else(|e| panic!("spot: {e}"));
    println!("isolate {:?}", t.elapsed());
    let t = std::time::Instant::now();
    let _ = butterfly_refine(&iso.mesh).expect("refines");
    println!("one refinement of the isolated mesh {:?}", t.elapsed());
}
