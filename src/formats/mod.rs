//! File readers: text -> model. Each reader stays faithful to its format and reports
//! malformed input as a typed error naming the file, the line and what was expected.

mod cif;
pub mod cube;
pub mod cube_write;
mod e_format;
mod error;
mod excited_logs;
pub mod fchk;
mod fchk_amplitudes;
mod fchk_excited;
pub mod gamess_log;
pub mod gaussian_log;
pub mod json_wfn;
mod log_modes;
pub mod logs;
pub mod mesh_write;
pub mod mkl;
pub mod mmcif;
pub mod modes;
pub mod molden;
pub mod nwchem_log;
pub mod orca_json;
pub mod orca_log;
pub mod pdb;
mod primitives;
mod printed;
pub mod psi4_log;
pub mod qchem_log;
pub mod qcschema;
pub mod scan;
mod structure;
mod text;
pub mod wavefunction;
pub mod wfn;
pub mod wfx;
pub mod xyz;

pub use error::{LoadError, ParseError};
pub use wavefunction::OverlapFn;

/// The plain reference overlap matrix the readers' tests check orbitals with.
#[cfg(test)]
#[path = "../../tests/fixtures/readers/ref_overlap.rs"]
mod ref_overlap;
#[cfg(test)]
use crate::model::basis::{Basis, ShellKind};

/// Orbitals orthonormal in the reference overlap of `basis` (contractions already normalised),
/// by Gram–Schmidt from `start(i, k)` (coefficient `i` of orbital `k`): the readers' tests write
/// them in each program's layout and check them back.
#[cfg(test)]
fn orthonormal_orbitals(basis: &Basis, start: impl Fn(usize, usize) -> f64) -> Vec<Vec<f64>> {
    let s = ref_overlap::reference_overlap(basis);
    let n = basis.n_functions();
    let dot =
        |a: &[f64], b: &[f64]| -> f64 { (0..n).map(|i| (0..n).map(|j| a[i] * s[i * n + j] * b[j]).sum::<f64>()).sum() };
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for k in 0..n {
        let mut v: Vec<f64> = (0..n).map(|i| start(i, k)).collect();
        for c in &cols {
            let p = dot(&v, c);
            v.iter_mut().zip(c).for_each(|(x, y)| *x -= p * y);
        }
        let norm = dot(&v, &v).sqrt();
        v.iter_mut().for_each(|x| *x /= norm);
        cols.push(v);
    }
    cols
}

use std::path::Path;

use crate::model::Document;

/// Largest grid a file may declare before anything is allocated: 2³⁰ values (4 GiB of f32)
/// is beyond any GPU texture the viewer can use.
pub const MAX_GRID_VALUES: u64 = 1 << 30;

/// The overlap function wavefunction readers check orbitals (and choose writer repairs) with:
/// the analytic overlap of the functions as the file writes them.
pub const DEFAULT_OVERLAP: Option<OverlapFn<'static>> = Some(&crate::model::overlap::overlap_matrix_as_written);

/// Largest atomic number a file may give (oganesson); 0 is a ghost centre.
pub const MAX_Z: u32 = 118;

/// Longest line a reader accepts: a longer one is refused before it is buffered whole (JSON,
/// which writers may put on one line, is bounded by the gzip guard and its parser instead).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Blank bytes a cube may carry after the values its header declares before reading stops.
pub const MAX_TRAILING_BYTES: usize = 64 << 10;

/// Reads a file from disk, picking the reader by the ending of its name ([`FORMATS`]).
pub fn load(path: &Path) -> Result<Document, LoadError> {
    load_with(path, DEFAULT_OVERLAP)
}

/// [`load`] with the overlap function that checks (and selects repairs for) wavefunctions.
pub fn load_with(path: &Path, overlap: Option<OverlapFn>) -> Result<Document, LoadError> {
    let reader = reader_for(path)?;
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| LoadError::Io { path: name.clone(), source })?;
    let text = read_bounded(&name, std::io::BufReader::new(file), Some(reader))?;
    parse_text(&name, reader, text, overlap)
}

