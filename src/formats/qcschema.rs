//! QCSchema results with a wavefunction: the `AtomicResult` JSON that Psi4 (`psi4 --qcschema`,
//! `psi4.schema_wrapper.run_qcschema`) and QCEngine write when the input asks
//! `protocols: {wavefunction: "all"}` (or `"orbitals_and_eigenvalues"`).
//!
//! ```text
//! { "schema_name": "qcschema_output", "provenance": {"creator": "Psi4", "version": …},
//!   "molecule": { "symbols": [...], "geometry": [x0, y0, z0, x1, …] (bohr),
//!                 "atomic_numbers"?, "real"?, "molecular_charge", "molecular_multiplicity" },
//!   "properties": { "calcinfo_nalpha", "calcinfo_nbeta", … },
//!   "wavefunction": {
//!     "basis": { "center_data": { NAME: { "electron_shells": [ { "angular_momentum": [l] (or
//!                  [0, 1] for an sp shell), "harmonic_type": "spherical"|"cartesian",
//!                  "exponents": [...], "coefficients": [[...], …] } ], "ecp_electrons"? } },
//!                "atom_map": [NAME per atom] },
//!     "restricted": true|false,
//!     "orbitals_a": "scf_orbitals_a", "eigenvalues_a": …, "occupations_a": …  (which fields hold
//!     the result), "scf_orbitals_a": [nao × nmo, row after row], "scf_eigenvalues_a": [nmo],
//!     "scf_occupations_a": [nmo] (electrons per spin), and the same for _b } }
//! ```
//! Numbers in the basis may be strings (the schema's own examples write them so).
//!
//! What real files hold, and where they and the specification part: the specification orders
//! a shell's functions as libint's CCA standard does (pure m = −l … +l, cartesian
//! xx, xy, xz, yy, yz, zz, every cartesian component normalised like x^l) and calls matrices
//! column-major; QCElemental writes the orbitals `[nao][nmo]` row after row, and Psi4 (its
//! `schema_wrapper._convert_wavefunction`) writes its pure functions in the order m = +l … −l (a
//! p shell x, z, y: measured on QCArchive's Psi4 1.10 test results, whose orbitals are
//! orthonormal only so) and its contraction coefficients with the primitives' (x^l)
//! normalisation folded in. The reader therefore tries, in turn, Psi4's reading and the
//! specification's (the one the file's `provenance.creator` names first) and keeps the first
//! whose orbitals are orthonormal, saying so when it is not the writer's.

use super::ParseError;
use super::json_wfn::Node;
use super::molden::MAX_MO_VALUES;
use super::wavefunction::{
    AS_READ_TOLERANCE, OverlapFn, cartesian_norm, normalize_contractions, residual, wavefunction_document,
};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind, cartesian_powers};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::{Atom, Document};

/// How a file's basis functions are to be taken: what the writers do differently.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Reading {
    /// Pure functions in the order m = +l … −l (Psi4) rather than −l … +l (the specification).
    descending: bool,
    /// Coefficients carry the x^l primitive normalisation (Psi4) rather than multiply normalised
    /// primitives (a basis-set library's numbers).
    folded: bool,
}

/// The readings tried, in turn, for a file Psi4 wrote and for any other.
const PSI4_FIRST: [Reading; 4] = [Reading::PSI4, Reading::SPEC, Reading::SPEC_FOLDED, Reading::PSI4_UNFOLDED];
const SPEC_FIRST: [Reading; 4] = [Reading::SPEC, Reading::SPEC_FOLDED, Reading::PSI4, Reading::PSI4_UNFOLDED];

impl Reading {
    const PSI4: Reading = Reading { descending: true, folded: true };
    const PSI4_UNFOLDED: Reading = Reading { descending: true, folded: false };
    const SPEC: Reading = Reading { descending: false, folded: false };
    const SPEC_FOLDED: Reading = Reading { descending: false, folded: true };

