//! A small software rasterizer for looking at meshes (`subtess render`): a perspective orbit
//! camera around the mesh's bounding sphere, a z-buffer, two-sided Lambert shading, smooth from
//! area-weighted vertex normals except across edges sharper than about 35 degrees (a control
//! mesh's facets stay flat), an optional wireframe, a checkerboard where the mesh has
//! texture coordinates, 3 x 3 supersampling, and a PNG out.
//!
//! Deterministic: the image is cut into bands of rows rasterized in parallel, each band drawing
//! every triangle in input order, so the same mesh and options give the same bytes on any
//! number of threads.

use std::io::Write as _;
use std::path::Path;

use rayon::prelude::*;

use crate::io::atomic::write_atomically;
use crate::io::mesh_input::Triangles;
use crate::mesh::geometry::{cross, dot, normalize as unit, sub};
use crate::RuntimeError;

/// What to draw and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera azimuth around the up axis, degrees; 0 looks along -z (+y up) or +y (+z up).
    pub azimuth: f64,
    /// Camera elevation above the plane normal to the up axis, degrees.
    pub elevation: f64,
    /// Whether +z is up (as in CAD files) rather than +y (as in most OBJ files).
    pub z_up: bool,
    /// Distance from the bounding sphere's centre in units of its radius; `None` frames the
    /// sphere in the image.
    pub distance: Option<f64>,
    /// Draw every triangle's edges.
    pub wireframe: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            azimuth: 30.0,
            elevation: 20.0,
            z_up: false,
            distance: None,
            wireframe: false,
        }
    }
}

/// Vertical field of view of the camera.
const FOV_DEGREES: f64 = 30.0;

/// Samples per pixel along each axis.
const SUPERSAMPLE: usize = 3;

/// Largest image side accepted, in pixels.
pub const MAX_SIDE: u32 = 8192;

/// A perspective camera: `eye`, an orthonormal frame (`right`, `up`, `forward`) and the focal
/// length in pixels of the image it draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub eye: [f64; 3],
    /// Screen x.
    pub right: [f64; 3],
    /// Screen y (up).
    pub up: [f64; 3],
    /// The viewing direction.
    pub forward: [f64; 3],
    /// Pixels per unit of `x / depth`.
    pub focal: f64,
    /// Image size in pixels.
    pub size: [f64; 2],
}

impl Camera {
    /// The orbit camera of `options` around the bounding sphere of `positions` (centre of the
    /// bounding box, half its diagonal): at distance `d r` from the centre, with `d` by default
    /// the distance at which the sphere's silhouette fills 90% of the smaller image side.
    pub fn orbit(positions: &[[f32; 3]], options: &RenderOptions) -> Camera {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in positions {
            for c in 0..3 {
                lo[c] = lo[c].min(f64::from(p[c]));
                hi[c] = hi[c].max(f64::from(p[c]));
            }
        }
        if positions.is_empty() {
            (lo, hi) = ([-1.0; 3], [1.0; 3]);
        }
        let centre: [f64; 3] = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
        let radius = (0..3)
            .map(|c| (hi[c] - lo[c]).powi(2))
            .sum::<f64>()
            .sqrt()
            .max(f64::MIN_POSITIVE)
            * 0.5;
        let (w, h) = (f64::from(options.width), f64::from(options.height));
        let half = (FOV_DEGREES.to_radians() / 2.0).tan();
        let focal = 0.5 * h / half;
        // A sphere at distance D subtends asin(r / D); fill 90% of the smaller half-side.
        let fill = 0.9 * 0.5 * w.min(h) / focal;
        let distance = options
            .distance
            .unwrap_or_else(|| (1.0 + fill * fill).sqrt() / fill);
        let (az, el) = (options.azimuth.to_radians(), options.elevation.to_radians());
        let (back, world_up, pole) = if options.z_up {
            (
                [el.cos() * az.sin(), -el.cos() * az.cos(), el.sin()],
                [0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0],
            )
        } else {
            (
                [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, -1.0],
            )
        };
        let eye = std::array::from_fn(|c| centre[c] + distance * radius * back[c]);
        let forward = back.map(|x| -x);
        // Straight above or below, "up" on the screen is the horizontal axis the camera faced.
        let world_up = if el.cos().abs() < 1e-9 {
            pole.map(|x| x * el.sin().signum())
        } else {
            world_up
        };
        let right = unit(cross(forward, world_up));
        let up = cross(right, forward);
        Camera {
            eye,
            right,
            up,
            forward,
            focal,
            size: [w, h],
        }
    }

