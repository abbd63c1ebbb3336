//! Adaptive tessellation of bicubic Bézier surfaces driven by displacement maps
//! (F.J. Espino, M. Bóo, M. Amor, J.D. Bruguera, WSCG 2005;
//! `../shared/papers/espino-bezier-displacement-maps.txt`), with the "flat" test it is
//! compared against. docs/espino.md has the method, our readings of the paper and the results.
//!
//! * [`patch_input`]: Newell "patches + vertices" and `.bpt` files → [`BezierPatches`].
//! * [`bicubic`]: evaluation, derivatives, normals (limit normals on collapsed rows).
//! * [`displacement_map`]: the 18-triangle coarse tessellation and the `M × N` map (section 2.1).
//! * [`edge_tests`]: Map2p / Map4p / Map8p (eq. 1–3) and the flat test.
//! * [`adaptive`]: the crack-free refinement, every edge decided once.
//! * [`mesh_error`]: the error measure (max distance from dense surface samples to the mesh).
//!
//! ```no_run
//! use subtess::tessellate::bezier::{tessellate_bezier, BezierOptions, BezierPatches, EdgeTest};
//! let patches = BezierPatches::read("teapot.bpt".as_ref())?;
//! let options = BezierOptions { test: EdgeTest::Map4p, threshold: 0.01, ..Default::default() };
//! let (mesh, stats) = tessellate_bezier(&patches, &options)?;
//! subtess::io::mesh_output::write_mesh(&mesh, "teapot.ply".as_ref())?;
//! println!("{}", stats.to_json());
//! # Ok::<(), subtess::RuntimeError>(())
//! ```

pub mod adaptive;
pub mod bicubic;
pub mod displacement_map;
pub mod edge_tests;
pub mod mesh_error;
pub mod patch_input;

use std::time::Instant;

use serde_json::{json, Value};

pub use adaptive::SharedCurves;
pub use bicubic::{BicubicPatch, Point3, SurfacePoint};
pub use displacement_map::DisplacementMap;
pub use edge_tests::EdgeTest;
pub use patch_input::{BezierPatches, PatchFormat};

use crate::mesh::triangle_mesh::TriangleMesh;
use crate::RuntimeError;
use adaptive::{Prepared, Refinement};

/// How to tessellate.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierOptions {
    /// The edge test (eq. 1–3, or the flat baseline).
    pub test: EdgeTest,
    /// The threshold `th` of eq. (1) and (3) (a distance; finite, `> 0`). Ignored when
    /// `target_triangles` is set.
    pub threshold: f64,
    /// Map resolution `(M, N)`: samples along `u` and `v` (the paper uses 16 × 16).
    pub map_resolution: (usize, usize),
    /// A triangle budget: search `th` (by bisection on `log th`) for the count nearest it.
    pub target_triangles: Option<usize>,
    /// Finest level: parameters are multiples of `1 / (3 · 2^max_depth)` (1..=20).
    pub max_depth: u32,
    /// Refuse (or, in a budget search, treat as too many) more triangles than this.
    pub max_triangles: usize,
    /// Samples per patch side for the error measure ([`mesh_error::max_surface_distance`]);
    /// 0 skips it (`max_error` is then `None`).
    pub error_samples: usize,
}

impl Default for BezierOptions {
    /// Map4p at `th = 0.01`, a 16 × 16 map, depth 6 (edges down to 1/192 of the patch), at most 10 million triangles, error
    /// measured on 32 × 32 samples per patch.
    fn default() -> Self {
        BezierOptions {
            test: EdgeTest::Map4p,
            threshold: 0.01,
            map_resolution: (16, 16),
            target_triangles: None,
            max_depth: 6,
            max_triangles: 10_000_000,
            error_samples: 32,
        }
    }
}

