//! `subtess`: the runtime's command line: `subtess tessellate`, `subtess eval`, `subtess bench`,
//! `subtess tables info` (docs/cli.md).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use subtess::eval::exact_eval::{evaluate_subface, parse_rational};
use subtess::eval::loop_exact_eval::LoopExactEvaluator;
use subtess::io::mesh_output::{write_mesh, MeshFormat};
use subtess::io::obj::read_obj;
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::isolate::{isolate_with_origins, Isolation};
use subtess::scheme::catmull_clark::refine::refine;
use subtess::scheme::loop_scheme::isolate::isolate_loop;
use subtess::scheme::loop_scheme::refine::loop_refine;
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::scheme::triangle::region_isolate::isolate_regions;
use subtess::scheme::triangle::region_patch::RegionScheme;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::bezier::{tessellate_bezier, BezierOptions, BezierPatches};
use subtess::tessellate::dual_grid::{tessellate, DualGrid};
use subtess::tessellate::lai_cheng::{tessellate_adaptive, write_obj_polygons, AdaptiveOptions};
use subtess::tessellate::rates::{tolerance_rates, view_rates, ViewCamera};
use subtess::tessellate::triangle_dual_grid::{tessellate_triangles, TriangleDualGrid};
use subtess::tessellate::triangle_rates::triangle_tolerance_rates;
use subtess::RuntimeError;

#[derive(Parser)]
#[command(
    name = "subtess",
    version,
    about = "Exact evaluation and tessellation of subdivision surfaces"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Tessellate a Catmull-Clark mesh (OBJ) with the dual-grid or the adaptive method, or
    /// Bezier patches with Espino et al.'s method.
    Tessellate(Box<TessellateArgs>),
    /// Measure per-frame tessellation throughput: the plan (topology, patches, stencil
    /// lookups) is built once, then every frame evaluates all positions and normals and writes
    /// all triangles. Prints one JSON object with the median over the frames.
    Bench {
        /// Input mesh (OBJ).
        mesh: PathBuf,
        /// Dual points per face side on every face.
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=24))]
        rate: u32,
        /// Mixed per-face rates instead (3, 5, 8, 12, 7, 16 in turn).
        #[arg(long, conflicts_with = "rate")]
        mixed: bool,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Catmull-Clark steps applied to the input first (to reach a given face count).
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=6))]
        refine: u32,
        /// Frames to time.
        #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// A stencil table file instead of the embedded default.
        #[arg(long)]
        table: Option<PathBuf>,
        /// Subdivision scheme: catmull-clark, or loop, butterfly or sqrt3 (a triangle mesh;
        /// --refine then takes steps of that scheme, two √3 steps each for sqrt3).
        #[arg(long, default_value = "catmull-clark")]
        scheme: String,
    },
    /// Exact limit position and first derivatives of face F at rational (u, v), in the face's
    /// own parameters (rounded once to f64).
    Eval {
        /// Input mesh (OBJ).
        mesh: PathBuf,
        /// Subdivision scheme: catmull-clark, or loop (a mesh of triangles, barycentric U,V
        /// with U + V <= 1).
        #[arg(long, default_value = "catmull-clark")]
        scheme: String,
        /// Face number, 0-based, in OBJ order.
        #[arg(long)]
        face: usize,
        /// `U,V`: rationals `p/q`, integers or decimals in [0, 1].
        #[arg(long)]
        uv: String,
        /// For a non-quad face: which sub-face (the quad of the first Catmull-Clark step at
        /// corner k).
        #[arg(long, default_value_t = 0)]
        corner: usize,
        /// Print JSON `{"position","du","dv"}`.
        #[arg(long)]
        json: bool,
    },
    /// Stencil tables.
    Tables {
        #[command(subcommand)]
        command: TablesCommand,
    },
}

