//! Which table patch of a region scheme (the butterfly, √3) evaluates a triangle, and its
//! control points in the table's order.
//!
//! The regular basis functions of the butterfly and of √3 (two steps) have supports wider than
//! a one-ring (radius 3 and 2.5 in lattice units), so an extraordinary vertex `V` of valence
//! `K` shapes not only its own `K` triangles but every triangle `T` with `V` in `T + int H`
//! (`H` the support): the **regions** of `schemes::cone_regions` (`schemes::butterfly_regions`,
//! `schemes::sqrt3_regions`), for both schemes the same nine per sector (the corner triangle,
//! three in the next band, five in the one after), each a table patch of its own: section key
//! `faces = K`, `sector = region`, with the region's layout in `V`'s cone coordinates
//! ([`crate::scheme::triangle::cone_chart`]). The same region in sector `s` around `V` reads every layout point
//! `(a, b)_t` as `(a, b)_{t + s}`. A triangle in no region is the regular patch: region 0 at
//! valence 6 around its corner 0.
//!
//! A triangle is a patch when
//! * it lies in the regions of at most one extraordinary vertex, and
//! * its layout holds no other extraordinary vertex (the rules the table was made with are the
//!   regular ones everywhere but at `V`).
//!
//! [`crate::scheme::region_isolate`] refines until that holds. A region's frame puts its first corner
//! at patch `(0,0)`: the patch's `corner` is the face corner that is the region's first.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use rayon::prelude::*;
use schemes::cone_regions::ConeRegions;
use schemes::triangle_local::{canonical_triangle_point, TrianglePoint};

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::neighbours;
use crate::scheme::patch::PatchKind;
use crate::scheme::triangle::cone_chart::{ConeChart, ConeCharts};
use crate::scheme::triangle::lattice_walk::LatticeWalk;
use crate::scheme::triangle::patch::TrianglePatch;
use crate::{MeshError, RuntimeError};

/// A triangle scheme whose extraordinary vertices shape nine regions per sector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegionScheme {
    /// The modified butterfly (Zorin, Schröder and Sweldens 1996), dyadic.
    Butterfly,
    /// √3 (Kobbelt 2000), two steps as one ternary step.
    Sqrt3,
}

impl RegionScheme {
    /// The scheme's name in `schemes::TriangleScheme` and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RegionScheme::Butterfly => "butterfly",
            RegionScheme::Sqrt3 => "sqrt3",
        }
    }

    /// The regions of an interior vertex of valence `k` ([`ConeRegions`]), built once per
    /// process and shared with a compact table's expansion
    /// ([`crate::stencil_table::cone_regions`]).
    pub(crate) fn cone_regions(self, k: u32) -> Result<Arc<ConeRegions>, RuntimeError> {
        crate::stencil_table::cone_regions(self.name(), k)
    }

    /// The regions of an interior vertex of valence `k`: every region's corners and layout.
    fn shapes(self, k: u32) -> Result<Vec<RegionShape>, RuntimeError> {
        Ok(self
            .cone_regions(k)?
            .regions
            .iter()
            .map(|r| RegionShape {
                corners: r.triangle.corners(),
                layout: r.layout.clone(),
            })
            .collect())
    }
}

/// The regions of every valence a mesh has: corners in sector-0 chart coordinates and layouts.
#[derive(Clone, Debug)]
pub struct RegionCatalogue {
    by_valence: BTreeMap<u32, Vec<RegionShape>>,
}

/// What the runtime needs of one region: its corners and its layout.
#[derive(Clone, Debug)]
struct RegionShape {
    corners: [(i64, i64); 3],
    layout: Vec<TrianglePoint>,
}

/// The graph distance from `V` that a layout reaches.
fn reach(layout: &[TrianglePoint]) -> i64 {
    layout
        .iter()
        .map(|p| match *p {
            TrianglePoint::Centre => 0,
            TrianglePoint::Sector { a, b, .. } => a + b,
        })
        .max()
        .unwrap_or(0)
}

impl RegionCatalogue {
    /// The regions of `scheme` at the valences in `valences` (and 6, the regular patch's).
    pub fn new(
        scheme: RegionScheme,
        valences: impl IntoIterator<Item = u32>,
    ) -> Result<Self, RuntimeError> {
        let mut by_valence = BTreeMap::new();
        for k in valences.into_iter().chain([6]) {
            if let std::collections::btree_map::Entry::Vacant(slot) = by_valence.entry(k) {
                slot.insert(scheme.shapes(k)?);
            }
        }
        Ok(RegionCatalogue { by_valence })
    }

