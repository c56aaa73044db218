//! PDB format reader (wwPDB 3.3 fixed columns): ATOM/HETATM with hybrid-36 serials and residue
//! numbers, MODEL/ENDMDL, CONECT, LINK, HELIX/SHEET, TITLE. Elements from columns 77–78, else
//! from the atom name as the format defines it.

use glam::DVec3;

use super::ParseError;
use super::structure::{document, element_of};
use super::text::excerpt;
use crate::model::structure::{AtomName, AtomRecord, ChainName, NamedAtom, ResidueName, Secondary};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, Structure};

/// Decodes a hybrid-36 field of width `w` (5 for serials, 4 for residue numbers): decimal up
/// to 10^w − 1, then A000… (upper case) and a000… (lower case) in base 36.
pub fn hybrid36(field: &str, w: u32) -> Option<i32> {
    let s = field.trim();
    let first = s.bytes().next()?;
    if first == b'-' || first.is_ascii_digit() {
        return s.parse().ok();
    }
    if field.len() != w as usize || !s.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return None;
    }
    let upper = first.is_ascii_uppercase();
    if s.bytes().any(|b| b.is_ascii_alphabetic() && b.is_ascii_uppercase() != upper) {
        return None;
    }
    let v = i64::from_str_radix(s, 36).ok()?;
    let block = 36i64.pow(w - 1);
    let decimal = 10i64.pow(w);
    let v = if upper { v - 10 * block + decimal } else { v - 10 * block + decimal + 26 * block };
    i32::try_from(v).ok()
}

/// The columns `a..=b` (1-based, inclusive) of a line, "" where the line is shorter.
fn cols(line: &str, a: usize, b: usize) -> Option<&str> {
    let end = b.min(line.len());
    if a > end {
        return Some("");
    }
    line.get(a - 1..end)
}

fn col_byte(line: &str, c: usize) -> u8 {
    match line.as_bytes().get(c - 1) {
        Some(b' ') | None => 0,
        Some(&b) => b,
    }
}

/// Element from a PDB atom name (columns 13–16) when columns 77–78 are blank: a name starting
/// in column 13 is a two-letter element (" CA " is carbon alpha, "CA  " calcium), except the
/// four-letter hydrogen names of ATOM records ("HG21").
fn element_from_name(name: &str, hetero: bool) -> Option<u8> {
    let b = name.as_bytes();
    let letter = |i: usize| b.get(i).copied().filter(u8::is_ascii_alphabetic);
    match (letter(0), letter(1)) {
        (None, Some(c)) => element_of(&(c as char).to_string()),
        (Some(c0), Some(c1)) => {
            let two = format!("{}{}", c0 as char, c1 as char);
            if (c0 == b'H' || c0 == b'D') && !hetero {
                return Some(1);
            }
            element_of(&two).or_else(|| element_of(&(c0 as char).to_string()))
        }
        (Some(c0), None) => element_of(&(c0 as char).to_string()),
        (None, None) => None,
    }
}

struct Reader<'a> {
    file: &'a str,
    line: usize,
}

