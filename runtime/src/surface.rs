//! The facade: a [`Surface`] is a mesh's topology prepared once for one scheme (validated,
//! isolated, its patches gathered, its tables loaded); [`Surface::tessellator`] plans a
//! tessellation at some [`Rates`]; [`Tessellator::evaluate`] turns the *input* control points
//! of one frame into a [`Frame`].
//!
//! The per-frame path never refines. Isolation's refinement steps are linear in the control
//! points, so they are composed once into one sparse map from the input vertices to the isolated
//! mesh's vertices ([`crate::scheme::stencil::Stencil`]); a frame applies that map (a few dozen
//! multiply-adds per isolated vertex, in f64; at rate 4 only the rows of the faces that the
//! plan does not evaluate from their input face's own points) and then the table stencils of
//! the plan (in f32,
//! on every patch's control points relative to one of them, so that tangents and normals do
//! not depend on where the mesh sits: docs/reliability.md, *Precision*).

use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use std::time::Instant;

use rayon::prelude::*;

use crate::budget::OutputEstimate;
use crate::mesh::face_varying::FaceVaryingMode;
use crate::mesh::triangle_mesh::TriangleMesh;
use crate::mesh::{Mesh, VertexSource};
use crate::once::TryOnce;
use crate::scheme::catmull_clark::face_varying::ChannelIsolation;
use crate::scheme::catmull_clark::isolate::{isolate_with_origins, Isolation};
use crate::scheme::loop_scheme::isolate::isolate_loop;
use crate::scheme::region_isolate::isolate_regions;
use crate::scheme::sqrt3::boundary_grids::Sqrt3BoundaryStencils;
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::isolation::TriangleIsolation;
use crate::scheme::triangle::region_patch::RegionScheme;
use crate::scheme::Scheme;
use crate::stencil_table::StencilTable;
use crate::tessellate::dual_grid::{DualGrid, MAX_RATE};
use crate::tessellate::lai_cheng::{
    check_input, tessellate_adaptive_with, AdaptiveMesh, AdaptiveOptions, AdaptiveStats,
    PatchOperators,
};
use crate::tessellate::rate_memory::{QuadSelection, RateMemory};
use crate::tessellate::rates::{adaptive_face_list, view_rates, ViewCamera, RATIONAL_RATES};
use crate::tessellate::triangle_dual_grid::TriangleDualGrid;
use crate::tessellate::triangle_rates::{
    triangle_table_rates, TriangleSampling, TriangleSelection,
};
use crate::tessellate::{total_bytes, vec_bytes, GridPlan};
use crate::RuntimeError;

/// How finely to tessellate: points per face side, on every face or chosen per face.
#[derive(Clone, Debug, PartialEq)]
pub enum Rates {
    /// Rate `n` on every face: 1..=24 with the default Catmull–Clark and Loop tables, 1..=8
    /// with the butterfly's and √3's (a rate the table lacks is refused by name).
    Uniform(u32),
    /// One rate per **input** face, in OBJ face order; faces made by isolation inherit their
    /// input face's rate.
    PerFace(Vec<u32>),
    /// Per face the smallest rate whose tessellation deviates from the limit surface by at most
    /// this distance (in the mesh's units), measured on the surface's positions: the mesh's
    /// given to [`Surface::new`], or those set since ([`Surface::set_positions`])
    /// (docs/results.md, docs/cli.md).
    Tolerance(f64),
    /// Per face the projected size over a target edge length in pixels (docs/cli.md).
    View(ViewCamera),
}

/// The isolated mesh of either family of schemes.
#[derive(Debug)]
enum Isolated {
    Quad(Isolation),
    Triangle(TriangleIsolation),
}

/// A subdivision surface: one mesh's topology prepared for one scheme. Build it once per
/// topology; positions may change every frame ([`Tessellator::evaluate`], and
/// [`Surface::set_positions`] where the rates follow them).
///
/// ```
/// let mesh = subtess::Mesh::read_obj(concat!(env!("CARGO_MANIFEST_DIR"), "/data/cube.obj"))?;
/// let surface = subtess::Surface::new(&mesh, subtess::Scheme::CatmullClark)?;
/// let mut tessellator = surface.tessellator(&subtess::Rates::Uniform(4))?;
/// let frame = tessellator.evaluate(&mesh.positions_f32())?;
/// assert_eq!(frame.positions().len(), frame.normals().len());
/// assert!(frame.triangles().iter().flatten().all(|&i| (i as usize) < frame.positions().len()));
/// # Ok::<(), subtess::RuntimeError>(())
/// ```
#[derive(Debug)]
pub struct Surface {
    scheme: Scheme,
    table: StencilTable,
    isolated: Isolated,
    input_vertices: usize,
    input_faces: usize,
    boundary_loops: usize,
    /// Whether the isolated control points are the input's refined ([`Surface::refinement`]):
    /// isolation took steps or split vertices.
    refines: bool,
    /// The texture coordinates' channel (Catmull–Clark), refined as the positions were.
    channel: Option<ChannelIsolation>,
    isolation_seconds: f64,
    /// Lai–Cheng's patch-kind operators, made by the first [`Surface::tessellate_adaptive`]
    /// and kept (they depend on the topology only, which [`Surface::set_positions`] keeps).
    adaptive_operators: Mutex<Option<Arc<PatchOperators>>>,
    /// The last tolerance selection, what lets the next frame keep the rates
    /// of faces that moved almost rigidly ([`RateMemory`]).
    rate_memory: Mutex<Option<RateMemory>>,
    /// A triangle mesh's sampling grid and sample templates, and a quad mesh's faces sampled
    /// adaptively, found by the first tolerance selection and kept (the table's and the
    /// topology's alone).
    triangle_sampling: OnceLock<TriangleSampling>,
    quad_adaptive_faces: OnceLock<Vec<usize>>,
    /// The output buffers and the plan of the last [`Tessellator`] dropped, for the next plan to
    /// fill or, at the same rates, to take whole.
    frame_buffers: Mutex<FrameBuffers>,
}

