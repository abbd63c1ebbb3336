//! One uniform Catmull–Clark refinement step on a polygon mesh (Catmull and Clark 1978) with
//! sharp features (DeRose, Kass and Truong 1998), by OpenSubdiv's rules (`Sdc::Scheme`
//! `<SCHEME_CATMARK>`), for any valence and any polygon.
//!
//! New vertices are numbered vertex points first (so old vertex `i` becomes new vertex `i`),
//! then one edge point per edge (in order of first appearance), then one face point per face.
//! Face `f` with `k` corners becomes `k` quads, corner `i` giving
//! `(vertex point v_i, edge point (v_i, v_{i+1}), face point f, edge point (v_{i-1}, v_i))`,
//! which keeps the orientation. Rules:
//!
//! * face point: the centroid;
//! * edge point: smooth `(v_0 + v_1 + f_left + f_right) / 4` (with "smooth triangles", a
//!   triangle's centroid weighs 0.47); on a sharp edge (a boundary edge is infinitely sharp) the
//!   midpoint; on a semi-sharp edge whose children are not both sharp, the blend
//!   `s * midpoint + (1 - s) * smooth` by its sharpness `s`;
//! * vertex point, by the vertex's rule ([`CreaseRule`]): smooth and dart
//!   `(Q + 2R + (n - 3) V) / n` (`Q`: mean of the new face points around it, `R`: mean of the
//!   midpoints of its edges); crease `(E_a + 6 V + E_b) / 8` along its two sharp edges (the
//!   boundary rule); corner `V`. When the rule of the vertex's child differs, the point is
//!   `w * (parent rule) + (1 - w) * (child rule)` with the fractional weight `w`
//!   ([`schemes::CreaseMethod::fractional_weight`]).
//!
//! The children's sharpness: an edge's two halves decay by the mesh's [`schemes::CreaseMethod`], a
//! vertex's sharpness loses one unit, the edges inside a face are smooth; a hole's children are
//! holes.

use schemes::crease::{crease_pair, decrement, is_sharp, CreaseRule};

use crate::mesh::topology::{Mesh, NONE};
use crate::scheme::stencil::{Stencil, Weight};

/// The refined mesh, and for each refined vertex what it was made from.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The refined mesh (all quads).
    pub mesh: Mesh,
    /// Number of vertex points (= the coarse vertex count); edge points follow, then face points.
    pub vertex_points: usize,
    /// Number of edge points.
    pub edge_points: usize,
    /// Every refined vertex as a combination of the coarse ones (the rules above).
    pub stencil: Stencil<f64>,
}

/// What one step needs to know of a mesh's edges: their numbering (edge points in order of the
/// first half-edge of each edge) and the sharpness of each edge's two children.
#[derive(Clone, Debug)]
pub struct LevelEdges {
    /// The first half-edge of every edge.
    pub halfedge: Vec<usize>,
    /// The edge of every half-edge.
    pub of_halfedge: Vec<u32>,
    /// The sharpness of the child of half-edge `h`'s edge at its tail vertex.
    pub child_at_tail: Vec<f32>,
    /// The sharpness of the child of half-edge `h`'s edge at its head vertex.
    pub child_at_head: Vec<f32>,
}