    fn regions(&self, valence: u32) -> Option<&[RegionShape]> {
        self.by_valence.get(&valence).map(Vec::as_slice)
    }
}

/// The half-edge `a -> b`, if there is one.
fn halfedge(mesh: &Mesh, a: u32, b: u32) -> Option<usize> {
    mesh.fan(a as usize)
        .into_iter()
        .find(|&h| mesh.head(h) == b)
}

/// The layout's vertices, `V`'s chart read `rotation` sectors on; every point but the centre
/// must be regular.
fn gather(
    chart: &ConeChart,
    layout: &[TrianglePoint],
    rotation: u32,
    valence: &[usize],
) -> Result<Vec<u32>, String> {
    layout
        .iter()
        .map(|&p| {
            let v = chart
                .vertex(p, rotation)
                .ok_or_else(|| format!("its layout point {p:?} is beyond the mesh's chart"))?;
            if p != TrianglePoint::Centre && valence[v as usize] != 6 {
                return Err(format!(
                    "its layout holds vertex {v} of valence {} besides the patch's own \
                     extraordinary vertex",
                    valence[v as usize]
                ));
            }
            Ok(v)
        })
        .collect()
}

/// The patch of every triangle of a triangle mesh, or the first triangle that is not one yet
/// (see the module docs). `claimed` holds the patches found before (√3's boundary patches,
/// one per triangle, `None` elsewhere); a region may not hold one of them.
pub fn gather_region_patches(
    mesh: &Mesh,
    catalogue: &RegionCatalogue,
    claimed: Vec<Option<TrianglePatch>>,
) -> Result<Vec<TrianglePatch>, RuntimeError> {
    let valence = mesh.valences();
    if claimed.len() != mesh.faces() {
        return Err(RuntimeError::Unsupported(format!(
            "{} claimed patches for {} triangles",
            claimed.len(),
            mesh.faces()
        )));
    }
    let mut patches = claimed;
    // The extraordinary vertex whose region every claimed triangle is.
    let mut owner: Vec<u32> = vec![u32::MAX; mesh.faces()];
    let mut charts = ConeCharts::new(mesh);
    let not_isolated = |face: usize, reason: String| MeshError::NotIsolated { face, reason };
    for v in 0..mesh.positions.len() {
        // A boundary vertex's triangles are boundary patches (or refused with the boundary).
        if valence[v] == 6 || valence[v] == 0 || mesh.is_boundary_vertex(v) {
            continue;
        }
        let k = valence[v] as u32;
        let first_face = mesh.face_of[mesh.fan(v)[0]] as usize;
        let regions = catalogue.regions(k).ok_or_else(|| {
            not_isolated(
                first_face,
                format!("its corner {v} has valence {k}, which the region catalogue lacks"),
            )
        })?;
        let radius = regions.iter().map(|r| reach(&r.layout)).max().unwrap_or(1);
        let first = neighbours(mesh, v)[0];
        let chart = charts
            .chart(mesh, v as u32, first, radius)
            .map_err(|e| not_isolated(first_face, format!("around vertex {v}: {e}")))?;
        for s in 0..k {
            for (r, region) in regions.iter().enumerate() {
                let corners = region
                    .corners
                    .map(|(a, b)| chart.vertex(canonical_triangle_point(k, 0, a, b), s));
                let [Some(c0), Some(c1), Some(c2)] = corners else {
                    return Err(not_isolated(
                        first_face,
                        format!("region {r} of vertex {v} is beyond its chart"),
                    )
                    .into());
                };
                let h = halfedge(mesh, c0, c1)
                    .filter(|&h| mesh.head(mesh.next(h)) == c2)
                    .ok_or_else(|| {
                        not_isolated(
                            first_face,
                            format!("region {r} of vertex {v} is not a triangle of the mesh"),
                        )
                    })?;
                let f = mesh.face_of[h] as usize;
                if patches[f].is_some() {
                    let reason = if owner[f] == u32::MAX {
                        format!("it lies in the regions of vertex {v} and beside the boundary")
                    } else if owner[f] == v as u32 {
                        format!("it is two regions of vertex {v}: the mesh closes on itself there")
                    } else {
                        format!(
                            "it lies in the regions of two extraordinary vertices, {} and {v}",
                            owner[f]
                        )
                    };
                    return Err(not_isolated(f, reason).into());
                }
                owner[f] = v as u32;
                let points =
                    gather(&chart, &region.layout, s, &valence).map_err(|e| not_isolated(f, e))?;
                patches[f] = Some(TrianglePatch {
                    kind: PatchKind {
                        boundary: false,
                        feature: table_format::Feature::None,
                        faces: k,
                        sector: r as u32,
                    },
                    points,
                    corner: h - mesh.face_halfedges(f).start,
                });
            }
        }
    }
    let regular = catalogue
        .regions(6)
        .and_then(|r| r.first())
        .ok_or_else(|| RuntimeError::Unsupported("no regular region".into()))?;
    let regular = RegularLayout::new(&regular.layout);
    let interior_regular = interior_regular(mesh, &valence);
    let regular_patch =
        |scratch: &mut RegularScratch, f: usize| -> Result<TrianglePatch, RuntimeError> {
            let points = match regular.by_walk(mesh, &interior_regular, &mut scratch.halfedges, f) {
                Some(points) => points,
                None => {
                    let charts = scratch.charts.get_or_insert_with(|| ConeCharts::new(mesh));
                    regular.by_chart(mesh, &valence, charts, f)?
                }
            };
            Ok(TrianglePatch {
                kind: PatchKind {
                    boundary: false,
                    feature: table_format::Feature::None,
                    faces: 6,
                    sector: 0,
                },
                points,
                corner: 0,
            })
        };
    // The regular triangles, most of the mesh, filled in place in one chunk per thread, each
    // with its own scratch space; the first failing chunk's first error, as a sequential pass
    // would report.
    let chunk = mesh.faces().div_ceil(rayon::current_num_threads()).max(1);
    let chunks: Vec<Result<(), RuntimeError>> = patches
        .par_chunks_mut(chunk)
        .enumerate()
        .map(|(c, slice)| {
            let mut scratch = RegularScratch::default();
            slice.iter_mut().enumerate().try_for_each(|(i, patch)| {
                if patch.is_none() {
                    *patch = Some(regular_patch(&mut scratch, c * chunk + i)?);
                }
                Ok(())
            })
        })
        .collect();
    for c in chunks {
        c?;
    }
    // Every triangle has its patch now.
    Ok(patches.into_iter().flatten().collect())
}

