//! Exact evaluation: the limit position and the first derivatives `d/du`, `d/dv` of one face
//! of a Catmull–Clark surface at any rational `(u, v)`, in the face's own parameterization,
//! correct to f64 rounding.
//!
//! Everything is computed in exact rational arithmetic from the f64 control points (which are
//! exact binary rationals) and rounded once at the end, so the result is the correctly rounded
//! value of the limit surface — except the derivatives *at* an extraordinary vertex, whose
//! masks are irrational (they are computed in f64, to about 1e-15).
//!
//! # Method (Schaefer–Warren section 5.2, "substitution")
//!
//! 1. **Isolation.** The mesh is refined by global Catmull–Clark steps ([`crate::scheme::catmull_clark::refine`]) until
//!    the face's piece containing `(u, v)` is a table patch ([`face_patch`]: a quad with at most
//!    one irregular corner, no interior irregular corner beside the boundary). A quad face
//!    descends into the quarter containing `(u, v)` (`u, v <= 1/2` goes to the lower quarter),
//!    child `i` (the one at corner `i`) with the child's own parameters
//!    `(2u, 2v)`, `(2v, 2 - 2u)`, `(2 - 2u, 2 - 2v)`, `(2 - 2v, 2u)` for `i = 0..3` (the child's
//!    first vertex is the parent's corner `i`, see [`crate::scheme::catmull_clark::refine`]). The refined control
//!    points are recomputed exactly (rationals) from the original ones with the same rules.
//! 2. **Rotation.** The patch's `(0,0)` is the face corner of [`face_patch`];
//!    [`crate::scheme::patch::to_patch`] maps face to patch parameters.
//! 3. **Substitution.** With `K` control points `P` in the table layout
//!    (`docs/algorithms/extraordinary-stencils.md`), the local subdivision matrix `A` and the
//!    sub-patch nets `R_b` ([`schemes::local_matrices::LocalMatrices`]): double `x = (u, v)`
//!    `k` times until it leaves `[0,1/2]^2`, take the regular sub-patch `b` it falls in and
//!    `t = 2x - o_b`; then
//!    `S(x) = psi(t) R_b A^k P` and `d/du S(x) = 2^(k+1) (d/du psi)(t) R_b A^k P`,
//!    `psi` the bicubic B-spline basis (closed form). A regular patch (valence 4, a regular
//!    boundary vertex, a pinned corner) is `psi(x) N P` directly, `N` its 4 x 4 net.
//! 4. **At the extraordinary vertex** (`x = (0,0)`, not regular): the position is the limit mask
//!    `l`, `l A = l`, `sum l = 1` (solved exactly: `(v^2 V + 4 sum E + sum F) / (v (v + 5))` in the
//!    interior, `(E_1 + 4 V + E_{f+1}) / 6` on the boundary). The parametric derivatives
//!    vanish or diverge there (like `(2 lambda)^k`), so `du`, `dv` are the tables' tangent
//!    masks instead (the same convention as `stencilgen`'s `ev_tangents`): the left
//!    eigenvectors of the two subdominant eigenvalues of the 1-ring block of `A`, normalized
//!    on the reference planar net so that `du` points along `E_{s+1}` and `dv` along
//!    `E_{s+2}` with unit length there. The eigenvalues are known in closed form for
//!    Catmull–Clark (Stam 1998, eq. 9: `lambda(v) = (5 + cos(2 pi/v) + cos(pi/v)
//!    sqrt(18 + 2 cos(2 pi/v)))/16`, double, in the interior; at a boundary vertex with `f`
//!    faces the antisymmetric modes of valence `2f`: `lambda_1(2f)` and the larger of
//!    `lambda_2(2f)` and the boundary tangent's `1/2`, or `1/2` and `1/4` with one face); the
//!    eigenvectors are null vectors found by elimination with complete pivoting, the boundary
//!    tangent `E_1 - E_{f+1}` and `2V - E_1 - E_2` (one face) in closed form. When the
//!    vertex's patch lies `L` isolation steps below the original face, each eigen-component
//!    `w_i` is divided by `(2 lambda_i)^L`, so that with the chain rule's `2^L` the result does
//!    not depend on `L` (`w_i P_{l+1} = lambda_i w_i P_l`): it is the tables' mask when no
//!    isolation is needed, and the true derivative at a regular vertex (`lambda = 1/2`).
//!    Only the plane they span (the tangent plane) is geometric; their lengths are this
//!    convention.
//! 5. **Chain rule.** Derivatives go back through the rotation and the quarter maps, whose
//!    matrices are signed permutations times powers of two (exact in f64).
//!
//! Cost: `k` matrix-vector products on integers that grow by about 12 bits per doubling
//! (`k = log2(1 / max(u, v))` in patch parameters); microseconds to a few milliseconds.
//!
//! # Non-quad faces
//!
//! A face with `n != 4` corners has no `[0,1]^2` parameterization of its own. Its domain is
//! split like its first Catmull–Clark step splits it (the Ptex / OpenSubdiv convention): sub-face
//! `k` is the quad `(vertex k, midpoint side of edge (k, k+1), centroid, edge (k-1, k))` with
//! `(0,0)` at corner `k`, `(1,0)` on the edge to the next corner, `(1,1)` at the face's centre and
//! `(0,1)` on the edge from the previous corner. [`ExactEvaluator::evaluate_subface`] takes `k`;
//! [`ExactEvaluator::evaluate`] on an n-gon means sub-face 0.
//!
//! ```
//! use num_rational::BigRational;
//! use subtess::eval::exact_eval::{evaluate, parse_rational};
//! use subtess::mesh::topology::Mesh;
//! use schemes::BoundaryMode;
//! // A cube: every corner has valence 3.
//! let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!              [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0]];
//! let f = vec![vec![0, 3, 2, 1], vec![4, 5, 6, 7], vec![0, 1, 5, 4],
//!              vec![1, 2, 6, 5], vec![2, 3, 7, 6], vec![3, 0, 4, 7]];
//! let cube = Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("valid");
//! let half = parse_rational("1/2").expect("a rational");
//! let centre = evaluate(&cube, 1, &half, &half).expect("evaluates");
//! // The centre of the top face of the unit cube's limit surface, by symmetry on the axis.
//! assert!((centre.position[0] - 0.5).abs() < 1e-15 && (centre.position[1] - 0.5).abs() < 1e-15);
//! ```