impl LevelEdges {
    /// Number the edges of `mesh` and decay their sharpness.
    pub fn new(mesh: &Mesh) -> Self {
        let halfedges = mesh.face_vertices.len();
        let mut of_halfedge = vec![NONE; halfedges];
        let mut halfedge = Vec::new();
        for h in 0..halfedges {
            if of_halfedge[h] != NONE {
                continue;
            }
            of_halfedge[h] = halfedge.len() as u32;
            if mesh.twin[h] != NONE {
                of_halfedge[mesh.twin[h] as usize] = halfedge.len() as u32;
            }
            halfedge.push(h);
        }
        let (child_at_tail, child_at_head) = if mesh.creasing == schemes::CreaseMethod::Uniform {
            let decayed: Vec<f32> = mesh.edge_sharpness.iter().map(|&s| decrement(s)).collect();
            (decayed.clone(), decayed)
        } else {
            // Chaikin: each half depends on the edges at its own end vertex.
            let mut at_tail = vec![0.0; halfedges];
            let mut at_head = vec![0.0; halfedges];
            for v in 0..mesh.positions.len() {
                let edges = mesh.vertex_edges(v);
                let around: Vec<f32> = edges.iter().map(|&h| mesh.edge_sharpness[h]).collect();
                for (&h, &s) in edges.iter().zip(&around) {
                    let child = mesh.creasing.child_sharpness(s, &around);
                    if mesh.face_vertices[h] as usize == v {
                        at_tail[h] = child;
                        if mesh.twin[h] != NONE {
                            at_head[mesh.twin[h] as usize] = child;
                        }
                    } else {
                        at_head[h] = child;
                    }
                }
            }
            (at_tail, at_head)
        };
        LevelEdges {
            halfedge,
            of_halfedge,
            child_at_tail,
            child_at_head,
        }
    }

    /// The sharpness of the child of half-edge `h`'s edge at its end vertex `v`.
    pub fn child_at(&self, mesh: &Mesh, h: usize, v: usize) -> f32 {
        if mesh.face_vertices[h] as usize == v {
            self.child_at_tail[h]
        } else {
            self.child_at_head[h]
        }
    }
}

/// `(index, weight)` terms of the centroid of face `f`, scaled by `s`.
fn face_terms<W: Weight>(mesh: &Mesh, f: usize, s: W, out: &mut Vec<(u32, W)>) {
    let face = mesh.face(f);
    let w = s * W::ratio(1, face.len() as i64);
    out.extend(face.iter().map(|&v| (v, w.clone())));
}

/// Every term of `terms` scaled by `s`.
fn scaled<W: Weight>(terms: Vec<(u32, W)>, s: &W) -> impl Iterator<Item = (u32, W)> + '_ {
    terms.into_iter().map(move |(v, w)| (v, w * s.clone()))
}

/// The smooth edge point of interior half-edge `h` (twin `t`), scaled by `s`.
fn smooth_edge<W: Weight>(mesh: &Mesh, h: usize, t: usize, s: W, out: &mut Vec<(u32, W)>) {
    let (a, b) = (mesh.face_vertices[h], mesh.head(h));
    let faces = [mesh.face_of[h] as usize, mesh.face_of[t] as usize];
    let triangle = |f: usize| mesh.smooth_triangles && mesh.face(f).len() == 3;
    if faces.iter().any(|&f| triangle(f)) {
        // OpenSubdiv's smooth-triangle edge: a triangle's centroid weighs 0.47.
        let face_weight = |f: usize| {
            if triangle(f) {
                W::ratio(47, 100)
            } else {
                W::ratio(1, 4)
            }
        };
        let f_weight = (face_weight(faces[0]) + face_weight(faces[1])) * W::ratio(1, 2);
        let v_weight = (W::ratio(1, 1) - f_weight.clone() * W::ratio(2, 1)) * W::ratio(1, 2);
        out.extend([(a, v_weight.clone() * s.clone()), (b, v_weight * s.clone())]);
        for f in faces {
            face_terms(mesh, f, f_weight.clone() * s.clone(), out);
        }
    } else {
        let quarter = W::ratio(1, 4) * s;
        out.extend([(a, quarter.clone()), (b, quarter.clone())]);
        for f in faces {
            face_terms(mesh, f, quarter.clone(), out);
        }
    }
}

