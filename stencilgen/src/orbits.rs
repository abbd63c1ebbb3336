//! The block structure of a scaling-relation system: orbits of its class map.
//!
//! For a uniform scheme the relation writes `phi(k/n)` through `phi((2k - i n)/n)`: an unknown
//! with numerator residue `r = k mod n` depends only on residue `2r mod n`, and a
//! partition-of-unity equation at `x = k/n` involves only residue `r`. Next to an extraordinary
//! vertex the classes are single grid points and `x` depends on `2x`, or on nothing unknown once
//! `2x` has left the patch. In every case the classes form a functional graph (each class has at
//! most one successor). Each connected component (an *orbit*) ends either in one cycle or in one
//! terminal class, with trees hanging off it; the cycle's equations close on themselves and need
//! a real solve, every other class follows explicitly from its successor.

/// One connected component of a class map.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Orbit {
    /// The cycle in map order (`next(cycle[j]) = cycle[j + 1]`, cyclically); empty when the
    /// component ends in a terminal class instead.
    pub cycle: Vec<u32>,
    /// The other classes, each after the class it maps to (a terminal class comes first).
    pub tree: Vec<u32>,
}

/// The class map of residues mod n under doubling: `r -> 2r mod n`.
pub fn doubling(n: u32) -> Vec<Option<u32>> {
    (0..n)
        .map(|r| Some(((2 * u64::from(r)) % u64::from(n)) as u32))
        .collect()
}

/// All orbits of the class map `next` (`None`: terminal), ordered by their smallest cycle
/// class (cycles first), then by terminal class.
pub fn orbits(next: &[Option<u32>]) -> Vec<Orbit> {
    let count = next.len();
    const UNSEEN: u32 = u32::MAX;
    // Walk from every class, stamping what the walk visits; a walk that runs into its own
    // stamp has closed a cycle not seen before.
    let mut on_cycle = vec![false; count];
    let mut stamp = vec![UNSEEN; count];
    for start in 0..count as u32 {
        let mut r = start;
        loop {
            if stamp[r as usize] != UNSEEN {
                if stamp[r as usize] == start {
                    let mut c = r;
                    loop {
                        on_cycle[c as usize] = true;
                        c = next[c as usize]
                            .unwrap_or_else(|| unreachable!("a cycle has successors"));
                        if c == r {
                            break;
                        }
                    }
                }
                break;
            }
            stamp[r as usize] = start;
            match next[r as usize] {
                Some(s) => r = s,
                None => break,
            }
        }
    }
    // Roots: each cycle (once) and each terminal class.
    let mut root = vec![UNSEEN; count];
    let mut depth = vec![UNSEEN; count];
    let mut result: Vec<Orbit> = Vec::new();
    for r in 0..count as u32 {
        if on_cycle[r as usize] && root[r as usize] == UNSEEN {
            let index = result.len() as u32;
            let mut cycle = Vec::new();
            let mut c = r;
            loop {
                cycle.push(c);
                root[c as usize] = index;
                depth[c as usize] = 0;
                c = next[c as usize].unwrap_or_else(|| unreachable!("a cycle has successors"));
                if c == r {
                    break;
                }
            }
            result.push(Orbit {
                cycle,
                tree: Vec::new(),
            });
        }
    }
    for r in 0..count as u32 {
        if next[r as usize].is_none() {
            root[r as usize] = result.len() as u32;
            depth[r as usize] = 0;
            result.push(Orbit {
                cycle: Vec::new(),
                tree: vec![r],
            });
        }
    }
    for r in 0..count as u32 {
        let mut path = Vec::new();
        let mut c = r;
        while depth[c as usize] == UNSEEN {
            path.push(c);
            c = next[c as usize].unwrap_or_else(|| unreachable!("terminals have depth 0"));
        }
        for &p in path.iter().rev() {
            let s = next[p as usize]
                .unwrap_or_else(|| unreachable!("only terminals lack a successor"))
                as usize;
            depth[p as usize] = depth[s] + 1;
            root[p as usize] = root[s];
        }
    }
    let mut tree: Vec<u32> = (0..count as u32)
        .filter(|&r| depth[r as usize] > 0)
        .collect();
    tree.sort_by_key(|&r| (depth[r as usize], r));
    for r in tree {
        result[root[r as usize] as usize].tree.push(r);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn n3_has_the_fixed_point_and_one_two_cycle() {
        assert_eq!(
            orbits(&doubling(3)),
            vec![
                Orbit {
                    cycle: vec![0],
                    tree: vec![]
                },
                Orbit {
                    cycle: vec![1, 2],
                    tree: vec![]
                },
            ]
        );
    }

    #[test]
    fn powers_of_two_drain_into_zero() {
        let orbits = orbits(&doubling(8));
        assert_eq!(orbits.len(), 1);
        assert_eq!(orbits[0].cycle, vec![0]);
        assert_eq!(orbits[0].tree, vec![4, 2, 6, 1, 3, 5, 7]);
    }

    #[test]
    fn terminal_classes_root_their_trees() {
        // 0 -> 1 -> terminal 2; 3 -> 3.
        let next = [Some(1), Some(2), None, Some(3)];
        assert_eq!(
            orbits(&next),
            vec![
                Orbit {
                    cycle: vec![3],
                    tree: vec![]
                },
                Orbit {
                    cycle: vec![],
                    tree: vec![2, 1, 0]
                },
            ]
        );
    }

    #[test]
    fn every_residue_once_and_trees_after_their_images() {
        for n in 1..=64u32 {
            let next = doubling(n);
            let mut seen = vec![false; n as usize];
            for orbit in orbits(&next) {
                let mut known: Vec<u32> = orbit.cycle.clone();
                for (j, &r) in orbit.cycle.iter().enumerate() {
                    assert_eq!(
                        next[r as usize],
                        Some(orbit.cycle[(j + 1) % orbit.cycle.len()])
                    );
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
