//! Brute-force √3 subdivision (Kobbelt 2000) on an explicit fan mesh around one vertex of
//! valence `K`: face centroids, Kobbelt's vertex rule and edge flips as plain mesh operations,
//! and Kobbelt's limit rule at a vertex, with no lattice charts and no library code. After
//! `2m` steps the vertex named `(i, j)` in units of `1/3^m` is the surface's point at the
//! ternary parameter `(i/3^m, j/3^m)`.

use std::collections::{BTreeSet, HashMap};

/// Kobbelt's (2000) `alpha_v = (4 - 2 cos(2π/v)) / 9`, written from the paper.
pub fn alpha(v: usize) -> f64 {
    (4.0 - 2.0 * (2.0 * std::f64::consts::PI / v as f64).cos()) / 9.0
}

/// The test's own naming of cone points: `(s, a, b)` given in sector `s`'s chart (any `a, b`),
/// turned sector by sector until `a >= 1, b >= 0` (`(a, b)` of sector `s` is `(a + b, -a)` of
/// sector `s + 1`), `V` as `(0, 0, 0)`. The convention of `TrianglePoint`, written out here.
pub fn name(k: u32, s: i64, a: i64, b: i64) -> (u32, i64, i64) {
    let (mut s, mut a, mut b) = (s, a, b);
    loop {
        if a == 0 && b == 0 {
            return (0, 0, 0);
        }
        if a >= 1 && b >= 0 {
            return (s.rem_euclid(i64::from(k)) as u32, a, b);
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a + b);
        } else {
            (s, a, b) = (s + 1, a + b, -a);
        }
    }
}

/// An explicit triangle mesh on the K-valent cone: faces are corner ids (counter-clockwise);
/// every vertex has a value (`None` where a rule ran off the finite mesh) and a name (its
/// position in units of `1/unit` of the level-0 spacing, [`name`]), used only to build the
/// first mesh and to find vertices by parameter at the end.
pub struct FanMesh {
    /// The valence of V.
    pub valence: u32,
    /// The naming unit: names are in units of `1/unit` of the level-0 spacing.
    pub unit: i64,
    /// Vertex values; `None` where a rule ran off the finite mesh.
    pub values: Vec<Option<f64>>,
    /// Vertex names ([`name`]).
    pub names: Vec<(u32, i64, i64)>,
    /// Faces: corner ids, counter-clockwise.
    pub faces: Vec<[usize; 3]>,
}

impl FanMesh {
    /// The fan of `radius` rings around V, random values everywhere.
    pub fn new(k: u32, radius: i64, unit: i64, value: &mut dyn FnMut() -> f64) -> Self {
        let mut mesh = FanMesh {
            valence: k,
            unit,
            values: Vec::new(),
            names: Vec::new(),
            faces: Vec::new(),
        };
        let mut ids: HashMap<(u32, i64, i64), usize> = HashMap::new();
        for s in 0..i64::from(k) {
            for b in 0..radius {
                for a in 0..radius - b {
                    let mut tris = vec![[(a, b), (a + 1, b), (a, b + 1)]];
                    if a + b + 2 <= radius {
                        tris.push([(a + 1, b), (a + 1, b + 1), (a, b + 1)]);
                    }
                    for tri in tris {
                        let face = tri.map(|(x, y)| {
                            let key = name(k, s, unit * x, unit * y);
                            *ids.entry(key).or_insert_with(|| {
                                mesh.values.push(Some(value()));
                                mesh.names.push(key);
                                mesh.names.len() - 1
                            })
                        });
                        mesh.faces.push(face);
                    }
                }
            }
        }
        mesh
    }

    /// The name's coordinates in sector `s`'s chart, `s` at most one sector away.
    pub fn in_chart(&self, (t, a, b): (u32, i64, i64), s: u32) -> (i64, i64) {
        if (a, b) == (0, 0) {
            return (0, 0);
        }
        let k = self.valence;
        match (t + k - s) % k {
            0 => (a, b),
            1 => (-b, a + b),
            d if d == k - 1 => (a + b, -a),
            d => panic!("a face spans {d} sectors"),
        }
    }

