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
//!
//! A plan reads a region's three kinds at a rate together, so they are expanded together: one
//! tile search and one basis lookup (`[psi, psi_1, psi_2]` from the basis spread once per rate
//! on its support box) per tile point, one pass over its sparse row updating the three sums.
//! Each kind's sums are still its own operations in its order: where a kind's weight is zero
//! (`stencilgen` skips the point) the pass adds zero products, which leaves sums that start at
//! `+0` unchanged bit for bit.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use schemes::cone_regions::{ConeRegion, ConeRegions};
use schemes::lattice_symmetry::{quarter_points, reflect, rotate, support_box, wedge_points};
use schemes::TriangleScheme;
use table_format::{PointSet, SchemeId, SectionKey, StencilKind, TableIndex};

use super::{compact_pieces, GridSlots, Grids, PatchId, MAX_COMPACT_RATE};
use crate::once::TryOnce;
use crate::RuntimeError;

/// The regular basis of one rate on its whole support box, spread once from the stored
/// canonical values by the lattice's symmetries (module docs): a lookup is then one index.
///
/// `psi(k/d)` is the stored value at `to_wedge(k)`, the one image of `k` in the wedge `W`
/// (`W` is a closed fundamental domain of the twelve symmetries, so every orbit meets it
/// once and writing each wedge value to its twelve images fills the same numbers); `psi_1(k/d)`
/// is `sign * psi_1(q)` for `(q, sign) = to_quarter(k)`, the first of `k`, `sigma k`, `-k`,
/// `-sigma k` in the quarter `Q` with its sign `+1, +1, -1, -1`: the values are written in the
/// reverse of that order, so the first image's value is the one left; `psi_2(k/d) =
/// psi_1(rho^-1 k/d)`, written at `rho x` from every `x` the quarter's images reach. Zero
/// outside the open support, as the canonical lookups give (the support is invariant under
/// the symmetries, so the images of the canonical points are all its points).
#[derive(Debug)]
pub struct RateBasis {
    /// The grid denominator `3n`.
    d: i64,
    /// The box's lowest numerators `(lo_1, lo_2)`.
    low: (i64, i64),
    /// Its extent `(hi_1 - lo_1 + 1, hi_2 - lo_2 + 1)`.
    size: (i64, i64),
    /// `[psi, psi_1, psi_2, 0]` at every box point, `k_2` outer.
    values: Box<[Lanes]>,
}

impl RateBasis {
    /// Rate `n`'s basis from its stored wedge values `psi` and quarter values `psi_1`
    /// (`None` if their counts are not the canonical points' of the scheme's support).
    fn spread(scheme: &TriangleScheme, n: u32, psi: &[f64], psi_1: &[f64]) -> Option<Self> {
        let mask = scheme.regular_mask();
        let hull = mask.hull();
        let d = 3 * n;
        let ((l1, h1), (l2, h2)) = support_box(&hull, mask.dilation, d);
        let wedge = wedge_points(&hull, mask.dilation, d);
        let quarter = quarter_points(&hull, mask.dilation, d);
        if psi.len() != wedge.len() || psi_1.len() != quarter.len() {
            return None;
        }
        let mut basis = RateBasis {
            d: i64::from(d),
            low: (l1, l2),
            size: (h1 - l1 + 1, h2 - l2 + 1),
            values: Box::default(),
        };
        let mut values = vec![[0.0f64; 4]; (basis.size.0 * basis.size.1) as usize];
        for (&w, &value) in wedge.iter().zip(psi) {
            let mut y = w;
            for _ in 0..6 {
                for image in [y, reflect(y)] {
                    if let Some(i) = basis.index(image) {
                        values[i][0] = value;
                    }
                }
                y = rotate(y);
            }
        }
        type Map = fn((i64, i64)) -> (i64, i64);
        let images: [Map; 4] = [
            |q| q,
            reflect,
            |q| (-q.0, -q.1),
            |q| {
                let m = reflect(q);
                (-m.0, -m.1)
            },
        ];
        // `psi_2` at `rho x` is written with `psi_1` at `x`, so the last value written there is
        // `psi_1`'s last at `x` too.
        for (image, sign) in images.into_iter().zip([1.0, 1.0, -1.0, -1.0]).rev() {
            for (&q, &value) in quarter.iter().zip(psi_1) {
                let x = image(q);
                if let Some(i) = basis.index(x) {
                    values[i][1] = sign * value;
                }
                if let Some(i) = basis.index(rotate(x)) {
                    values[i][2] = sign * value;
                }
            }
        }
        basis.values = values.into_boxed_slice();
        Some(basis)
    }

