//! Gaussian logs (GUIDE §10): what a Gaussian job prints, read into the model.
//!
//! ```text
//!                          Standard orientation:            (Å; `Input orientation:` with nosymm)
//!  ---------------------------------------------------------------------
//!  Center     Atomic      Atomic             Coordinates (Angstroms)
//!  Number     Number       Type             X           Y           Z
//!  ---------------------------------------------------------------------
//!       1          6           0        0.269481   -1.410087    0.000000
//!  ---------------------------------------------------------------------
//!  Standard basis: STO-3G (5D, 7F)                            pure or cartesian d and f (and up)
//!  AO basis set in the form of general basis input (Overlap normalization):     `gfinput`
//!       1 0                                                   atom
//!  SP   3 1.00       0.000000000000                           shell, primitives, scale factor
//!       0.2941249355D+01 -0.9996722919D-01  0.1559162750D+00  exponent, s (and p) coefficients
//!  ****
//!  SCF Done:  E(RB3LYP) =  -382.308266580     A.U. after    1 cycles
//!      Molecular Orbital Coefficients:                        `pop=full` (Alpha …/Beta … when
//!                            1         2                      unrestricted); 5 columns a block
//!                         (BU)--O   (AG)--V                   symmetry and occupied/virtual
//!      Eigenvalues --   -10.02021 -10.02016
//!    1 1   C  1S          0.69929   0.69929                   one row per basis function
//!   Harmonic frequencies (cm**-1), IR intensities (KM/Mole), …  normal modes, 3 a block, or 5
//!                                                             with `freq=hpmodes` (`---`)
//! ```
//! Each orientation followed by an `SCF Done` energy is a frame (an optimisation's, an IRC's
//! steps): an orientation printed again without a new energy (the converged geometry after
//! "Optimization completed") is no new frame; a relaxed scan (several "Optimization completed")
//! keeps one frame per point, its converged geometry, and the coordinate it scans from the
//! echoed ModRedundant section (`D 3 4 9 10 S 12 30.000`), measured in each point's geometry
//! (the layout of cclib's regression files `dvb_scan_relaxed.log` and `dvb_scan.log`, Gaussian
//! 09 D.01 and A.02). A rigid scan of Z-matrix variables (`Scan`, cclib's `water-pes.g09`: two
//! variables, a grid of points) keeps every point as a frame without a coordinate. The orbitals belong to the last orientation
//! printed before them. Within a shell Gaussian orders functions as its fchk files do
//! ([`super::fchk::gaussian_cartesian_order`], pure m = 0, +1, −1, …); the AO labels of the
//! orbital rows (`3D 0` or `3XX`) say whether each shell is pure or cartesian, and must agree
//! with the basis line. Coefficients are printed to 5 decimals: the residual max |CᵀSC − I| is
//! of that size, measured and reported as such, and no writer repair is tried on it.

use glam::DVec3;

use super::logs::{Geometry as Orientation, LogLines, decimals, error, frames, trailing_numbers, trajectory};
use super::printed::column_numbers;
use super::text::parse_real;
use super::wavefunction::{OverlapFn, check_printed, to_model_order};
use super::{MAX_Z, ParseError};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind};
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::scan::{Coordinate, JobScan};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::vibrations::{NormalMode, Vibrations};
use crate::model::{Atom, Document, Molecule};

/// The keywords that make Gaussian print what the viewer needs to draw orbitals.
pub const ORBITAL_KEYWORDS: &str = "pop=full gfinput";

/// Parses a Gaussian log, checking its orbitals (if printed) with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let scan = Scan::read(&log)?;
    let mut doc = scan.into_document(&log, overlap)?;
    // A malformed table leaves the states out, not the file.
    match super::excited_logs::gaussian(&log) {
        Ok(states) => doc.excited = states,
        Err(e) => doc.problems.push(format!("excited states left out: {e}")),
    }
    Ok(doc)
}

/// A `gfinput` shell as printed: its atom (1-based), type letters, exponents and coefficient
/// columns (one, or two for SP).
#[derive(Debug, Clone)]
struct PrintedShell {
    line: usize,
    atom: usize,
    letters: String,
    exponents: Vec<f64>,
    coefficients: Vec<Vec<f64>>,
}

/// A molecular-orbital section: its header's line, spin (`None`: restricted), the rows' labels
/// and lines, and its orbitals.
#[derive(Debug, Clone)]
struct MoSection {
    line: usize,
    spin: Option<Spin>,
    labels: Vec<(usize, String)>,
    orbitals: Vec<PrintedOrbital>,
    decimals: u32,
}

#[derive(Debug, Clone)]
struct PrintedOrbital {
    energy: f64,
    /// From the `(AG)--O` / `V` line, when printed.
    occupied: Option<bool>,
    symmetry: String,
    coefficients: Vec<f64>,
}