/// `subtess tessellate`'s arguments.
#[derive(clap::Args)]
struct TessellateArgs {
    /// Input mesh (OBJ: triangles, quads, n-gons; closed or with boundary).
    #[arg(required_unless_present = "bezier", conflicts_with = "bezier")]
    mesh: Option<PathBuf>,
    /// Output triangle mesh: .obj, .ply (with per-vertex face, u, v), .glb or .gltf.
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Subdivision scheme: catmull-clark (any polygons), loop (triangles), butterfly or sqrt3
    /// (closed triangle meshes); the triangle schemes take --rate, --rates, --tolerance or
    /// --view.
    #[arg(long, default_value = "catmull-clark")]
    scheme: String,
    /// Dual points per face side, 1..=24, on every face.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=24), conflicts_with_all = ["rates", "tolerance", "view"])]
    rate: u32,
    /// Per-face rates: a text file with one rate (1..=24) per input face, in OBJ face
    /// order, separated by white space; faces made by isolation inherit their input
    /// face's rate.
    #[arg(long, conflicts_with_all = ["tolerance", "view"])]
    rates: Option<PathBuf>,
    /// A distance T in the mesh's units. Dual grid: per face the smallest rate whose
    /// tessellation deviates from the limit surface by at most T, measured on the table's
    /// rate-24 grid (docs/results.md); loop, butterfly and sqrt3: on the triangle grids of the table's
    /// two largest rates, rates among the table's (docs/cli.md). Adaptive: the guaranteed
    /// bound every polygon meets.
    #[arg(long, conflicts_with = "view")]
    tolerance: Option<f64>,
    /// View-dependent rates: `PX,PY,PZ,TX,TY,TZ,FOV,HEIGHT,EDGE` = camera position, target,
    /// vertical field of view (degrees), image height (pixels) and the target edge length
    /// (pixels); per face the projected size over the edge length, in 1..=24.
    #[arg(long, value_parser = parse_view)]
    view: Option<ViewCamera>,
    /// A stencil table file instead of the embedded default.
    #[arg(long)]
    table: Option<PathBuf>,
    /// Print statistics as JSON on stdout.
    #[arg(long)]
    stats: bool,
    /// Bicubic Bezier patches instead of a mesh (Newell "patches + vertices" text, or
    /// `.bpt`), tessellated adaptively by Espino et al.'s displacement-map method
    /// (docs/espino.md).
    #[arg(long)]
    bezier: Option<PathBuf>,
    /// Bezier edge test: map2p, map4p, map8p or flat.
    #[arg(long = "test", default_value = "map4p", requires = "bezier")]
    edge_test: String,
    /// Bezier split threshold `th` (eq. 1-3), a distance.
    #[arg(long, requires = "bezier", conflicts_with = "triangles")]
    threshold: Option<f64>,
    /// Bezier triangle budget: search the threshold whose output is nearest it.
    #[arg(long, requires = "bezier")]
    triangles: Option<usize>,
    /// `dual-grid` (Schaefer-Warren, one rate per face) or `adaptive` (Lai-Cheng: recursive
    /// subdivision of each face's domain until a guaranteed bound meets `--tolerance`).
    #[arg(long, default_value = "dual-grid", value_parser = ["dual-grid", "adaptive"])]
    method: String,
    /// Adaptive: the tolerance is relative to each square's base quadrilateral's longer
    /// diagonal (Lai-Cheng section 6) instead of a distance.
    #[arg(long)]
    relative: bool,
    /// Adaptive: write triangles; without it an .obj output holds the polygons (n-gons).
    #[arg(long)]
    triangulate: bool,
}