    /// The box index of `k`, if inside the box.
    #[inline]
    fn index(&self, k: (i64, i64)) -> Option<usize> {
        let (a, b) = (k.0 - self.low.0, k.1 - self.low.1);
        if a < 0 || a >= self.size.0 || b < 0 || b >= self.size.1 {
            return None;
        }
        Some((b * self.size.0 + a) as usize)
    }

    /// `[psi, psi_1, psi_2, 0]` at `k/d`.
    #[inline]
    fn at(&self, k: (i64, i64)) -> Lanes {
        self.index(k)
            .and_then(|i| self.values.get(i))
            .copied()
            .unwrap_or([0.0; 4])
    }
}

/// `psi` and its skew-axis derivatives on the grid `1/3n` as √3's boundary patches read them
/// (`schemes::sqrt3_boundary_surface`).
impl schemes::sqrt3_boundary_surface::RegularBasis for RateBasis {
    fn denominator(&self) -> i64 {
        self.d
    }

    fn support_box(&self, _: schemes::loop_regular::RegularDerivative) -> ((i64, i64), (i64, i64)) {
        (
            (self.low.0, self.low.0 + self.size.0 - 1),
            (self.low.1, self.low.1 + self.size.1 - 1),
        )
    }

    fn value(&self, what: schemes::loop_regular::RegularDerivative, k: (i64, i64)) -> f64 {
        use schemes::loop_regular::RegularDerivative;
        let lanes = self.at(k);
        match what {
            RegularDerivative::Position => lanes[0],
            RegularDerivative::U => lanes[1],
            RegularDerivative::V => lanes[2],
        }
    }
}

/// A region's tile rows and, in the corner region, `A`'s columns, without their zero entries
/// (about 60% of the rows' entries): read once per region, shared by its kinds and rates.
#[derive(Debug)]
struct SparseRows {
    /// The nonzero entries `(c, R[u][c])` of the tile row of each regular point `u`, `c`
    /// ascending: `entries[starts[u]..starts[u + 1]]`.
    starts: Vec<usize>,
    entries: Vec<(u8, f64)>,
    /// The nonzero entries `(i, A[i][c])` of each column `c` of `A`, `i` ascending
    /// (`a_entries[a_starts[c]..a_starts[c + 1]]`); region 0 only (empty otherwise).
    a_starts: Vec<usize>,
    a_entries: Vec<(usize, f64)>,
}

impl SparseRows {
    /// The nonzero entries of the `k`-wide rows of `rows` and of the columns of the `k x k`
    /// matrix `a` (empty: none).
    fn new(rows: &[f64], a: &[f64], k: usize) -> Self {
        let mut sparse = SparseRows {
            starts: vec![0],
            entries: Vec::new(),
            a_starts: Vec::new(),
            a_entries: Vec::new(),
        };
        for row in rows.chunks_exact(k) {
            // `k <= MAX_REGION_WIDTH = 256` (checked by the caller): `c` fits a byte.
            sparse.entries.extend(
                row.iter()
                    .enumerate()
                    .filter(|&(_, &x)| x != 0.0)
                    .map(|(c, &x)| (c as u8, x)),
            );
            sparse.starts.push(sparse.entries.len());
        }
        if !a.is_empty() {
            sparse.a_starts.push(0);
            for c in 0..k {
                sparse
                    .a_entries
                    .extend((0..k).map(|i| (i, a[i * k + c])).filter(|&(_, x)| x != 0.0));
                sparse.a_starts.push(sparse.a_entries.len());
            }
        }
        sparse
    }

