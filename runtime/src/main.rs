//! `subtess`: the command line, a thin client of the library's facade (`subtess::Surface`):
//! `subtess tessellate`, `subtess eval`, `subtess bench`, `subtess tables info` (docs/cli.md).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};
use subtess::budget::refined_faces;
use subtess::io::mesh_output::write_mesh;
use subtess::tessellate::lai_cheng::write_obj_polygons;
use subtess::{
    eval, parse_rational, tessellate_bezier, AdaptiveMesh, AdaptiveOptions, BezierOptions,
    BezierPatches, FaceVaryingMode, Mesh, MeshFormat, OutputEstimate, Rates, RuntimeError, Scheme,
    StencilTable, Surface, Tessellator, ViewCamera,
};

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

/// The most worker threads `subtess bench --threads` accepts (docs/reliability.md): far above
/// any core count the work scales to, low enough that a typo cannot start 20,000 threads.
const MAX_THREADS: usize = 256;

/// `--threads`: 1..=[`MAX_THREADS`].
fn threads_arg(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n @ 1..=MAX_THREADS) => Ok(n),
        Ok(n) => Err(format!("{n} threads: the limit is 1..={MAX_THREADS}")),
        Err(_) => Err(format!("a number of threads in 1..={MAX_THREADS}")),
    }
}

/// `--motion`: a finite angle in degrees.
fn degrees_arg(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(d) if d.is_finite() => Ok(d),
        _ => Err(format!("{text}: an angle in degrees (a finite number)")),
    }
}

/// Write one line on stdout. A closed pipe (`subtess tables info | head -1`) ends the
/// program quietly with status 0, as Unix tools do; any other write error is an error.
fn print_line(line: std::fmt::Arguments) -> Result<(), RuntimeError> {
    let mut stdout = std::io::stdout().lock();
    match writeln!(stdout, "{line}").and_then(|()| stdout.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(source) => Err(RuntimeError::Io {
            path: "standard output".to_owned(),
            source,
        }),
    }
}

/// `println!` through [`print_line`]: returns the write's result.
macro_rules! out {
    ($($arg:tt)*) => {
        print_line(format_args!($($arg)*))
    };
}

/// `--scheme`: a scheme with a table; a catalogued scheme without one is named as such.
fn scheme_arg(name: &str) -> Result<Scheme, String> {
    name.parse::<Scheme>().map_err(|e| e.to_string())
}

/// `--uv-interpolation`.
fn uv_interpolation_arg(name: &str) -> Result<FaceVaryingMode, String> {
    FaceVaryingMode::parse(name).ok_or_else(|| {
        let names: Vec<&str> = FaceVaryingMode::ALL.iter().map(|m| m.name()).collect();
        format!("one of {} (or 0..5)", names.join(", "))
    })
}

/// `--method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    /// Schaefer–Warren's dual grid, one rate per face.
    DualGrid,
    /// Lai–Cheng: recursive subdivision of each face's domain until a guaranteed bound meets
    /// `--tolerance`.
    Adaptive,
}