/// The edge point of the edge of half-edge `h`.
fn edge_point<W: Weight>(mesh: &Mesh, level: &LevelEdges, h: usize) -> Vec<(u32, W)> {
    let (a, b) = (mesh.face_vertices[h], mesh.head(h));
    let midpoint = |s: W| vec![(a, s.clone() * W::ratio(1, 2)), (b, s * W::ratio(1, 2))];
    let s = mesh.edge_sharpness[h];
    let t = mesh.twin[h];
    if t == NONE {
        return midpoint(W::ratio(1, 1));
    }
    let mut terms = Vec::new();
    if !is_sharp(s) {
        smooth_edge(mesh, h, t as usize, W::ratio(1, 1), &mut terms);
        return terms;
    }
    // The edge point's own rule: a crease when both children stay sharp.
    let child = CreaseRule::of(0.0, &[level.child_at_tail[h], level.child_at_head[h]]);
    if child == CreaseRule::Crease {
        return midpoint(W::ratio(1, 1));
    }
    let sharp = W::from_f32(s);
    terms = midpoint(sharp.clone());
    smooth_edge(mesh, h, t as usize, W::ratio(1, 1) - sharp, &mut terms);
    terms
}

/// The vertex mask of `rule` at vertex `v` with edges `edges` of sharpness `sharpness`.
fn vertex_mask<W: Weight>(
    mesh: &Mesh,
    v: usize,
    rule: CreaseRule,
    edges: &[usize],
    sharpness: &[f32],
) -> Vec<(u32, W)> {
    let fan = mesh.fan(v);
    let mut terms = Vec::new();
    let crease = (rule == CreaseRule::Crease)
        .then(|| crease_pair(sharpness))
        .flatten();
    if let Some((i, j)) = crease {
        terms.extend([
            (mesh.opposite(edges[i], v), W::ratio(1, 8)),
            (mesh.opposite(edges[j], v), W::ratio(1, 8)),
            (v as u32, W::ratio(3, 4)),
        ]);
    } else if rule.is_smooth() && !mesh.is_boundary_vertex(v) {
        // (Q + 2R + (n - 3) V) / n = (sum F / n + sum (V + E) / n + (n - 3) V) / n.
        let n = fan.len() as i64;
        let nn = n * n;
        terms.push((v as u32, W::ratio(n - 2, n)));
        for &h in &fan {
            terms.push((mesh.head(h), W::ratio(1, nn)));
            face_terms(mesh, mesh.face_of[h] as usize, W::ratio(1, nn), &mut terms);
        }
    } else {
        // A corner, or a rule the topology cannot hold (a smooth boundary vertex): pinned.
        terms.push((v as u32, W::ratio(1, 1)));
    }
    terms
}

/// The vertex point of vertex `v`.
fn vertex_point<W: Weight>(mesh: &Mesh, level: &LevelEdges, v: usize) -> Vec<(u32, W)> {
    let edges = mesh.vertex_edges(v);
    if edges.is_empty() {
        return vec![(v as u32, W::ratio(1, 1))];
    }
    let sharpness: Vec<f32> = edges.iter().map(|&h| mesh.edge_sharpness[h]).collect();
    let vertex = mesh.vertex_sharpness[v];
    let rule = CreaseRule::of(vertex, &sharpness);
    if rule.is_smooth() {
        return vertex_mask(mesh, v, rule, &edges, &sharpness);
    }
    let child_sharpness: Vec<f32> = edges.iter().map(|&h| level.child_at(mesh, h, v)).collect();
    let child_vertex = decrement(vertex);
    let child_rule = CreaseRule::of(child_vertex, &child_sharpness);
    let parent = vertex_mask(mesh, v, rule, &edges, &sharpness);
    if child_rule == rule {
        return parent;
    }
    let w = mesh
        .creasing
        .fractional_weight(vertex, child_vertex, &sharpness, &child_sharpness);
    let (pw, cw) = (W::from_f32(w), W::from_f32(1.0 - w));
    let child = vertex_mask(mesh, v, child_rule, &edges, &child_sharpness);
    scaled(parent, &pw).chain(scaled(child, &cw)).collect()
}

