//! subtess's texture coordinates against OpenSubdiv 3.7's face-varying limit surface, on every
//! OpenSubdiv regression shape in `shared/models/opensubdiv/` whose faces all name `vt`, in all
//! six modes (the shape's own `t facevaryinginterpolateboundary` is overridden).
//!
//! Run with the parity test's command (`opensubdiv_parity.rs`), filter `opensubdiv_fvar_parity`;
//! `SUBTESS_FVAR_PARITY_TABLE=path` writes the table as markdown.
//!
//! Per shape and mode: subtess tessellates at `Rates::Uniform(4)` and every output vertex's
//! texture coordinates are compared with OpenSubdiv's at its source (the Ptex point, as in the
//! position harness): a `Far::LimitStencilTable` in face-varying mode (channel 0) on a
//! `Far::TopologyRefiner` whose descriptor carries the shape's `vt` as its one channel
//! (`subtess-opensubdiv-fvar`), refined adaptively to level 10 with the face-varying channel
//! considered and infinitely sharp patches, the stencils applied in f64 to the `vt` values.
//! Points without an OpenSubdiv patch (holes) are counted, not compared. *Faithful*: the largest
//! difference in either coordinate below 1e-5 (texture units).
#![cfg(feature = "opensubdiv")]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use opensubdiv_petite::far;
use subtess::FaceVaryingMode;
use subtess_opensubdiv_fvar::{attach, FaceVaryingChannel};

use crate::opensubdiv_parity::{
    descriptor, located_stencils, models, osd_tags, parse_shape, Far, Shape, RATE,
};

const FAITHFUL: f64 = 1e-5;

fn osd_mode(mode: FaceVaryingMode) -> Option<far::FaceVaryingLinearInterpolation> {
    use far::FaceVaryingLinearInterpolation as Osd;
    match mode {
        FaceVaryingMode::None => None,
        FaceVaryingMode::CornersOnly => Some(Osd::CornersOnly),
        FaceVaryingMode::CornersPlus1 => Some(Osd::CornersPlusOne),
        FaceVaryingMode::CornersPlus2 => Some(Osd::CornersPlusTwo),
        FaceVaryingMode::Boundaries => Some(Osd::Boundaries),
        FaceVaryingMode::All => Some(Osd::All),
    }
}

#[derive(Default)]
struct Row {
    name: String,
    mode: String,
    points: usize,
    /// Points OpenSubdiv has no patch at.
    missing: usize,
    worst: Option<f64>,
    worst_at: String,
    refused: Option<String>,
}

impl Row {
    fn verdict(&self) -> &'static str {
        match (&self.refused, self.worst) {
            (Some(_), _) => "refused",
            (None, Some(w)) if w < FAITHFUL => "faithful",
            (None, None) => "faithful",
            _ => "differs",
        }
    }
}

/// subtess's sources and texture coordinates at `mode`.
fn ours(
    path: &Path,
    mode: FaceVaryingMode,
) -> Result<(Vec<subtess::VertexSource>, Vec<[f32; 2]>), String> {
    let (mut mesh, _) = subtess::Mesh::read_obj_with_warnings(path).map_err(|e| e.to_string())?;
    mesh.face_varying
        .as_mut()
        .ok_or("subtess read no texture coordinates")?
        .mode = mode;
    let surface =
        subtess::Surface::new(&mesh, subtess::Scheme::CatmullClark).map_err(|e| e.to_string())?;
    let mut tessellator = surface
        .tessellator(&subtess::Rates::Uniform(RATE))
        .map_err(|e| e.to_string())?;
    let frame = tessellator
        .evaluate(&mesh.positions_f32())
        .map_err(|e| e.to_string())?;
    let uvs = frame.uvs().ok_or("no texture coordinates in the frame")?;
    Ok((frame.sources().to_vec(), uvs.to_vec()))
}

/// OpenSubdiv's face-varying limit at `sources` (`None`: no patch there).
fn theirs(
    shape: &Shape,
    mode: FaceVaryingMode,
    sources: &[subtess::VertexSource],
) -> Result<Vec<Option<[f64; 2]>>, String> {
    let tags = osd_tags(shape)?;
    let mut options = tags.options;
    options.face_varying_linear_interpolation = osd_mode(mode);
    let sizes: Vec<u32> = shape.faces.iter().map(|f| f.len() as u32).collect();
    let indices: Vec<u32> = shape.faces.iter().flatten().copied().collect();
    let values: Vec<i32> = shape
        .face_uvs
        .iter()
        .flatten()
        .map(|&t| i32::try_from(t).map_err(|_| format!("vt index {t}")))
        .collect::<Result<_, _>>()?;
    let channel = FaceVaryingChannel::new(shape.uvs.len(), &values);
    let mut desc = descriptor(shape, &sizes, &indices, &tags)?;
    attach(
        &mut desc,
        &channel,
        shape.positions.len(),
        shape.faces.len(),
    );
    let osd = Far::from_descriptor(shape, desc, options, true)?;
    let points: Vec<(usize, f32, f32)> = sources
        .iter()
        .map(|src| {
            let (u, v) = src.uv();
            let face = osd.ptex_face(src.face as usize, usize::from(src.subface));
            (face, u as f32, v as f32)
        })
        .collect();
    let (found, table) = located_stencils(
        &osd.refiner,
        None,
        &osd.map,
        &points,
        far::LimitStencilTableOptions {
            interpolation_mode: far::InterpolationMode::FaceVarying,
            generate_1st_derivatives: false,
            generate_2nd_derivatives: false,
            face_varying_channel: 0,
        },
    )?;
    let mut out = vec![None; points.len()];
    let Some(table) = table else {
        return Ok(out);
    };
    let (sizes, offsets, cv, w) = (
        table.sizes(),
        table.offsets(),
        table.control_indices(),
        table.weights(),
    );
    let mut k = 0;
    for (i, slot) in out.iter_mut().enumerate() {
        if !found[i] {
            continue;
        }
        let start = offsets[k].0 as usize;
        let mut uv = [0.0f64; 2];
        for j in start..start + sizes[k] as usize {
            let value = shape
                .uvs
                .get(cv[j].0 as usize)
                .ok_or_else(|| format!("stencil names value {}", cv[j].0))?;
            uv[0] += f64::from(w[j]) * value[0];
            uv[1] += f64::from(w[j]) * value[1];
        }
        *slot = Some(uv);
        k += 1;
    }
    Ok(out)
}

