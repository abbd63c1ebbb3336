//! Lai–Cheng on faces next to sharp features (creases, corners, darts, semi-sharp tags): the
//! feature-adaptive descent of [`crate::scheme::catmull_clark::adaptive`] (refine a
//! neighbourhood until each piece is a feature-aware B-spline patch), with a convex-hull bound
//! on the pieces that never become one (those at feature vertices).
//!
//! At each level the quad `g` holding the square is either
//! * a **B-spline patch** in the feature-aware sense (`adaptive::bspline_patch`: settled
//!   sharpness, regular corners, phantom points `2 P_0 - P_1` beyond infinitely sharp edges):
//!   its bicubic is converted to Bézier form and split like any regular square, with the same
//!   guaranteed bound ([`super::bezier_net::flatness_bound`]: the Bernstein hull needs no
//!   condition on the B-spline net, phantom points included); or
//! * a **hull square**: every Catmull–Clark rule, sharp and semi-sharp ones included, is a
//!   non-negative combination (checked on every refinement stencil used), and the limit surface
//!   over `g` depends only on the one-ring of `g` (the vertices of the faces sharing a vertex
//!   with it), whose refinement gives the children's one-rings. So the surface over `g`, its
//!   boundary points and any polygon through them lie in the convex hull of that one-ring, and
//!   `|S - L| <= diam(one-ring)`: the extraordinary vertex's sphere bound, which decays like
//!   the subdominant eigenvalue at the vertex (1/2 at creases and corners). The square is kept
//!   when that is within the tolerance, else the neighbourhood is refined once and its four
//!   children follow. Its corners are evaluated afterwards by
//!   [`crate::scheme::catmull_clark::adaptive::limit_stencils`] (Sdc limit masks at feature
//!   vertices).

use std::collections::BTreeSet;
use std::iter::once;

use super::bezier_net::{bspline_to_bezier, Net, Point};
use super::{diameter_above, FaceWork};
use crate::mesh::topology::Mesh;
use crate::scheme::catmull_clark::adaptive::{bspline_patch, neighbourhood, submesh, RINGS};
use crate::scheme::catmull_clark::refine::refine;

/// The face grid coordinates of a level quad's corners 0..3 (counter-clockwise in the face).
pub(super) type Frame = [(u32, u32); 4];

/// The neighbourhood of face `face` of `mesh` (positions set), and its face there.
pub(super) fn root(mesh: &Mesh, face: usize) -> (Mesh, usize) {
    let faces = neighbourhood(mesh, once(face), RINGS);
    let (mut sub, vertices, face_of) = submesh(mesh, &faces);
    sub.positions = vertices
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    (sub, face_of[&face])
}

/// The frame of child `c` of a quad with frame `frame`: child `c` starts at the quad's corner
/// `c`, then the midpoint towards corner `c + 1`, the centre, the midpoint from corner `c - 1`
/// (`refine` numbers the children by the quad's half-edges, their corner 0 at its vertex).
fn child_frame(frame: &Frame, c: usize) -> Frame {
    let mid = |a: (u32, u32), b: (u32, u32)| ((a.0 + b.0) / 2, (a.1 + b.1) / 2);
    let centre = mid(frame[0], frame[2]);
    [
        frame[c],
        mid(frame[c], frame[(c + 1) % 4]),
        centre,
        mid(frame[(c + 3) % 4], frame[c]),
    ]
}

