//! File readers: text -> model. Each reader stays faithful to its format and reports
//! malformed input as a typed error naming the file, the line and what was expected.

pub mod cube;
pub mod cube_write;
mod error;
mod text;

pub use error::{LoadError, ParseError};

use std::path::Path;

use crate::model::Document;

/// Largest grid a file may declare before anything is allocated: 2³⁰ values (4 GiB of f32)
/// is beyond any GPU texture the viewer can use.
pub const MAX_GRID_VALUES: u64 = 1 << 30;

/// Reads a file from disk, picking the reader by extension (`.cube`, `.cub`, `.cube.gz`).
pub fn load(path: &Path) -> Result<Document, LoadError> {
    reader_for(path)?;
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io { path: path.display().to_string(), source })?;
    load_bytes(path, &bytes)
}

/// Parses a file's bytes already in memory; `path` picks the reader and names the file in errors.
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Document, LoadError> {
    let name = path.display().to_string();
    let text = gunzip_text(&name, bytes)?;
    let mut doc = match reader_for(path)? {
        Reader::Cube => cube::parse(&name, &text)?,
    };
    doc.source = name;
    Ok(doc)
}

enum Reader {
    Cube,
}

fn reader_for(path: &Path) -> Result<Reader, LoadError> {
    let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
    let base = name.strip_suffix(".gz").unwrap_or(&name);
    if base.ends_with(".cube") || base.ends_with(".cub") {
        Ok(Reader::Cube)
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