    fn describe(self) -> String {
        let order = if self.descending { "m = +l … −l (Psi4's)" } else { "m = −l … +l (the specification's)" };
        let coefficients = if self.folded {
            "coefficients with the primitives' normalisation folded in"
        } else {
            "coefficients of normalised primitives"
        };
        format!("pure functions in the order {order}, {coefficients}")
    }
}

/// A shell as the file writes it.
struct FileShell {
    atom: usize,
    l: u32,
    pure: bool,
    exponents: Vec<f64>,
    coefficients: Vec<f64>,
}

/// The orbitals of one spin as the file writes them: `coefficients[i * nmo + k]` is function
/// `i`'s coefficient in orbital `k`.
struct FileOrbitals {
    nmo: usize,
    coefficients: Vec<f64>,
    energies: Vec<f64>,
    occupations: Vec<f64>,
    spin: Spin,
}

/// Reads the document of a QCSchema result's tree.
pub(super) fn read(root: Node, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let file = root.file;
    let wavefunction = root.opt("wavefunction").ok_or_else(|| ParseError {
        file: file.into(),
        line: 0,
        expected: "a QCSchema result with a \"wavefunction\" (run with protocols: {wavefunction: \"all\"})".into(),
        found: "none: the result holds no orbitals".into(),
    })?;
    let molecule = root.get("molecule", "the molecule: symbols and geometry in bohr")?;
    let (mut atoms, charge, multiplicity) = read_molecule(&molecule)?;
    let basis_node = wavefunction.get("basis", "the basis set: center_data and atom_map")?;
    let (shells, ecp_electrons) = read_basis(&basis_node, atoms.len())?;
    let mut problems = Vec::new();
    let core: i64 = ecp_electrons.iter().sum();
    if core > 0 {
        for (atom, &e) in atoms.iter_mut().zip(&ecp_electrons) {
            atom.charge -= e as f64;
        }
        problems.push(format!(
            "{file}: {core} core electrons are replaced by effective core potentials; the density shown lacks them"
        ));
    }
    let nao: usize = shells.iter().map(|s| if s.pure { 2 * s.l as usize + 1 } else { n_functions(s.l, false) }).sum();
    if nao == 0 {
        return Err(basis_node.error("a basis set of at least one shell"));
    }
    if (nao as u64).saturating_mul(nao as u64) > MAX_MO_VALUES {
        return Err(basis_node.error(format!("a basis of at most {} functions", (MAX_MO_VALUES as f64).sqrt())));
    }
    let restricted = wavefunction.get("restricted", "whether alpha and beta share orbitals")?.bool()?;
    let electrons = atoms.iter().map(|a| a.charge).sum::<f64>() - charge;
    let counts = electron_counts(&root, electrons, multiplicity)?;
    let mut spins = vec![read_orbitals(&wavefunction, "a", nao, counts.0, Spin::Alpha)?];
    if restricted {
        // One set of orbitals; each holds the electrons of both spins.
        let beta = match wavefunction.opt(&field_name(&wavefunction, "occupations_b")?) {
            Some(o) => {
                let occ = o.reals(false, false)?;
                if occ.len() != spins[0].nmo {
                    return Err(o.error(format!("{} occupations (the orbitals)", spins[0].nmo)));
                }
                occ
            }
            None => by_energy(&spins[0].energies, counts.1),
        };
        spins[0].occupations.iter_mut().zip(&beta).for_each(|(a, b)| *a += b);
    } else {
        spins.push(read_orbitals(&wavefunction, "b", nao, counts.1, Spin::Beta)?);
    }
    for s in &spins {
        let limit = if restricted { 2.0 } else { 1.0 };
        if let Some(&bad) = s.occupations.iter().find(|&&o| !(-1e-9..=limit + 1e-9).contains(&o)) {
            return Err(ParseError {
                file: file.into(),
                line: 0,
                expected: format!("wavefunction occupations 0..={limit} per orbital"),
                found: format!("{bad}"),
            });
        }
    }

    let creator = root
        .opt("provenance")
        .and_then(|p| p.opt("creator"))
        .and_then(|c| c.str().ok().map(str::to_string))
        .unwrap_or_default();
    let psi4 = creator.to_ascii_lowercase().starts_with("psi4");
    // The writer's reading first, then the other with and without the coefficients' folding.
    let readings = if psi4 { PSI4_FIRST } else { SPEC_FIRST };
    // The first reading whose orbitals are orthonormal; without an overlap to measure with,
    // the writer's. The chosen reading's overlap is kept for the check every reader's
    // wavefunction gets ([`wavefunction_document`]), which would otherwise build it again.
    let last: std::sync::Mutex<Option<(Basis, Vec<f64>)>> = Default::default();
    let remembered = overlap.map(|overlap| {
        move |basis: &Basis| {
            let mut last = last.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            match last.as_ref() {
                Some((b, s)) if b == basis => s.clone(),
                _ => {
                    let s = overlap(basis);
                    *last = Some((basis.clone(), s.clone()));
                    s
                }
            }
        }
    });
    let overlap: Option<OverlapFn> = remembered.as_ref().map(|f| f as OverlapFn);
    let mut chosen = (readings[0], f64::INFINITY);
    if let Some(overlap) = overlap {
        for reading in readings {
            let mut wf = build(&shells, &atoms, &spins, restricted, reading);
            normalize_contractions(&mut wf);
            let r = residual(&wf.orbitals, &overlap(&wf.basis));
            let r = if r.is_nan() { f64::INFINITY } else { r };
            if r < chosen.1 {
                chosen = (reading, r);
            }
            if r <= AS_READ_TOLERANCE {
                break;
            }
        }
    }
    let wf = build(&shells, &atoms, &spins, restricted, chosen.0);
    let title = match molecule.opt("name") {
        Some(n) => n.str()?.to_string(),
        None => String::new(),
    };
    let program = if creator.is_empty() { None } else { Some(creator.as_str()) };
    let mut doc = wavefunction_document(file, &title, atoms, wf, program, overlap);
    if let Some(wf) = doc.wavefunction.as_mut()
        && chosen.0 != readings[0]
        && wf.normalization.repair == "none"
    {
        wf.normalization.repair = format!("read with {}", chosen.0.describe());
    }
    doc.problems.extend(problems);
    Ok(doc)
}

