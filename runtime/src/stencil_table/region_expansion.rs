//! Grid stencils from a compact region table (the butterfly, √3; docs/table-format.md, "Compact
//! region tables"): the regular tiles' formula and the corner's scaling relation
//! (Schaefer–Warren eqs. (2) and (3); `stencilgen::cone_regions`) evaluated when a plan first
//! asks for a grid.
//!
//! Let `phi(x)` be the row of the basis functions of region `r`'s layout at `x = (u, v)` in the
//! region's frame, `λ` the dilation (2 for the butterfly, 3 for two √3 steps), `psi` the
//! scheme's regular basis and `psi_1`, `psi_2` its derivatives along the skew axes. On a
//! non-corner region (triangle `c_0, c_1, c_2` of `V`'s sector-0 chart, tile level `L`), with
//! the chart point `c = c_0 + u (c_1 - c_0) + v (c_2 - c_0)` and `y = λ^L c`,
//!
//! ```text
//!   phi(x)      = sum_j psi(y - j) R[j]
//!   d/du phi(x) = sum_j (λ^L (D_{c_1 - c_0} psi))(y - j) R[j],   D_w psi = w_1 psi_1 + w_2 psi_2
//!   d/dv phi(x) = sum_j (λ^L (D_{c_2 - c_0} psi))(y - j) R[j]
//! ```
//!
//! over the control points `j` of the first regular tile holding `y` (`R[j]` their level-0 rows,
//! stored per region). In the corner region (region 0) `phi(x) = phi(λx) A` (times `λ` per
//! step for a derivative) while `u + v <= 1/λ`, the tile formula with axes `(1,0), (0,1)`
//! outside, and at `x = 0` the masks at `V` (stored). The grids of rate `n` are on the lattice
//! `1/3n` (primal points `3i/3n`, centroids `(3i+1)/3n`, `(3i+2)/3n`), where the table stores
//! `psi` by its values on the wedge and `psi_1` on the quarter of `schemes::lattice_symmetry`:
//! every other value is one of those, or its negative, under a symmetry of the lattice, and
//! `psi_2(y) = psi_1(rho^-1 y)`. The tiles and regular points are the region geometry of
//! `schemes::cone_regions`, which the table does not store (it is integer geometry the
//! runtime builds anyway to find a mesh's regions).
//!
//! The arithmetic is `stencilgen::cone_regions`' f64 evaluation, operation for operation (the
//! tile's terms in its points' order, `A` applied as a sum over its rows ascending, the
//! derivative factor `λ` after each such sum), so the grids are those its f64 evaluation makes
//! from the same basis; they are rounded once to f32. Against the grid layout, whose basis is
//! solved on each whole grid by the orbit solver, they agree to 1 ulp of f32
//! (`runtime/tests/integration/compact_tables.rs`).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use schemes::cone_regions::ConeRegions;
use schemes::lattice_symmetry::{
    quarter_points, rotate_back, support_box, to_quarter, to_wedge, wedge_points,
};
use schemes::TriangleScheme;
use table_format::{PointSet, SchemeId, SectionKey, StencilKind, TableIndex};

use super::{compact_pieces, expanded_once, GridSlots, Grids, PatchId, MAX_COMPACT_RATE};
use crate::RuntimeError;

/// The regular basis of one rate, as lookups into the stored canonical values.
#[derive(Debug)]
struct RateBasis {
    /// The grid denominator `3n`.
    d: i64,
    /// The numerator box of the support, `((lo_1, hi_1), (lo_2, hi_2))`.
    bbox: ((i64, i64), (i64, i64)),
    /// Per box point (`k_2` outer), its index among the wedge points, or `u32::MAX`.
    wedge: Vec<u32>,
    /// Per box point, its index among the quarter points, or `u32::MAX`.
    quarter: Vec<u32>,
}

impl RateBasis {
    /// The box index of `k`, if inside the box.
    fn at(&self, k: (i64, i64)) -> Option<usize> {
        let ((l1, h1), (l2, h2)) = self.bbox;
        if k.0 < l1 || k.0 > h1 || k.1 < l2 || k.1 > h2 {
            return None;
        }
        Some(((k.1 - l2) * (h1 - l1 + 1) + (k.0 - l1)) as usize)
    }

