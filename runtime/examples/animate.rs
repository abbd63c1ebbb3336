//! An animated surface: the topology is fixed, the input control points move every frame.
//!
//! `cargo run --release -p subtess --example animate -- [MESH.obj] [--rate N] [--frames F]
//! [-o LAST.obj]` (default: the shipped cube, rate 8, 120 frames). The surface (isolation) and
//! the tessellator (the plan) are built once; every frame twists the input cage about its
//! vertical axis and evaluates the limit surface of the moved cage, no refinement involved.

use std::time::Instant;

use subtess::io::mesh_output::write_mesh;
use subtess::{Mesh, Rates, RuntimeError, Scheme, Surface};

/// The rest pose twisted by `angle` radians per unit of height about the y axis.
fn twist(rest: &[[f32; 3]], angle: f32) -> Vec<[f32; 3]> {
    rest.iter()
        .map(|&[x, y, z]| {
            let (s, c) = (angle * y).sin_cos();
            [c * x - s * z, y, s * x + c * z]
        })
        .collect()
}

fn main() -> Result<(), RuntimeError> {
    let mut path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/cube.obj").to_owned();
    let (mut rate, mut frames, mut output) = (8u32, 120u32, None);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| {
            args.next().ok_or_else(|| RuntimeError::InvalidParameter {
                name: name.to_owned(),
                reason: "it needs a value".to_owned(),
            })
        };
        let number = |name: &str, text: String| {
            text.parse::<u32>()
                .map_err(|_| RuntimeError::InvalidParameter {
                    name: name.to_owned(),
                    reason: format!("`{text}` is not a whole number"),
                })
        };
        match arg.as_str() {
            "--rate" => rate = number("--rate", value("--rate")?)?,
            "--frames" => frames = number("--frames", value("--frames")?)?.max(1),
            "-o" => output = Some(value("-o")?),
            _ => path = arg,
        }
    }
    let mesh = Mesh::read_obj(&path)?;
    let surface = Surface::new(&mesh, Scheme::CatmullClark)?;
    let mut tessellator = surface.tessellator(&Rates::Uniform(rate))?;
    let rest = mesh.positions_f32();
    let started = Instant::now();
    let mut last = None;
    for frame in 0..frames {
        let angle = 1.5 * (frame as f32 / frames as f32 * std::f32::consts::TAU).sin();
        let moved = twist(&rest, angle);
        let evaluated = tessellator.evaluate(&moved)?;
        if frame + 1 == frames {
            last = Some(evaluated.to_triangle_mesh());
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    println!(
        "{path}: {} input faces, {} after {} isolation step(s) ({:.3} s), plan {:.3} s; \
         {frames} frames of {} triangles in {seconds:.3} s ({:.1} M triangles/s, twist included)",
        surface.input_faces(),
        surface.faces(),
        surface.isolation_steps(),
        surface.isolation_seconds(),
        tessellator.plan_seconds(),
        tessellator.triangle_count(),
        f64::from(frames) * tessellator.triangle_count() as f64 / seconds / 1e6,
    );
    if let (Some(out), Some(mesh)) = (output, last) {
        write_mesh(&mesh, std::path::Path::new(&out))?;
        println!("last frame written to {out}");
    }
    Ok(())
}