/// A tessellator's output buffers and its vertices' sources, kept by its surface when it is
/// dropped ([`FrameBuffers::KEPT`] bytes at most), with its plan where that is small enough
/// too: an animation at a tolerance plans every frame, and buffers of a frame's size allocated
/// afresh each time had their pages faulted in and zeroed again every frame; and most frames of
/// a mesh at rest, moving rigidly or bending a little keep every face's rate, and so the plan.
#[derive(Debug, Default)]
struct FrameBuffers {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    sources: Vec<VertexSource>,
    /// The plan whose triangles and sources these are.
    plan: Option<KeptPlan>,
}

/// A plan kept for the next tessellator at the same rates. The plan, its triangles, sources,
/// texture coordinates and seam copies depend on the rates, the topology and the table alone,
/// none of which a surface changes after it is made ([`Surface::set_positions`] moves points
/// only): the same rates, the same plan.
#[derive(Debug)]
struct KeptPlan {
    rates: Vec<u32>,
    grid: Box<dyn GridPlan>,
    uvs: Vec<[f32; 2]>,
    seam_copies: Vec<[u32; 2]>,
}

impl FrameBuffers {
    /// The most a surface keeps (a one-off tessellation larger than this returns its memory).
    const KEPT: usize = 64 << 20;

    /// The buffers' and the plan's heap bytes.
    fn kept_bytes(&self) -> usize {
        let plan = self.plan.as_ref().map_or(0, |plan| {
            total_bytes([
                vec_bytes(&plan.rates),
                plan.grid.heap_bytes(),
                vec_bytes(&plan.uvs),
                vec_bytes(&plan.seam_copies),
            ])
        });
        self.bytes().saturating_add(plan)
    }

    /// The buffers' capacity in bytes.
    fn bytes(&self) -> usize {
        total_bytes([
            vec_bytes(&self.positions),
            vec_bytes(&self.normals),
            vec_bytes(&self.triangles),
            vec_bytes(&self.sources),
        ])
    }
}

impl Surface {
    /// Validate `mesh` for `scheme`, isolate its irregular vertices and gather its patches,
    /// with the scheme's embedded default table.
    pub fn new(mesh: &Mesh, scheme: Scheme) -> Result<Surface, RuntimeError> {
        Self::with_table(mesh, scheme, scheme.default_table(mesh.boundary)?)
    }

    /// [`Surface::new`] with another table (one written by `stencilgen tables` for `scheme`).
    pub fn with_table(
        mesh: &Mesh,
        scheme: Scheme,
        table: StencilTable,
    ) -> Result<Surface, RuntimeError> {
        scheme.check_table(&table)?;
        if scheme != Scheme::CatmullClark && !mesh.copies.is_empty() {
            return Err(RuntimeError::Unsupported(format!(
                "non-manifold topology with --scheme {scheme} (catmull-clark splits it as OpenSubdiv does)"
            )));
        }
        let started = Instant::now();
        let isolated = match scheme {
            Scheme::CatmullClark => Isolated::Quad(isolate_with_origins(mesh)?),
            Scheme::Loop => Isolated::Triangle(isolate_loop(mesh)?),
            Scheme::Butterfly => {
                Isolated::Triangle(isolate_regions(mesh, RegionScheme::Butterfly)?)
            }
            Scheme::Sqrt3 => Isolated::Triangle(isolate_regions(mesh, RegionScheme::Sqrt3)?),
        };
        let steps = match &isolated {
            Isolated::Quad(iso) => iso.steps,
            Isolated::Triangle(iso) => iso.steps,
        };
        // Without steps and split vertices the input points are the control points.
        let refines = steps > 0 || !mesh.copies.is_empty();
        let channel = match &isolated {
            Isolated::Quad(iso) => ChannelIsolation::new(mesh, iso)?,
            Isolated::Triangle(_) => None,
        };
        Ok(Surface {
            channel,
            scheme,
            table,
            input_vertices: mesh.input_vertices(),
            input_faces: mesh.faces(),
            boundary_loops: mesh.boundary_loops(),
            refines,
            isolation_seconds: started.elapsed().as_secs_f64(),
            isolated,
            adaptive_operators: Mutex::new(None),
            rate_memory: Mutex::new(None),
            frame_buffers: Mutex::new(FrameBuffers::default()),
            triangle_sampling: OnceLock::new(),
            quad_adaptive_faces: OnceLock::new(),
        })
    }

    /// The scheme.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The stencil table the surface reads.
    pub fn table(&self) -> &StencilTable {
        &self.table
    }

    /// Number of input vertices: the length [`Tessellator::evaluate`] wants.
    pub fn input_vertices(&self) -> usize {
        self.input_vertices
    }

    /// Number of input faces.
    pub fn input_faces(&self) -> usize {
        self.input_faces
    }

    /// Number of faces after isolation (the patches a tessellation evaluates).
    pub fn faces(&self) -> usize {
        self.mesh().faces()
    }

    /// Refinement steps isolation took (0 when every input face is a table patch).
    pub fn isolation_steps(&self) -> usize {
        match &self.isolated {
            Isolated::Quad(iso) => iso.steps,
            Isolated::Triangle(iso) => iso.steps,
        }
    }

    /// Wall time of isolation: the refinement steps, the patch gathering of each attempt, and
    /// composing the refinement map.
    pub fn isolation_seconds(&self) -> f64 {
        self.isolation_seconds
    }

