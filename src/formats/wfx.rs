//! AIMAll's extended wavefunction files (`.wfx`; GUIDE §9): the data of a `.wfn` file in
//! tagged sections, free format, full precision.
//!
//! ```text
//! <Number of Nuclei>                          each section: an opening tag on its own line, its
//!  3                                          values (any number a line), the closing tag (whose
//! </Number of Nuclei>                         spacing may differ: `</Energy  = T + …>`)
//! <Nuclear Names> <Atomic Numbers> <Nuclear Charges> <Nuclear Cartesian Coordinates> (bohr)
//! <Number of Primitives> <Primitive Centers> <Primitive Types> <Primitive Exponents>
//! <Molecular Orbital Occupation Numbers> <Molecular Orbital Energies>
//! <Molecular Orbital Spin Types>              `Alpha and Beta` (a restricted orbital holding
//!                                             both), `Alpha`, `Beta`; one a line
//! <Molecular Orbital Primitive Coefficients>  per orbital `<MO Number>` n `</MO Number>`, then
//!                                             its coefficients over the primitives
//! <Additional Electron Density Function (EDF)>   core densities of pseudopotential atoms
//! ```
//! Lines starting with `#` and `<!-- … -->` comments (on one line or several) are skipped;
//! sections the viewer does not use are skipped whatever they hold. The primitives are those of
//! `.wfn` files (see [`super::primitives`]). Spin types decide the kind: `Alpha and Beta` with
//! `Alpha` is restricted (closed or open shell, ROHF), `Alpha` with `Beta` unrestricted (beta
//! orbitals go after alpha). The EDF section adds a density that belongs to no orbital: it is
//! left out, and `Document::problems` says so.

use std::borrow::Cow;
use std::collections::HashMap;

use glam::DVec3;

use super::molden::MAX_MO_VALUES;
use super::primitives::{MAX_TYPE, PrimitiveBasis, TYPE_RANGE};
use super::text::{excerpt, parse_real};
use super::wavefunction::{OverlapFn, program_named_in, wavefunction_document};
use super::{MAX_Z, ParseError};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::{Atom, Document};

/// Parses `.wfx` text into a document, checking the orbitals with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let w = WfxFile::parse(file, text)?;
    w.into_document(overlap)
}

/// One section: the line of its opening tag and its lines (comments removed), with numbers.
struct Section<'a> {
    line: usize,
    end: usize,
    body: Vec<(usize, Cow<'a, str>)>,
}

impl Section<'_> {
    /// Every whitespace-separated value of the section, with its line.
    fn tokens(&self) -> impl Iterator<Item = (usize, &str)> {
        self.body.iter().flat_map(|(line, text)| text.split_whitespace().map(move |t| (*line, t)))
    }
}

struct WfxFile<'a> {
    file: &'a str,
    /// By tag name, lower case without spaces.
    sections: HashMap<String, Section<'a>>,
    n_lines: usize,
}

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// A tag name as sections are keyed: lower case, no spaces (closing tags vary in spacing).
fn key(name: &str) -> String {
    name.chars().filter(|c| !c.is_whitespace()).flat_map(char::to_lowercase).collect()
}

const COEFFICIENTS: &str = "Molecular Orbital Primitive Coefficients";
const EDF: &str = "Additional Electron Density Function (EDF)";

/// Removes `<!-- … -->` comments from a line; `open` carries a comment on to the next line.
fn strip_comments<'a>(line: &'a str, open: &mut bool) -> Cow<'a, str> {
    let mut out = Cow::Borrowed(line);
    loop {
        if *open {
            match out.find("-->") {
                Some(end) => {
                    out = match out {
                        Cow::Borrowed(s) => Cow::Borrowed(&s[end + 3..]),
                        Cow::Owned(s) => Cow::Owned(s[end + 3..].to_string()),
                    };
                    *open = false;
                }
                None => return Cow::Borrowed(""),
            }
        }
        let Some(start) = out.find("<!--") else { return out };
        match out[start + 4..].find("-->") {
            Some(len) => out = Cow::Owned(format!("{}{}", &out[..start], &out[start + 4 + len + 3..])),
            None => {
                *open = true;
                return match out {
                    Cow::Borrowed(s) => Cow::Borrowed(&s[..start]),
                    Cow::Owned(s) => Cow::Owned(s[..start].to_string()),
                };
            }
        }
    }
}