    /// Row `u`'s nonzero entries.
    #[inline]
    fn row(&self, u: usize) -> &[(u8, f64)] {
        &self.entries[self.starts[u]..self.starts[u + 1]]
    }

    /// Column `c` of `A`'s nonzero entries.
    #[inline]
    fn a_column(&self, c: usize) -> &[(usize, f64)] {
        &self.a_entries[self.a_starts[c]..self.a_starts[c + 1]]
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
    /// Per rate (the slots' order), the regular basis spread on its support box, made on
    /// first use.
    bases: Vec<OnceLock<RateBasis>>,
    /// The valences with a subdivision matrix, ascending, and their region geometry, fetched
    /// on first use ([`cone_regions`], shared with the isolation).
    geometry: Vec<(u32, OnceLock<Arc<ConeRegions>>)>,
    /// Per patch (the slots' order), its sparse tile rows (and `A`), read on first use.
    rows: Vec<OnceLock<SparseRows>>,
    /// The expansion's working buffers, kept between grids (a thread that finds them taken
    /// makes its own).
    buffers: Mutex<Option<Box<Buffers>>>,
}

/// The working buffers of an expansion: 20 KiB, allocated and zeroed once per table rather
/// than per grid.
#[derive(Debug)]
struct Buffers {
    /// A stencil's weights per control point, and the corner's next ones.
    row: Width,
    scratch: Width,
    /// The stencil rounded, per kind.
    rounded: [[f32; MAX_REGION_WIDTH]; 3],
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
            rows: (0..slots.patches.len()).map(|_| OnceLock::new()).collect(),
            buffers: Mutex::new(None),
            slots,
            geometry: valences,
        }))
    }

    /// The grid stencils of `key` (a triangle primal or dual section), expanded on first use
    /// from `bytes`, the bytes `index` was parsed from. `None` if the table cannot expand it.
    /// The first grid of a rate spreads its basis on the support box, the first of a region
    /// reads its rows; both are kept for the region's other kinds and the rate's other
    /// regions.
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
        if let Some(grids) = slot.grids.get() {
            return Some(Ok(&*grids[usize::from(!primal)]));
        }
        let geometry = self
            .geometry
            .binary_search_by_key(&key.faces, |v| v.0)
            .ok()
            .map(|v| &self.geometry[v].1)?;
        // Every plan reads the three kinds of a patch and rate together: they are expanded
        // together, sharing the tile search, the basis lookups and the pass over the rows.
        let kinds = KINDS.map(|kind| self.slots.slot(&SectionKey { kind, ..*key }));
        Some(
            slot.grids
                .get_or_try(|| {
                    let regions = geometry.get_or_try(|| cone_regions(self.name, key.faces))?;
                    let basis = self.bases[slot.rate]
                        .get_or_try(|| self.rate_basis(index, bytes, key.n))?;
                    let [position, du, dv] = Region::read(
                        index,
                        bytes,
                        key,
                        slot.k,
                        regions,
                        &self.rows[slot.patch],
                        basis,
                    )?
                    .grids(key.n, &self.buffers)?;
                    let mut asked = None;
                    for (grids, kind) in [position, du, dv].into_iter().zip(KINDS) {
                        if kind == key.kind {
                            asked = Some(grids);
                        } else if let Some(other) = &kinds[kind as usize] {
                            // Another thread may have filled it: the same bytes.
                            let _ = other.grids.get_or_init(|| grids);
                        }
                    }
                    asked.ok_or_else(|| incomplete(format!("{key} is of no kind expanded")))
                })
                .map(|grids| &*grids[usize::from(!primal)]),
        )
    }

    /// Rate `n`'s regular basis on the grid `1/3n`, spread on first use and kept (what the
    /// grids of the rate read too); `None` if the table has no basis at `n`.
    pub(super) fn regular_basis(
        &self,
        index: &TableIndex,
        bytes: &[u8],
        n: u32,
    ) -> Option<Result<&RateBasis, RuntimeError>> {
        let rate = match self.slots.rate_index.get(n as usize) {
            Some(&i) if i != u32::MAX => i as usize,
            _ => return None,
        };
        Some(self.bases[rate].get_or_try(|| self.rate_basis(index, bytes, n)))
    }

    /// Rate `n`'s regular basis spread on its support box from the table's canonical values.
    fn rate_basis(
        &self,
        index: &TableIndex,
        bytes: &[u8],
        n: u32,
    ) -> Result<RateBasis, RuntimeError> {
        let psi = index.weights_f64(bytes, &basis_key(StencilKind::Position, n))?;
        let psi_1 = index.weights_f64(bytes, &basis_key(StencilKind::DerivativeU, n))?;
        RateBasis::spread(&self.scheme, n, psi, psi_1).ok_or_else(|| {
            let mask = self.scheme.regular_mask();
            let hull = mask.hull();
            incomplete(format!(
                "the regular basis at rate {n} has {} and {} values, not the {} wedge and {} \
                 quarter points of its support",
                psi.len(),
                psi_1.len(),
                wedge_points(&hull, mask.dilation, 3 * n).len(),
                quarter_points(&hull, mask.dilation, 3 * n).len()
            ))
        })
    }
}

