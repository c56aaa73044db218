//! What a macromolecular file (PDB, mmCIF) or a multi-frame XYZ says about its atoms beyond
//! element and position: names, residues, chains, alternate locations, occupancies, B-factors
//! and models (or frames). Kept as arrays, one entry per atom of every model, so a million
//! atoms cost no heap object each; residues and chains are ranges of atoms.

use std::ops::Range;

use glam::DVec3;

use super::bonds::bonds_where;
use super::molecule::{Atom, Molecule};

/// A short name stored inline, padded with zeros (atom, residue and chain names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Label<const N: usize>(pub [u8; N]);

impl<const N: usize> Label<N> {
    /// `None` when `s` (trimmed) is longer than `N` bytes.
    pub fn new(s: &str) -> Option<Self> {
        let s = s.trim().as_bytes();
        (s.len() <= N).then(|| {
            let mut b = [0; N];
            b[..s.len()].copy_from_slice(s);
            Self(b)
        })
    }

    pub fn as_str(&self) -> &str {
        let n = self.0.iter().position(|&b| b == 0).unwrap_or(N);
        std::str::from_utf8(&self.0[..n]).unwrap_or("?")
    }
}

impl<const N: usize> Default for Label<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

impl<const N: usize> std::fmt::Display for Label<N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

pub type AtomName = Label<4>;
/// Chemical component ids have up to five characters since 2023.
pub type ResidueName = Label<5>;
pub type ChainName = Label<8>;

/// Secondary structure a file declares for a residue (HELIX/SHEET, `_struct_conf`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Secondary {
    #[default]
    None,
    Helix,
    Sheet,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Residue {
    pub name: ResidueName,
    /// Author residue number (PDB resSeq, mmCIF auth_seq_id).
    pub number: i32,
    /// Insertion code, 0 when none.
    pub insertion: u8,
    pub chain: u32,
    /// Every atom was a HETATM record.
    pub hetero: bool,
    pub secondary: Secondary,
    pub atoms: Range<u32>,
}

impl Residue {
    /// "ALA 42", "ALA 42A".
    pub fn label(&self) -> String {
        let ins = if self.insertion == 0 { String::new() } else { (self.insertion as char).to_string() };
        format!("{} {}{ins}", self.name, self.number)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    pub name: ChainName,
    pub model: u32,
    pub residues: Range<u32>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct StructureModel {
    /// The number the file gives (MODEL n, `pdbx_PDB_model_num`; frames count from 1).
    pub number: i32,
    pub atoms: Range<u32>,
    /// A frame's own title (an XYZ comment line), if any.
    pub title: String,
    /// The frame's energy in hartree, where the file gives one (a program log's steps).
    pub energy: Option<f64>,
}

/// Per-atom annotations of every model, in file order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Structure {
    pub z: Vec<u8>,
    pub position: Vec<DVec3>,
    pub name: Vec<AtomName>,
    /// Alternate location indicator, 0 when none.
    pub altloc: Vec<u8>,
    pub occupancy: Vec<f32>,
    pub b_factor: Vec<f32>,
    /// Serial number as written (PDB serial, mmCIF id); -1 when it has none.
    pub serial: Vec<i32>,
    pub residue: Vec<u32>,
    pub residues: Vec<Residue>,
    pub chains: Vec<Chain>,
    pub models: Vec<StructureModel>,
    /// Bonds the file states (CONECT, `struct_conn`), as atom indices into these arrays.
    pub explicit_bonds: Vec<(u32, u32)>,
}

/// One atom as a reader finds it.
#[derive(Debug, Clone, Copy)]
pub struct AtomRecord {
    pub chain: ChainName,
    pub residue: ResidueName,
    pub number: i32,
    pub insertion: u8,
    pub hetero: bool,
    pub name: AtomName,
    pub altloc: u8,
    pub z: u8,
    pub position: DVec3,
    pub occupancy: f32,
    pub b_factor: f32,
    pub serial: i32,
}

impl Structure {
    pub fn len(&self) -> usize {
        self.z.len()
    }

    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// Each model's positions (bohr), for the models of exactly `atoms` atoms: the frames of a
    /// trajectory, as a scan's path or a computation reads them.
    pub fn model_positions(&self, atoms: usize) -> Vec<Vec<DVec3>> {
        (self.models.iter())
            .map(|m| self.position[m.atoms.start as usize..m.atoms.end as usize].to_vec())
            .filter(|p| p.len() == atoms)
            .collect()
    }

