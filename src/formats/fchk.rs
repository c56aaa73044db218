//! Gaussian formatted checkpoint files (`.fchk`, also written by Q-Chem; GUIDE §3).
//!
//! ```text
//! title
//! type  method  basis
//! Label (columns 1-43)                       I     value          scalar record
//! Label                                      R   N=        n      array record: n values,
//!   values …                                                        5 reals or 6 integers a line
//! ```
//! Record types I (integer), R (real, `E` or `D` exponents), C, H (text), L (logical); records
//! the viewer does not need are skipped whatever their type.
//!
//! [`FchkFile::parse`] keeps the records it needs as written; [`FchkFile::into_document`] builds
//! the model: shell types 0 s, 1 p, −1 sp (split into s and p), +l cartesian, −l pure; Gaussian's
//! cartesian order (d: xx yy zz xy xz yz; f: xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz; g and
//! higher: reverse alphabetical zzzz, yzzz, …, xxxx) permuted into orbcloud's alphabetical one;
//! pure functions already in orbcloud's order m = 0, +1, −1, …. Occupations come from the electron
//! counts. Atoms whose nuclear charge is 0 are ghosts. The orbitals are checked like Molden's
//! (see [`super::wavefunction`]).
//!
//! Optimisations, scans and IRCs store further geometries in records such as
//! `Opt point       1 Geometries` or `IRC point       1 Geometries` (3 × atoms × steps reals);
//! they are kept in [`FchkFile::geometries`] and returned by [`geometries`]. A relaxed scan
//! writes one `Opt point N` record per point (cclib's `water-pes.fchk`, a rigid Z-matrix scan,
//! holds none: its last point's geometry and orbitals only): such a file opens as the points'
//! converged geometries with their energies (`Opt point N Results for each geome`).

use std::collections::HashMap;

use glam::DVec3;

use super::text::{excerpt, parse_real};
use super::wavefunction::{OverlapFn, powers, program_named_in, to_model_order, wavefunction_document};
use super::{MAX_Z, ParseError};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind, cartesian_powers};
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::vibrations::Vibrations;
use crate::model::{Atom, Document};

/// Parses fchk text into a document, checking the orbitals with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    FchkFile::parse(file, text)?.into_document(file, overlap)
}

/// Every geometry of the file: the current one first, then those of the `… point N Geometries`
/// records in file order (bohr).
pub fn geometries(file: &str, text: &str) -> Result<Vec<Vec<DVec3>>, ParseError> {
    let f = FchkFile::parse(file, text)?;
    let mut out = vec![f.coordinates(file)?];
    out.extend(f.geometries.into_iter().flat_map(|g| g.frames));
    Ok(out)
}

/// One record's value as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Int(i64),
    Real(f64),
    Ints(Vec<i64>),
    Reals(Vec<f64>),
}

/// The geometries of one `… point N Geometries` record.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometrySet {
    /// The record's label, e.g. "Opt point       1 Geometries".
    pub label: String,
    /// One frame per step, atoms in file order, bohr.
    pub frames: Vec<Vec<DVec3>>,
}

/// The records of an fchk file the viewer uses, as written.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FchkFile {
    pub title: String,
    /// Line 2: job type, method, basis.
    pub job: String,
    /// Needed records by label, with the 1-based line of their header.
    pub records: HashMap<String, (usize, Value)>,
    /// Further geometries (optimisation, scan, IRC points).
    pub geometries: Vec<GeometrySet>,
    /// Lines in the file (for end-of-file errors).
    pub n_lines: usize,
    /// Whether the file has records only Q-Chem writes.
    pub labels_of_qchem: bool,
}

/// Records Q-Chem's fchk files carry and Gaussian's do not.
const QCHEM_ONLY: [&str; 4] = ["Pure Switching", "Core Hamiltonian Matrix", "Octapole", "Hexadecapole"];

impl FchkFile {
    /// The program that wrote the file: one its title names, else Q-Chem when it has Q-Chem's
    /// own records, else Gaussian (whose format this is).
    pub fn writer(&self) -> &'static str {
        program_named_in(&self.title).unwrap_or(if self.labels_of_qchem { "Q-Chem" } else { "Gaussian" })
    }
}

/// The records [`FchkFile::parse`] keeps.
const NEEDED: [&str; 40] = [
    // A relaxed scan's: how many values each step of `Opt point N Results for each geome` has.
    "Optimization Num results per geometry",
    "Number of atoms",
    "Number of electrons",
    "Number of alpha electrons",
    "Number of beta electrons",
    "Number of basis functions",
    "Number of independent functions",
    "Atomic numbers",
    "Nuclear charges",
    "Current cartesian coordinates",
    "Shell types",
    "Number of primitives per shell",
    "Shell to atom map",
    "Primitive exponents",
    "Contraction coefficients",
    "P(S=P) Contraction coefficients",
    "Alpha Orbital Energies",
    "Beta Orbital Energies",
    "Alpha MO coefficients",
    "Beta MO coefficients",
    "Multiplicity",
    "Number of Normal Modes",
    "Vib-E2",
    "Vib-Modes",
    // A TD job's (see `fchk_excited`).
    "SCF Energy",
    "CIS Energy",
    "Total SCF Density",
    "Total CI Density",
    "Total CI Rho(1) Density",
    "ETran scalars",
    "ETran spin",
    "ETran sym",
    "ETran state values",
    // A Q-Chem CIS/TDA job's (see `fchk_amplitudes`).
    "Number of Excited States",
    "Excitation Energies",
    "Oscillator Strengths",
    "Alpha Amplitudes",
    "Beta Amplitudes",
    "Alpha X Amplitudes",
    "Alpha Y Amplitudes",
];

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