/// The stencil kinds, in their numbering's order.
const KINDS: [StencilKind; 3] = [
    StencilKind::Position,
    StencilKind::DerivativeU,
    StencilKind::DerivativeV,
];

/// A control point's weights of the three kinds (position, d/du, d/dv) and a fourth, zero
/// lane: four lanes are two pairs of f64 to the vector unit, each lane's operations the
/// scalar ones.
type Lanes = [f64; 4];

/// The widest region the expansion takes: its rows' column indices are bytes, and indexing a
/// buffer of this many control points by a byte needs no bounds check. (The tessellator
/// takes patches of at most 40 points; a region of valence `K` has about `3K + 9`.)
const MAX_REGION_WIDTH: usize = 256;

/// The weights of a region's control points, [`MAX_REGION_WIDTH`] long (the first `K` used).
type Width = [Lanes; MAX_REGION_WIDTH];

/// One region's pieces for one rate, checked against the region geometry.
struct Region<'a> {
    /// Which region.
    r: usize,
    /// The region's width (layout size).
    k: usize,
    /// The valence's regions (the corner's dilation and level scale).
    regions: &'a ConeRegions,
    /// The region.
    region: &'a ConeRegion,
    /// Its tile rows and, region 0 only, `A`.
    rows: &'a SparseRows,
    /// The masks at `V` of the three kinds, region 0 only (empty otherwise).
    vertex: [&'a [f64]; 3],
    basis: &'a RateBasis,
}

impl<'a> Region<'a> {
    /// The pieces of `key`'s region (`k` wide), its rows read into `rows` if not yet there.
    fn read(
        index: &TableIndex,
        bytes: &'a [u8],
        key: &SectionKey,
        k: usize,
        regions: &'a ConeRegions,
        rows: &'a OnceLock<SparseRows>,
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
        // Read (and its shape checked against the geometry) before the masks' widths are.
        let rows = rows.get_or_try(|| Self::read_rows(index, bytes, key, k, region))?;
        let mut vertex = [&[][..]; 3];
        if region.is_corner() {
            for (mask, kind) in vertex.iter_mut().zip(KINDS) {
                *mask = index
                    .weights_f64(bytes, &valence_key(kind, PointSet::VertexMask, key.faces))?;
                if mask.len() != k {
                    return Err(incomplete(format!(
                        "valence {}'s A or mask at V is not of the corner's width {k}",
                        key.faces
                    )));
                }
            }
        }
        Ok(Region {
            r,
            k,
            regions,
            region,
            rows,
            vertex,
            basis,
        })
    }

