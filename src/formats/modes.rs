//! Normal modes as files write them: Molden's `[FREQ]`, `[FR-COORD]`, `[FR-NORM-COORD]` and
//! `[INT]` sections, and Gaussian fchk's `Vib-E2` and `Vib-Modes` records. A malformed mode
//! section is an error naming its line; the reader keeps the rest of the file.

use glam::DVec3;

use super::ParseError;
use super::text::{excerpt, parse_real};
use crate::model::vibrations::{NormalMode, Vibrations};

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// The mode sections of a Molden file as written: each value with its 1-based line.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MoldenModes {
    /// `[FREQ]`: one wavenumber per line, and the header's line.
    pub frequencies: Vec<(usize, f64)>,
    pub freq_line: usize,
    /// `[FR-COORD]`: the geometry of the modes (bohr), and the header's line.
    pub coords: Vec<(usize, DVec3)>,
    pub coord_line: usize,
    /// `[FR-NORM-COORD]`: each `vibration N` block's line and displacements, and the header's line.
    pub vectors: Vec<(usize, Vec<DVec3>)>,
    pub norm_line: usize,
    /// `[INT]`: each mode's IR intensity, and the header's line.
    pub intensities: Vec<(usize, f64)>,
    pub int_line: usize,
}

/// The numbers of a line (D exponents allowed), or `None` when one is not a number.
fn numbers(tokens: &[&str]) -> Option<Vec<f64>> {
    tokens.iter().map(|t| parse_real(t)).collect()
}

/// The first number of each line of `body` (index, text), with its 1-based line.
fn first_numbers<'a>(
    file: &str,
    body: impl Iterator<Item = (usize, &'a &'a str)>,
    expected: &str,
) -> Result<Vec<(usize, f64)>, ParseError> {
    body.map(|(k, l)| {
        let first = l.split_whitespace().next().and_then(parse_real).filter(|v| v.is_finite());
        first.map(|v| (k + 1, v)).ok_or_else(|| error(file, k + 1, expected, excerpt(l)))
    })
    .collect()
}

impl MoldenModes {
    /// Reads mode section `name` (lower case) whose header is line `header` (1-based) and whose
    /// body is `lines[start..end]`; other sections are no business of it.
    pub fn read(
        &mut self,
        file: &str,
        name: &str,
        header: usize,
        lines: &[&str],
        (start, end): (usize, usize),
    ) -> Result<(), ParseError> {
        let body = lines.iter().enumerate().take(end).skip(start).filter(|(_, l)| !l.trim().is_empty());
        match name {
            "freq" => {
                self.freq_line = header;
                self.frequencies = first_numbers(file, body, "a wavenumber in cm⁻¹")?;
            }
            "fr-coord" => {
                self.coord_line = header;
                for (k, l) in body {
                    let t: Vec<&str> = l.split_whitespace().collect();
                    let xyz = (t.len() == 4).then(|| numbers(&t[1..])).flatten();
                    let xyz = xyz.ok_or_else(|| error(file, k + 1, "an atom `symbol x y z` (bohr)", excerpt(l)))?;
                    self.coords.push((k + 1, DVec3::new(xyz[0], xyz[1], xyz[2])));
                }
            }
            "fr-norm-coord" => {
                self.norm_line = header;
                for (k, l) in body {
                    let t: Vec<&str> = l.split_whitespace().collect();
                    if t[0].eq_ignore_ascii_case("vibration") {
                        self.vectors.push((k + 1, Vec::new()));
                        continue;
                    }
                    let Some(block) = self.vectors.last_mut() else {
                        return Err(error(file, k + 1, "a `vibration N` line", excerpt(l)));
                    };
                    let d = (t.len() == 3).then(|| numbers(&t)).flatten();
                    let d = d.ok_or_else(|| error(file, k + 1, "a displacement `dx dy dz`", excerpt(l)))?;
                    block.1.push(DVec3::new(d[0], d[1], d[2]));
                }
            }
            "int" => {
                self.int_line = header;
                // A Raman activity may follow in a second column.
                self.intensities = first_numbers(file, body, "an IR intensity in km/mol")?;
            }
            _ => {}
        }
        Ok(())
    }