    /// Whether tessellations carry texture coordinates: the mesh has a face-varying channel
    /// ([`Mesh::face_varying`]) and the scheme is Catmull–Clark (the triangle schemes ignore
    /// it).
    pub fn has_uvs(&self) -> bool {
        self.channel.is_some()
    }

    /// Number of boundary loops of the input (0: closed, and a watertight output is expected).
    pub fn boundary_loops(&self) -> usize {
        self.boundary_loops
    }

    /// Weights of the map from input to isolated control points (0 when none is needed): the
    /// per-frame cost isolation adds.
    pub fn refinement_weights(&self) -> usize {
        self.refinement().map_or(0, Stencil::entries)
    }

    /// The heap bytes the surface keeps from its last dropped [`Tessellator`] for the next
    /// one: the output buffers and vertex sources, which the next plan fills, and the plan,
    /// which the next tessellator at the same rates takes whole (64 MiB at most each; none
    /// after [`Surface::trim`]).
    pub fn kept_bytes(&self) -> usize {
        self.frame_buffers
            .lock()
            .map_or(0, |kept| kept.kept_bytes())
    }

    /// Free what the surface keeps from one frame to the next to make the next one faster: the
    /// last dropped tessellator's buffers and plan ([`Surface::kept_bytes`]) and the last
    /// tolerance selection (the next [`Rates::Tolerance`] samples every face again). What
    /// depends on the topology and the table alone stays (the isolation, the table's expanded
    /// grids, Lai–Cheng's operators). For a surface that sits idle between bursts of frames:
    /// the next frame then costs what the first did, and gives the same output.
    pub fn trim(&self) {
        // A lock poisoned by a panicking frame still guards what is to be freed.
        *self
            .frame_buffers
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = FrameBuffers::default();
        *self
            .rate_memory
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = None;
    }

    /// Move the control points: `positions`, one per **input** vertex in OBJ order, replace
    /// those of the mesh given to [`Surface::new`], refined through isolation's map as a frame's
    /// are. What the surface computes from its own positions afterwards, the rates a
    /// tessellator chooses ([`Rates::Tolerance`], [`Rates::View`]) and
    /// [`Surface::tessellate_adaptive`], is then the moved surface's, what a fresh `Surface` of
    /// the moved mesh gives (up to the last bits of the isolated points, which the map composes
    /// in another order than isolation's steps), without isolating again and with the table's
    /// grids already expanded: set the positions, plan, evaluate, frame after frame, for a mesh
    /// that moves and keeps a tolerance. Refused, and nothing moved, unless there is one finite
    /// point per input vertex.
    pub fn set_positions(&mut self, positions: &[[f32; 3]]) -> Result<(), RuntimeError> {
        check_positions(positions, self.input_vertices)?;
        let input: Vec<[f64; 3]> = positions.iter().map(|p| p.map(f64::from)).collect();
        // The isolated points are written over the last frame's, in their vector: one of the
        // isolated mesh's size allocated afresh had its pages faulted in every frame.
        let mut moved = std::mem::take(&mut self.mesh_mut().positions);
        if !self.control_points(&input, &mut moved) {
            // No map: the input is the control.
            moved = input;
        }
        self.mesh_mut().positions = moved;
        Ok(())
    }

    /// Input vertices to isolated vertices; `None` when isolation took no step.
    fn refinement(&self) -> Option<&Stencil> {
        let map = match &self.isolated {
            Isolated::Quad(iso) => &iso.refinement,
            Isolated::Triangle(iso) => &iso.refinement,
        };
        self.refines.then_some(map)
    }

    /// The isolated mesh (at the positions given to [`Surface::new`] or, since,
    /// [`Surface::set_positions`]).
    fn mesh(&self) -> &Mesh {
        match &self.isolated {
            Isolated::Quad(iso) => &iso.mesh,
            Isolated::Triangle(iso) => &iso.mesh,
        }
    }

    /// [`Surface::mesh`], to move its points.
    fn mesh_mut(&mut self) -> &mut Mesh {
        match &mut self.isolated {
            Isolated::Quad(iso) => &mut iso.mesh,
            Isolated::Triangle(iso) => &mut iso.mesh,
        }
    }

    /// The input face every isolated face lies in.
    fn origin(&self) -> &[u32] {
        match &self.isolated {
            Isolated::Quad(iso) => &iso.origin,
            Isolated::Triangle(iso) => &iso.origin,
        }
    }

    /// Points on isolated faces in their input faces' own parameters, in place, in parallel.
    fn map_to_input(&self, sources: &mut [VertexSource]) {
        match &self.isolated {
            Isolated::Quad(iso) => iso.map_to_input(sources),
            Isolated::Triangle(iso) => sources
                .par_iter_mut()
                .for_each(|s| *s = iso.input_source(*s)),
        }
    }

    /// The isolated mesh's control points for input positions `input` (one per input vertex,
    /// widened to f64: [`GridPlan::evaluate`]), into `out`; `false` (and `out` untouched) when
    /// isolation took no step, so that the input itself is the control.
    fn control_points(&self, input: &[[f64; 3]], out: &mut Vec<[f64; 3]>) -> bool {
        match self.refinement() {
            Some(map) => {
                out.resize(map.rows(), [0.0; 3]);
                map.apply_into(input, out);
                true
            }
            None => false,
        }
    }

    /// The size of a dual-grid tessellation at `rates` (one per isolated face), holes
    /// excluded.
    fn estimate_rates(&self, rates: &[u32]) -> OutputEstimate {
        let holes = &self.mesh().holes;
        let rates = rates
            .iter()
            .enumerate()
            .filter(|&(f, _)| !holes.get(f).copied().unwrap_or(false))
            .map(|(_, &n)| n);
        OutputEstimate::dual_grid(self.scheme.is_triangle(), rates)
    }