/// Whether every vertex is interior of valence 6 (a vertex is on the boundary where an edge
/// leaving it is).
fn interior_regular(mesh: &Mesh, valence: &[usize]) -> Vec<bool> {
    let mut regular: Vec<bool> = valence.iter().map(|&k| k == 6).collect();
    for (h, &t) in mesh.twin.iter().enumerate() {
        if t == NONE {
            regular[mesh.face_vertices[h] as usize] = false;
        }
    }
    regular
}

/// The regular patch's layout and the two ways to find its vertices around a triangle.
struct RegularLayout<'a> {
    layout: &'a [TrianglePoint],
    within: BTreeSet<TrianglePoint>,
    radius: i64,
    walk: Option<LatticeWalk>,
}

impl<'a> RegularLayout<'a> {
    fn new(layout: &'a [TrianglePoint]) -> Self {
        RegularLayout {
            layout,
            within: layout.iter().copied().collect(),
            radius: reach(layout),
            walk: LatticeWalk::new(layout),
        }
    }

    /// The layout's vertices by the chart of corner 0 grown only through the layout: the
    /// reference, and the reason where triangle `f` is not a regular patch.
    fn by_chart(
        &self,
        mesh: &Mesh,
        valence: &[usize],
        charts: &mut ConeCharts,
        f: usize,
    ) -> Result<Vec<u32>, MeshError> {
        let not_isolated = |reason: String| MeshError::NotIsolated { face: f, reason };
        let corners = mesh.face(f);
        let chart = charts
            .chart_within(mesh, corners[0], corners[1], self.radius, |p| {
                self.within.contains(&p)
            })
            .map_err(not_isolated)?;
        if chart.valence != 6 {
            return Err(not_isolated(format!(
                "its corner {} has valence {} but the triangle is in none of its regions",
                corners[0], chart.valence
            )));
        }
        gather(&chart, self.layout, 0, valence).map_err(not_isolated)
    }