    /// `psi(k/d)` from the stored wedge values `psi`.
    fn psi(&self, psi: &[f64], k: (i64, i64)) -> f64 {
        self.at(to_wedge(k))
            .and_then(|i| psi.get(self.wedge[i] as usize))
            .copied()
            .unwrap_or(0.0)
    }

    /// `psi_1(k/d)` from the stored quarter values `psi_1`.
    fn psi_1(&self, psi_1: &[f64], k: (i64, i64)) -> f64 {
        let (q, sign) = to_quarter(k);
        self.at(q)
            .and_then(|i| psi_1.get(self.quarter[i] as usize))
            .map_or(0.0, |v| sign * v)
    }
}

/// What a compact region table's grids are expanded from, and the grids once a plan asked for
/// them.
#[derive(Debug)]
pub(super) struct RegionExpansion {
    /// The table's scheme.
    scheme: TriangleScheme,
    /// Its name (`butterfly`, `sqrt3`), the key of the shared region geometry.
    name: &'static str,
    /// The rates the markers list; the regions with tile rows (patch `sector` = region).
    slots: GridSlots,
    /// Per rate (the slots' order), the basis lookups, made on first use.
    bases: Vec<OnceLock<RateBasis>>,
    /// The valences with a subdivision matrix, ascending, and their region geometry, fetched
    /// on first use ([`cone_regions`], shared with the isolation).
    geometry: Vec<(u32, OnceLock<Arc<ConeRegions>>)>,
}

