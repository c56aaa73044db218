//! mmCIF reader (PDBx): `_atom_site` in any column order (author names preferred, as the PDB
//! shows them), models, alternate locations; bonds from `_struct_conn`; helices and strands
//! from `_struct_conf` and `_struct_sheet_range`; the title from `_struct.title`. Only the
//! first data block is read.

use std::collections::HashMap;

use glam::DVec3;

use super::ParseError;
use super::cif::{Kind, Token, Tokens};
use super::structure::{document, element_of};
use super::text::excerpt;
use crate::model::structure::{AtomName, AtomRecord, ChainName, NamedAtom, ResidueName, Secondary};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, Structure};

/// Categories kept whole (they are small); `_atom_site` is streamed row by row.
const KEPT: [&str; 4] = ["_struct_conn", "_struct_conf", "_struct_sheet_range", "_struct"];

/// One category's rows.
#[derive(Default)]
struct Table<'a> {
    items: Vec<&'a str>,
    rows: Vec<Vec<Token<'a>>>,
}

impl<'a> Table<'a> {
    fn column(&self, item: &str) -> Option<usize> {
        self.items.iter().position(|i| i.eq_ignore_ascii_case(item))
    }

    /// The first of `items` the table has, in row `r`; `None` when absent or null.
    fn get(&self, r: usize, items: &[&str]) -> Option<&'a str> {
        let token: Token<'a> = *items.iter().find_map(|i| self.column(i)).and_then(|c| self.rows[r].get(c))?;
        token.value()
    }
}

/// Column positions in `_atom_site`.
struct Columns {
    group: Option<usize>,
    id: Option<usize>,
    symbol: Option<usize>,
    atom: Option<usize>,
    alt: Option<usize>,
    comp: Option<usize>,
    asym: Option<usize>,
    seq: Option<usize>,
    ins: Option<usize>,
    xyz: [usize; 3],
    occupancy: Option<usize>,
    b: Option<usize>,
    model: Option<usize>,
}

impl Columns {
    fn new(file: &str, items: &[&str], line: usize) -> Result<Self, ParseError> {
        let col = |names: &[&str]| names.iter().find_map(|n| items.iter().position(|i| i.eq_ignore_ascii_case(n)));
        let coord =
            |n: &str| col(&[n]).ok_or_else(|| error(file, line, format!("an _atom_site.{n} column"), "none".into()));
        let c = Self {
            group: col(&["group_pdb"]),
            id: col(&["id"]),
            symbol: col(&["type_symbol"]),
            atom: col(&["auth_atom_id", "label_atom_id"]),
            alt: col(&["label_alt_id", "auth_alt_id"]),
            comp: col(&["auth_comp_id", "label_comp_id"]),
            asym: col(&["auth_asym_id", "label_asym_id"]),
            seq: col(&["auth_seq_id", "label_seq_id"]),
            ins: col(&["pdbx_pdb_ins_code"]),
            xyz: [coord("Cartn_x")?, coord("Cartn_y")?, coord("Cartn_z")?],
            occupancy: col(&["occupancy"]),
            b: col(&["b_iso_or_equiv"]),
            model: col(&["pdbx_pdb_model_num"]),
        };
        if c.symbol.is_none() && c.atom.is_none() {
            return Err(error(file, line, "an _atom_site.type_symbol or atom_id column".into(), "neither".into()));
        }
        Ok(c)
    }
}

/// Builds the structure from `_atom_site` rows.
struct AtomSite<'f> {
    file: &'f str,
    columns: Columns,
    structure: Structure,
    model: Option<i32>,
}