    /// Per isolated face rates, and what a tolerance's selection reports.
    fn face_rates(&self, rates: &Rates) -> Result<FaceRates, RuntimeError> {
        let faces = self.faces();
        let check = |n: u32, what: &str| {
            if (1..=MAX_RATE).contains(&n) {
                Ok(n)
            } else {
                Err(RuntimeError::InvalidParameter {
                    name: what.to_owned(),
                    reason: format!("{n} is not a rate in 1..={MAX_RATE}"),
                })
            }
        };
        Ok(match rates {
            Rates::Uniform(n) => FaceRates::given(vec![check(*n, "rate")?; faces]),
            Rates::PerFace(per_input) => {
                if per_input.len() != self.input_faces {
                    return Err(RuntimeError::InvalidParameter {
                        name: "rates".to_owned(),
                        reason: format!(
                            "{} rates for a mesh of {} faces",
                            per_input.len(),
                            self.input_faces
                        ),
                    });
                }
                for (f, &n) in per_input.iter().enumerate() {
                    check(n, &format!("rate of face {f}"))?;
                }
                let rates = self
                    .origin()
                    .iter()
                    .map(|&f| per_input[f as usize])
                    .collect();
                FaceRates::given(rates)
            }
            Rates::Tolerance(t) => {
                if let Isolated::Triangle(iso) = &self.isolated {
                    if self.scheme == Scheme::Sqrt3 && iso.patches.iter().any(|p| p.kind.boundary) {
                        return Err(RuntimeError::Unsupported(
                            "tolerance rates for √3 on a mesh with boundary (use --rate or \
                             per-face rates)"
                                .to_owned(),
                        ));
                    }
                }
                let mut memory = self.rate_memory.lock().map_err(|_| {
                    RuntimeError::Unsupported(
                        "internal: a thread panicked while choosing rates".to_owned(),
                    )
                })?;
                let chosen = match &self.isolated {
                    Isolated::Quad(iso) => {
                        let adaptive = self.quad_adaptive_faces.get_or_try(|| {
                            adaptive_face_list(&self.table, &iso.mesh, &iso.patches)
                        })?;
                        let selection = QuadSelection::new(
                            &self.table,
                            &iso.mesh,
                            &iso.patches,
                            *t,
                            &RATIONAL_RATES,
                        )?
                        .knowing(adaptive);
                        RateMemory::rates(&mut memory, &selection)?
                    }
                    Isolated::Triangle(iso) => {
                        let rates = triangle_table_rates(&self.table);
                        let sampling = self
                            .triangle_sampling
                            .get_or_try(|| TriangleSampling::new(&self.table))?;
                        let selection =
                            TriangleSelection::sharing(&self.table, iso, *t, &rates, sampling)?;
                        RateMemory::rates(&mut memory, &selection)?
                    }
                };
                let sampled = memory.as_ref().map(RateMemory::sampled);
                let unmet = chosen.unmet.len();
                FaceRates {
                    rates: chosen.rates,
                    faces_over_tolerance: Some(unmet),
                    faces_sampled: sampled,
                }
            }
            Rates::View(camera) => FaceRates::given(view_rates(self.mesh(), camera)?),
        })
    }