    /// The modes of a molecule of `atoms` (its positions, bohr); `None` when the file has no
    /// `[FREQ]` section. Counts that do not match are errors naming the line.
    pub fn into_vibrations(self, file: &str, atoms: &[DVec3]) -> Result<Option<Vibrations>, ParseError> {
        if self.freq_line == 0 {
            return Ok(None);
        }
        let n = self.frequencies.len();
        if self.norm_line == 0 {
            return Err(error(file, self.freq_line, "an [FR-NORM-COORD] section for the [FREQ] modes", "none"));
        }
        if self.vectors.len() != n {
            let found = format!("{} vibration blocks", self.vectors.len());
            return Err(error(file, self.norm_line, format!("{n} vibration blocks, one per [FREQ] line"), found));
        }
        for (line, d) in &self.vectors {
            if d.len() != atoms.len() {
                let found = format!("{} displacement lines", d.len());
                return Err(error(file, *line, format!("{} displacement lines, one per atom", atoms.len()), found));
            }
        }
        if self.coord_line > 0 && self.coords.len() != atoms.len() {
            let found = format!("{} atoms", self.coords.len());
            return Err(error(file, self.coord_line, format!("{} atoms, as in [Atoms]", atoms.len()), found));
        }
        if self.int_line > 0 && self.intensities.len() != n {
            let found = format!("{} intensities", self.intensities.len());
            return Err(error(file, self.int_line, format!("{n} intensities, one per [FREQ] line"), found));
        }
        let (geometry, geometry_from) = match self.coord_line {
            0 => (atoms.to_vec(), "the molecule's (no [FR-COORD])".to_string()),
            _ => (self.coords.iter().map(|c| c.1).collect(), "[FR-COORD]".to_string()),
        };
        let modes = (self.frequencies.iter().zip(self.vectors))
            .enumerate()
            .map(|(k, (&(_, frequency_cm1), (_, displacement)))| NormalMode {
                frequency_cm1,
                ir_intensity: self.intensities.get(k).map(|i| i.1),
                displacement,
            })
            .collect();
        Ok(Some(Vibrations { modes, geometry, geometry_from }))
    }
}