#[derive(Subcommand)]
enum Command {
    /// Tessellate a mesh (OBJ) with the dual-grid or the adaptive method, or Bezier patches
    /// with Espino et al.'s method.
    Tessellate(Box<TessellateArgs>),
    /// Measure per-frame throughput from the input control points: the surface (isolation)
    /// and the plan (table lookups, connectivity, triangles) are built once, then every frame
    /// maps the input control points through the isolation's refinement stencils and evaluates
    /// all positions and normals. Prints one JSON object with the median over the frames.
    Bench {
        /// Input mesh (OBJ).
        mesh: PathBuf,
        /// Dual points per face side on every face.
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=24))]
        rate: u32,
        /// Mixed per-input-face rates instead (3, 5, 8, 12, 7, 16 in turn).
        #[arg(long, conflicts_with = "rate")]
        mixed: bool,
        /// Rates from a tolerance instead, chosen again every frame: each frame sets the
        /// surface's positions, plans (the selection included) and evaluates, as a moving mesh
        /// that keeps a tolerance does (docs/cli.md).
        #[arg(long, conflicts_with_all = ["rate", "mixed"])]
        tolerance: Option<f64>,
        /// With --tolerance: Lai–Cheng's adaptive tessellation (catmull-clark) instead of the
        /// dual grid: every frame sets the surface's positions and tessellates adaptively into
        /// triangles (docs/cli.md).
        #[arg(long, requires = "tolerance")]
        adaptive: bool,
        /// With --tolerance: move the mesh every frame, as an arm bends at a joint: the points
        /// beyond the middle of the bounding box's longest side turn about its shortest axis by
        /// up to DEGREES (a sine over 60 frames), blended across a band of a tenth of that
        /// side (docs/cli.md). 0, the default, sets the same points every frame.
        #[arg(
            long,
            requires = "tolerance",
            conflicts_with = "adaptive",
            default_value_t = 0.0,
            value_parser = degrees_arg
        )]
        motion: f64,
        /// Worker threads, 1..=256 (default: one per core).
        #[arg(long, value_parser = threads_arg)]
        threads: Option<usize>,
        /// Subdivision steps of the scheme applied to the input first (to reach a given face
        /// count; two √3 steps each for sqrt3).
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=6))]
        refine: u32,
        /// Refuse a refinement or a plan estimated above N output triangles (docs/reliability.md).
        #[arg(long, default_value_t = subtess::DEFAULT_MAX_TRIANGLES, value_parser = clap::value_parser!(u64).range(1..))]
        max_triangles: u64,
        /// Frames to time.
        #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// A stencil table file instead of the embedded default.
        #[arg(long)]
        table: Option<PathBuf>,
        /// Subdivision scheme: catmull-clark, loop, butterfly or sqrt3.
        #[arg(long, default_value = "catmull-clark", value_parser = scheme_arg)]
        scheme: Scheme,
    },
    /// Exact limit position and first derivatives of face F at rational (u, v), in the face's
    /// own parameters (rounded once to f64).
    Eval {
        /// Input mesh (OBJ).
        mesh: PathBuf,
        /// Subdivision scheme: catmull-clark, or loop (a mesh of triangles, barycentric U,V
        /// with U + V <= 1).
        #[arg(long, default_value = "catmull-clark", value_parser = scheme_arg)]
        scheme: Scheme,
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
    /// Draw triangle meshes (OBJ, PLY, GLB) into a PNG, side by side, seen by one orbit
    /// camera: z-buffer, smooth shading, a checkerboard where the mesh has texture
    /// coordinates.
    Render {
        /// Input meshes (.obj, .ply, .glb), drawn left to right.
        #[arg(required = true)]
        meshes: Vec<PathBuf>,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// `WxH`: pixels per mesh (at most 8192 a side).
        #[arg(long, default_value = "800x600", value_parser = size_arg)]
        size: (u32, u32),
        /// `AZ,EL[,DIST]`: azimuth around +y and elevation in degrees, distance in radii of
        /// the meshes' bounding sphere (default: the sphere fills 90% of the smaller side).
        #[arg(long, default_value = "30,20", value_parser = view_arg, allow_hyphen_values = true)]
        view: (f64, f64, Option<f64>),
        /// Darken every triangle's edges.
        #[arg(long)]
        wireframe: bool,
        /// Take +z as up (CAD files) instead of +y.
        #[arg(long)]
        z_up: bool,
    },
}

/// `--size WxH`.
fn size_arg(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text.split_once('x').ok_or("WxH, e.g. 800x600")?;
    let side = |t: &str| match t.parse::<u32>() {
        Ok(n @ 1..=subtess::render::MAX_SIDE) => Ok(n),
        _ => Err(format!(
            "`{t}`: a side of 1..={} pixels",
            subtess::render::MAX_SIDE
        )),
    };
    Ok((side(w)?, side(h)?))
}

/// `--view AZ,EL[,DIST]`.
fn view_arg(text: &str) -> Result<(f64, f64, Option<f64>), String> {
    let numbers = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<f64>>>()
        .ok_or("AZ,EL[,DIST]: finite numbers")?;
    match numbers[..] {
        [az, el] => Ok((az, el, None)),
        [az, el, d] if d > 1.0 => Ok((az, el, Some(d))),
        [_, _, d] => Err(format!(
            "distance {d}: more than 1 radius (outside the sphere)"
        )),
        _ => Err("AZ,EL[,DIST]".to_string()),
    }
}

