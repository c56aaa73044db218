//! Molden files (GUIDE §3).
//!
//! ```text
//! [Molden Format]
//! [Title]                      optional, the next line is the title
//! [Atoms] AU|Angs              `name index Z x y z`; also `(AU)`, any case; no unit = Å
//! [5D] [5D7F] [5D10F] [7F] [9G]   pure d/f/g tags, anywhere; no tag = cartesian
//! [GTO]                        per atom `index 0`, then shells `label nprim [scale]` and
//!                              nprim lines `exponent coefficient` (two coefficients for `sp`)
//! [MO]                         per orbital `Sym= Ene= Spin= Occup=` (any order), then sparse
//!                              `index coefficient` lines (missing = 0)
//! ```
//!
//! Other sections (`[Molpro variables]`, `[SCFCONV]`, `[GEOMETRIES]`, …) are skipped, a repeated
//! `[Molden Format]` header is harmless. [`MoldenFile::parse`] reads the file as written;
//! [`MoldenFile::into_document`] converts once to the model: bohr, `sp` shells split into s and p,
//! Molden's cartesian order (d: xx yy zz xy xz yz; f: xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz; g:
//! xxxx yyyy zzzz xxxy xxxz yyyx yyyz zzzx zzzy xxyy xxzz yyzz xxyz yyxz zzxy) permuted into
//! orbcloud's alphabetical one (cartesian h, which Molden does not define, is read in alphabetical
//! order), alpha orbitals before beta; then the orbitals are checked and a known writer quirk
//! undone (see [`super::wavefunction`]). Pure h functions are assumed when g is pure.
//!
//! An atom whose Z column is 0 while its name is an element symbol is a ghost: basis functions,
//! no nucleus.

use glam::DVec3;

use super::text::{excerpt, parse_real};
use super::wavefunction::{OverlapFn, powers, program_named_in, to_model_order, wavefunction_document};
use super::{MAX_Z, ParseError};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind, cartesian_powers};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Atom, Document};

/// Largest orbital-coefficient matrix (orbitals × basis functions) a file may imply before
/// anything is allocated: 2²⁸ values, 2 GiB of f64.
pub const MAX_MO_VALUES: u64 = 1 << 28;

/// Parses Molden text into a document, checking and repairing the orbitals with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    MoldenFile::parse(file, text)?.into_document(file, overlap)
}

/// One `[Atoms]` line as written.
#[derive(Debug, Clone, PartialEq)]
pub struct MoldenAtom {
    pub name: String,
    /// The second column, which `[GTO]` refers to.
    pub index: i64,
    /// The third column: the atomic number (0 for a ghost).
    pub charge: f64,
    /// In the section's unit.
    pub position: [f64; 3],
}

/// One shell of `[GTO]` as written.
#[derive(Debug, Clone, PartialEq)]
pub struct MoldenShell {
    /// The atom index of the block (the `[Atoms]` index column).
    pub atom: i64,
    /// Angular momentum; an `sp` shell has `l = 1` and `sp_coefficients`.
    pub l: u32,
    pub exponents: Vec<f64>,
    /// The (first) coefficient column.
    pub coefficients: Vec<f64>,
    /// The p coefficients of an `sp` shell (whose `coefficients` are the s ones).
    pub sp_coefficients: Option<Vec<f64>>,
    /// 1-based line of the shell header.
    pub line: usize,
}

/// One orbital of `[MO]` as written.
#[derive(Debug, Clone, PartialEq)]
pub struct MoldenOrbital {
    pub symmetry: String,
    pub energy: Option<f64>,
    pub spin: Spin,
    pub occupation: Option<f64>,
    /// `(1-based index, coefficient)` pairs in file order.
    pub coefficients: Vec<(usize, f64)>,
    /// 1-based line of the orbital's first line.
    pub line: usize,
}

/// Which shells are pure, from the `[5D]`-type tags.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PureTags {
    pub d: bool,
    pub f: bool,
    pub g: bool,
}

impl PureTags {
    pub fn is_pure(&self, l: u32) -> bool {
        match l {
            0 | 1 => false,
            2 => self.d,
            3 => self.f,
            _ => self.g,
        }
    }
}

/// A Molden file as written, before any conversion.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MoldenFile {
    pub title: String,
    pub atoms: Vec<MoldenAtom>,
    /// True when `[Atoms]` says Angs (or nothing), false for AU.
    pub angstrom: bool,
    pub shells: Vec<MoldenShell>,
    pub pure: PureTags,
    pub orbitals: Vec<MoldenOrbital>,
    /// Section names in file order, lower case (`"molden format"`, `"atoms"`, …).
    pub sections: Vec<String>,
    /// 1-based line of the `[MO]` header (0 when absent).
    pub mo_line: usize,
    /// The normal-mode sections (`[FREQ]`, `[FR-COORD]`, `[FR-NORM-COORD]`, `[INT]`).
    pub modes: super::modes::MoldenModes,
    /// The first malformation in a mode section: the file still opens, without modes.
    pub modes_error: Option<ParseError>,
}

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// `[name] rest` → (lower-case name, rest); `None` when the line is no section header.
fn section_header(line: &str) -> Option<Result<(String, &str), ()>> {
    let t = line.trim();
    let inner = t.strip_prefix('[')?;
    Some(match inner.find(']') {
        Some(end) => Ok((inner[..end].trim().to_ascii_lowercase(), inner[end + 1..].trim())),
        None => Err(()),
    })
}

