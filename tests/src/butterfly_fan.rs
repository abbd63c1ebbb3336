//! Brute-force modified butterfly (Zorin, Schröder, Sweldens 1996) on an explicit fan mesh
//! around one vertex of valence `K`: faces, edges across faces, and the rules written out from
//! the paper, with no lattice charts and no library code. The level-`k` vertices are the limit
//! surface at the dyadic points (the scheme interpolates).

use std::collections::HashMap;

/// The test's own naming of fan vertices: `(s, a, b)` with `a, b >= 0` in sector `s`'s chart,
/// normalized to `a >= 1` (the point `(0, b)` of sector `s` is `(b, 0)` of sector `s + 1`), and
/// `V` as `(0, 0, 0)`. The same convention as `TrianglePoint`, written out independently.
pub fn name(k: u32, s: i64, a: i64, b: i64) -> (u32, i64, i64) {
    assert!(a >= 0 && b >= 0);
    let k = i64::from(k);
    match (a, b) {
        (0, 0) => (0, 0, 0),
        (0, b) => ((s + 1).rem_euclid(k) as u32, b, 0),
        (a, b) => (s.rem_euclid(k) as u32, a, b),
    }
}

/// A face of [`FanMesh`]: corner ids (counter-clockwise), its sector, the corners' chart
/// coordinates in that sector (used only to name the new vertices).
pub type Face = ([usize; 3], i64, [(i64, i64); 3]);

/// An explicit triangle mesh: the K-valent fan of radius `R` around V, subdivided by the
/// butterfly's rules applied topologically (edge -> its two faces -> opposite and wing
/// vertices), with no lattice charts and no library code.
pub struct FanMesh {
    /// The valence of V.
    pub valence: u32,
    /// Values of the vertices; `None` where the stencil ran off the finite mesh.
    pub values: Vec<Option<f64>>,
    /// The vertex of each name.
    pub by_name: HashMap<(u32, i64, i64), usize>,
    /// Faces: corners (ids, counter-clockwise), the sector and the corners' chart coordinates.
    pub faces: Vec<Face>,
}

/// The modified butterfly's extraordinary weights (Zorin, Schröder, Sweldens 1996, written
/// from the paper): K = 3: 5/12, -1/12, -1/12; K = 4: 3/8, 0, -1/8, 0; K >= 5:
/// (1/4 + cos(2πj/K) + cos(4πj/K)/2)/K; 3/4 at the vertex.
pub fn zss_weights(k: u32) -> Vec<f64> {
    match k {
        3 => vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0],
        4 => vec![3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0],
        _ => (0..k)
            .map(|j| {
                let t = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(k);
                (0.25 + t.cos() + 0.5 * (2.0 * t).cos()) / f64::from(k)
            })
            .collect(),
    }
}

impl FanMesh {
    /// The fan of radius `radius` (rings of triangles) around V, every vertex valued by `value`.
    pub fn new(k: u32, radius: i64, value: &mut dyn FnMut() -> f64) -> Self {
        let mut mesh = FanMesh {
            valence: k,
            values: Vec::new(),
            by_name: HashMap::new(),
            faces: Vec::new(),
        };
        for s in 0..i64::from(k) {
            for b in 0..radius {
                for a in 0..radius - b {
                    let up = [(a, b), (a + 1, b), (a, b + 1)];
                    mesh.add_face(s, up, value);
                    if a + b + 2 <= radius {
                        mesh.add_face(s, [(a + 1, b), (a + 1, b + 1), (a, b + 1)], value);
                    }
                }
            }
        }
        mesh
    }

    fn vertex(&mut self, key: (u32, i64, i64), value: &mut dyn FnMut() -> Option<f64>) -> usize {
        if let Some(&v) = self.by_name.get(&key) {
            return v;
        }
        self.values.push(value());
        self.by_name.insert(key, self.values.len() - 1);
        self.values.len() - 1
    }

    fn add_face(&mut self, s: i64, chart: [(i64, i64); 3], value: &mut dyn FnMut() -> f64) {
        let k = self.valence;
        let ids = chart.map(|(a, b)| self.vertex(name(k, s, a, b), &mut || Some(value())));
        self.faces.push((ids, s, chart));
    }

    /// One step of the modified butterfly.
    pub fn subdivide(&self) -> FanMesh {
        let k = self.valence;
        // Edge (min, max) -> the third corners of its faces.
        let mut opposite: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (ids, _, _) in &self.faces {
            for e in 0..3 {
                let (p, q, o) = (ids[e], ids[(e + 1) % 3], ids[(e + 2) % 3]);
                opposite.entry((p.min(q), p.max(q))).or_default().push(o);
            }
        }
        let across = |p: usize, q: usize, not: usize| -> Option<usize> {
            opposite
                .get(&(p.min(q), p.max(q)))?
                .iter()
                .copied()
                .find(|&o| o != not)
        };
        let centre = self.by_name[&(0, 0, 0)];
        let weights = zss_weights(k);
        let edge_value = |p: usize, q: usize| -> Option<f64> {
            let val = |v: usize| self.values[v];
            if k != 6 && (p == centre || q == centre) {
                let other = if p == centre { q } else { p };
                let (s, _, _) = *self.by_name.iter().find(|(_, &v)| v == other)?.0;
                let mut sum = 0.75 * val(centre)?;
                for (j, w) in weights.iter().enumerate() {
                    let e = self.by_name[&((s + j as u32) % k, 1, 0)];
                    sum += w * val(e)?;
                }
                return Some(sum);
            }
            let ops = opposite.get(&(p.min(q), p.max(q)))?;
            if ops.len() != 2 {
                return None;
            }
            let mut sum = 0.5 * (val(p)? + val(q)?) + 0.125 * (val(ops[0])? + val(ops[1])?);
            for &o in ops {
                for (x, y) in [(p, o), (q, o)] {
                    let third = if x == p { q } else { p };
                    sum -= val(across(x, y, third)?)? / 16.0;
                }
            }
            Some(sum)
        };
        let mut fine = FanMesh {
            valence: k,
            values: Vec::new(),
            by_name: HashMap::new(),
            faces: Vec::new(),
        };
        for (ids, s, chart) in &self.faces {
            let doubled = chart.map(|(a, b)| (2 * a, 2 * b));
            let corner: Vec<usize> = (0..3)
                .map(|c| {
                    let (a, b) = doubled[c];
                    fine.vertex(name(k, *s, a, b), &mut || self.values[ids[c]])
                })
                .collect();
            let mid: Vec<usize> = (0..3)
                .map(|e| {
                    let (c, d) = (e, (e + 1) % 3);
                    let (a, b) = (chart[c].0 + chart[d].0, chart[c].1 + chart[d].1);
                    fine.vertex(name(k, *s, a, b), &mut || edge_value(ids[c], ids[d]))
                })
                .collect();
            let m = |x: usize| {
                (
                    mid[x],
                    (
                        chart[x].0 + chart[(x + 1) % 3].0,
                        chart[x].1 + chart[(x + 1) % 3].1,
                    ),
                )
            };
            let c = |x: usize| (corner[x], doubled[x]);
            for tri in [
                [c(0), m(0), m(2)],
                [m(0), c(1), m(1)],
                [m(2), m(1), c(2)],
                [m(0), m(1), m(2)],
            ] {
                fine.faces.push((tri.map(|t| t.0), *s, tri.map(|t| t.1)));
            }
        }
        fine
    }
}