/// `subtess render`: every mesh drawn by one camera around all of them, side by side.
fn render_command(
    meshes: &[PathBuf],
    output: &Path,
    (width, height): (u32, u32),
    (azimuth, elevation, distance): (f64, f64, Option<f64>),
    wireframe: bool,
    z_up: bool,
) -> Result<(), RuntimeError> {
    let options = subtess::render::RenderOptions {
        width,
        height,
        azimuth,
        elevation,
        z_up,
        distance,
        wireframe,
    };
    let meshes = meshes
        .iter()
        .map(|path| subtess::io::mesh_input::read_triangles(path))
        .collect::<Result<Vec<_>, _>>()?;
    let all: Vec<[f32; 3]> = meshes
        .iter()
        .flat_map(|m| m.positions.iter().copied())
        .collect();
    let camera = subtess::render::Camera::orbit(&all, &options);
    let panels = meshes
        .iter()
        .map(|m| subtess::render::render(m, &camera, &options))
        .collect::<Result<Vec<_>, _>>()?;
    let image = subtess::render::Image::beside(&panels)
        .ok_or_else(|| RuntimeError::Unsupported("panels of different heights".to_string()))?;
    image.write_png(output)
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
    /// Subdivision scheme: catmull-clark (any polygons), loop and sqrt3 (triangles), butterfly
    /// (closed triangle meshes); the triangle schemes take --rate, --rates, --tolerance (not
    /// sqrt3 with a boundary) or --view.
    #[arg(long, default_value = "catmull-clark", value_parser = scheme_arg)]
    scheme: Scheme,
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
    /// Where the texture coordinates (the mesh's `vt`, catmull-clark) are linear instead of
    /// smooth: none, corners-only, corners-plus1, corners-plus2, boundaries or all
    /// (OpenSubdiv's face-varying linear interpolation, 0..5; default: the file's `t
    /// facevaryinginterpolateboundary`, else all).
    #[arg(long = "uv-interpolation", value_parser = uv_interpolation_arg)]
    uv_interpolation: Option<FaceVaryingMode>,
    /// Ignore the mesh's texture coordinates: no `vt` in the output and no vertices split
    /// along texture seams.
    #[arg(long = "no-uvs", conflicts_with = "uv_interpolation")]
    no_uvs: bool,
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
    #[arg(long, value_enum, default_value_t = Method::DualGrid)]
    method: Method,
    /// Adaptive: the tolerance is relative to each square's base quadrilateral's longer
    /// diagonal (Lai-Cheng section 6) instead of a distance.
    #[arg(long)]
    relative: bool,
    /// Adaptive: write triangles; without it an .obj output holds the polygons (n-gons).
    #[arg(long)]
    triangulate: bool,
    /// Dual grid: refuse an output estimated above N triangles, before allocating it
    /// (docs/reliability.md: 200 million, about 16 GB, by default).
    #[arg(long, default_value_t = subtess::DEFAULT_MAX_TRIANGLES, value_parser = clap::value_parser!(u64).range(1..))]
    max_triangles: u64,
    /// Adaptive: the deepest midpoint subdivision of a face's square (1..=24). A square still
    /// over the tolerance there is kept with its bound, counted in `--stats`'
    /// `leaves_over_tolerance`, and warned about (cone tips need about log T / log 0.654
    /// levels: docs/lai-cheng.md).
    #[arg(long, default_value_t = AdaptiveOptions::default().max_depth, value_parser = clap::value_parser!(u32).range(1..=i64::from(subtess::tessellate::lai_cheng::MAX_DEPTH)))]
    max_depth: u32,
    /// Adaptive: fail when meeting the tolerance needs more than N polygons (docs/reliability.md:
    /// 20 million, about 15 GB, by default).
    #[arg(long, default_value_t = subtess::tessellate::lai_cheng::DEFAULT_MAX_POLYGONS as u64, value_parser = clap::value_parser!(u64).range(1..))]
    max_polygons: u64,
}