/// Everything of the log the document needs, in file order.
#[derive(Default)]
struct Scan {
    route: String,
    standard: Vec<Orientation>,
    input: Vec<Orientation>,
    /// `SCF Done` energies (hartree) with their lines.
    energies: Vec<(usize, f64)>,
    /// Each `gfinput` section: its line and shells.
    bases: Vec<(usize, Vec<PrintedShell>)>,
    /// From "Standard basis: … (5D, 7F)": whether d, and f and higher, are cartesian, and the line.
    cartesian: Option<(bool, bool, usize)>,
    sections: Vec<MoSection>,
    electrons: Option<(usize, usize)>,
    /// Lines of "Optimization completed": several make a relaxed scan.
    completed: Vec<usize>,
    /// The echoed ModRedundant section's lines (0-based), after "The following ModRedundant
    /// input section has been read:".
    modredundant: Vec<usize>,
    /// The line of "Scan the potential surface." (a rigid scan of Z-matrix variables).
    zmatrix_scan: Option<usize>,
    modes: Option<(usize, Vec<NormalMode>)>,
}

impl Scan {
    fn read(log: &LogLines) -> Result<Self, ParseError> {
        let mut s = Scan::default();
        let mut hp_modes: Option<(usize, Vec<NormalMode>)> = None;
        let mut low_modes: Option<(usize, Vec<NormalMode>)> = None;
        let mut i = 0;
        while i < log.lines.len() {
            let l = log.lines[i];
            let t = l.trim_start();
            if s.route.is_empty() && t.starts_with('#') && i > 0 && log.lines[i - 1].trim_start().starts_with("---") {
                s.route = route(log, i);
            } else if t.starts_with("Standard orientation:") {
                let (o, next) = orientation(log, i)?;
                s.standard.push(o);
                i = next;
                continue;
            } else if t.starts_with("Input orientation:") {
                let (o, next) = orientation(log, i)?;
                s.input.push(o);
                i = next;
                continue;
            } else if t.starts_with("SCF Done:") {
                let value = t.split_once('=').and_then(|(_, r)| r.split_whitespace().next()).and_then(parse_real);
                let e = value.ok_or_else(|| log.error_at(i, "an energy after `SCF Done:  E(…) =`"))?;
                s.energies.push((i, e));
            } else if t.starts_with("AO basis set in the form of general basis input") {
                let (shells, next) = general_basis(log, i)?;
                s.bases.push((i, shells));
                i = next;
                continue;
            } else if (t.starts_with("Standard basis:") || t.starts_with("General basis read from cards"))
                && let Some(kinds) = basis_kinds(t)
            {
                s.cartesian = Some((kinds.0, kinds.1, i));
            } else if let Some(spin) = mo_header(t) {
                let (section, next) = mo_section(log, i, spin)?;
                s.sections.push(section);
                i = next;
                continue;
            } else if t.starts_with("Optimization completed") {
                s.completed.push(i);
            } else if t.starts_with("The following ModRedundant input section has been read") {
                // Its lines up to a blank line or one that names no coordinate (G09 A.02 goes on
                // straight to "Isotopes and Nuclear Properties:").
                i += 1;
                while let Some(l) = log.lines.get(i)
                    && is_modredundant_line(l)
                {
                    s.modredundant.push(i);
                    i += 1;
                }
                continue;
            } else if t.starts_with("Scan the potential surface") {
                s.zmatrix_scan = Some(i);
            } else if t.contains("alpha electrons") && t.contains("beta electrons") {
                let n: Vec<usize> = t.split_whitespace().filter_map(|w| w.parse().ok()).collect();
                if let [a, b] = n[..] {
                    s.electrons = Some((a, b));
                }
            } else if t.starts_with("Harmonic frequencies") {
                let (modes, hp, next) = frequencies(log, i)?;
                if !modes.is_empty() {
                    *(if hp { &mut hp_modes } else { &mut low_modes }) = Some((i, modes));
                }
                i = next;
                continue;
            }
            i += 1;
        }
        // freq=hpmodes prints both; its five-decimal displacements are the better ones.
        s.modes = hp_modes.or(low_modes);
        Ok(s)
    }

    /// The orientations the frames come from: the standard ones, or the input ones with nosymm.
    fn orientations(&self) -> &[Orientation] {
        if self.standard.is_empty() { &self.input } else { &self.standard }
    }

    /// The frames: each orientation with its `SCF Done` energy.
    /// A relaxed scan (`opt=modredundant`, one "Optimization completed" per point) keeps the
    /// converged geometry of each point, the last before its "Optimization completed"; any other
    /// series keeps every step.
    fn frames(&self) -> Vec<(&Orientation, Option<f64>)> {
        let all = frames(self.orientations(), &self.energies);
        if self.completed.len() < 2 {
            return all;
        }
        let mut points: Vec<(&Orientation, Option<f64>)> = Vec::new();
        for &c in &self.completed {
            if let Some(&f) = all.iter().rev().find(|f| f.0.line < c)
                && points.last().is_none_or(|p| p.0.line != f.0.line)
            {
                points.push(f);
            }
        }
        points
    }