pub mod feature;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use schemes::local_matrices::{LocalMatrices, Neighbourhood, SUB_PATCH_ORIGINS};
use schemes::tangent_frame::{frame_masks, quad_edge, quad_net};
use schemes::QuadScheme;

use crate::mesh::topology::Mesh;
use crate::scheme::catmull_clark::isolate::MAX_STEPS;
use crate::scheme::catmull_clark::refine::{refine, refined_vertex, LevelEdges};
use crate::scheme::patch::face_patch;
use crate::scheme::patch::gather_patches;
use crate::scheme::stencil::Weight;
use crate::RuntimeError;

/// The limit surface at one point: position and first derivatives, in the face's own `(u, v)`
/// (DESIGN.md conventions: `(0,0)` at the face's first vertex, `(1,0)` at its second).
///
/// What is exact (the exact value rounded once to f64): the position always (on meshes with
/// sharp features too, [`feature`]); the derivatives everywhere but at a vertex
/// that is extraordinary or a feature. What is f64: the tangents at an extraordinary vertex
/// (the tables' irrational masks) and at a feature vertex — a corner, a crease, a dart, a
/// crease sector (OpenSubdiv's tangent masks, at darts and sectors of three or more faces
/// their eigen-iteration), applied exactly and rounded once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitPoint {
    /// The limit position.
    pub position: [f64; 3],
    /// `dS/du`. At an extraordinary vertex: the tables' tangent mask along the face's `u` edge
    /// (see the module documentation), not a parametric derivative. At a feature vertex of a
    /// mesh with sharp features: a tangent along the frame of the face the descent ended in
    /// ([`feature`]); with [`LimitPoint::dv`] it spans the tangent plane and its
    /// cross product with it is the outward normal.
    pub du: [f64; 3],
    /// `dS/dv`, likewise.
    pub dv: [f64; 3],
}

/// An exact point.
pub(crate) type Point = [BigRational; 3];

/// Position, `d/du`, `d/dv` in patch parameters.
pub(crate) type Derivatives = ([f64; 3], [f64; 3], [f64; 3]);

/// The most bits of a parameter's numerator and denominator, in lowest terms
/// ([`parse_rational`]; docs/reliability.md).
pub const MAX_RATIONAL_BITS: u64 = 64;

/// The most characters of a parameter's text ([`parse_rational`]): room for two 20-digit
/// integers and a slash, with some leading zeros.
pub const MAX_RATIONAL_CHARS: usize = 64;

/// Parse a parameter value in the one rational grammar ([`schemes::rational::parse_rational`]:
/// `p/q`, an integer, or a decimal like `0.25` taken exactly, not through a float), which must
/// lie in `[0, 1]`, a face's parameter domain, with at most [`MAX_RATIONAL_CHARS`] characters
/// and a numerator and denominator of at most [`MAX_RATIONAL_BITS`] bits. DESIGN.md: rational
/// parameters are written `p/q` on the command line and in JSON.
pub fn parse_rational(text: &str) -> Result<BigRational, RuntimeError> {
    let bad = |reason: String| RuntimeError::InvalidParameter {
        name: format!("`{}`", crate::error::excerpt(text)),
        reason,
    };
    // Bounded before parsing: big integers parse in time quadratic in their digits (a
    // `1/2^k` with a million digits took over a minute).
    if text.trim().len() > MAX_RATIONAL_CHARS {
        return Err(bad(format!(
            "{} characters; a parameter is at most {MAX_RATIONAL_CHARS} (numerator and denominator of at most {MAX_RATIONAL_BITS} bits)",
            text.trim().len()
        )));
    }
    let value = schemes::rational::parse_rational(text).map_err(|e| bad(e.to_string()))?;
    if value.numer().bits() > MAX_RATIONAL_BITS || value.denom().bits() > MAX_RATIONAL_BITS {
        return Err(bad(format!(
            "in lowest terms its numerator or denominator has more than {MAX_RATIONAL_BITS} bits (each must fit 64 bits: 1/2^63 is the finest power of two)"
        )));
    }
    if value.is_negative() || value > BigRational::one() {
        return Err(bad(format!(
            "{value} is outside [0, 1]; a face's parameters lie in [0, 1]"
        )));
    }
    Ok(value)
}

