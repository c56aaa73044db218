//! JSON wavefunctions (`.json`): ORCA's `orca_2json` files and QCSchema results, told apart by
//! their content, and what both readers need to walk a JSON tree with errors that say where.
//!
//! JSON carries no line structure a reader could point at once the text is parsed, so an error
//! in a well-formed file names the value by its path (`Molecule.Atoms[3].Coords`) rather than a
//! line; a syntax error names the line and column serde_json found it at.

use serde_json::Value;

use super::wavefunction::OverlapFn;
use super::{ParseError, orca_json, qcschema};
use crate::model::Document;

/// What a `.json` file must be, in words (the message when it is neither).
const EXPECTED: &str = "an ORCA wavefunction (orca_2json: a \"Molecule\" object with \"Atoms\" and \"MolecularOrbitals\") or a QCSchema result with a \"wavefunction\" (Psi4, QCEngine: protocols wavefunction \"all\" or \"orbitals_and_eigenvalues\")";

/// Parses a JSON wavefunction, choosing the layout by the keys at its top.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    if text.trim().is_empty() {
        return Err(ParseError {
            file: file.into(),
            line: 1,
            expected: EXPECTED.into(),
            found: "an empty file".into(),
        });
    }
    let root: Value = serde_json::from_str(text).map_err(|e| syntax_error(file, &e))?;
    let top = Node::root(file, &root);
    let Value::Object(map) = &root else {
        return Err(ParseError { file: file.into(), line: 0, expected: EXPECTED.into(), found: describe(&root) });
    };
    if map.contains_key("Molecule") {
        orca_json::read(top, overlap)
    } else if map.contains_key("wavefunction") || map.contains_key("schema_name") {
        qcschema::read(top, overlap)
    } else {
        Err(ParseError { file: file.into(), line: 0, expected: EXPECTED.into(), found: describe(&root) })
    }
}

fn syntax_error(file: &str, e: &serde_json::Error) -> ParseError {
    use serde_json::error::Category;
    // serde_json's message ends with " at line L column C"; the line is the error's own field.
    let message = e.to_string();
    let message = message.split(" at line ").next().unwrap_or(&message).to_string();
    let found = match e.classify() {
        Category::Eof => "the end of the file inside a value (a truncated file)".to_string(),
        _ => format!("{message} (column {})", e.column()),
    };
    ParseError { file: file.into(), line: e.line(), expected: "JSON text".into(), found }
}

/// A JSON value in words, short enough for a message.
pub(super) fn describe(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the string {:?}", s.chars().take(40).collect::<String>()),
        Value::Array(a) => format!("an array of {} values", a.len()),
        Value::Object(m) => {
            let keys: Vec<&str> = m.keys().take(6).map(String::as_str).collect();
            let more = if m.len() > keys.len() { ", …" } else { "" };
            format!("an object with keys {}{more}", keys.join(", "))
        }
    }
}

/// A value of the tree with its path, so that an error can say which one is at fault.
#[derive(Clone, Debug)]
pub(super) struct Node<'a> {
    pub file: &'a str,
    pub path: String,
    pub value: &'a Value,
}

impl<'a> Node<'a> {
    fn root(file: &'a str, value: &'a Value) -> Self {
        Node { file, path: String::new(), value }
    }

    /// "the top of the file" for the root, else the path.
    pub fn name(&self) -> &str {
        if self.path.is_empty() { "the top of the file" } else { &self.path }
    }

    /// An error at this value: `expected` says what it should have been.
    pub fn error(&self, expected: impl std::fmt::Display) -> ParseError {
        ParseError {
            file: self.file.into(),
            line: 0,
            expected: format!("{} as {expected}", self.name()),
            found: describe(self.value),
        }
    }

    fn child(&self, key: &str, value: &'a Value) -> Node<'a> {
        let path = if self.path.is_empty() { key.to_string() } else { format!("{}.{key}", self.path) };
        Node { file: self.file, path, value }
    }

    /// The member `key`, if this is an object that has it (null counts as absent).
    pub fn opt(&self, key: &str) -> Option<Node<'a>> {
        match self.value.get(key) {
            None | Some(Value::Null) => None,
            Some(v) => Some(self.child(key, v)),
        }
    }