    /// The region's tile rows and (region 0) `A`, their shapes checked.
    fn read_rows(
        index: &TableIndex,
        bytes: &[u8],
        key: &SectionKey,
        k: usize,
        region: &ConeRegion,
    ) -> Result<SparseRows, RuntimeError> {
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
        if k > MAX_REGION_WIDTH {
            return Err(RuntimeError::Unsupported(format!(
                "{rows_key}: a region of {k} control points; the expansion takes at most \
                 {MAX_REGION_WIDTH}"
            )));
        }
        let a = if region.is_corner() {
            let a = index.weights_f64(
                bytes,
                &valence_key(StencilKind::Position, PointSet::Subdivision, key.faces),
            )?;
            if a.len() != k * k {
                return Err(incomplete(format!(
                    "valence {}'s A or mask at V is not of the corner's width {k}",
                    key.faces
                )));
            }
            a
        } else {
            &[][..]
        };
        // The zero entries are skipped as `stencilgen`'s evaluation skips them, so sparse rows
        // give the same sums in the same order.
        Ok(SparseRows::new(rows, a, k))
    }

    /// Both grids of the three kinds at rate `n` (module docs), rounded to f32.
    fn grids(
        &self,
        n: u32,
        pool: &Mutex<Option<Box<Buffers>>>,
    ) -> Result<[Grids; 3], RuntimeError> {
        if !(1..=MAX_COMPACT_RATE).contains(&n) {
            return Err(incomplete(format!(
                "rate {n} is outside 1..={MAX_COMPACT_RATE}"
            )));
        }
        let n = i64::from(n);
        let k = self.k;
        // A panic while the lock was held leaves buffers whose contents are never read
        // before being written.
        let lock = || pool.lock().unwrap_or_else(|e| e.into_inner());
        let taken = lock().take();
        let mut buffers = taken.unwrap_or_else(|| {
            Box::new(Buffers {
                row: [[0.0; 4]; MAX_REGION_WIDTH],
                scratch: [[0.0; 4]; MAX_REGION_WIDTH],
                rounded: [[0.0; MAX_REGION_WIDTH]; 3],
            })
        });
        let Buffers {
            row,
            scratch,
            rounded,
        } = &mut *buffers;
        let mut hint = 0;
        // Point `p`'s stencils appended to each kind's grid.
        let mut eval = |p: (i64, i64), grids: &mut [Vec<f32>; 3]| -> Result<(), RuntimeError> {
            self.stencil(p, row, scratch, &mut hint)?;
            let [r0, r1, r2] = rounded;
            for (((w, a), b), c) in row[..k].iter().zip(&mut *r0).zip(&mut *r1).zip(&mut *r2) {
                (*a, *b, *c) = (w[0] as f32, w[1] as f32, w[2] as f32);
            }
            for (grid, r) in grids.iter_mut().zip(&*rounded) {
                grid.extend_from_slice(&r[..k]);
            }
            Ok(())
        };
        // The primal grid (3i/3n, 3j/3n), i + j <= n, j outer.
        let count = ((n + 1) * (n + 2) / 2) as usize * k;
        let mut primal: [Vec<f32>; 3] = std::array::from_fn(|_| Vec::with_capacity(count));
        for j in 0..=n {
            for i in 0..=n - j {
                eval((3 * i, 3 * j), &mut primal)?;
            }
        }
        // The centroids over 3n in table order: row j, up(0, j), down(0, j), up(1, j), ...
        let count = (n * n) as usize * k;
        let mut dual: [Vec<f32>; 3] = std::array::from_fn(|_| Vec::with_capacity(count));
        for j in 0..n {
            for i in 0..n - j {
                eval((3 * i + 1, 3 * j + 1), &mut dual)?;
                if i + j + 2 <= n {
                    eval((3 * i + 2, 3 * j + 2), &mut dual)?;
                }
            }
        }
        *lock() = Some(buffers);
        let [p0, p1, p2] = primal.map(Vec::into_boxed_slice);
        let [d0, d1, d2] = dual.map(Vec::into_boxed_slice);
        Ok([[p0, d0], [p1, d1], [p2, d2]])
    }