#[derive(Subcommand)]
enum TablesCommand {
    /// What a table holds: format, scheme, precision, coverage, size (default: the embedded one).
    Info {
        /// A table file written by `stencilgen tables`.
        file: Option<PathBuf>,
        /// Without a file: which embedded default (catmull-clark, loop, butterfly or sqrt3).
        #[arg(long, default_value = "catmull-clark", conflicts_with = "file")]
        scheme: String,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The table file, or the embedded default for the mesh's boundary rule.
fn load_table(
    table: &Option<PathBuf>,
    mode: schemes::BoundaryMode,
) -> Result<StencilTable, RuntimeError> {
    match table {
        Some(path) => StencilTable::read(path),
        None => StencilTable::default_for(mode),
    }
}

fn load_mesh(path: &Path) -> Result<Mesh, RuntimeError> {
    let obj = read_obj(path)?;
    let (mesh, warnings) = Mesh::from_obj(&obj)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(mesh)
}

/// Per-input-face rates from a text file, spread to the isolated faces.
fn read_rates(path: &Path, input_faces: usize, origin: &[u32]) -> Result<Vec<u32>, RuntimeError> {
    let text = std::fs::read_to_string(path).map_err(|source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let bad = |message: String| RuntimeError::Unsupported(format!("{}: {message}", path.display()));
    let rates = text
        .split_whitespace()
        .enumerate()
        .map(|(i, word)| match word.parse::<u32>() {
            Ok(n) if (1..=24).contains(&n) => Ok(n),
            _ => Err(bad(format!(
                "rate {} is `{word}`, not an integer in 1..=24",
                i + 1
            ))),
        })
        .collect::<Result<Vec<u32>, _>>()?;
    if rates.len() != input_faces {
        return Err(bad(format!(
            "{} rates for a mesh of {input_faces} faces",
            rates.len()
        )));
    }
    Ok(origin.iter().map(|&f| rates[f as usize]).collect())
}

/// `--view PX,PY,PZ,TX,TY,TZ,FOV,HEIGHT,EDGE`.
fn parse_view(text: &str) -> Result<ViewCamera, String> {
    let values = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|e| format!("`{text}`: {e}"))?;
    match values[..] {
        [px, py, pz, tx, ty, tz, fov, height, edge] => Ok(ViewCamera {
            position: [px, py, pz],
            target: [tx, ty, tz],
            vertical_fov_degrees: fov,
            image_height_px: height,
            target_edge_px: edge,
        }),
        _ => Err(format!(
            "`{text}`: 9 numbers wanted (position x,y,z, target x,y,z, fov degrees, image height px, edge px), got {}",
            values.len()
        )),
    }
}

/// `subtess tessellate`: Bezier patches (Espino et al.), or a mesh by the dual grid or the
/// adaptive method (Lai-Cheng).
fn tessellate_command(args: TessellateArgs) -> Result<(), RuntimeError> {
    MeshFormat::from_path(&args.output)?;
    let mesh = match (&args.mesh, &args.bezier) {
        (_, Some(file)) => return bezier_command(file, &args),
        (Some(_), None) if args.threshold.is_some() || args.triangles.is_some() => {
            return Err(RuntimeError::Unsupported(
                "--threshold and --triangles belong to --bezier tessellation".to_owned(),
            ))
        }
        (Some(mesh), None) => mesh,
        (None, None) => {
            return Err(RuntimeError::Unsupported(
                "nothing to tessellate: give a mesh or --bezier FILE".to_owned(),
            ))
        }
    };
    let input = load_mesh(mesh)?;
    let scheme = parse_scheme(&args.scheme)?;
    if scheme.is_triangle() {
        return triangle_command(&args, &input, scheme);
    }
    let table = load_table(&args.table, input.boundary)?;
    let started = Instant::now();
    let iso = isolate_with_origins(&input)?;
    let isolation_seconds = started.elapsed().as_secs_f64();
    if args.method == "adaptive" {
        return adaptive_command(&args, &input, &table, &iso, isolation_seconds);
    }
    if args.relative || args.triangulate {
        return Err(RuntimeError::InvalidParameter {
            name: "--relative / --triangulate".to_owned(),
            reason: "they belong to --method adaptive".to_owned(),
        });
    }
    let mut unmet = None;
    let rates = if let Some(path) = &args.rates {
        read_rates(path, input.faces(), &iso.origin)?
    } else if let Some(t) = args.tolerance {
        let chosen = tolerance_rates(&table, &iso.mesh, &iso.patches, t)?;
        if !chosen.unmet.is_empty() {
            eprintln!(
                "warning: {} faces do not meet the tolerance {t} at rate 24; they get 24",
                chosen.unmet.len()
            );
        }
        unmet = Some(chosen.unmet.len());
        chosen.rates
    } else if let Some(camera) = &args.view {
        view_rates(&iso.mesh, camera)?
    } else {
        vec![args.rate; iso.patches.len()]
    };
    let (mut triangles, time) = tessellate(&table, &iso.mesh, &iso.patches, &rates)?;
    // Sources in the user's own faces and parameters.
    for source in &mut triangles.sources {
        *source = iso.input_source(*source);
    }
    write_mesh(&triangles, &args.output)?;
    if args.stats {
        let count = triangles.triangles.len();
        let loops = input.boundary_loops();
        let stats = serde_json::json!({
            "triangles": count,
            "vertices": triangles.positions.len(),
            "seconds": time.seconds,
            "plan_seconds": time.plan_seconds,
            "triangles_per_second": count as f64 / time.seconds.max(1e-12),
            "watertight": loops == 0 && triangles.is_watertight(),
            "boundary_loops": loops,
            "input_faces": input.faces(),
            "faces": iso.mesh.faces(),
            "isolation_steps": iso.steps,
            "isolation_seconds": isolation_seconds,
            "rate_min": rates.iter().min(),
            "rate_max": rates.iter().max(),
            "tolerance": args.tolerance,
            "faces_over_tolerance": unmet,
            "threads": rayon::current_num_threads(),
        });
        println!("{stats}");
    }
    Ok(())
}

/// The schemes the runtime has tables for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scheme {
    CatmullClark,
    Loop,
    Butterfly,
    Sqrt3,
}

impl Scheme {
    fn name(self) -> &'static str {
        match self {
            Scheme::CatmullClark => "catmull-clark",
            Scheme::Loop => "loop",
            Scheme::Butterfly => "butterfly",
            Scheme::Sqrt3 => "sqrt3",
        }
    }