fn n_functions(l: u32, pure: bool) -> usize {
    if pure { 2 * l as usize + 1 } else { ((l + 1) * (l + 2) / 2) as usize }
}

/// Atoms (bohr), the molecule's charge and multiplicity.
fn read_molecule(molecule: &Node) -> Result<(Vec<Atom>, f64, u32), ParseError> {
    let symbols = molecule.get("symbols", "the atoms' element symbols")?.items("symbols")?;
    let geometry = molecule.get("geometry", "the atoms' coordinates in bohr")?;
    let xyz = geometry.reals(false, true)?;
    if symbols.is_empty() || xyz.len() != 3 * symbols.len() {
        return Err(geometry.error(format!(
            "{} coordinates (x, y, z of each of the {} atoms)",
            3 * symbols.len(),
            symbols.len()
        )));
    }
    let numbers = match molecule.opt("atomic_numbers") {
        Some(n) => {
            let items = n.items("atomic numbers")?;
            if items.len() != symbols.len() {
                return Err(n.error(format!("{} atomic numbers", symbols.len())));
            }
            Some(
                items
                    .iter()
                    .map(|z| z.integer(0..=super::MAX_Z as i64).map(|z| z as u32))
                    .collect::<Result<Vec<_>, _>>()?,
            )
        }
        None => None,
    };
    let real = match molecule.opt("real") {
        Some(r) => {
            let items = r.items("flags")?;
            if items.len() != symbols.len() {
                return Err(r.error(format!("{} flags, one per atom", symbols.len())));
            }
            Some(items.iter().map(Node::bool).collect::<Result<Vec<_>, _>>()?)
        }
        None => None,
    };
    let mut atoms = Vec::with_capacity(symbols.len());
    for (i, s) in symbols.iter().enumerate() {
        let z = match &numbers {
            Some(n) => n[i],
            None => {
                let text = s.str()?;
                // Ghosts may be written "Gh(He)" or "@He".
                let bare = text.trim().trim_start_matches('@').trim_start_matches("Gh(").trim_end_matches(')');
                atomic_number(bare).ok_or_else(|| s.error("an element symbol"))?
            }
        };
        let ghost = z == 0 || real.as_ref().is_some_and(|r| !r[i]);
        let position = glam::DVec3::new(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        atoms.push(Atom { z, charge: if ghost { 0.0 } else { z as f64 }, position, ghost });
    }
    let charge = match molecule.opt("molecular_charge") {
        Some(c) => c.real(false)?,
        None => 0.0,
    };
    let multiplicity = match molecule.opt("molecular_multiplicity") {
        Some(m) => m.integer(1..=1000)? as u32,
        None => 1,
    };
    Ok((atoms, charge, multiplicity))
}

/// The shells of every atom, in the file's order, and each atom's electrons replaced by an ECP.
fn read_basis(basis: &Node, n_atoms: usize) -> Result<(Vec<FileShell>, Vec<i64>), ParseError> {
    let centers = basis.get("center_data", "the basis of each kind of centre")?;
    // An object, even where atom_map names none of its entries.
    centers.members("centres")?;
    let atom_map = basis.get("atom_map", "the name of each atom's centre in center_data")?;
    let names = atom_map.items("centre names")?;
    if names.len() != n_atoms {
        return Err(atom_map.error(format!("{n_atoms} names, one per atom")));
    }
    let mut shells = Vec::new();
    let mut ecp = Vec::with_capacity(n_atoms);
    for (atom, name) in names.iter().enumerate() {
        let key = name.str()?;
        let center = centers.opt(key).ok_or_else(|| name.error("the name of an entry of center_data"))?;
        ecp.push(match center.opt("ecp_electrons") {
            Some(e) => e.integer(0..=200)?,
            None => 0,
        });
        for s in center.get("electron_shells", "the centre's shells")?.items("shells")? {
            let pure = match s.get("harmonic_type", "\"spherical\" or \"cartesian\"")? {
                h if h.str().ok() == Some("spherical") => true,
                h if h.str().ok() == Some("cartesian") => false,
                h => return Err(h.error("\"spherical\" or \"cartesian\"")),
            };
            let am_node = s.get("angular_momentum", "the shell's l (several for an sp shell)")?;
            let ls = am_node
                .items("angular momenta")?
                .iter()
                .map(|l| l.integer(0..=MAX_L as i64).map(|l| l as u32))
                .collect::<Result<Vec<_>, _>>()?;
            let exponents_node = s.get("exponents", "the primitives' exponents")?;
            let exponents = exponents_node.reals(true, false)?;
            if exponents.is_empty() || exponents.iter().any(|&e| e <= 0.0) {
                return Err(exponents_node.error("positive exponents, at least one"));
            }
            let rows_node = s.get("coefficients", "the contraction coefficients, a row per contraction")?;
            let rows = rows_node.items("rows of coefficients")?;
            // One l for every row (a general contraction), or one l per row (sp shells).
            if ls.is_empty() || rows.is_empty() || (ls.len() > 1 && ls.len() != rows.len()) {
                return Err(rows_node.error(format!(
                    "one row of coefficients per angular momentum ({}), or rows of one angular momentum",
                    ls.len()
                )));
            }
            for (k, row) in rows.iter().enumerate() {
                let coefficients = row.reals(true, false)?;
                if coefficients.len() != exponents.len() {
                    return Err(row.error(format!("{} coefficients, one per exponent", exponents.len())));
                }
                let l = if ls.len() == 1 { ls[0] } else { ls[k] };
                shells.push(FileShell { atom, l, pure, exponents: exponents.clone(), coefficients });
            }
        }
    }
    Ok((shells, ecp))
}

/// The name of the field that holds `role` ("orbitals_a" → "scf_orbitals_a" unless the file
/// names another, such as "localized_orbitals_a").
fn field_name(wavefunction: &Node, role: &str) -> Result<String, ParseError> {
    Ok(match wavefunction.opt(role) {
        Some(name) => name.str()?.to_string(),
        None => format!("scf_{role}"),
    })
}

/// Alpha and beta electrons: the result's properties, else the molecule's charge and
/// multiplicity.
fn electron_counts(root: &Node, electrons: f64, multiplicity: u32) -> Result<(f64, f64), ParseError> {
    let properties = root.opt("properties");
    let count = |key: &str| -> Result<Option<f64>, ParseError> {
        match properties.as_ref().and_then(|p| p.opt(key)) {
            Some(n) => Ok(Some(n.integer(0..=1_000_000)? as f64)),
            None => Ok(None),
        }
    };
    let unpaired = multiplicity as f64 - 1.0;
    let alpha = count("calcinfo_nalpha")?.unwrap_or(((electrons + unpaired) / 2.0).round().max(0.0));
    let beta = count("calcinfo_nbeta")?.unwrap_or(((electrons - unpaired) / 2.0).round().max(0.0));
    Ok((alpha, beta))
}

/// Occupations 1 for the `n` orbitals of lowest energy (file order where energies are absent).
fn by_energy(energies: &[f64], n: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..energies.len()).collect();
    order.sort_by(|&a, &b| energies[a].total_cmp(&energies[b]));
    let mut occ = vec![0.0; energies.len()];
    for &i in order.iter().take(n.max(0.0) as usize) {
        occ[i] = 1.0;
    }
    occ
}