#[derive(Subcommand)]
enum TablesCommand {
    /// What a table holds: format, scheme, precision, coverage, size (default: the embedded one).
    Info {
        /// A table file written by `stencilgen tables`.
        file: Option<PathBuf>,
        /// Without a file: which embedded default (catmull-clark, loop, butterfly or sqrt3).
        #[arg(long, default_value = "catmull-clark", conflicts_with = "file", value_parser = scheme_arg)]
        scheme: Scheme,
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

/// The mesh, its ignored tags reported on stderr.
fn load_mesh(path: &Path) -> Result<Mesh, RuntimeError> {
    let (mesh, warnings) = Mesh::read_obj_with_warnings(path)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(mesh)
}

/// The surface of `mesh`, with the table file or the scheme's embedded default.
fn load_surface(
    mesh: &Mesh,
    scheme: Scheme,
    table: &Option<PathBuf>,
) -> Result<Surface, RuntimeError> {
    match table {
        Some(path) => Surface::with_table(mesh, scheme, StencilTable::read(path)?),
        None => Surface::new(mesh, scheme),
    }
}

/// Per-input-face rates from a text file ([`subtess::tessellate::rates::parse_rates`]), its
/// messages naming the file.
fn read_rates(path: &Path, input_faces: usize) -> Result<Vec<u32>, RuntimeError> {
    let text = std::fs::read_to_string(path).map_err(|source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    })?;
    subtess::tessellate::rates::parse_rates(&text, input_faces).map_err(|e| match e {
        RuntimeError::ParseFile { line, message, .. } => RuntimeError::ParseFile {
            path: path.display().to_string(),
            line,
            message,
        },
        other => other,
    })
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
    let mut input = load_mesh(mesh)?;
    if let (Some(mode), Some(channel)) = (args.uv_interpolation, &mut input.face_varying) {
        channel.mode = mode;
    }
    if args.no_uvs {
        input.face_varying = None;
    }
    if input.face_varying.is_some() && args.scheme.is_triangle() {
        eprintln!(
            "warning: texture coordinates are interpolated with catmull-clark only; the --scheme {} output has none",
            args.scheme
        );
    }
    if args.method == Method::Adaptive && args.scheme.is_triangle() {
        return Err(RuntimeError::Unsupported(format!(
            "--scheme {} tessellates with the dual grid at --rate, --rates, --tolerance or --view (no --method adaptive yet)",
            args.scheme
        )));
    }
    let surface = load_surface(&input, args.scheme, &args.table)?;
    if args.method == Method::Adaptive {
        return adaptive_command(&args, &surface);
    }
    if args.relative || args.triangulate {
        return Err(RuntimeError::InvalidParameter {
            name: "--relative / --triangulate".to_owned(),
            reason: "they belong to --method adaptive".to_owned(),
        });
    }
    let rates = if let Some(path) = &args.rates {
        Rates::PerFace(read_rates(path, input.faces())?)
    } else if let Some(t) = args.tolerance {
        Rates::Tolerance(t)
    } else if let Some(camera) = &args.view {
        Rates::View(*camera)
    } else {
        Rates::Uniform(args.rate)
    };
    let mut tessellator = surface.tessellator_within(&rates, args.max_triangles)?;
    if let (Some(unmet @ 1..), Some(t), Some(largest)) = (
        tessellator.faces_over_tolerance(),
        args.tolerance,
        tessellator.rates().iter().max(),
    ) {
        let what = if args.scheme.is_triangle() {
            "triangles"
        } else {
            "faces"
        };
        eprintln!(
            "warning: {unmet} {what} do not meet the tolerance {t} at rate {largest}; they get {largest}"
        );
    }
    let started = Instant::now();
    let frame = tessellator.evaluate(&input.positions_f32())?;
    let seconds = started.elapsed().as_secs_f64();
    let output = frame.to_triangle_mesh();
    let closed = surface.boundary_loops() == 0;
    let (write_seconds, check) = write_and_check(
        args.stats,
        || write_mesh(&output, &args.output),
        || closed && output.is_watertight(),
    )?;
    if let Some((watertight, check_seconds)) = check {
        let mut stats = plan_stats(&surface, &tessellator);
        stats["write_seconds"] = write_seconds.into();
        stats["check_seconds"] = check_seconds.into();
        stats["seconds"] = seconds.into();
        stats["triangles_per_second"] =
            (tessellator.triangle_count() as f64 / seconds.max(1e-12)).into();
        stats["watertight"] = watertight.into();
        stats["uvs"] = surface.has_uvs().into();
        stats["seam_vertices"] = output.seam_copies.len().into();
        stats["tolerance"] = args.tolerance.into();
        out!("{stats}")?;
    }
    Ok(())
}

/// Write the output (`write`) and, for `--stats`, check that it is watertight (`check`) at the
/// same time, on the pool's threads: the check reads what the writer reads and costs a fraction
/// of it (docs/benchmarks.md, "Output"), so it leaves the critical path. The seconds of the
/// write, and with `stats` the check's answer and seconds.
fn write_and_check(
    stats: bool,
    write: impl FnOnce() -> Result<(), RuntimeError> + Send,
    check: impl FnOnce() -> bool + Send,
) -> Result<(f64, Option<(bool, f64)>), RuntimeError> {
    let writing = || {
        let started = Instant::now();
        write().map(|()| started.elapsed().as_secs_f64())
    };
    if !stats {
        return Ok((writing()?, None));
    }
    let (written, checked) = rayon::join(writing, || {
        let started = Instant::now();
        (check(), started.elapsed().as_secs_f64())
    });
    Ok((written?, Some(checked)))
}

/// The statistics every dual-grid run reports (docs/cli.md), less the timings of frames.
fn plan_stats(surface: &Surface, tessellator: &Tessellator<'_>) -> serde_json::Value {
    let rates = tessellator.rates();
    serde_json::json!({
        "scheme": surface.scheme().name(),
        "triangles": tessellator.triangle_count(),
        "vertices": tessellator.vertex_count(),
        "plan_seconds": tessellator.plan_seconds(),
        "rates_seconds": tessellator.rates_seconds(),
        "boundary_loops": surface.boundary_loops(),
        "input_faces": surface.input_faces(),
        "faces": surface.faces(),
        "isolation_steps": surface.isolation_steps(),
        "isolation_seconds": surface.isolation_seconds(),
        "refinement_weights": surface.refinement_weights(),
        "separable_faces": tessellator.separable_faces(),
        "refined_faces": tessellator.refined_faces(),
        "rate_min": rates.iter().min(),
        "rate_max": rates.iter().max(),
        "faces_over_tolerance": tessellator.faces_over_tolerance(),
        "threads": rayon::current_num_threads(),
    })
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
        out!("{}", stats.to_json())?;
    }
    Ok(())
}