impl Reader<'_> {
    fn error(&self, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
        ParseError { file: self.file.to_string(), line: self.line, expected: expected.into(), found: found.into() }
    }

    fn field<'l>(&self, line: &'l str, a: usize, b: usize, what: &str) -> Result<&'l str, ParseError> {
        cols(line, a, b).ok_or_else(|| self.error(format!("{what} in ASCII columns {a}–{b}"), excerpt(line)))
    }

    fn real(&self, line: &str, a: usize, b: usize, what: &str) -> Result<f64, ParseError> {
        let f = self.field(line, a, b, what)?.trim();
        fast_float2::parse::<f64, _>(f)
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.error(format!("{what} (columns {a}–{b})"), excerpt(f)))
    }

    fn atom(&self, line: &str) -> Result<AtomRecord, ParseError> {
        let hetero = line.starts_with("HETATM");
        let name_field = self.field(line, 13, 16, "an atom name")?;
        let name = AtomName::new(name_field).unwrap_or_default();
        let number_field = self.field(line, 23, 26, "a residue number")?;
        let number = hybrid36(number_field, 4)
            .ok_or_else(|| self.error("a residue number (columns 23–26)", excerpt(number_field)))?;
        let x = self.real(line, 31, 38, "an x coordinate")?;
        let y = self.real(line, 39, 46, "a y coordinate")?;
        let z = self.real(line, 47, 54, "a z coordinate")?;
        let optional = |a, b, default: f32| -> Result<f32, ParseError> {
            let f = self.field(line, a, b, "a number")?.trim();
            if f.is_empty() { Ok(default) } else { Ok(self.real(line, a, b, "a number")? as f32) }
        };
        let element_field = self.field(line, 77, 78, "an element symbol")?.trim();
        let element =
            if element_field.is_empty() { element_from_name(name_field, hetero) } else { element_of(element_field) };
        let element = element.ok_or_else(|| {
            let found = if element_field.is_empty() { name_field } else { element_field };
            self.error("an element symbol (columns 77–78, or the atom name)", excerpt(found))
        })?;
        // Residue names take columns 18–20 (some writers use 21 too); two-letter chains 21–22.
        let resname = self.field(line, 18, 21, "a residue name")?;
        let (resname, chain) = if resname.len() == 4 && !resname.ends_with(' ') && col_byte(line, 22) != 0 {
            (resname, self.field(line, 22, 22, "a chain")?)
        } else {
            (self.field(line, 18, 20, "a residue name")?, self.field(line, 21, 22, "a chain")?)
        };
        Ok(AtomRecord {
            chain: ChainName::new(chain).unwrap_or_default(),
            residue: ResidueName::new(resname).unwrap_or_default(),
            number,
            insertion: col_byte(line, 27),
            hetero,
            name,
            altloc: col_byte(line, 17),
            z: element,
            position: DVec3::new(x, y, z) * BOHR_PER_ANGSTROM,
            occupancy: optional(55, 60, 1.0)?,
            b_factor: optional(61, 66, 0.0)?,
            serial: hybrid36(self.field(line, 7, 11, "a serial number")?, 5).unwrap_or(-1),
        })
    }

    /// A LINK partner: name 13–16, altloc 17, chain 22, resSeq 23–26, iCode 27 (or shifted by 30).
    fn link_atom(&self, line: &str, shift: usize) -> Result<NamedAtom, ParseError> {
        let number_field = self.field(line, 23 + shift, 26 + shift, "a residue number")?;
        Ok(NamedAtom {
            chain: ChainName::new(self.field(line, 22 + shift, 22 + shift, "a chain")?).unwrap_or_default(),
            number: hybrid36(number_field, 4).ok_or_else(|| self.error("a residue number", excerpt(number_field)))?,
            insertion: col_byte(line, 27 + shift),
            name: AtomName::new(self.field(line, 13 + shift, 16 + shift, "an atom name")?).unwrap_or_default(),
            altloc: col_byte(line, 17 + shift),
        })
    }
}

/// A secondary-structure range: chain, first (number, insertion), last.
type Range2 = (String, (i32, u8), (i32, u8), Secondary);

pub fn parse(file: &str, text: &str) -> Result<Document, ParseError> {
    let mut r = Reader { file, line: 0 };
    let mut s = Structure::with_capacity(text.len() / 81);
    let mut title = String::new();
    let mut conect: Vec<(i32, i32)> = Vec::new();
    let mut links: Vec<(NamedAtom, NamedAtom)> = Vec::new();
    let mut ranges: Vec<Range2> = Vec::new();
    for line in text.split('\n') {
        r.line += 1;
        let line = line.strip_suffix('\r').unwrap_or(line);
        let record = line.get(..6).unwrap_or(line);
        match record.trim_end() {
            "ATOM" | "HETATM" => s.push(&r.atom(line)?),
            "MODEL" => {
                let f = r.field(line, 7, 80, "a model number")?.trim();
                let number = f.parse().map_err(|_| r.error("a model number after MODEL", excerpt(f)))?;
                s.begin_model(number, String::new());
            }
            "TITLE" => {
                let t = r.field(line, 11, 80, "a title")?.trim();
                title = if title.is_empty() { t.to_string() } else { format!("{title} {t}") };
            }
            "HEADER" if title.is_empty() => title = r.field(line, 11, 50, "a header")?.trim().to_string(),
            "CONECT" => {
                let from = r.field(line, 7, 11, "a serial number")?;
                let from = hybrid36(from, 5).ok_or_else(|| r.error("a serial number (columns 7–11)", excerpt(from)))?;
                for k in 0..4 {
                    let f = r.field(line, 12 + 5 * k, 16 + 5 * k, "a serial number")?;
                    if let Some(to) = hybrid36(f, 5) {
                        conect.push((from, to));
                    }
                }
            }
            "LINK" => links.push((r.link_atom(line, 0)?, r.link_atom(line, 30)?)),
            "HELIX" => ranges.push(secondary(&r, line, [20, 22, 25, 26, 32, 34, 37, 38], Secondary::Helix)?),
            "SHEET" => ranges.push(secondary(&r, line, [22, 23, 26, 27, 33, 34, 37, 38], Secondary::Sheet)?),
            "END" => break,
            _ => {}
        }
    }
    if s.is_empty() {
        return Err(ParseError {
            file: file.to_string(),
            line: r.line,
            expected: "ATOM or HETATM records".into(),
            found: "none".into(),
        });
    }
    for (chain, first, last, kind) in ranges {
        s.mark_secondary(&chain, first, last, kind);
    }
    add_conect(&mut s, &conect);
    s.add_named_bonds(&links);
    Ok(document(file, &title, s))
}