/// What a tessellation did. `vertices_evaluated - vertices` surface evaluations were thrown
/// away (the flat test's rejected candidates); a map test throws none away and
/// `evaluations_saved` counts the candidates a compute-then-decide test would have evaluated
/// for the same decisions (one per edge tested and not split).
#[derive(Clone, Debug, PartialEq)]
pub struct BezierStats {
    /// The test.
    pub test: EdgeTest,
    /// The threshold used (the one found, with a budget).
    pub threshold: f64,
    /// Map resolution `(M, N)`.
    pub map_resolution: (usize, usize),
    /// Patches.
    pub patches: usize,
    /// Output triangles.
    pub triangles: usize,
    /// Output vertices.
    pub vertices: usize,
    /// Surface evaluations (position + normal) made while tessellating.
    pub vertices_evaluated: usize,
    /// Of those, evaluated and thrown away.
    pub vertices_discarded: usize,
    /// Edge tests run (each edge once).
    pub edges_tested: usize,
    /// Edges split.
    pub edges_split: usize,
    /// Evaluations a compute-then-decide test would have thrown away for these decisions (map
    /// tests; 0 for flat, which pays them: see `vertices_discarded`).
    pub evaluations_saved: usize,
    /// Edges left unsplit because they reached `max_depth`.
    pub edges_capped: usize,
    /// Surface samples taken to build the displacement maps (`patches · M · N`; 0 for flat).
    pub map_evaluations: usize,
    /// Max distance from surface samples to the mesh, when measured.
    pub max_error: Option<f64>,
    /// Wall time of the tessellation (maps, decisions, evaluation; not the error measure or
    /// the budget search).
    pub seconds: f64,
    /// With a budget: the target and the number of trial refinements the search ran.
    pub search: Option<(usize, usize)>,
}

impl BezierStats {
    /// The stats as a JSON object (field names as above).
    pub fn to_json(&self) -> Value {
        json!({
            "test": self.test.name(),
            "threshold": self.threshold,
            "map_resolution": [self.map_resolution.0, self.map_resolution.1],
            "patches": self.patches,
            "triangles": self.triangles,
            "vertices": self.vertices,
            "vertices_evaluated": self.vertices_evaluated,
            "vertices_discarded": self.vertices_discarded,
            "edges_tested": self.edges_tested,
            "edges_split": self.edges_split,
            "evaluations_saved": self.evaluations_saved,
            "edges_capped": self.edges_capped,
            "map_evaluations": self.map_evaluations,
            "max_error": self.max_error,
            "seconds": self.seconds,
            "target_triangles": self.search.map(|s| s.0),
            "search_iterations": self.search.map(|s| s.1),
        })
    }
}

/// A tessellation with, per triangle, the patch it came from.
#[derive(Clone, Debug)]
pub struct BezierTessellation {
    /// The mesh (sources: patch and exact `(u, v)` on the grid of denominator `3 · 2^max_depth`).
    pub mesh: TriangleMesh,
    /// The patch of each triangle.
    pub triangle_patches: Vec<u32>,
    /// What it did.
    pub stats: BezierStats,
}

fn check(patches: &BezierPatches, options: &BezierOptions) -> Result<(), RuntimeError> {
    let bad = |m: String| Err(RuntimeError::invalid_option(m));
    if patches.is_empty() {
        return bad("no patches to tessellate".into());
    }
    if options.target_triangles.is_none()
        && !(options.threshold.is_finite() && options.threshold > 0.0)
    {
        return bad(format!(
            "threshold {} must be finite and positive",
            options.threshold
        ));
    }
    let (m, n) = options.map_resolution;
    if !(2..=4096).contains(&m) || !(2..=4096).contains(&n) {
        return bad(format!("map resolution {m}x{n}: each must be in 2..=4096"));
    }
    if !(1..=20).contains(&options.max_depth) {
        return bad(format!("max depth {} must be in 1..=20", options.max_depth));
    }
    if options.target_triangles == Some(0) {
        return bad("a triangle budget must be at least 1".into());
    }
    Ok(())
}

/// Tessellate `patches` adaptively (Espino et al., section 2): coarse 18-triangle tessellation
/// per patch, displacement maps (section 2.1), edge tests (eq. 1–3 or flat) deciding every
/// split once, then one evaluation per output vertex. Watertight wherever patches share a
/// boundary curve with exactly equal control points.
pub fn tessellate_bezier(
    patches: &BezierPatches,
    options: &BezierOptions,
) -> Result<(TriangleMesh, BezierStats), RuntimeError> {
    let t = tessellate_bezier_full(patches, options)?;
    Ok((t.mesh, t.stats))
}