    /// Pixel coordinates (x right, y down, pixel centres at half-integers) and depth of `p`;
    /// `None` behind the camera.
    pub fn project(&self, p: [f32; 3]) -> Option<[f64; 3]> {
        let q: [f64; 3] = std::array::from_fn(|c| f64::from(p[c]) - self.eye[c]);
        let depth = dot(q, self.forward);
        (depth > 1e-9).then(|| {
            [
                0.5 * self.size[0] + self.focal * dot(q, self.right) / depth,
                0.5 * self.size[1] - self.focal * dot(q, self.up) / depth,
                depth,
            ]
        })
    }
}

/// An RGB image, 8 bits per channel, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 * width * height` bytes.
    pub rgb: Vec<u8>,
    /// The fraction of the image's samples the mesh covers.
    pub coverage: f64,
}

impl Image {
    /// The images side by side, left to right, on one row; `None` unless all have one height
    /// (or if the width overflows).
    pub fn beside(images: &[Image]) -> Option<Image> {
        let height = images.first()?.height;
        if images.iter().any(|i| i.height != height) {
            return None;
        }
        let width = images
            .iter()
            .try_fold(0u32, |sum, i| sum.checked_add(i.width))?;
        let mut rgb = Vec::with_capacity(3 * width as usize * height as usize);
        for y in 0..height as usize {
            for image in images {
                let row = 3 * image.width as usize;
                rgb.extend_from_slice(&image.rgb[y * row..(y + 1) * row]);
            }
        }
        let coverage = images
            .iter()
            .map(|i| i.coverage * f64::from(i.width))
            .sum::<f64>()
            / f64::from(width);
        Some(Image {
            width,
            height,
            rgb,
            coverage,
        })
    }

    /// Encode as PNG.
    pub fn png(&self) -> Result<Vec<u8>, RuntimeError> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let fail = |e: png::EncodingError| RuntimeError::Unsupported(format!("PNG encoding: {e}"));
        let mut writer = encoder.write_header().map_err(fail)?;
        writer.write_image_data(&self.rgb).map_err(fail)?;
        writer.finish().map_err(fail)?;
        Ok(out)
    }

    /// Write as a PNG file, all or nothing ([`crate::io::atomic`]).
    pub fn write_png(&self, path: &Path) -> Result<(), RuntimeError> {
        let bytes = self.png()?;
        write_atomically(path, |w| {
            w.write_all(&bytes).map_err(|source| RuntimeError::Io {
                path: path.display().to_string(),
                source,
            })
        })
    }
}

const BACKGROUND: [u8; 3] = [255, 255, 255];
const SURFACE: [f64; 3] = [0.72, 0.77, 0.86];
const CHECKER_DARK: [f64; 3] = [0.25, 0.28, 0.36];
const WIRE: [f64; 3] = [0.1, 0.1, 0.12];

/// A triangle's normal scaled by twice its area.
fn face_normal(mesh: &Triangles, t: &[u32; 3]) -> [f64; 3] {
    let p = t.map(|v| mesh.positions[v as usize].map(f64::from));
    cross(sub(p[1], p[0]), sub(p[2], p[0]))
}

/// Where a triangle's normal and its corner's vertex normal differ by more than this angle's
/// cosine (about 35 degrees), the corner is shaded with the triangle's own normal.
const CREASE_COS: f64 = 0.82;

/// Area-weighted vertex normals (the cross products summed, then normalized).
fn vertex_normals(mesh: &Triangles) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0f64; 3]; mesh.positions.len()];
    for t in &mesh.triangles {
        let n = face_normal(mesh, t);
        for &v in t {
            for c in 0..3 {
                normals[v as usize][c] += n[c];
            }
        }
    }
    normals.into_iter().map(unit).collect()
}

/// One sample: depth (0 where nothing is drawn) and colour.
#[derive(Clone, Copy)]
struct Sample {
    depth: f64,
    colour: [f64; 3],
}

