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