/// `subtess tessellate MESH --method adaptive --tolerance T`.
fn adaptive_command(args: &TessellateArgs, surface: &Surface) -> Result<(), RuntimeError> {
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
        max_polygons: usize::try_from(args.max_polygons).unwrap_or(usize::MAX),
        max_depth: args.max_depth,
        ..AdaptiveOptions::default()
    };
    let (adaptive, stats) = surface.tessellate_adaptive(&options)?;
    if stats.leaves_over_tolerance > 0 {
        eprintln!(
            "warning: {} squares do not meet the tolerance {tolerance} at depth {} (--max-depth);              they are kept with their bounds",
            stats.leaves_over_tolerance, args.max_depth
        );
    }
    let polygons = MeshFormat::from_path(&args.output)? == MeshFormat::Obj && !args.triangulate;
    let closed = surface.boundary_loops() == 0;
    let (write_seconds, check) = write_and_check(
        args.stats,
        || {
            if polygons {
                write_obj_polygons(&adaptive, &args.output)
            } else {
                write_mesh(&adaptive.to_triangle_mesh(), &args.output)
            }
        },
        || closed && adaptive.is_watertight(),
    )?;
    if let Some((watertight, check_seconds)) = check {
        let mut report = stats.to_json();
        report["watertight"] = serde_json::json!(watertight);
        report["write_seconds"] = serde_json::json!(write_seconds);
        report["check_seconds"] = serde_json::json!(check_seconds);
        report["isolation_seconds"] = serde_json::json!(surface.isolation_seconds());
        out!("{report}")?;
    }
    Ok(())
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

/// The median of `seconds` (the upper one of an even count; zero for none).
fn median_seconds(mut seconds: Vec<f64>) -> f64 {
    seconds.sort_by(f64::total_cmp);
    seconds.get(seconds.len() / 2).copied().unwrap_or(0.0)
}

/// The keys every `subtess bench` report shares: what was measured, how, and what a frame does.
fn bench_keys(
    report: &mut serde_json::Value,
    args: &BenchArgs,
    pool: &rayon::ThreadPool,
    rates: String,
    per_frame: &str,
) {
    report["mesh"] = args.mesh.display().to_string().into();
    report["rates"] = rates.into();
    report["threads"] = pool.current_num_threads().into();
    report["frames"] = args.frames.into();
    report["per_frame"] = per_frame.into();
}

/// `subtess bench`'s settings.
struct BenchArgs {
    mesh: PathBuf,
    rate: u32,
    mixed: bool,
    tolerance: Option<f64>,
    adaptive: bool,
    motion: f64,
    threads: Option<usize>,
    steps: u32,
    max_triangles: u64,
    frames: u32,
    table: Option<PathBuf>,
    scheme: Scheme,
}