    /// Plan a dual-grid tessellation at `rates`: table lookups, connectivity and the triangles
    /// (the topology does not change between frames), built once. Refused before anything of
    /// the output's size is allocated when its estimate exceeds
    /// [`crate::DEFAULT_MAX_TRIANGLES`] ([`Surface::tessellator_within`] takes another limit).
    /// Where the rates (chosen now, for a tolerance or a camera) are those of the last
    /// tessellator dropped, its plan is taken whole instead of made again.
    pub fn tessellator(&self, rates: &Rates) -> Result<Tessellator<'_>, RuntimeError> {
        self.tessellator_within(rates, crate::DEFAULT_MAX_TRIANGLES)
    }

    /// [`Surface::tessellator`] with at most about `max_triangles` output triangles: the
    /// output is estimated from the per-face rates ([`OutputEstimate::dual_grid`]) before the
    /// plan is built, and refused above the limit with the estimate in the message.
    pub fn tessellator_within(
        &self,
        rates: &Rates,
        max_triangles: u64,
    ) -> Result<Tessellator<'_>, RuntimeError> {
        let started = Instant::now();
        let FaceRates {
            rates,
            faces_over_tolerance,
            faces_sampled,
        } = self.face_rates(rates)?;
        let rates_seconds = started.elapsed().as_secs_f64();
        self.estimate_rates(&rates)
            .check("the tessellation", max_triangles)?;
        // The last tessellator's buffers where it left them (none when a thread panicked with
        // them: fresh ones then), and its plan if it was made at these rates.
        let FrameBuffers {
            mut positions,
            mut normals,
            mut triangles,
            mut sources,
            plan,
        } = self
            .frame_buffers
            .lock()
            .map(|mut kept| std::mem::take(&mut *kept))
            .unwrap_or_default();
        let (grid, uvs, seam_copies) = match plan.filter(|plan| plan.rates == rates) {
            Some(plan) => (plan.grid, plan.uvs, plan.seam_copies),
            None => {
                let grid = self.plan(&rates)?;
                triangles.clear();
                triangles.resize(grid.triangle_count(), [0; 3]);
                grid.connect(&mut triangles);
                // The channel's limit values read the points on the isolated faces; then every
                // point is mapped to its input face once, in place and in parallel, a map per
                // face (mapped twice, point by point, serially, these took a third of Spot's
                // plan at rate 16).
                grid.sources_into(&mut sources);
                let limit_uvs = match &self.channel {
                    Some(channel) if channel.mode() != FaceVaryingMode::All => {
                        Some(channel.limit_values(&sources)?)
                    }
                    _ => None,
                };
                self.map_to_input(&mut sources);
                let uvs = match (&self.channel, limit_uvs) {
                    (_, Some(uvs)) => uvs,
                    (Some(channel), None) => channel.linear_values(&sources),
                    (None, None) => Vec::new(),
                };
                let seam_copies = grid.seam_copies().to_vec();
                (grid, uvs, seam_copies)
            }
        };
        // Every point is written by `evaluate` before a frame shows it.
        let vertices = grid.vertex_count();
        positions.resize(vertices, [0.0; 3]);
        normals.resize(vertices, [0.0; 3]);
        Ok(Tessellator {
            surface: self,
            grid: Some(grid),
            rates,
            faces_over_tolerance,
            faces_sampled,
            input: Vec::new(),
            control: Vec::new(),
            positions,
            normals,
            triangles,
            sources,
            uvs,
            seam_copies,
            rates_seconds,
            plan_seconds: started.elapsed().as_secs_f64(),
        })
    }

    /// The dual grid's plan at `rates` (one per isolated face), for either family of schemes.
    fn plan(&self, rates: &[u32]) -> Result<Box<dyn GridPlan>, RuntimeError> {
        Ok(match &self.isolated {
            Isolated::Quad(iso) => Box::new(
                DualGrid::with_channel(
                    &self.table,
                    &iso.mesh,
                    &iso.patches,
                    rates,
                    self.channel
                        .as_ref()
                        .map(|c| c.mesh.face_vertices.as_slice()),
                )?
                .with_input_patches(
                    iso.steps,
                    &iso.input_nets,
                    &iso.origin,
                    |f| iso.placement(f),
                    &iso.refinement,
                )?,
            ),
            Isolated::Triangle(iso)
                if iso.patches.iter().any(|p| p.kind.boundary) && self.scheme == Scheme::Sqrt3 =>
            {
                // √3's boundary patches: their grids are made now, from the table's basis.
                let stencils = Sqrt3BoundaryStencils::new(&self.table, &iso.patches, rates)?;
                Box::new(TriangleDualGrid::new(
                    &stencils,
                    &iso.mesh,
                    &iso.patches,
                    rates,
                )?)
            }
            Isolated::Triangle(iso) => Box::new(TriangleDualGrid::new(
                &self.table,
                &iso.mesh,
                &iso.patches,
                rates,
            )?),
        })
    }

    /// Lai and Cheng's error-bounded adaptive tessellation (Catmull–Clark only), its sources in
    /// the input faces' own parameters; sharp features (creases, corners, darts, semi-sharp
    /// tags, holes, boundary modes) are honoured with the same guarantee
    /// ([`crate::tessellate::lai_cheng`], `docs/lai-cheng.md`).
    pub fn tessellate_adaptive(
        &self,
        options: &AdaptiveOptions,
    ) -> Result<(AdaptiveMesh, AdaptiveStats), RuntimeError> {
        let mut out = AdaptiveMesh::default();
        let stats = self.tessellate_adaptive_into(options, &mut out)?;
        out.release_buffers();
        Ok((out, stats))
    }

    /// [`Surface::tessellate_adaptive`] into `out`, whose lists are resized in place and
    /// overwritten, their memory kept: for a mesh that moves every frame, each frame writes the pages the
    /// frame before wrote rather than memory fresh from the system (a tenth of a frame on two
    /// threads, docs/benchmarks.md). On an error `out` holds no tessellation.
    pub fn tessellate_adaptive_into(
        &self,
        options: &AdaptiveOptions,
        out: &mut AdaptiveMesh,
    ) -> Result<AdaptiveStats, RuntimeError> {
        let Isolated::Quad(iso) = &self.isolated else {
            return Err(RuntimeError::Unsupported(format!(
                "--scheme {} tessellates with the dual grid (Lai–Cheng's adaptive method is for catmull-clark)",
                self.scheme
            )));
        };
        // Counted from here: the first call's seconds include making the operators.
        let started = Instant::now();
        check_input(&iso.mesh, &iso.patches, options)?;
        let operators = {
            let mut cached = self.adaptive_operators.lock().map_err(|_| {
                RuntimeError::Unsupported(
                    "internal: a thread panicked while making the adaptive operators".to_owned(),
                )
            })?;
            match &*cached {
                Some(operators) => Arc::clone(operators),
                None => {
                    let made = Arc::new(PatchOperators::new(&iso.mesh, &iso.patches)?);
                    *cached = Some(Arc::clone(&made));
                    made
                }
            }
        };
        let stats = tessellate_adaptive_with(
            &self.table,
            &iso.mesh,
            &iso.patches,
            options,
            &operators,
            started,
            out,
        )?;
        iso.map_to_input(&mut out.sources);
        Ok(stats)
    }
}

/// A planned tessellation of a [`Surface`]: evaluate it once per frame. Dropped, it leaves its
/// output buffers and its vertices' sources (64 MiB at most) to the surface, whose next plan
/// fills them, and its plan (64 MiB at most), which the surface's next tessellator at the same
/// rates takes whole ([`Surface::kept_bytes`] says how much; [`Surface::trim`] frees it).
#[derive(Debug)]
pub struct Tessellator<'s> {
    surface: &'s Surface,
    /// The plan (`None` once it has gone back to the surface, on drop).
    grid: Option<Box<dyn GridPlan>>,
    rates: Vec<u32>,
    faces_over_tolerance: Option<usize>,
    faces_sampled: Option<usize>,
    /// The input points of the current frame, in f64.
    input: Vec<[f64; 3]>,
    /// The isolated control points of the current frame (when isolation took steps).
    control: Vec<[f64; 3]>,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    sources: Vec<VertexSource>,
    /// Texture coordinates (constant: planned once), or empty.
    uvs: Vec<[f32; 2]>,
    seam_copies: Vec<[u32; 2]>,
    rates_seconds: f64,
    plan_seconds: f64,
}