    fn into_document(self, log: &LogLines, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
        let file = log.file;
        let frames = self.frames();
        let Some(last) = frames.last().map(|f| f.0) else {
            return Err(error(
                file,
                log.lines.len().max(1),
                "a `Standard orientation:` or `Input orientation:` table of the atoms",
                "none in the file",
            ));
        };
        for (o, _) in &frames {
            if o.z != last.z {
                return Err(log.error_at(
                    o.line,
                    format!("the same {} atoms in every orientation (as at line {})", last.z.len(), last.line + 1),
                ));
            }
        }
        let title = if self.route.is_empty() { file.to_string() } else { self.route.clone() };
        let modes = match &self.modes {
            Some((line, modes)) => Some(vibrations(log, *line, modes, self.orientations())?),
            None => None,
        };
        let mut doc = match self.orbitals(log)? {
            Orbitals::Read { section, basis_line } => {
                let geometry = self.orientation_before(section.line).unwrap_or(last);
                let mut doc = self.wavefunction_document(log, geometry, section, basis_line, overlap)?;
                super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
                doc
            }
            Orbitals::Missing(why) => {
                let mut doc = trajectory(file, &title, &frames);
                doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
                // A malformed ModRedundant section leaves the coordinate out, not the frames.
                match self.job_scan(log, &frames) {
                    Ok(scan) => doc.job_scan = scan,
                    Err(e) => doc.problems.push(format!("the scan's coordinate left out: {e}")),
                }
                doc
            }
        };
        doc.title = title;
        doc.vibrations = modes;
        Ok(doc)
    }

    /// The coordinate of a relaxed scan (`opt=modredundant` with an `S` line) and its value at
    /// each frame, the frames being the scan's points. `None` for any other job; an error for a
    /// ModRedundant line that cannot be read, a scan of two coordinates (a grid) or of another
    /// kind than a bond, an angle or a dihedral, and a scan of Z-matrix variables.
    fn job_scan(&self, log: &LogLines, frames: &[(&Orientation, Option<f64>)]) -> Result<Option<JobScan>, ParseError> {
        let mut scanned: Option<(usize, Coordinate, usize)> = None;
        for &i in &self.modredundant {
            let Some((coordinate, steps)) = modredundant_line(log, i)? else { continue };
            if let Some((first, ..)) = scanned {
                return Err(log.error_at(
                    i,
                    format!(
                        "one scanned coordinate (line {} scans one already: a scan of two is a grid of points, not a series along one coordinate)",
                        first + 1
                    ),
                ));
            }
            scanned = Some((i, coordinate, steps));
        }
        let Some((line, coordinate, steps)) = scanned else {
            if let Some(z) = self.zmatrix_scan {
                return Err(log.error_at(
                    z,
                    "a scan of ModRedundant coordinates (`opt=modredundant` with an `S` line): a rigid scan of Z-matrix \
                     variables opens as frames without its coordinate",
                ));
            }
            return Ok(None);
        };
        if self.completed.len() < 2 {
            return Err(log.error_at(
                line,
                format!(
                    "at least two of the scan's points optimised (\"Optimization completed\" {} times)",
                    self.completed.len()
                ),
            ));
        }
        super::logs::job_scan(log, line, log.lines[line], coordinate, steps + 1, frames).map(Some)
    }

    /// The last orientation printed before line `line`.
    fn orientation_before(&self, line: usize) -> Option<&Orientation> {
        self.orientations().iter().rev().find(|o| o.line < line)
    }

