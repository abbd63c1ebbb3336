//! √3 beside a straight boundary (Kobbelt's boundary rules): the generator's strip evaluation
//! (`stencilgen::sqrt3_strip`, the scaling relation with the regular basis and the boundary
//! rules of `schemes::sqrt3_boundary`) against whole-mesh refinement (`subtess`'s
//! `sqrt3_refine`) and Kobbelt's limit positions, which share no code with it.

use crate::common;
use crate::common::ring_normal;
use schemes::loop_regular::RegularDerivative;
use schemes::BoundaryMode;
use stencilgen::sqrt3_strip::{self, StripStencil};
use subtess::mesh::geometry::{add, cross, dot, norm, scale};
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_topology::neighbours;
use subtess::scheme::sqrt3::refine::{
    sqrt3_boundary_limit_position, sqrt3_limit_position, sqrt3_refine,
};
use subtess::scheme::triangle::split::ternary_child_to_parent;

/// The lattice parallelogram `0..=m` squared, vertex `(a, b)` numbered `a + (m + 1) b`, at a
/// smooth non-planar height field so that every coordinate is generic.
fn parallelogram(m: i64) -> Mesh {
    let index = |a: i64, b: i64| a + (m + 1) * b;
    let positions = (0..(m + 1) * (m + 1))
        .map(|k| {
            let (a, b) = ((k % (m + 1)) as f64, (k / (m + 1)) as f64);
            [
                a + 0.3 * (0.7 * b).sin(),
                b + 0.2 * (0.5 * a).cos(),
                (0.4 * a + 0.9 * b).sin(),
            ]
        })
        .collect();
    let mut faces = Vec::new();
    for b in 0..m {
        for a in 0..m {
            faces.push(vec![index(a, b), index(a + 1, b), index(a, b + 1)]);
            faces.push(vec![index(a + 1, b), index(a + 1, b + 1), index(a, b + 1)]);
        }
    }
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid mesh")
}

/// `steps` ternary steps of the parallelogram, and every refined vertex's lattice point
/// (level-`steps` coordinates).
fn refined_lattice(m: i64, steps: u32) -> (Mesh, Mesh, Vec<(i64, i64)>) {
    let coarse = parallelogram(m);
    let mut corners: Vec<[(i64, i64); 3]> = (0..coarse.faces())
        .map(|f| {
            let t = coarse.face(f);
            [0, 1, 2].map(|i| (i64::from(t[i]) % (m + 1), i64::from(t[i]) / (m + 1)))
        })
        .collect();
    let mut mesh = coarse.clone();
    let mut at = Vec::new();
    for _ in 0..steps {
        let fine = sqrt3_refine(&mesh).expect("refines").mesh;
        let mut fine_corners = Vec::with_capacity(fine.faces());
        at = vec![(0, 0); fine.positions.len()];
        for (f, c) in corners.iter().enumerate() {
            for g in 9 * f..9 * f + 9 {
                let mut child = [(0, 0); 3];
                for (i, (&v, (s, t))) in fine
                    .face(g)
                    .iter()
                    .zip([(0, 0), (1, 0), (0, 1)])
                    .enumerate()
                {
                    let (u, w) = ternary_child_to_parent((g % 9) as u8, s, t, 1);
                    let (u, w) = (i64::from(u), i64::from(w));
                    let q = (
                        3 * c[0].0 + u * (c[1].0 - c[0].0) + w * (c[2].0 - c[0].0),
                        3 * c[0].1 + u * (c[1].1 - c[0].1) + w * (c[2].1 - c[0].1),
                    );
                    child[i] = q;
                    at[v as usize] = q;
                }
                fine_corners.push(child);
            }
        }
        corners = fine_corners;
        mesh = fine;
    }
    (coarse, mesh, at)
}

fn apply(stencil: &StripStencil, mesh: &Mesh, m: i64) -> [f64; 3] {
    stencil.iter().fold([0.0; 3], |acc, (&(a, b), &w)| {
        assert!((0..=m).contains(&a) && (0..=m).contains(&b), "({a}, {b})");
        add(acc, scale(w, mesh.positions[(a + (m + 1) * b) as usize]))
    })
}