    /// Whether the scheme subdivides triangles (the triangle dual grid tessellates it).
    fn is_triangle(self) -> bool {
        self != Scheme::CatmullClark
    }

    /// The triangle scheme's table: a file (which must be this scheme's), or the embedded
    /// default.
    fn triangle_table(self, table: &Option<PathBuf>) -> Result<StencilTable, RuntimeError> {
        match (table, self) {
            (Some(path), _) => StencilTable::read(path),
            (None, Scheme::Butterfly) => StencilTable::default_butterfly(),
            (None, Scheme::Sqrt3) => StencilTable::default_sqrt3(),
            (None, _) => StencilTable::default_loop(),
        }
    }

    /// Isolate a triangle mesh for this scheme's table.
    fn isolate_triangles(self, mesh: &Mesh) -> Result<TriangleIsolation, RuntimeError> {
        match self {
            Scheme::Butterfly => isolate_regions(mesh, RegionScheme::Butterfly),
            Scheme::Sqrt3 => isolate_regions(mesh, RegionScheme::Sqrt3),
            _ => isolate_loop(mesh),
        }
    }

    /// One subdivision step of a triangle mesh by this scheme's rules (two for √3).
    fn refine_triangles(self, mesh: &Mesh) -> Result<Mesh, RuntimeError> {
        match self {
            Scheme::Butterfly => RegionScheme::Butterfly.refine(mesh),
            Scheme::Sqrt3 => RegionScheme::Sqrt3.refine(mesh),
            _ => Ok(loop_refine(mesh)?.mesh),
        }
    }
}

/// `--scheme NAME`: a scheme with a table, or an error saying which schemes exist and which
/// have no table yet.
fn parse_scheme(name: &str) -> Result<Scheme, RuntimeError> {
    match name {
        "catmull-clark" => Ok(Scheme::CatmullClark),
        "loop" => Ok(Scheme::Loop),
        "butterfly" => Ok(Scheme::Butterfly),
        "sqrt3" => Ok(Scheme::Sqrt3),
        other
            if schemes::triangle::TRIANGLE_SCHEME_NAMES.contains(&other)
                || schemes::quad::QUAD_SCHEME_NAMES.contains(&other) =>
        {
            Err(RuntimeError::Unsupported(format!(
                "scheme `{other}`: no table for this scheme yet (the runtime has tables for catmull-clark, loop, butterfly and sqrt3)"
            )))
        }
        other => Err(RuntimeError::InvalidParameter {
            name: format!("--scheme `{other}`"),
            reason: "not a scheme; catmull-clark, loop, butterfly or sqrt3".to_owned(),
        }),
    }
}

