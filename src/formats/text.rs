//! Line-oriented helpers shared by the text readers.

use super::ParseError;

/// Lines with 1-based numbers, for error messages.
pub(crate) struct Lines<'a> {
    file: &'a str,
    text: &'a str,
    /// Byte offset of the start of the next line.
    pos: usize,
    /// Line number of the last line returned.
    pub line: usize,
}

impl<'a> Lines<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self { file, text, pos: 0, line: 0 }
    }

    /// The next line, without its trailing `\r`, or an error saying what was expected.
    pub fn next_line(&mut self, expected: &str) -> Result<&'a str, ParseError> {
        if self.pos > self.text.len() || (self.pos == self.text.len() && self.pos > 0) {
            return Err(self.error(expected, "end of file"));
        }
        let rest = &self.text[self.pos..];
        let l = match rest.find('\n') {
            Some(n) => {
                self.pos += n + 1;
                &rest[..n]
            }
            None => {
                self.pos = self.text.len() + 1;
                rest
            }
        };
        self.line += 1;
        Ok(l.strip_suffix('\r').unwrap_or(l))
    }

    pub fn error(&self, expected: &str, found: &str) -> ParseError {
        ParseError {
            file: self.file.to_string(),
            line: self.line.max(1),
            expected: expected.to_string(),
            found: found.to_string(),
        }
    }

    /// Everything after the current line (as one slice of the original text).
    pub fn rest(&mut self) -> &'a str {
        self.text.get(self.pos..).unwrap_or("")
    }
}

/// Shortens a line for an error message.
pub(crate) fn excerpt(s: &str) -> String {
    let s = s.trim();
    if s.is_empty() {
        return "an empty line".into();
    }
    let short: String = s.chars().take(60).collect();
    if short.len() < s.len() { format!("\"{short}…\"") } else { format!("\"{short}\"") }
}

/// A Fortran-style real number: also accepts `D`/`d` exponents (`1.0D-03`).
/// `None` when the token is not a number or not finite.
pub(crate) fn parse_real(token: &str) -> Option<f64> {
    let v = match token.parse::<f64>() {
        Ok(v) => v,
        Err(_) if token.contains(['D', 'd']) => token.replace(['D', 'd'], "E").parse::<f64>().ok()?,
        Err(_) => return None,
    };
    v.is_finite().then_some(v)
}

/// 1-based number of the line holding byte `offset` of `text`.
pub(crate) fn line_at(text: &[u8], offset: usize) -> usize {
    1 + text[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count()
}