/// Render `mesh` seen by `camera` (made for `options`' image size, e.g. by [`Camera::orbit`]
/// around this mesh or around several drawn side by side).
pub fn render(
    mesh: &Triangles,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Image, RuntimeError> {
    mesh.check()
        .map_err(|reason| RuntimeError::InvalidParameter {
            name: "mesh to render".to_string(),
            reason,
        })?;
    for (name, side) in [("width", options.width), ("height", options.height)] {
        if !(1..=MAX_SIDE).contains(&side) {
            return Err(RuntimeError::InvalidParameter {
                name: name.to_string(),
                reason: format!("{side} pixels; 1..={MAX_SIDE}"),
            });
        }
    }
    let normals = vertex_normals(mesh);
    let projected: Vec<Option<[f64; 3]>> =
        mesh.positions.iter().map(|&p| camera.project(p)).collect();
    // A key light above and to the left of the viewer, fixed to the camera.
    let light = unit(std::array::from_fn(|c| {
        -camera.forward[c] + 0.5 * camera.up[c] - 0.4 * camera.right[c]
    }));
    let (w, h) = (options.width as usize, options.height as usize);
    let (sw, sh) = (w * SUPERSAMPLE, h * SUPERSAMPLE);
    let s = SUPERSAMPLE as f64;
    const BAND: usize = 8 * SUPERSAMPLE;
    let empty = Sample {
        depth: 0.0,
        colour: BACKGROUND.map(|b| f64::from(b) / 255.0),
    };
    let mut samples = vec![empty; sw * sh];
    samples
        .par_chunks_mut(sw * BAND)
        .enumerate()
        .for_each(|(band, rows)| {
            let y0 = band * BAND;
            let y1 = y0 + rows.len() / sw;
            for t in &mesh.triangles {
                let [Some(a), Some(b), Some(c)] = t.map(|v| projected[v as usize]) else {
                    continue;
                };
                // Supersampled pixel coordinates.
                let [a, b, c] = [a, b, c].map(|p| [p[0] * s, p[1] * s, p[2]]);
                let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                if area.abs() < 1e-12 {
                    continue;
                }
                let ymin = a[1].min(b[1]).min(c[1]).floor().max(y0 as f64) as usize;
                let ymax = (a[1].max(b[1]).max(c[1]).ceil().min(y1 as f64 - 1.0)).max(-1.0);
                let xmin = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
                let xmax = a[0].max(b[0]).max(c[0]).ceil().min(sw as f64 - 1.0);
                if ymax < ymin as f64 || xmax < xmin as f64 {
                    continue;
                }
                let edges = [[b, c], [c, a], [a, b]];
                // Smooth across gentle angles, flat across sharp ones (a control mesh's edges).
                let flat = unit(face_normal(mesh, t));
                let corners = t.map(|v| {
                    let n = normals[v as usize];
                    if dot(n, flat) > CREASE_COS {
                        n
                    } else {
                        flat
                    }
                });
                let lengths = edges.map(|[p, q]| (q[0] - p[0]).hypot(q[1] - p[1]));
                for y in ymin..=ymax as usize {
                    let py = y as f64 + 0.5;
                    for x in xmin..=xmax as usize {
                        let px = x as f64 + 0.5;
                        // Barycentric weights from the edge functions, either orientation.
                        let e = edges.map(|[p, q]| {
                            ((q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0])) / area
                        });
                        if e.iter().any(|&k| k < 0.0) {
                            continue;
                        }
                        // Perspective-correct: interpolate 1 / depth, then the attributes.
                        let inverse = e[0] / a[2] + e[1] / b[2] + e[2] / c[2];
                        let sample = &mut rows[(y - y0) * sw + x];
                        if inverse <= sample.depth {
                            continue;
                        }
                        let weights = [e[0] / a[2], e[1] / b[2], e[2] / c[2]].map(|k| k / inverse);
                        let n = unit(std::array::from_fn(|k| {
                            (0..3).map(|i| weights[i] * corners[i][k]).sum()
                        }));
                        let lambert = dot(n, light).abs();
                        let mut base = SURFACE;
                        if let Some(uvs) = &mesh.uvs {
                            let uv: [f64; 2] = std::array::from_fn(|k| {
                                (0..3)
                                    .map(|i| weights[i] * f64::from(uvs[t[i] as usize][k]))
                                    .sum()
                            });
                            if ((8.0 * uv[0]).floor() + (8.0 * uv[1]).floor()) as i64 % 2 != 0 {
                                base = CHECKER_DARK;
                            }
                        }
                        let mut colour = base.map(|b| b * (0.25 + 0.75 * lambert));
                        if options.wireframe {
                            // Lines about 0.7 pixels wide, half opaque.
                            let near = (0..3)
                                .map(|i| e[i] * area.abs() / lengths[i])
                                .fold(f64::INFINITY, f64::min);
                            if near < 0.35 * s {
                                colour = std::array::from_fn(|k| 0.5 * (colour[k] + WIRE[k]));
                            }
                        }
                        *sample = Sample {
                            depth: inverse,
                            colour,
                        };
                    }
                }
            }
        });
    let covered = samples.iter().filter(|s| s.depth > 0.0).count();
    let mut rgb = vec![0u8; 3 * w * h];
    rgb.par_chunks_mut(3 * w).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            for k in 0..3 {
                let mut sum = 0.0;
                for dy in 0..SUPERSAMPLE {
                    for dx in 0..SUPERSAMPLE {
                        sum +=
                            samples[(y * SUPERSAMPLE + dy) * sw + x * SUPERSAMPLE + dx].colour[k];
                    }
                }
                let mean = sum / (SUPERSAMPLE * SUPERSAMPLE) as f64;
                row[3 * x + k] = (mean.clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        }
    });
    Ok(Image {
        width: options.width,
        height: options.height,
        rgb,
        coverage: covered as f64 / samples.len() as f64,
    })
}

