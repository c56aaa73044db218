//! CIF 1.1 / mmCIF tokens: tags, `loop_`, `data_` blocks, bare, quoted ('…', "…") and
//! semicolon text-field values, `#` comments; each token with its line for error messages.

use super::ParseError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `_category.item`
    Tag,
    Loop,
    /// `data_NAME`
    Data,
    /// A bare value (`.` and `?` mean null).
    Value,
    /// A quoted or text-field value (never null, never a keyword).
    Quoted,
}

#[derive(Debug, Clone, Copy)]
pub struct Token<'a> {
    pub kind: Kind,
    pub text: &'a str,
    pub line: usize,
}

impl<'a> Token<'a> {
    pub fn is_value(&self) -> bool {
        matches!(self.kind, Kind::Value | Kind::Quoted)
    }

    /// `None` for the null values `.` (inapplicable) and `?` (unknown).
    pub fn value(&self) -> Option<&'a str> {
        match (self.kind, self.text) {
            (Kind::Value, "." | "?") => None,
            _ => Some(self.text),
        }
    }
}

pub struct Tokens<'a> {
    file: &'a str,
    text: &'a str,
    pos: usize,
    line: usize,
    /// The previous byte was a line break (or the start): `;` opens a text field only there.
    at_line_start: bool,
}

impl<'a> Tokens<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self { file, text, pos: 0, line: 1, at_line_start: true }
    }

    pub fn line(&self) -> usize {
        self.line
    }

    pub fn error(&self, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
        ParseError { file: self.file.to_string(), line, expected: expected.into(), found: found.into() }
    }

    /// The next token, `None` at the end of the text.
    pub fn next_token(&mut self) -> Result<Option<Token<'a>>, ParseError> {
        let b = self.text.as_bytes();
        // Whitespace and comments.
        loop {
            match b.get(self.pos) {
                None => return Ok(None),
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                    self.at_line_start = true;
                }
                Some(b' ' | b'\t' | b'\r' | 0x0b | 0x0c) => {
                    self.pos += 1;
                    self.at_line_start = false;
                }
                Some(b'#') => {
                    self.pos = memchr_newline(b, self.pos);
                }
                Some(_) => break,
            }
        }
        let start = self.pos;
        let line = self.line;
        let c = b[start];
        if c == b';' && self.at_line_start {
            // A text field: up to a line that starts with ';'.
            let mut p = start + 1;
            loop {
                let nl = memchr_newline(b, p);
                if nl >= b.len() {
                    return Err(self.error(
                        line,
                        "a text field closed by a line starting with ';'",
                        "the end of the file",
                    ));
                }
                self.line += 1;
                if b.get(nl + 1) == Some(&b';') {
                    let value = self.text[start + 1..nl].trim_end_matches('\r');
                    self.pos = nl + 2;
                    self.at_line_start = false;
                    return Ok(Some(Token { kind: Kind::Quoted, text: value, line }));
                }
                p = nl + 1;
            }
        }
        self.at_line_start = false;
        if c == b'\'' || c == b'"' {
            // Closed by the same quote followed by whitespace or the end.
            let mut p = start + 1;
            loop {
                match b.get(p) {
                    None | Some(b'\n') => {
                        return Err(self.error(line, format!("a closing {} on the same line", c as char), "none"));
                    }
                    Some(&q) if q == c && b.get(p + 1).is_none_or(u8::is_ascii_whitespace) => {
                        self.pos = p + 1;
                        return Ok(Some(Token { kind: Kind::Quoted, text: &self.text[start + 1..p], line }));
                    }
                    _ => p += 1,
                }
            }
        }
        let mut p = start;
        while p < b.len() && !b[p].is_ascii_whitespace() {
            p += 1;
        }
        self.pos = p;
        let text = &self.text[start..p];
        let kind = if c == b'_' {
            Kind::Tag
        } else if text.eq_ignore_ascii_case("loop_") {
            Kind::Loop
        } else if text.len() >= 5 && text.as_bytes()[..5].eq_ignore_ascii_case(b"data_") {
            Kind::Data
        } else {
            Kind::Value
        };
        Ok(Some(Token { kind, text, line }))
    }
}

/// Offset of the next `\n` at or after `from` (the end of `b` if none).
fn memchr_newline(b: &[u8], from: usize) -> usize {
    b[from.min(b.len())..].iter().position(|&c| c == b'\n').map_or(b.len(), |n| from + n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Vec<(Kind, String, usize)> {
        let mut t = Tokens::new("t.cif", text);
        let mut out = Vec::new();
        while let Some(tok) = t.next_token().unwrap() {
            out.push((tok.kind, tok.text.to_string(), tok.line));
        }
        out
    }

    #[test]
    fn quotes_text_fields_and_comments() {
        let toks = all("data_x\n# c\nloop_\n_a.b\n'it''s ok' \"x y\"\n;line one\nline two\n;\n. ?\n");
        let kinds: Vec<Kind> = toks.iter().map(|t| t.0).collect();
        assert_eq!(
            kinds,
            [Kind::Data, Kind::Loop, Kind::Tag, Kind::Quoted, Kind::Quoted, Kind::Quoted, Kind::Value, Kind::Value]
        );
        assert_eq!(toks[3].1, "it''s ok");
        assert_eq!(toks[4].1, "x y");
        assert_eq!(toks[5].1, "line one\nline two");
        assert_eq!(toks[6].2, 9);
    }

    #[test]
    fn unclosed_quotes_are_errors() {
        let mut t = Tokens::new("t.cif", "data_x\n_a.b 'open\n");
        t.next_token().unwrap();
        t.next_token().unwrap();
        let e = t.next_token().unwrap_err();
        assert_eq!(e.line, 2);
    }
}