    /// The member `key`, which must be there; `what` says what it holds.
    pub fn get(&self, key: &str, what: &str) -> Result<Node<'a>, ParseError> {
        if !self.value.is_object() {
            return Err(self.error("an object"));
        }
        self.opt(key).ok_or_else(|| {
            let path = if self.path.is_empty() { key.to_string() } else { format!("{}.{key}", self.path) };
            ParseError {
                file: self.file.into(),
                line: 0,
                expected: format!("{path} ({what})"),
                found: format!("no \"{key}\" in {}", self.name()),
            }
        })
    }

    /// The items of an array, each with its index in the path.
    pub fn items(&self, what: &str) -> Result<Vec<Node<'a>>, ParseError> {
        let Value::Array(items) = self.value else {
            return Err(self.error(format!("an array of {what}")));
        };
        Ok(items
            .iter()
            .enumerate()
            .map(|(i, v)| Node { file: self.file, path: format!("{}[{i}]", self.path), value: v })
            .collect())
    }

    /// The keys and values of an object.
    pub fn members(&self, what: &str) -> Result<Vec<(&'a str, Node<'a>)>, ParseError> {
        let Value::Object(map) = self.value else {
            return Err(self.error(format!("an object of {what}")));
        };
        Ok(map.iter().map(|(k, v)| (k.as_str(), self.child(k, v))).collect())
    }

    pub fn str(&self) -> Result<&'a str, ParseError> {
        self.value.as_str().ok_or_else(|| self.error("a string"))
    }

    pub fn bool(&self) -> Result<bool, ParseError> {
        self.value.as_bool().ok_or_else(|| self.error("true or false"))
    }

    /// A finite number; with `strings`, also a string holding one (QCSchema's basis sets may
    /// write exponents and coefficients as strings).
    pub fn real(&self, strings: bool) -> Result<f64, ParseError> {
        let v = match self.value {
            Value::Number(n) => n.as_f64(),
            Value::String(s) if strings => super::text::parse_real(s.trim()),
            _ => None,
        };
        v.filter(|x| x.is_finite()).ok_or_else(|| self.error("a finite number"))
    }

    /// A whole number in `range`.
    pub fn integer(&self, range: std::ops::RangeInclusive<i64>) -> Result<i64, ParseError> {
        let v = match self.value {
            Value::Number(n) => n.as_i64().or_else(|| n.as_f64().filter(|x| x.fract() == 0.0).map(|x| x as i64)),
            _ => None,
        };
        v.filter(|x| range.contains(x))
            .ok_or_else(|| self.error(format!("a whole number {}..={}", range.start(), range.end())))
    }

    /// An array of finite numbers (a number array may also be nested one level, row by row,
    /// when `nested` is given: the rows are then concatenated).
    pub fn reals(&self, strings: bool, nested: bool) -> Result<Vec<f64>, ParseError> {
        let Value::Array(items) = self.value else {
            return Err(self.error("an array of numbers"));
        };
        let mut out = Vec::with_capacity(items.len());
        for (i, v) in items.iter().enumerate() {
            let node = Node { file: self.file, path: format!("{}[{i}]", self.path), value: v };
            match v {
                Value::Array(_) if nested => out.extend(node.reals(strings, false)?),
                _ => out.push(node.real(strings)?),
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn syntax_errors_name_the_line() {
        let e = parse("x.json", "{\n \"Molecule\": [1, 2,\n", None).unwrap_err();
        assert_eq!(e.line, 3, "{e}");
        assert!(e.found.contains("truncated"), "{e}");
        let e = parse("x.json", "{\"a\": 1,,}", None).unwrap_err();
        assert_eq!(e.line, 1, "{e}");
    }

    #[test]
    fn other_json_is_refused_naming_what_was_expected() {
        for text in ["[1, 2]", "{\"name\": \"basis\"}", "3"] {
            let e = parse("x.json", text, None).unwrap_err();
            assert!(e.expected.contains("orca_2json") && e.expected.contains("QCSchema"), "{e}");
        }
    }

    #[test]
    fn paths_name_the_value_at_fault() {
        let v: Value = serde_json::from_str("{\"a\": {\"b\": [1, \"x\"]}}").unwrap();
        let root = Node::root("f.json", &v);
        let e = root.get("a", "an object").unwrap().get("b", "numbers").unwrap().reals(false, false).unwrap_err();
        assert_eq!(e.to_string(), "f.json: expected a.b[1] as a finite number, found the string \"x\"");
        let e = root.get("z", "a thing").unwrap_err();
        assert_eq!(e.to_string(), "f.json: expected z (a thing), found no \"z\" in the top of the file");
    }
}