impl Drop for Tessellator<'_> {
    /// The output buffers go back to the surface for its next plan, unless they are large, and
    /// the plan with them, unless it is large.
    fn drop(&mut self) {
        let plan = self
            .grid
            .take()
            .filter(|grid| grid.heap_bytes() <= FrameBuffers::KEPT)
            .map(|grid| KeptPlan {
                rates: std::mem::take(&mut self.rates),
                grid,
                uvs: std::mem::take(&mut self.uvs),
                seam_copies: std::mem::take(&mut self.seam_copies),
            });
        let buffers = FrameBuffers {
            positions: std::mem::take(&mut self.positions),
            normals: std::mem::take(&mut self.normals),
            triangles: std::mem::take(&mut self.triangles),
            sources: std::mem::take(&mut self.sources),
            plan,
        };
        if buffers.bytes() <= FrameBuffers::KEPT {
            if let Ok(mut kept) = self.surface.frame_buffers.lock() {
                *kept = buffers;
            }
        }
    }
}

impl<'s> Tessellator<'s> {
    /// Evaluate one frame from `positions`, one point per **input** vertex in OBJ order: the
    /// limit positions and unit normals of every output vertex. The same positions give the
    /// same frame; deformed positions give what a fresh [`Surface`] of the deformed mesh gives.
    pub fn evaluate(&mut self, positions: &[[f32; 3]]) -> Result<Frame<'_>, RuntimeError> {
        check_positions(positions, self.surface.input_vertices)?;
        self.input.clear();
        self.input
            .extend(positions.iter().map(|p| p.map(f64::from)));
        // Taken only by the tessellator's drop.
        let Some(grid) = &self.grid else {
            return Err(RuntimeError::Unsupported(
                "internal: the tessellator's plan is gone".to_owned(),
            ));
        };
        let control = if let Some(map) = grid.control_map() {
            // The plan's own rows, then the input points it reads itself.
            self.control.resize(map.rows(), [0.0; 3]);
            map.apply_into(&self.input, &mut self.control);
            self.control.extend_from_slice(&self.input);
            self.control.as_slice()
        } else if self.surface.control_points(&self.input, &mut self.control) {
            self.control.as_slice()
        } else {
            self.input.as_slice()
        };
        grid.evaluate(control, &mut self.positions, &mut self.normals);
        Ok(Frame {
            positions: &self.positions,
            normals: &self.normals,
            triangles: &self.triangles,
            sources: &self.sources,
            uvs: &self.uvs,
            seam_copies: &self.seam_copies,
        })
    }

    /// The surface this plan belongs to.
    pub fn surface(&self) -> &'s Surface {
        self.surface
    }

    /// Output vertices per frame.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Output triangles per frame.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The rate of every isolated face.
    pub fn rates(&self) -> &[u32] {
        &self.rates
    }

    /// With [`Rates::Tolerance`]: how many faces do not meet it even at the largest rate (they
    /// get the largest).
    pub fn faces_over_tolerance(&self) -> Option<usize> {
        self.faces_over_tolerance
    }

    /// With [`Rates::Tolerance`]: how many faces the selection sampled. The
    /// first plan of a surface samples every face; after [`Surface::set_positions`], a face
    /// whose neighbourhood moved almost rigidly since it was sampled keeps its rate unsampled
    /// where a bound proves the selection would choose it again (the rates are a fresh
    /// surface's either way; docs/runtime.md).
    pub fn faces_sampled(&self) -> Option<usize> {
        self.faces_sampled
    }

    /// How many faces take a polynomial fast path: quads the separable (tensor-product)
    /// bicubic, Loop triangles one quartic per face (0 for the other triangle schemes).
    pub fn separable_faces(&self) -> usize {
        self.grid.as_ref().map_or(0, |grid| grid.separable_faces())
    }

    /// How many faces are evaluated by feature-adaptive refinement: next to sharp features the
    /// tables do not describe (semi-sharp ones, a crease that turns between two irregular
    /// corners, ...) or at a valence beyond the table (0 for the triangle schemes).
    pub fn refined_faces(&self) -> usize {
        self.grid.as_ref().map_or(0, |grid| grid.refined_faces())
    }

    /// Seconds spent planning (rates, table lookups, connectivity, triangles, sources).
    pub fn plan_seconds(&self) -> f64 {
        self.plan_seconds
    }

    /// Seconds of [`Tessellator::plan_seconds`] spent choosing the rates: a tolerance's
    /// selection or a camera's, next to nothing for rates given.
    pub fn rates_seconds(&self) -> f64 {
        self.rates_seconds
    }
}

/// Per isolated face rates, and with a tolerance how many faces miss it and how many its
/// selection sampled.
struct FaceRates {
    rates: Vec<u32>,
    faces_over_tolerance: Option<usize>,
    faces_sampled: Option<usize>,
}

impl FaceRates {
    /// Rates given or from a camera: nothing to report.
    fn given(rates: Vec<u32>) -> Self {
        FaceRates {
            rates,
            faces_over_tolerance: None,
            faces_sampled: None,
        }
    }
}

