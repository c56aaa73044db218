//! ORCA's JSON wavefunctions, as `orca_2json NAME` writes them from a `.gbw` (ORCA 5 and 6).
//!
//! ```text
//! "Molecule": {
//!   "Atoms": [ { "ElementLabel", "ElementNumber", "NuclearCharge", "Idx", "Coords": [x, y, z],
//!                "Basis" (ORCA 6; "BasisFunctions" in ORCA 5):
//!                  [ { "Shell": "s"|"p"|"d"|…, "Exponents": […], "Coefficients": […] }, … ] } ],
//!   "CoordinateUnits": "Bohrs" (ORCA 5) | "Angs" (ORCA 6.1),
//!   "HFTyp": "RHF" | "UHF" | "ROHF" | …, "Charge", "Multiplicity", "BaseName",
//!   "MolecularOrbitals": { "EnergyUnit": "Eh", "OrbitalLabels": ["0O   1s", …],
//!     "MOs": [ { "MOCoefficients": [one per basis function], "OrbitalEnergy", "Occupancy",
//!                "OrbitalSymLabel" (ORCA 6) }, … ] } }
//! "ORCA Header": { "Version": "5.0 - current" | "6.1.x", … }
//! ```
//! Measured on real files (pysisyphus' wf_library and test data, ORCA 5; OPI's test fixture,
//! ORCA 6.1) against the overlap matrix the files carry: every function is pure (p too) and
//! unit-normalised, in ORCA's order m = 0, +1, −1, +2, −2, … (p: z, x, y), with the sign of the
//! m = ±3 and ±4 functions of f, g and h opposite to the real solid harmonics' (as in ORCA's
//! Molden files and printed orbitals, [`super::wavefunction::orca_flipped`]); contraction
//! coefficients multiply normalised primitives. A UHF file lists the alpha orbitals, then the beta
//! ones (twice as many entries as functions).

use super::ParseError;
use super::json_wfn::Node;
use super::molden::MAX_MO_VALUES;
use super::wavefunction::{OverlapFn, orca_flipped, wavefunction_document};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Atom, Document};

/// Shell letters by l, as ORCA writes them.
const LETTERS: &str = "spdfgh";