    /// The orbitals the document shows (the last section of each spin), or why there are none.
    fn orbitals(&self, log: &LogLines) -> Result<Orbitals<'_>, ParseError> {
        let last = self.sections.last();
        let basis = self.bases.last();
        Ok(match (last, basis) {
            (None, None) => Orbitals::Missing(format!(
                "the log prints neither the basis set nor the orbitals (run Gaussian with `{ORBITAL_KEYWORDS}`)"
            )),
            (None, Some(_)) => Orbitals::Missing(
                "the log prints the basis set but not the orbitals (add `pop=full` to the route)".to_string(),
            ),
            (Some(_), None) => Orbitals::Missing(
                "the log prints the orbitals but not the basis set (add `gfinput` to the route)".to_string(),
            ),
            (Some(section), Some(&(basis_line, _))) => {
                if section.spin == Some(Spin::Alpha) {
                    return Err(log.error_at(
                        log.lines.len(),
                        format!("the beta orbitals after the alpha ones of line {}", section.line + 1),
                    ));
                }
                Orbitals::Read { section, basis_line }
            }
        })
    }

    /// The alpha (or restricted) section the beta `section` follows.
    fn alpha_of(&self, beta: &MoSection) -> Option<&MoSection> {
        self.sections.iter().rev().find(|s| s.line < beta.line && s.spin == Some(Spin::Alpha))
    }

    fn wavefunction_document(
        &self,
        log: &LogLines,
        geometry: &Orientation,
        last: &MoSection,
        basis_line: usize,
        overlap: Option<OverlapFn>,
    ) -> Result<Document, ParseError> {
        let file = log.file;
        let sections: Vec<&MoSection> = match last.spin {
            Some(Spin::Beta) => {
                let alpha = self.alpha_of(last).ok_or_else(|| {
                    log.error_at(last.line, "alpha orbitals (`Alpha Molecular Orbital Coefficients:`) before the beta")
                })?;
                vec![alpha, last]
            }
            _ => vec![last],
        };
        let printed = self.bases.iter().rev().find(|b| b.0 == basis_line).map_or(&[][..], |b| &b.1[..]);
        let atoms: Vec<Atom> = geometry
            .z
            .iter()
            .zip(&geometry.positions)
            .map(|(&z, &position)| Atom { z, charge: z as f64, position, ghost: z == 0 })
            .collect();
        let (basis, file_to_model) = self.basis(log, printed, &atoms, sections[0])?;
        let n = basis.n_functions();
        let unrestricted = sections.len() == 2;
        let mut orbitals = Vec::new();
        for section in &sections {
            if section.labels.len() != n {
                return Err(log.error_at(
                    section.line,
                    format!("{n} rows of coefficients (the basis set's functions) in the orbitals here"),
                ));
            }
            let spin = section.spin.unwrap_or(Spin::Alpha);
            for (i, o) in section.orbitals.iter().enumerate() {
                let mut coefficients = vec![0.0; n];
                for (k, &v) in o.coefficients.iter().enumerate() {
                    coefficients[file_to_model[k]] = v;
                }
                let occupied = o.occupied.unwrap_or_else(|| {
                    let (a, b) = self.electrons.unwrap_or((0, 0));
                    i < if spin == Spin::Beta { b } else { a }
                });
                let occupation = match (unrestricted, occupied) {
                    (_, false) => 0.0,
                    (true, true) => 1.0,
                    (false, true) => 2.0,
                };
                orbitals.push(MolecularOrbital {
                    energy: o.energy,
                    occupation,
                    spin,
                    symmetry: o.symmetry.clone(),
                    coefficients,
                });
            }
        }
        let digits = sections.iter().map(|s| s.decimals).min().unwrap_or(5);
        let wf = Wavefunction {
            basis,
            orbitals,
            restricted: !unrestricted,
            normalization: Default::default(),
            excited: None,
        };
        Ok(Document {
            source: file.to_string(),
            title: file.to_string(),
            molecule: Molecule::new(atoms),
            wavefunction: Some(check_printed(wf, "Gaussian", overlap, digits)),
            ..Default::default()
        })
    }

    /// The model's basis from the printed shells, pure or cartesian as the basis line and the
    /// orbital rows' labels say, and for each printed row its function in the model's order.
    fn basis(
        &self,
        log: &LogLines,
        printed: &[PrintedShell],
        atoms: &[Atom],
        section: &MoSection,
    ) -> Result<(Basis, Vec<usize>), ParseError> {
        let mut shells = Vec::new();
        let mut file_to_model = Vec::new();
        let mut row = 0;
        for p in printed {
            let atom = p.atom.checked_sub(1).filter(|&a| a < atoms.len()).ok_or_else(|| {
                log.error_at(p.line, format!("a shell on one of the {} atoms of the orientation", atoms.len()))
            })?;
            let parts: Vec<(u32, &[f64])> = if p.letters == "SP" {
                vec![(0, &p.coefficients[0][..]), (1, &p.coefficients[1][..])]
            } else {
                vec![(shell_l(&p.letters).unwrap_or(0), &p.coefficients[0][..])]
            };
            for (l, coefficients) in parts {
                let kind = if l < 2 {
                    ShellKind::Cartesian
                } else {
                    let label = section.labels.get(row).map_or("", |(_, s)| s.as_str());
                    self.shell_kind(log, l, label, section.labels.get(row).map(|r| r.0))?
                };
                let shell = Shell {
                    atom,
                    center: atoms[atom].position,
                    l,
                    kind,
                    exponents: p.exponents.clone(),
                    coefficients: coefficients.to_vec(),
                };
                let first = file_to_model.len();
                let count = shell.n_functions();
                if kind == ShellKind::Cartesian && l >= 2 {
                    let order = super::fchk::gaussian_cartesian_order(l);
                    file_to_model.extend(to_model_order(&order).into_iter().map(|k| first + k));
                } else {
                    file_to_model.extend(first..first + count);
                }
                row += count;
                shells.push(shell);
            }
        }
        Ok((Basis { shells }, file_to_model))
    }

    /// Whether a shell of `l` ≥ 2 is pure or cartesian: its first row's label (`3D 0` pure,
    /// `3XX` cartesian), which must agree with the basis line's `(5D, 7F)` when there is one.
    fn shell_kind(&self, log: &LogLines, l: u32, label: &str, row: Option<usize>) -> Result<ShellKind, ParseError> {
        let component = label.trim_start_matches(|c: char| c.is_ascii_digit());
        let from_label = if !component.is_empty() && component.chars().all(|c| matches!(c, 'X' | 'Y' | 'Z')) {
            Some(ShellKind::Cartesian)
        } else if component.starts_with(shell_letter(l)) {
            Some(ShellKind::Pure)
        } else {
            None
        };
        let from_line = self.cartesian.map(|(d, f, line)| {
            let cartesian = if l == 2 { d } else { f };
            (if cartesian { ShellKind::Cartesian } else { ShellKind::Pure }, line)
        });
        match (from_label, from_line, row) {
            (Some(a), Some((b, line)), Some(row)) if a != b => Err(log.error_at(
                row,
                format!(
                    "a {} {} function, as the basis line {} says",
                    if b == ShellKind::Pure { "pure" } else { "cartesian" },
                    shell_letter(l),
                    line + 1
                ),
            )),
            (Some(kind), _, _) => Ok(kind),
            (None, Some((kind, _)), _) => Ok(kind),
            (None, None, row) => Err(log.error_at(
                row.unwrap_or(log.lines.len()),
                format!(
                    "the label of a {} function (`{}0` pure or cartesian letters)",
                    shell_letter(l),
                    shell_letter(l)
                ),
            )),
        }
    }
}