/// The orbitals of spin `suffix` ("a" or "b"), with their energies and occupations (per spin).
fn read_orbitals(
    wavefunction: &Node,
    suffix: &str,
    nao: usize,
    electrons: f64,
    spin: Spin,
) -> Result<FileOrbitals, ParseError> {
    let name = field_name(wavefunction, &format!("orbitals_{suffix}"))?;
    let node = wavefunction.get(&name, "the orbitals' coefficients, nao × nmo row after row")?;
    let coefficients = node.reals(false, true)?;
    if nao == 0 || coefficients.is_empty() || coefficients.len() % nao != 0 {
        return Err(
            node.error(format!("a multiple of {nao} coefficients (the basis set's functions times the orbitals)"))
        );
    }
    let nmo = coefficients.len() / nao;
    let energies = match wavefunction.opt(&field_name(wavefunction, &format!("eigenvalues_{suffix}"))?) {
        Some(e) => {
            let v = e.reals(false, false)?;
            if v.len() != nmo {
                return Err(e.error(format!("{nmo} orbital energies (the orbitals)")));
            }
            v
        }
        None => vec![f64::NAN; nmo],
    };
    let occupations = match wavefunction.opt(&field_name(wavefunction, &format!("occupations_{suffix}"))?) {
        Some(o) => {
            let v = o.reals(false, false)?;
            if v.len() != nmo {
                return Err(o.error(format!("{nmo} occupations (the orbitals)")));
            }
            v
        }
        None => by_energy(&energies, electrons),
    };
    Ok(FileOrbitals { nmo, coefficients, energies, occupations, spin })
}

