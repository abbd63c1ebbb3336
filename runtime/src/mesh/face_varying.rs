//! Face-varying data (texture coordinates): a value index per face corner, and OpenSubdiv's
//! modes of linear interpolation.
//!
//! A face-varying channel assigns every face corner a value index. Where two faces sharing an
//! edge use different values at either end of it, the edge is *discontinuous* (a seam,
//! [`crate::Mesh::is_seam`]): the channel's surface is cut there. The channel is a subdivision
//! surface of its own mesh (`scheme::catmull_clark::face_varying::channel_mesh`;
//! docs/algorithms/face-varying.md).

use std::ops::Range;

use crate::MeshError;

/// Where the face-varying surface is linear instead of smooth: OpenSubdiv's
/// `Sdc::Options::FVarLinearInterpolation`, in the order of the OBJ tag
/// `t facevaryinginterpolateboundary k` (k = 0..=5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FaceVaryingMode {
    /// 0, `FVAR_LINEAR_NONE`: smooth everywhere; a seam or boundary is a smooth crease, a
    /// one-face corner follows it ("edge only").
    None,
    /// 1, `FVAR_LINEAR_CORNERS_ONLY`: one-face corners of the channel pinned.
    CornersOnly,
    /// 2, `FVAR_LINEAR_CORNERS_PLUS1`: corners pinned, and vertices where three or more
    /// values meet, or two with a sharp edge or a further seam inside either.
    CornersPlus1,
    /// 3, `FVAR_LINEAR_CORNERS_PLUS2`: as `CornersPlus1`, and both values of a two-value
    /// vertex pinned when either is a corner, and the ends of seams (darts) pinned.
    CornersPlus2,
    /// 4, `FVAR_LINEAR_BOUNDARIES`: every vertex on a seam or boundary pinned, so the channel
    /// is linear along them; smooth inside.
    Boundaries,
    /// 5, `FVAR_LINEAR_ALL`: bilinear on every face (OpenSubdiv's default).
    #[default]
    All,
}

impl FaceVaryingMode {
    /// The mode of `t facevaryinginterpolateboundary k`.
    pub fn from_tag(k: i64) -> Option<Self> {
        Some(match k {
            0 => Self::None,
            1 => Self::CornersOnly,
            2 => Self::CornersPlus1,
            3 => Self::CornersPlus2,
            4 => Self::Boundaries,
            5 => Self::All,
            _ => return None,
        })
    }

    /// The tag value `k` of this mode.
    pub fn tag(self) -> u8 {
        self as u8
    }

    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::CornersOnly => "corners-only",
            Self::CornersPlus1 => "corners-plus1",
            Self::CornersPlus2 => "corners-plus2",
            Self::Boundaries => "boundaries",
            Self::All => "all",
        }
    }

    /// Every mode, in tag order.
    pub const ALL: [FaceVaryingMode; 6] = [
        Self::None,
        Self::CornersOnly,
        Self::CornersPlus1,
        Self::CornersPlus2,
        Self::Boundaries,
        Self::All,
    ];

    /// The mode named `name` ([`FaceVaryingMode::name`]) or numbered `0`..`5`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name || m.tag().to_string() == name)
    }

    /// Whether seams and boundaries are linear (every value on them pinned).
    pub fn linear_boundaries(self) -> bool {
        matches!(self, Self::Boundaries | Self::All)
    }
}

/// One face-varying channel of a mesh: the values and the value of every face corner.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceVarying {
    /// The values (texture coordinates).
    pub values: Vec<[f64; 2]>,
    /// The value index of every half-edge's corner (the corner at the half-edge's tail, in
    /// the mesh's face order).
    pub corners: Vec<u32>,
    /// Where the channel is linear.
    pub mode: FaceVaryingMode,
}

impl FaceVarying {
    /// A channel over a mesh of `face_corners` corners (half-edges), checked: one value per
    /// corner, every index in range, every value finite.
    pub fn new(
        face_corners: usize,
        values: Vec<[f64; 2]>,
        corners: Vec<u32>,
        mode: FaceVaryingMode,
    ) -> Result<Self, MeshError> {
        if corners.len() != face_corners {
            return Err(MeshError::FaceVarying(format!(
                "{} face-varying corners for {face_corners} face corners",
                corners.len()
            )));
        }
        if let Some(h) = corners.iter().position(|&c| c as usize >= values.len()) {
            return Err(MeshError::FaceVarying(format!(
                "face corner {h} names value {} of {}",
                corners[h],
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(MeshError::FaceVarying(format!(
                "value {i} {:?} is not finite",
                values[i]
            )));
        }
        Ok(FaceVarying {
            values,
            corners,
            mode,
        })
    }

    /// The bilinear value at `(u, v)` of the face whose corners are the half-edges `corners`
    /// (a quad), or of the quad at corner `subface` of an n-gon's first bilinear step (corner,
    /// next edge's midpoint, centroid, previous edge's midpoint, the Ptex convention of
    /// [`crate::VertexSource`]): the channel under [`FaceVaryingMode::All`].
    pub fn bilinear(&self, corners: Range<usize>, subface: usize, u: f64, v: f64) -> [f64; 2] {
        bilinear_in(&self.quad(corners, subface), u, v)
    }

    /// The four values [`FaceVarying::bilinear`] interpolates on a face (or sub-face): made once
    /// for all the points of a face.
    pub fn quad(&self, corners: Range<usize>, subface: usize) -> [[f64; 2]; 4] {
        let value = |h: usize| self.values[self.corners[h] as usize];
        if corners.len() == 4 {
            [0, 1, 2, 3].map(|k| value(corners.start + k))
        } else {
            let n = corners.len();
            let at = |k: usize| value(corners.start + k % n);
            let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
            let mut centroid = [0.0; 2];
            for k in 0..n {
                centroid[0] += at(k)[0] / n as f64;
                centroid[1] += at(k)[1] / n as f64;
            }
            let k = subface % n;
            [
                at(k),
                mid(at(k), at(k + 1)),
                centroid,
                mid(at(k + n - 1), at(k)),
            ]
        }
    }
}

/// The bilinear interpolation at `(u, v)` of `quad`'s values (counter-clockwise from `(0, 0)`).
pub fn bilinear_in(quad: &[[f64; 2]; 4], u: f64, v: f64) -> [f64; 2] {
    let w = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
    let mut out = [0.0; 2];
    for (p, w) in quad.iter().zip(w) {
        out[0] += w * p[0];
        out[1] += w * p[1];
    }
    out
}