/// Kobbelt's limit position of `mesh`'s vertex `v` (closed forms: the interior rule's left
/// eigenvector, the cubic B-spline's on the boundary).
fn limit_position(mesh: &Mesh, v: usize) -> [f64; 3] {
    let ring = neighbours(mesh, v);
    let p = |i: u32| mesh.positions[i as usize];
    if mesh.is_boundary_vertex(v) {
        return sqrt3_boundary_limit_position(
            p(ring[ring.len() - 1]),
            mesh.positions[v],
            p(ring[0]),
        );
    }
    let sum = ring.iter().fold([0.0; 3], |acc, &e| add(acc, p(e)));
    let k = ring.len() as f64;
    sqrt3_limit_position(mesh.positions[v], scale(1.0 / k, sum), ring.len())
}

/// At every ternary point `(i/27, j/27)` within three rows of the boundary `b = 0` (and four
/// units from the parallelogram's other sides, whose own boundary rules reach about three), the
/// strip's position stencil applied to the coarse points is the limit position of the vertex
/// that three whole-mesh ternary steps put there: to 1e-12.
#[test]
fn the_strip_is_the_limit_of_whole_mesh_refinement() {
    let m = 12;
    let (coarse, fine, at) = refined_lattice(m, 3);
    let mut strip = sqrt3_strip::strip(27).expect("psi on 1/27");
    let mut checked = 0;
    for (v, &q) in at.iter().enumerate() {
        if q.0 < 108 || q.0 > 216 || q.1 > 81 {
            continue;
        }
        let want = limit_position(&fine, v);
        let got = apply(
            &strip
                .half_plane_stencil(q, RegularDerivative::Position)
                .expect("evaluates"),
            &coarse,
            m,
        );
        for x in 0..3 {
            assert!(
                (got[x] - want[x]).abs() < 1e-12,
                "({}/27, {}/27): {got:?} {want:?}",
                q.0,
                q.1
            );
        }
        checked += 1;
    }
    assert!(checked > 8000, "{checked} points");
}

/// The derivative stencils against central differences of the position stencils at the points
/// `k/36`, from two grid steps above the line up: the quotient's error shrinks with the step
/// (`h = 2/36` against `1/36`, to at most 0.75 of it), and at `h = 1/36` it is within 1e-3 of
/// the derivative's size from a third of a unit above the line up, within 3e-2 below. Far from
/// the line the error falls like `h^2` (ratio about 0.25); within a sixth of a unit of it like
/// `h^1.2` (ratios 0.42 to 0.70): the surface's second derivatives grow towards the line
/// (docs/algorithms/sqrt3.md). `--nocapture` prints the errors.
#[test]
fn strip_derivatives_are_the_positions_slopes() {
    let m = 12;
    let coarse = parallelogram(m);
    let d = 36;
    let mut strip = sqrt3_strip::strip(d).expect("psi on 1/36");
    let mut at = |k: (i64, i64), kind| {
        apply(
            &strip.half_plane_stencil(k, kind).expect("evaluates"),
            &coarse,
            m,
        )
    };
    for k in [
        (200, 2),
        (201, 5),
        (210, 13),
        (190, 30),
        (215, 40),
        (205, 71),
    ] {
        for (kind, step) in [
            (RegularDerivative::U, (1, 0)),
            (RegularDerivative::V, (0, 1)),
        ] {
            let exact = at(k, kind);
            let size = exact.iter().map(|x| x * x).sum::<f64>().sqrt();
            let error = |at: &mut dyn FnMut((i64, i64), RegularDerivative) -> [f64; 3], s: i64| {
                let plus = at(
                    (k.0 + s * step.0, k.1 + s * step.1),
                    RegularDerivative::Position,
                );
                let minus = at(
                    (k.0 - s * step.0, k.1 - s * step.1),
                    RegularDerivative::Position,
                );
                let h = s as f64 / f64::from(d);
                (0..3)
                    .map(|x| ((plus[x] - minus[x]) / (2.0 * h) - exact[x]).abs())
                    .fold(0.0, f64::max)
            };
            let (fine, coarse_step) = (error(&mut at, 1), error(&mut at, 2));
            println!("{k:?} {kind:?}: {coarse_step:.3e} -> {fine:.3e} (size {size:.3})");
            let bound = if k.1 >= 12 { 1e-3 } else { 3e-2 };
            assert!(fine < bound * size, "{k:?} {kind:?}: {fine}");
            assert!(
                fine <= 0.75 * coarse_step,
                "{k:?} {kind:?}: {coarse_step} -> {fine}"
            );
        }
    }
}