/// [`tessellate_bezier`], also returning each triangle's patch.
pub fn tessellate_bezier_full(
    patches: &BezierPatches,
    options: &BezierOptions,
) -> Result<BezierTessellation, RuntimeError> {
    check(patches, options)?;
    let start = Instant::now();
    let (m, n) = options.map_resolution;
    let maps = if options.test.uses_map() {
        patches
            .patches
            .iter()
            .map(|p| DisplacementMap::build(p, m, n))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        Vec::new()
    };
    let map_seconds = start.elapsed().as_secs_f64();
    let prepared = Prepared::new(patches, maps, options.max_depth);
    let (threshold, search) = match options.target_triangles {
        None => (options.threshold, None),
        Some(target) => {
            let (th, iterations) = search_threshold(&prepared, options, target, patches.diagonal());
            (th, Some((target, iterations)))
        }
    };
    let start = Instant::now();
    let refinement = prepared
        .refine(options.test, threshold, options.max_triangles)
        .map_err(|_| too_many(options))?;
    let (mesh, triangle_patches, counts) = prepared.assemble(refinement);
    let seconds = map_seconds + start.elapsed().as_secs_f64();
    let max_error = (options.error_samples > 0)
        .then(|| mesh_error::max_surface_distance(patches, &mesh, options.error_samples));
    let vertices = mesh.positions.len();
    let stats = BezierStats {
        test: options.test,
        threshold,
        map_resolution: options.map_resolution,
        patches: patches.len(),
        triangles: mesh.triangles.len(),
        vertices,
        vertices_evaluated: counts.evaluations,
        vertices_discarded: counts.evaluations - vertices,
        edges_tested: counts.edges_tested,
        edges_split: counts.edges_split,
        evaluations_saved: if options.test.uses_map() {
            counts.edges_tested - counts.edges_split
        } else {
            0
        },
        edges_capped: counts.edges_capped,
        map_evaluations: if options.test.uses_map() {
            patches.len() * m * n
        } else {
            0
        },
        max_error,
        seconds,
        search,
    };
    Ok(BezierTessellation {
        mesh,
        triangle_patches,
        stats,
    })
}

fn too_many(options: &BezierOptions) -> RuntimeError {
    RuntimeError::invalid_option(format!(
        "threshold {} with test {} gives more than {} triangles; raise the threshold",
        options.threshold, options.test, options.max_triangles
    ))
}

/// Find the threshold whose triangle count is nearest `target`: from `diagonal / 64`, divide
/// by 4 until the count reaches the target, then bisect `log th` (at most 40 steps). Returns
/// the threshold and the number of trial refinements.
fn search_threshold(
    prepared: &Prepared<'_>,
    options: &BezierOptions,
    target: usize,
    diagonal: f64,
) -> (f64, usize) {
    let mut trials = 0;
    let mut count = |th: f64| -> usize {
        trials += 1;
        match prepared.refine(options.test, th, options.max_triangles) {
            Ok(r) => surviving(prepared, &r),
            Err(_) => usize::MAX,
        }
    };
    let mut best = (usize::MAX, diagonal);
    let consider = |th: f64, c: usize, best: &mut (usize, f64)| {
        if c.abs_diff(target) < best.0 {
            *best = (c.abs_diff(target), th);
        }
    };
    let mut hi = diagonal;
    let c_hi = count(hi);
    consider(hi, c_hi, &mut best);
    if c_hi >= target {
        return (hi, trials);
    }
    let mut lo = diagonal / 64.0;
    loop {
        let c = count(lo);
        consider(lo, c, &mut best);
        if c >= target {
            break;
        }
        hi = lo;
        lo /= 4.0;
        if lo < diagonal * 1e-12 {
            return (best.1, trials);
        }
    }
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        let c = count(mid);
        consider(mid, c, &mut best);
        if c == target || hi / lo < 1.0 + 1e-9 {
            break;
        }
        if c > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (best.1, trials)
}

fn surviving(prepared: &Prepared<'_>, r: &Refinement) -> usize {
    prepared.surviving(r)
}