const SHELL: &str = "a shell `label nprim [scale]` (label s, p, sp, d, f, g or h) or an atom line `index 0`";

impl MoldenFile {
    /// Reads the file as written. Every malformation is an error naming its 1-based line.
    pub fn parse(file: &str, text: &str) -> Result<Self, ParseError> {
        let lines: Vec<&str> = text.lines().collect();
        let mut out = MoldenFile { angstrom: true, ..Default::default() };
        if !lines.iter().any(|l| section_header(l).is_some_and(|h| h.is_ok_and(|(n, _)| n == "molden format"))) {
            let found = lines.iter().find(|l| !l.trim().is_empty()).map_or("an empty file".to_string(), |l| excerpt(l));
            return Err(error(file, 1, "a Molden file (a `[Molden Format]` header)", found));
        }
        let (mut seen_atoms, mut seen_gto) = (0usize, 0usize);
        let mut mo_ends_file = false;
        let mut i = 0;
        while i < lines.len() {
            let line_no = i + 1;
            let Some(header) = section_header(lines[i]) else {
                // Text outside any known section is skipped (it belongs to an ignored one).
                i += 1;
                continue;
            };
            let (name, arg) =
                header.map_err(|_| error(file, line_no, "a section header `[name]`", excerpt(lines[i])))?;
            out.sections.push(name.clone());
            i += 1;
            // The section body: up to the next header.
            let end = (i..lines.len()).find(|&k| section_header(lines[k]).is_some()).unwrap_or(lines.len());
            match name.as_str() {
                "title" => {
                    out.title =
                        lines[i..end].iter().map(|l| l.trim()).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ");
                }
                "atoms" => {
                    if seen_atoms > 0 {
                        return Err(error(file, line_no, "one [Atoms] section", "a second one"));
                    }
                    seen_atoms = line_no;
                    let unit = arg.trim_matches(|c| c == '(' || c == ')').trim().to_ascii_lowercase();
                    out.angstrom = match unit.as_str() {
                        "au" | "bohr" => false,
                        "" | "angs" | "angstrom" | "angstroms" => true,
                        _ => {
                            return Err(error(file, line_no, "the unit of [Atoms]: AU or Angs", excerpt(arg)));
                        }
                    };
                    out.atoms = parse_atoms(file, &lines, i, end)?;
                }
                "gto" => {
                    if seen_gto > 0 {
                        return Err(error(file, line_no, "one [GTO] section", "a second one"));
                    }
                    seen_gto = line_no;
                    out.shells = parse_gto(file, &lines, i, end)?;
                }
                "mo" => {
                    if out.mo_line > 0 {
                        return Err(error(file, line_no, "one [MO] section", "a second one"));
                    }
                    out.mo_line = line_no;
                    out.orbitals = parse_mo(file, &lines, i, end)?;
                    mo_ends_file = end == lines.len();
                }
                "freq" | "fr-coord" | "fr-norm-coord" | "int" => {
                    let read = out.modes.read(file, &name, line_no, &lines, (i, end));
                    if let (Err(e), None) = (read, &out.modes_error) {
                        out.modes_error = Some(e);
                    }
                }
                "5d" | "5d7f" => {
                    out.pure.d = true;
                    out.pure.f = true;
                }
                "5d10f" => out.pure.d = true,
                "7f" => out.pure.f = true,
                "9g" => out.pure.g = true,
                _ => {}
            }
            i = end;
        }
        let eof = lines.len().max(1);
        if seen_atoms == 0 {
            return Err(error(file, eof, "an [Atoms] section", "end of file"));
        }
        if seen_gto == 0 {
            return Err(error(file, eof, "a [GTO] section", "end of file"));
        }
        if out.mo_line == 0 {
            return Err(error(file, eof, "an [MO] section", "end of file"));
        }
        if mo_ends_file {
            out.check_not_cut(file, &lines, text.ends_with('\n'))?;
        }
        Ok(out)
    }

    /// The number of basis functions `[GTO]` defines, as the file counts them.
    fn n_file_functions(&self) -> usize {
        self.shells
            .iter()
            .map(|s| match (&s.sp_coefficients, self.pure.is_pure(s.l)) {
                (Some(_), _) => 4,
                (None, true) => 2 * s.l as usize + 1,
                (None, false) => (s.l as usize + 1) * (s.l as usize + 2) / 2,
            })
            .sum()
    }