    pub fn with_capacity(n: usize) -> Self {
        Self {
            z: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            name: Vec::with_capacity(n),
            altloc: Vec::with_capacity(n),
            occupancy: Vec::with_capacity(n),
            b_factor: Vec::with_capacity(n),
            serial: Vec::with_capacity(n),
            residue: Vec::with_capacity(n),
            ..Self::default()
        }
    }

    /// Starts a model (MODEL n, an XYZ frame); atoms pushed before any model form model 1.
    pub fn begin_model(&mut self, number: i32, title: String) {
        let at = self.z.len() as u32;
        self.models.push(StructureModel { number, atoms: at..at, title, energy: None });
    }

    /// Appends an atom to the last model; a new chain or residue starts where the record's
    /// differs from the previous atom's.
    pub fn push(&mut self, a: &AtomRecord) {
        let index = self.z.len() as u32;
        if self.models.is_empty() {
            self.begin_model(1, String::new());
        }
        let model = self.models.len() as u32 - 1;
        let new_chain = self.chains.last().is_none_or(|c| c.name != a.chain || c.model != model);
        if new_chain {
            let at = self.residues.len() as u32;
            self.chains.push(Chain { name: a.chain, model, residues: at..at });
        }
        let new_residue = new_chain
            || self
                .residues
                .last()
                .is_none_or(|r| r.number != a.number || r.insertion != a.insertion || r.name != a.residue);
        if new_residue {
            self.residues.push(Residue {
                name: a.residue,
                number: a.number,
                insertion: a.insertion,
                chain: self.chains.len() as u32 - 1,
                hetero: a.hetero,
                secondary: Secondary::None,
                atoms: index..index,
            });
        }
        let residue = self.residues.len() - 1;
        let r = &mut self.residues[residue];
        r.atoms.end = index + 1;
        r.hetero &= a.hetero;
        if let Some(c) = self.chains.last_mut() {
            c.residues.end = residue as u32 + 1;
        }
        if let Some(m) = self.models.last_mut() {
            m.atoms.end = index + 1;
        }
        self.z.push(a.z);
        self.position.push(a.position);
        self.name.push(a.name);
        self.altloc.push(a.altloc);
        self.occupancy.push(a.occupancy);
        self.b_factor.push(a.b_factor);
        self.serial.push(a.serial);
        self.residue.push(residue as u32);
    }

    /// The atoms of `model` a viewer shows: in each residue, atoms without an alternate
    /// location and those of the first one the residue names (all altlocs stay in the arrays).
    /// An atom written with no alternate location beside the same atom with one (a writer's
    /// slip for the first conformer: blank and `B`) is one site: the blank one is shown, never
    /// both.
    pub fn shown_atoms(&self, model: usize) -> Vec<u32> {
        let Some(m) = self.models.get(model) else { return Vec::new() };
        let mut out = Vec::with_capacity(m.atoms.len());
        let mut residue = u32::MAX;
        let mut first_alt = 0u8;
        let mut blank_names = Vec::new();
        for i in m.atoms.clone() {
            let r = self.residue[i as usize];
            if r != residue {
                residue = r;
                let atoms = self.residues[r as usize].atoms.clone();
                blank_names =
                    atoms.clone().filter(|&j| self.altloc[j as usize] == 0).map(|j| self.name[j as usize]).collect();
                let partner = |j: u32| blank_names.contains(&self.name[j as usize]);
                first_alt =
                    atoms.filter(|&j| !partner(j)).map(|j| self.altloc[j as usize]).find(|&a| a != 0).unwrap_or(0);
            }
            let alt = self.altloc[i as usize];
            if alt == 0 || (alt == first_alt && !blank_names.contains(&self.name[i as usize])) {
                out.push(i);
            }
        }
        out
    }