impl<'a> WfxFile<'a> {
    fn parse(file: &'a str, text: &'a str) -> Result<Self, ParseError> {
        let mut sections: HashMap<String, Section<'a>> = HashMap::new();
        let mut open: Option<(String, String, Section<'a>)> = None;
        let mut in_comment = 0usize;
        let mut comment_open = false;
        let mut n_lines = 0;
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            n_lines = line_no;
            let was_open = comment_open;
            let content = strip_comments(raw, &mut comment_open);
            if comment_open && !was_open {
                in_comment = line_no;
            }
            let t = content.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            let is_tag = t.starts_with('<') && t.ends_with('>');
            match &mut open {
                None => {
                    if !is_tag || t.starts_with("</") {
                        return Err(error(file, line_no, "a section's opening tag `<Name>`", excerpt(t)));
                    }
                    let name = t[1..t.len() - 1].trim().to_string();
                    open = Some((key(&name), name, Section { line: line_no, end: 0, body: Vec::new() }));
                }
                Some((k, name, section)) => {
                    let closes = t.starts_with("</") && is_tag && key(&t[2..t.len() - 1]) == *k;
                    if closes {
                        section.end = line_no;
                        let (k, name, section) = open.take().expect("an open section");
                        if let Some(first) = sections.get(&k) {
                            let expected = format!("one <{name}> section");
                            return Err(error(
                                file,
                                section.line,
                                expected,
                                format!("a second (the first on line {})", first.line),
                            ));
                        }
                        sections.insert(k, section);
                        continue;
                    }
                    // Only the coefficients and the EDF hold tags of their own.
                    if is_tag && *k != key(COEFFICIENTS) && *k != key(EDF) {
                        let expected =
                            format!("the closing tag </{name}> of the section opened on line {}", section.line);
                        return Err(error(file, line_no, expected, excerpt(t)));
                    }
                    section.body.push((line_no, content));
                }
            }
        }
        if comment_open {
            let expected = format!("the end `-->` of the comment opened on line {in_comment}");
            return Err(error(file, n_lines.max(1), expected, "end of file"));
        }
        if let Some((_, name, section)) = open {
            let expected = format!("the closing tag </{name}> of the section opened on line {}", section.line);
            return Err(error(file, n_lines.max(1), expected, "end of file"));
        }
        if sections.is_empty() {
            let found = if text.trim().is_empty() { "an empty file" } else { "no section" };
            return Err(error(file, n_lines.max(1), "a .wfx file: tagged sections `<Name>` … `</Name>`", found));
        }
        Ok(Self { file, sections, n_lines })
    }

