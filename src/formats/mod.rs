//! File readers: text -> model. Each reader stays faithful to its format and reports
//! malformed input as a typed error naming the file, the line and what was expected.

pub mod cube;
pub mod cube_write;
mod error;
pub mod fchk;
pub mod mesh_write;
pub mod molden;
pub mod scan;
mod text;
pub mod wavefunction;

pub use error::{LoadError, ParseError};
pub use wavefunction::OverlapFn;

/// The plain reference overlap matrix the readers' tests check orbitals with.
#[cfg(test)]
#[path = "../../tests/fixtures/readers/ref_overlap.rs"]
mod ref_overlap;
#[cfg(test)]
use crate::model::basis::{Basis, ShellKind};

use std::path::Path;

use crate::model::Document;

/// Largest grid a file may declare before anything is allocated: 2³⁰ values (4 GiB of f32)
/// is beyond any GPU texture the viewer can use.
pub const MAX_GRID_VALUES: u64 = 1 << 30;

/// The overlap function wavefunction readers check orbitals (and choose writer repairs) with:
/// the analytic overlap of the functions as the file writes them.
pub const DEFAULT_OVERLAP: Option<OverlapFn<'static>> = Some(&crate::model::overlap::overlap_matrix_as_written);

/// Reads a file from disk, picking the reader by extension: `.cube`, `.cub`, `.molden`,
/// `.molden.input`, `.mold`, `.fchk`, `.fch`, each also gzipped (`.gz`).
pub fn load(path: &Path) -> Result<Document, LoadError> {
    load_with(path, DEFAULT_OVERLAP)
}

/// [`load`] with the overlap function that checks (and selects repairs for) wavefunctions.
pub fn load_with(path: &Path, overlap: Option<OverlapFn>) -> Result<Document, LoadError> {
    reader_for(path)?;
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io { path: path.display().to_string(), source })?;
    load_bytes_with(path, &bytes, overlap)
}

/// Parses a file's bytes already in memory; `path` picks the reader and names the file in errors.
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Document, LoadError> {
    load_bytes_with(path, bytes, DEFAULT_OVERLAP)
}

/// [`load_bytes`] with the overlap function that checks wavefunctions.
pub fn load_bytes_with(path: &Path, bytes: &[u8], overlap: Option<OverlapFn>) -> Result<Document, LoadError> {
    let name = path.display().to_string();
    let text = gunzip_text(&name, bytes)?;
    let mut doc = match reader_for(path)? {
        Reader::Cube => cube::parse(&name, &text)?,
        Reader::Molden => molden::parse(&name, &text, overlap)?,
        Reader::Fchk => fchk::parse(&name, &text, overlap)?,
    };
    doc.source = name;
    Ok(doc)
}

enum Reader {
    Cube,
    Molden,
    Fchk,
}

fn reader_for(path: &Path) -> Result<Reader, LoadError> {
    let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
    let base = name.strip_suffix(".gz").unwrap_or(&name);
    if base.ends_with(".cube") || base.ends_with(".cub") {
        Ok(Reader::Cube)
    } else if base.ends_with(".molden") || base.ends_with(".molden.input") || base.ends_with(".mold") {
        Ok(Reader::Molden)
    } else if base.ends_with(".fchk") || base.ends_with(".fch") {
        Ok(Reader::Fchk)
    } else {
        Err(LoadError::UnknownFormat { path: path.display().to_string() })
    }
}

/// Reads a whole file, transparently gunzipping `*.gz`.
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io { path: path.display().to_string(), source })?;
    gunzip_text(&path.display().to_string(), &bytes)
}

/// Bytes as text, gunzipped first when they start with the gzip magic number.
pub fn gunzip_text(name: &str, bytes: &[u8]) -> Result<String, LoadError> {
    let bytes = if bytes.starts_with(&[0x1f, 0x8b]) {
        use std::io::Read;
        let mut out = Vec::new();
        flate2::read::MultiGzDecoder::new(bytes)
            .read_to_end(&mut out)
            .map_err(|source| LoadError::Io { path: name.to_string(), source })?;
        out
    } else {
        bytes.to_vec()
    };
    String::from_utf8(bytes)
        .map_err(|e| LoadError::NotText { path: name.to_string(), offset: e.utf8_error().valid_up_to() })
}
