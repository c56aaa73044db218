//! Which atoms of a structure are shown: a short query over chains, residue numbers and
//! residue names, e.g. `chain A B resi 30-50`, `not resn HOH`. Terms are ANDed; `not` negates
//! the term after it; an empty query shows every atom.

use crate::model::{Document, Molecule, StructureView};

#[derive(Debug, Clone, PartialEq)]
enum Field {
    Chain(Vec<String>),
    /// Inclusive ranges of residue numbers.
    Residue(Vec<(i32, i32)>),
    Name(Vec<String>),
}

#[derive(Debug, Clone, PartialEq)]
struct Term {
    negated: bool,
    field: Field,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Selection {
    terms: Vec<Term>,
}

impl Selection {
    /// Parses a query; the error says what was expected where.
    pub fn parse(query: &str) -> Result<Self, String> {
        let mut terms = Vec::new();
        let mut words = query.split_whitespace().peekable();
        let keyword = |w: &str| matches!(w, "chain" | "resi" | "resn" | "not" | "and");
        while let Some(word) = words.next() {
            if word == "and" {
                continue;
            }
            let negated = word == "not";
            let key = if negated { words.next().ok_or("a term after `not`")? } else { word };
            let mut values = Vec::new();
            while let Some(v) = words.next_if(|w| !keyword(w)) {
                values.extend(v.split(',').filter(|s| !s.is_empty()).map(str::to_string));
            }
            if values.is_empty() {
                return Err(format!("values after `{key}`"));
            }
            let field = match key {
                "chain" => Field::Chain(values),
                "resn" => Field::Name(values.iter().map(|v| v.to_ascii_uppercase()).collect()),
                "resi" => Field::Residue(
                    values
                        .iter()
                        .map(|v| {
                            let (a, b) = match v.get(1..).and_then(|rest| rest.find('-')) {
                                Some(dash) => (&v[..dash + 1], &v[dash + 2..]),
                                None => (v.as_str(), v.as_str()),
                            };
                            Some((a.parse().ok()?, b.parse().ok()?))
                        })
                        .collect::<Option<Vec<_>>>()
                        .ok_or_else(|| format!("residue numbers or ranges after `resi`, not `{}`", values.join(" ")))?,
                ),
                other => return Err(format!("`chain`, `resi`, `resn` or `not`, not `{other}`")),
            };
            terms.push(Term { negated, field });
        }
        Ok(Self { terms })
    }

    pub fn is_everything(&self) -> bool {
        self.terms.is_empty()
    }

    /// Which atoms of `molecule` (the model `structure` shows) are selected; every atom when
    /// the query is empty or the file has no residues.
    pub fn mask(&self, molecule: &Molecule, structure: Option<&StructureView>) -> Vec<bool> {
        let Some(view) = structure.filter(|v| v.atoms.len() == molecule.atoms.len() && !self.is_everything()) else {
            return vec![true; molecule.atoms.len()];
        };
        let s = &view.structure;
        view.atoms
            .iter()
            .map(|&i| {
                let r = &s.residues[s.residue[i as usize] as usize];
                let chain = s.chains[r.chain as usize].name.as_str();
                self.terms.iter().all(|t| {
                    let hit = match &t.field {
                        Field::Chain(names) => names.iter().any(|n| n == chain),
                        Field::Residue(ranges) => ranges.iter().any(|&(a, b)| (a..=b).contains(&r.number)),
                        Field::Name(names) => names.iter().any(|n| n == r.name.as_str()),
                    };
                    hit != t.negated
                })
            })
            .collect()
    }
}

/// Which of `doc`'s atoms `selection` shows; `None` for all of them (an empty query, or one that
/// does not parse: the panel says why).
pub fn shown_atoms(doc: &Document, selection: &str) -> Option<Vec<bool>> {
    let query = Selection::parse(selection).ok().filter(|q| !q.is_everything())?;
    Some(query.mask(&doc.molecule, doc.structure.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_parse_and_refuse_with_reasons() {
        let s = Selection::parse("chain A,B and resi 30-50 -3 not resn hoh").unwrap();
        assert_eq!(s.terms.len(), 3);
        assert_eq!(s.terms[1].field, Field::Residue(vec![(30, 50), (-3, -3)]));
        assert!(s.terms[2].negated);
        assert!(Selection::parse("").unwrap().is_everything());
        assert!(Selection::parse("chain").unwrap_err().contains("values after `chain`"));
        assert!(Selection::parse("resi x").unwrap_err().contains("residue numbers"));
        assert!(Selection::parse("color red").unwrap_err().contains("`color`"));
    }
}