    /// The stencils of the three kinds at `(i/d, j/d)`, `d = 3n`, into `out` (`scratch`:
    /// another `K` entries; `hint`: the tile of the previous point)
    /// (`stencilgen::cone_regions`' `ConeRegionStencils::stencil`, each kind's operations in
    /// its order).
    fn stencil(
        &self,
        (i, j): (i64, i64),
        out: &mut Width,
        scratch: &mut Width,
        hint: &mut usize,
    ) -> Result<(), RuntimeError> {
        let d = self.basis.d;
        if !self.region.is_corner() {
            return self.tile(self.region.triangle.chart_point(i, j, d), out, hint);
        }
        if (i, j) == (0, 0) {
            for (c, w) in out[..self.k].iter_mut().enumerate() {
                let [p, du, dv] = self.vertex.map(|mask| mask[c]);
                *w = [p, du, dv, 0.0];
            }
            return Ok(());
        }
        let l = i64::from(self.regions.corner.dilation());
        let (mut x, mut steps) = ((i, j), 0u32);
        while l * (x.0 + x.1) <= d {
            x = (l * x.0, l * x.1);
            steps += 1;
        }
        self.tile(x, out, hint)?;
        // phi(x) = phi(λx) A, `steps` times; times λ per step for a derivative.
        let lambda = l as f64;
        for _ in 0..steps {
            for (c, next) in scratch[..self.k].iter_mut().enumerate() {
                // Over the rows i ascending where both factors are nonzero, as `stencilgen`
                // sums them.
                let mut sum = [0.0f64; 4];
                for &(i, a) in self.rows.a_column(c) {
                    for (s, &x) in sum.iter_mut().zip(&out[i]) {
                        if x != 0.0 {
                            *s += x * a;
                        }
                    }
                }
                *next = [sum[0], sum[1] * lambda, sum[2] * lambda, 0.0];
            }
            out[..self.k].copy_from_slice(&scratch[..self.k]);
        }
        Ok(())
    }

    /// The tile formula of the three kinds at the chart point `c / d` of the region (module
    /// docs), into `out`. A kind's weight of a tile point that is zero is not skipped as
    /// `stencilgen` skips it: adding its products (zeros) to sums that started at `+0` leaves
    /// every sum's bits as they were (a sum is `-0` only if both terms are).
    fn tile(&self, c: (i64, i64), out: &mut Width, hint: &mut usize) -> Result<(), RuntimeError> {
        let region = self.region;
        let d = self.basis.d;
        let scale = self.regions.corner.family.scale(region.tile_level);
        let y = (scale * c.0, scale * c.1);
        // The first tile holding `y`: the previous point's if `y` is inside it (tiles do not
        // overlap, so no other holds it), else the search.
        let inside = region
            .tiles
            .get(*hint)
            .is_some_and(|t| strictly_inside(&t.corners, y, d));
        if !inside {
            *hint = region.tile_containing(y, d).ok_or_else(|| {
                incomplete(format!(
                    "({}/{d}, {}/{d}) (level {}) is in no regular tile of region {}",
                    y.0, y.1, region.tile_level, self.r
                ))
            })?;
        }
        // D_w psi = w_1 psi_1 + w_2 psi_2 along the axes, times λ^L for the level-L
        // coordinates (a zero term is not added).
        let along = |(w1, w2): (i64, i64)| {
            [
                (w1 != 0, (w1 * scale) as f64),
                (w2 != 0, (w2 * scale) as f64),
            ]
        };
        let [e1, e2] = region.triangle.axes();
        let (along_1, along_2) = (along(e1), along(e2));
        let derivative = |[(has_1, f_1), (has_2, f_2)]: [(bool, f64); 2], v: &Lanes| {
            let mut w = 0.0;
            if has_1 {
                w += f_1 * v[1];
            }
            if has_2 {
                w += f_2 * v[2];
            }
            w
        };
        out[..self.k].fill([0.0; 4]);
        for &u in &region.tiles[*hint].points {
            let Some(&(j1, j2)) = region.regular_points.get(u) else {
                continue;
            };
            let v = self.basis.at((y.0 - d * j1, y.1 - d * j2));
            let w = [v[0], derivative(along_1, &v), derivative(along_2, &v), 0.0];
            if w == [0.0; 4] {
                continue;
            }
            for &(c, rw) in self.rows.row(u) {
                for (o, w) in out[usize::from(c)].iter_mut().zip(w) {
                    *o += w * rw;
                }
            }
        }
        Ok(())
    }
}