/// Position and derivatives of face `face` of `mesh` (the user's original mesh: any polygons,
/// closed or with boundary, either boundary mode) at `(u, v)`, exact to f64 rounding.
/// Convenience for one point: builds an [`ExactEvaluator`] (which refines the mesh) each call.
pub fn evaluate(
    mesh: &Mesh,
    face: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<LimitPoint, RuntimeError> {
    ExactEvaluator::new(mesh).evaluate(face, u, v)
}

/// [`ExactEvaluator::evaluate_subface`] for one point.
pub fn evaluate_subface(
    mesh: &Mesh,
    face: usize,
    corner: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<LimitPoint, RuntimeError> {
    ExactEvaluator::new(mesh).evaluate_subface(face, corner, u, v)
}

/// Evaluates faces of one mesh exactly; refines it (in f64, for the topology) once, up to the
/// steps [`crate::scheme::catmull_clark::isolate`] would take, and reuses that for every call.
#[derive(Debug)]
pub struct ExactEvaluator {
    /// `levels[0]` is the mesh, `levels[i]` its `i`-th refinement (none for a mesh with sharp
    /// features, which [`feature`] refines locally, point by point).
    levels: Vec<Mesh>,
    /// Whether points take the feature descent ([`feature`]): the mesh has sharp features
    /// ([`Mesh::has_sharp_features`]) or an interior vertex of valence 2, where no patch of the
    /// scaling relation exists.
    tagged: bool,
    /// The edge numbering of each refinement step (`levels[i]` -> `levels[i + 1]`).
    edges: Vec<LevelEdges>,
    scheme: QuadScheme,
    /// The operators of every patch kind met so far.
    operators: Mutex<HashMap<(Neighbourhood, u32), Arc<PatchOperators>>>,
}

/// One patch kind's local subdivision matrices, and as integer matrices the ones applied.
#[derive(Debug)]
struct PatchOperators {
    matrices: LocalMatrices,
    a: IntMatrix,
    sub_patches: [IntMatrix; 3],
    regular_net: Option<IntMatrix>,
}

/// Where a face parameter landed: a patch of some level, the patch parameters, and the matrix
/// `M` with `d(patch params) = M d(face params)`.
struct Located {
    level: usize,
    patch: crate::scheme::patch::FacePatch,
    u: BigRational,
    v: BigRational,
    jacobian: [[i64; 2]; 2],
}

/// Checks a query: face `face` exists, `corner` names one of its sub-faces (0 for a quad), `u`
/// and `v` lie in `[0, 1]`; the face's number of sides.
pub(crate) fn check_query(
    mesh: &Mesh,
    face: usize,
    corner: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<usize, RuntimeError> {
    let bad = |text: String, reason: String| RuntimeError::InvalidParameter {
        name: format!("`{text}`"),
        reason,
    };
    if face >= mesh.faces() {
        return Err(bad(
            format!("face {face}"),
            format!(
                "the mesh has {} faces, numbered from 0 in file order",
                mesh.faces()
            ),
        ));
    }
    let (zero, one) = (BigRational::zero(), BigRational::one());
    for (name, x) in [("u", u), ("v", v)] {
        if *x < zero || *x > one {
            return Err(bad(
                format!("{name} = {x}"),
                "a face's parameters lie in [0, 1]".to_owned(),
            ));
        }
    }
    let sides = mesh.face(face).len();
    if sides == 4 && corner != 0 {
        return Err(bad(
            format!("corner {corner}"),
            format!("face {face} is a quad: it is its own domain, use corner 0"),
        ));
    }
    if corner >= sides {
        return Err(bad(
            format!("corner {corner}"),
            format!("face {face} has {sides} corners (sub-faces 0..{sides})"),
        ));
    }
    Ok(sides)
}

/// The quarter of a quad holding face parameters `(s, t)` (module documentation, step 1):
/// child `c` of [`refine`], at corner `c`, the point in the child's own parameters, and the
/// matrix `d(child parameters) / d(parent parameters)`. A point on the lines `s = 1/2` or
/// `t = 1/2` goes to the lower quarter.
pub(crate) fn descend(
    s: &BigRational,
    t: &BigRational,
) -> (usize, BigRational, BigRational, [[i64; 2]; 2]) {
    let half = ratio(1, 2);
    let two = int(2);
    match (*s > half, *t > half) {
        (false, false) => (0, &two * s, &two * t, [[2, 0], [0, 2]]),
        (true, false) => (1, &two * t, &two - &two * s, [[0, 2], [-2, 0]]),
        (true, true) => (2, &two - &two * s, &two - &two * t, [[-2, 0], [0, -2]]),
        (false, true) => (3, &two - &two * t, &two * s, [[0, -2], [2, 0]]),
    }
}

/// Face parameters `(s, t)` in the parameters of a patch whose `(0, 0)` is the face's corner
/// `corner` (module documentation, step 2), and the rotation `d(patch) / d(face)`.
pub(crate) fn to_corner(
    corner: usize,
    s: &BigRational,
    t: &BigRational,
) -> (BigRational, BigRational, [[i64; 2]; 2]) {
    match corner {
        0 => (s.clone(), t.clone(), [[1, 0], [0, 1]]),
        1 => (t.clone(), int(1) - s, [[0, 1], [-1, 0]]),
        2 => (int(1) - s, int(1) - t, [[-1, 0], [0, -1]]),
        _ => (int(1) - t, s.clone(), [[0, -1], [1, 0]]),
    }
}

fn mul(a: [[i64; 2]; 2], b: [[i64; 2]; 2]) -> [[i64; 2]; 2] {
    let mut c = [[0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}

pub(crate) fn ratio(p: i64, q: i64) -> BigRational {
    BigRational::ratio(p, q)
}

pub(crate) fn int(i: i64) -> BigRational {
    BigRational::from_integer(BigInt::from(i))
}

impl ExactEvaluator {
    /// Prepare `mesh` (refined as far as its isolation needs, at most
    /// [`crate::scheme::catmull_clark::isolate::MAX_STEPS`] steps).
    pub fn new(mesh: &Mesh) -> Self {
        let mut levels = vec![mesh.clone()];
        let mut edges = Vec::new();
        let valence_two = (0..mesh.positions.len())
            .any(|v| !mesh.is_boundary_vertex(v) && mesh.fan_iter(v).count() == 2);
        let tagged = mesh.has_sharp_features() || valence_two;
        while !tagged && levels.len() <= MAX_STEPS {
            let last = &levels[levels.len() - 1];
            if gather_patches(last).is_ok() {
                break;
            }
            edges.push(LevelEdges::new(last));
            let next = refine(last).mesh;
            levels.push(next);
        }
        ExactEvaluator {
            levels,
            tagged,
            edges,
            scheme: QuadScheme::by_name("catmull-clark")
                .unwrap_or_else(|| unreachable!("catmull-clark is catalogued")),
            operators: Mutex::new(HashMap::new()),
        }
    }

    /// The operators of a patch kind (built once, then shared).
    fn operators(
        &self,
        nb: Neighbourhood,
        sector: u32,
    ) -> Result<Arc<PatchOperators>, RuntimeError> {
        let cached = self
            .operators
            .lock()
            .ok()
            .and_then(|cache| cache.get(&(nb, sector)).cloned());
        if let Some(operators) = cached {
            return Ok(operators);
        }
        let matrices = LocalMatrices::new(&self.scheme, nb, sector)
            .map_err(|e| RuntimeError::Unsupported(e.to_string()))?;
        let operators = Arc::new(PatchOperators {
            a: IntMatrix::new(&matrices.a),
            sub_patches: std::array::from_fn(|b| IntMatrix::new(&matrices.sub_patches[b])),
            regular_net: matrices.regular_net().map(|n| IntMatrix::new(&n)),
            matrices,
        });
        if let Ok(mut cache) = self.operators.lock() {
            cache.insert((nb, sector), Arc::clone(&operators));
        }
        Ok(operators)
    }

    /// The mesh being evaluated.
    pub fn mesh(&self) -> &Mesh {
        &self.levels[0]
    }

    /// Position and derivatives of face `face` at `(u, v)` in `[0,1]^2`, the face's own
    /// parameters (for a face that is not a quad: those of its sub-face 0, see the module
    /// documentation). Exact to f64 rounding (Schaefer–Warren section 5.2, by substitution).
    pub fn evaluate(
        &self,
        face: usize,
        u: &BigRational,
        v: &BigRational,
    ) -> Result<LimitPoint, RuntimeError> {
        self.evaluate_subface(face, 0, u, v)
    }

    /// Position and derivatives of sub-face `corner` of face `face` at `(u, v)`: for a face with
    /// `n != 4` corners, the quad its first Catmull–Clark step makes at corner `corner`
    /// (`(0,0)` at that corner, `(1,0)` towards the next corner, `(1,1)` at the centre);
    /// for a quad, `corner` must be 0 and `(u, v)` are the face's own parameters.
    pub fn evaluate_subface(
        &self,
        face: usize,
        corner: usize,
        u: &BigRational,
        v: &BigRational,
    ) -> Result<LimitPoint, RuntimeError> {
        if self.tagged {
            return feature::evaluate(self, face, corner, u, v);
        }
        let located = self.locate(face, corner, u, v)?;
        let mut exact = ExactPositions::new(self);
        let points: Vec<Point> = located
            .patch
            .points
            .iter()
            .map(|&p| exact.vertex(located.level, p as usize))
            .collect();
        let (position, du, dv) = self.table_patch(
            face,
            &located.patch,
            &points,
            &located.u,
            &located.v,
            located.level,
        )?;
        // d/d(face) = M^T d/d(patch); M's entries are 0 or +-2^m: exact.
        let m = located.jacobian;
        let combine = |a: i64, b: i64| -> [f64; 3] {
            std::array::from_fn(|c| a as f64 * du[c] + b as f64 * dv[c])
        };
        Ok(LimitPoint {
            position,
            du: combine(m[0][0], m[1][0]),
            dv: combine(m[0][1], m[1][1]),
        })
    }

    /// Position, `d/du`, `d/dv` in patch parameters `(u, v)` of the table patch `patch` (of face
    /// `face`, for messages) with exact control points `points` in its layout, `level` steps
    /// below the input mesh (Schaefer–Warren substitution, module documentation steps 3–4).
    pub(crate) fn table_patch(
        &self,
        face: usize,
        patch: &crate::scheme::patch::FacePatch,
        points: &[Point],
        u: &BigRational,
        v: &BigRational,
        level: usize,
    ) -> Result<Derivatives, RuntimeError> {
        let nb = patch.kind.neighbourhood(self.levels[0].boundary);
        let operators = self.operators(nb, patch.kind.sector)?;
        let matrices = &operators.matrices;
        if matrices.size() != points.len() {
            return Err(RuntimeError::Unsupported(format!(
                "face {face}: its patch ({}) has {} control points, the layout {}",
                matrices.describe(),
                points.len(),
                matrices.size()
            )));
        }
        evaluate_patch(&operators, points, u, v, level)
    }

    fn locate(
        &self,
        face: usize,
        corner: usize,
        u: &BigRational,
        v: &BigRational,
    ) -> Result<Located, RuntimeError> {
        let mesh = &self.levels[0];
        let sides = check_query(mesh, face, corner, u, v)?;
        let (mut level, mut f) = (0, face);
        if sides != 4 {
            if self.levels.len() < 2 {
                unreachable!("a mesh with a non-quad face is refined at least once");
            }
            f = mesh.face_offsets[face] as usize + corner;
            level = 1;
        }
        let (mut s, mut t) = (u.clone(), v.clone());
        let mut jacobian = [[1, 0], [0, 1]];
        loop {
            let current = &self.levels[level];
            match face_patch(current, f) {
                Ok(patch) => {
                    let (pu, pv, rotation) = to_corner(patch.corner, &s, &t);
                    return Ok(Located {
                        level,
                        patch,
                        u: pu,
                        v: pv,
                        jacobian: mul(rotation, jacobian),
                    });
                }
                Err(e) if level + 1 >= self.levels.len() => return Err(e.into()),
                Err(_) => {}
            }
            let (quarter, ns, nt, map) = descend(&s, &t);
            (s, t) = (ns, nt);
            jacobian = mul(map, jacobian);
            f = current.face_offsets[f] as usize + quarter;
            level += 1;
        }
    }
}

/// Exact positions of the vertices of the refined meshes, recomputed from the original f64
/// positions with the rules of [`crate::scheme::catmull_clark::refine`] in rationals
/// ([`refined_vertex`]), memoized.
struct ExactPositions<'e> {
    evaluator: &'e ExactEvaluator,
    vertices: HashMap<(usize, usize), Point>,
}

impl<'e> ExactPositions<'e> {
    fn new(evaluator: &'e ExactEvaluator) -> Self {
        ExactPositions {
            evaluator,
            vertices: HashMap::new(),
        }
    }

    /// Vertex `v` of level `level`.
    fn vertex(&mut self, level: usize, v: usize) -> Point {
        if let Some(p) = self.vertices.get(&(level, v)) {
            return p.clone();
        }
        let point = if level == 0 {
            let p = self.evaluator.levels[0].positions[v];
            // Mesh positions are finite (validated), so exactly representable.
            std::array::from_fn(|c| BigRational::from_float(p[c]).unwrap_or_else(BigRational::zero))
        } else {
            let coarse = &self.evaluator.levels[level - 1];
            let terms: Vec<(u32, BigRational)> =
                refined_vertex(coarse, &self.evaluator.edges[level - 1], v);
            let mut sum: Point = std::array::from_fn(|_| BigRational::zero());
            for (j, w) in terms {
                let q = self.vertex(level - 1, j as usize);
                for c in 0..3 {
                    sum[c] += &q[c] * &w;
                }
            }
            sum
        };
        self.vertices.insert((level, v), point.clone());
        point
    }
}

/// Points with one common denominator per coordinate: point `j`, coordinate `c` is
/// `num[j][c] / den[c]`. Applying a rational matrix is then integer arithmetic only.
#[derive(Clone, Debug)]
pub(crate) struct Scaled {
    num: Vec<[BigInt; 3]>,
    den: [BigInt; 3],
}

impl Scaled {
    pub(crate) fn new(points: &[Point]) -> Self {
        let den: [BigInt; 3] = std::array::from_fn(|c| {
            points
                .iter()
                .fold(BigInt::one(), |acc, p| acc.lcm(p[c].denom()))
        });
        let num = points
            .iter()
            .map(|p| std::array::from_fn(|c| p[c].numer() * (&den[c] / p[c].denom())))
            .collect();
        Scaled { num, den }
    }
}

/// A rational matrix as integers over one denominator, rows sparse.
#[derive(Debug)]
struct IntMatrix {
    rows: Vec<Vec<(usize, BigInt)>>,
    den: BigInt,
}

impl IntMatrix {
    fn new(m: &[Vec<BigRational>]) -> Self {
        let den = m
            .iter()
            .flatten()
            .fold(BigInt::one(), |acc, x| acc.lcm(x.denom()));
        let rows = m
            .iter()
            .map(|row| {
                row.iter()
                    .enumerate()
                    .filter(|(_, x)| !x.is_zero())
                    .map(|(j, x)| (j, x.numer() * (&den / x.denom())))
                    .collect()
            })
            .collect();
        IntMatrix { rows, den }
    }

    fn apply(&self, x: &Scaled) -> Scaled {
        let num = self
            .rows
            .iter()
            .map(|row| {
                std::array::from_fn(|c| {
                    row.iter()
                        .fold(BigInt::zero(), |acc, (j, w)| acc + w * &x.num[*j][c])
                })
            })
            .collect();
        Scaled {
            num,
            den: std::array::from_fn(|c| &x.den[c] * &self.den),
        }
    }
}

/// The cubic B-spline basis at `t = p/q` on the four control points `-1..=2` of a cell, as
/// integers over a common denominator: values over `6 q^3`, derivatives over `2 q^2`.
fn bspline(t: &BigRational, derivative: bool) -> ([BigInt; 4], BigInt) {
    let (p, q) = (t.numer().clone(), t.denom().clone());
    let r = &q - &p;
    if derivative {
        let w = [
            -(&r * &r),
            BigInt::from(3) * &p * &p - BigInt::from(4) * &p * &q,
            BigInt::from(-3) * &p * &p + BigInt::from(2) * &p * &q + &q * &q,
            &p * &p,
        ];
        (w, BigInt::from(2) * &q * &q)
    } else {
        let (p2, q2) = (&p * &p, &q * &q);
        let w = [
            &r * &r * &r,
            BigInt::from(3) * &p2 * &p - BigInt::from(6) * &p2 * &q + BigInt::from(4) * &q2 * &q,
            BigInt::from(-3) * &p2 * &p
                + BigInt::from(3) * &p2 * &q
                + BigInt::from(3) * &p * &q2
                + &q2 * &q,
            &p2 * &p,
        ];
        (w, BigInt::from(6) * &q2 * &q)
    }
}

/// The bicubic B-spline patch of the 16 points `net` (`(p, q)` in `-1..=2`, `q` outer) at
/// `(tu, tv)`: position, `d/dtu`, `d/dtv`, each times `factor` for the derivatives.
pub(crate) fn bicubic(
    net: &Scaled,
    tu: &BigRational,
    tv: &BigRational,
    factor: &BigInt,
) -> [[f64; 3]; 3] {
    let evaluate = |du: bool, dv: bool| -> [f64; 3] {
        let (wu, nu) = bspline(tu, du);
        let (wv, nv) = bspline(tv, dv);
        let times = if du || dv {
            factor.clone()
        } else {
            BigInt::one()
        };
        std::array::from_fn(|c| {
            let mut sum = BigInt::zero();
            for (qi, a) in wv.iter().enumerate() {
                for (pi, b) in wu.iter().enumerate() {
                    sum += a * b * &net.num[qi * 4 + pi][c];
                }
            }
            let value = BigRational::new(sum * &times, &nu * &nv * &net.den[c]);
            value.to_f64().unwrap_or(f64::NAN)
        })
    };
    [
        evaluate(false, false),
        evaluate(true, false),
        evaluate(false, true),
    ]
}

/// Position, `d/du`, `d/dv` of a patch at patch parameters `(u, v)` (Schaefer–Warren section
/// 5.2: `phi(x) = psi(t) R_b A^k`, derivatives times `2^(k+1)`).
fn evaluate_patch(
    operators: &PatchOperators,
    points: &[Point],
    u: &BigRational,
    v: &BigRational,
    level: usize,
) -> Result<Derivatives, RuntimeError> {
    let matrices = &operators.matrices;
    let p = Scaled::new(points);
    if let Some(net) = &operators.regular_net {
        let net = net.apply(&p);
        let [position, du, dv] = bicubic(&net, u, v, &BigInt::one());
        return Ok((position, du, dv));
    }
    if u.is_zero() && v.is_zero() {
        return at_vertex(matrices, points, level);
    }
    let half = ratio(1, 2);
    let two = int(2);
    let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
    while x <= half && y <= half {
        x *= &two;
        y *= &two;
        k += 1;
    }
    let b = match (x > half, y > half) {
        (true, false) => 0,
        (true, true) => 1,
        _ => 2,
    };
    let (a0, b0) = SUB_PATCH_ORIGINS[b];
    let tu = &x * &two - int(a0);
    let tv = &y * &two - int(b0);
    let mut level = p;
    for _ in 0..k {
        level = operators.a.apply(&level);
    }
    let net = operators.sub_patches[b].apply(&level);
    let factor = BigInt::one() << (k as usize + 1);
    let [position, du, dv] = bicubic(&net, &tu, &tv, &factor);
    Ok((position, du, dv))
}

/// Exact Gaussian elimination: the unique solution of `rows . x = rhs` (more rows than
/// unknowns allowed, as long as they are consistent), or `None`.
pub(crate) fn solve_exact(
    mut rows: Vec<(Vec<BigRational>, BigRational)>,
    n: usize,
) -> Option<Vec<BigRational>> {
    let mut pivots = Vec::with_capacity(n);
    let mut r = 0;
    for col in 0..n {
        let i = (r..rows.len()).find(|&i| !rows[i].0[col].is_zero())?;
        rows.swap(r, i);
        let (pivot_row, pivot_rhs) = rows[r].clone();
        let inverse = BigRational::one() / &pivot_row[col];
        for (i, (row, rhs)) in rows.iter_mut().enumerate() {
            if i == r || row[col].is_zero() {
                continue;
            }
            let f = &row[col] * &inverse;
            for (x, y) in row.iter_mut().zip(&pivot_row) {
                *x -= &f * y;
            }
            *rhs -= &f * &pivot_rhs;
        }
        pivots.push(r);
        r += 1;
    }
    if rows[r..].iter().any(|(_, rhs)| !rhs.is_zero()) {
        return None;
    }
    Some(
        (0..n)
            .map(|c| &rows[pivots[c]].1 / &rows[pivots[c]].0[c])
            .collect(),
    )
}

/// The value and the tangent masks at the extraordinary vertex itself (module docs, step 4).
fn at_vertex(
    matrices: &LocalMatrices,
    points: &[Point],
    level: usize,
) -> Result<Derivatives, RuntimeError> {
    let nb = matrices.neighbourhood;
    let (edges, faces) = (nb.edges() as usize, nb.faces as usize);
    let ring = 1 + edges + faces;
    let failure = |what: &str| {
        RuntimeError::Unsupported(format!(
            "the limit at the extraordinary vertex ({}): {what}",
            matrices.describe()
        ))
    };
    // The limit mask: l A_1 = l, sum l = 1.
    let mut rows: Vec<(Vec<BigRational>, BigRational)> = (0..ring)
        .map(|j| {
            let mut row: Vec<BigRational> = (0..ring).map(|i| matrices.a[i][j].clone()).collect();
            row[j] -= BigRational::one();
            (row, BigRational::zero())
        })
        .collect();
    rows.push((vec![BigRational::one(); ring], BigRational::one()));
    let limit = solve_exact(rows, ring).ok_or_else(|| failure("no unique limit mask"))?;
    let position: [f64; 3] = std::array::from_fn(|c| {
        let sum = limit
            .iter()
            .zip(points)
            .fold(BigRational::zero(), |acc, (w, p)| acc + w * &p[c]);
        sum.to_f64().unwrap_or(f64::NAN)
    });
    let (du_mask, dv_mask) =
        tangent_masks(matrices, level).ok_or_else(|| failure("no tangent plane"))?;
    let apply = |mask: &[f64]| -> [f64; 3] {
        std::array::from_fn(|c| {
            let sum = mask
                .iter()
                .zip(points)
                .fold(BigRational::zero(), |acc, (w, p)| {
                    acc + BigRational::from_float(*w).unwrap_or_else(BigRational::zero) * &p[c]
                });
            sum.to_f64().unwrap_or(f64::NAN)
        })
    };
    Ok((position, apply(&du_mask), apply(&dv_mask)))
}

/// The larger eigenvalue of Fourier frequency `j` of Catmull–Clark's 1-ring at valence `v`;
/// `j = 1` is the subdominant eigenvalue (Stam 1998, eq. 9).
fn catmull_clark_lambda(v: f64, j: f64) -> f64 {
    let c = (2.0 * std::f64::consts::PI * j / v).cos();
    let h = (std::f64::consts::PI * j / v).cos();
    (5.0 + c + h * (18.0 + 2.0 * c).sqrt()) / 16.0
}

/// The `u` and `v` tangent masks at the vertex (`K` weights, zero beyond the 1-ring): the
/// combinations of the subdominant left eigenvectors of the 1-ring block that map the reference
/// net `V = 0, E_i = (cos t_i, sin t_i), F_i = E_i + E_{i+1}` to the unit vectors of `E_{s+1}`
/// and `E_{s+2}` (the normalization of `stencilgen`'s `ev_tangents`, hence of the tables).
///
/// For a patch `level` isolation steps below the original face, each eigen-component is
/// divided by `(2 lambda_i)^level`: after the chain rule's `2^level` the result is
/// `sum_i c_i (w_i . P_level) / lambda_i^level = sum_i c_i (w_i . P_0)`, independent of how many
/// steps isolated the face (`w_i P_{l+1} = lambda_i w_i P_l`); at a regular vertex
/// (`lambda = 1/2`) this is the chain rule itself.
fn tangent_masks(matrices: &LocalMatrices, level: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let nb = matrices.neighbourhood;
    let (edges, faces) = (nb.edges() as usize, nb.faces as usize);
    let ring = 1 + edges + faces;
    let a1: Vec<Vec<f64>> = (0..ring)
        .map(|i| {
            (0..ring)
                .map(|j| matrices.a[i][j].to_f64().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    // The two largest eigenvalues below 1 and their left eigenvectors. The 1-ring of a boundary
    // vertex with f faces splits into the boundary curve's block (V, E_1, E_{f+1}: 1, 1/2,
    // 1/4) and the interior points, whose eigenvalues are the antisymmetric modes of an interior
    // vertex of valence 2f: lambda_j(2f), j = 1..f-1 (and smaller ones). So the pair is
    // lambda_1(2f) and the larger of lambda_2(2f) and 1/2 (the boundary tangent
    // `E_1 - E_{f+1}`, taken as it is: at 4 faces 1/2 is a defective double eigenvalue whose
    // only eigenvector it is); with one face, 1/2 and 1/4.
    let numeric = |lambda: f64, count: usize| -> Vec<(Vec<f64>, f64)> {
        let b: Vec<Vec<f64>> = (0..ring)
            .map(|i| {
                (0..ring)
                    .map(|j| a1[j][i] - if i == j { lambda } else { 0.0 })
                    .collect()
            })
            .collect();
        null_vectors(b, count)
            .into_iter()
            .map(|w| (w, lambda))
            .collect()
    };
    let mut boundary_tangent = vec![0.0; ring];
    (boundary_tangent[1], boundary_tangent[edges]) = (1.0, -1.0);
    let basis: Vec<(Vec<f64>, f64)> = match nb.boundary {
        None => numeric(catmull_clark_lambda(faces as f64, 1.0), 2),
        Some(_) if faces == 1 => {
            // 1/4: defective double; its one eigenvector is 2 V - E_1 - E_2.
            vec![(boundary_tangent, 0.5), (vec![2.0, -1.0, -1.0, 0.0], 0.25)]
        }
        Some(_) => {
            let v = 2.0 * faces as f64;
            let mut b = numeric(catmull_clark_lambda(v, 1.0), 1);
            if faces >= 5 {
                b.extend(numeric(catmull_clark_lambda(v, 2.0), 1));
            } else {
                b.push((boundary_tangent, 0.5));
            }
            b
        }
    };
    if basis.len() != 2 {
        return None;
    }
    let level = i32::try_from(level).unwrap_or(i32::MAX);
    let scales: Vec<f64> = basis.iter().map(|(_, l)| (2.0 * l).powi(-level)).collect();
    let basis: Vec<Vec<f64>> = basis.into_iter().map(|(w, _)| w).collect();
    let boundary = nb.boundary.is_some();
    let edge = |i: usize| quad_edge(boundary, edges, faces, i);
    let net = quad_net(boundary, edges, faces);
    let sector = matrices.sector as usize;
    let [du, dv] = frame_masks(
        [&basis[0], &basis[1]],
        &net,
        [scales[0], scales[1]],
        [edge(sector), edge(sector + 1)],
        matrices.size(),
    )?;
    Some((du, dv))
}

/// `count` independent null vectors of the (numerically) singular square matrix `b`, whose
/// null space has dimension `count`: Gaussian elimination with complete pivoting for
/// `n - count` steps, then back substitution with each remaining column set to 1 in turn.
pub(crate) fn null_vectors(mut b: Vec<Vec<f64>>, count: usize) -> Vec<Vec<f64>> {
    let n = b.len();
    let rank = n.saturating_sub(count);
    let mut columns: Vec<usize> = (0..n).collect();
    for k in 0..rank {
        let (mut pi, mut pj, mut best) = (k, k, -1.0);
        for (i, row) in b.iter().enumerate().skip(k) {
            for (j, x) in row.iter().enumerate().skip(k) {
                if x.abs() > best {
                    (pi, pj, best) = (i, j, x.abs());
                }
            }
        }
        b.swap(k, pi);
        for row in b.iter_mut() {
            row.swap(k, pj);
        }
        columns.swap(k, pj);
        let pivot_row = b[k].clone();
        for row in b.iter_mut().skip(k + 1) {
            let f = row[k] / pivot_row[k];
            for j in k..n {
                row[j] -= f * pivot_row[j];
            }
        }
    }
    (rank..n)
        .map(|free| {
            let mut x = vec![0.0; n];
            x[free] = 1.0;
            for k in (0..rank).rev() {
                let s: f64 = (k + 1..n).map(|j| b[k][j] * x[j]).sum();
                x[k] = -s / b[k][k];
            }
            let mut w = vec![0.0; n];
            for (j, &c) in columns.iter().enumerate() {
                w[c] = x[j];
            }
            w
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_rationals_integers_and_decimals_exactly() {
        assert_eq!(parse_rational("1/3").ok(), Some(ratio(1, 3)));
        assert_eq!(parse_rational(" 2/4 ").ok(), Some(ratio(1, 2)));
        assert_eq!(parse_rational("0").ok(), Some(int(0)));
        assert_eq!(parse_rational("1").ok(), Some(int(1)));
        assert_eq!(parse_rational("0.25").ok(), Some(ratio(1, 4)));
        assert_eq!(parse_rational(".1").ok(), Some(ratio(1, 10)));
        assert_eq!(parse_rational("1.").ok(), Some(int(1)));
        assert_eq!(parse_rational("1.000").ok(), Some(int(1)));
        for (text, needle) in [
            ("1/0", "denominator is 0"),
            ("4/3", "outside [0, 1]"),
            ("-1/3", "outside [0, 1]"),
            ("1.5", "outside [0, 1]"),
            ("-0.1", "outside [0, 1]"),
            ("2", "outside [0, 1]"),
            ("", "empty"),
            ("a/3", "numerator `a`"),
            ("1/x", "denominator `x`"),
            ("1/-2", "without a sign"),
            ("0.2.5", "not a number"),
            ("1e-3", "not an integer"),
            (".", "not a number"),
        ] {
            let e = parse_rational(text).expect_err(text).to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }

    #[test]
    fn bspline_weights_sum_to_one_and_derivatives_to_zero() {
        for t in [ratio(0, 1), ratio(1, 3), ratio(5, 7), ratio(1, 1)] {
            let (w, d) = bspline(&t, false);
            assert_eq!(w.iter().sum::<BigInt>(), d);
            let (w, _) = bspline(&t, true);
            assert!(w.iter().sum::<BigInt>().is_zero());
        }
    }
}
