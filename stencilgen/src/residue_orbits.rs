//! The block structure of the scaling-relation system: orbits of `r -> 2r (mod n)`.
//!
//! The scaling relation (Schaefer–Warren eq. (3)) writes `phi(k/n)` through `phi((2k - i n)/n)`:
//! an unknown with numerator residue `r = k mod n` depends only on unknowns of residue
//! `2r mod n`, and a partition-of-unity equation at `x = k/n` involves only residue `r`.
//! Under the map `f(r) = 2r mod n`, the residues `0..n` form a functional graph: each
//! connected component (an *orbit*) is one cycle with trees hanging off it. The cycle's
//! equations close on themselves and need a real solve; a tree residue `r` is then given
//! explicitly by the values at `f(r)`, nearer the cycle.

/// One connected component of the residue graph `r -> 2r (mod n)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResidueOrbit {
    /// The cycle, in map order: `cycle[j + 1] = 2 cycle[j] mod n` (cyclically).
    pub cycle: Vec<u32>,
    /// The other residues of the component, each after the residue `2r mod n` it depends on.
    pub tree: Vec<u32>,
}

/// All orbits of `r -> 2r (mod n)` on `0..n`, ordered by their smallest cycle residue.
pub fn residue_orbits(n: u32) -> Vec<ResidueOrbit> {
    let n_us = n as usize;
    let double = |r: u32| ((2 * u64::from(r)) % u64::from(n)) as u32;
    // Walk from every residue, stamping what the walk visits; a walk that runs into its own
    // stamp has closed a cycle not seen before.
    let mut on_cycle = vec![false; n_us];
    let mut stamp = vec![u32::MAX; n_us];
    for start in 0..n {
        let mut r = start;
        while stamp[r as usize] == u32::MAX {
            stamp[r as usize] = start;
            r = double(r);
        }
        if stamp[r as usize] == start {
            // This walk closed a new cycle at r.
            let mut c = r;
            loop {
                on_cycle[c as usize] = true;
                c = double(c);
                if c == r {
                    break;
                }
            }
        }
    }
    // Distance to the cycle and the cycle each residue drains into.
    let mut depth = vec![u32::MAX; n_us];
    let mut root = vec![u32::MAX; n_us];
    let mut orbits: Vec<ResidueOrbit> = Vec::new();
    for r in 0..n {
        if on_cycle[r as usize] && root[r as usize] == u32::MAX {
            let index = orbits.len() as u32;
            let mut cycle = Vec::new();
            let mut c = r;
            loop {
                cycle.push(c);
                root[c as usize] = index;
                depth[c as usize] = 0;
                c = double(c);
                if c == r {
                    break;
                }
            }
            orbits.push(ResidueOrbit {
                cycle,
                tree: Vec::new(),
            });
        }
    }
    fn resolve(r: u32, double: &dyn Fn(u32) -> u32, depth: &mut [u32], root: &mut [u32]) {
        let mut path = Vec::new();
        let mut c = r;
        while depth[c as usize] == u32::MAX {
            path.push(c);
            c = double(c);
        }
        for &p in path.iter().rev() {
            let next = double(p) as usize;
            depth[p as usize] = depth[next] + 1;
            root[p as usize] = root[next];
        }
    }
    for r in 0..n {
        resolve(r, &double, &mut depth, &mut root);
    }
    let mut tree_residues: Vec<u32> = (0..n).filter(|&r| depth[r as usize] > 0).collect();
    tree_residues.sort_by_key(|&r| (depth[r as usize], r));
    for r in tree_residues {
        orbits[root[r as usize] as usize].tree.push(r);
    }
    orbits
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn n3_has_the_fixed_point_and_one_two_cycle() {
        let orbits = residue_orbits(3);
        assert_eq!(
            orbits,
            vec![
                ResidueOrbit {
                    cycle: vec![0],
                    tree: vec![]
                },
                ResidueOrbit {
                    cycle: vec![1, 2],
                    tree: vec![]
                },
            ]
        );
    }

    #[test]
    fn powers_of_two_drain_into_zero() {
        let orbits = residue_orbits(8);
        assert_eq!(orbits.len(), 1);
        assert_eq!(orbits[0].cycle, vec![0]);
        assert_eq!(orbits[0].tree, vec![4, 2, 6, 1, 3, 5, 7]);
    }

    #[test]
    fn every_residue_once_and_trees_after_their_images() {
        for n in 1..=64u32 {
            let orbits = residue_orbits(n);
            let mut seen = vec![false; n as usize];
            for orbit in &orbits {
                let mut known: Vec<u32> = orbit.cycle.clone();
                for (j, &r) in orbit.cycle.iter().enumerate() {
                    let next = orbit.cycle[(j + 1) % orbit.cycle.len()];
                    assert_eq!(2 * r % n, next, "n = {n}");
                }
                for &r in &orbit.tree {
                    assert!(known.contains(&(2 * r % n)), "n = {n}, r = {r}");
                    known.push(r);
                }
                for r in known {
                    assert!(!seen[r as usize], "n = {n}, r = {r} twice");
                    seen[r as usize] = true;
                }
            }
            assert!(seen.iter().all(|&s| s), "n = {n}");
        }
    }
}