/// Reads the document of an `orca_2json` file's tree.
pub(super) fn read(root: Node, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let file = root.file;
    let molecule = root.get("Molecule", "ORCA's molecule: atoms, basis and orbitals")?;
    let units = molecule.get("CoordinateUnits", "\"Bohrs\" or \"Angs\": the coordinates' unit")?;
    let scale = match units.str()?.to_ascii_lowercase().as_str() {
        "bohrs" | "bohr" => 1.0,
        "angs" | "angstrom" => BOHR_PER_ANGSTROM,
        _ => return Err(units.error("\"Bohrs\" or \"Angs\"")),
    };
    let mut atoms = Vec::new();
    let mut shells = Vec::new();
    // For each of the file's functions, its index in the model's order and its sign.
    let mut file_to_model = Vec::new();
    let mut signs = Vec::new();
    let atoms_node = molecule.get("Atoms", "the atoms")?;
    let atom_nodes = atoms_node.items("atoms")?;
    if atom_nodes.is_empty() {
        return Err(atoms_node.error("at least one atom"));
    }
    for (a, node) in atom_nodes.iter().enumerate() {
        let atom = read_atom(node, scale)?;
        let basis = match node.opt("Basis") {
            Some(b) => b,
            None => node.get("BasisFunctions", "the atom's shells (\"Basis\" in ORCA 6)")?,
        };
        for s in basis.items("shells")? {
            let letter = s.get("Shell", "the shell's letter s, p, d, f, g or h")?;
            let l = letter
                .str()
                .ok()
                .and_then(|t| LETTERS.find(&t.to_ascii_lowercase()).filter(|_| t.len() == 1))
                .map(|l| l as u32)
                .filter(|&l| l <= MAX_L)
                .ok_or_else(|| letter.error("a shell letter s, p, d, f, g or h"))?;
            let exponents = s.get("Exponents", "the primitives' exponents")?;
            let exps = exponents.reals(false, false)?;
            let coefficients = s.get("Coefficients", "the contraction coefficients")?;
            let coefs = coefficients.reals(false, false)?;
            if exps.is_empty() || exps.iter().any(|&e| e <= 0.0) {
                return Err(exponents.error("positive exponents, at least one"));
            }
            if coefs.len() != exps.len() {
                return Err(coefficients.error(format!("{} coefficients, one per exponent", exps.len())));
            }
            let kind = if l < 2 { ShellKind::Cartesian } else { ShellKind::Pure };
            let shell = Shell { atom: a, center: atom.position, l, kind, exponents: exps, coefficients: coefs };
            let first = file_to_model.len();
            let n = shell.n_functions();
            if l == 1 {
                // z, x, y → x, y, z.
                file_to_model.extend([first + 2, first, first + 1]);
            } else {
                file_to_model.extend(first..first + n);
            }
            let flipped = if kind == ShellKind::Pure { orca_flipped(l) } else { 0..0 };
            signs.extend((0..n).map(|k| if flipped.contains(&k) { -1.0 } else { 1.0 }));
            shells.push(shell);
        }
        atoms.push(atom);
    }
    let n = file_to_model.len();
    if n == 0 {
        return Err(atoms_node.error("atoms with at least one shell of basis functions"));
    }
    if (n as u64).saturating_mul(n as u64) > MAX_MO_VALUES {
        return Err(molecule
            .get("Atoms", "")?
            .error(format!("a basis of at most {} functions", (MAX_MO_VALUES as f64).sqrt())));
    }
    let mos = molecule.get("MolecularOrbitals", "the orbitals")?;
    if let Some(unit) = mos.opt("EnergyUnit")
        && unit.str()? != "Eh"
    {
        return Err(unit.error("\"Eh\" (hartree)"));
    }
    let list = mos.get("MOs", "the orbitals, each with MOCoefficients, OrbitalEnergy and Occupancy")?;
    let items = list.items("orbitals")?;
    if (items.len() as u64).saturating_mul(n as u64) > MAX_MO_VALUES {
        return Err(list.error(format!("at most {MAX_MO_VALUES} orbital coefficients ({n} functions each)")));
    }
    let hf = molecule.opt("HFTyp").map(|h| h.str()).transpose()?.unwrap_or("");
    let unrestricted = hf.eq_ignore_ascii_case("UHF");
    if items.is_empty() || (unrestricted && items.len() % 2 != 0) {
        let expected =
            if unrestricted { "the alpha and then the beta orbitals (UHF): an even number" } else { "orbitals" };
        return Err(list.error(expected));
    }
    let half = items.len() / 2;
    let mut orbitals = Vec::with_capacity(items.len());
    for (k, mo) in items.iter().enumerate() {
        let c = mo.get("MOCoefficients", "the orbital's coefficients")?;
        let values = c.reals(false, false)?;
        if values.len() != n {
            return Err(c.error(format!("{n} coefficients (the basis set's functions)")));
        }
        let mut coefficients = vec![0.0; n];
        for ((&v, &to), &sign) in values.iter().zip(&file_to_model).zip(&signs) {
            coefficients[to] = sign * v;
        }
        let energy = mo.get("OrbitalEnergy", "the orbital's energy (hartree)")?.real(false)?;
        let occupation = mo.get("Occupancy", "the orbital's occupation")?;
        let limit = if unrestricted { 1.0 } else { 2.0 };
        let occ = occupation.real(false)?;
        if !(-1e-9..=limit + 1e-9).contains(&occ) {
            return Err(occupation.error(format!("an occupation 0..={limit}")));
        }
        let symmetry = match mo.opt("OrbitalSymLabel") {
            Some(s) => s.str()?.to_string(),
            None => String::new(),
        };
        let spin = if unrestricted && k >= half { Spin::Beta } else { Spin::Alpha };
        orbitals.push(MolecularOrbital { energy, occupation: occ, spin, symmetry, coefficients });
    }
    // ORCA labels every orbital of a calculation without symmetry "A": one label for all names
    // nothing.
    if orbitals.iter().all(|o| o.symmetry == orbitals[0].symmetry) {
        orbitals.iter_mut().for_each(|o| o.symmetry.clear());
    }
    let wf = Wavefunction {
        basis: Basis { shells },
        orbitals,
        restricted: !unrestricted,
        normalization: Default::default(),
        excited: None,
    };
    let title = match molecule.opt("BaseName") {
        Some(b) => b.str()?.to_string(),
        None => String::new(),
    };
    let version = root.opt("ORCA Header").and_then(|h| h.opt("Version")).and_then(|v| v.str().ok().map(str::to_string));
    let program = match version {
        Some(v) => format!("ORCA {v}"),
        None => "ORCA".to_string(),
    };
    Ok(wavefunction_document(file, &title, atoms, wf, Some(&program), overlap))
}

/// One atom: its element (by number, else by label), nuclear charge and position (bohr).
fn read_atom(node: &Node, scale: f64) -> Result<Atom, ParseError> {
    let z = match node.opt("ElementNumber") {
        Some(n) => n.integer(0..=super::MAX_Z as i64)? as u32,
        None => {
            let label = node.get("ElementLabel", "the element (or ElementNumber)")?;
            let text = label.str()?;
            match text.trim() {
                "X" | "Q" | "DA" => 0,
                t => atomic_number(t).ok_or_else(|| label.error("an element symbol"))?,
            }
        }
    };
    let charge = match node.opt("NuclearCharge") {
        Some(c) => c.real(false)?,
        None => z as f64,
    };
    let coords = node.get("Coords", "the atom's x, y, z")?;
    let xyz = coords.reals(false, false)?;
    if xyz.len() != 3 {
        return Err(coords.error("three coordinates x, y, z"));
    }
    let position = glam::DVec3::new(xyz[0], xyz[1], xyz[2]) * scale;
    // A ghost atom (ORCA's `H:`) keeps its element and loses its nuclear charge.
    Ok(Atom { z, charge, position, ghost: z == 0 || charge == 0.0 })
}
