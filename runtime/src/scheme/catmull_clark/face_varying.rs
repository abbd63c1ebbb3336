//! The face-varying channel (texture coordinates) of an isolated Catmull–Clark surface: the
//! channel's mesh ([`channel_mesh`]) refined by the same steps as the positions, so that its
//! faces and corners are the isolated mesh's, and its limit values at any points of those
//! faces.
//!
//! The values are evaluated once, when a tessellation is planned: they do not move with the
//! control points. Smooth modes take exact limit stencils by feature-adaptive refinement of the
//! channel's mesh ([`limit_stencils`]: seams and boundaries are its boundaries, pinned values
//! its corners, so every rule of the positions applies unchanged); the linear mode
//! ([`FaceVaryingMode::All`]) is the bilinear interpolation of the input face's corner values,
//! in closed form.

use crate::mesh::face_varying::{channel_mesh, FaceVarying, FaceVaryingMode};
use crate::mesh::{Mesh, VertexSource};
use crate::scheme::catmull_clark::adaptive::{limit_stencils, LimitQuery};
use crate::scheme::catmull_clark::isolate::Isolation;
use crate::scheme::catmull_clark::refine::refine;
use crate::MeshError;

/// A face-varying channel prepared for an [`Isolation`].
#[derive(Clone, Debug)]
pub struct ChannelIsolation {
    /// The channel's mesh after the isolation's steps: its face `f` is the isolated mesh's face
    /// `f`, its half-edge `h` the same corner; its vertices are the channel's (split along
    /// seams), at the refined values `(u, v, 0)`.
    pub mesh: Mesh,
    /// The input channel (for the linear mode's closed form).
    input: FaceVarying,
    /// The input mesh's face offsets (a face's corners, for the linear mode).
    input_mesh: Mesh,
}

impl ChannelIsolation {
    /// The channel of `input` (which must have one) refined `isolation.steps` times.
    pub fn new(input: &Mesh, isolation: &Isolation) -> Result<Option<Self>, MeshError> {
        let Some(fvar) = &input.face_varying else {
            return Ok(None);
        };
        let mut mesh = channel_mesh(input, fvar)?;
        for _ in 0..isolation.steps {
            mesh = refine(&mesh).mesh;
        }
        if mesh.face_vertices.len() != isolation.mesh.face_vertices.len() {
            return Err(MeshError::FaceVarying(format!(
                "the channel refined to {} corners, the positions to {}",
                mesh.face_vertices.len(),
                isolation.mesh.face_vertices.len()
            )));
        }
        let mut input_mesh = input.clone();
        input_mesh.face_varying = None;
        Ok(Some(ChannelIsolation {
            mesh,
            input: fvar.clone(),
            input_mesh,
        }))
    }

    /// The channel's mode.
    pub fn mode(&self) -> FaceVaryingMode {
        self.input.mode
    }

    /// The channel's limit values at `sources` (points of the isolated mesh's faces); `input`
    /// maps each to its input face, sub-face and parameters (the linear mode's closed form
    /// takes those).
    pub fn values(
        &self,
        sources: &[VertexSource],
        input: impl Fn(VertexSource) -> VertexSource,
    ) -> Result<Vec<[f32; 2]>, MeshError> {
        if self.input.mode == FaceVaryingMode::All {
            return Ok(sources
                .iter()
                .map(|&s| {
                    let s = input(s);
                    let (u, v) = s.uv();
                    let [x, y] = self.input.bilinear(
                        &self.input_mesh,
                        s.face as usize,
                        usize::from(s.subface),
                        u,
                        v,
                    );
                    [x as f32, y as f32]
                })
                .collect());
        }
        let queries: Vec<LimitQuery> = sources
            .iter()
            .map(|s| {
                let (u, v) = s.uv();
                LimitQuery { face: s.face, u, v }
            })
            .collect();
        let stencils = limit_stencils(&self.mesh, &queries)?;
        Ok(stencils
            .iter()
            .map(|stencil| {
                let mut out = [0.0f64; 2];
                for &(vertex, [w, _, _]) in stencil {
                    let p = self.mesh.positions[vertex as usize];
                    out[0] += w * p[0];
                    out[1] += w * p[1];
                }
                [out[0] as f32, out[1] as f32]
            })
            .collect())
    }
}
