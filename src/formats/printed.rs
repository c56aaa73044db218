//! Orbitals as program logs print them (GAMESS, NWChem, Psi4, Q-Chem): a basis set shell by
//! shell per atom, and rows of coefficients, one per basis function, each naming its atom and
//! function. Each reader turns its own layout into these; [`document`] takes the rows into the
//! model's function order, shell by shell, checking that every row belongs to the atom and the
//! shell the printed basis says, and measures CᵀSC − I ([`check_printed`]).

use super::ParseError;
use super::logs::{Geometry, LogLines};
use super::wavefunction::{OverlapFn, check_printed};
use crate::model::basis::{Basis, Shell, ShellKind, cartesian_powers};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::{Atom, Document, Molecule};

/// A shell as printed: angular momentum, exponents, coefficients (for normalised primitives).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PrintedShell {
    pub l: u32,
    pub exponents: Vec<f64>,
    pub coefficients: Vec<f64>,
}

/// A shell read primitive by primitive (GAMESS, NWChem print one primitive a line): its number
/// as printed, its type (`S`, `P`, … or `L`/`SP`), its exponents and coefficient columns.
#[derive(Debug, Clone, Default)]
pub(crate) struct OpenShell {
    pub number: String,
    pub kind: String,
    pub exponents: Vec<f64>,
    pub columns: Vec<Vec<f64>>,
}

impl OpenShell {
    /// Its shells: an `L` or `SP` shell is an s and a p shell sharing the exponents.
    pub fn finish(self) -> Vec<PrintedShell> {
        let ls: Vec<u32> = if self.kind == "L" || self.kind == "SP" {
            vec![0, 1]
        } else {
            vec![LETTERS.to_ascii_uppercase().find(self.kind.as_str()).unwrap_or(0) as u32]
        };
        ls.into_iter()
            .enumerate()
            .map(|(k, l)| PrintedShell {
                l,
                exponents: self.exponents.clone(),
                coefficients: self.columns.iter().map(|c| c.get(k).copied().unwrap_or(0.0)).collect(),
            })
            .collect()
    }
}

/// Atoms' names (or tags) with their shells.
pub(crate) type NamedShells = Vec<(String, Vec<PrintedShell>)>;

/// One row of coefficients: its 0-based line, atom (0-based) and function label as printed.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub line: usize,
    pub atom: usize,
    pub label: String,
}

#[derive(Debug, Clone)]
pub(crate) struct Orbital {
    pub energy: f64,
    pub occupation: f64,
    pub spin: Spin,
    pub symmetry: String,
    /// In the rows' order.
    pub coefficients: Vec<f64>,
}

/// An orbital section: its header's 0-based line, its rows, its orbitals (alpha then beta) and
/// the decimals its coefficients are printed to.
#[derive(Debug, Clone, Default)]
pub(crate) struct Section {
    pub line: usize,
    pub rows: Vec<Row>,
    pub orbitals: Vec<Orbital>,
    pub decimals: u32,
}

impl Section {
    /// Takes a block's row `new` (number `row` of the block at line `header`'s section) and its
    /// coefficients, one per column: the first block sets the rows, every later one must repeat
    /// them (the same atom and label) or the file is refused at the row's line.
    pub(crate) fn take_row(
        &mut self,
        log: &LogLines,
        (header, row, first_block): (usize, usize, bool),
        new: Row,
        values: Vec<f64>,
        columns: &mut [Vec<f64>],
    ) -> Result<(), ParseError> {
        if first_block {
            self.rows.push(new);
        } else if self.rows.get(row).is_none_or(|r| r.atom != new.atom || r.label != new.label) {
            return Err(log.error_at(new.line, format!("row {} as in the first block (line {})", row + 1, header + 1)));
        }
        for (column, v) in columns.iter_mut().zip(values) {
            column.push(v);
        }
        Ok(())
    }
}

/// How a program names a shell's functions: for a row's label and the shell's l, the shell's
/// kind and the function's index within the shell in the model's order; `None` when the label
/// names no function of such a shell.
pub(crate) type FunctionOf<'a> = &'a dyn Fn(&str, u32) -> Option<(ShellKind, usize)>;

/// Letters of shells by l.
pub(crate) const LETTERS: &str = "spdfgh";