/// One finite point per input vertex, or the error that says which is not.
fn check_positions(positions: &[[f32; 3]], input_vertices: usize) -> Result<(), RuntimeError> {
    if positions.len() != input_vertices {
        return Err(RuntimeError::InvalidParameter {
            name: "positions".to_owned(),
            reason: format!(
                "{} points for a mesh of {input_vertices} vertices",
                positions.len()
            ),
        });
    }
    match positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        Some(v) => Err(RuntimeError::InvalidParameter {
            name: format!("position of vertex {v}"),
            reason: format!("{:?} is not finite", positions[v]),
        }),
        None => Ok(()),
    }
}

/// One evaluated frame: borrowed from its [`Tessellator`] until the next
/// [`Tessellator::evaluate`].
#[derive(Clone, Copy, Debug)]
pub struct Frame<'a> {
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    triangles: &'a [[u32; 3]],
    sources: &'a [VertexSource],
    uvs: &'a [[f32; 2]],
    seam_copies: &'a [[u32; 2]],
}

impl<'a> Frame<'a> {
    /// Limit positions, one per output vertex.
    pub fn positions(&self) -> &'a [[f32; 3]] {
        self.positions
    }

    /// Unit normals, one per output vertex (zero where the tangents are degenerate).
    pub fn normals(&self) -> &'a [[f32; 3]] {
        self.normals
    }

    /// Triangles (indices into the vertices), counter-clockwise seen from outside for
    /// counter-clockwise input faces.
    pub fn triangles(&self) -> &'a [[u32; 3]] {
        self.triangles
    }

    /// Where every output vertex lies: input face, sub-face (of an n-gon), exact `(u, v)`.
    pub fn sources(&self) -> &'a [VertexSource] {
        self.sources
    }

    /// Texture coordinates, one per output vertex, when the surface has them
    /// ([`Surface::has_uvs`]): the face-varying limit surface at each vertex's source, in the
    /// channel's mode. Vertices are split along texture seams only
    /// ([`Frame::seam_copies`]).
    pub fn uvs(&self) -> Option<&'a [[f32; 2]]> {
        (!self.uvs.is_empty()).then_some(self.uvs)
    }

    /// Output vertices that repeat another's position on the other side of a texture seam,
    /// `[copy, original]`: the same position and normal bits, their own texture coordinates.
    pub fn seam_copies(&self) -> &'a [[u32; 2]] {
        self.seam_copies
    }

    /// A copy as the tessellators' [`TriangleMesh`] (for the writers in [`crate::io`]).
    pub fn to_triangle_mesh(&self) -> TriangleMesh {
        TriangleMesh {
            positions: self.positions.to_vec(),
            normals: self.normals.to_vec(),
            sources: self.sources.to_vec(),
            triangles: self.triangles.to_vec(),
            uvs: self.uvs.to_vec(),
            seam_copies: self.seam_copies.to_vec(),
        }
    }
}

#[cfg(all(test, feature = "catmull-clark"))]
mod tests {
    use super::*;

    /// The cube with a texture atlas (every edge a seam): its plan has texture coordinates and
    /// seam copies to keep too.
    fn cube_uv() -> Mesh {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube_uv.obj");
        Mesh::read_obj(path).expect("cube_uv.obj")
    }

    /// Turned about the z axis and moved: every face keeps its rate.
    fn turned(points: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let (s, c) = 0.3f32.sin_cos();
        points
            .iter()
            .map(|p| {
                [
                    c * p[0] - s * p[1] + 0.5,
                    s * p[0] + c * p[1] - 0.25,
                    p[2] + 2.0,
                ]
            })
            .collect()
    }

    fn kept_rates(surface: &Surface) -> Option<Vec<u32>> {
        let kept = surface.frame_buffers.lock().expect("buffers");
        kept.plan.as_ref().map(|plan| plan.rates.clone())
    }

    /// A torus of 12 x 8 quads (`test_meshes::quad_torus`) with its first quad cut into two
    /// triangles: isolation takes two steps, and the input faces away from them are regular.
    fn torus_with_triangles() -> Mesh {
        let torus = crate::mesh::test_meshes::quad_torus(12, 8);
        let mut faces: Vec<Vec<i64>> = Vec::new();
        for f in 0..torus.faces() {
            let q: Vec<i64> = torus.face(f).iter().map(|&v| i64::from(v)).collect();
            if f == 0 {
                faces.push(vec![q[0], q[1], q[2]]);
                faces.push(vec![q[0], q[2], q[3]]);
            } else {
                faces.push(q);
            }
        }
        Mesh::new(
            torus.positions,
            &faces,
            &[],
            schemes::BoundaryMode::EdgeOnly,
        )
        .expect("a torus")
    }

    /// The regular input faces evaluated whole from the input points (every turn of their
    /// pieces met) give what the plan of the isolated mesh gives face by face (the table's
    /// stencils on the refined points) to f32 rounding, and the map keeps fewer rows.
    #[test]
    fn whole_input_faces_are_their_pieces_face_by_face() {
        // With an infinitely sharp edge too (a dart at both ends), whose faces and those that
        // touch it at a corner must not be evaluated as plain B-spline patches.
        let mut dart = torus_with_triangles();
        dart.set_edge_sharpness(54, 55, schemes::crease::INFINITE)
            .expect("an edge of the torus");
        for mesh in [torus_with_triangles(), dart] {
            whole_faces_agree(&mesh);
        }
    }