    /// The molecule of the atoms `shown` (indices into these arrays): bonds from distances
    /// within residues, polymer links (peptide C–N, nucleic O3′–P, disulfide SG–SG) between
    /// residues, and the bonds the file states.
    pub fn molecule(&self, shown: &[u32]) -> Molecule {
        let atoms: Vec<Atom> = shown
            .iter()
            .map(|&i| {
                let z = self.z[i as usize] as u32;
                Atom { z, charge: z as f64, position: self.position[i as usize], ghost: false }
            })
            .collect();
        let linked = |i: usize, j: usize| {
            let (a, b) = (shown[i] as usize, shown[j] as usize);
            let (ra, rb) = (self.residue[a], self.residue[b]);
            ra == rb || self.polymer_link(a, b)
        };
        let mut bonds = bonds_where(&atoms, linked);
        if !self.explicit_bonds.is_empty() {
            let mut at = std::collections::HashMap::with_capacity(self.explicit_bonds.len() * 2);
            let wanted: std::collections::HashSet<u32> =
                self.explicit_bonds.iter().flat_map(|&(a, b)| [a, b]).collect();
            for (k, &i) in shown.iter().enumerate() {
                if wanted.contains(&i) {
                    at.insert(i, k as u32);
                }
            }
            for &(a, b) in &self.explicit_bonds {
                if let (Some(&x), Some(&y)) = (at.get(&a), at.get(&b))
                    && x != y
                {
                    bonds.push(super::Bond { a: x.min(y), b: x.max(y) });
                }
            }
            bonds.sort_unstable_by_key(|b| (b.a, b.b));
            bonds.dedup();
        }
        Molecule { atoms, bonds }
    }

    /// Atoms `a` and `b` of different residues that polymers link: C–N of consecutive
    /// residues, O3′–P of consecutive nucleotides, SG–SG of two cysteines.
    fn polymer_link(&self, a: usize, b: usize) -> bool {
        let (na, nb) = (self.name[a].as_str(), self.name[b].as_str());
        let pair = |x: &str, y: &str| (na == x && nb == y) || (na == y && nb == x);
        if pair("SG", "SG") {
            return true;
        }
        let (ra, rb) = (self.residue[a] as usize, self.residue[b] as usize);
        let consecutive = ra.abs_diff(rb) == 1 && self.residues[ra].chain == self.residues[rb].chain;
        consecutive && (pair("C", "N") || pair("O3'", "P") || pair("O3*", "P"))
    }

    /// "A ALA 42 CA" for an atom index into these arrays, with its alternate location.
    pub fn describe(&self, i: usize) -> String {
        let r = &self.residues[self.residue[i] as usize];
        let chain = &self.chains[r.chain as usize];
        let alt = match self.altloc[i] {
            0 => String::new(),
            a => format!(" alt {}", a as char),
        };
        format!("{} {} {}{alt}", chain.name, r.label(), self.name[i]).trim().to_string()
    }

    /// Marks the residues of `chain` from `first` to `last` (number, insertion code) inclusive.
    pub fn mark_secondary(&mut self, chain: &str, first: (i32, u8), last: (i32, u8), kind: Secondary) {
        for c in self.chains.iter().filter(|c| c.name.as_str() == chain) {
            let mut inside = false;
            for r in &mut self.residues[c.residues.start as usize..c.residues.end as usize] {
                let key = (r.number, r.insertion);
                inside |= key == first;
                if inside {
                    r.secondary = kind;
                }
                if key == last {
                    inside = false;
                }
            }
        }
    }
}

/// An atom named the way LINK records and `struct_conn` rows name it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NamedAtom {
    pub chain: ChainName,
    pub number: i32,
    pub insertion: u8,
    pub name: AtomName,
    /// 0: any alternate location.
    pub altloc: u8,
}