    /// The layout's vertices by a walk ([`LatticeWalk`]), where it vouches for the chart's
    /// answer (`None` elsewhere).
    fn by_walk(
        &self,
        mesh: &Mesh,
        interior_regular: &[bool],
        halfedges: &mut Vec<usize>,
        f: usize,
    ) -> Option<Vec<u32>> {
        let walk = self.walk.as_ref()?;
        let mut points = Vec::with_capacity(self.layout.len());
        let start = mesh.face_halfedges(f).start;
        walk.walk(mesh, start, interior_regular, halfedges, &mut points)
            .then_some(points)
    }
}

/// What the regular patches of one thread reuse: the walk's half-edges, and chart scratch
/// space, made only when a walk cannot answer.
#[derive(Default)]
struct RegularScratch {
    halfedges: Vec<usize>,
    charts: Option<ConeCharts>,
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::io::obj::read_obj;
    use crate::mesh::test_meshes::{lattice_torus, octahedron, tetrahedron};

    /// On every triangle of `mesh` the walk answers exactly where the chart finds a regular
    /// patch, with the same vertices in the same order; the number of triangles it answers.
    fn walk_agrees_with_chart(name: &str, mesh: &Mesh, scheme: RegionScheme) -> usize {
        let catalogue = RegionCatalogue::new(scheme, [6]).expect("the regular region");
        let regions = catalogue.regions(6).expect("valence 6");
        let regular = RegularLayout::new(&regions[0].layout);
        assert!(regular.walk.is_some(), "the layout is a disc of triangles");
        let valence = mesh.valences();
        let interior_regular = interior_regular(mesh, &valence);
        let mut charts = ConeCharts::new(mesh);
        let mut halfedges = Vec::new();
        let mut walked = 0;
        for f in 0..mesh.faces() {
            let chart = regular.by_chart(mesh, &valence, &mut charts, f).ok();
            let walk = regular.by_walk(mesh, &interior_regular, &mut halfedges, f);
            assert_eq!(walk, chart, "{name} ({}), face {f}", scheme.name());
            walked += usize::from(walk.is_some());
        }
        walked
    }

    /// Every mesh of `steps + 1` levels of `scheme`'s refinement of `mesh`: failed isolation
    /// attempts (charts that leave the mesh or wrap around an extraordinary vertex) and
    /// successful ones. The number of triangles the walk answers on the finest.
    fn levels_agree(name: &str, mesh: &Mesh, scheme: RegionScheme, steps: usize) -> usize {
        let mut mesh = mesh.clone();
        for _ in 0..steps {
            walk_agrees_with_chart(name, &mesh, scheme);
            mesh = scheme
                .refine(&mesh)
                .expect("a closed triangle mesh refines");
        }
        walk_agrees_with_chart(name, &mesh, scheme)
    }

    #[test]
    fn the_walk_finds_what_the_chart_finds() {
        let torus = lattice_torus(8, |a, b| [a as f64, b as f64, 0.0]);
        for scheme in [RegionScheme::Butterfly, RegionScheme::Sqrt3] {
            assert_eq!(
                walk_agrees_with_chart("torus", &torus, scheme),
                torus.faces()
            );
            // Valence 3 (a chart wraps around it within its layout until it is far enough)
            // and 4.
            let steps = match scheme {
                RegionScheme::Butterfly => 4,
                RegionScheme::Sqrt3 => 2,
            };
            assert!(levels_agree("tetrahedron", &tetrahedron(), scheme, steps) > 0);
            assert!(levels_agree("octahedron", &octahedron(), scheme, steps) > 0);
        }
    }

    /// Spot (valences 4, 5, 7 and 8) through its isolation: three butterfly steps, two ternary
    /// √3 steps.
    #[test]
    fn on_spot_the_walk_finds_what_the_chart_finds() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/models/crane/spot_triangulated.obj");
        if !path.is_file() {
            println!("skipping: {} is absent", path.display());
            return;
        }
        let obj = read_obj(&path).expect("Spot reads");
        let (spot, _) = Mesh::from_obj(&obj).expect("Spot is a valid mesh");
        for (scheme, steps) in [(RegionScheme::Butterfly, 3), (RegionScheme::Sqrt3, 2)] {
            assert!(levels_agree("Spot", &spot, scheme, steps) > 0);
        }
    }
}