enum Orbitals<'a> {
    Read { section: &'a MoSection, basis_line: usize },
    Missing(String),
}

/// Letters of shells by l, as Gaussian names them.
const SHELL_LETTERS: &str = "SPDFGHI";

fn shell_letter(l: u32) -> char {
    SHELL_LETTERS.chars().nth(l as usize).unwrap_or('?')
}

fn shell_l(letters: &str) -> Option<u32> {
    let mut chars = letters.chars();
    let c = chars.next()?;
    if chars.next().is_some() {
        return None;
    }
    SHELL_LETTERS.find(c).map(|l| l as u32).filter(|&l| l <= MAX_L)
}

/// The route section: from its `#` line up to the dashes, lines joined as Gaussian wrapped them.
fn route(log: &LogLines, first: usize) -> String {
    let mut s = String::new();
    for l in log.lines.iter().skip(first).take(20) {
        if l.trim_start().starts_with("---") {
            break;
        }
        s.push_str(l.strip_prefix(' ').unwrap_or(l));
    }
    s.trim().to_string()
}

/// Whether a line of the echoed ModRedundant section names a coordinate: a type letter (`B`,
/// `A`, `D`, `L`, `O`, `X`) or an atom number (or `*`) first. Gaussian echoes the type letter
/// even where the input left it out (`10 9 4 3 S 12 30.0` is echoed `D 3 4 9 10 S 12 30.000`).
fn is_modredundant_line(line: &str) -> bool {
    let Some(first) = line.split_whitespace().next() else { return false };
    matches!(first.to_ascii_uppercase().as_str(), "B" | "A" | "D" | "L" | "O" | "X" | "*")
        || first.parse::<usize>().is_ok()
}

/// A ModRedundant line at `i`: the coordinate and its number of steps when it is scanned (`S
/// steps size`), `None` for any other action (frozen, added, removed …).
///
/// ```text
///  D       3       4       9      10 S  12 30.000      type, atoms, `S`, steps, step size
///  B 1 2 F                                             another action: no scan
/// ```
fn modredundant_line(log: &LogLines, i: usize) -> Result<Option<(Coordinate, usize)>, ParseError> {
    const SCAN: &str = "a scanned coordinate `B i j S steps size` (or `A i j k`, `D i j k l`)";
    let t: Vec<&str> = log.lines[i].split_whitespace().collect();
    let Some(s) = t.iter().position(|w| w.eq_ignore_ascii_case("S")) else { return Ok(None) };
    let kind = t[0].to_ascii_uppercase();
    let typed = kind.parse::<usize>().is_err() && kind != "*";
    // Atom numbers, then any values given before the action.
    let fields = &t[usize::from(typed)..s];
    let atoms: Vec<usize> = fields.iter().map_while(|w| w.parse::<usize>().ok()).collect();
    if atoms.contains(&0) || fields.contains(&"*") {
        return Err(log.error_at(i, format!("{SCAN}: atoms numbered from 1, no `*`")));
    }
    let expected = match kind.as_str() {
        "B" => Some(2),
        "A" => Some(3),
        "D" => Some(4),
        _ if !typed => None,
        _ => return Err(log.error_at(i, format!("{SCAN}: only bonds, angles and dihedrals are scanned here"))),
    };
    let n = expected.unwrap_or(atoms.len());
    if atoms.len() != n || !(2..=4).contains(&n) {
        return Err(log.error_at(i, format!("{SCAN}: {n} atom numbers")));
    }
    let steps = t.get(s + 1).and_then(|w| w.parse::<usize>().ok()).filter(|&n| n > 0);
    let size = t.get(s + 2).and_then(|w| parse_real(w)).filter(|v| v.is_finite() && *v != 0.0);
    let (Some(steps), Some(_)) = (steps, size) else {
        return Err(log.error_at(i, format!("{SCAN}: `S`, a number of steps and a step size")));
    };
    let a = |k: usize| atoms[k] - 1;
    let coordinate = match n {
        2 => Coordinate::Distance([a(0), a(1)]),
        3 => Coordinate::Angle([a(0), a(1), a(2)]),
        _ => Coordinate::Dihedral([a(0), a(1), a(2), a(3)]),
    };
    Ok(Some((coordinate, steps)))
}