/// Parses a file's bytes already in memory; `path` picks the reader and names the file in errors.
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Document, LoadError> {
    load_bytes_with(path, bytes, DEFAULT_OVERLAP)
}

/// [`load_bytes`] with the overlap function that checks wavefunctions.
pub fn load_bytes_with(path: &Path, bytes: &[u8], overlap: Option<OverlapFn>) -> Result<Document, LoadError> {
    let name = path.display().to_string();
    let reader = reader_for(path)?;
    let text = read_bounded(&name, bytes, Some(reader))?;
    parse_text(&name, reader, text, overlap)
}

fn parse_text(name: &str, reader: Reader, text: Bounded, overlap: Option<OverlapFn>) -> Result<Document, LoadError> {
    let parsed = match reader {
        Reader::Cube => cube::parse(name, &text.text),
        Reader::Molden => molden::parse(name, &text.text, overlap),
        Reader::Fchk => fchk::parse(name, &text.text, overlap),
        Reader::Wfn => wfn::parse(name, &text.text, overlap),
        Reader::Wfx => wfx::parse(name, &text.text, overlap),
        Reader::Mkl => mkl::parse(name, &text.text, overlap),
        Reader::Json => json_wfn::parse(name, &text.text, overlap),
        Reader::Pdb => pdb::parse(name, &text.text),
        Reader::Mmcif => mmcif::parse(name, &text.text),
        Reader::Xyz => xyz::parse(name, &text.text),
        Reader::Log => logs::parse(name, &text.text, overlap),
    };
    // When reading stopped early the parser names the first fault in what was read, if it
    // sees one; otherwise the reason reading stopped is the error.
    let mut doc = match (parsed, text.stopped) {
        (Err(e), _) | (Ok(_), Some(e)) => return Err(e.into()),
        (Ok(doc), None) => doc,
    };
    doc.source = name.to_string();
    Ok(doc)
}

#[derive(Clone, Copy)]
enum Reader {
    Cube,
    Molden,
    Fchk,
    Wfn,
    Wfx,
    Mkl,
    Json,
    Pdb,
    Mmcif,
    Xyz,
    Log,
}

/// A file format a reader takes: what users call it and the file name endings it has (each also
/// with `.gz`).
pub struct Format {
    pub name: &'static str,
    pub endings: &'static [&'static str],
    reader: Reader,
}

/// Every format orbcloud reads. The command line's help, the unknown-type message and the
/// viewer's file chooser are made from this table, so a new reader is one row here.
pub const FORMATS: &[Format] = &[
    Format { name: "Gaussian cube", endings: &[".cube", ".cub"], reader: Reader::Cube },
    Format { name: "Molden", endings: &[".molden", ".molden.input", ".mold"], reader: Reader::Molden },
    Format { name: "Gaussian formatted checkpoint", endings: &[".fchk", ".fch"], reader: Reader::Fchk },
    Format { name: "AIM wavefunction", endings: &[".wfn"], reader: Reader::Wfn },
    Format { name: "AIM extended wavefunction", endings: &[".wfx"], reader: Reader::Wfx },
    Format { name: "ORCA Molekel", endings: &[".mkl"], reader: Reader::Mkl },
    Format { name: "JSON wavefunction (ORCA orca_2json, QCSchema)", endings: &[".json"], reader: Reader::Json },
    Format { name: "PDB", endings: &[".pdb", ".ent"], reader: Reader::Pdb },
    Format { name: "mmCIF", endings: &[".cif", ".mmcif"], reader: Reader::Mmcif },
    Format { name: "XYZ", endings: &[".xyz"], reader: Reader::Xyz },
    Format { name: "Gaussian or ORCA output", endings: &[".log", ".out"], reader: Reader::Log },
];