impl AtomSite<'_> {
    fn row(&mut self, row: &[Token]) -> Result<(), ParseError> {
        let c = &self.columns;
        let line = row[0].line;
        let err = |expected: String, found: &str| error(self.file, line, expected, excerpt(found));
        let get = |i: Option<usize>| i.and_then(|i| row[i].value());
        let real = |i: usize, what: &str| -> Result<f64, ParseError> {
            let v = row[i].value().unwrap_or("");
            fast_float2::parse::<f64, _>(v).ok().filter(|v| v.is_finite()).ok_or_else(|| err(what.to_string(), v))
        };
        let model = match get(c.model) {
            None => 1,
            Some(m) => m.parse().map_err(|_| err("a model number (pdbx_PDB_model_num)".into(), m))?,
        };
        if self.model != Some(model) {
            self.structure.begin_model(model, String::new());
            self.model = Some(model);
        }
        let name = get(c.atom).unwrap_or("");
        let z = match get(c.symbol) {
            Some(s) => element_of(s),
            None => element_of(name.trim_start_matches(|ch: char| ch.is_ascii_digit()).get(..1).unwrap_or("")),
        }
        .ok_or_else(|| err("an element symbol (type_symbol)".into(), get(c.symbol).unwrap_or(name)))?;
        let label =
            |v: Option<&str>, what: &str, n: usize| err(format!("{what} of at most {n} characters"), v.unwrap_or(""));
        let first_byte = |v: Option<&str>| v.and_then(|s| s.bytes().next()).unwrap_or(0);
        let seq = get(c.seq);
        let optional = |i: Option<usize>, default: f32, what: &str| match i.and_then(|i| row[i].value()) {
            None => Ok(default),
            Some(_) => real(i.unwrap_or(0), what).map(|v| v as f32),
        };
        let record = AtomRecord {
            chain: ChainName::new(get(c.asym).unwrap_or("")).ok_or_else(|| label(get(c.asym), "a chain name", 8))?,
            residue: ResidueName::new(get(c.comp).unwrap_or(""))
                .ok_or_else(|| label(get(c.comp), "a residue name", 5))?,
            number: match seq {
                None => 0,
                Some(s) => s.parse().map_err(|_| err("a residue number (seq_id)".into(), s))?,
            },
            insertion: first_byte(get(c.ins)),
            hetero: get(c.group) == Some("HETATM"),
            name: AtomName::new(name).ok_or_else(|| label(Some(name), "an atom name", 4))?,
            altloc: first_byte(get(c.alt)),
            z,
            position: DVec3::new(
                real(c.xyz[0], "a Cartn_x coordinate")?,
                real(c.xyz[1], "a Cartn_y coordinate")?,
                real(c.xyz[2], "a Cartn_z coordinate")?,
            ) * BOHR_PER_ANGSTROM,
            occupancy: optional(c.occupancy, 1.0, "an occupancy")?,
            b_factor: optional(c.b, 0.0, "a B-factor (B_iso_or_equiv)")?,
            serial: get(c.id).and_then(|s| s.parse().ok()).unwrap_or(-1),
        };
        self.structure.push(&record);
        Ok(())
    }
}

