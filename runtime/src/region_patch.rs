//! Which table patch of a region scheme (the butterfly, √3) evaluates a triangle, and its
//! control points in the table's order.
//!
//! The regular basis functions of the butterfly and of √3 (two steps) have supports wider than
//! a one-ring (radius 3 and 2.5 in lattice units), so an extraordinary vertex `V` of valence
//! `K` shapes not only its own `K` triangles but every triangle `T` with `V` in `T + int H`
//! (`H` the support): the **regions** of `schemes::butterfly_regions` and
//! `schemes::sqrt3_regions`, for both schemes the same nine per sector (the corner triangle,
//! three in the next band, five in the one after), each a table patch of its own: section key
//! `faces = K`, `sector = region`, with the region's layout in `V`'s cone coordinates
//! ([`crate::cone_chart`]). The same region in sector `s` around `V` reads every layout point
//! `(a, b)_t` as `(a, b)_{t + s}`. A triangle in no region is the regular patch: region 0 at
//! valence 6 around its corner 0.
//!
//! A triangle is a patch when
//! * it lies in the regions of at most one extraordinary vertex, and
//! * its layout holds no other extraordinary vertex (the rules the table was made with are the
//!   regular ones everywhere but at `V`).
//!
//! [`crate::region_isolate`] refines until that holds. A region's frame puts its first corner
//! at patch `(0,0)`: the patch's `corner` is the face corner that is the region's first.

use std::collections::{BTreeMap, BTreeSet};

use rayon::prelude::*;
use schemes::butterfly_regions::ButterflyRegions;
use schemes::sqrt3_regions::Sqrt3Regions;
use schemes::triangle_local::{canonical_triangle_point, TrianglePoint};
use schemes::TriangleScheme;

use crate::cone_chart::{ConeChart, ConeCharts};
use crate::patch::PatchKind;
use crate::topology::Mesh;
use crate::triangle_patch::TrianglePatch;
use crate::triangle_topology::neighbours;
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

    /// The regions of an interior vertex of valence `k`: every region's corners and layout.
    fn shapes(self, k: u32) -> Result<Vec<RegionShape>, RuntimeError> {
        let name = self.name();
        let scheme = TriangleScheme::by_name(name)
            .ok_or_else(|| RuntimeError::Unsupported(format!("{name} is not catalogued")))?;
        let failed = |e: &dyn std::fmt::Display| {
            RuntimeError::Unsupported(format!("{name} at valence {k}: {e}"))
        };
        Ok(match self {
            RegionScheme::Butterfly => ButterflyRegions::new(&scheme, k)
                .map_err(|e| failed(&e))?
                .regions
                .into_iter()
                .map(|r| RegionShape {
                    corners: r.triangle.corners(),
                    layout: r.layout,
                })
                .collect(),
            RegionScheme::Sqrt3 => Sqrt3Regions::new(&scheme, k)
                .map_err(|e| failed(&e))?
                .regions
                .into_iter()
                .map(|r| RegionShape {
                    corners: r.triangle.corners(),
                    layout: r.layout,
                })
                .collect(),
        })
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

/// The patch of every triangle of a closed triangle mesh, or the first triangle that is not
/// one yet (see the module docs).
pub fn gather_region_patches(
    mesh: &Mesh,
    catalogue: &RegionCatalogue,
) -> Result<Vec<TrianglePatch>, RuntimeError> {
    let valence: Vec<usize> = (0..mesh.positions.len())
        .map(|v| mesh.fan(v).len())
        .collect();
    let mut patches: Vec<Option<TrianglePatch>> = vec![None; mesh.faces()];
    let mut charts = ConeCharts::new(mesh);
    let not_isolated = |face: usize, reason: String| MeshError::NotIsolated { face, reason };
    for v in 0..mesh.positions.len() {
        if valence[v] == 6 || valence[v] == 0 {
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
                    return Err(not_isolated(
                        f,
                        "it lies in the regions of two extraordinary vertices".to_owned(),
                    )
                    .into());
                }
                let points =
                    gather(&chart, &region.layout, s, &valence).map_err(|e| not_isolated(f, e))?;
                patches[f] = Some(TrianglePatch {
                    kind: PatchKind {
                        boundary: false,
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
    let radius = reach(&regular.layout);
    let regular_layout: BTreeSet<TrianglePoint> = regular.layout.iter().copied().collect();
    // The regular triangles, most of the mesh, in one chunk per thread, each with its own
    // chart scratch space.
    let regular_patch =
        |charts: &mut ConeCharts, f: usize| -> Result<TrianglePatch, RuntimeError> {
            let corners = mesh.face(f);
            let chart = charts
                .chart_within(mesh, corners[0], corners[1], radius, |p| {
                    regular_layout.contains(&p)
                })
                .map_err(|e| not_isolated(f, e))?;
            if chart.valence != 6 {
                return Err(not_isolated(
                    f,
                    format!(
                        "its corner {} has valence {} but the triangle is in none of its regions",
                        corners[0], chart.valence
                    ),
                )
                .into());
            }
            let points =
                gather(&chart, &regular.layout, 0, &valence).map_err(|e| not_isolated(f, e))?;
            Ok(TrianglePatch {
                kind: PatchKind {
                    boundary: false,
                    faces: 6,
                    sector: 0,
                },
                points,
                corner: 0,
            })
        };
    let chunk = mesh.faces().div_ceil(rayon::current_num_threads()).max(1);
    let mut out: Vec<TrianglePatch> = Vec::with_capacity(mesh.faces());
    let chunks: Vec<Result<Vec<TrianglePatch>, RuntimeError>> = patches
        .par_chunks_mut(chunk)
        .enumerate()
        .map(|(c, slice)| {
            let mut charts = ConeCharts::new(mesh);
            slice
                .iter_mut()
                .enumerate()
                .map(|(i, patch)| match patch.take() {
                    Some(p) => Ok(p),
                    None => regular_patch(&mut charts, c * chunk + i),
                })
                .collect()
        })
        .collect();
    for c in chunks {
        out.extend(c?);
    }
    Ok(out)
}