/// The regions of an interior vertex of valence `k` of the region scheme `name` (`butterfly`,
/// `sqrt3`; [`ConeRegions`]: corners, layouts, tiles, the corner's matrices), built once per
/// process and shared: the isolation reads their shapes
/// (`scheme::triangle::region_patch::RegionScheme::cone_regions`), the expansion their tiles.
/// Building them takes exact rational arithmetic (about 150 M instructions at valence 4),
/// which a plan would otherwise pay twice.
pub(crate) fn cone_regions(name: &'static str, k: u32) -> Result<Arc<ConeRegions>, RuntimeError> {
    type Cache = Mutex<BTreeMap<(&'static str, u32), Arc<ConeRegions>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(BTreeMap::new()));
    // A panic elsewhere while the lock was held leaves complete entries only (each is inserted
    // whole), so a poisoned lock is still a valid cache.
    let lock = || cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(regions) = lock().get(&(name, k)) {
        return Ok(Arc::clone(regions));
    }
    let scheme = TriangleScheme::by_name(name)
        .ok_or_else(|| RuntimeError::Unsupported(format!("{name} is not catalogued")))?;
    // `ConeRegions::new` reads the dilation (2 or 3) from the scheme's rules. Built without the
    // lock held; two threads asking at once both build, and the first is kept.
    let built = Arc::new(
        ConeRegions::new(&scheme, k)
            .map_err(|e| RuntimeError::Unsupported(format!("{name} at valence {k}: {e}")))?,
    );
    Ok(Arc::clone(lock().entry((name, k)).or_insert(built)))
}

/// The error of a compact region table missing or misshaping a piece.
fn incomplete(what: String) -> RuntimeError {
    RuntimeError::InvalidParameter {
        name: "table".to_owned(),
        reason: format!(
            "{what}: a compact region table needs every piece of the scaling relation; \
             regenerate it with `stencilgen tables --schemes butterfly` (or sqrt3)"
        ),
    }
}

/// The key of rate `n`'s basis section of `kind`.
fn basis_key(kind: StencilKind, n: u32) -> SectionKey {
    SectionKey {
        kind,
        points: PointSet::RegionBasis,
        boundary: false,
        feature: table_format::Feature::None,
        faces: 0,
        sector: 0,
        n,
    }
}

/// The key of a valence's piece (`A` or a vertex mask) of `kind`.
fn valence_key(kind: StencilKind, points: PointSet, faces: u32) -> SectionKey {
    SectionKey {
        kind,
        points,
        boundary: false,
        feature: table_format::Feature::None,
        faces,
        sector: 0,
        n: 0,
    }
}

impl RegionExpansion {
    /// The expansion of a validated butterfly or √3 table, `None` if it holds grids only.
    /// Refused here, naming the piece: pieces in f32, a rate marker outside
    /// `1..=`[`MAX_COMPACT_RATE`] or without both basis kinds, a basis of another kind or
    /// without a marker, a valence without its three masks at `V` (of `A`'s width), region
    /// rows without their valence's `A`, a boundary piece. The counts the region geometry
    /// fixes (the canonical points of a rate's basis, a region's regular points and layout)
    /// are checked when a grid is first expanded.
    pub(super) fn new(index: &TableIndex) -> Result<Option<Self>, RuntimeError> {
        let Some(pieces) = compact_pieces(index)? else {
            return Ok(None);
        };
        let name = match index.meta.scheme {
            SchemeId::Butterfly => "butterfly",
            SchemeId::Sqrt3 => "sqrt3",
            other => {
                return Err(incomplete(format!(
                    "a {} table is not a region table",
                    other.name()
                )))
            }
        };
        let scheme = TriangleScheme::by_name(name)
            .ok_or_else(|| incomplete(format!("{name} is not catalogued")))?;
        let patchless = |key: &SectionKey| !key.boundary && key.faces == 0 && key.sector == 0;
        let (mut rates, mut patches, mut valences) = (Vec::new(), Vec::new(), Vec::new());
        for key in pieces {
            let width = index.entry(key)?.width;
            if key.boundary {
                return Err(incomplete(format!(
                    "{key}: region tables have no boundary vertices"
                )));
            }
            match key.points {
                PointSet::TriangleRate => {
                    if key.kind != StencilKind::Position
                        || !patchless(key)
                        || !(1..=MAX_COMPACT_RATE).contains(&key.n)
                    {
                        return Err(incomplete(format!(
                            "{key} is not a position rate marker in \
                             1..={MAX_COMPACT_RATE} without a patch"
                        )));
                    }
                    for kind in [StencilKind::Position, StencilKind::DerivativeU] {
                        if index.get(&basis_key(kind, key.n)).is_none() {
                            return Err(incomplete(format!(
                                "{key} has no {}",
                                basis_key(kind, key.n)
                            )));
                        }
                    }
                    rates.push(key.n);
                }
                PointSet::RegionBasis => {
                    let marker = SectionKey {
                        kind: StencilKind::Position,
                        points: PointSet::TriangleRate,
                        ..*key
                    };
                    if key.kind == StencilKind::DerivativeV
                        || !patchless(key)
                        || index.get(&marker).is_none()
                    {
                        return Err(incomplete(format!(
                            "{key} is not a position or d/du basis of a listed rate"
                        )));
                    }
                }
                PointSet::Subdivision => {
                    if key.kind != StencilKind::Position || key.n != 0 || key.sector != 0 {
                        return Err(incomplete(format!(
                            "{key} is not a valence's matrix (sector 0, n = 0)"
                        )));
                    }
                    for kind in [
                        StencilKind::Position,
                        StencilKind::DerivativeU,
                        StencilKind::DerivativeV,
                    ] {
                        let mask = valence_key(kind, PointSet::VertexMask, key.faces);
                        match index.get(&mask) {
                            Some(e) if e.width == width => {}
                            _ => {
                                return Err(incomplete(format!(
                                    "{key} has no {mask} of its width {width}"
                                )))
                            }
                        }
                    }
                    valences.push((key.faces, OnceLock::new()));
                }
                PointSet::VertexMask | PointSet::RegionRows => {
                    let a = valence_key(StencilKind::Position, PointSet::Subdivision, key.faces);
                    if index.get(&a).is_none() {
                        return Err(incomplete(format!("{key} has no {a}")));
                    }
                    if key.points == PointSet::RegionRows {
                        if key.kind != StencilKind::Position || width == 0 {
                            return Err(incomplete(format!(
                                "{key} is not a region's position rows"
                            )));
                        }
                        patches.push((PatchId::of(key), width));
                    }
                }
                // The format admits no other non-grid point set in a triangle table.
                _ => {
                    return Err(incomplete(format!(
                        "{key} does not belong to a region table"
                    )))
                }
            }
        }
        if rates.is_empty() {
            return Err(incomplete("the table lists no rate".to_owned()));
        }
        valences.sort_unstable_by_key(|v| v.0);
        // A region's rows are keyed by their count `n` too, which a grid's key does not
        // carry: the slots know a patch by (valence, region) alone (`PatchId`).
        let slots = GridSlots::new(rates, patches);
        Ok(Some(RegionExpansion {
            scheme,
            name,
            bases: (0..slots.rates.len()).map(|_| OnceLock::new()).collect(),
            slots,
            geometry: valences,
        }))
    }

    /// The grid stencils of `key` (a triangle primal or dual section), expanded on first use
    /// from `bytes`, the bytes `index` was parsed from. `None` if the table cannot expand it.
    pub(super) fn grid<'s>(
        &'s self,
        index: &TableIndex,
        bytes: &[u8],
        key: &SectionKey,
    ) -> Option<Result<&'s [f32], RuntimeError>> {
        let primal = match key.points {
            PointSet::TrianglePrimal => true,
            PointSet::TriangleDual => false,
            _ => return None,
        };
        let slot = self.slots.slot(key)?;
        let geometry = self
            .geometry
            .binary_search_by_key(&key.faces, |v| v.0)
            .ok()
            .map(|v| &self.geometry[v].1)?;
        Some(
            expanded_once(slot.grids, || {
                let regions = match geometry.get() {
                    Some(regions) => regions,
                    None => {
                        let shared = cone_regions(self.name, key.faces)?;
                        geometry.get_or_init(|| shared)
                    }
                };
                let basis = self.bases[slot.rate].get_or_init(|| self.rate_basis(key.n));
                Pieces::read(index, bytes, key, slot.k, regions, basis)?.grids(key.n)
            })
            .map(|grids| &*grids[usize::from(!primal)]),
        )
    }

    /// The lookups of rate `n`'s basis on `1/3n`: where each point of the support box is among
    /// the canonical points.
    fn rate_basis(&self, n: u32) -> RateBasis {
        let mask = self.scheme.regular_mask();
        let hull = mask.hull();
        let d = 3 * n;
        let bbox = support_box(&hull, mask.dilation, d);
        let ((l1, h1), (l2, h2)) = bbox;
        let size = ((h1 - l1 + 1) * (h2 - l2 + 1)) as usize;
        let at = |k: (i64, i64)| ((k.1 - l2) * (h1 - l1 + 1) + (k.0 - l1)) as usize;
        let mut wedge = vec![u32::MAX; size];
        for (i, k) in wedge_points(&hull, mask.dilation, d)
            .into_iter()
            .enumerate()
        {
            wedge[at(k)] = i as u32;
        }
        let mut quarter = vec![u32::MAX; size];
        for (i, k) in quarter_points(&hull, mask.dilation, d)
            .into_iter()
            .enumerate()
        {
            quarter[at(k)] = i as u32;
        }
        RateBasis {
            d: i64::from(d),
            bbox,
            wedge,
            quarter,
        }
    }
}