/// `subtess bench`: per-frame work from the input control points.
fn bench_command(args: BenchArgs) -> Result<(), RuntimeError> {
    let mut input = load_mesh(&args.mesh)?;
    // The refined mesh and its plan, estimated before refining: the largest rate on every face.
    // A tolerance chooses its rates after refining, and its plan checks its own estimate
    // (`Surface::tessellator_within`): before refining, only the refined mesh at rate 1.
    let largest_rate = match (args.tolerance, args.mixed) {
        (Some(_), _) => 1,
        (None, true) => 16,
        (None, false) => args.rate,
    };
    let face_sizes = input
        .face_offsets
        .windows(2)
        .map(|w| (w[1] - w[0]) as usize);
    let faces = refined_faces(args.scheme, face_sizes, args.steps);
    OutputEstimate::uniform(args.scheme.is_triangle(), faces, largest_rate).check(
        &format!(
            "--refine {} then rate {largest_rate} ({} faces after refinement)",
            args.steps, faces
        ),
        args.max_triangles,
    )?;
    for _ in 0..args.steps {
        input = args.scheme.refine(&input)?;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .map_err(|e| RuntimeError::Unsupported(format!("a pool of threads: {e}")))?;
    let (rates, rates_label) = if let Some(t) = args.tolerance {
        (Rates::Tolerance(t), format!("tolerance {t}"))
    } else if args.mixed {
        let per_face = (0..input.faces())
            .map(|f| [3, 5, 8, 12, 7, 16][f % 6])
            .collect();
        (Rates::PerFace(per_face), "mixed 3..16".to_owned())
    } else {
        (Rates::Uniform(args.rate), args.rate.to_string())
    };
    let mut surface = pool.install(|| load_surface(&input, args.scheme, &args.table))?;
    let control = input.positions_f32();
    if let (Some(tolerance), true) = (args.tolerance, args.adaptive) {
        return bench_adaptive_frames(&pool, &mut surface, tolerance, &control, &args);
    }
    if args.tolerance.is_some() {
        return bench_planned_frames(&pool, &mut surface, &rates, &control, &args, rates_label);
    }
    let mut tessellator =
        pool.install(|| surface.tessellator_within(&rates, args.max_triangles))?;
    // The input is valid (it was evaluated into the surface), so a frame cannot fail. In the
    // pool like every frame (a profiler that follows the frames' calls sees their work).
    pool.install(|| tessellator.evaluate(&control).map(|_| ()))?;
    let seconds = time_frames(&pool, args.frames, || {
        let _ = tessellator.evaluate(&control);
    });
    let median = seconds[seconds.len() / 2];
    let mut report = plan_stats(&surface, &tessellator);
    bench_keys(
        &mut report,
        &args,
        &pool,
        rates_label,
        "from the input control points: refinement stencils, then positions and normals (triangles are connected once, in the plan)",
    );
    report["median_seconds"] = median.into();
    report["min_seconds"] = seconds[0].into();
    report["max_seconds"] = seconds[seconds.len() - 1].into();
    report["triangles_per_second"] =
        (tessellator.triangle_count() as f64 / median.max(1e-12)).into();
    out!("{report}")?;
    Ok(())
}

/// `subtess bench --tolerance`: every frame sets the surface's positions, plans at the rates
/// the tolerance chooses on them and evaluates; the medians of each part's seconds.
fn bench_planned_frames(
    pool: &rayon::ThreadPool,
    surface: &mut Surface,
    rates: &Rates,
    control: &[[f32; 3]],
    args: &BenchArgs,
    rates_label: String,
) -> Result<(), RuntimeError> {
    // [rates, plan after the rates, evaluate, the whole frame, faces sampled] of every frame.
    let mut parts: Vec<[f64; 5]> = Vec::new();
    let mut report = serde_json::Value::Null;
    // The frames' points, made before the timing.
    let moved: Vec<Vec<[f32; 3]>> = (0..=args.frames)
        .map(|frame| joint_motion(control, args.motion, frame))
        .collect();
    pool.install(|| -> Result<(), RuntimeError> {
        // One frame untimed (the table's grids are expanded on first use, and the rates are
        // chosen on every face), then the frames.
        for (frame, points) in moved.iter().enumerate() {
            let started = Instant::now();
            surface.set_positions(points)?;
            let mut tessellator = surface.tessellator_within(rates, args.max_triangles)?;
            let planned = Instant::now();
            tessellator.evaluate(points)?;
            let (evaluate, whole) = (planned.elapsed(), started.elapsed());
            if frame > 0 {
                let rates = tessellator.rates_seconds();
                parts.push([
                    rates,
                    tessellator.plan_seconds() - rates,
                    evaluate.as_secs_f64(),
                    whole.as_secs_f64(),
                    tessellator.faces_sampled().map_or(f64::NAN, |n| n as f64),
                ]);
            }
            if frame == args.frames as usize {
                report = plan_stats(surface, &tessellator);
            }
        }
        Ok(())
    })?;
    let median = |k: usize| median_seconds(parts.iter().map(|p| p[k]).collect());
    bench_keys(
        &mut report,
        args,
        pool,
        rates_label,
        "set the positions, choose the rates, plan at them, evaluate from the input control points",
    );
    report["median_rates_seconds"] = median(0).into();
    report["median_plan_seconds"] = median(1).into();
    report["median_evaluate_seconds"] = median(2).into();
    report["median_seconds"] = median(3).into();
    report["motion_degrees"] = args.motion.into();
    let sampled = median(4);
    if sampled.is_finite() {
        report["median_faces_sampled"] = sampled.into();
    }
    out!("{report}")?;
    Ok(())
}

/// Frame `frame` of `subtess bench --motion DEGREES`: the points beyond the middle of the
/// bounding box's longest side turned about the box's shortest axis (through its centre) by
/// `DEGREES sin(2 pi frame / 60)`, blended by a smoothstep across a band of a tenth of that side
/// about the middle, as skinning bends an arm at a joint; `points` itself for 0 degrees.
fn joint_motion(points: &[[f32; 3]], degrees: f64, frame: u32) -> Vec<[f32; 3]> {
    if degrees == 0.0 {
        return points.to_vec();
    }
    let (mut low, mut high) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for c in 0..3 {
            low[c] = low[c].min(f64::from(p[c]));
            high[c] = high[c].max(f64::from(p[c]));
        }
    }
    let extent = [0, 1, 2].map(|c| high[c] - low[c]);
    let mut axes = [0, 1, 2];
    axes.sort_by(|&a, &b| extent[b].total_cmp(&extent[a]));
    let [long, middle, _] = axes;
    let centre = [0, 1, 2].map(|c| 0.5 * (low[c] + high[c]));
    let angle = degrees.to_radians() * (std::f64::consts::TAU * f64::from(frame) / 60.0).sin();
    let band = 0.05 * extent[long];
    points
        .iter()
        .map(|p| {
            let along = f64::from(p[long]) - centre[long];
            let t = ((along + band) / (2.0 * band)).clamp(0.0, 1.0);
            let (sin, cos) = (angle * t * t * (3.0 - 2.0 * t)).sin_cos();
            let (x, y) = (
                f64::from(p[long]) - centre[long],
                f64::from(p[middle]) - centre[middle],
            );
            let mut q = *p;
            q[long] = (centre[long] + cos * x - sin * y) as f32;
            q[middle] = (centre[middle] + sin * x + cos * y) as f32;
            q
        })
        .collect()
}