/// The letter of a shell of `l` ("?" past h).
pub(crate) fn letter(l: u32) -> char {
    LETTERS.chars().nth(l as usize).unwrap_or('?')
}

/// The index in the model's order of the cartesian component `letters` ("xxy", any order and
/// case) of a shell of `l`.
pub(crate) fn cartesian_index(letters: &str, l: u32) -> Option<usize> {
    let letters = letters.to_ascii_lowercase();
    if letters.len() != l as usize || !letters.chars().all(|c| matches!(c, 'x' | 'y' | 'z')) {
        return None;
    }
    let count = |ch| letters.chars().filter(|&c| c == ch).count() as u32;
    let p = [count('x'), count('y'), count('z')];
    cartesian_powers(l).iter().position(|q| *q == p)
}

/// The index in the model's pure order (m = 0, +1, −1, +2, −2, …) of the function m.
pub(crate) fn pure_index(m: i32) -> usize {
    match m {
        0 => 0,
        m if m > 0 => 2 * m as usize - 1,
        m => 2 * m.unsigned_abs() as usize,
    }
}

/// Occupations filled from the bottom: a restricted set holds 2 in the first `beta` orbitals and
/// 1 in the next `alpha − beta`; an unrestricted spin holds 1 in its first electrons' worth.
pub(crate) fn aufbau(index: usize, spin: Spin, restricted: bool, (alpha, beta): (usize, usize)) -> f64 {
    match (restricted, spin) {
        (true, _) if index < beta => 2.0,
        (true, _) if index < alpha => 1.0,
        (false, Spin::Alpha) if index < alpha => 1.0,
        (false, Spin::Beta) if index < beta => 1.0,
        _ => 0.0,
    }
}

/// The atoms of a printed geometry.
pub(crate) fn atoms(geometry: &Geometry) -> Vec<Atom> {
    geometry
        .z
        .iter()
        .zip(&geometry.positions)
        .map(|(&z, &position)| Atom { z, charge: z as f64, position, ghost: z == 0 })
        .collect()
}

/// The document of a log's printed orbitals: `shells[a]` are atom `a`'s shells in the order its
/// rows list their functions, `function_of` reads the rows' labels; `program` names the writer.
pub(crate) fn document(
    log: &LogLines,
    program: &str,
    geometry: &Geometry,
    shells: &[Vec<PrintedShell>],
    section: &Section,
    function_of: FunctionOf,
    overlap: Option<OverlapFn>,
) -> Result<Document, ParseError> {
    let atoms = atoms(geometry);
    let mut model_shells = Vec::new();
    // For each printed row, its function in the model's order.
    let mut file_to_model = Vec::with_capacity(section.rows.len());
    for (a, (atom, printed)) in atoms.iter().zip(shells).enumerate() {
        for p in printed {
            let first = file_to_model.len();
            let want = || {
                format!(
                    "a {} function of atom {} ({}), as the printed basis set says",
                    letter(p.l),
                    a + 1,
                    atom.element().symbol
                )
            };
            let Some(row) = section.rows.get(first) else {
                return Err(log.error_at(
                    section.line,
                    format!("{} rows of coefficients or more (the printed basis set's functions)", first + 1),
                ));
            };
            let Some((kind, _)) = function_of(&row.label, p.l).filter(|_| row.atom == a) else {
                return Err(log.error_at(row.line, want()));
            };
            let shell = Shell {
                atom: a,
                center: atom.position,
                l: p.l,
                kind,
                exponents: p.exponents.clone(),
                coefficients: p.coefficients.clone(),
            };
            let n = shell.n_functions();
            let mut seen = vec![false; n];
            for k in 0..n {
                let Some(row) = section.rows.get(first + k) else {
                    return Err(log.error_at(
                        section.line,
                        format!("{} rows of coefficients or more (the printed basis set's functions)", first + k + 1),
                    ));
                };
                let index = function_of(&row.label, p.l)
                    .filter(|&(kind_k, i)| row.atom == a && kind_k == kind && i < n && !seen[i])
                    .map(|(_, i)| i)
                    .ok_or_else(|| log.error_at(row.line, want()))?;
                seen[index] = true;
                file_to_model.push(model_shells_offset(&model_shells) + index);
            }
            model_shells.push(shell);
        }
    }
    let n = file_to_model.len();
    if section.rows.len() != n {
        let at = section.rows.get(n).map_or(section.line, |r| r.line);
        return Err(log.error_at(at, format!("{n} rows of coefficients (the printed basis set's functions)")));
    }
    if section.orbitals.iter().any(|o| o.coefficients.len() != n) {
        return Err(log.error_at(section.line, format!("{n} coefficients in every orbital")));
    }
    let orbitals = section
        .orbitals
        .iter()
        .map(|o| {
            let mut coefficients = vec![0.0; n];
            for (&v, &k) in o.coefficients.iter().zip(&file_to_model) {
                coefficients[k] = v;
            }
            MolecularOrbital {
                energy: o.energy,
                occupation: o.occupation,
                spin: o.spin,
                symmetry: o.symmetry.clone(),
                coefficients,
            }
        })
        .collect();
    Ok(log_document(log, program, atoms, Basis { shells: model_shells }, orbitals, overlap, section.decimals))
}

