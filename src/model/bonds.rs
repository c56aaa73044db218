//! Bond perception from covalent radii, O(n) with a uniform spatial hash.

use std::collections::HashMap;

use glam::DVec3;

use super::molecule::{Atom, Bond};
use super::units::BOHR_PER_ANGSTROM;

/// Two atoms bond when their distance is below the sum of covalent radii plus this (Å),
/// the tolerance Jmol and Open Babel use.
const BOND_TOLERANCE_ANG: f64 = 0.45;
/// Closer than this (Å) is an overlap, not a bond.
const MIN_BOND_ANG: f64 = 0.1;
/// A cell as wide as the longest bond holds a few dozen real atoms; more means a degenerate
/// structure (atoms piled on one spot), whose pairs are not searched so that a hostile file
/// cannot make bond perception quadratic.
const MAX_ATOMS_PER_CELL: usize = 256;

/// Bonds between non-ghost atoms, each pair once with `a < b`, sorted.
pub fn infer_bonds(atoms: &[Atom]) -> Vec<Bond> {
    let max_radius = atoms.iter().filter(|a| !a.ghost).map(|a| a.element().covalent_radius as f64).fold(0.0, f64::max);
    // A cell as wide as the longest possible bond: neighbours lie in the 27 cells around.
    let cell = ((2.0 * max_radius + BOND_TOLERANCE_ANG) * BOHR_PER_ANGSTROM).max(1e-3);
    let key = |p: DVec3| {
        let c = (p / cell).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    };
    let mut cells: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    for (i, a) in atoms.iter().enumerate() {
        if !a.ghost && a.position.is_finite() {
            cells.entry(key(a.position)).or_default().push(i as u32);
        }
    }
    let mut bonds = Vec::new();
    for (i, a) in atoms.iter().enumerate() {
        if a.ghost || !a.position.is_finite() {
            continue;
        }
        let (cx, cy, cz) = key(a.position);
        let ra = a.element().covalent_radius as f64;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    // Saturating: a far-away atom's cell index sits at the i64 limit.
                    let neighbour = (cx.saturating_add(dx), cy.saturating_add(dy), cz.saturating_add(dz));
                    let Some(list) = cells.get(&neighbour) else {
                        continue;
                    };
                    if list.len() > MAX_ATOMS_PER_CELL {
                        continue;
                    }
                    for &j in list.iter().filter(|&&j| j as usize > i) {
                        let b = &atoms[j as usize];
                        let rb = b.element().covalent_radius as f64;
                        let d = a.position.distance(b.position) / BOHR_PER_ANGSTROM;
                        if d > MIN_BOND_ANG && d < ra + rb + BOND_TOLERANCE_ANG {
                            bonds.push(Bond { a: i as u32, b: j });
                        }
                    }
                }
            }
        }
    }
    bonds.sort_unstable_by_key(|b| (b.a, b.b));
    bonds
}

#[cfg(test)]
mod tests {
    use super::*;

    fn atom(z: u32, x: f64, y: f64, zz: f64) -> Atom {
        Atom { z, charge: z as f64, position: DVec3::new(x, y, zz) * BOHR_PER_ANGSTROM, ghost: false }
    }

    #[test]
    fn water_has_two_bonds() {
        let atoms = vec![atom(8, 0.0, 0.0, 0.0), atom(1, 0.757, 0.586, 0.0), atom(1, -0.757, 0.586, 0.0)];
        let bonds = infer_bonds(&atoms);
        assert_eq!(bonds, vec![Bond { a: 0, b: 1 }, Bond { a: 0, b: 2 }]);
    }

    #[test]
    fn ghosts_and_distant_atoms_do_not_bond() {
        let mut atoms = vec![atom(6, 0.0, 0.0, 0.0), atom(6, 1.54, 0.0, 0.0), atom(6, 5.0, 0.0, 0.0)];
        assert_eq!(infer_bonds(&atoms).len(), 1);
        atoms[1].ghost = true;
        assert!(infer_bonds(&atoms).is_empty());
    }

    #[test]
    fn piled_up_atoms_stay_linear() {
        let atoms: Vec<Atom> = (0..20_000).map(|_| atom(6, 1.0, 1.0, 1.0)).collect();
        assert!(infer_bonds(&atoms).is_empty());
    }

    #[test]
    fn grid_search_matches_all_pairs() {
        // A pseudo-random cloud of carbons: the spatial hash must find exactly the brute-force pairs.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let atoms: Vec<Atom> = (0..400).map(|_| atom(6, rnd() * 15.0 - 7.0, rnd() * 15.0, rnd() * 15.0)).collect();
        let fast = infer_bonds(&atoms);
        let mut slow = Vec::new();
        for i in 0..atoms.len() {
            for j in i + 1..atoms.len() {
                let d = atoms[i].position.distance(atoms[j].position) / BOHR_PER_ANGSTROM;
                if d > MIN_BOND_ANG && d < 0.76 * 2.0 + BOND_TOLERANCE_ANG {
                    slow.push(Bond { a: i as u32, b: j as u32 });
                }
            }
        }
        assert!(!slow.is_empty());
        assert_eq!(fast, slow);
    }
}