/// HELIX/SHEET columns: first chain, number from–to, insertion, last chain, number from–to,
/// insertion.
fn secondary(r: &Reader, line: &str, c: [usize; 8], kind: Secondary) -> Result<Range2, ParseError> {
    let number = |a, b| {
        let f = r.field(line, a, b, "a residue number")?;
        hybrid36(f, 4).ok_or_else(|| r.error(format!("a residue number (columns {a}–{b})"), excerpt(f)))
    };
    let chain = r.field(line, c[0], c[0], "a chain")?.trim().to_string();
    Ok((chain, (number(c[1], c[2])?, col_byte(line, c[3])), (number(c[5], c[6])?, col_byte(line, c[7])), kind))
}

/// CONECT serials → bonds within each model (serials repeat from model to model).
fn add_conect(s: &mut Structure, conect: &[(i32, i32)]) {
    if conect.is_empty() {
        return;
    }
    let wanted: std::collections::HashSet<i32> = conect.iter().flat_map(|&(a, b)| [a, b]).collect();
    let mut bonds = Vec::new();
    for m in &s.models {
        let mut at = std::collections::HashMap::new();
        for i in m.atoms.clone() {
            let serial = s.serial[i as usize];
            if wanted.contains(&serial) {
                at.entry(serial).or_insert(i);
            }
        }
        bonds.extend(conect.iter().filter_map(|(a, b)| Some((*at.get(a)?, *at.get(b)?))).filter(|(a, b)| a != b));
    }
    s.explicit_bonds.extend(bonds);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hybrid36_decodes_both_blocks() {
        assert_eq!(hybrid36("99999", 5), Some(99999));
        assert_eq!(hybrid36("A0000", 5), Some(100000));
        assert_eq!(hybrid36("A0001", 5), Some(100001));
        assert_eq!(hybrid36("ZZZZZ", 5), Some(100000 + 26 * 36i32.pow(4) - 1));
        assert_eq!(hybrid36("a0000", 5), Some(100000 + 26 * 36i32.pow(4)));
        assert_eq!(hybrid36("A000", 4), Some(10000));
        assert_eq!(hybrid36("  -1", 4), Some(-1));
        assert_eq!(hybrid36("aB000", 5), None);
        assert_eq!(hybrid36("*****", 5), None);
    }

    #[test]
    fn element_from_names() {
        assert_eq!(element_from_name(" CA ", false), Some(6));
        assert_eq!(element_from_name("CA  ", true), Some(20));
        assert_eq!(element_from_name("HG21", false), Some(1));
        assert_eq!(element_from_name("HG  ", true), Some(80));
        assert_eq!(element_from_name("1HB ", false), Some(1));
        assert_eq!(element_from_name("FE  ", true), Some(26));
    }

    const TWO_MODELS: &str = "\
HEADER    TEST
MODEL        1
ATOM      1  N   GLY A   1      11.104   6.134  -6.504  1.00  0.00           N
ATOM      2  CA  GLY A   1      11.639   6.071  -5.147  1.00  0.00           C
ATOM      3  C   GLY A   1      10.680   5.464  -4.144  0.50 12.30           C
ENDMDL
MODEL        2
ATOM      1  N   GLY A   1      12.104   6.134  -6.504  1.00  0.00           N
ATOM      2  CA  GLY A   1      12.639   6.071  -5.147  1.00  0.00           C
ATOM      3  C   GLY A   1      11.680   5.464  -4.144  0.50 12.30           C
ENDMDL
CONECT    1    3
END
";

    #[test]
    fn models_and_conect() {
        let d = parse("t.pdb", TWO_MODELS).unwrap();
        let view = d.structure.as_ref().unwrap();
        assert_eq!(view.structure.models.len(), 2);
        assert_eq!(d.molecule.atoms.len(), 3);
        assert_eq!(view.structure.explicit_bonds, vec![(0, 2), (3, 5)]);
        assert_eq!(view.structure.b_factor[2], 12.3);
        assert!((d.molecule.atoms[0].position.x / BOHR_PER_ANGSTROM - 11.104).abs() < 1e-9);
        // N–CA, CA–C by distance; N–C from CONECT.
        assert_eq!(d.molecule.bonds.len(), 3);
    }

    #[test]
    fn bad_coordinates_name_the_line() {
        let text = TWO_MODELS.replace("  11.639", "  11.6x9");
        let e = parse("t.pdb", &text).unwrap_err();
        assert_eq!(e.line, 4, "{e}");
        assert!(e.expected.contains("x coordinate"), "{e}");
    }
}