    /// Refuses an `[MO]` section that ends the file and was cut short. Coefficients may be
    /// sparse, so a short orbital alone proves nothing; a cut shows as the last orbital
    /// stopping partway through indices 1, 2, 3, … while every orbital before it has all of
    /// them (or, alone, its last line lacks its newline), or as fewer beta orbitals than a full
    /// set of alpha ones. Otherwise the partial orbital would be shown as if whole.
    fn check_not_cut(&self, file: &str, lines: &[&str], ends_with_newline: bool) -> Result<(), ParseError> {
        let n = self.n_file_functions();
        let last_line = lines.iter().rposition(|l| !l.trim().is_empty()).map_or(1, |k| k + 1);
        let dense = |o: &MoldenOrbital, len: usize| {
            o.coefficients.len() == len && o.coefficients.iter().enumerate().all(|(k, &(index, _))| index == k + 1)
        };
        if let Some((last, before)) = self.orbitals.split_last() {
            let k = last.coefficients.len();
            let written_in_full =
                if before.is_empty() { !ends_with_newline } else { before.iter().all(|o| dense(o, n)) };
            if k < n && dense(last, k) && written_in_full {
                return Err(error(
                    file,
                    last_line,
                    format!(
                        "{n} coefficients `index value` for the orbital from line {} (one per basis function of [GTO])",
                        last.line
                    ),
                    format!("{k}, then the end of the file: the file was cut short"),
                ));
            }
        }
        let count = |spin| self.orbitals.iter().filter(|o| o.spin == spin).count();
        let (alpha, beta) = (count(Spin::Alpha), count(Spin::Beta));
        let beta_block_last = self.orbitals.iter().skip_while(|o| o.spin == Spin::Alpha).all(|o| o.spin == Spin::Beta);
        if beta > 0 && beta < alpha && alpha == n && beta_block_last {
            return Err(error(
                file,
                last_line,
                format!("{alpha} Beta orbitals, as many as the Alpha ones"),
                format!("{beta}, then the end of the file: the file was cut short"),
            ));
        }
        Ok(())
    }

    /// The writer the file names in its title or betrays by its layout, if any.
    pub fn program(&self) -> Option<&'static str> {
        if let Some(p) = program_named_in(&self.title) {
            return Some(p);
        }
        if self.sections.iter().any(|s| s.starts_with("molpro")) {
            return Some("Molpro");
        }
        if self.sections.iter().filter(|s| *s == "molden format").count() > 1 {
            return Some("CFOUR");
        }
        None
    }

    /// The model: bohr, orbcloud's basis order, orbitals checked and repaired with `overlap`.
    pub fn into_document(self, source: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
        let file = source;
        let scale = if self.angstrom { BOHR_PER_ANGSTROM } else { 1.0 };
        let atoms: Vec<Atom> = self
            .atoms
            .iter()
            .map(|a| {
                let symbol: String = a.name.chars().take_while(char::is_ascii_alphabetic).collect();
                let named = atomic_number(&symbol);
                let column = a.charge.round();
                let (z, ghost) = if column >= 1.0 { (column as u32, false) } else { (named.unwrap_or(0), true) };
                Atom { z, charge: a.charge, position: DVec3::from_array(a.position) * scale, ghost }
            })
            .collect();

        // Shells, split and reordered; `file_to_model[k]` is the model index of file function k.
        let mut shells = Vec::new();
        let mut file_to_model = Vec::new();
        let mut n_model = 0usize;
        for s in &self.shells {
            let atom = self
                .atoms
                .iter()
                .position(|a| a.index == s.atom)
                .or_else(|| usize::try_from(s.atom - 1).ok().filter(|&k| k < self.atoms.len()))
                .ok_or_else(|| {
                    error(
                        file,
                        s.line,
                        format!("a shell on one of the {} atoms of [Atoms]", self.atoms.len()),
                        format!("atom index {}", s.atom),
                    )
                })?;
            let center = atoms[atom].position;
            let shell = |l: u32, kind: ShellKind, coefficients: Vec<f64>| Shell {
                atom,
                center,
                l,
                kind,
                exponents: s.exponents.clone(),
                coefficients,
            };
            if let Some(p) = &s.sp_coefficients {
                shells.push(shell(0, ShellKind::Cartesian, s.coefficients.clone()));
                shells.push(shell(1, ShellKind::Cartesian, p.clone()));
                file_to_model.extend((0..4).map(|k| n_model + k));
                n_model += 4;
                continue;
            }
            let pure = self.pure.is_pure(s.l);
            let kind = if pure { ShellKind::Pure } else { ShellKind::Cartesian };
            let new = shell(s.l, kind, s.coefficients.clone());
            let n = new.n_functions();
            if pure || s.l < 2 || s.l > 4 {
                file_to_model.extend((0..n).map(|k| n_model + k));
            } else {
                let order: Vec<[u32; 3]> = MOLDEN_CARTESIAN[s.l as usize - 2].split(' ').map(powers).collect();
                file_to_model.extend(to_model_order(&order).into_iter().map(|k| n_model + k));
            }
            n_model += n;
            shells.push(new);
        }
        let basis = Basis { shells };

        let n_mo = self.orbitals.len() as u64;
        if n_mo.saturating_mul(n_model as u64) > MAX_MO_VALUES {
            return Err(error(
                file,
                self.mo_line,
                format!("at most {MAX_MO_VALUES} orbital coefficients"),
                format!("{n_mo} orbitals × {n_model} basis functions"),
            ));
        }
        let mut orbitals = Vec::with_capacity(self.orbitals.len());
        for o in &self.orbitals {
            let mut c = vec![0.0; n_model];
            for &(index, value) in &o.coefficients {
                let Some(&k) = file_to_model.get(index.wrapping_sub(1)) else {
                    return Err(error(
                        file,
                        o.line,
                        format!("coefficient indices 1..={n_model} (the basis functions of [GTO])"),
                        format!("index {index} in the orbital starting here"),
                    ));
                };
                c[k] = value;
            }
            orbitals.push(MolecularOrbital {
                energy: o.energy.unwrap_or(f64::NAN),
                occupation: o.occupation.unwrap_or(0.0),
                spin: o.spin,
                symmetry: o.symmetry.clone(),
                coefficients: c,
            });
        }
        orbitals.sort_by_key(|o| o.spin == Spin::Beta);
        let restricted = !orbitals.iter().any(|o| o.spin == Spin::Beta);
        let wf = Wavefunction { basis, orbitals, restricted, normalization: Default::default(), excited: None };
        let positions: Vec<DVec3> = atoms.iter().map(|a| a.position).collect();
        let program = self.program();
        let mut doc = wavefunction_document(source, &self.title, atoms, wf, program, overlap);
        // A malformed mode section leaves the modes out; the orbitals open all the same.
        match self.modes_error.map_or_else(|| self.modes.into_vibrations(file, &positions), Err) {
            Ok(modes) => doc.vibrations = modes,
            Err(e) => doc.problems.push(format!("normal modes left out: {e}")),
        }
        Ok(doc)
    }
}