fn compare(path: &Path, shape: &Shape, mode: FaceVaryingMode) -> Row {
    let mut row = Row {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        mode: mode.name().to_owned(),
        ..Row::default()
    };
    let result = ours(path, mode).and_then(|(sources, uvs)| {
        theirs(shape, mode, &sources).map(|limits| (sources, uvs, limits))
    });
    let (sources, uvs, limits) = match result {
        Ok(r) => r,
        Err(e) => {
            row.refused = Some(e.replace('\n', " "));
            return row;
        }
    };
    row.points = sources.len();
    for ((src, uv), limit) in sources.iter().zip(&uvs).zip(&limits) {
        let Some(limit) = limit else {
            row.missing += 1;
            continue;
        };
        let off = (f64::from(uv[0]) - limit[0])
            .abs()
            .max((f64::from(uv[1]) - limit[1]).abs());
        if row.worst.map_or(true, |w| off > w) {
            row.worst = Some(off);
            let (u, v) = src.uv();
            row.worst_at = format!(
                "face {} sub {} ({u:.4}, {v:.4}): ours {uv:?}, theirs [{:.6}, {:.6}]",
                src.face, src.subface, limit[0], limit[1]
            );
        }
    }
    row
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn texture_coordinates_match_opensubdiv() {
    let dir = models();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    paths.sort();
    let only = std::env::var("SUBTESS_PARITY_ONLY").ok();
    let mut rows = Vec::new();
    for path in &paths {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if only.as_deref().is_some_and(|o| !name.contains(o)) {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let shape = parse_shape(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        if shape.uvs.is_empty() || shape.face_uvs.iter().any(Vec::is_empty) {
            continue;
        }
        for mode in FaceVaryingMode::ALL {
            let row = compare(path, &shape, mode);
            eprintln!(
                "{:<28} {:<14} points {:>6} missing {:>4} worst {:>9} {} {}",
                row.name,
                row.mode,
                row.points,
                row.missing,
                row.worst.map_or("-".to_owned(), |w| format!("{w:.1e}")),
                row.verdict(),
                row.refused.as_deref().unwrap_or(&row.worst_at)
            );
            rows.push(row);
        }
    }
    // One line per shape, the largest difference per mode.
    let mut markdown = String::from("| shape | points | no patch |");
    for mode in FaceVaryingMode::ALL {
        let _ = write!(markdown, " {} |", mode.name());
    }
    markdown += "\n|---|---|---|---|---|---|---|---|---|\n";
    for shape in rows.chunks(FaceVaryingMode::ALL.len()) {
        let _ = write!(
            markdown,
            "| {} | {} | {} |",
            shape[0].name, shape[0].points, shape[0].missing
        );
        for r in shape {
            let cell = match (&r.refused, r.worst) {
                (Some(e), _) => format!("refused: {e}"),
                (None, Some(w)) if w >= FAITHFUL => format!("**{w:.1e}**"),
                (None, Some(w)) => format!("{w:.1e}"),
                (None, None) => "-".to_owned(),
            };
            let _ = write!(markdown, " {cell} |");
        }
        markdown += "\n";
    }
    println!("{markdown}");
    if let Ok(path) = std::env::var("SUBTESS_FVAR_PARITY_TABLE") {
        std::fs::write(&path, &markdown).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    let compared = rows.iter().filter(|r| r.refused.is_none()).count();
    let faithful = rows.iter().filter(|r| r.verdict() == "faithful").count();
    eprintln!(
        "{} shape-modes: {compared} compared, {faithful} faithful",
        rows.len()
    );
    if only.is_none() {
        assert!(
            compared >= 40 * FaceVaryingMode::ALL.len(),
            "compared {compared} shape-modes with OpenSubdiv (at least 40 shapes in six modes expected)"
        );
    }
    let differing: Vec<String> = rows
        .iter()
        .filter(|r| r.verdict() == "differs")
        .map(|r| format!("{} {}: {}", r.name, r.mode, r.worst_at))
        .collect();
    assert!(
        differing.is_empty(),
        "texture coordinates differ from OpenSubdiv's by 1e-5 or more:\n{}",
        differing.join("\n")
    );
}