pub fn parse(file: &str, text: &str) -> Result<Document, ParseError> {
    let mut t = Tokens::new(file, text);
    let mut tables: HashMap<String, Table> = HashMap::new();
    let mut structure: Option<Structure> = None;
    let mut block: Option<String> = None;
    let mut pending: Option<Token> = None;
    let mut row: Vec<Token> = Vec::new();
    while let Some(tok) = match pending.take() {
        Some(p) => Some(p),
        None => t.next_token()?,
    } {
        match tok.kind {
            Kind::Data if block.is_some() => break,
            Kind::Data => block = Some(tok.text[5..].to_string()),
            Kind::Loop => {
                let mut items = Vec::new();
                let mut category = "";
                let header_line = tok.line;
                let mut next = t.next_token()?;
                while let Some(tag) = next.filter(|n| n.kind == Kind::Tag) {
                    let (cat, item) = tag.text.split_once('.').unwrap_or((tag.text, ""));
                    if items.is_empty() {
                        category = cat;
                    } else if !cat.eq_ignore_ascii_case(category) {
                        return Err(t.error(tag.line, format!("a {category}.… tag in this loop"), tag.text));
                    }
                    items.push(item);
                    next = t.next_token()?;
                }
                if items.is_empty() {
                    return Err(t.error(
                        header_line,
                        "tags after loop_",
                        next.map_or("the end of the file", |n| n.text),
                    ));
                }
                let category = category.to_ascii_lowercase();
                let mut site = if category == "_atom_site" && structure.is_none() {
                    let columns = Columns::new(file, &items, header_line)?;
                    Some(AtomSite { file, columns, structure: Structure::with_capacity(text.len() / 90), model: None })
                } else {
                    None
                };
                let keep = KEPT.contains(&category.as_str());
                let mut table = Table { items: items.clone(), rows: Vec::new() };
                let mut count = 0usize;
                let mut last_line = header_line;
                // Values until the next tag, loop_ or data_.
                while let Some(v) = next.filter(super::cif::Token::is_value) {
                    last_line = v.line;
                    count += 1;
                    if site.is_some() || keep {
                        row.push(v);
                        if row.len() == items.len() {
                            if let Some(s) = &mut site {
                                s.row(&row)?;
                            } else {
                                table.rows.push(std::mem::take(&mut row));
                            }
                            row.clear();
                        }
                    }
                    next = t.next_token()?;
                }
                if !count.is_multiple_of(items.len()) {
                    return Err(t.error(
                        last_line,
                        format!("a multiple of {} values in the {category} loop", items.len()),
                        format!("{count} values"),
                    ));
                }
                row.clear();
                if let Some(s) = site {
                    structure = Some(s.structure);
                } else if keep {
                    tables.insert(category, table);
                }
                pending = next;
            }
            Kind::Tag => {
                let value = t
                    .next_token()?
                    .filter(super::cif::Token::is_value)
                    .ok_or_else(|| t.error(tok.line, format!("a value after {}", tok.text), "none"))?;
                let (cat, item) = tok.text.split_once('.').unwrap_or((tok.text, ""));
                let cat = cat.to_ascii_lowercase();
                if cat == "_atom_site" || KEPT.contains(&cat.as_str()) {
                    let table = tables.entry(cat).or_default();
                    table.items.push(item);
                    match table.rows.first_mut() {
                        Some(r) => r.push(value),
                        None => table.rows.push(vec![value]),
                    }
                }
            }
            Kind::Value | Kind::Quoted => {
                return Err(t.error(tok.line, "a tag, loop_ or data_", excerpt(tok.text)));
            }
        }
    }
    // A single atom may be written as tag–value pairs.
    if structure.is_none()
        && let Some(single) = tables.remove("_atom_site")
    {
        let line = single.rows[0][0].line;
        let mut site = AtomSite {
            file,
            columns: Columns::new(file, &single.items, line)?,
            structure: Structure::default(),
            model: None,
        };
        site.row(&single.rows[0])?;
        structure = Some(site.structure);
    }
    let mut s = structure
        .filter(|s| !s.is_empty())
        .ok_or_else(|| t.error(t.line(), "an _atom_site loop with Cartn_x, Cartn_y and Cartn_z", "no atoms"))?;
    if let Some(conn) = tables.get("_struct_conn") {
        s.add_named_bonds(&struct_conn(conn));
    }
    for (category, kind) in [("_struct_conf", Secondary::Helix), ("_struct_sheet_range", Secondary::Sheet)] {
        let Some(table) = tables.get(category) else { continue };
        for r in 0..table.rows.len() {
            if kind == Secondary::Helix && !table.get(r, &["conf_type_id"]).unwrap_or("HELX").starts_with("HELX") {
                continue;
            }
            let end = |which: &str| -> Option<(i32, u8)> {
                let seq = table.get(r, &[&format!("{which}_auth_seq_id"), &format!("{which}_label_seq_id")])?;
                let ins = table.get(r, &[&format!("pdbx_{which}_pdb_ins_code")]).and_then(|s| s.bytes().next());
                Some((seq.parse().ok()?, ins.unwrap_or(0)))
            };
            let chain = table.get(r, &["beg_auth_asym_id", "beg_label_asym_id"]);
            if let (Some(chain), Some(first), Some(last)) = (chain, end("beg"), end("end")) {
                s.mark_secondary(chain, first, last, kind);
            }
        }
    }
    let title = tables.get("_struct").and_then(|t| t.get(0, &["title"])).map(str::to_string);
    Ok(document(file, &title.or(block).unwrap_or_default(), s))
}