    fn section(&self, name: &str) -> Result<&Section<'a>, ParseError> {
        self.sections
            .get(&key(name))
            .ok_or_else(|| error(self.file, self.n_lines.max(1), format!("a <{name}> section"), "none in the file"))
    }

    /// The `n` values of a section (all of them when `n` is `None`), each parsed by `read`.
    fn values<T>(
        &self,
        name: &str,
        n: Option<usize>,
        what: &str,
        read: impl Fn(&str) -> Option<T>,
    ) -> Result<Vec<T>, ParseError> {
        let section = self.section(name)?;
        let mut out = Vec::new();
        for (line, token) in section.tokens() {
            if n.is_some_and(|n| out.len() == n) {
                let n = n.unwrap_or(0);
                return Err(error(self.file, line, format!("{n} values in <{name}>"), "more"));
            }
            let v = read(token).ok_or_else(|| error(self.file, line, format!("{what} in <{name}>"), excerpt(token)))?;
            out.push(v);
        }
        match n {
            Some(n) if out.len() != n => {
                Err(error(self.file, section.end, format!("{n} values in <{name}>"), format!("{}", out.len())))
            }
            _ => Ok(out),
        }
    }

    fn count(&self, name: &str) -> Result<usize, ParseError> {
        let v = self.values(name, Some(1), "a count", |t| t.parse::<usize>().ok())?;
        Ok(v[0])
    }

    fn into_document(self, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
        let file = self.file;
        let title = match self.sections.get(&key("Title")) {
            Some(s) => s.body.iter().map(|(_, t)| t.trim()).filter(|t| !t.is_empty()).collect::<Vec<_>>().join(" "),
            None => String::new(),
        };
        let n_nuclei = self.count("Number of Nuclei")?;
        // The coordinates must be there before anything is sized by the count.
        let n3 = n_nuclei.saturating_mul(3);
        let xyz = self.values("Nuclear Cartesian Coordinates", Some(n3), "a coordinate", parse_real)?;
        let atoms = self.atoms(n_nuclei, &xyz)?;
        let positions: Vec<DVec3> = atoms.iter().map(|a| a.position).collect();

        let n_prim = self.count("Number of Primitives")?;
        let centres = self.values("Primitive Centers", Some(n_prim), &format!("a centre 1..={n_nuclei}"), |t| {
            t.parse::<usize>().ok().filter(|c| (1..=n_nuclei).contains(c)).map(|c| c - 1)
        })?;
        let types = self.values("Primitive Types", Some(n_prim), TYPE_RANGE, |t| {
            t.parse::<u32>().ok().filter(|c| (1..=MAX_TYPE).contains(c))
        })?;
        let exponents = self.values("Primitive Exponents", Some(n_prim), "a positive exponent", |t| {
            parse_real(t).filter(|&v| v > 0.0)
        })?;
        let primitives = PrimitiveBasis::new(&positions, &centres, &types, &exponents);

        let occupations = self.values("Molecular Orbital Occupation Numbers", None, "an occupation", parse_real)?;
        let n_mo = occupations.len();
        if let Some(s) = self.sections.get(&key("Number of Occupied Molecular Orbitals")) {
            let declared = self.count("Number of Occupied Molecular Orbitals")?;
            if declared != n_mo {
                let expected =
                    format!("{declared} occupations (<Number of Occupied Molecular Orbitals>, line {})", s.line);
                let line = self.section("Molecular Orbital Occupation Numbers")?.end;
                return Err(error(file, line, expected, format!("{n_mo}")));
            }
        }
        let energies = self.values("Molecular Orbital Energies", Some(n_mo), "an energy", parse_real)?;
        let spins = self.spins(n_mo)?;
        let section = self.section(COEFFICIENTS)?;
        if (n_mo as u64).saturating_mul(n_prim as u64) > MAX_MO_VALUES {
            let expected = format!("at most {MAX_MO_VALUES} orbital coefficients");
            return Err(error(file, section.line, expected, format!("{n_mo} orbitals × {n_prim} primitives")));
        }
        let coefficients = self.coefficients(section, n_mo, n_prim)?;

        let restricted = spins.contains(&None);
        let mut orbitals: Vec<MolecularOrbital> = (0..n_mo)
            .map(|i| MolecularOrbital {
                energy: energies[i],
                occupation: occupations[i],
                spin: spins[i].unwrap_or(Spin::Alpha),
                symmetry: String::new(),
                coefficients: primitives.orbital(&coefficients[i * n_prim..(i + 1) * n_prim]),
            })
            .collect();
        orbitals.sort_by_key(|o| o.spin == Spin::Beta);
        let wf = Wavefunction {
            basis: primitives.basis,
            orbitals,
            restricted,
            normalization: Default::default(),
            excited: None,
        };
        let mut doc = wavefunction_document(file, &title, atoms, wf, program_named_in(&title), overlap);
        if let Some(edf) = self.sections.get(&key(EDF)) {
            let core =
                self.count("Number of Core Electrons").map_or(String::new(), |n| format!(" ({n} core electrons)"));
            doc.problems.push(format!(
                "{file}:{}: the additional electron density function (EDF: the core density of atoms with pseudopotentials{core}) is left out; the density shown lacks it",
                edf.line
            ));
        }
        Ok(doc)
    }

    /// Atoms from the atomic numbers, else the names' leading letters, else the charges.
    fn atoms(&self, n: usize, xyz: &[f64]) -> Result<Vec<Atom>, ParseError> {
        let file = self.file;
        let numbers = match self.sections.contains_key(&key("Atomic Numbers")) {
            true => Some(self.values("Atomic Numbers", Some(n), &format!("an atomic number 0..={MAX_Z}"), |t| {
                t.parse::<u32>().ok().filter(|&z| z <= MAX_Z)
            })?),
            false => None,
        };
        let charges = match self.sections.contains_key(&key("Nuclear Charges")) {
            true => Some(self.values("Nuclear Charges", Some(n), "a charge", parse_real)?),
            false => None,
        };
        let names: Option<Vec<(usize, String)>> = self.sections.get(&key("Nuclear Names")).map(|s| {
            s.body.iter().filter(|(_, t)| !t.trim().is_empty()).map(|(l, t)| (*l, t.trim().to_string())).collect()
        });
        if let (Some(names), Some(s)) = (&names, self.sections.get(&key("Nuclear Names")))
            && names.len() != n
        {
            return Err(error(file, s.end, format!("{n} names in <Nuclear Names>"), format!("{}", names.len())));
        }
        let mut atoms = Vec::with_capacity(n);
        for i in 0..n {
            let named = names.as_ref().and_then(|v| {
                let letters: String = v[i].1.chars().take_while(char::is_ascii_alphabetic).collect();
                atomic_number(&letters)
            });
            let charge = charges.as_ref().map(|c| c[i]);
            let from_charge = charge.map(f64::round).filter(|c| (0.0..=f64::from(MAX_Z)).contains(c)).map(|c| c as u32);
            let z = numbers.as_ref().map(|v| v[i]).or(named).or(from_charge).ok_or_else(|| {
                let line = self.sections.get(&key("Nuclear Names")).map_or(self.n_lines.max(1), |s| s.line);
                error(file, line, "atomic numbers, element names or nuclear charges for the nuclei", "none")
            })?;
            let charge = charge.unwrap_or(z as f64);
            let position = DVec3::new(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
            atoms.push(Atom { z, charge, position, ghost: charge == 0.0 });
        }
        Ok(atoms)
    }

    /// Spin per orbital: `None` for `Alpha and Beta`; restricted files mix only `Alpha and Beta`
    /// with `Alpha`.
    fn spins(&self, n: usize) -> Result<Vec<Option<Spin>>, ParseError> {
        const NAME: &str = "Molecular Orbital Spin Types";
        let section = self.section(NAME)?;
        let mut out = Vec::with_capacity(n.min(section.body.len()));
        // The first `Alpha and Beta` and the first `Beta`: together they mix the two kinds.
        let (mut first_both, mut first_beta) = (None, None);
        for (line, text) in &section.body {
            let words: Vec<String> = text.split_whitespace().map(str::to_ascii_lowercase).collect();
            if words.is_empty() {
                continue;
            }
            let spin = match words.join(" ").as_str() {
                "alpha and beta" => None,
                "alpha" => Some(Spin::Alpha),
                "beta" => Some(Spin::Beta),
                _ => {
                    return Err(error(
                        self.file,
                        *line,
                        "a spin type `Alpha and Beta`, `Alpha` or `Beta`",
                        excerpt(text),
                    ));
                }
            };
            if out.len() == n {
                return Err(error(self.file, *line, format!("{n} spin types (one per occupation)"), "more"));
            }
            match spin {
                None => first_both = first_both.or(Some(*line)),
                Some(Spin::Beta) => first_beta = first_beta.or(Some(*line)),
                Some(Spin::Alpha) => {}
            }
            if let (Some(both), Some(beta)) = (first_both, first_beta) {
                let expected = "spin types of one kind: `Alpha and Beta` with `Alpha` (restricted) or `Alpha` with `Beta` (unrestricted)";
                let found = format!("Alpha and Beta on line {both}, Beta on line {beta}");
                return Err(error(self.file, *line, expected, found));
            }
            out.push(spin);
        }
        if out.len() != n {
            return Err(error(
                self.file,
                section.end,
                format!("{n} spin types (one per occupation)"),
                format!("{}", out.len()),
            ));
        }
        Ok(out)
    }

    /// `n_mo × n_prim` coefficients, orbital after orbital: in `<MO Number>` blocks of `n_prim`
    /// each, or as one run of values without them.
    fn coefficients(&self, section: &Section, n_mo: usize, n_prim: usize) -> Result<Vec<f64>, ParseError> {
        let file = self.file;
        let mut out: Vec<f64> = Vec::new();
        // The block being read: its number, the line of its tag, where its values start.
        let mut block: Option<(usize, usize, usize)> = None;
        let check_block = |block: Option<(usize, usize, usize)>, len: usize, line: usize| match block {
            Some((k, tag_line, start)) if len - start != n_prim => Err(error(
                file,
                line,
                format!("{n_prim} coefficients for orbital {k} (line {tag_line})"),
                format!("{}", len - start),
            )),
            _ => Ok(()),
        };
        let mut body = section.body.iter();
        while let Some((line, text)) = body.next() {
            let t = text.trim();
            if key(t) == key("<MO Number>") {
                check_block(block, out.len(), *line)?;
                let number = body.next().filter(|(_, n)| n.trim().parse::<usize>().is_ok());
                let end = body.next().filter(|(_, e)| key(e.trim()) == key("</MO Number>"));
                if number.is_none() || end.is_none() {
                    let expected = "an orbital number, then </MO Number>, after <MO Number>";
                    return Err(error(file, *line, expected, "something else"));
                }
                let k = block.map_or(1, |b| b.0 + 1);
                if k > n_mo {
                    return Err(error(file, *line, format!("{n_mo} orbitals (one per occupation)"), "more"));
                }
                block = Some((k, *line, out.len()));
                continue;
            }
            if t.starts_with('<') {
                return Err(error(file, *line, "coefficients or <MO Number>", excerpt(t)));
            }
            for token in t.split_whitespace() {
                if out.len() == n_mo * n_prim {
                    return Err(error(file, *line, format!("{n_mo} × {n_prim} coefficients"), "more"));
                }
                let v = parse_real(token).ok_or_else(|| error(file, *line, "a coefficient", excerpt(token)))?;
                out.push(v);
            }
        }
        check_block(block, out.len(), section.end)?;
        if out.len() != n_mo * n_prim {
            let expected = format!("{} coefficients ({n_mo} orbitals × {n_prim} primitives)", n_mo * n_prim);
            return Err(error(file, section.end, expected, format!("{}", out.len())));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// H2: one s primitive per atom and a pz on atom 1; two restricted orbitals.
    const H2: &str = "<Title>
 H2 test
</Title>
<Keywords>
 GTO
</Keywords>
<Number of Nuclei>
 2
</Number of Nuclei>
<Nuclear Names>
 H1
 H2
</Nuclear Names>
<Nuclear Charges>
 1.0 1.0
</Nuclear Charges>
<Nuclear Cartesian Coordinates>
 0.0 0.0 0.0
 0.0 0.0 1.4
</Nuclear Cartesian Coordinates>
<Number of Primitives>
 3
</Number of Primitives>
<Primitive Centers>
 1 2 1
</Primitive Centers>
<Primitive Types>
 1 1 4
</Primitive Types>
<Primitive Exponents>
 1.0 1.0 0.8
</Primitive Exponents>
<Molecular Orbital Occupation Numbers>
 2.0
 0.0
</Molecular Orbital Occupation Numbers>
<Molecular Orbital Energies>
 -0.6
 0.7
</Molecular Orbital Energies>
<Molecular Orbital Spin Types>
 Alpha and Beta
 Alpha and Beta
</Molecular Orbital Spin Types>
<Molecular Orbital Primitive Coefficients>
<MO Number>
 1
</MO Number>
 0.4 0.4 0.1
<MO Number>
 2
</MO Number>
 0.5 -0.5 0.0
</Molecular Orbital Primitive Coefficients>
<Energy = T + Vne + Vee + Vnn>
 -1.1
</Energy  = T + Vne + Vee + Vnn>
";

    fn doc(text: &str) -> Document {
        parse("t.wfx", text, None).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_restricted_file_reads_with_comments() {
        let d = doc(H2);
        assert_eq!(d.title, "H2 test");
        assert_eq!((d.molecule.atoms[1].z, d.molecule.atoms[1].position.z), (1, 1.4));
        let wf = d.wavefunction.expect("wf");
        assert!(wf.restricted);
        assert_eq!(wf.basis.n_functions(), 5);
        assert_eq!(wf.orbitals[1].energy, 0.7);
        assert!(d.problems.is_empty());
        let commented = format!(
            "# a comment line\n<!-- a comment\n  over lines -->\n{}",
            H2.replace("<Title>", "<Title> <!-- inline -->").replace(" 1.0 1.0\n", " 1.0 <!-- one --> 1.0\n")
        );
        assert_eq!(doc(&commented).molecule.atoms.len(), 2);
        // An EDF section is left out and said so.
        let edf = H2.replace(
            "<Molecular Orbital Occupation",
            "<Additional Electron Density Function (EDF)>\n<Number of EDF Primitives>\n 1\n</Number of EDF Primitives>\n</Additional Electron Density Function (EDF)>\n<Molecular Orbital Occupation",
        );
        let d = doc(&edf);
        assert!(d.problems[0].contains("EDF"), "{:?}", d.problems);
    }

    #[test]
    fn spin_types_decide_the_kind() {
        let uhf = H2.replace(" Alpha and Beta\n Alpha and Beta\n", " Alpha\n Beta\n");
        let wf = doc(&uhf).wavefunction.expect("wf");
        assert!(!wf.restricted);
        assert_eq!(wf.of_spin(Spin::Beta).count(), 1);
        let rohf = H2.replace(" Alpha and Beta\n Alpha and Beta\n", " Alpha and Beta\n Alpha\n");
        assert!(doc(&rohf).wavefunction.expect("wf").restricted);
        // Beta listed first still goes after alpha.
        let swapped = H2.replace(" Alpha and Beta\n Alpha and Beta\n", " Beta\n Alpha\n");
        let wf = doc(&swapped).wavefunction.expect("wf");
        assert_eq!((wf.orbitals[0].spin, wf.orbitals[0].energy), (Spin::Alpha, 0.7));
    }

    #[test]
    fn malformed_files_name_their_line() {
        let cases: Vec<(String, usize, &str)> = vec![
            (String::new(), 1, "a .wfx file"),
            ("hello\n".into(), 1, "opening tag"),
            (H2.replace("</Title>\n", ""), 3, "the closing tag </Title>"),
            (H2.replace("</Energy  = T + Vne + Vee + Vnn>\n", ""), 56, "the closing tag </Energy"),
            (H2.replace(" 2\n</Number of Nuclei>", " two\n</Number of Nuclei>"), 8, "a count"),
            (H2.replace(" 0.0 0.0 1.4\n", " 0.0 0.0\n"), 20, "6 values"),
            (H2.replace(" 1 2 1\n", " 1 3 1\n"), 25, "a centre 1..=2"),
            (H2.replace(" 1 1 4\n", " 1 1 57\n"), 28, "primitive type 1..=56"),
            (H2.replace(" 1.0 1.0 0.8\n", " 1.0 1.0 -0.8\n"), 31, "positive exponent"),
            (H2.replace(" 1.0 1.0 0.8\n", " 1.0 1.0 0.8 0.9\n"), 31, "3 values"),
            (H2.replace(" -0.6\n", " low\n"), 38, "an energy"),
            (H2.replace(" 0.7\n", ""), 39, "2 values"),
            (H2.replace(" Alpha and Beta\n Alpha and Beta\n", " Alpha and Beta\n Beta\n"), 43, "one kind"),
            (H2.replace(" Alpha and Beta\n Alpha and Beta\n", " Alpha and Beta\n Up\n"), 43, "a spin type"),
            (H2.replace(" 0.4 0.4 0.1\n", " 0.4 0.4\n"), 50, "3 coefficients for orbital 1"),
            (H2.replace(" 0.5 -0.5 0.0\n", " 0.5 -0.5 x\n"), 53, "a coefficient"),
            (H2.replace("<Primitive Types>\n 1 1 4\n</Primitive Types>\n", ""), 54, "a <Primitive Types> section"),
            (format!("{H2}<Title>\n again\n</Title>\n"), 58, "one <Title>"),
            (H2.replace("<Title>\n", "<Title>\n<!-- open\n"), 58, "-->"),
        ];
        let mut wrong = Vec::new();
        for (text, line, expected) in cases {
            match parse("t.wfx", &text, None) {
                Ok(_) => wrong.push(format!("wanted line {line} \"{expected}\", but it parsed")),
                Err(e) if e.line != line || !e.expected.contains(expected) || e.file != "t.wfx" => {
                    wrong.push(format!("wanted line {line} \"{expected}\", got {e}"));
                }
                Err(_) => {}
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }
}