/// The cross-boundary tangent mask on the line (`cross_mask_on_line`, the direction the
/// derivatives across the line take in the limit) gives the plane the surface's normals above
/// the line converge to: with `du` the B-spline's derivative, the angle between `du x mask` at
/// `(t, 0)` and the exact normal at `(t, e)`, `e = 1/3, 1/9, 1/36`, shrinks with `e`, at a
/// vertex (`t = 6`) and at an edge's midpoint (`t = 6.5`, where the derivative across itself
/// grows without bound). `--nocapture` prints the angles.
#[test]
fn normals_above_the_line_converge_to_the_cross_mask() {
    let m = 12;
    let coarse = parallelogram(m);
    let d = 36i64;
    let mut strip = sqrt3_strip::strip(d as u32).expect("psi on 1/36");
    let angle =
        |a: [f64; 3], b: [f64; 3]| (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0).acos();
    for t in [6 * d, 6 * d + d / 2] {
        let du = apply(
            &strip
                .half_plane_stencil((t, 0), RegularDerivative::U)
                .expect("along the line"),
            &coarse,
            m,
        );
        let mask = apply(&strip.cross_mask_on_line(t).expect("settles"), &coarse, m);
        let limit = cross(du, mask);
        let angles: Vec<f64> = [12, 4, 1]
            .iter()
            .map(|&e| {
                let mut at = |kind| {
                    apply(
                        &strip.half_plane_stencil((t, e), kind).expect("evaluates"),
                        &coarse,
                        m,
                    )
                };
                let (u, v) = (at(RegularDerivative::U), at(RegularDerivative::V));
                angle(cross(u, v), limit)
            })
            .collect();
        println!("t = {t}/{d}: angles {angles:?}");
        assert!(
            angles[1] < angles[0] && angles[2] < angles[1],
            "t = {t}/{d}: {angles:?}"
        );
    }
}

/// The runtime's boundary patches (`subtess::scheme::sqrt3::boundary_patch`, their grids made
/// from the √3 table's regular basis) on an open mesh: a 4 x 4 lattice parallelogram whose
/// corners have one and two triangles (fans of `K = 1, 2`) and whose sides are straight
/// (strip patches). Every output vertex of the tessellation at rate 3 is at a ternary parameter
/// of an input triangle; its position is the limit position of the vertex that four
/// whole-mesh ternary steps put there (to 2e-5, the output's f32), and the output is a
/// manifold with boundary whose normals turn with the reference normals of the refined mesh.
#[test]
#[cfg(feature = "sqrt3")]
fn boundary_patches_are_the_limit_of_whole_mesh_refinement() {
    let m = 4;
    let (coarse, fine, at) = refined_lattice(m, 4);
    let surface = subtess::Surface::new(&coarse, subtess::Scheme::Sqrt3).expect("isolates");
    assert!(
        surface.isolation_steps() <= 2,
        "{} steps",
        surface.isolation_steps()
    );
    let mut tessellator = surface
        .tessellator(&subtess::Rates::Uniform(3))
        .expect("plans");
    let frame = tessellator
        .evaluate(&coarse.positions_f32())
        .expect("evaluates");
    let vertex_at: std::collections::HashMap<(i64, i64), usize> =
        at.iter().enumerate().map(|(v, &q)| (q, v)).collect();
    let level = 81;
    let mut worst: f64 = 0.0;
    let mut worst_normal = [0.0f64; 2];
    for (i, source) in frame.sources().iter().enumerate() {
        let t = coarse.face(source.face as usize);
        let c: Vec<(i64, i64)> = t
            .iter()
            .map(|&v| (i64::from(v) % (m + 1), i64::from(v) / (m + 1)))
            .collect();
        let den = i64::from(source.denominator);
        assert_eq!(level % den, 0, "denominator {den}");
        let (u, v) = (
            i64::from(source.u) * level / den,
            i64::from(source.v) * level / den,
        );
        let q = (
            level * c[0].0 + u * (c[1].0 - c[0].0) + v * (c[2].0 - c[0].0),
            level * c[0].1 + u * (c[1].1 - c[0].1) + v * (c[2].1 - c[0].1),
        );
        let w = vertex_at[&q];
        let want = limit_position(&fine, w);
        let got = frame.positions()[i];
        for x in 0..3 {
            worst = worst.max((f64::from(got[x]) - want[x]).abs());
        }
        let n = frame.normals()[i].map(f64::from);
        let reference = ring_normal(&fine, w);
        let angle = dot(n, reference).clamp(-1.0, 1.0).acos();
        let slot = usize::from(fine.is_boundary_vertex(w));
        worst_normal[slot] = worst_normal[slot].max(angle);
    }
    println!(
        "positions within {worst:.1e}; normals (interior, boundary) within {:.1e}, {:.1e} rad",
        worst_normal[0], worst_normal[1]
    );
    assert!(worst < 2e-5, "worst position error {worst}");
    assert!(
        worst_normal[0] < 2e-2 && worst_normal[1] < 0.1,
        "worst normal angles {worst_normal:?}"
    );
    assert!(
        frame.sources().len() > 500,
        "{} vertices",
        frame.sources().len()
    );
    common::check_topology(&coarse, &frame.to_triangle_mesh(), "parallelogram");
}