/// Molden's cartesian orders for d, f and g.
const MOLDEN_CARTESIAN: [&str; 3] = [
    "xx yy zz xy xz yz",
    "xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz",
    "xxxx yyyy zzzz xxxy xxxz yyyx yyyz zzzx zzzy xxyy xxzz yyzz xxyz yyxz zzxy",
];

fn parse_atoms(file: &str, lines: &[&str], start: usize, end: usize) -> Result<Vec<MoldenAtom>, ParseError> {
    let mut atoms = Vec::new();
    for (k, l) in lines.iter().enumerate().take(end).skip(start) {
        let t: Vec<&str> = l.split_whitespace().collect();
        if t.is_empty() {
            continue;
        }
        let bad = || error(file, k + 1, "an atom line `name index Z x y z`", excerpt(l));
        if t.len() != 6 {
            return Err(bad());
        }
        let index: i64 = t[1].parse().map_err(|_| bad())?;
        let charge = parse_real(t[2]).ok_or_else(bad)?;
        if !(0.0..=f64::from(MAX_Z)).contains(&charge) {
            return Err(error(file, k + 1, format!("an atomic number 0..={MAX_Z} (0 for a ghost)"), t[2]));
        }
        let position =
            [parse_real(t[3]).ok_or_else(bad)?, parse_real(t[4]).ok_or_else(bad)?, parse_real(t[5]).ok_or_else(bad)?];
        atoms.push(MoldenAtom { name: t[0].to_string(), index, charge, position });
    }
    if atoms.is_empty() {
        return Err(error(file, start.max(1), "at least one atom in [Atoms]", "none"));
    }
    Ok(atoms)
}

fn parse_gto(file: &str, lines: &[&str], start: usize, end: usize) -> Result<Vec<MoldenShell>, ParseError> {
    let mut shells = Vec::new();
    let mut atom: Option<i64> = None;
    let mut k = start;
    while k < end {
        let l = lines[k];
        let t: Vec<&str> = l.split_whitespace().collect();
        k += 1;
        if t.is_empty() {
            continue;
        }
        let first = t[0];
        if first.chars().all(|c| c.is_ascii_digit()) {
            // `index 0`
            if t.len() > 2 || t.get(1).is_some_and(|s| s.parse::<i64>().is_err()) {
                return Err(error(file, k, "an atom line `index 0`", excerpt(l)));
            }
            atom = Some(first.parse().map_err(|_| error(file, k, "an atom index", first))?);
            continue;
        }
        let label = first.to_ascii_lowercase();
        let (l_value, sp) = match label.as_str() {
            "s" => (0, false),
            "p" => (1, false),
            "sp" => (1, true),
            "d" => (2, false),
            "f" => (3, false),
            "g" => (4, false),
            "h" => (5, false),
            _ => return Err(error(file, k, SHELL, excerpt(l))),
        };
        debug_assert!(l_value <= MAX_L);
        let Some(atom) = atom else {
            return Err(error(file, k, "an atom line `index 0` before the first shell", excerpt(l)));
        };
        if !(2..=3).contains(&t.len()) {
            return Err(error(file, k, SHELL, excerpt(l)));
        }
        let nprim: usize = t[1].parse().map_err(|_| error(file, k, "a primitive count", t[1]))?;
        if nprim == 0 || nprim > end - k {
            return Err(error(file, k, format!("a primitive count 1..={} (the lines left in [GTO])", end - k), t[1]));
        }
        let scale = match t.get(2) {
            Some(s) => {
                parse_real(s).filter(|&v| v > 0.0).ok_or_else(|| error(file, k, "a positive scale factor", *s))?
            }
            None => 1.0,
        };
        let header_line = k;
        let mut exponents = Vec::with_capacity(nprim);
        let mut coefficients = Vec::with_capacity(nprim);
        let mut sp_coefficients = sp.then(|| Vec::with_capacity(nprim));
        for _ in 0..nprim {
            let l = lines[k];
            k += 1;
            let t: Vec<&str> = l.split_whitespace().collect();
            let expected = if sp {
                "a primitive `exponent s-coefficient p-coefficient`"
            } else {
                "a primitive `exponent coefficient`"
            };
            let bad = || error(file, k, expected, excerpt(l));
            if t.len() != if sp { 3 } else { 2 } {
                return Err(bad());
            }
            let e = parse_real(t[0]).ok_or_else(bad)?;
            if e <= 0.0 {
                return Err(error(file, k, "a positive exponent", t[0]));
            }
            exponents.push(e * scale * scale);
            coefficients.push(parse_real(t[1]).ok_or_else(bad)?);
            if let Some(p) = &mut sp_coefficients {
                p.push(parse_real(t[2]).ok_or_else(bad)?);
            }
        }
        shells.push(MoldenShell { atom, l: l_value, exponents, coefficients, sp_coefficients, line: header_line });
    }
    if shells.is_empty() {
        return Err(error(file, start.max(1), "at least one shell in [GTO]", "none"));
    }
    Ok(shells)
}