fn error(file: &str, line: usize, expected: String, found: String) -> ParseError {
    ParseError { file: file.to_string(), line, expected, found }
}

/// Covalent, disulfide and metal bonds of `_struct_conn` (hydrogen bonds left out).
fn struct_conn(table: &Table) -> Vec<(NamedAtom, NamedAtom)> {
    let partner = |r: usize, p: &str| -> Option<NamedAtom> {
        let get = |items: &[String]| table.get(r, &items.iter().map(String::as_str).collect::<Vec<_>>());
        let chain = get(&[format!("ptnr{p}_auth_asym_id"), format!("ptnr{p}_label_asym_id")])?;
        let seq = get(&[format!("ptnr{p}_auth_seq_id"), format!("ptnr{p}_label_seq_id")])?;
        let ins = get(&[format!("pdbx_ptnr{p}_pdb_ins_code")]).and_then(|s| s.bytes().next());
        let atom = get(&[format!("ptnr{p}_label_atom_id"), format!("ptnr{p}_auth_atom_id")])?;
        let alt = get(&[format!("pdbx_ptnr{p}_label_alt_id")]).and_then(|s| s.bytes().next());
        Some(NamedAtom {
            chain: ChainName::new(chain)?,
            number: seq.parse().ok()?,
            insertion: ins.unwrap_or(0),
            name: AtomName::new(atom)?,
            altloc: alt.unwrap_or(0),
        })
    };
    (0..table.rows.len())
        .filter(|&r| table.get(r, &["conn_type_id"]).is_none_or(|k| !k.eq_ignore_ascii_case("hydrog")))
        .filter_map(|r| Some((partner(r, "1")?, partner(r, "2")?)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "data_TEST
_struct.title 'A test, quoted'
loop_
_atom_site.group_PDB
_atom_site.id
_atom_site.type_symbol
_atom_site.label_atom_id
_atom_site.label_alt_id
_atom_site.label_comp_id
_atom_site.label_asym_id
_atom_site.Cartn_x
_atom_site.Cartn_y
_atom_site.Cartn_z
_atom_site.occupancy
_atom_site.B_iso_or_equiv
_atom_site.auth_seq_id
_atom_site.auth_asym_id
_atom_site.pdbx_PDB_model_num
ATOM   1 N N   . GLY A 11.104 6.134 -6.504 1.00 10.0 1 A 1
ATOM   2 C CA  . GLY A 11.639 6.071 -5.147 1.00 10.0 1 A 1
ATOM   3 C C   . GLY A 10.680 5.464 -4.144 1.00 10.0 1 A 1
HETATM 4 O O   A HOH B 14.000 6.000 -4.000 0.60 20.0 2 B 1
HETATM 5 O O   B HOH B 14.300 6.000 -4.000 0.40 20.0 2 B 1
#
";

    #[test]
    fn reads_atom_site_in_any_order() {
        let d = parse("t.cif", SMALL).unwrap();
        let s = &d.structure.as_ref().unwrap().structure;
        assert_eq!(d.title, "A test, quoted");
        assert_eq!(s.len(), 5);
        assert_eq!(d.molecule.atoms.len(), 4, "first altloc shown");
        assert_eq!(s.chains.len(), 2);
        assert_eq!(s.altloc[4], b'B');
        assert!(s.residues[1].hetero);
        assert_eq!(d.molecule.bonds.len(), 2);
    }

    #[test]
    fn ragged_loops_and_bad_numbers_name_the_line() {
        let e = parse("t.cif", &SMALL.replace("-4.144", "-4.1x4")).unwrap_err();
        assert_eq!(e.line, 21, "{e}");
        let e = parse("t.cif", &SMALL.replace("20.0 2 B 1\n#", "20.0 2 B\n#")).unwrap_err();
        assert!(e.expected.contains("multiple of 15"), "{e}");
        let e = parse("t.cif", "data_x\n_cell.length_a 3\n").unwrap_err();
        assert!(e.expected.contains("_atom_site"), "{e}");
    }
}
