//! A molecule: its atoms and the bonds between them, positions in bohr.

use glam::DVec3;

pub use super::atom::{Atom, Bond};
use super::bonds::infer_bonds;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Molecule {
    pub atoms: Vec<Atom>,
    pub bonds: Vec<Bond>,
}

impl Molecule {
    /// Builds a molecule and infers its bonds from covalent radii.
    pub fn new(atoms: Vec<Atom>) -> Self {
        let bonds = infer_bonds(&atoms);
        Self { atoms, bonds }
    }

    /// Axis-aligned bounds of the atom centres, `None` when there are no atoms.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let mut it = self.atoms.iter().map(|a| a.position);
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Empirical formula in Hill order (C, H, then alphabetical), ghosts left out.
    pub fn formula(&self) -> String {
        let mut counts = std::collections::BTreeMap::<&str, usize>::new();
        for a in self.atoms.iter().filter(|a| !a.ghost && a.z > 0) {
            *counts.entry(a.element().symbol).or_default() += 1;
        }
        let mut out = String::new();
        let mut push = |sym: &str, n: usize| {
            out.push_str(sym);
            if n > 1 {
                out.push_str(&n.to_string());
            }
        };
        if let Some(c) = counts.remove("C") {
            push("C", c);
            if let Some(h) = counts.remove("H") {
                push("H", h);
            }
        }
        for (sym, n) in counts {
            push(sym, n);
        }
        out
    }
}