fn parse_mo(file: &str, lines: &[&str], start: usize, end: usize) -> Result<Vec<MoldenOrbital>, ParseError> {
    let mut orbitals: Vec<MoldenOrbital> = Vec::new();
    let mut current: Option<MoldenOrbital> = None;
    for (k, l) in lines.iter().enumerate().take(end).skip(start) {
        let line_no = k + 1;
        let t = l.trim();
        if t.is_empty() {
            continue;
        }
        if let Some((key, value)) = t.split_once('=') {
            let key = key.trim().to_ascii_lowercase();
            let value = value.trim();
            let o = match &mut current {
                Some(o) if o.coefficients.is_empty() => o,
                _ => {
                    if let Some(done) = current.take() {
                        orbitals.push(done);
                    }
                    current.insert(MoldenOrbital {
                        symmetry: String::new(),
                        energy: None,
                        spin: Spin::Alpha,
                        occupation: None,
                        coefficients: Vec::new(),
                        line: line_no,
                    })
                }
            };
            match key.as_str() {
                "sym" => o.symmetry = value.to_string(),
                "ene" => {
                    o.energy = Some(
                        parse_real(value).ok_or_else(|| error(file, line_no, "an energy `Ene= value`", excerpt(l)))?,
                    );
                }
                "occup" => {
                    o.occupation = Some(
                        parse_real(value)
                            .ok_or_else(|| error(file, line_no, "an occupation `Occup= value`", excerpt(l)))?,
                    );
                }
                "spin" => {
                    o.spin = match value.to_ascii_lowercase().as_str() {
                        "alpha" => Spin::Alpha,
                        "beta" => Spin::Beta,
                        _ => {
                            return Err(error(file, line_no, "`Spin= Alpha` or `Spin= Beta`", excerpt(l)));
                        }
                    }
                }
                _ => {}
            }
            continue;
        }
        let tok: Vec<&str> = t.split_whitespace().collect();
        let bad = || {
            error(
                file,
                line_no,
                "an orbital line `Sym=`, `Ene=`, `Spin=`, `Occup=` or a coefficient `index value`",
                excerpt(l),
            )
        };
        let Some(o) = &mut current else {
            return Err(error(
                file,
                line_no,
                "an orbital header (`Ene=`, `Spin=`, `Occup=`) before the coefficients",
                excerpt(l),
            ));
        };
        if tok.len() != 2 {
            return Err(bad());
        }
        let index: usize = tok[0].parse().map_err(|_| bad())?;
        if index == 0 {
            return Err(error(file, line_no, "a coefficient index ≥ 1", "0"));
        }
        let value = parse_real(tok[1]).ok_or_else(bad)?;
        o.coefficients.push((index, value));
    }
    if let Some(done) = current {
        if done.coefficients.is_empty() {
            return Err(error(file, end.max(1), "the coefficient lines `index value` of the last orbital", "none"));
        }
        orbitals.push(done);
    }
    if orbitals.is_empty() {
        return Err(error(file, start.max(1), "at least one orbital in [MO]", "none"));
    }
    Ok(orbitals)
}