    /// The name of the centroid of `face`, from its corners' names.
    pub fn centroid_name(&self, face: [usize; 3]) -> (u32, i64, i64) {
        let names = face.map(|v| self.names[v]);
        let s = names
            .iter()
            .find(|n| (n.1, n.2) != (0, 0))
            .expect("a face has a corner other than V")
            .0;
        let (mut a, mut b) = (0, 0);
        for n in names {
            let (x, y) = self.in_chart(n, s);
            a += x;
            b += y;
        }
        assert!(
            a % 3 == 0 && b % 3 == 0,
            "centroid off the unit grid: raise `unit`"
        );
        name(self.valence, i64::from(s), a / 3, b / 3)
    }

    /// The ring of every vertex (distinct neighbours), and whether it is on the boundary (an
    /// edge with one face).
    pub fn rings(&self) -> (Vec<BTreeSet<usize>>, Vec<bool>) {
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        let mut ring = vec![BTreeSet::new(); self.values.len()];
        for f in &self.faces {
            for e in 0..3 {
                let (p, r) = (f[e], f[(e + 1) % 3]);
                *edges.entry((p.min(r), p.max(r))).or_default() += 1;
                ring[p].insert(r);
                ring[r].insert(p);
            }
        }
        let mut boundary = vec![false; self.values.len()];
        for (&(p, r), &count) in &edges {
            if count == 1 {
                boundary[p] = true;
                boundary[r] = true;
            }
        }
        (ring, boundary)
    }

    /// Kobbelt's vertex rule with weight `a(valence)` at interior vertex `v`.
    pub fn smoothed(
        &self,
        v: usize,
        ring: &[BTreeSet<usize>],
        boundary: &[bool],
        a: &dyn Fn(usize) -> f64,
    ) -> Option<f64> {
        if boundary[v] {
            return None;
        }
        let n = ring[v].len();
        let mut sum = 0.0;
        for &w in &ring[v] {
            sum += self.values[w]?;
        }
        Some((1.0 - a(n)) * self.values[v]? + a(n) / n as f64 * sum)
    }

    /// One √3 step (Kobbelt 2000): a centroid in every face, every old vertex by the vertex
    /// rule, every interior edge flipped (the edge p q between faces f1 = (p, q, ..) and
    /// f2 = (q, p, ..) becomes the triangles (p, m2, m1) and (q, m1, m2)); boundary edges are
    /// dropped, so the mesh shrinks by a strip per step.
    pub fn subdivide(&self) -> FanMesh {
        let (ring, boundary) = self.rings();
        let old = self.values.len();
        let mut values: Vec<Option<f64>> = (0..old)
            .map(|v| self.smoothed(v, &ring, &boundary, &alpha))
            .collect();
        let mut names = self.names.clone();
        for f in &self.faces {
            let sum: Option<f64> = f.iter().map(|&v| self.values[v]).sum();
            values.push(sum.map(|s| s / 3.0));
            names.push(self.centroid_name(*f));
        }
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for (i, f) in self.faces.iter().enumerate() {
            for e in 0..3 {
                directed.insert((f[e], f[(e + 1) % 3]), i);
            }
        }
        let mut faces = Vec::new();
        for (&(p, r), &f1) in &directed {
            if p > r {
                continue;
            }
            let Some(&f2) = directed.get(&(r, p)) else {
                continue;
            };
            let (m1, m2) = (old + f1, old + f2);
            faces.push([p, m2, m1]);
            faces.push([r, m1, m2]);
        }
        FanMesh {
            valence: self.valence,
            unit: self.unit,
            values,
            names,
            faces,
        }
    }

    /// The limit position of vertex `v`: Kobbelt's rule `V_inf = (1 - b) V + b R`,
    /// `b = 3 a_v / (1 + 3 a_v)`, `R` the average of the ring (the pair recursion of
    /// `limit_mask_at_v_is_kobbelts_limit_rule`).
    pub fn limit(&self, v: usize, ring: &[BTreeSet<usize>], boundary: &[bool]) -> Option<f64> {
        let b = |n: usize| 3.0 * alpha(n) / (1.0 + 3.0 * alpha(n));
        self.smoothed(v, ring, boundary, &b)
    }

    /// Vertex ids by name.
    pub fn by_name(&self) -> HashMap<(u32, i64, i64), usize> {
        self.names
            .iter()
            .enumerate()
            .map(|(i, &n)| (n, i))
            .collect()
    }
}