/// A log's document: its atoms and the wavefunction of `basis` and `orbitals` (restricted when
/// every orbital is alpha) as `program` printed it to `decimals`, checked with `overlap`.
pub(crate) fn log_document(
    log: &LogLines,
    program: &str,
    atoms: Vec<Atom>,
    basis: Basis,
    orbitals: Vec<MolecularOrbital>,
    overlap: Option<OverlapFn>,
    decimals: u32,
) -> Document {
    let restricted = orbitals.iter().all(|o| o.spin == Spin::Alpha);
    let wf = Wavefunction { basis, orbitals, restricted, normalization: Default::default(), excited: None };
    Document {
        source: log.file.to_string(),
        title: log.file.to_string(),
        molecule: Molecule::new(atoms),
        wavefunction: Some(check_printed(wf, program, overlap, decimals)),
        ..Default::default()
    }
}

fn model_shells_offset(shells: &[Shell]) -> usize {
    shells.iter().map(Shell::n_functions).sum()
}

/// The element of an atom row that prints the nuclear `charge` and a `name`: the charge when
/// it is an element's, else (a pseudopotential's reduced charge, a ghost's 0) the element the
/// name starts with ("CL1" → Cl, "C12" → C); 0 when neither tells.
pub(crate) fn element_of(charge: f64, name: &str) -> u32 {
    let charge = charge.round();
    if (1.0..=super::MAX_Z as f64).contains(&charge) {
        return charge as u32;
    }
    let letters: String = name.chars().take_while(char::is_ascii_alphabetic).collect();
    atomic_number(&letters).or_else(|| atomic_number(&letters[..letters.len().min(1)])).unwrap_or(0)
}

/// A block's header: the orbitals' numbers (from 1), one after another.
pub(crate) fn column_numbers(line: &str) -> Option<Vec<usize>> {
    let n: Option<Vec<usize>> = line.split_whitespace().map(|t| t.parse().ok()).collect();
    n.filter(|n| !n.is_empty() && n.windows(2).all(|w| w[1] == w[0] + 1))
}

/// The next block of printed orbital columns at or after line `i` (blank lines skipped): the
/// line that numbers its columns and their numbers, when they continue the `done` orbitals
/// already read (the first column numbered `done + 1`); `None` ends the section.
pub(crate) fn next_block(log: &LogLines, mut i: usize, done: usize) -> Option<(usize, Vec<usize>)> {
    while log.lines.get(i).is_some_and(|l| l.trim().is_empty()) {
        i += 1;
    }
    let numbers = log.lines.get(i).and_then(|l| column_numbers(l))?;
    (numbers[0] == done + 1).then_some((i, numbers))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_map_into_the_models_order() {
        assert_eq!(cartesian_index("X", 1), Some(0));
        assert_eq!(cartesian_index("z", 1), Some(2));
        assert_eq!(cartesian_index("YX", 2), Some(1));
        assert_eq!(cartesian_index("zz", 2), Some(5));
        assert_eq!(cartesian_index("xyz", 2), None);
        assert_eq!([0, 1, -1, 2, -2].map(pure_index), [0, 1, 2, 3, 4]);
        assert_eq!(aufbau(34, Spin::Alpha, true, (35, 35)), 2.0);
        assert_eq!(aufbau(35, Spin::Alpha, true, (36, 35)), 1.0);
        assert_eq!(aufbau(35, Spin::Beta, false, (36, 35)), 0.0);
    }
}