/// The file name endings [`load`] reads (each also gzipped, `.gz`).
pub fn extensions() -> impl Iterator<Item = &'static str> {
    FORMATS.iter().flat_map(|f| f.endings.iter().copied())
}

/// Whether `name` (maybe gzipped) ends as a Molden or fchk file does: the wavefunctions a scan's
/// frames are.
pub fn is_molden_or_fchk(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    let n = n.strip_suffix(".gz").unwrap_or(&n);
    (FORMATS.iter())
        .filter(|f| matches!(f.reader, Reader::Molden | Reader::Fchk))
        .flat_map(|f| f.endings.iter())
        .any(|e| n.ends_with(e))
}

/// The formats in words: "Gaussian cube (.cube, .cub), Molden (…), … or XYZ (.xyz), each also
/// gzipped (.gz)".
pub fn described() -> String {
    let each: Vec<String> = FORMATS.iter().map(|f| format!("{} ({})", f.name, f.endings.join(", "))).collect();
    let (last, rest) = each.split_last().expect("at least one format");
    format!("{} or {last}, each also gzipped (.gz)", rest.join(", "))
}

fn reader_for(path: &Path) -> Result<Reader, LoadError> {
    let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
    let base = name.strip_suffix(".gz").unwrap_or(&name);
    FORMATS
        .iter()
        .find(|f| f.endings.iter().any(|e| base.ends_with(e)))
        .map(|f| f.reader)
        .ok_or_else(|| LoadError::UnknownFormat { path: path.display().to_string() })
}

/// Reads a whole file, transparently gunzipping `*.gz`, within the bounds of [`read_bounded`].
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| LoadError::Io { path: name.clone(), source })?;
    read_bounded(&name, std::io::BufReader::new(file), reader_for(path).ok())?.into_whole()
}

/// Bytes as text, gunzipped first when they start with the gzip magic number.
pub fn gunzip_text(name: &str, bytes: &[u8]) -> Result<String, LoadError> {
    read_bounded(name, bytes, None)?.into_whole()
}

/// Text read within bounds; `stopped` says why reading ended before the end of the input.
struct Bounded {
    text: String,
    stopped: Option<ParseError>,
}

impl Bounded {
    fn into_whole(self) -> Result<String, LoadError> {
        match self.stopped {
            Some(e) => Err(e.into()),
            None => Ok(self.text),
        }
    }
}

/// Reads (and gunzips) `input` as text, refusing, as soon as it appears and before more is
/// inflated: a control byte (a binary file), a line longer than [`MAX_LINE_BYTES`], and, for a
/// cube, data beyond what its header declares. A decompression bomb thus costs no more memory
/// than its header honestly implies.
fn read_bounded(name: &str, mut input: impl std::io::BufRead, reader: Option<Reader>) -> Result<Bounded, LoadError> {
    let io = |source| LoadError::Io { path: name.to_string(), source };
    if input.fill_buf().map_err(io)?.starts_with(&[0x1f, 0x8b]) {
        let consumed = std::cell::Cell::new(0u64);
        let counted = Counted { inner: input, consumed: &consumed };
        read_stream(name, flate2::bufread::MultiGzDecoder::new(counted), reader, Some(&consumed))
    } else {
        read_stream(name, input, reader, None)
    }
}

/// Inflated text beyond this needs no more than [`MAX_INFLATION`] bytes per compressed byte.
pub const INFLATION_FLOOR: u64 = 32 << 20;

/// Deflate reaches ~1000:1 only on degenerate input (a decompression bomb); text compresses
/// tenfold or so. Cubes are bounded by their header instead, so a cube of zeros may exceed it.
pub const MAX_INFLATION: u64 = 200;

/// A reader that counts the compressed bytes the decoder has consumed.
struct Counted<'a, R> {
    inner: R,
    consumed: &'a std::cell::Cell<u64>,
}

impl<R: std::io::BufRead> std::io::Read for Counted<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.consumed.set(self.consumed.get() + n as u64);
        Ok(n)
    }
}