/// The functions of a file's shell in the model's order: for each of the file's functions, its
/// index within the model's shell and the factor its coefficients take.
fn shell_map(l: u32, pure: bool, reading: Reading) -> Vec<(usize, f64)> {
    if !pure || l == 0 {
        // Cartesian components in the specification's order, which is the model's; each
        // normalised like x^l, where the model's are normalised each on its own.
        let dl = double_factorial(2 * l as i64 - 1);
        return cartesian_powers(l)
            .iter()
            .enumerate()
            .map(|(k, p)| (k, (p.iter().map(|&n| double_factorial(2 * n as i64 - 1)).product::<f64>() / dl).sqrt()))
            .collect();
    }
    let l = l as i64;
    let ms: Vec<i64> = if reading.descending { (-l..=l).rev().collect() } else { (-l..=l).collect() };
    ms.into_iter()
        .map(|m| {
            let index = if l == 1 {
                // The model's p shell is x (m = +1), y (m = −1), z (m = 0).
                match m {
                    1 => 0,
                    -1 => 1,
                    _ => 2,
                }
            } else if m == 0 {
                0
            } else if m > 0 {
                2 * m as usize - 1
            } else {
                2 * (-m) as usize
            };
            (index, 1.0)
        })
        .collect()
}

fn double_factorial(n: i64) -> f64 {
    (1..=n.max(0)).rev().step_by(2).map(|k| k as f64).product()
}