/// Whether `(y_1/d, y_2/d)` is strictly inside the triangle `corners` (counter-clockwise;
/// `schemes::cone_local::RegularTile::contains` for the closed triangle).
fn strictly_inside(corners: &[(i64, i64); 3], y: (i64, i64), d: i64) -> bool {
    (0..3).all(|e| {
        let (p, q) = (corners[e], corners[(e + 1) % 3]);
        (q.0 - p.0) * (y.1 - d * p.1) - (q.1 - p.1) * (y.0 - d * p.0) > 0
    })
}

// The test reads the embedded region tables.
#[cfg(all(test, feature = "butterfly", feature = "sqrt3"))]
mod tests {
    use super::*;
    use schemes::lattice_symmetry::{rotate_back, to_quarter, to_wedge};
    use std::collections::HashMap;

    /// The basis spread on the support box is, bit for bit, what the canonical lookups give
    /// (`psi` at the wedge image `to_wedge(k)`, `psi_1` at the quarter image `to_quarter(k)`
    /// times its sign, `psi_2(k) = psi_1(rho^-1 k)`, zero where the image is no stored point)
    /// at every point of the box and of a margin around it: both embedded tables, rates 1..=8
    /// and 24.
    #[test]
    fn the_spread_basis_is_the_canonical_lookups() {
        for (name, table) in [
            ("butterfly", super::super::StencilTable::default_butterfly()),
            ("sqrt3", super::super::StencilTable::default_sqrt3()),
        ] {
            let table = table.expect("embedded table");
            let (bytes, index) = (table.bytes(), table.index());
            let scheme = TriangleScheme::by_name(name).expect("catalogued");
            let mask = scheme.regular_mask();
            let hull = mask.hull();
            for n in (1..=8).chain([24]) {
                let d = 3 * n;
                let psi = index
                    .weights_f64(bytes, &basis_key(StencilKind::Position, n))
                    .expect("psi");
                let psi_1 = index
                    .weights_f64(bytes, &basis_key(StencilKind::DerivativeU, n))
                    .expect("psi_1");
                let basis = RateBasis::spread(&scheme, n, psi, psi_1).expect("counts");
                let wedge: HashMap<_, _> = wedge_points(&hull, mask.dilation, d)
                    .into_iter()
                    .zip(psi.iter().copied())
                    .collect();
                let quarter: HashMap<_, _> = quarter_points(&hull, mask.dilation, d)
                    .into_iter()
                    .zip(psi_1.iter().copied())
                    .collect();
                let canonical_psi = |k| wedge.get(&to_wedge(k)).copied().unwrap_or(0.0);
                let canonical_psi_1 = |k| {
                    let (q, sign) = to_quarter(k);
                    quarter.get(&q).map_or(0.0, |v| sign * v)
                };
                let ((l1, h1), (l2, h2)) = support_box(&hull, mask.dilation, d);
                let mut nonzero = [0usize; 3];
                for k2 in l2 - 3..=h2 + 3 {
                    for k1 in l1 - 3..=h1 + 3 {
                        let k = (k1, k2);
                        let want = [
                            canonical_psi(k),
                            canonical_psi_1(k),
                            canonical_psi_1(rotate_back(k)),
                            0.0,
                        ];
                        let got = basis.at(k);
                        assert_eq!(
                            got.map(f64::to_bits),
                            want.map(f64::to_bits),
                            "{name} at rate {n}, {k:?}: {got:?} vs {want:?}"
                        );
                        for (count, w) in nonzero.iter_mut().zip(want) {
                            *count += usize::from(w != 0.0);
                        }
                    }
                }
                // Not vacuous: every nonzero stored value is met at least at its own point.
                let stored = |v: &[f64]| v.iter().filter(|&&w| w != 0.0).count();
                assert!(stored(psi) > 0 && stored(psi_1) > 0, "{name} at rate {n}");
                assert!(nonzero[0] >= stored(psi), "{name} at rate {n}");
                assert!(
                    nonzero[1].min(nonzero[2]) >= stored(psi_1),
                    "{name} at rate {n}"
                );
            }
        }
    }
}