#[cfg(test)]
// Two tests render the shipped cube through the embedded Catmull–Clark table; without it, their
// helpers go unused.
#[cfg_attr(not(feature = "catmull-clark"), allow(unused))]
mod tests {
    use super::*;
    use crate::{Mesh, Rates, Scheme, Surface};

    /// The limit surface of the shipped cube at rate 12, as triangles.
    fn limit_cube() -> Triangles {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let mesh = Mesh::read_obj(&path).expect("the shipped cube");
        let surface = Surface::new(&mesh, Scheme::CatmullClark).expect("a surface");
        let mut tessellator = surface.tessellator(&Rates::Uniform(12)).expect("a plan");
        let frame = tessellator
            .evaluate(&mesh.positions_f32())
            .expect("a frame");
        Triangles {
            positions: frame.positions().to_vec(),
            triangles: frame.triangles().to_vec(),
            uvs: None,
        }
    }

    /// The same mesh renders to the same bytes, on one thread as on several.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn rendering_is_deterministic() {
        let cube = limit_cube();
        let options = RenderOptions {
            width: 160,
            height: 120,
            wireframe: true,
            ..RenderOptions::default()
        };
        let camera = Camera::orbit(&cube.positions, &options);
        let a = render(&cube, &camera, &options)
            .expect("renders")
            .png()
            .expect("encodes");
        let b = render(&cube, &camera, &options)
            .expect("renders")
            .png()
            .expect("encodes");
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a pool");
        let c = pool
            .install(|| render(&cube, &camera, &options))
            .expect("renders")
            .png()
            .expect("encodes");
        assert_eq!(a, b);
        assert_eq!(a, c);
        assert_eq!(&a[1..4], b"PNG");
    }

    /// Area of the convex hull of 2D points (Andrew's monotone chain, then the shoelace).
    fn hull_area(mut points: Vec<[f64; 2]>) -> f64 {
        points.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
        let turn = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
            (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
        };
        let mut hull: Vec<[f64; 2]> = Vec::new();
        for pass in [points.clone(), points.into_iter().rev().collect()] {
            let start = hull.len();
            for p in pass {
                while hull.len() >= start + 2
                    && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
                {
                    hull.pop();
                }
                hull.push(p);
            }
            hull.pop();
        }
        let n = hull.len();
        (0..n)
            .map(|i| {
                let (p, q) = (hull[i], hull[(i + 1) % n]);
                p[0] * q[1] - p[1] * q[0]
            })
            .sum::<f64>()
            .abs()
            / 2.0
    }

    /// The cube's limit surface is convex, so its silhouette is the convex hull of its
    /// projected vertices: the rasterized coverage matches the hull's area (an independent
    /// computation) within 0.5%, from several directions and distances.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn the_silhouette_of_a_convex_limit_surface_covers_its_hull() {
        let cube = limit_cube();
        for (azimuth, elevation, distance) in [
            (30.0, 20.0, None),
            (0.0, 0.0, Some(4.0)),
            (75.0, -40.0, Some(2.5)),
        ] {
            let options = RenderOptions {
                width: 200,
                height: 150,
                azimuth,
                elevation,
                z_up: false,
                distance,
                wireframe: false,
            };
            let camera = Camera::orbit(&cube.positions, &options);
            let image = render(&cube, &camera, &options).expect("renders");
            let points = cube
                .positions
                .iter()
                .map(|&p| {
                    let q = camera.project(p).expect("in front");
                    [q[0], q[1]]
                })
                .collect();
            let expected = hull_area(points) / (200.0 * 150.0);
            println!(
                "view ({azimuth}, {elevation}, {distance:?}): coverage {:.5}, hull {expected:.5}",
                image.coverage
            );
            assert!(
                (image.coverage - expected).abs() < 0.005 * expected,
                "view ({azimuth}, {elevation}, {distance:?}): coverage {} vs hull {expected}",
                image.coverage
            );
            assert!(expected > 0.1, "the cube fills a good part of the image");
        }
    }

    /// Triangles built by a caller are checked before they are indexed: a vertex beyond the
    /// positions or texture coordinates of another count is an error, not a panic.
    #[test]
    fn inconsistent_meshes_are_refused() {
        let options = RenderOptions::default();
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let camera = Camera::orbit(&positions, &options);
        let beyond = Triangles {
            positions: positions.clone(),
            triangles: vec![[0, 1, 3]],
            uvs: None,
        };
        let e = render(&beyond, &camera, &options).expect_err("refused");
        assert!(e.to_string().contains("beyond the 3 vertices"), "{e}");
        let uvs = Triangles {
            positions,
            triangles: vec![[0, 1, 2]],
            uvs: Some(vec![[0.0, 0.0]]),
        };
        let e = render(&uvs, &camera, &options).expect_err("refused");
        assert!(
            e.to_string()
                .contains("1 texture coordinates for 3 vertices"),
            "{e}"
        );
    }
}