impl Structure {
    /// Adds the bonds between named atoms of the first model (LINK, `struct_conn`); a pair
    /// naming an atom the file lacks is left out. Returns how many were left out.
    pub fn add_named_bonds(&mut self, pairs: &[(NamedAtom, NamedAtom)]) -> usize {
        let Some(first) = self.models.first() else { return pairs.len() };
        let mut residues = std::collections::HashMap::new();
        for (k, r) in self.residues.iter().enumerate() {
            if r.atoms.start >= first.atoms.end {
                break;
            }
            residues.entry((self.chains[r.chain as usize].name, r.number, r.insertion)).or_insert(k);
        }
        let find = |a: &NamedAtom| {
            let r = &self.residues[*residues.get(&(a.chain, a.number, a.insertion))?];
            r.atoms.clone().find(|&i| {
                let i = i as usize;
                self.name[i] == a.name && (a.altloc == 0 || self.altloc[i] == 0 || self.altloc[i] == a.altloc)
            })
        };
        let found: Vec<(u32, u32)> = pairs.iter().filter_map(|(a, b)| Some((find(a)?, find(b)?))).collect();
        let missing = pairs.len() - found.len();
        self.explicit_bonds.extend(found);
        missing
    }
}

/// A structure with the model a viewer shows: `atoms[i]` is the structure atom behind
/// molecule atom `i`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StructureView {
    pub structure: Structure,
    pub model: usize,
    pub atoms: Vec<u32>,
}

impl StructureView {
    /// The first model, and its molecule.
    pub fn new(structure: Structure) -> (Self, Molecule) {
        let mut view = Self { structure, model: 0, atoms: Vec::new() };
        let molecule = view.show(0);
        (view, molecule)
    }

    /// Shows model `model` (clamped to those there are) and returns its molecule.
    pub fn show(&mut self, model: usize) -> Molecule {
        self.model = model.min(self.structure.models.len().saturating_sub(1));
        self.atoms = self.structure.shown_atoms(self.model);
        self.structure.molecule(&self.atoms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::units::BOHR_PER_ANGSTROM;

    fn record(residue: &str, number: i32, name: &str, z: u8, x: f64, altloc: u8) -> AtomRecord {
        AtomRecord {
            chain: Label::new("A").unwrap(),
            residue: Label::new(residue).unwrap(),
            number,
            insertion: 0,
            hetero: false,
            name: Label::new(name).unwrap(),
            altloc,
            z,
            position: DVec3::new(x, 0.0, 0.0) * BOHR_PER_ANGSTROM,
            occupancy: 1.0,
            b_factor: 10.0,
            serial: -1,
        }
    }

    #[test]
    fn residues_chains_and_altlocs() {
        let mut s = Structure::default();
        s.push(&record("GLY", 1, "N", 7, 0.0, 0));
        s.push(&record("GLY", 1, "C", 6, 1.4, 0));
        s.push(&record("SER", 2, "N", 7, 2.7, 0));
        s.push(&record("SER", 2, "OG", 8, 4.0, b'A'));
        s.push(&record("SER", 2, "OG", 8, 4.1, b'B'));
        // A water too close to the serine: not bonded across residues.
        s.push(&record("HOH", 3, "O", 8, 5.0, 0));
        assert_eq!(s.residues.len(), 3);
        assert_eq!(s.chains.len(), 1);
        assert_eq!(s.models.len(), 1);
        let shown = s.shown_atoms(0);
        assert_eq!(shown, vec![0, 1, 2, 3, 5]);
        let m = s.molecule(&shown);
        let pairs: Vec<(u32, u32)> = m.bonds.iter().map(|b| (b.a, b.b)).collect();
        assert_eq!(pairs, vec![(0, 1), (1, 2), (2, 3)], "peptide C–N linked, the water left alone");
        assert_eq!(s.describe(4), "A SER 2 OG alt B");
    }

    #[test]
    fn a_blank_alternate_location_beside_its_b_partner_is_one_site() {
        let mut s = Structure::default();
        s.push(&record("SER", 2, "N", 7, 0.0, 0));
        s.push(&record("SER", 2, "OG", 8, 1.4, 0));
        s.push(&record("SER", 2, "OG", 8, 1.5, b'B'));
        s.push(&record("SER", 2, "CB", 6, 2.8, b'A'));
        s.push(&record("SER", 2, "CB", 6, 2.9, b'B'));
        assert_eq!(s.shown_atoms(0), vec![0, 1, 3], "the blank OG, not its B partner; CB's first conformer");
        assert_eq!(s.z.len(), 5, "every conformer is kept");
    }

    #[test]
    fn labels_refuse_long_names() {
        assert_eq!(AtomName::new(" CA ").unwrap().as_str(), "CA");
        assert!(AtomName::new("ABCDE").is_none());
    }
}
