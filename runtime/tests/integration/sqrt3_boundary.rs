//! √3 beside a straight boundary (Kobbelt's boundary rules): the generator's strip evaluation
//! (`stencilgen::sqrt3_strip`, the scaling relation with the regular basis and the boundary
//! rules of `schemes::sqrt3_boundary`) against whole-mesh refinement (`subtess`'s
//! `sqrt3_refine`) and Kobbelt's limit positions, which share no code with it.

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