/// Molden's cartesian function order for `l` as powers (used by tests and by writers).
pub fn molden_cartesian_order(l: u32) -> Vec<[u32; 3]> {
    match l {
        2..=4 => MOLDEN_CARTESIAN[l as usize - 2].split(' ').map(powers).collect(),
        _ => cartesian_powers(l),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::basis::Basis;

    use super::super::ref_overlap;

    fn doc(text: &str) -> Document {
        parse("t.molden", text, None).unwrap_or_else(|e| panic!("{e}"))
    }

    fn err(text: &str) -> ParseError {
        match parse("t.molden", text, None) {
            Ok(_) => panic!("parsed a malformed file"),
            Err(e) => e,
        }
    }

    const H2: &str = "[Molden Format]
[Title]
 hydrogen molecule
[Atoms] Angs
H 1 1 0.0 0.0 0.0
H 2 1 0.0 0.0 0.74
[GTO]
1 0
s 2 1.00
 1.0D+00 0.5
 0.5D+00 0.5

2 0
s 2 1.00
 1.0D+00 0.5
 0.5D+00 0.5

[MO]
 Sym= 1a
 Ene= -0.6
 Spin= Alpha
 Occup= 2.0
 1 0.5
 2 0.5
 Occup= 0.0
 Ene= 0.7
 Sym= 2a
 2 -0.9
";

    #[test]
    fn restricted_file_with_sparse_coefficients() {
        let d = doc(H2);
        assert_eq!(d.title, "hydrogen molecule");
        let a = &d.molecule.atoms;
        assert_eq!(a.len(), 2);
        assert!((a[1].position.z - 0.74 * BOHR_PER_ANGSTROM).abs() < 1e-12);
        let wf = d.wavefunction.expect("wavefunction");
        assert!(wf.restricted);
        assert_eq!(wf.basis.n_functions(), 2);
        assert_eq!(wf.orbitals.len(), 2);
        let o = &wf.orbitals[1];
        assert_eq!((o.energy, o.occupation, o.symmetry.as_str()), (0.7, 0.0, "2a"));
        // Index 1 missing: 0. The contraction is normalised, its norm folded into the orbital.
        let n = super::super::wavefunction::contraction_norm(0, &[1.0, 0.5], &[0.5, 0.5]);
        assert_eq!(o.coefficients[0], 0.0);
        assert!((o.coefficients[1] + 0.9 * n).abs() < 1e-12);
        assert_eq!(wf.normalization.repair, "unchecked");
        assert_eq!(wf.homo(Spin::Alpha), Some(0));
    }

    /// A one-atom file with one shell and one orbital whose coefficients are 1, 2, 3, ….
    fn one_shell(tags: &str, label: &str, n: usize) -> Wavefunction {
        let sp = label.eq_ignore_ascii_case("sp");
        let prim = if sp { " 1.0 1.0 1.0" } else { " 1.0 1.0" };
        let coefs: String = (1..=n).map(|i| format!("{i} {i}.0\n")).collect();
        let text = format!(
            "[Molden Format]\n{tags}\n[Atoms] AU\nC 1 6 0 0 0\n[GTO]\n1 0\n{label} 1 1.00\n{prim}\n\n[MO]\nEne= 0\nSpin= Alpha\nOccup= 0\n{coefs}"
        );
        doc(&text).wavefunction.expect("wavefunction")
    }

    fn model_values(wf: &Wavefunction) -> Vec<f64> {
        wf.orbitals[0].coefficients.clone()
    }

    #[test]
    fn cartesian_orders_become_alphabetical() {
        // Molden d: xx yy zz xy xz yz -> xx xy xz yy yz zz.
        let wf = one_shell("", "d", 6);
        assert_eq!(wf.basis.shells[0].kind, ShellKind::Cartesian);
        assert_eq!(model_values(&wf), vec![1.0, 4.0, 5.0, 2.0, 6.0, 3.0]);
        // Molden f: xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz.
        let wf = one_shell("", "f", 10);
        // Alphabetical: xxx xxy xxz xyy xyz xzz yyy yyz yzz zzz.
        assert_eq!(model_values(&wf), vec![1.0, 5.0, 6.0, 4.0, 10.0, 7.0, 2.0, 9.0, 8.0, 3.0]);
        let wf = one_shell("", "g", 15);
        let file = molden_cartesian_order(4);
        let model = cartesian_powers(4);
        for (k, p) in file.iter().enumerate() {
            let m = model.iter().position(|q| q == p).expect("component");
            assert_eq!(model_values(&wf)[m], (k + 1) as f64, "{p:?}");
        }
    }

    #[test]
    fn sp_shells_split_into_s_and_p() {
        let wf = one_shell("", "SP", 4);
        let kinds: Vec<u32> = wf.basis.shells.iter().map(|s| s.l).collect();
        assert_eq!(kinds, vec![0, 1]);
        assert_eq!(model_values(&wf), vec![1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn pure_tags_anywhere_any_case() {
        let pure = |tags: &str, label: &str, n: usize| {
            let wf = one_shell(tags, label, n);
            assert_eq!(wf.basis.n_functions(), n, "{tags} {label}");
            wf.basis.shells[0].kind
        };
        assert_eq!(pure("[5d]", "d", 5), ShellKind::Pure);
        assert_eq!(pure("[5D]", "f", 7), ShellKind::Pure);
        assert_eq!(pure("[5D7F]", "f", 7), ShellKind::Pure);
        assert_eq!(pure("[5D10F]", "d", 5), ShellKind::Pure);
        assert_eq!(pure("[5D10F]", "f", 10), ShellKind::Cartesian);
        assert_eq!(pure("[7F]", "f", 7), ShellKind::Pure);
        assert_eq!(pure("[7F]", "d", 6), ShellKind::Cartesian);
        assert_eq!(pure("[9G]", "g", 9), ShellKind::Pure);
        assert_eq!(pure("", "g", 15), ShellKind::Cartesian);
        // Pure order is kept as written.
        assert_eq!(model_values(&one_shell("[5D]", "d", 5)), vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        // A tag after [MO] still counts.
        let text =
            format!("{}[5D]\n", H2.replace("s 2 1.00\n 1.0D+00 0.5\n 0.5D+00 0.5\n\n2 0", "d 1 1.00\n 1.0 1.0\n\n2 0"));
        let d = doc(&text);
        assert_eq!(d.wavefunction.expect("wf").basis.shells[0].kind, ShellKind::Pure);
    }

    #[test]
    fn unrestricted_alpha_before_beta() {
        let text = H2
            .replace(" Sym= 2a", " Sym= 2a\n Spin= Beta")
            .replace(" 2 -0.9\n", " 2 -0.9\n Spin= Alpha\n Ene= 0.8\n Occup= 0\n 1 1\n");
        let wf = doc(&text).wavefunction.expect("wf");
        assert!(!wf.restricted);
        let spins: Vec<Spin> = wf.orbitals.iter().map(|o| o.spin).collect();
        assert_eq!(spins, vec![Spin::Alpha, Spin::Alpha, Spin::Beta]);
        assert_eq!(wf.orbitals[2].energy, 0.7);
    }

    #[test]
    fn units_ghosts_extra_sections_and_repeated_headers() {
        let text = H2
            .replace("[Atoms] Angs\nH 1 1", "[ATOMS] (au)\nHe1 1 0")
            .replace("[Title]", "[Molden Format]\n[Molpro variables]\n_X= 1.0\n[Title]")
            + "[SCFCONV]\n scf-first 1 THROUGH 3\n -1.0\n";
        let d = doc(&text);
        let a = &d.molecule.atoms;
        assert!(a[0].ghost && a[0].z == 2 && a[0].charge == 0.0);
        assert!(!a[1].ghost && a[1].z == 1);
        assert_eq!(a[1].position.z, 0.74);
        assert_eq!(d.wavefunction.expect("wf").normalization.program, "Molpro");
        let text = H2.replace("[Atoms] Angs\nH 1 1", "[Atoms] AU\nBq 1 0");
        let a = &doc(&text).molecule.atoms;
        assert!(a[0].ghost && a[0].z == 0);
    }

    #[test]
    fn fewer_orbitals_than_functions() {
        let text = H2.replace(" Occup= 0.0\n Ene= 0.7\n Sym= 2a\n 2 -0.9\n", "");
        let wf = doc(&text).wavefunction.expect("wf");
        assert_eq!((wf.basis.n_functions(), wf.orbitals.len()), (2, 1));
    }

    #[test]
    fn an_mo_section_cut_short_is_refused_at_the_end_of_the_file() {
        let dense = H2.replace(" Sym= 2a\n 2 -0.9\n", " Sym= 2a\n 1 0.3\n 2 -0.9\n");
        assert_eq!(doc(&dense).wavefunction.expect("wf").orbitals.len(), 2);
        let cut = dense.replace(" 2 -0.9\n", "");
        let e = err(&cut);
        assert_eq!((e.file.as_str(), e.line), ("t.molden", cut.lines().count()), "{e}");
        assert!(e.expected.contains("2 coefficients") && e.expected.contains("from line 25"), "{e}");
        assert!(e.found.contains("cut short"), "{e}");
        // One orbital, its last line without a newline: cut inside the line.
        let alone = H2.split(" Occup= 0.0").next().unwrap().replace(" 1 0.5\n 2 0.5\n", " 1 0.5");
        assert!(err(&alone).expected.contains("2 coefficients"));
        // Trailing blank lines and a last line without its newline are no cut.
        assert_eq!(doc(&format!("{dense}\n\n  \n")).wavefunction.expect("wf").orbitals.len(), 2);
        assert_eq!(doc(dense.trim_end()).wavefunction.expect("wf").orbitals.len(), 2);
        // Sparse coefficients (index 1 left out) are no cut either.
        assert_eq!(doc(H2).wavefunction.expect("wf").orbitals.len(), 2);
    }

    #[test]
    fn an_unrestricted_file_cut_among_its_beta_orbitals_is_refused() {
        let beta = |n: usize| {
            let alpha = " Ene= -0.6\n Spin= Alpha\n Occup= 1.0\n 1 0.5\n 2 0.5\n Ene= 0.7\n Spin= Alpha\n Occup= 0.0\n 1 0.5\n 2 -0.5\n";
            let b = " Ene= -0.5\n Spin= Beta\n Occup= 1.0\n 1 0.5\n 2 0.5\n Ene= 0.8\n Spin= Beta\n Occup= 0.0\n 1 0.5\n 2 -0.5\n";
            let b: Vec<&str> = b.split_inclusive('\n').collect();
            format!("{}[MO]\n{alpha}{}", H2.split("[MO]").next().unwrap(), b[..5 * n].concat())
        };
        assert!(!doc(&beta(2)).wavefunction.expect("wf").restricted);
        let e = err(&beta(1));
        assert!(e.expected.contains("2 Beta orbitals") && e.found.contains("1,"), "{e}");
        assert_eq!(e.line, beta(1).lines().count());
    }

    #[test]
    fn malformed_files_name_their_line() {
        let cases: Vec<(String, usize, &str)> = vec![
            ("hello\n".into(), 1, "[Molden Format]"),
            (H2.replace("H 2 1 0.0 0.0 0.74", "H 2 1 0.0 0.0"), 6, "name index Z x y z"),
            (H2.replace("H 2 1 0.0 0.0 0.74", "H 2 one 0.0 0.0 0.74"), 6, "name index Z x y z"),
            (H2.replace("[Atoms] Angs", "[Atoms] furlongs"), 4, "AU or Angs"),
            (H2.replace("[GTO]", "[GTO"), 7, "section header"),
            (H2.replacen("s 2 1.00", "q 2 1.00", 1), 9, "a shell"),
            (H2.replacen("s 2 1.00", "s 99 1.00", 1), 9, "primitive count"),
            (H2.replacen(" 0.5D+00 0.5", " 0.5D+00 x", 1), 11, "exponent coefficient"),
            (H2.replacen(" 0.5D+00 0.5", " -0.5 0.5", 1), 11, "positive exponent"),
            (H2.replacen("s 2 1.00", "sp 2 1.00", 1), 10, "p-coefficient"),
            (H2.replacen("1 0\ns", "s", 1), 8, "atom line"),
            (H2.replacen("2 0\n", "7 0\n", 1), 14, "atoms of [Atoms]"),
            (H2.replace(" 2 -0.9", " 3 -0.9"), 25, "indices 1..=2"),
            (H2.replace(" 2 -0.9", " 0 -0.9"), 28, "index ≥ 1"),
            (H2.replace(" 2 -0.9", " 2 -0.9 7"), 28, "coefficient `index value`"),
            (H2.replace("Spin= Alpha", "Spin= Up"), 21, "Spin= Beta"),
            (H2.replace("Ene= -0.6", "Ene= low"), 20, "energy"),
            (H2.replace("Occup= 2.0", "Occup= two"), 22, "occupation"),
            (H2.replace("[MO]\n Sym= 1a\n Ene= -0.6\n Spin= Alpha\n Occup= 2.0\n", "[MO]\n"), 19, "orbital header"),
            (format!("{H2} Ene= 1.0\n"), 29, "last orbital"),
            (H2.split("[MO]").next().unwrap_or("").to_string(), 17, "[MO]"),
            (H2.replace("[GTO]", "[GTX]"), 28, "[GTO]"),
            (format!("{H2}[GTO]\n"), 29, "one [GTO]"),
        ];
        let mut wrong = Vec::new();
        for (text, line, expected) in cases {
            let Err(e) = parse("t.molden", &text, None) else {
                wrong.push(format!("wanted line {line} \"{expected}\", but it parsed"));
                continue;
            };
            if e.line != line || !e.expected.contains(expected) || e.file != "t.molden" {
                wrong.push(format!("wanted line {line} \"{expected}\", got {e}"));
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }

    #[test]
    fn absurd_orbital_matrices_are_refused_before_allocating() {
        // 200 h shells (21 functions each) on one atom and 2^28/4000 + 1 orbitals would be
        // too many to build here; check the guard on its own instead.
        let n_mo = MAX_MO_VALUES / 4200 + 1;
        let mut text = String::from("[Molden Format]\n[Atoms] AU\nC 1 6 0 0 0\n[GTO]\n1 0\n");
        for _ in 0..200 {
            text.push_str("h 1 1.00\n 1.0 1.0\n");
        }
        text.push_str("[MO]\n");
        for _ in 0..n_mo {
            text.push_str("Ene= 0\n1 1\n");
        }
        let e = err(&text);
        assert!(e.expected.contains("orbital coefficients"), "{e}");
        assert_eq!(e.line, 406);
    }

    #[test]
    fn overlap_check_selects_no_repair_for_a_correct_file() {
        let overlap = |b: &Basis| ref_overlap::reference_overlap(b);
        // One normalised s function per atom: the bonding orbital 1/sqrt(2(1+S)).
        let text = "[Molden Format]\n[Atoms] AU\nH 1 1 0 0 0\nH 2 1 0 0 1.4\n[GTO]\n1 0\ns 1 1.0\n 1.0 1.0\n\n2 0\ns 1 1.0\n 1.0 1.0\n[MO]\nEne= -0.5\nOccup= 2\n";
        let s12 = (-0.5f64 * 1.4 * 1.4).exp(); // overlap of two unit s Gaussians, exponent 1
        let c = 1.0 / (2.0 * (1.0 + s12)).sqrt();
        let text = format!("{text}1 {c:.15}\n2 {c:.15}\n");
        let d = parse("t.molden", &text, Some(&overlap)).expect("parse");
        let n = d.wavefunction.expect("wf").normalization;
        assert_eq!(n.repair, "none");
        assert!(n.residual < 1e-12, "{n:?}");
    }
}