/// `subtess tessellate MESH --scheme loop|butterfly|sqrt3`: the triangle dual grid at `--rate`,
/// `--rates`, `--tolerance` (per triangle, `subtess::tessellate::triangle_rates`) or `--view` (the
/// projected-edge rule is the same for triangles).
fn triangle_command(
    args: &TessellateArgs,
    input: &Mesh,
    scheme: Scheme,
) -> Result<(), RuntimeError> {
    if args.method != "dual-grid" {
        return Err(RuntimeError::Unsupported(format!(
            "--scheme {} tessellates with the dual grid at --rate, --rates, --tolerance or --view (no --method adaptive yet)",
            scheme.name()
        )));
    }
    let table = scheme.triangle_table(&args.table)?;
    let started = Instant::now();
    let iso = scheme.isolate_triangles(input)?;
    let isolation_seconds = started.elapsed().as_secs_f64();
    let mut unmet = None;
    let rates = match (&args.rates, &args.view, args.tolerance) {
        (Some(path), _, _) => read_rates(path, input.faces(), &iso.origin)?,
        (None, Some(camera), _) => view_rates(&iso.mesh, camera)?,
        (None, None, Some(t)) => {
            let chosen = triangle_tolerance_rates(&table, &iso, t)?;
            if let (false, Some(largest)) = (chosen.unmet.is_empty(), chosen.rates.iter().max()) {
                eprintln!(
                    "warning: {} triangles do not meet the tolerance {t} at rate {largest}; they get {largest}",
                    chosen.unmet.len()
                );
            }
            unmet = Some(chosen.unmet.len());
            chosen.rates
        }
        (None, None, None) => vec![args.rate; iso.patches.len()],
    };
    let (mut triangles, time) = tessellate_triangles(&table, &iso.mesh, &iso.patches, &rates)?;
    for source in &mut triangles.sources {
        *source = iso.input_source(*source);
    }
    write_mesh(&triangles, &args.output)?;
    if args.stats {
        let count = triangles.triangles.len();
        let loops = input.boundary_loops();
        let stats = serde_json::json!({
            "scheme": scheme.name(),
            "triangles": count,
            "vertices": triangles.positions.len(),
            "seconds": time.seconds,
            "plan_seconds": time.plan_seconds,
            "triangles_per_second": count as f64 / time.seconds.max(1e-12),
            "watertight": loops == 0 && triangles.is_watertight(),
            "boundary_loops": loops,
            "input_faces": input.faces(),
            "faces": iso.mesh.faces(),
            "isolation_steps": iso.steps,
            "isolation_seconds": isolation_seconds,
            "rate_min": rates.iter().min(),
            "rate_max": rates.iter().max(),
            "tolerance": args.tolerance,
            "faces_over_tolerance": unmet,
            "threads": rayon::current_num_threads(),
        });
        println!("{stats}");
    }
    Ok(())
}

/// `subtess tessellate --bezier FILE`.
fn bezier_command(file: &Path, args: &TessellateArgs) -> Result<(), RuntimeError> {
    let patches = BezierPatches::read(file)?;
    let defaults = BezierOptions::default();
    let options = BezierOptions {
        test: args.edge_test.parse()?,
        threshold: args.threshold.unwrap_or(defaults.threshold),
        target_triangles: args.triangles,
        error_samples: if args.stats {
            defaults.error_samples
        } else {
            0
        },
        ..defaults
    };
    let (triangles, stats) = tessellate_bezier(&patches, &options)?;
    write_mesh(&triangles, &args.output)?;
    if args.stats {
        println!("{}", stats.to_json());
    }
    Ok(())
}

/// `subtess tessellate MESH --method adaptive --tolerance T`.
fn adaptive_command(
    args: &TessellateArgs,
    input: &Mesh,
    table: &StencilTable,
    iso: &Isolation,
    isolation_seconds: f64,
) -> Result<(), RuntimeError> {
    let tolerance = args
        .tolerance
        .ok_or_else(|| RuntimeError::InvalidParameter {
            name: "--method adaptive".to_owned(),
            reason: "it needs --tolerance T".to_owned(),
        })?;
    let options = AdaptiveOptions {
        tolerance,
        relative: args.relative,
        triangulate: args.triangulate,
        ..AdaptiveOptions::default()
    };
    let (mut adaptive, stats) = tessellate_adaptive(table, &iso.mesh, &iso.patches, &options)?;
    for source in &mut adaptive.sources {
        *source = iso.input_source(*source);
    }
    if MeshFormat::from_path(&args.output)? == MeshFormat::Obj && !args.triangulate {
        write_obj_polygons(&adaptive, &args.output)?;
    } else {
        write_mesh(&adaptive.to_triangle_mesh(), &args.output)?;
    }
    if args.stats {
        let mut report = stats.to_json();
        report["watertight"] =
            serde_json::json!(input.boundary_loops() == 0 && adaptive.is_watertight());
        report["isolation_seconds"] = serde_json::json!(isolation_seconds);
        println!("{report}");
    }
    Ok(())
}