/// The pieces of one region for one kind, read from the table, their lengths checked against
/// the region geometry.
struct Pieces<'a> {
    kind: StencilKind,
    /// The region's width (layout size).
    k: usize,
    /// The valence's regions.
    regions: &'a ConeRegions,
    /// Which region.
    r: usize,
    /// The nonzero entries `(i, A[i][c])` of each column `c` of `A` (`K x K`, the corner's
    /// width), `i` ascending; region 0 only (empty otherwise).
    a_columns: Vec<Vec<(usize, f64)>>,
    /// The mask at `V` for this kind, region 0 only.
    vertex: &'a [f64],
    /// The nonzero entries `(c, R[u][c])` of the region's tile row of each regular point `u`,
    /// `c` ascending (about 60% of the rows' entries are zero).
    rows: Vec<Vec<(usize, f64)>>,
    /// `psi` on the wedge and `psi_1` on the quarter.
    psi: &'a [f64],
    psi_1: &'a [f64],
    basis: &'a RateBasis,
}

impl<'a> Pieces<'a> {
    fn read(
        index: &TableIndex,
        bytes: &'a [u8],
        key: &SectionKey,
        k: usize,
        regions: &'a ConeRegions,
        basis: &'a RateBasis,
    ) -> Result<Self, RuntimeError> {
        let r = key.sector as usize;
        let region = regions.regions.get(r).ok_or_else(|| {
            incomplete(format!(
                "valence {} has {} regions, not a region {r}",
                key.faces,
                regions.regions.len()
            ))
        })?;
        let points = region.regular_points.len();
        let rows_key = SectionKey {
            kind: StencilKind::Position,
            points: PointSet::RegionRows,
            n: u32::try_from(points).unwrap_or(u32::MAX),
            ..*key
        };
        let rows = index.weights_f64(bytes, &rows_key)?;
        if k != region.size() || rows.len() != points * k {
            return Err(incomplete(format!(
                "{rows_key} has {} weights, not {points} x {} (the region's regular points x \
                 its layout)",
                rows.len(),
                region.size()
            )));
        }
        let (a, vertex) = if region.is_corner() {
            let a = index.weights_f64(
                bytes,
                &valence_key(StencilKind::Position, PointSet::Subdivision, key.faces),
            )?;
            let vertex = index.weights_f64(
                bytes,
                &valence_key(key.kind, PointSet::VertexMask, key.faces),
            )?;
            if a.len() != k * k || vertex.len() != k {
                return Err(incomplete(format!(
                    "valence {}'s A or mask at V is not of the corner's width {k}",
                    key.faces
                )));
            }
            (a, vertex)
        } else {
            (&[][..], &[][..])
        };
        let psi = index.weights_f64(bytes, &basis_key(StencilKind::Position, key.n))?;
        let psi_1 = index.weights_f64(bytes, &basis_key(StencilKind::DerivativeU, key.n))?;
        let count = |table: &[u32]| table.iter().filter(|&&i| i != u32::MAX).count();
        if psi.len() != count(&basis.wedge) || psi_1.len() != count(&basis.quarter) {
            return Err(incomplete(format!(
                "the regular basis at rate {} has {} and {} values, not the {} wedge and {} \
                 quarter points of its support",
                key.n,
                psi.len(),
                psi_1.len(),
                count(&basis.wedge),
                count(&basis.quarter)
            )));
        }
        // The zero entries are skipped as `stencilgen`'s evaluation skips them, so sparse rows
        // give the same sums in the same order.
        let sparse = |row: &[f64]| -> Vec<(usize, f64)> {
            row.iter()
                .copied()
                .enumerate()
                .filter(|&(_, x)| x != 0.0)
                .collect()
        };
        let a_columns = if a.is_empty() {
            Vec::new()
        } else {
            (0..k)
                .map(|c| {
                    (0..k)
                        .map(|i| (i, a[i * k + c]))
                        .filter(|&(_, x)| x != 0.0)
                        .collect()
                })
                .collect()
        };
        Ok(Pieces {
            kind: key.kind,
            k,
            regions,
            r,
            a_columns,
            vertex,
            rows: rows.chunks_exact(k).map(sparse).collect(),
            psi,
            psi_1,
            basis,
        })
    }