const HEADER: &str = "a record `Label  I|R|C|H|L  value` or `Label  I|R|C|H|L  N= count` (type in column 44)";

/// `(label, type, rest)` of a record header line, `None` when the line is no header.
fn record_header(line: &str) -> Option<(&str, char, &str)> {
    if line.len() < 45 || !line.is_char_boundary(43) || line.starts_with(' ') {
        return None;
    }
    let (label, rest) = line.split_at(43);
    let mut chars = rest.chars();
    let kind = chars.next()?;
    if !matches!(kind, 'I' | 'R' | 'C' | 'H' | 'L') || chars.next() != Some(' ') {
        return None;
    }
    Some((label.trim(), kind, rest[1..].trim()))
}

fn is_geometry_label(label: &str) -> bool {
    label.contains(" point ") && label.ends_with("Geometries")
}

/// `Opt point N Results for each geome`: per step the energy first, then what else Gaussian
/// records there (`Optimization Num results per geometry` values a step).
fn is_results_label(label: &str) -> bool {
    label.contains(" point ") && label.ends_with("Results for each geome")
}

impl FchkFile {
    /// Reads the records the viewer needs. Every malformation is an error naming its line.
    pub fn parse(file: &str, text: &str) -> Result<Self, ParseError> {
        let lines: Vec<&str> = text.lines().collect();
        if lines.len() < 3 {
            return Err(error(
                file,
                lines.len().max(1),
                "an fchk file: a title line, a job line, then records",
                if text.trim().is_empty() { "an empty file".to_string() } else { "end of file".to_string() },
            ));
        }
        let mut out = FchkFile {
            title: lines[0].trim().to_string(),
            job: lines[1].split_whitespace().collect::<Vec<_>>().join(" "),
            n_lines: lines.len(),
            ..Default::default()
        };
        let mut geometry_records = Vec::new();
        let mut k = 2;
        while k < lines.len() {
            let line_no = k + 1;
            let l = lines[k];
            k += 1;
            if l.trim().is_empty() {
                continue;
            }
            let Some((label, kind, rest)) = record_header(l) else {
                return Err(error(file, line_no, HEADER, excerpt(l)));
            };
            let tokens: Vec<&str> = rest.split_whitespace().collect();
            let count = match tokens.first() {
                Some(&"N=") => Some(tokens.get(1).copied().unwrap_or("")),
                Some(t) if t.starts_with("N=") => Some(&t[2..]),
                _ => None,
            };
            let wanted =
                NEEDED.contains(&label) || (kind == 'R' && (is_geometry_label(label) || is_results_label(label)));
            out.labels_of_qchem |= QCHEM_ONLY.contains(&label);
            let Some(count) = count else {
                // A scalar.
                if wanted {
                    let bad = || error(file, line_no, format!("a value of type {kind} for \"{label}\""), excerpt(rest));
                    let v = tokens.first().ok_or_else(bad)?;
                    let value = match kind {
                        'I' => Value::Int(v.parse().map_err(|_| bad())?),
                        'R' => Value::Real(parse_real(v).ok_or_else(bad)?),
                        _ => return Err(bad()),
                    };
                    out.records.insert(label.to_string(), (line_no, value));
                }
                continue;
            };
            let n: usize =
                count.parse().map_err(|_| error(file, line_no, "an array length `N= count`", excerpt(rest)))?;
            if !wanted || !matches!(kind, 'I' | 'R') {
                // Skip the values: up to the next header.
                while k < lines.len() && record_header(lines[k]).is_none() {
                    k += 1;
                }
                continue;
            }
            // Refuse counts the rest of the file cannot hold (at most 6 values a line).
            let left = lines.len() - k;
            if n > left.saturating_mul(6) {
                return Err(error(
                    file,
                    line_no,
                    format!("an array length the file can hold (at most {} values in the {left} lines left)", left * 6),
                    format!("N= {n}"),
                ));
            }
            let mut ints = Vec::new();
            let mut reals = Vec::new();
            if kind == 'I' {
                ints.reserve(n);
            } else {
                reals.reserve(n);
            }
            let mut got = 0;
            while got < n {
                let Some(l) = lines.get(k) else {
                    return Err(error(
                        file,
                        lines.len(),
                        format!("{n} values for \"{label}\" (line {line_no})"),
                        format!("end of file after {got}"),
                    ));
                };
                k += 1;
                if record_header(l).is_some() {
                    return Err(error(
                        file,
                        k,
                        format!("{n} values for \"{label}\" (line {line_no})"),
                        format!("a new record after {got}"),
                    ));
                }
                for t in l.split_whitespace() {
                    if got == n {
                        return Err(error(
                            file,
                            k,
                            format!("{n} values for \"{label}\" (line {line_no})"),
                            "more values",
                        ));
                    }
                    let bad = || {
                        error(
                            file,
                            k,
                            format!(
                                "{} value {} of {n} for \"{label}\"",
                                if kind == 'I' { "an integer" } else { "a real" },
                                got + 1
                            ),
                            excerpt(t),
                        )
                    };
                    if kind == 'I' {
                        ints.push(t.parse::<i64>().map_err(|_| bad())?);
                    } else {
                        reals.push(parse_real(t).ok_or_else(bad)?);
                    }
                    got += 1;
                }
            }
            if is_geometry_label(label) && kind == 'R' {
                geometry_records.push((label.to_string(), line_no, reals));
                continue;
            }
            let value = if kind == 'I' { Value::Ints(ints) } else { Value::Reals(reals) };
            out.records.insert(label.to_string(), (line_no, value));
        }
        // Split the geometry records into frames of the current molecule's size.
        let n_atoms = match out.records.get("Atomic numbers") {
            Some((_, Value::Ints(z))) => z.len(),
            _ => 0,
        };
        for (label, line, values) in geometry_records {
            if n_atoms == 0 || values.len() % (3 * n_atoms) != 0 {
                return Err(error(
                    file,
                    line,
                    format!("a multiple of 3 × {n_atoms} coordinates"),
                    format!("{}", values.len()),
                ));
            }
            let frames = values
                .chunks(3 * n_atoms)
                .map(|f| f.chunks(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect())
                .collect();
            out.geometries.push(GeometrySet { label, frames });
        }
        Ok(out)
    }

    pub(super) fn missing(&self, file: &str, label: &str) -> ParseError {
        error(file, self.n_lines.max(1), format!("a record \"{label}\""), "end of file")
    }

    pub(super) fn int(&self, file: &str, label: &str) -> Result<i64, ParseError> {
        match self.records.get(label) {
            Some((_, Value::Int(v))) => Ok(*v),
            Some((line, _)) => Err(error(file, *line, format!("\"{label}\" as one integer"), "an array")),
            None => Err(self.missing(file, label)),
        }
    }

    /// A scalar real record.
    pub(super) fn real(&self, file: &str, label: &str) -> Result<f64, ParseError> {
        match self.records.get(label) {
            Some((_, Value::Real(v))) => Ok(*v),
            Some((line, _)) => Err(error(file, *line, format!("\"{label}\" as one real"), "another type")),
            None => Err(self.missing(file, label)),
        }
    }

    /// An array record, required to have `len` values when given.
    pub(super) fn ints(&self, file: &str, label: &str, len: Option<usize>) -> Result<&[i64], ParseError> {
        match self.records.get(label) {
            Some((line, Value::Ints(v))) => {
                check_len(file, *line, label, v.len(), len)?;
                Ok(v)
            }
            Some((line, _)) => Err(error(file, *line, format!("\"{label}\" as an integer array"), "another type")),
            None => Err(self.missing(file, label)),
        }
    }

    pub(super) fn reals(&self, file: &str, label: &str, len: Option<usize>) -> Result<&[f64], ParseError> {
        match self.records.get(label) {
            Some((line, Value::Reals(v))) => {
                check_len(file, *line, label, v.len(), len)?;
                Ok(v)
            }
            Some((line, _)) => Err(error(file, *line, format!("\"{label}\" as a real array"), "another type")),
            None => Err(self.missing(file, label)),
        }
    }

    pub(super) fn line_of(&self, label: &str) -> usize {
        self.records.get(label).map_or(self.n_lines.max(1), |r| r.0)
    }

    /// The current geometry, bohr.
    pub fn coordinates(&self, file: &str) -> Result<Vec<DVec3>, ParseError> {
        let z = self.ints(file, "Atomic numbers", None)?;
        let xyz = self.reals(file, "Current cartesian coordinates", Some(3 * z.len()))?;
        Ok(xyz.chunks(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect())
    }

    /// The model: atoms, basis in orbcloud's order, orbitals with occupations, checked with
    /// `overlap`.
    pub fn into_document(self, source: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
        let file = source;
        let z = self.ints(file, "Atomic numbers", None)?;
        let n_atoms = z.len();
        let xyz = self.reals(file, "Current cartesian coordinates", Some(3 * n_atoms))?;
        let charges = match self.records.get("Nuclear charges") {
            Some(_) => Some(self.reals(file, "Nuclear charges", Some(n_atoms))?),
            None => None,
        };
        let mut atoms = Vec::with_capacity(n_atoms);
        for (i, &zi) in z.iter().enumerate() {
            let zi = u32::try_from(zi).ok().filter(|&v| v <= MAX_Z).ok_or_else(|| {
                error(file, self.line_of("Atomic numbers"), format!("atomic numbers 0..={MAX_Z}"), format!("{zi}"))
            })?;
            let charge = charges.map_or(zi as f64, |c| c[i]);
            atoms.push(Atom {
                z: zi,
                charge,
                position: DVec3::new(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]),
                ghost: zi == 0 || charge == 0.0,
            });
        }

        // A relaxed scan's file: its points, whose orbitals it does not hold (but the last's).
        if let Some(doc) = self.scan_document(source, &atoms) {
            return Ok(doc);
        }
        // An optimisation's or scan's file without a basis: its geometries, as a trajectory.
        if !self.records.contains_key("Shell types") {
            return Ok(self.geometry_document(source, &atoms));
        }

        // Basis.
        let types = self.ints(file, "Shell types", None)?;
        let n_shells = types.len();
        let nprims = self.ints(file, "Number of primitives per shell", Some(n_shells))?;
        let map = self.ints(file, "Shell to atom map", Some(n_shells))?;
        let total: i64 = nprims.iter().sum();
        let line = self.line_of("Number of primitives per shell");
        if nprims.iter().any(|&n| n < 1) {
            return Err(error(file, line, "primitive counts ≥ 1", "a count < 1"));
        }
        let exps = self.reals(file, "Primitive exponents", Some(total as usize))?;
        let coefs = self.reals(file, "Contraction coefficients", Some(total as usize))?;
        let sp_coefs = if types.contains(&-1) {
            Some(self.reals(file, "P(S=P) Contraction coefficients", Some(total as usize))?)
        } else {
            None
        };
        let mut shells = Vec::new();
        let mut file_to_model = Vec::new();
        let mut n_model = 0usize;
        let mut p0 = 0usize;
        for s in 0..n_shells {
            let (t, np) = (types[s], nprims[s] as usize);
            let range = p0..p0 + np;
            p0 += np;
            let atom = usize::try_from(map[s] - 1).ok().filter(|&a| a < n_atoms).ok_or_else(|| {
                error(
                    file,
                    self.line_of("Shell to atom map"),
                    format!("atom numbers 1..={n_atoms}"),
                    format!("{} (shell {})", map[s], s + 1),
                )
            })?;
            if t.unsigned_abs() > MAX_L as u64 {
                return Err(error(
                    file,
                    self.line_of("Shell types"),
                    format!("shell types -{MAX_L}..={MAX_L}"),
                    format!("{t} (shell {})", s + 1),
                ));
            }
            let exponents = exps[range.clone()].to_vec();
            if exponents.iter().any(|&e| e <= 0.0) {
                return Err(error(
                    file,
                    self.line_of("Primitive exponents"),
                    "positive exponents",
                    format!("a non-positive one in shell {}", s + 1),
                ));
            }
            let shell = |l: u32, kind, coefficients: Vec<f64>| Shell {
                atom,
                center: atoms[atom].position,
                l,
                kind,
                exponents: exponents.clone(),
                coefficients,
            };
            if t == -1 {
                let p = sp_coefs.map(|c| c[range.clone()].to_vec()).unwrap_or_default();
                shells.push(shell(0, ShellKind::Cartesian, coefs[range].to_vec()));
                shells.push(shell(1, ShellKind::Cartesian, p));
                file_to_model.extend((0..4).map(|k| n_model + k));
                n_model += 4;
                continue;
            }
            let l = t.unsigned_abs() as u32;
            let kind = if t < -1 { ShellKind::Pure } else { ShellKind::Cartesian };
            let new = shell(l, kind, coefs[range].to_vec());
            let n = new.n_functions();
            if kind == ShellKind::Pure || l < 2 {
                file_to_model.extend((0..n).map(|k| n_model + k));
            } else {
                file_to_model.extend(to_model_order(&gaussian_cartesian_order(l)).into_iter().map(|k| n_model + k));
            }
            n_model += n;
            shells.push(new);
        }
        let basis = Basis { shells };
        let nbasis = self.int(file, "Number of basis functions")?;
        if nbasis != n_model as i64 {
            return Err(error(
                file,
                self.line_of("Number of basis functions"),
                format!("{n_model} basis functions (the shells' count)"),
                format!("{nbasis}"),
            ));
        }

        // Orbitals.
        let n_alpha = self.int(file, "Number of alpha electrons")?.max(0) as usize;
        let n_beta = self.int(file, "Number of beta electrons")?.max(0) as usize;
        let unrestricted = self.records.contains_key("Beta MO coefficients");
        let mut orbitals = Vec::new();
        for (spin, label, energies) in [
            (Spin::Alpha, "Alpha MO coefficients", "Alpha Orbital Energies"),
            (Spin::Beta, "Beta MO coefficients", "Beta Orbital Energies"),
        ] {
            if spin == Spin::Beta && !unrestricted {
                continue;
            }
            let c = self.reals(file, label, None)?;
            if n_model == 0 || c.len() % n_model != 0 {
                return Err(error(
                    file,
                    self.line_of(label),
                    format!("a multiple of {n_model} coefficients (one row per orbital)"),
                    format!("{}", c.len()),
                ));
            }
            let n_mo = c.len() / n_model;
            if let Ok(ni) = self.int(file, "Number of independent functions")
                && ni != n_mo as i64
            {
                return Err(error(
                    file,
                    self.line_of(label),
                    format!("{ni} orbitals (Number of independent functions)"),
                    format!("{n_mo}"),
                ));
            }
            let e = self.reals(file, energies, Some(n_mo))?;
            for (i, row) in c.chunks(n_model).enumerate() {
                let mut coefficients = vec![0.0; n_model];
                for (k, &v) in row.iter().enumerate() {
                    coefficients[file_to_model[k]] = v;
                }
                let occupation = match (unrestricted, spin) {
                    (false, _) => ((i < n_alpha) as u8 + (i < n_beta) as u8) as f64,
                    (true, Spin::Alpha) => (i < n_alpha) as u8 as f64,
                    (true, Spin::Beta) => (i < n_beta) as u8 as f64,
                };
                orbitals.push(MolecularOrbital {
                    energy: e[i],
                    occupation,
                    spin,
                    symmetry: String::new(),
                    coefficients,
                });
            }
        }
        let wf = Wavefunction {
            basis,
            orbitals,
            restricted: !unrestricted,
            normalization: Default::default(),
            excited: None,
        };
        let positions: Vec<DVec3> = atoms.iter().map(|a| a.position).collect();
        let mut doc = wavefunction_document(source, &self.title, atoms, wf, Some(self.writer()), overlap);
        // A TD job's states and the excited state's density: a malformed record leaves them out.
        // Without `ETran` records the density is taken as state 1's (Gaussian's default root);
        // with records that disagree its state is unknown, and it is left out too.
        let state = match self.excited_states(file) {
            Ok(states) => {
                let state = states.as_ref().map_or(Some(1), |s| s.density_of);
                doc.excited = states;
                state
            }
            Err(e) => {
                doc.problems.push(format!("excited states (and their density) left out: {e}"));
                None
            }
        };
        if let (Some(wf), Some(state)) = (doc.wavefunction.as_mut(), state) {
            match self.excited_density(file, &file_to_model, wf, state) {
                Ok(density) => wf.excited = density.map(std::sync::Arc::new),
                Err(e) => doc.problems.push(format!("excited-state density left out: {e}")),
            }
        }
        // Q-Chem's states carry their amplitudes instead (and no density).
        if !self.records.contains_key("ETran scalars")
            && let Some(wf) = doc.wavefunction.as_ref()
        {
            match self.qchem_excited_states(file, n_alpha, wf) {
                Ok(Some(q)) => {
                    doc.excited = Some(q.states);
                    doc.problems.extend(q.left_out.map(|why| format!("excited states' transitions left out: {why}")));
                }
                Ok(None) => {}
                Err(e) => doc.problems.push(format!("excited states left out: {e}")),
            }
        }
        // A malformed mode record leaves the modes out; the orbitals open all the same.
        match self.vibrations(file, &positions) {
            Ok(modes) => doc.vibrations = modes,
            Err(e) => doc.problems.push(format!("normal modes left out: {e}")),
        }
        Ok(doc)
    }

    /// A relaxed scan's file (`opt=modredundant` with an `S` line): one `Opt point N
    /// Geometries` record per point (every optimisation step of that point), each with its `Opt
    /// point N Results for each geome` (energy first). Its points open as the frames of a
    /// trajectory, each its last (converged) geometry with that step's energy; the orbitals,
    /// which the file holds for the last point only, are left out, saying so. `None` for any
    /// other file (an optimisation has one point). The file does not name the scanned
    /// coordinate (no ModRedundant section): the frames have none.
    fn scan_document(&self, source: &str, atoms: &[Atom]) -> Option<Document> {
        let points: Vec<&GeometrySet> = self.geometries.iter().filter(|g| g.label.starts_with("Opt point")).collect();
        if points.len() < 2 {
            return None;
        }
        let per_step = match self.records.get("Optimization Num results per geometry") {
            Some((_, Value::Int(n))) => usize::try_from(*n).ok().filter(|&n| n > 0),
            _ => None,
        }
        .unwrap_or(2);
        let z: Vec<u8> = atoms.iter().map(|a| a.z as u8).collect();
        let mut frames = Vec::with_capacity(points.len());
        let mut energies = Vec::with_capacity(points.len());
        for set in &points {
            let Some(last) = set.frames.last() else { continue };
            let results = set.label.replace("Geometries", "Results for each geome");
            // The last step's energy, when the record has one per step.
            let energy = match self.records.get(&results) {
                Some((_, Value::Reals(v))) if v.len() == per_step * set.frames.len() => {
                    v.get(v.len() - per_step).copied()
                }
                _ => None,
            };
            let point = set.label.trim_start_matches("Opt point").trim_end_matches("Geometries").trim();
            let name = match energy {
                Some(e) => format!("point {point}: E = {e:.9} Eh"),
                None => format!("point {point}"),
            };
            frames.push((name, last.clone()));
            energies.push(energy);
        }
        let mut doc = super::structure::trajectory(source, &self.title, &z, &frames);
        if let Some(view) = doc.structure.as_mut() {
            for (model, e) in view.structure.models.iter_mut().zip(&energies) {
                model.energy = *e;
            }
        }
        let orbitals = match self.records.contains_key("Shell types") {
            true => "its orbitals belong to the last point only and are not shown",
            false => "it holds no orbitals",
        };
        doc.problems.push(format!(
            "{source}: a relaxed scan's {} points open as frames, each its converged geometry; {orbitals} \
             (compute orbitals for the frames, or keep a checkpoint per point and run formchk on each)",
            frames.len()
        ));
        Some(doc)
    }

    /// A file with geometries but no orbitals: its current geometry, then every step of its
    /// `… Geometries` records, as the frames of a trajectory, saying that it holds no orbitals.
    fn geometry_document(&self, source: &str, atoms: &[Atom]) -> Document {
        let z: Vec<u8> = atoms.iter().map(|a| a.z as u8).collect();
        let mut frames = vec![("current geometry".to_string(), atoms.iter().map(|a| a.position).collect())];
        for set in &self.geometries {
            let label = set.label.trim();
            frames.extend(set.frames.iter().enumerate().map(|(k, f)| (format!("{label}, step {}", k + 1), f.clone())));
        }
        let mut doc = super::structure::trajectory(source, &self.title, &z, &frames);
        doc.problems.push(format!(
            "{source}: holds no orbitals (no basis set: a geometry-only fchk); its {} geometries open as frames",
            frames.len()
        ));
        doc
    }

    /// The normal modes of a frequency job (`Vib-E2`, `Vib-Modes`), at `geometry`; `None` when
    /// the file has none (Q-Chem's fchk files never do). The count comes from `Vib-Modes`, one
    /// vector of 3 × atoms values per mode: `Vib-NDim` is no mode count (Gaussian 16 writes the
    /// atom count there).
    fn vibrations(&self, file: &str, geometry: &[DVec3]) -> Result<Option<Vibrations>, ParseError> {
        if !self.records.contains_key("Vib-Modes") {
            return Ok(None);
        }
        let e2 = (self.reals(file, "Vib-E2", None)?, self.line_of("Vib-E2"));
        let vectors = (self.reals(file, "Vib-Modes", None)?, self.line_of("Vib-Modes"));
        let per_mode = 3 * geometry.len();
        if per_mode == 0 || vectors.0.len() % per_mode != 0 {
            let expected =
                format!("a multiple of 3 × {} atoms values in Vib-Modes (one vector per mode)", geometry.len());
            return Err(error(file, vectors.1, expected, format!("{} values", vectors.0.len())));
        }
        let count = vectors.0.len() / per_mode;
        if self.records.contains_key("Number of Normal Modes") {
            let stated = self.int(file, "Number of Normal Modes")?;
            if stated != count as i64 {
                let expected = format!("{count} normal modes (the vectors in Vib-Modes)");
                return Err(error(file, self.line_of("Number of Normal Modes"), expected, stated.to_string()));
            }
        }
        super::modes::from_fchk(file, count, e2, vectors, geometry).map(Some)
    }
}

fn check_len(file: &str, line: usize, label: &str, got: usize, want: Option<usize>) -> Result<(), ParseError> {
    match want {
        Some(n) if n != got => Err(error(file, line, format!("{n} values for \"{label}\""), format!("N= {got}"))),
        _ => Ok(()),
    }
}

/// Gaussian's cartesian order: d and f as in Molden, g and higher reverse alphabetical.
pub fn gaussian_cartesian_order(l: u32) -> Vec<[u32; 3]> {
    match l {
        2 => "xx yy zz xy xz yz".split(' ').map(powers).collect(),
        3 => "xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz".split(' ').map(powers).collect(),
        _ => cartesian_powers(l).into_iter().rev().collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ints(label: &str, v: &[i64]) -> String {
        let mut s = format!("{label:<43}I   N={:>12}\n", v.len());
        for row in v.chunks(6) {
            s.extend(row.iter().map(|x| format!("{x:>12}")));
            s.push('\n');
        }
        s
    }

    fn reals(label: &str, v: &[f64]) -> String {
        let mut s = format!("{label:<43}R   N={:>12}\n", v.len());
        for row in v.chunks(5) {
            s.extend(row.iter().map(|x| format!("{x:>16.8E}")));
            s.push('\n');
        }
        s
    }

    fn int(label: &str, v: i64) -> String {
        format!("{label:<43}I     {v:>12}\n")
    }

    /// Two atoms (the second a ghost), shells sp, cartesian d, pure d, cartesian g on atom 1 and
    /// s on atom 2; one alpha orbital per function with coefficients 1, 2, 3, … in row 0.
    fn file(beta: bool, extra: &str) -> String {
        let types = [-1i64, 2, -2, 4, 0];
        let nbf = 4 + 6 + 5 + 15 + 1;
        let mut c = vec![0.0; nbf * nbf];
        for (k, v) in c.iter_mut().take(nbf).enumerate() {
            *v = (k + 1) as f64;
        }
        let mut t =
            String::from("water\nSP        RHF                                                         STO-3G\n");
        t += &int("Number of atoms", 2);
        t += &int("Number of alpha electrons", 2);
        t += &int("Number of beta electrons", 1);
        t += &int("Number of basis functions", nbf as i64);
        t += &ints("Atomic numbers", &[8, 1]);
        t += &reals("Nuclear charges", &[8.0, 0.0]);
        t += &reals("Current cartesian coordinates", &[0.0, 0.0, 0.0, 0.0, 0.0, 1.5]);
        t += &ints("Shell types", &types);
        t += &ints("Number of primitives per shell", &[1, 1, 1, 1, 1]);
        t += &ints("Shell to atom map", &[1, 1, 1, 1, 2]);
        t += &reals("Primitive exponents", &[1.0, 0.8, 0.9, 0.7, 0.5]);
        t += &reals("Contraction coefficients", &[1.0; 5]);
        t += &reals("P(S=P) Contraction coefficients", &[1.0, 0.0, 0.0, 0.0, 0.0]);
        t += "Total Energy                               R     -7.5D+01\n";
        t += &reals("Alpha Orbital Energies", &(0..nbf).map(|i| i as f64).collect::<Vec<_>>());
        t += &reals("Alpha MO coefficients", &c);
        if beta {
            t += &reals("Beta Orbital Energies", &(0..nbf).map(|i| i as f64).collect::<Vec<_>>());
            t += &reals("Beta MO coefficients", &c);
        }
        t += "Route                                      C   N=           2\nsp hf/sto-3g    extra      \n";
        t += extra;
        t
    }

    fn doc(text: &str) -> Document {
        parse("t.fchk", text, None).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_file_without_a_basis_opens_its_geometries_as_frames() {
        let mut t =
            String::from("water opt\nFOpt      RHF                                                         STO-3G\n");
        t += &int("Number of atoms", 2);
        t += &ints("Atomic numbers", &[8, 1]);
        t += &reals("Current cartesian coordinates", &[0.0, 0.0, 0.0, 0.0, 0.0, 1.8]);
        t += &reals("Opt point       1 Geometries", &[0.0, 0.0, 0.0, 0.0, 0.0, 1.95, 0.0, 0.0, 0.0, 0.0, 0.0, 1.85]);
        let d = doc(&t);
        assert!(d.wavefunction.is_none());
        let models = &d.structure.as_ref().expect("a trajectory").structure.models;
        assert_eq!(models.len(), 3, "the current geometry, then each step");
        assert_eq!(d.molecule.atoms[1].position.z, 1.8);
        assert!(d.problems[0].contains("holds no orbitals"), "{:?}", d.problems);
        assert_eq!(d.molecule.bonds.len(), 1);
    }

    #[test]
    fn shells_orders_occupations_and_ghosts() {
        let d = doc(&file(false, ""));
        let a = &d.molecule.atoms;
        assert!(!a[0].ghost && a[1].ghost && a[1].z == 1);
        let wf = d.wavefunction.expect("wf");
        let ls: Vec<(u32, ShellKind)> = wf.basis.shells.iter().map(|s| (s.l, s.kind)).collect();
        use ShellKind::{Cartesian as C, Pure as P};
        assert_eq!(ls, vec![(0, C), (1, C), (2, C), (2, P), (4, C), (0, C)]);
        assert_eq!(wf.basis.shells[1].coefficients, vec![1.0]);
        assert_eq!(wf.basis.shells[1].exponents, vec![1.0]);
        let c = &wf.orbitals[0].coefficients;
        // sp: s x y z as written.
        assert_eq!(&c[..4], &[1.0, 2.0, 3.0, 4.0]);
        // Cartesian d written xx yy zz xy xz yz.
        assert_eq!(&c[4..10], &[5.0, 8.0, 9.0, 6.0, 10.0, 7.0]);
        // Pure d as written.
        assert_eq!(&c[10..15], &[11.0, 12.0, 13.0, 14.0, 15.0]);
        // Cartesian g written reverse alphabetical: zzzz first, xxxx last.
        let g: Vec<f64> = (16..=30).rev().map(|v| v as f64).collect();
        assert_eq!(&c[15..30], g.as_slice());
        assert_eq!(c[30], 31.0);
        // Restricted open shell: 2 alpha, 1 beta electrons.
        let occ: Vec<f64> = wf.orbitals.iter().take(3).map(|o| o.occupation).collect();
        assert_eq!(occ, vec![2.0, 1.0, 0.0]);
        assert!(wf.restricted);
    }

    #[test]
    fn unrestricted_occupations_per_spin() {
        let wf = doc(&file(true, "")).wavefunction.expect("wf");
        assert!(!wf.restricted);
        let occ = |spin| -> Vec<f64> { wf.of_spin(spin).take(3).map(|(_, o)| o.occupation).collect() };
        assert_eq!(occ(Spin::Alpha), vec![1.0, 1.0, 0.0]);
        assert_eq!(occ(Spin::Beta), vec![1.0, 0.0, 0.0]);
    }

    #[test]
    fn scan_geometries_are_exposed() {
        let frames = [0.0, 0.0, 0.0, 0.0, 0.0, 1.6, 0.0, 0.0, 0.0, 0.0, 0.0, 1.7];
        let extra = reals("Opt point       1 Geometries", &frames)
            + &reals("Opt point       1 Results for each geome", &[1.0, 2.0, 3.0, 4.0]);
        let g = geometries("t.fchk", &file(false, &extra)).expect("geometries");
        assert_eq!(g.len(), 3);
        assert_eq!(g[0][1].z, 1.5);
        assert_eq!(g[2][1].z, 1.7);
        let bad = reals("IRC point       1 Geometries", &[0.0; 5]);
        let e = geometries("t.fchk", &file(false, &bad)).expect_err("odd geometry");
        assert!(e.expected.contains("multiple of 3 × 2"), "{e}");
    }

    /// A frequency job's records for the two atoms of [`file`] and 3 modes: Gaussian 16 writes
    /// `Number of Normal Modes`, the atom count in `Vib-NDim` and 14 values per mode in `Vib-E2`.
    fn mode_records(stated: Option<i64>, ndim: i64, vectors: usize) -> String {
        let e2: Vec<f64> = (0..14 * 3).map(|k| 100.0 * (k + 1) as f64).collect();
        let modes: Vec<f64> = (0..vectors).map(|k| k as f64 / 10.0).collect();
        let mut t = stated.map_or(String::new(), |n| int("Number of Normal Modes", n));
        t += &int("Vib-NDim", ndim);
        t += &int("Vib-NDim0", ndim);
        t += &reals("Vib-AtMass", &[15.99491, 1.00783]);
        t += &reals("Vib-E2", &e2);
        t + &reals("Vib-Modes", &modes)
    }

    #[test]
    fn mode_count_comes_from_the_vectors_not_vib_ndim() {
        let gaussian16 = doc(&file(false, &mode_records(Some(3), 2, 18)));
        assert!(gaussian16.problems.is_empty(), "{:?}", gaussian16.problems);
        let gaussian09 = doc(&file(false, &mode_records(None, 3, 18)));
        for d in [&gaussian16, &gaussian09] {
            let v = d.vibrations.as_ref().expect("modes read");
            assert_eq!(v.modes.len(), 3);
            assert_eq!(v.modes[2].frequency_cm1, 300.0, "frequencies come first");
            assert_eq!(v.modes[2].ir_intensity, Some(1200.0), "intensities after 3 × 3 values");
            assert_eq!(v.modes[1].displacement[1], DVec3::new(0.9, 1.0, 1.1));
        }
        let mismatch = doc(&file(false, &mode_records(Some(4), 2, 18)));
        assert!(mismatch.vibrations.is_none() && mismatch.wavefunction.is_some());
        assert!(mismatch.problems[0].contains("3 normal modes"), "{:?}", mismatch.problems);
        let ragged = doc(&file(false, &mode_records(None, 2, 17)));
        assert!(ragged.vibrations.is_none());
        assert!(ragged.problems[0].contains("multiple of 3 × 2 atoms"), "{:?}", ragged.problems);
    }

    #[test]
    fn malformed_files_name_their_line() {
        let good = file(false, "");
        let line_of = |needle: &str| good.lines().position(|l| l.starts_with(needle)).map_or(0, |i| i + 1);
        let n_lines = good.lines().count();
        let mo = line_of("Alpha MO coefficients");
        let cases: Vec<(String, usize, &str)> = vec![
            ("x\n".into(), 1, "an fchk file"),
            (good.replace("Number of atoms          ", "Number of atoms\n"), 3, "a record"),
            (good.replace("           1           1           1           2", "           1           1           x           2"), line_of("Shell to atom map") + 1, "an integer value 4 of 5"),
            (good.replace("I                2\nNumber of beta", "I              two\nNumber of beta"), line_of("Number of alpha"), "a value of type I"),
            (good.replacen("1.50000000E0", "1.5000000QE0", 1), line_of("Current cartesian") + 2, "a real value 6 of 6"),
            (good.replace("Shell to atom map                          I   N=           5", "Shell to atom map                          I   N=     9999999"), line_of("Shell to atom map"), "an array length the file can hold"),
            (good.replace("Shell to atom map                          I   N=           5", "Shell to atom map                          I   N=           6"), line_of("Shell to atom map") + 2, "6 values"),
            (good.replace("           1           1           1           2", "           1           1           1           3"), line_of("Shell to atom map"), "atom numbers 1..=2"),
            (good.replace("Number of basis functions                  I               31", "Number of basis functions                  I               30"), line_of("Number of basis functions"), "31 basis functions"),
            (good.replace("Alpha MO coefficients", "Alpha MO coefficientz"), n_lines, "Alpha MO coefficients"),
            (good.replace("Shell types                                I   N=           5\n          -1           2          -2           4           0", "Shell types                                I   N=           5\n          -1           2          -2           9           0"), line_of("Shell types"), "shell types"),
        ];
        let _ = mo;
        let mut wrong = Vec::new();
        for (text, line, expected) in cases {
            let Err(e) = parse("t.fchk", &text, None) else {
                wrong.push(format!("wanted line {line} \"{expected}\", but it parsed"));
                continue;
            };
            if e.line != line || !e.expected.contains(expected) {
                wrong.push(format!("wanted line {line} \"{expected}\", got {e}"));
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }
}