/// `(d cartesian, f and up cartesian)` from a basis line's "(5D, 7F)".
fn basis_kinds(line: &str) -> Option<(bool, bool)> {
    let inside = line.rsplit_once('(')?.1.split_once(')')?.0;
    let mut parts = inside.split(',').map(str::trim);
    let d = match parts.next()? {
        "5D" => false,
        "6D" => true,
        _ => return None,
    };
    let f = match parts.next()? {
        "7F" => false,
        "10F" => true,
        _ => return None,
    };
    Some((d, f))
}

fn is_dashes(line: &str) -> bool {
    let t = line.trim();
    t.len() >= 10 && t.bytes().all(|b| b == b'-')
}

/// An orientation table at line `header`; returns it and the line after it.
fn orientation(log: &LogLines, header: usize) -> Result<(Orientation, usize), ParseError> {
    const TABLE: &str = "an orientation table: dashes, two heading lines, dashes, then `center Z type x y z` rows";
    let mut i = header + 1;
    let mut dashes = 0;
    while dashes < 2 {
        let l = log.get(i, TABLE)?;
        if is_dashes(l) {
            dashes += 1;
        } else if dashes == 0 || i > header + 5 {
            return Err(log.error_at(i, TABLE));
        }
        i += 1;
    }
    let mut o = Orientation { line: header, z: Vec::new(), positions: Vec::new() };
    loop {
        let l = log.get(i, "the dashes that close the orientation table")?;
        if is_dashes(l) {
            break;
        }
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `center  atomic-number  [type]  x y z` (Å)";
        if !(5..=6).contains(&t.len()) {
            return Err(log.error_at(i, row));
        }
        let z: u32 = t[1]
            .parse()
            .ok()
            .filter(|&z| z <= MAX_Z)
            .ok_or_else(|| log.error_at(i, format!("an atomic number 0..={MAX_Z} in the second column")))?;
        let xyz: Option<Vec<f64>> = t[t.len() - 3..].iter().map(|v| parse_real(v)).collect();
        let xyz = xyz.ok_or_else(|| log.error_at(i, row))?;
        o.z.push(z);
        o.positions.push(DVec3::new(xyz[0], xyz[1], xyz[2]) * BOHR_PER_ANGSTROM);
        i += 1;
    }
    if o.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the orientation table"));
    }
    Ok((o, i + 1))
}

/// The `gfinput` section at line `header`: per atom `N 0`, its shells, `****`.
fn general_basis(log: &LogLines, header: usize) -> Result<(Vec<PrintedShell>, usize), ParseError> {
    let mut shells = Vec::new();
    let mut i = header + 1;
    while let Some(l) = log.lines.get(i) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let atom = match t[..] {
            [a, "0"] => a.parse::<usize>().ok(),
            _ => None,
        };
        let Some(atom) = atom else { break };
        i += 1;
        loop {
            let l = log.get(i, "a shell line `S 3 1.00` or `****`")?;
            if l.trim() == "****" {
                i += 1;
                break;
            }
            let t: Vec<&str> = l.split_whitespace().collect();
            let shell = "a shell line `S|SP|P|D|F|G|H  primitives  scale` or `****`";
            let letters = t.first().map(|s| s.to_ascii_uppercase()).unwrap_or_default();
            let columns = if letters == "SP" { 2 } else { 1 };
            if letters != "SP" && shell_l(&letters).is_none() {
                return Err(log.error_at(i, shell));
            }
            let count: usize = t.get(1).and_then(|n| n.parse().ok()).ok_or_else(|| log.error_at(i, shell))?;
            let scale = t.get(2).and_then(|v| parse_real(v)).filter(|&v| v > 0.0).unwrap_or(1.0);
            if count == 0 {
                return Err(log.error_at(i, "a shell of at least one primitive"));
            }
            let mut p =
                PrintedShell { line: i, atom, letters, exponents: Vec::new(), coefficients: vec![Vec::new(); columns] };
            for _ in 0..count {
                i += 1;
                let expected = format!("a primitive `exponent coefficient{}`", if columns == 2 { "s" } else { "" });
                let l = log.get(i, &expected)?;
                let v: Option<Vec<f64>> = l.split_whitespace().map(parse_real).collect();
                let v = v.filter(|v| v.len() == 1 + columns && v[0] > 0.0).ok_or_else(|| log.error_at(i, expected))?;
                p.exponents.push(v[0] * scale * scale);
                for (c, column) in p.coefficients.iter_mut().enumerate() {
                    column.push(v[1 + c]);
                }
            }
            shells.push(p);
            i += 1;
        }
    }
    if shells.is_empty() {
        return Err(log.error_at(header + 1, "an atom line `N 0` opening the basis set"));
    }
    Ok((shells, i))
}

