//! Program logs (`.log`, `.out`): many programs write files with these endings, so the program
//! is told from the text, not the name. Gaussian prints "Entering Gaussian System" and its
//! copyright ("Gaussian, Inc.") at the top; ORCA its banner "O   R   C   A".
//!
//! What the readers of logs share: the lines with their numbers, numbers in fixed-width
//! columns, and the errors they raise.

use super::text::{excerpt, parse_real};
use super::wavefunction::OverlapFn;
use super::{ParseError, gaussian_log};
use crate::model::Document;

/// Lines of the file's top in which the program's banner is looked for: a job scheduler may
/// write a few lines first, and the banners sit within the first hundred lines.
const BANNER_LINES: usize = 500;

/// The programs whose logs orbcloud reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Program {
    Gaussian,
    Orca,
}

/// The program that wrote `text`, from its banner.
pub fn program(text: &str) -> Option<Program> {
    for line in text.lines().take(BANNER_LINES) {
        if line.contains("Entering Gaussian System") || line.contains("Gaussian, Inc.") {
            return Some(Program::Gaussian);
        }
        if line.contains("O   R   C   A") {
            return Some(Program::Orca);
        }
    }
    None
}

/// What the banner check looks for, in words.
pub const BANNERS: &str =
    "a Gaussian log (\"Entering Gaussian System\" or \"Gaussian, Inc.\") or an ORCA output (\"O   R   C   A\")";

/// Parses a program's log into a document, the program told by its banner.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    if text.trim().is_empty() {
        return Err(error(file, 1, BANNERS, "an empty file"));
    }
    match program(text) {
        Some(Program::Gaussian) => gaussian_log::parse(file, text, overlap),
        Some(Program::Orca) => Err(error(
            file,
            1,
            "a Gaussian log (ORCA's output is recognised but not read yet)",
            "ORCA's banner \"O   R   C   A\"",
        )),
        None => Err(error(
            file,
            1,
            BANNERS,
            format!("neither banner in the first {BANNER_LINES} lines (another program's output?)"),
        )),
    }
}

pub(crate) fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// The lines of a log, each with its 1-based number, for readers that look back and forth.
pub(crate) struct LogLines<'a> {
    pub file: &'a str,
    pub lines: Vec<&'a str>,
}

impl<'a> LogLines<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self { file, lines: text.lines().collect() }
    }

    /// Line `i` (0-based), or an error at the end of the file saying what was expected.
    pub fn get(&self, i: usize, expected: &str) -> Result<&'a str, ParseError> {
        self.lines.get(i).copied().ok_or_else(|| error(self.file, self.lines.len().max(1), expected, "end of file"))
    }

    /// An error at line `i` (0-based), quoting it.
    pub fn error_at(&self, i: usize, expected: impl Into<String>) -> ParseError {
        let found = self.lines.get(i).map_or_else(|| "end of file".to_string(), |l| excerpt(l));
        error(self.file, (i + 1).min(self.lines.len().max(1)), expected, found)
    }
}

/// The last `count` numbers of `line`, printed in fields `width` characters wide (Fortran's
/// `F10.5`, which may run two numbers together) or, where the fields do not parse, separated by
/// blanks. `None` when the line does not end in that many numbers.
pub(crate) fn trailing_numbers(line: &str, count: usize, width: usize) -> Option<(Vec<f64>, &str)> {
    let line = line.trim_end();
    let span = count.checked_mul(width)?;
    if line.len() >= span && line.is_char_boundary(line.len() - span) {
        let (head, fields) = line.split_at(line.len() - span);
        let parsed: Option<Vec<f64>> =
            (0..count).map(|k| fields.get(k * width..(k + 1) * width).and_then(|f| parse_real(f.trim()))).collect();
        if let Some(values) = parsed {
            return Some((values, head));
        }
    }
    let tokens: Vec<&str> = line.split_whitespace().collect();
    let first = tokens.len().checked_sub(count)?;
    let values: Option<Vec<f64>> = tokens[first..].iter().map(|t| parse_real(t)).collect();
    let head_len = tokens[first..].first().map_or(line.len(), |t| t.as_ptr() as usize - line.as_ptr() as usize);
    Some((values?, &line[..head_len]))
}

/// Digits after the decimal point of a printed number ("-0.02805" → 5).
pub(crate) fn decimals(token: &str) -> Option<u32> {
    let (_, frac) = token.split_once('.')?;
    let digits = frac.chars().take_while(char::is_ascii_digit).count();
    u32::try_from(digits).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn programs_are_told_by_their_banner() {
        assert_eq!(program(" Entering Gaussian System, Link 0=g16\n"), Some(Program::Gaussian));
        assert_eq!(program("\n  * O   R   C   A *\n"), Some(Program::Orca));
        assert_eq!(program(" GAMESS VERSION = 30 SEP 2017\n"), None);
        let e = parse("x.out", " NWChem Input Module\n", None).unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.expected.contains("Entering Gaussian System") && e.expected.contains("O   R   C   A"), "{e}");
        assert!(e.to_string().starts_with("x.out:1:"), "{e}");
    }

    #[test]
    fn fixed_width_numbers_run_together_or_stand_apart() {
        let (v, head) = trailing_numbers("   1 1   C  1S        -10.12345-100.12345", 2, 10).unwrap();
        assert_eq!(v, vec![-10.12345, -100.12345]);
        assert_eq!(head.trim(), "1 1   C  1S");
        let (v, head) = trailing_numbers("  2  2S  0.5 -0.25", 2, 10).unwrap();
        assert_eq!(v, vec![0.5, -0.25]);
        assert_eq!(head.trim(), "2  2S");
        assert!(trailing_numbers("  2  2S  0.5", 2, 10).is_none());
        assert_eq!(decimals("-0.02805"), Some(5));
    }
}