/// The wavefunction in the model's conventions, taking the file as `reading` says.
fn build(
    shells: &[FileShell],
    atoms: &[Atom],
    spins: &[FileOrbitals],
    restricted: bool,
    reading: Reading,
) -> Wavefunction {
    let mut basis = Vec::with_capacity(shells.len());
    let mut to_model = Vec::new();
    for s in shells {
        let coefficients = if reading.folded {
            s.exponents.iter().zip(&s.coefficients).map(|(&a, &c)| c / cartesian_norm(a, [s.l, 0, 0])).collect()
        } else {
            s.coefficients.clone()
        };
        let kind = if s.pure && s.l >= 2 { ShellKind::Pure } else { ShellKind::Cartesian };
        let first = to_model.len();
        to_model.extend(shell_map(s.l, s.pure, reading).into_iter().map(|(k, f)| (first + k, f)));
        basis.push(Shell {
            atom: s.atom,
            center: atoms[s.atom].position,
            l: s.l,
            kind,
            exponents: s.exponents.clone(),
            coefficients,
        });
    }
    let nao = to_model.len();
    let mut orbitals = Vec::new();
    for spin in spins {
        for k in 0..spin.nmo {
            let mut c = vec![0.0; nao];
            for (i, &(to, factor)) in to_model.iter().enumerate() {
                c[to] = spin.coefficients[i * spin.nmo + k] * factor;
            }
            orbitals.push(MolecularOrbital {
                energy: spin.energies[k],
                occupation: spin.occupations[k],
                spin: spin.spin,
                symmetry: String::new(),
                coefficients: c,
            });
        }
    }
    Wavefunction {
        basis: Basis { shells: basis },
        orbitals,
        restricted,
        normalization: Default::default(),
        excited: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_orders() {
        let order = |l, pure, reading| shell_map(l, pure, reading).into_iter().map(|(k, _)| k).collect::<Vec<_>>();
        // Psi4's p: x, z, y; the specification's: y, z, x.
        assert_eq!(order(1, true, Reading::PSI4), vec![0, 2, 1]);
        assert_eq!(order(1, true, Reading::SPEC), vec![1, 2, 0]);
        // d: m = +2 +1 0 −1 −2 and −2 … +2 into 0, +1, −1, +2, −2.
        assert_eq!(order(2, true, Reading::PSI4), vec![3, 1, 0, 2, 4]);
        assert_eq!(order(2, true, Reading::SPEC), vec![4, 2, 0, 1, 3]);
        // Cartesian d: same order, xy scaled by 1/√3 relative to xx.
        let d = shell_map(2, false, Reading::SPEC);
        assert_eq!(d.iter().map(|p| p.0).collect::<Vec<_>>(), vec![0, 1, 2, 3, 4, 5]);
        assert!((d[1].1 - (1.0f64 / 3.0).sqrt()).abs() < 1e-15 && d[0].1 == 1.0);
        assert_eq!(double_factorial(-1), 1.0);
        assert_eq!(double_factorial(7), 105.0);
    }
}