/// The modes of a Gaussian fchk file from its `Vib-E2` (frequencies, then reduced masses, force
/// constants and IR intensities, `count` each, then more) and `Vib-Modes` (each mode's
/// displacements, atom by atom) records; `lines` are the records' header lines.
pub fn from_fchk(
    file: &str,
    count: usize,
    (e2, e2_line): (&[f64], usize),
    (vectors, modes_line): (&[f64], usize),
    geometry: &[DVec3],
) -> Result<Vibrations, ParseError> {
    if e2.len() < 4 * count {
        let expected = format!("at least {} values in Vib-E2 (4 per mode)", 4 * count);
        return Err(error(file, e2_line, expected, format!("{} values", e2.len())));
    }
    let per_mode = 3 * geometry.len();
    if vectors.len() != count * per_mode {
        let expected =
            format!("{} values in Vib-Modes ({count} modes × 3 × {} atoms)", count * per_mode, geometry.len());
        return Err(error(file, modes_line, expected, format!("{} values", vectors.len())));
    }
    let modes = (0..count)
        .map(|k| NormalMode {
            frequency_cm1: e2[k],
            ir_intensity: Some(e2[3 * count + k]),
            displacement: vectors[k * per_mode..(k + 1) * per_mode]
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect(),
        })
        .collect();
    Ok(Vibrations { modes, geometry: geometry.to_vec(), geometry_from: "Current cartesian coordinates".into() })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SECTIONS: &str = "[FREQ]
 -120.5
 1598.42
[FR-COORD]
O 0.0 0.0 0.22
H 0.0 1.43 -0.89
H 0.0 -1.43 -0.89
[FR-NORM-COORD]
vibration 1
 0.0 0.0 0.1
 0.0 0.0 -0.5
 0.0 0.0 -0.5
vibration 2
 0.0 0.0 -0.07
 0.0 0.43 0.56
 0.0 -0.43 0.56
[INT]
 3.5 1.0
 63.8D0 2.0
";

    fn read(text: &str) -> Result<MoldenModes, ParseError> {
        let lines: Vec<&str> = text.lines().collect();
        let mut m = MoldenModes::default();
        let headers: Vec<usize> = (0..lines.len()).filter(|&i| lines[i].starts_with('[')).collect();
        for (n, &h) in headers.iter().enumerate() {
            let end = headers.get(n + 1).copied().unwrap_or(lines.len());
            let name = lines[h].trim_matches(|c| c == '[' || c == ']').to_ascii_lowercase();
            m.read("f.molden", &name, h + 1, &lines, (h + 1, end))?;
        }
        Ok(m)
    }

    fn atoms() -> Vec<DVec3> {
        vec![DVec3::ZERO; 3]
    }

    #[test]
    fn molden_modes_read_with_their_geometry_and_intensities() {
        let v = read(SECTIONS).unwrap().into_vibrations("f.molden", &atoms()).unwrap().unwrap();
        assert_eq!(v.modes.len(), 2);
        assert!(v.modes[0].is_imaginary() && v.modes[0].frequency_cm1 == -120.5);
        assert_eq!(v.modes[1].ir_intensity, Some(63.8));
        assert_eq!(v.modes[1].displacement[1], DVec3::new(0.0, 0.43, 0.56));
        assert_eq!(v.geometry[1], DVec3::new(0.0, 1.43, -0.89), "the modes' own geometry");
        assert_eq!(v.geometry_from, "[FR-COORD]");
        assert!(read("[ATOMS]\n").unwrap().into_vibrations("f", &atoms()).unwrap().is_none(), "no [FREQ]: no modes");
    }

    #[test]
    fn malformed_mode_sections_name_their_line() {
        let check = |text: String, line: usize, expected: &str| {
            let e = read(&text).and_then(|m| m.into_vibrations("f.molden", &atoms())).unwrap_err();
            assert_eq!(e.line, line, "{e}");
            assert!(e.expected.contains(expected), "{e}");
        };
        check(SECTIONS.replace(" 1598.42", " 1598.4x"), 3, "wavenumber");
        check(SECTIONS.replace("vibration 2\n 0.0 0.0 -0.07\n", "vibration 2\n"), 13, "3 displacement lines");
        check(SECTIONS.replace("vibration 2", "vibration 2\n 1 2"), 14, "displacement `dx dy dz`");
        check(SECTIONS.replace("H 0.0 -1.43 -0.89\n", ""), 4, "3 atoms");
        check(SECTIONS.replace(" 63.8D0 2.0\n", ""), 17, "2 intensities");
        check(SECTIONS.replace(" 1598.42\n", ""), 7, "1 vibration blocks");
        check(SECTIONS.split("[FR-NORM-COORD]").next().unwrap().to_string(), 1, "[FR-NORM-COORD]");
    }

    #[test]
    fn fchk_modes_split_vib_e2_and_vib_modes() {
        let geometry = vec![DVec3::ZERO, DVec3::X];
        // Two modes: frequencies, reduced masses, force constants, intensities, then more.
        let e2 = [1500.0, 3000.0, 1.1, 1.2, 0.5, 0.6, 40.0, 7.0, 9.9, 9.9];
        let modes: Vec<f64> = (0..12).map(f64::from).collect();
        let v = from_fchk("f.fchk", 2, (&e2, 10), (&modes, 12), &geometry).unwrap();
        assert_eq!(v.modes[1].frequency_cm1, 3000.0);
        assert_eq!(v.modes[1].ir_intensity, Some(7.0));
        assert_eq!(v.modes[1].displacement[1], DVec3::new(9.0, 10.0, 11.0));
        let e = from_fchk("f.fchk", 2, (&e2, 10), (&modes[..11], 12), &geometry).unwrap_err();
        assert_eq!(e.line, 12);
        let e = from_fchk("f.fchk", 3, (&e2, 10), (&modes, 12), &geometry).unwrap_err();
        assert_eq!(e.line, 10);
    }
}
