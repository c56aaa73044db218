//! Bond perception from covalent radii, O(n) with a cell search.

use glam::DVec3;

use super::atom::{Atom, Bond};
use super::neighbours::for_each_near_pair;
use super::units::BOHR_PER_ANGSTROM;

/// Two atoms bond when their distance is below the sum of covalent radii plus this (Å),
/// the tolerance Jmol and Open Babel use.
const BOND_TOLERANCE_ANG: f64 = 0.45;
/// Closer than this (Å) is an overlap, not a bond.
const MIN_BOND_ANG: f64 = 0.1;
/// Bonds between non-ghost atoms, each pair once with `a < b`, sorted.
pub fn infer_bonds(atoms: &[Atom]) -> Vec<Bond> {
    bonds_where(atoms, |_, _| true)
}

/// Bonds from covalent radii between the non-ghost atoms `accept` allows (a structure allows
/// pairs within a residue and polymer links between residues), each pair once, sorted.
pub fn bonds_where(atoms: &[Atom], accept: impl Fn(usize, usize) -> bool) -> Vec<Bond> {
    let max_radius = atoms.iter().filter(|a| !a.ghost).map(|a| a.element().covalent_radius as f64).fold(0.0, f64::max);
    // A cell as wide as the longest possible bond: partners lie in the neighbouring cells.
    let cell = ((2.0 * max_radius + BOND_TOLERANCE_ANG) * BOHR_PER_ANGSTROM).max(1e-3);
    let positions: Vec<DVec3> = atoms.iter().map(|a| a.position).collect();
    let mut bonds = Vec::new();
    for_each_near_pair(
        &positions,
        |i| !atoms[i].ghost,
        cell,
        |i, j| {
            let (a, b) = (&atoms[i], &atoms[j]);
            let reach = (a.element().covalent_radius + b.element().covalent_radius) as f64 + BOND_TOLERANCE_ANG;
            let d = a.position.distance(b.position) / BOHR_PER_ANGSTROM;
            if d > MIN_BOND_ANG && d < reach && accept(i, j) {
                bonds.push(Bond { a: i as u32, b: j as u32 });
            }
        },
    );
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