/// The spin of a molecular-orbital section's header; `Some(None)` when restricted.
fn mo_header(t: &str) -> Option<Option<Spin>> {
    match t.trim_end() {
        "Molecular Orbital Coefficients:" => Some(None),
        "Alpha Molecular Orbital Coefficients:" => Some(Some(Spin::Alpha)),
        "Beta Molecular Orbital Coefficients:" => Some(Some(Spin::Beta)),
        _ => None,
    }
}

/// Width of Gaussian's `F10.5` orbital columns.
const COLUMN: usize = 10;

/// A section of orbitals at line `header`: blocks of up to 5 orbitals until a line that opens
/// no block. Every block must have as many rows as the first.
fn mo_section(log: &LogLines, header: usize, spin: Option<Spin>) -> Result<(MoSection, usize), ParseError> {
    let mut section = MoSection { line: header, spin, labels: Vec::new(), orbitals: Vec::new(), decimals: 5 };
    let mut i = header + 1;
    let mut first_decimals = None;
    while let Some(numbers) = log.lines.get(i).and_then(|l| column_numbers(l)) {
        let block = i;
        let k = numbers.len();
        if numbers[0] != section.orbitals.len() + 1 {
            // Numbers that do not continue the orbitals belong to what follows the section.
            break;
        }
        i += 1;
        let mut occupied = vec![None; k];
        let mut symmetry = vec![String::new(); k];
        let l = log.get(i, "`Eigenvalues --` or the orbitals' occupations")?;
        if !l.contains("Eigenvalues") {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.len() != k {
                return Err(log.error_at(i, format!("{k} occupations (`O` or `V`, after a symmetry)")));
            }
            for (c, w) in t.iter().enumerate() {
                occupied[c] = match w.chars().last() {
                    Some('O') => Some(true),
                    Some('V') => Some(false),
                    _ => return Err(log.error_at(i, format!("{k} occupations (`O` or `V`, after a symmetry)"))),
                };
                symmetry[c] = w.split_once(')').map_or("", |s| s.0).trim_start_matches('(').to_string();
            }
            i += 1;
        }
        let l = log.get(i, "`Eigenvalues --`")?;
        let energies = l
            .split_once("--")
            .filter(|(head, _)| head.contains("Eigenvalues"))
            .and_then(|(_, rest)| trailing_numbers(rest, k, COLUMN))
            .map(|(v, _)| v)
            .ok_or_else(|| log.error_at(i, format!("`Eigenvalues --` and {k} energies")))?;
        i += 1;
        let rows_before = section.labels.len();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            let head: Vec<&str> = head.split_whitespace().collect();
            // A row: its number, the atom's number and symbol on its first function, the label.
            let Some(label_at) = (match head[..] {
                [n, ..] if n.parse::<usize>().is_err() => None,
                [_, a, s, _, ..] if a.parse::<usize>().is_ok() && s.chars().all(|c| c.is_ascii_alphabetic()) => Some(3),
                [_, _, ..] => Some(1),
                _ => None,
            }) else {
                break;
            };
            let label: String = head[label_at..].concat().to_ascii_uppercase();
            if first_decimals.is_none() {
                let digits = l.split_whitespace().last().and_then(decimals);
                first_decimals = digits;
            }
            if rows_before == 0 {
                section.labels.push((i, label));
            } else if section.labels.get(row).is_none_or(|(_, known)| *known != label) {
                let expected = match section.labels.get(row) {
                    Some((_, known)) => format!("row {} labelled {known}, as in the first block", row + 1),
                    None => format!("{} rows, as in the first block", section.labels.len()),
                };
                return Err(log.error_at(i, expected));
            }
            for (c, v) in values.into_iter().enumerate() {
                columns[c].push(v);
            }
            row += 1;
            i += 1;
        }
        log.block_rows(i, row, (rows_before > 0).then_some(rows_before), (numbers[0], numbers[k - 1]), block)?;
        for (c, coefficients) in columns.into_iter().enumerate() {
            section.orbitals.push(PrintedOrbital {
                energy: energies[c],
                occupied: occupied[c],
                symmetry: std::mem::take(&mut symmetry[c]),
                coefficients,
            });
        }
    }
    if section.orbitals.is_empty() {
        return Err(log.error_at(i, "a block of orbitals: their numbers `1 2 3 4 5`"));
    }
    section.decimals = first_decimals.unwrap_or(5);
    Ok((section, i))
}

