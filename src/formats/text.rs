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

/// A Fortran real as [`parse_real`] reads it, also with a three-digit exponent written without
/// its letter (`0.12345678-100`: what Fortran's `E16.8` prints for 1.2e-101).
pub(crate) fn parse_fortran_real(token: &str) -> Option<f64> {
    parse_real(token).or_else(|| {
        let at = token.rfind(['+', '-']).filter(|&i| i > 0 && token.as_bytes()[i - 1].is_ascii_digit())?;
        let (mantissa, exponent) = token.split_at(at);
        let exponent: i32 = exponent.parse().ok()?;
        let v = mantissa.parse::<f64>().ok()? * 10f64.powi(exponent);
        v.is_finite().then_some(v)
    })
}

/// The numbers of a line of Fortran fixed-width fields: split at whitespace and before a minus
/// sign that follows a digit or a point and starts a number with a point of its own, since a
/// negative value that fills its field leaves no space before it (`-12.34567890-10.12345678` is
/// two `F12.8` fields; `0.12345678-100` stays one, a letterless exponent).
pub(crate) fn fortran_fields(line: &str) -> Vec<&str> {
    let mut out = Vec::new();
    for word in line.split_whitespace() {
        let b = word.as_bytes();
        let mut start = 0;
        for i in 1..b.len() {
            let after_number = b[i - 1].is_ascii_digit() || b[i - 1] == b'.';
            if b[i] == b'-' && after_number && word[i + 1..].split('-').next().is_some_and(|s| s.contains('.')) {
                out.push(&word[start..i]);
                start = i;
            }
        }
        out.push(&word[start..]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_numbers() {
        assert_eq!(parse_fortran_real("0.8588500D+04"), Some(8588.5));
        assert_eq!(parse_fortran_real("-0.5D-02"), Some(-0.005));
        let tiny = parse_fortran_real("0.12345678-100").expect("a letterless exponent");
        assert!((tiny / 1.2345678e-101 - 1.0).abs() < 1e-12);
        assert_eq!(parse_fortran_real("0.1+002"), Some(10.0));
        assert_eq!(parse_fortran_real("-"), None);
        assert_eq!(parse_fortran_real("1.0.0"), None);
        assert_eq!(
            fortran_fields("  -12.34567890-10.12345678  0.5E-02-0.3D+00 0.12345678-100"),
            ["-12.34567890", "-10.12345678", "0.5E-02", "-0.3D+00", "0.12345678-100"]
        );
        assert_eq!(fortran_fields("1.0 2.0"), ["1.0", "2.0"]);
    }
}