impl<R: std::io::BufRead> std::io::BufRead for Counted<'_, R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }
    fn consume(&mut self, n: usize) {
        self.consumed.set(self.consumed.get() + n as u64);
        self.inner.consume(n);
    }
}

fn read_stream(
    name: &str,
    mut input: impl std::io::Read,
    reader: Option<Reader>,
    compressed: Option<&std::cell::Cell<u64>>,
) -> Result<Bounded, LoadError> {
    let mut out = Vec::new();
    let mut chunk = vec![0u8; 256 << 10];
    // JSON writers (QCElemental) put a whole file on one line; its parser needs no lines.
    let max_line = if matches!(reader, Some(Reader::Json)) { usize::MAX } else { MAX_LINE_BYTES };
    let mut lines = LineGuard { line: 1, len: 0, max: max_line };
    let mut cube = matches!(reader, Some(Reader::Cube)).then(cube::ValueGuard::default);
    let mut stopped = None;
    loop {
        let n = match input.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(source) => return Err(LoadError::Io { path: name.to_string(), source }),
        };
        out.extend_from_slice(&chunk[..n]);
        if let Err(e) = lines.scan(name, &chunk[..n]) {
            return Err(e.into());
        }
        let inflated = out.len() as u64;
        if let Some(c) = compressed.map(std::cell::Cell::get)
            && cube.is_none()
            && inflated > INFLATION_FLOOR.max(c.saturating_mul(MAX_INFLATION))
        {
            return Err(ParseError {
                file: name.to_string(),
                line: lines.line,
                expected: format!(
                    "a gzip stream that inflates at most {MAX_INFLATION}-fold beyond {INFLATION_FLOOR} bytes"
                ),
                found: format!("{inflated} bytes from {c} compressed bytes (a decompression bomb)"),
            }
            .into());
        }
        if let Some(guard) = &mut cube
            && let Some(found) = guard.scan(&out)
        {
            // Keep whole tokens only, so that the text stays valid UTF-8 and the parser sees
            // no half value.
            let keep = out.iter().rposition(u8::is_ascii_whitespace).map_or(0, |p| p + 1);
            out.truncate(keep);
            stopped = Some(ParseError {
                file: name.to_string(),
                line: text::line_at(&out, out.len()),
                expected: "the end of the file after the values its header declares".into(),
                found,
            });
            break;
        }
    }
    let text = String::from_utf8(out)
        .map_err(|e| LoadError::NotText { path: name.to_string(), offset: e.utf8_error().valid_up_to() })?;
    Ok(Bounded { text, stopped })
}

/// Counts lines as bytes arrive; refuses control bytes and over-long lines.
struct LineGuard {
    line: usize,
    len: usize,
    max: usize,
}

impl LineGuard {
    fn scan(&mut self, name: &str, bytes: &[u8]) -> Result<(), ParseError> {
        let error =
            |line, expected: String, found: String| ParseError { file: name.to_string(), line, expected, found };
        // Tab, vertical tab, form feed, carriage return and a DOS end-of-file mark occur in text
        // files; any other control byte means binary data. (Fold, not `any`: it vectorises.)
        let control = |b: u8| b < 0x20 && !matches!(b, b'\t' | b'\n' | 0x0b | 0x0c | b'\r' | 0x1a);
        if bytes.iter().fold(false, |bad, &b| bad | control(b)) {
            let i = bytes.iter().position(|&b| control(b)).unwrap_or(0);
            let line = self.line + bytes[..i].iter().filter(|&&b| b == b'\n').count();
            return Err(error(line, "text".into(), format!("the control byte 0x{:02x} (binary data)", bytes[i])));
        }
        for (k, segment) in bytes.split(|&b| b == b'\n').enumerate() {
            if k > 0 {
                self.line += 1;
                self.len = 0;
            }
            self.len += segment.len();
            if self.len > self.max {
                return Err(error(self.line, format!("a line of at most {} bytes", self.max), "a longer line".into()));
            }
        }
        Ok(())
    }
}