    /// Both grids at rate `n` (module docs), rounded to f32.
    fn grids(&self, n: u32) -> Result<Grids, RuntimeError> {
        if !(1..=MAX_COMPACT_RATE).contains(&n) {
            return Err(incomplete(format!(
                "rate {n} is outside 1..={MAX_COMPACT_RATE}"
            )));
        }
        let n = i64::from(n);
        // The primal grid (3i/3n, 3j/3n), i + j <= n, j outer.
        let primal: Vec<(i64, i64)> = (0..=n)
            .flat_map(|j| (0..=n - j).map(move |i| (3 * i, 3 * j)))
            .collect();
        // The centroids over 3n in table order: row j, up(0, j), down(0, j), up(1, j), ...
        let mut dual = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n - j {
                dual.push((3 * i + 1, 3 * j + 1));
                if i + j + 2 <= n {
                    dual.push((3 * i + 2, 3 * j + 2));
                }
            }
        }
        let expand = |points: &[(i64, i64)]| -> Result<Box<[f32]>, RuntimeError> {
            let mut out = Vec::with_capacity(points.len() * self.k);
            for &p in points {
                out.extend(self.stencil(p)?.into_iter().map(|w| w as f32));
            }
            Ok(out.into_boxed_slice())
        };
        Ok([expand(&primal)?, expand(&dual)?])
    }

    /// The stencil at `(i/d, j/d)`, `d = 3n` (`stencilgen::cone_regions`'
    /// `ConeRegionStencils::stencil`).
    fn stencil(&self, (i, j): (i64, i64)) -> Result<Vec<f64>, RuntimeError> {
        let region = &self.regions.regions[self.r];
        let d = self.basis.d;
        if !region.is_corner() {
            return self.tile(region.triangle.chart_point(i, j, d));
        }
        if (i, j) == (0, 0) {
            return Ok(self.vertex.to_vec());
        }
        let l = i64::from(self.regions.corner.dilation());
        let (mut x, mut steps) = ((i, j), 0u32);
        while l * (x.0 + x.1) <= d {
            x = (l * x.0, l * x.1);
            steps += 1;
        }
        let mut row = self.tile(x)?;
        // phi(x) = phi(λx) A, `steps` times; times λ per step for a derivative.
        let lambda = l as f64;
        for _ in 0..steps {
            row = self
                .a_columns
                .iter()
                .map(|column| {
                    // Over the rows i ascending where both factors are nonzero, as
                    // `stencilgen` sums them.
                    let sum = column
                        .iter()
                        .filter(|&&(i, _)| row[i] != 0.0)
                        .fold(0.0, |acc, &(i, a)| acc + row[i] * a);
                    if self.kind == StencilKind::Position {
                        sum
                    } else {
                        sum * lambda
                    }
                })
                .collect();
        }
        Ok(row)
    }

    /// The tile formula at the chart point `c / d` of the region (module docs).
    fn tile(&self, c: (i64, i64)) -> Result<Vec<f64>, RuntimeError> {
        let region = &self.regions.regions[self.r];
        let d = self.basis.d;
        let scale = self.regions.corner.family.scale(region.tile_level);
        let y = (scale * c.0, scale * c.1);
        let tile = region.tile_containing(y, d).ok_or_else(|| {
            incomplete(format!(
                "({}/{d}, {}/{d}) (level {}) is in no regular tile of region {}",
                y.0, y.1, region.tile_level, self.r
            ))
        })?;
        let [e1, e2] = region.triangle.axes();
        let axis = match self.kind {
            StencilKind::Position => None,
            StencilKind::DerivativeU => Some(e1),
            StencilKind::DerivativeV => Some(e2),
        };
        let mut out = vec![0.0f64; self.k];
        for &u in &region.tiles[tile].points {
            let Some(&(j1, j2)) = region.regular_points.get(u) else {
                continue;
            };
            let at = (y.0 - d * j1, y.1 - d * j2);
            let w = match axis {
                None => self.basis.psi(self.psi, at),
                // D_w psi = w_1 psi_1 + w_2 psi_2, times λ^L for the level-L coordinates;
                // psi_2(y) = psi_1(rho^-1 y).
                Some((w1, w2)) => {
                    let mut w = 0.0;
                    if w1 != 0 {
                        w += (w1 * scale) as f64 * self.basis.psi_1(self.psi_1, at);
                    }
                    if w2 != 0 {
                        w += (w2 * scale) as f64 * self.basis.psi_1(self.psi_1, rotate_back(at));
                    }
                    w
                }
            };
            if w == 0.0 {
                continue;
            }
            for &(c, rw) in &self.rows[u] {
                out[c] += w * rw;
            }
        }
        Ok(out)
    }
}