/// `subtess bench --tolerance T --adaptive`: every frame sets the surface's positions and
/// tessellates adaptively into triangles; the first frame (which makes the patch kinds'
/// operators, kept by the surface) is reported apart, the median over the others.
fn bench_adaptive_frames(
    pool: &rayon::ThreadPool,
    surface: &mut Surface,
    tolerance: f64,
    control: &[[f32; 3]],
    args: &BenchArgs,
) -> Result<(), RuntimeError> {
    let options = AdaptiveOptions {
        tolerance,
        triangulate: true,
        ..AdaptiveOptions::default()
    };
    let mut seconds = Vec::new();
    let mut last = None;
    // One output kept from frame to frame, as an animation would keep it.
    let mut out = AdaptiveMesh::default();
    pool.install(|| -> Result<(), RuntimeError> {
        for _ in 0..=args.frames {
            let started = Instant::now();
            surface.set_positions(control)?;
            let stats = surface.tessellate_adaptive_into(&options, &mut out)?;
            seconds.push(started.elapsed().as_secs_f64());
            last = Some(stats);
        }
        Ok(())
    })?;
    let first = seconds.remove(0);
    let median = median_seconds(seconds);
    let triangles = last.as_ref().map_or(0, |stats| stats.triangles);
    let mut report = last.map_or(serde_json::Value::Null, |stats| stats.to_json());
    bench_keys(
        &mut report,
        args,
        pool,
        format!("adaptive, tolerance {tolerance}"),
        "set the positions, tessellate adaptively (Lai–Cheng) into triangles, into an output kept from frame to frame",
    );
    report["first_frame_seconds"] = first.into();
    report["median_seconds"] = median.into();
    report["triangles_per_second"] = (triangles as f64 / median.max(1e-12)).into();
    out!("{report}")?;
    Ok(())
}