    fn whole_faces_agree(mesh: &Mesh) {
        let surface = Surface::new(mesh, Scheme::CatmullClark).expect("a surface");
        let Isolated::Quad(iso) = &surface.isolated else {
            panic!("a quad isolation");
        };
        assert_eq!(iso.steps, 2);
        let turns: std::collections::HashSet<u8> = (0..iso.mesh.faces())
            .filter_map(|f| iso.placement(f).map(|p| p.turns))
            .collect();
        assert_eq!(turns.len(), 4);
        for rate in [3, 4, 5] {
            let mut tessellator = surface.tessellator(&Rates::Uniform(rate)).expect("a plan");
            let grid = tessellator.grid.as_ref().expect("a plan");
            let rows = grid.control_map().map(Stencil::rows);
            let frame = tessellator
                .evaluate(&mesh.positions_f32())
                .expect("a frame");
            let rates = vec![rate; iso.mesh.faces()];
            let reference = DualGrid::new(&surface.table, &iso.mesh, &iso.patches, &rates)
                .expect("a plan")
                .tessellate(&iso.mesh);
            assert_eq!(frame.triangles(), reference.triangles.as_slice());
            for (p, q) in frame.positions().iter().zip(&reference.positions) {
                let d = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max);
                assert!(d < 2e-6, "positions {p:?} and {q:?} at rate {rate}");
            }
            // The input's rounding to f32 (the frame's) moves the points by about 1e-7.
            for (a, b) in frame.normals().iter().zip(&reference.normals) {
                let sine = [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ]
                .map(|c| c * c)
                .iter()
                .sum::<f32>()
                .sqrt();
                assert!(sine < 1e-5, "normals {a:?} and {b:?} at rate {rate}");
            }
            // Rate 4 takes the whole faces and reads fewer isolated points; 3 and 5 do not.
            if rate == 4 {
                let rows = rows.expect("whole input faces at rate 4");
                assert!(rows < iso.mesh.positions.len() / 2, "{rows} rows kept");
            } else {
                assert_eq!(rows, None);
            }
        }
    }

    #[test]
    fn a_plan_at_the_same_rates_is_kept_and_frames_as_a_fresh_one() {
        let mesh = cube_uv();
        let tolerance = Rates::Tolerance(2e-3);
        let mut surface = Surface::new(&mesh, Scheme::CatmullClark).expect("surface");
        let first = surface
            .tessellator(&tolerance)
            .expect("plan")
            .rates()
            .to_vec();
        assert!(first.iter().any(|&n| n > 1), "rates {first:?}");
        assert_eq!(kept_rates(&surface), Some(first.clone()), "kept on drop");

        let moved = turned(&mesh.positions_f32());
        surface.set_positions(&moved).expect("moved");
        let mut tessellator = surface.tessellator(&tolerance).expect("kept plan");
        assert_eq!(tessellator.rates(), &first[..]);
        assert_eq!(
            kept_rates(&surface),
            None,
            "the plan at the same rates is taken"
        );
        let frame = tessellator.evaluate(&moved).expect("frame");

        let mut fresh_mesh = mesh.clone();
        fresh_mesh.positions = moved.iter().map(|p| p.map(f64::from)).collect();
        let fresh = Surface::new(&fresh_mesh, Scheme::CatmullClark).expect("fresh surface");
        let mut fresh_tessellator = fresh.tessellator(&tolerance).expect("fresh plan");
        assert_eq!(fresh_tessellator.rates(), &first[..]);
        let reference = fresh_tessellator.evaluate(&moved).expect("fresh frame");
        assert_eq!(frame.triangles(), reference.triangles());
        assert_eq!(frame.sources(), reference.sources());
        assert_eq!(frame.uvs(), reference.uvs());
        assert!(frame.uvs().is_some());
        assert_eq!(frame.seam_copies(), reference.seam_copies());
        let worst = frame
            .positions()
            .iter()
            .zip(reference.positions())
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst <= 1e-5, "positions off by {worst}");
        drop(tessellator);

        // Other rates: a plan of their own, and that plan kept in turn.
        let uniform = surface.tessellator(&Rates::Uniform(3)).expect("uniform");
        assert!(uniform.rates().iter().all(|&n| n == 3));
        let fresh_uniform = fresh
            .tessellator(&Rates::Uniform(3))
            .expect("fresh uniform");
        assert_eq!(uniform.triangle_count(), fresh_uniform.triangle_count());
        let uniform_rates = uniform.rates().to_vec();
        drop(uniform);
        assert_eq!(kept_rates(&surface), Some(uniform_rates));
    }

    #[test]
    fn a_trimmed_surface_keeps_nothing_and_frames_as_before() {
        let mesh = cube_uv();
        let tolerance = Rates::Tolerance(2e-3);
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("surface");
        assert_eq!(surface.kept_bytes(), 0, "nothing kept before a tessellator");
        let positions = mesh.positions_f32();
        let mut tessellator = surface.tessellator(&tolerance).expect("plan");
        let all = surface.faces();
        assert_eq!(tessellator.faces_sampled(), Some(all));
        let before = tessellator
            .evaluate(&positions)
            .expect("frame")
            .to_triangle_mesh();
        drop(tessellator);
        let kept = surface.kept_bytes();
        // At least the output buffers: a position, a normal and a source per vertex.
        assert!(kept >= before.positions.len() * 24, "{kept} bytes kept");
        // Kept, the next selection samples no face.
        assert_eq!(
            surface
                .tessellator(&tolerance)
                .expect("kept")
                .faces_sampled(),
            Some(0)
        );

        surface.trim();
        assert_eq!(surface.kept_bytes(), 0);
        assert_eq!(kept_rates(&surface), None, "the plan freed");
        let mut tessellator = surface.tessellator(&tolerance).expect("plan again");
        assert_eq!(
            tessellator.faces_sampled(),
            Some(all),
            "the selection forgotten"
        );
        let after = tessellator
            .evaluate(&positions)
            .expect("frame")
            .to_triangle_mesh();
        assert_eq!(after.triangles, before.triangles);
        assert_eq!(after.sources, before.sources);
        assert_eq!(after.positions, before.positions);
        assert_eq!(after.normals, before.normals);
    }
}