/// The hand (`../shared/models/odedstein/hand_lowres.obj`: one boundary loop with fans of 2,
/// 3 and 4 triangles, interior vertices of valence 3 to 8) with √3: two isolation steps, a
/// manifold output with the input's boundary loop, and every output vertex of the rate-1
/// tessellation at the limit position of the vertex three whole-mesh ternary steps of the
/// input put at its parameter (to 1e-6).
#[test]
#[cfg(feature = "sqrt3")]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn the_hand_is_the_limit_of_whole_mesh_refinement() {
    let hand = common::load(&common::models().join("odedstein/hand_lowres.obj"));
    let surface = subtess::Surface::new(&hand, subtess::Scheme::Sqrt3).expect("isolates");
    assert_eq!(surface.isolation_steps(), 2);
    let mut tessellator = surface
        .tessellator(&subtess::Rates::Uniform(1))
        .expect("plans");
    let frame = tessellator
        .evaluate(&hand.positions_f32())
        .expect("evaluates");
    common::check_topology(&hand, &frame.to_triangle_mesh(), "hand");
    // Three steps, every refined vertex named by (input face, numerators over 27).
    let level = 27;
    let mut mesh = hand.clone();
    let mut corners: Vec<(u32, [(i64, i64); 3])> = (0..hand.faces())
        .map(|f| (f as u32, [(0, 0), (1, 0), (0, 1)]))
        .collect();
    for _ in 0..3 {
        let fine = sqrt3_refine(&mesh).expect("refines").mesh;
        corners = (0..fine.faces())
            .map(|g| {
                let (origin, c) = corners[g / 9];
                let child = [(0, 0), (1, 0), (0, 1)].map(|(s, t)| {
                    let (u, w) = ternary_child_to_parent((g % 9) as u8, s, t, 1);
                    let (u, w) = (i64::from(u), i64::from(w));
                    (
                        3 * c[0].0 + u * (c[1].0 - c[0].0) + w * (c[2].0 - c[0].0),
                        3 * c[0].1 + u * (c[1].1 - c[0].1) + w * (c[2].1 - c[0].1),
                    )
                });
                (origin, child)
            })
            .collect();
        mesh = fine;
    }
    let mut vertex_at = std::collections::HashMap::new();
    for (g, (origin, c)) in corners.iter().enumerate() {
        for (i, &q) in c.iter().enumerate() {
            vertex_at.insert((*origin, q), mesh.face(g)[i] as usize);
        }
    }
    let mut worst: f64 = 0.0;
    for (i, source) in frame.sources().iter().enumerate() {
        let den = i64::from(source.denominator);
        assert_eq!(level % den, 0, "denominator {den}");
        let q = (
            i64::from(source.u) * level / den,
            i64::from(source.v) * level / den,
        );
        let w = vertex_at[&(source.face, q)];
        let want = limit_position(&mesh, w);
        let got = frame.positions()[i];
        for x in 0..3 {
            worst = worst.max((f64::from(got[x]) - want[x]).abs());
        }
    }
    println!(
        "hand: {} vertices within {worst:.1e}",
        frame.sources().len()
    );
    assert!(worst < 1e-6, "worst position error {worst}");
}