/// The bench's rates: `rate` everywhere, or 3, 5, 8, 12, 7, 16 in turn.
fn bench_rates(faces: usize, rate: u32, mixed: bool) -> Vec<u32> {
    if mixed {
        (0..faces).map(|f| [3, 5, 8, 12, 7, 16][f % 6]).collect()
    } else {
        vec![rate; faces]
    }
}

/// A mesh's vertices as the evaluators' f32 control points.
fn f32_positions(mesh: &Mesh) -> Vec<[f32; 3]> {
    mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect()
}

/// Run `frame` once untimed (it brings the buffers and the table into memory), then `frames`
/// times timed, in `pool`; the seconds of each timed frame, sorted.
fn time_frames(pool: &rayon::ThreadPool, frames: u32, mut frame: impl FnMut() + Send) -> Vec<f64> {
    let mut seconds: Vec<f64> = pool.install(|| {
        frame();
        (0..frames)
            .map(|_| {
                let started = Instant::now();
                frame();
                started.elapsed().as_secs_f64()
            })
            .collect()
    });
    seconds.sort_by(f64::total_cmp);
    seconds
}

fn run(cli: Cli) -> Result<(), RuntimeError> {
    match cli.command {
        Command::Tessellate(args) => tessellate_command(*args),
        Command::Bench {
            mesh,
            rate,
            mixed,
            threads,
            refine: steps,
            frames,
            table,
            scheme,
        } => {
            let mut input = load_mesh(&mesh)?;
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads.unwrap_or(0))
                .build()
                .map_err(|e| RuntimeError::Unsupported(format!("a pool of threads: {e}")))?;
            let rates_label = if mixed {
                "mixed 3..16".to_owned()
            } else {
                rate.to_string()
            };
            let scheme = parse_scheme(&scheme)?;
            if scheme.is_triangle() {
                let table = scheme.triangle_table(&table)?;
                for _ in 0..steps {
                    input = scheme.refine_triangles(&input)?;
                }
                let started = Instant::now();
                let iso = scheme.isolate_triangles(&input)?;
                let isolation_seconds = started.elapsed().as_secs_f64();
                let faces = iso.patches.len();
                let rates = bench_rates(faces, rate, mixed);
                let (grid, control) = pool.install(|| {
                    let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates)?;
                    Ok::<_, RuntimeError>((grid, f32_positions(&iso.mesh)))
                })?;
                let mut positions = vec![[0.0f32; 3]; grid.vertex_count()];
                let mut normals = positions.clone();
                let mut triangles = vec![[0u32; 3]; grid.triangle_count()];
                let seconds = time_frames(&pool, frames, || {
                    grid.evaluate(&control, &mut positions, &mut normals);
                    grid.connect(&mut triangles);
                });
                let count = grid.triangle_count();
                let report = serde_json::json!({
                    "mesh": mesh.display().to_string(),
                    "scheme": scheme.name(),
                    "faces": faces,
                    "rates": rates_label,
                    "threads": pool.current_num_threads(),
                    "frames": frames,
                    "triangles": count,
                    "vertices": grid.vertex_count(),
                    "median_seconds": seconds[seconds.len() / 2],
                    "min_seconds": seconds[0],
                    "max_seconds": seconds[seconds.len() - 1],
                    "triangles_per_second": count as f64 / seconds[seconds.len() / 2].max(1e-12),
                    "isolation_seconds": isolation_seconds,
                });
                println!("{report}");
                return Ok(());
            }
            let table = load_table(&table, input.boundary)?;
            for _ in 0..steps {
                input = refine(&input).mesh;
            }
            let started = Instant::now();
            let iso = isolate_with_origins(&input)?;
            let isolation_seconds = started.elapsed().as_secs_f64();
            let faces = iso.patches.len();
            let rates = bench_rates(faces, rate, mixed);
            let (grid, control) = pool.install(|| {
                let grid = DualGrid::new(&table, &iso.mesh, &iso.patches, &rates)?;
                Ok::<_, RuntimeError>((grid, f32_positions(&iso.mesh)))
            })?;
            let mut positions = vec![[0.0f32; 3]; grid.vertex_count()];
            let mut normals = positions.clone();
            let mut triangles = vec![[0u32; 3]; grid.triangle_count()];
            let seconds = time_frames(&pool, frames, || {
                grid.evaluate(&control, &mut positions, &mut normals);
                grid.connect(&mut triangles);
            });
            let median = seconds[seconds.len() / 2];
            let count = grid.triangle_count();
            let report = serde_json::json!({
                "mesh": mesh.display().to_string(),
                "faces": faces,
                "rates": rates_label,
                "threads": pool.current_num_threads(),
                "frames": frames,
                "triangles": count,
                "vertices": grid.vertex_count(),
                "separable_faces": grid.separable_faces(),
                "median_seconds": median,
                "min_seconds": seconds[0],
                "max_seconds": seconds[seconds.len() - 1],
                "triangles_per_second": count as f64 / median.max(1e-12),
                "isolation_seconds": isolation_seconds,
            });
            println!("{report}");
            Ok(())
        }
        Command::Eval {
            mesh,
            scheme,
            face,
            uv,
            corner,
            json,
        } => {
            let scheme = parse_scheme(&scheme)?;
            let (u, v) = uv
                .split_once(',')
                .ok_or_else(|| RuntimeError::InvalidParameter {
                    name: format!("--uv `{uv}`"),
                    reason: "two rationals `U,V` wanted".to_owned(),
                })?;
            let (u, v) = (parse_rational(u.trim())?, parse_rational(v.trim())?);
            let input = load_mesh(&mesh)?;
            let point = match scheme {
                Scheme::CatmullClark => evaluate_subface(&input, face, corner, &u, &v)?,
                Scheme::Loop => LoopExactEvaluator::new(&input)?.evaluate(face, &u, &v)?,
                Scheme::Butterfly | Scheme::Sqrt3 => {
                    return Err(RuntimeError::Unsupported(format!(
                        "exact evaluation of {0} is not implemented yet (`subtess tessellate --scheme {0}` evaluates it from the table)",
                        scheme.name()
                    )))
                }
            };
            if json {
                let report = serde_json::json!({
                    "position": point.position,
                    "du": point.du,
                    "dv": point.dv,
                });
                println!("{report}");
            } else {
                println!("position {:?}", point.position);
                println!("du       {:?}", point.du);
                println!("dv       {:?}", point.dv);
            }
            Ok(())
        }
        Command::Tables {
            command: TablesCommand::Info { file, scheme },
        } => {
            let name = match &file {
                Some(path) => path.display().to_string(),
                None => format!("(embedded default, {scheme})"),
            };
            let table = match parse_scheme(&scheme)? {
                Scheme::Loop if file.is_none() => StencilTable::default_loop()?,
                scheme @ (Scheme::Butterfly | Scheme::Sqrt3) if file.is_none() => {
                    scheme.triangle_table(&None)?
                }
                _ => load_table(&file, schemes::BoundaryMode::EdgeOnly)?,
            };
            let index = table.index();
            let weights: u64 = index
                .entries
                .iter()
                .map(|e| u64::from(e.points) * u64::from(e.width))
                .sum();
            println!("table:      {name}");
            println!(
                "format:     version {}, little-endian, checksum {:#018x} (verified)",
                index.version, index.checksum
            );
            println!("scheme:     {}", index.meta.scheme.name());
            println!(
                "boundary:   {}",
                if index.meta.corners {
                    "edge and corner (one-face vertices pinned)"
                } else {
                    "edge only"
                }
            );
            println!("precision:  {}", index.meta.precision);
            println!("covers:     {}", index.coverage());
            println!(
                "sections:   {} (primal and dual grids; positions, d/du, d/dv)",
                index.entries.len()
            );
            println!("weights:    {weights}");
            println!(
                "size:       {} bytes ({:.1} MiB)",
                table.bytes().len(),
                table.bytes().len() as f64 / (1024.0 * 1024.0)
            );
            Ok(())
        }
    }
}
