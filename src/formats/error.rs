use thiserror::Error;

/// A malformed file: where, and what the reader expected there.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{file}:{line}: expected {expected}, found {found}")]
pub struct ParseError {
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    pub expected: String,
    pub found: String,
}

#[derive(Debug, Error)]
pub enum LoadError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not a text file (invalid UTF-8 at byte {offset})")]
    NotText { path: String, offset: usize },
    #[error(
        "{path}: unknown file type (expected .cube, .cub, .molden, .molden.input, .mold, .fchk, .fch, .wfn, .wfx, .mkl, .pdb, .ent, .cif, .mmcif or .xyz, optionally .gz)"
    )]
    UnknownFormat { path: String },
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// A file named by a manifest failed to load: the manifest's line comes first.
    #[error("{manifest}:{line}: {inner}")]
    Named { manifest: String, line: usize, inner: Box<LoadError> },
}