/// The Bézier net `net` (`b[4 j + i]`, `i` along the quad's own `s`) re-indexed in the face's
/// `(u, v)` directions, and the square's lower-left corner. The frames are rotations of the
/// face's (the children of `refine` keep the orientation), so normals keep their sign.
fn to_face_net(net: &Net, frame: &Frame) -> (Net, u32, u32) {
    let (u0, v0) = (
        frame.iter().map(|p| p.0).min().unwrap_or(0),
        frame.iter().map(|p| p.1).min().unwrap_or(0),
    );
    let sign = |a: u32, b: u32| i64::from(b > a) - i64::from(a > b);
    let (su, sv) = (sign(frame[0].0, frame[1].0), sign(frame[0].1, frame[1].1));
    let (tu, tv) = (sign(frame[0].0, frame[3].0), sign(frame[0].1, frame[3].1));
    let start = |x: u32, lo: u32| if x == lo { 0 } else { 3 };
    let (iu0, iv0) = (start(frame[0].0, u0), start(frame[0].1, v0));
    let mut out = *net;
    for j in 0..4i64 {
        for i in 0..4i64 {
            let iu = iu0 + i * su + j * tu;
            let iv = iv0 + i * sv + j * tv;
            out[(4 * iv + iu) as usize] = net[(4 * j + i) as usize];
        }
    }
    (out, u0, v0)
}

/// The positions of the one-ring of quad `g`: every vertex of a face sharing a vertex with it.
fn one_ring(level: &Mesh, g: usize) -> Vec<Point> {
    let mut ids = BTreeSet::new();
    for &v in level.face(g) {
        for h in level.fan(v as usize) {
            ids.extend(level.face(level.face_of[h] as usize).iter().copied());
        }
    }
    ids.into_iter()
        .map(|v| level.positions[v as usize])
        .collect()
}

impl FaceWork<'_> {
    /// The square of quad `g` of `level` (a neighbourhood, positions set), with face frame
    /// `frame`, `depth` levels below the face; `nonnegative` whether every refinement stencil
    /// that made `level` was (the hull bound's condition). Module documentation.
    pub(super) fn feature(
        &mut self,
        level: &Mesh,
        g: usize,
        frame: Frame,
        depth: u32,
        nonnegative: bool,
        root_diagonal: f64,
    ) {
        if let Some(grid) = bspline_patch::<f64>(level, g) {
            // `grid[a][b]` is the control point at (a - 1, b - 1) of the quad's (s, t).
            let mut spline: Net = [[0.0; 3]; 16];
            for (a, column) in grid.iter().enumerate() {
                for (b, combo) in column.iter().enumerate() {
                    let mut p = [0.0; 3];
                    for &(v, w) in combo {
                        for (x, q) in p.iter_mut().zip(level.positions[v as usize]) {
                            *x += w * q;
                        }
                    }
                    spline[4 * b + a] = p;
                }
            }
            let (net, u0, v0) = to_face_net(&bspline_to_bezier(&spline), &frame);
            self.regular(&net, u0, v0, depth);
            return;
        }
        let tolerance = self.tolerance(root_diagonal);
        // A square that may be split only asks whether the diameter exceeds the tolerance; a
        // leaf gets it exact.
        let bound = if nonnegative {
            diameter_above(&one_ring(level, g), self.diameter_floor(depth, tolerance))
        } else {
            f64::INFINITY
        };
        if self.done(depth, bound, tolerance) {
            self.pending_leaf(&frame, depth, bound, tolerance);
            return;
        }
        let step = refine(level);
        // Negative weights would void the hull bound below (never for Catmull–Clark's rules,
        // sharp or not; checked rather than assumed).
        let nonnegative = nonnegative
            && (0..step.stencil.rows()).all(|r| step.stencil.row(r).1.iter().all(|&w| w >= 0.0));
        let children: Vec<usize> = level.face_halfedges(g).collect();
        let faces = neighbourhood(&step.mesh, children.iter().copied(), RINGS);
        let (mut sub, vertices, face_of) = submesh(&step.mesh, &faces);
        sub.positions = vertices
            .iter()
            .map(|&v| step.mesh.positions[v as usize])
            .collect();
        for (c, child) in children.into_iter().enumerate() {
            if let Some(&h) = face_of.get(&child) {
                self.feature(
                    &sub,
                    h,
                    child_frame(&frame, c),
                    depth + 1,
                    nonnegative,
                    root_diagonal,
                );
            }
        }
    }
}