/// A `Harmonic frequencies` section at line `header`: its modes, whether they are the
/// high-precision ones (`freq=hpmodes`, `Frequencies ---`), and the line after it.
fn frequencies(log: &LogLines, header: usize) -> Result<(Vec<NormalMode>, bool, usize), ParseError> {
    let mut modes: Vec<NormalMode> = Vec::new();
    let mut hp = false;
    let mut i = header + 1;
    // The header's own continuation lines, then blocks: numbers, symmetries, values, a table.
    while i < log.lines.len() && i < header + 6 && column_numbers(log.lines[i]).is_none() {
        i += 1;
    }
    while let Some(numbers) = log.lines.get(i).and_then(|l| column_numbers(l)) {
        let k = numbers.len();
        let block = i;
        i += 1;
        let mut freqs = None;
        let mut intensities = None;
        // Up to the displacement table's heading.
        loop {
            let l = log.get(i, "the displacement table's heading (`Atom  AN  X  Y  Z` or `Coord Atom Element:`)")?;
            let t = l.trim_start();
            if t.starts_with("Atom") || t.starts_with("Coord Atom") {
                hp = t.starts_with("Coord");
                i += 1;
                break;
            }
            if let Some((name, rest)) = t.split_once("--") {
                let rest = rest.trim_start_matches('-');
                let values: Option<Vec<f64>> = rest.split_whitespace().map(parse_real).collect();
                let values = values.filter(|v| v.len() == k);
                if name.starts_with("Frequencies") {
                    freqs = Some(values.ok_or_else(|| log.error_at(i, format!("{k} frequencies")))?);
                } else if name.starts_with("IR Inten") {
                    intensities = Some(values.ok_or_else(|| log.error_at(i, format!("{k} IR intensities")))?);
                }
            }
            i += 1;
            if i > block + 20 {
                return Err(log.error_at(i, "the displacement table within 20 lines of the block's numbers"));
            }
        }
        let freqs = freqs.ok_or_else(|| log.error_at(block, "a `Frequencies --` line in the block"))?;
        let mut displacement = vec![Vec::new(); k];
        while let Some(l) = log.lines.get(i) {
            let t: Vec<&str> = l.split_whitespace().collect();
            if hp {
                // `coord atom Z  v…`: x, y, z rows of each atom.
                if t.len() != 3 + k || t[..3].iter().any(|w| w.parse::<usize>().is_err()) {
                    break;
                }
                let coord: usize = t[0].parse().unwrap_or(0);
                let v: Option<Vec<f64>> = t[3..].iter().map(|w| parse_real(w)).collect();
                let v = v.ok_or_else(|| log.error_at(i, format!("{k} displacements")))?;
                for (c, d) in displacement.iter_mut().enumerate() {
                    match coord {
                        1 => d.push(DVec3::new(v[c], 0.0, 0.0)),
                        2 | 3 => {
                            let last = d.last_mut().ok_or_else(|| log.error_at(i, "the atom's x row first"))?;
                            last[coord - 1] = v[c];
                        }
                        _ => return Err(log.error_at(i, "a coordinate 1, 2 or 3")),
                    }
                }
            } else {
                // `atom Z  x y z  x y z …`.
                if t.len() != 2 + 3 * k || t[..2].iter().any(|w| w.parse::<usize>().is_err()) {
                    break;
                }
                let v: Option<Vec<f64>> = t[2..].iter().map(|w| parse_real(w)).collect();
                let v = v.ok_or_else(|| log.error_at(i, format!("{} displacements", 3 * k)))?;
                for (c, d) in displacement.iter_mut().enumerate() {
                    d.push(DVec3::new(v[3 * c], v[3 * c + 1], v[3 * c + 2]));
                }
            }
            i += 1;
        }
        for (c, displacement) in displacement.into_iter().enumerate() {
            modes.push(NormalMode {
                frequency_cm1: freqs[c],
                ir_intensity: intensities.as_ref().map(|v| v[c]),
                displacement,
            });
        }
    }
    Ok((modes, hp, i))
}

/// The modes of the section at line `line`, at the last orientation printed before it.
fn vibrations(
    log: &LogLines,
    line: usize,
    modes: &[NormalMode],
    orientations: &[Orientation],
) -> Result<Vibrations, ParseError> {
    let geometry = orientations
        .iter()
        .rev()
        .find(|o| o.line < line)
        .ok_or_else(|| log.error_at(line, "an orientation of the atoms before the normal modes"))?;
    if let Some(m) = modes.iter().find(|m| m.displacement.len() != geometry.z.len()) {
        return Err(log.error_at(
            line,
            format!(
                "a displacement for each of the {} atoms of the orientation at line {} ({} found at {:.2} cm⁻¹)",
                geometry.z.len(),
                geometry.line + 1,
                m.displacement.len(),
                m.frequency_cm1
            ),
        ));
    }
    Ok(Vibrations {
        modes: modes.to_vec(),
        geometry: geometry.positions.clone(),
        geometry_from: format!("the orientation at line {}", geometry.line + 1),
    })
}

#[cfg(test)]
#[path = "gaussian_log_tests.rs"]
mod tests;