/// `subtess eval`.
fn eval_command(
    mesh: &Path,
    scheme: Scheme,
    face: usize,
    uv: &str,
    corner: usize,
    json: bool,
) -> Result<(), RuntimeError> {
    let (u, v) = uv
        .split_once(',')
        .ok_or_else(|| RuntimeError::InvalidParameter {
            name: format!("--uv `{}`", subtess::error::excerpt(uv)),
            reason: "two rationals `U,V` wanted".to_owned(),
        })?;
    let (u, v) = (parse_rational(u.trim())?, parse_rational(v.trim())?);
    let input = load_mesh(mesh)?;
    let point = eval::limit_point(&input, scheme, face, corner, &u, &v)?;
    let uv = match scheme {
        Scheme::CatmullClark => eval::limit_uv(&input, face, corner, &u, &v)?,
        _ => None,
    };
    if json {
        let mut report = serde_json::json!({
            "position": point.position,
            "du": point.du,
            "dv": point.dv,
        });
        if let Some(uv) = uv {
            report["uv"] = serde_json::json!(uv);
        }
        out!("{report}")?;
    } else {
        out!("position {:?}", point.position)?;
        out!("du       {:?}", point.du)?;
        out!("dv       {:?}", point.dv)?;
        if let Some(uv) = uv {
            out!("uv       {uv:?}")?;
        }
    }
    Ok(())
}

/// `subtess tables info`.
fn tables_info(file: Option<PathBuf>, scheme: Scheme) -> Result<(), RuntimeError> {
    let (name, table) = match &file {
        Some(path) => (path.display().to_string(), StencilTable::read(path)?),
        None => (
            format!("(embedded default, {scheme})"),
            scheme.default_table(schemes::BoundaryMode::EdgeOnly)?,
        ),
    };
    let index = table.index();
    let weights: u64 = index
        .entries
        .iter()
        .map(|e| u64::from(e.points) * u64::from(e.width))
        .sum();
    out!("table:      {name}")?;
    out!(
        "format:     version {}, little-endian, checksum {:#018x} (verified)",
        index.version,
        index.checksum
    )?;
    out!("scheme:     {}", index.meta.scheme.name())?;
    out!(
        "boundary:   {}",
        if index.meta.corners {
            "edge and corner (one-face vertices pinned)"
        } else {
            "edge only"
        }
    )?;
    out!("precision:  {}", index.meta.precision)?;
    out!("covers:     {}", index.coverage())?;
    out!(
        "sections:   {} ({})",
        index.entries.len(),
        match (table.is_compact(), index.meta.scheme) {
            (true, table_format::SchemeId::Butterfly | table_format::SchemeId::Sqrt3) => {
                "compact: the regular basis on 1/3n and a marker per rate; A and the vertex \
                 masks per valence, the tile rows per region; the grids are expanded when a \
                 plan needs them"
            }
            (true, scheme) if !scheme.is_triangle() => {
                "compact: the regular curve basis per rate; A, the sub-patch matrices and the \
                 vertex masks per patch; the grids are expanded when a plan needs them"
            }
            (true, _) => {
                "compact: the Loop basis on the lattice 1/4 and a marker per rate; A, the \
                 sub-triangle matrices and the vertex masks per patch; the grids are expanded \
                 when a plan needs them"
            }
            (false, _) => "grids; positions, d/du, d/dv",
        }
    )?;
    out!("weights:    {weights}")?;
    out!(
        "size:       {} bytes ({:.1} MiB)",
        table.bytes().len(),
        table.bytes().len() as f64 / (1024.0 * 1024.0)
    )?;
    Ok(())
}

fn run(cli: Cli) -> Result<(), RuntimeError> {
    match cli.command {
        Command::Tessellate(args) => tessellate_command(*args),
        Command::Bench {
            mesh,
            rate,
            mixed,
            tolerance,
            adaptive,
            motion,
            threads,
            refine,
            max_triangles,
            frames,
            table,
            scheme,
        } => bench_command(BenchArgs {
            mesh,
            rate,
            mixed,
            tolerance,
            adaptive,
            motion,
            threads,
            steps: refine,
            max_triangles,
            frames,
            table,
            scheme,
        }),
        Command::Eval {
            mesh,
            scheme,
            face,
            uv,
            corner,
            json,
        } => eval_command(&mesh, scheme, face, &uv, corner, json),
        Command::Tables {
            command: TablesCommand::Info { file, scheme },
        } => tables_info(file, scheme),
        Command::Render {
            meshes,
            output,
            size,
            view,
            wireframe,
            z_up,
        } => render_command(&meshes, &output, size, view, wireframe, z_up),
    }
}
