use thiserror::Error;

/// A malformed file: where, and what the reader expected there.
#[derive(Debug, Clone, PartialEq, Error)]
pub struct ParseError {
    pub file: String,
    /// 1-based line number; 0 when the error is the file's (or a directory's) as a whole.
    pub line: usize,
    pub expected: String,
    pub found: String,
}

impl std::fmt::Display for ParseError {
    /// `file:line: expected …, found …`, or `file: expected …` when no line is at fault.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            0 => write!(f, "{}: expected {}, found {}", self.file, self.expected, self.found),
            line => write!(f, "{}:{line}: expected {}, found {}", self.file, self.expected, self.found),
        }
    }
}

#[derive(Debug, Error)]
pub enum LoadError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not a text file (invalid UTF-8 at byte {offset})")]
    NotText { path: String, offset: usize },
    #[error("{path}: unknown file type (expected {})", super::described())]
    UnknownFormat { path: String },
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// A file named by a manifest failed to load: the manifest's line comes first.
    #[error("{manifest}:{line}: {inner}")]
    Named { manifest: String, line: usize, inner: Box<LoadError> },
}