/// Refined vertex `child` of `mesh` (numbered as [`refine`] numbers them) as `(coarse vertex,
/// weight)` terms, an index possibly repeated: the one statement of the Catmull–Clark rules,
/// in any [`Weight`] (f64 for positions and per-frame stencils, rationals for exact
/// evaluation).
pub fn refined_vertex<W: Weight>(mesh: &Mesh, level: &LevelEdges, child: usize) -> Vec<(u32, W)> {
    let nv = mesh.positions.len();
    let ne = level.halfedge.len();
    if child >= nv + ne {
        let mut terms = Vec::new();
        face_terms(mesh, child - nv - ne, W::ratio(1, 1), &mut terms);
        terms
    } else if child >= nv {
        edge_point(mesh, level, level.halfedge[child - nv])
    } else {
        vertex_point(mesh, level, child)
    }
}

/// Every refined vertex of one step of `mesh` as a combination of its vertices.
pub fn refinement_stencil<W: Weight>(mesh: &Mesh, level: &LevelEdges) -> Stencil<W> {
    let rows = mesh.positions.len() + level.halfedge.len() + mesh.faces();
    let mut stencil = Stencil::new(mesh.positions.len());
    for child in 0..rows {
        stencil.push_row(refined_vertex(mesh, level, child));
    }
    stencil
}

/// Refine `mesh` once.
pub fn refine(mesh: &Mesh) -> Refinement {
    let nv = mesh.positions.len();
    let level = LevelEdges::new(mesh);
    let ne = level.halfedge.len();
    let stencil = refinement_stencil::<f64>(mesh, &level);
    let positions = stencil.apply(&mesh.positions);
    let mut faces = Vec::with_capacity(mesh.face_vertices.len());
    // The children's sharpness, half-edge by half-edge of the child faces: the half of edge h
    // at v_i, two smooth edges inside the face, the half of the previous edge at v_i.
    let mut edge_sharpness = Vec::with_capacity(4 * mesh.face_vertices.len());
    for f in 0..mesh.faces() {
        for h in mesh.face_halfedges(f) {
            let v = i64::from(mesh.face_vertices[h]);
            let e_next = (nv + level.of_halfedge[h] as usize) as i64;
            let e_prev = (nv + level.of_halfedge[mesh.prev(h)] as usize) as i64;
            let fp = (nv + ne + f) as i64;
            faces.push(vec![v, e_next, fp, e_prev]);
            edge_sharpness.extend([
                level.child_at_tail[h],
                0.0,
                0.0,
                level.child_at_head[mesh.prev(h)],
            ]);
        }
    }
    let mut refined = Mesh::refined(positions, &faces, &[], mesh.boundary)
        .unwrap_or_else(|e| unreachable!("refining a valid mesh gives a valid mesh: {e}"));
    refined.edge_sharpness = edge_sharpness;
    for (child, &s) in refined
        .vertex_sharpness
        .iter_mut()
        .zip(&mesh.vertex_sharpness)
    {
        *child = decrement(s);
    }
    refined.holes = mesh
        .face_of
        .iter()
        .map(|&f| mesh.holes[f as usize])
        .collect();
    refined.creasing = mesh.creasing;
    refined.smooth_triangles = mesh.smooth_triangles;
    Refinement {
        mesh: refined,
        vertex_points: nv,
        edge_points: ne,
        stencil,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::cube;

    #[test]
    fn a_cube_refines_to_the_textbook_counts_and_stays_closed() {
        let r = refine(&cube());
        assert_eq!((r.mesh.positions.len(), r.mesh.faces()), (26, 24));
        assert_eq!(r.mesh.euler_characteristic(), 2);
        // Vertex point of corner 0 (valence 3): Q = (1/3)(1,1,1) (mean of the three face
        // centroids), R = (1/6)(1,1,1) (mean of the edge midpoints): (Q + 2R)/3 = (2/9)(1,1,1).
        let v0 = r.mesh.positions[0];
        for c in v0 {
            assert!((c - 2.0 / 9.0).abs() < 1e-15, "{v0:?}");
        }
    }
}
