//! Gaussian cube files (GUIDE §3).
//!
//! ```text
//! comment line 1
//! comment line 2
//! NAtoms  ox oy oz  [NVal]
//! N1  v1x v1y v1z             axis 1, slowest
//! N2  v2x v2y v2z
//! N3  v3x v3y v3z             axis 3, fastest
//! Z  charge  x y z            |NAtoms| lines
//! m  id1 … idm                only when NAtoms < 0 (may wrap); some writers (Molden) also with NAtoms > 0
//! values …                    x slowest, z fastest; the values of all data sets of a point adjacent
//! ```
//!
//! [`CubeFile::parse`] reads the file as written; [`CubeFile::into_document`] is the one place where
//! its units and layout become the model (bohr, one [`VolumeGrid`] per data set).
//!
//! Units: a negative `N_i` says that axis vector is in ångström, a positive one bohr. Gaussian
//! writes a whole file in one unit and flags it on every axis; the origin and the atom positions
//! carry no flag of their own, so they follow the first axis: when `N1 < 0` they are read as
//! ångström as well.

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use super::text::{Lines, excerpt, line_at, parse_real};
use super::{LoadError, MAX_GRID_VALUES, MAX_TRAILING_BYTES, MAX_Z, ParseError};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Atom, Document, Molecule, VolumeGrid};

/// Reads a `.cube` (or gzipped `.cube.gz`) file from disk.
pub fn load(path: &Path) -> Result<Document, LoadError> {
    let text = super::read_text(path)?;
    parse(&path.display().to_string(), &text).map_err(LoadError::from)
}

/// Parses cube text into a document; `file` names the source in errors.
pub fn parse(file: &str, text: &str) -> Result<Document, ParseError> {
    Ok(CubeFile::parse(file, text)?.into_document(file))
}

/// One grid axis as written: the signed point count and the step vector in the file's unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeAxis {
    /// Number of points; negative when `step` is in ångström.
    pub count: i64,
    pub step: [f64; 3],
}

impl CubeAxis {
    pub fn points(&self) -> usize {
        self.count.unsigned_abs() as usize
    }

    pub fn is_angstrom(&self) -> bool {
        self.count < 0
    }
}

/// One atom line as written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeAtom {
    /// Atomic number; 0 for a ghost or dummy centre.
    pub z: u32,
    /// The second column: usually Z, sometimes 0 or a pseudo-potential charge.
    pub charge: f64,
    /// In the file's unit (see the module documentation).
    pub position: [f64; 3],
}

/// A cube file as written, before any unit conversion.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeFile {
    pub comments: [String; 2],
    /// The atom count as written; negative when a data-set line follows the atoms.
    pub natoms: i64,
    pub origin: [f64; 3],
    /// The optional fifth field of line 3: values per grid point.
    pub nval: Option<i64>,
    pub axes: [CubeAxis; 3],
    pub atoms: Vec<CubeAtom>,
    /// The ids of the `m id1 … idm` line, when the file has one.
    pub dataset_ids: Option<Vec<i64>>,
    /// All values in file order: `dims[0] * dims[1] * dims[2] * values_per_point()` of them.
    pub values: Vec<f32>,
}

/// Whitespace between tokens (ASCII space, tab, newline, carriage return, vertical tab, form feed).
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

const LINE3: &str =
    "`NAtoms ox oy oz [NVal]` (an integer atom count, the origin, optionally the integer number of values per point)";
const ID_LINE: &str = "the data-set line `m id1 … idm` that follows the atoms when NAtoms is negative";

impl CubeFile {
    /// Points along each axis.
    pub fn dims(&self) -> [usize; 3] {
        self.axes.map(|a| a.points())
    }

    /// The comment line that names what the values are: the second when it names a quantity
    /// (cubegen: "Electrostatic potential from Total SCF Density", under the job's title),
    /// else the first when it does (PySCF: "Molecular electrostatic potential in real space",
    /// its version second), else the second, else none.
    fn quantity_comment(&self) -> Option<&str> {
        const QUANTITIES: [&str; 8] = ["density", "potential", "orbital", "esp", "mep", "spin", "laplacian", "elf"];
        let names = |c: &&str| {
            let c = c.to_ascii_lowercase();
            c.split(|ch: char| !ch.is_ascii_alphanumeric()).any(|w| QUANTITIES.contains(&w))
        };
        let mut lines = self.comments.iter().rev().map(|c| c.trim()).filter(|c| !c.is_empty());
        lines.find(names).or_else(|| Some(self.comments[1].trim()).filter(|c| !c.is_empty()))
    }

    /// Values stored per grid point (the number of data sets).
    pub fn values_per_point(&self) -> usize {
        match &self.dataset_ids {
            Some(ids) => ids.len(),
            None => self.nval.map_or(1, |n| n.max(1) as usize),
        }
    }

    /// Reads the file as written. Every malformation is an error naming its 1-based line.
    pub fn parse(file: &str, text: &str) -> Result<Self, ParseError> {
        let bytes = text.as_bytes();
        if text.trim().is_empty() {
            return Err(error(file, 1, "a cube file: two comment lines, then `NAtoms ox oy oz`", "an empty file"));
        }
        let mut lines = Lines::new(file, text);
        let comments = [
            lines.next_line("comment line 1")?.to_string(),
            lines.next_line("comment line 2, then `NAtoms ox oy oz`")?.to_string(),
        ];

        // Line 3: NAtoms ox oy oz [NVal]
        let l3 = lines.next_line(LINE3)?;
        let t: Vec<&str> = l3.split_whitespace().collect();
        let bad3 = || error(file, 3, LINE3, excerpt(l3));
        if !(4..=5).contains(&t.len()) {
            return Err(bad3());
        }
        let natoms: i64 = t[0].parse().map_err(|_| bad3())?;
        let origin = read3(&t[1..4]).ok_or_else(bad3)?;
        let nval = match t.get(4) {
            None => None,
            Some(s) => match s.parse::<i64>() {
                Ok(n) if n >= 1 => Some(n),
                _ => return Err(error(file, 3, "NVal (values per point) ≥ 1", excerpt(s))),
            },
        };

        // Lines 4-6: N vx vy vz
        let mut axes = [CubeAxis { count: 0, step: [0.0; 3] }; 3];
        for (a, axis) in axes.iter_mut().enumerate() {
            let expected = || format!("axis {} as `N vx vy vz` (an integer point count, the step vector)", a + 1);
            let l = lines.next_line("").map_err(|e| ParseError { expected: expected(), ..e })?;
            let t: Vec<&str> = l.split_whitespace().collect();
            let bad = || lines.error(&expected(), &excerpt(l));
            if t.len() != 4 {
                return Err(bad());
            }
            let count: i64 = t[0].parse().map_err(|_| bad())?;
            if count == 0 {
                return Err(lines.error(&format!("a non-zero number of points on axis {}", a + 1), "0"));
            }
            *axis = CubeAxis { count, step: read3(&t[1..4]).ok_or_else(bad)? };
        }
        check_axes(file, &axes)?;
        let dims = axes.map(|a| a.count.unsigned_abs());
        let grid_points = dims.iter().try_fold(1u64, |p, &n| p.checked_mul(n));
        let per_point = if natoms >= 0 { nval.unwrap_or(1) as u64 } else { 1 };
        match grid_points.and_then(|p| p.checked_mul(per_point)) {
            Some(n) if n <= MAX_GRID_VALUES => {}
            _ => {
                let per = if per_point > 1 { format!(" × {per_point} values per point") } else { String::new() };
                return Err(error(
                    file,
                    6,
                    format!("at most {MAX_GRID_VALUES} grid values"),
                    format!("{}×{}×{} points{per}", dims[0], dims[1], dims[2]),
                ));
            }
        }
        let grid_points = grid_points.unwrap_or(0);

        // Atoms. Each line needs at least 10 bytes (`1 0 0 0 0` and a newline).
        let n_atoms = natoms.unsigned_abs();
        let after_header = lines.rest().len() as u64;
        if n_atoms.saturating_mul(10) > after_header + 1 {
            return Err(error(
                file,
                3,
                format!(
                    "an atom count the file can hold ({n_atoms} atom lines need at least {} bytes)",
                    n_atoms.saturating_mul(10) - 1
                ),
                format!("{natoms} with {after_header} bytes after the header"),
            ));
        }
        let mut atoms = Vec::with_capacity(n_atoms as usize);
        for i in 0..n_atoms {
            let expected = || format!("atom {} of {n_atoms} as `Z charge x y z`", i + 1);
            let l = lines.next_line("").map_err(|e| ParseError { expected: expected(), ..e })?;
            let t: Vec<&str> = l.split_whitespace().collect();
            let bad = || lines.error(&expected(), &excerpt(l));
            if t.len() != 5 {
                return Err(bad());
            }
            let z: i64 = t[0].parse().map_err(|_| bad())?;
            let z = u32::try_from(z).ok().filter(|&z| z <= MAX_Z).ok_or_else(|| {
                lines.error(&format!("an atomic number 0..={MAX_Z} (0 for a ghost) for atom {}", i + 1), t[0])
            })?;
            let charge = parse_real(t[1]).ok_or_else(bad)?;
            atoms.push(CubeAtom { z, charge, position: read3(&t[2..5]).ok_or_else(bad)? });
        }
        let mut pos = text.len() - lines.rest().len();

        // The data-set line, then the values.
        let shape = |m: u64| {
            let per = if m > 1 { format!(" × {m} values per point") } else { String::new() };
            format!("{}×{}×{} points{per}", dims[0], dims[1], dims[2])
        };
        let (dataset_ids, values) = if natoms < 0 {
            let (ids, id_line) = read_dataset_ids(file, text, &mut pos)?;
            let m = ids.len() as u64;
            if let Some(n) = nval.filter(|&n| n > 1 && n as u64 != m) {
                return Err(error(file, id_line, format!("{n} data-set ids (NVal on line 3)"), format!("{m}")));
            }
            if grid_points.checked_mul(m).is_none_or(|n| n > MAX_GRID_VALUES) {
                return Err(error(file, id_line, format!("at most {MAX_GRID_VALUES} grid values"), shape(m)));
            }
            let values = read_values(file, bytes, pos, grid_points * m, &shape(m))?;
            (Some(ids), values)
        } else if nval.unwrap_or(1) == 1
            && let Some((ids, start, end)) = molden_ids(text, pos)
        {
            // An integer-only first line `m id1 … idm` is a data-set line only if the values that
            // follow fit the grid with m values per point and would not fit it as plain data.
            let m = ids.len() as u64;
            let plain = count_tokens(&bytes[end..]) + m + 1 == grid_points;
            if plain {
                (None, read_values(file, bytes, start, grid_points, &shape(1))?)
            } else {
                if grid_points.checked_mul(m).is_none_or(|n| n > MAX_GRID_VALUES) {
                    return Err(error(
                        file,
                        line_at(bytes, start),
                        format!("at most {MAX_GRID_VALUES} grid values"),
                        shape(m),
                    ));
                }
                (Some(ids), read_values(file, bytes, end, grid_points * m, &shape(m))?)
            }
        } else {
            (None, read_values(file, bytes, pos, grid_points * per_point, &shape(per_point))?)
        };

        Ok(Self { comments, natoms, origin, nval, axes, atoms, dataset_ids, values })
    }

    /// The model: positions in bohr, one volume per data set, ghosts for Z = 0.
    pub fn into_document(self, source: &str) -> Document {
        let scale = |axis: &CubeAxis| {
            if axis.is_angstrom() { BOHR_PER_ANGSTROM } else { 1.0 }
        };
        // Origin and atoms follow the unit flag of the first axis (see the module documentation).
        let frame = scale(&self.axes[0]);
        let origin = DVec3::from_array(self.origin) * frame;
        let steps = self.axes.map(|a| DVec3::from_array(a.step) * scale(&a));
        let world_from_grid = VolumeGrid::affine(origin, steps);
        let dims = self.dims();

        let atoms = self
            .atoms
            .iter()
            .map(|a| Atom {
                z: a.z,
                charge: a.charge,
                position: DVec3::from_array(a.position) * frame,
                ghost: a.z == 0,
            })
            .collect();
        let molecule = Molecule::new(atoms);

        let title = [&self.comments[0], &self.comments[1]]
            .into_iter()
            .map(|c| c.trim())
            .find(|c| !c.is_empty())
            .unwrap_or(source)
            .to_string();

        let m = self.values_per_point();
        let labels: Vec<String> = match (&self.dataset_ids, m) {
            (Some(ids), _) => ids.iter().map(|id| format!("MO {id}")).collect(),
            (None, 1) => vec![self.quantity_comment().unwrap_or("values").to_string()],
            (None, m) => (1..=m).map(|id| format!("data set {id}")).collect(),
        };
        let volumes = if m == 1 {
            let label = labels.into_iter().next().unwrap_or_default();
            vec![VolumeGrid::new(label, dims, world_from_grid, self.values)]
        } else {
            let values = &self.values;
            labels
                .into_par_iter()
                .enumerate()
                .map(|(d, label)| {
                    let v = values.iter().skip(d).step_by(m).copied().collect();
                    VolumeGrid::new(label, dims, world_from_grid, v)
                })
                .collect()
        };

        Document { source: source.to_string(), title, molecule, volumes, ..Document::default() }
    }
}

/// Refuses a singular grid: axis vectors that span no volume (zero, parallel or coplanar) would
/// leave the grid without an inverse transform. |det| is compared with the product of the step
/// lengths, so the test does not depend on the unit or the grid spacing.
fn check_axes(file: &str, axes: &[CubeAxis; 3]) -> Result<(), ParseError> {
    let [a, b, c] = axes.map(|a| DVec3::from_array(a.step));
    let det = a.dot(b.cross(c));
    let lengths = a.length() * b.length() * c.length();
    if det.abs() > 1e-6 * lengths && det.is_finite() {
        return Ok(());
    }
    Err(error(
        file,
        6,
        "three linearly independent axis vectors (a grid that spans a volume)",
        format!(
            "axis vectors whose determinant is {det:e} (step lengths {:e}, {:e}, {:e})",
            a.length(),
            b.length(),
            c.length()
        ),
    ))
}

/// Watches a cube arrive, so that reading stops as soon as the data exceed what the header
/// declares (see [`super::read_bounded`]): it finds the header, then counts the tokens after it.
#[derive(Debug, Default)]
pub(crate) struct ValueGuard {
    /// Where the data start and the most tokens they may hold, once the header is complete.
    declared: Option<(usize, u64)>,
    /// Bytes scanned so far, tokens seen, whether the last byte scanned was a space, and the
    /// end of the last token.
    pos: usize,
    tokens: u64,
    after_space: bool,
    last_end: usize,
}

impl ValueGuard {
    /// Looks at the bytes of `text` (the file so far) not seen yet; `Some(reason)` when reading
    /// should stop.
    pub(crate) fn scan(&mut self, text: &[u8]) -> Option<String> {
        if self.declared.is_none() {
            match declared(text) {
                Declared::NeedMore => return None,
                Declared::Broken => return Some("a header that does not declare a grid".into()),
                Declared::Tokens { start, max } => {
                    self.declared = Some((start, max));
                    (self.pos, self.last_end, self.after_space) = (start, start, true);
                }
            }
        }
        let (_, max) = self.declared?;
        let new = text.get(self.pos..).filter(|n| !n.is_empty())?;
        // A token starts at a non-space after a space; counted pairwise, so that it vectorises.
        let first = u64::from(self.after_space && !is_space(new[0]));
        self.tokens += first + new.windows(2).filter(|w| is_space(w[0]) && !is_space(w[1])).count() as u64;
        self.after_space = new.last().is_some_and(|&b| is_space(b));
        if let Some(p) = new.iter().rposition(|&b| !is_space(b)) {
            self.last_end = self.pos + p + 1;
        }
        self.pos = text.len();
        if self.tokens > max {
            return Some(format!("more than the {max} values it declares"));
        }
        (self.tokens == max && self.after_space && text.len() - self.last_end > MAX_TRAILING_BYTES)
            .then(|| format!("more than {MAX_TRAILING_BYTES} bytes after the {max} values it declares"))
    }
}

/// What the start of a cube declares.
#[derive(Debug, PartialEq)]
enum Declared {
    /// The header is not complete yet.
    NeedMore,
    /// The header is malformed: the parser will say how.
    Broken,
    /// The data start at byte `start` and hold at most `max` tokens (a data-set line included).
    Tokens { start: usize, max: u64 },
}

/// The next complete line (ending in a newline) from `*pos`, as text.
fn complete_line<'a>(prefix: &'a [u8], pos: &mut usize) -> Option<&'a str> {
    let n = prefix.get(*pos..)?.iter().position(|&b| b == b'\n')?;
    let line = &prefix[*pos..*pos + n];
    *pos += n + 1;
    // Invalid UTF-8 cannot be a header: an empty "line" makes the caller report it broken.
    Some(std::str::from_utf8(line).unwrap_or(""))
}

/// A light reading of a cube's header from the first bytes of the file, for [`ValueGuard`]; the
/// parser checks everything again.
fn declared(prefix: &[u8]) -> Declared {
    let mut pos = 0;
    for _ in 0..2 {
        if complete_line(prefix, &mut pos).is_none() {
            return Declared::NeedMore;
        }
    }
    let ints = |l: &str| l.split_whitespace().map(|t| t.parse::<i64>().ok()).collect::<Vec<_>>();
    let Some(line3) = complete_line(prefix, &mut pos) else { return Declared::NeedMore };
    let t: Vec<&str> = line3.split_whitespace().collect();
    let Some(Ok(natoms)) = t.first().map(|n| n.parse::<i64>()) else { return Declared::Broken };
    let nval = match t.get(4).map(|n| n.parse::<u64>()) {
        None => 1,
        Some(Ok(n)) if n >= 1 => n,
        _ => return Declared::Broken,
    };
    let mut grid = 1u64;
    for _ in 0..3 {
        let Some(l) = complete_line(prefix, &mut pos) else { return Declared::NeedMore };
        match ints(l).first() {
            Some(Some(n)) if *n != 0 => grid = grid.saturating_mul(n.unsigned_abs()),
            _ => return Declared::Broken,
        }
    }
    if grid.saturating_mul(nval) > MAX_GRID_VALUES {
        return Declared::Broken;
    }
    for _ in 0..natoms.unsigned_abs() {
        if complete_line(prefix, &mut pos).is_none() {
            return Declared::NeedMore;
        }
    }
    let start = pos;
    // The first non-blank line after the atoms may be a data-set line `m id1 … idm`.
    let first = loop {
        match complete_line(prefix, &mut pos) {
            None => return Declared::NeedMore,
            Some(l) if l.trim().is_empty() => continue,
            Some(l) => break ints(l),
        }
    };
    let m = match first.first() {
        Some(Some(m)) if *m >= 1 => *m as u64,
        _ if natoms < 0 => return Declared::Broken,
        _ => 0,
    };
    let max = if natoms < 0 {
        // The id line may wrap: only m is known to be on this line.
        (m + 1).saturating_add(grid.saturating_mul(m))
    } else if nval == 1 && m > 0 && first.len() as u64 == m + 1 && first.iter().all(Option::is_some) {
        grid.max((m + 1).saturating_add(grid.saturating_mul(m)))
    } else {
        grid * nval
    };
    Declared::Tokens { start, max }
}

fn read3(t: &[&str]) -> Option<[f64; 3]> {
    Some([parse_real(t[0])?, parse_real(t[1])?, parse_real(t[2])?])
}

/// The next whitespace-separated token at or after `*pos`, with its byte offset.
fn next_token<'a>(text: &'a str, pos: &mut usize) -> Option<(usize, &'a str)> {
    let b = text.as_bytes();
    let mut i = *pos;
    while i < b.len() && is_space(b[i]) {
        i += 1;
    }
    let start = i;
    while i < b.len() && !is_space(b[i]) {
        i += 1;
    }
    *pos = i;
    (i > start).then(|| (start, &text[start..i]))
}

/// 1-based line of the last non-blank byte (the header's last line when no data follow).
fn last_line(bytes: &[u8]) -> usize {
    line_at(bytes, bytes.iter().rposition(|&b| !is_space(b)).unwrap_or(0))
}

/// `m id1 … idm` after the atoms of a NAtoms < 0 file (may wrap over lines). Returns the ids
/// and the line of `m`, and moves `pos` past the last id.
fn read_dataset_ids(file: &str, text: &str, pos: &mut usize) -> Result<(Vec<i64>, usize), ParseError> {
    let bytes = text.as_bytes();
    let Some((off, tok)) = next_token(text, pos) else {
        return Err(error(file, last_line(bytes), ID_LINE, "end of file"));
    };
    let line = line_at(bytes, off);
    let m = match tok.parse::<i64>() {
        Ok(m) if m >= 1 => m as u64,
        _ => return Err(error(file, line, ID_LINE, excerpt(tok))),
    };
    if m > MAX_GRID_VALUES {
        return Err(error(file, line, format!("at most {MAX_GRID_VALUES} data sets"), tok));
    }
    let mut ids = Vec::new();
    for k in 0..m {
        let expected = || format!("data-set id {} of {m} (`m id1 … idm` after the atoms)", k + 1);
        let Some((off, tok)) = next_token(text, pos) else {
            return Err(error(file, last_line(bytes), expected(), "end of file"));
        };
        match tok.parse::<i64>() {
            Ok(id) => ids.push(id),
            Err(_) => return Err(error(file, line_at(bytes, off), expected(), excerpt(tok))),
        }
    }
    Ok((ids, line))
}

/// A Molden-style data-set line with a positive atom count: the first non-blank line after the
/// atoms holding an integer `m ≥ 1` followed by exactly `m` integers. Returns the ids, the line's
/// start and the offset just past it.
fn molden_ids(text: &str, pos: usize) -> Option<(Vec<i64>, usize, usize)> {
    let mut start = pos;
    while start < text.len() {
        let end = text[start..].find('\n').map_or(text.len(), |e| start + e + 1);
        let line = &text[start..end];
        if line.trim().is_empty() {
            start = end;
            continue;
        }
        let ints: Vec<i64> = line.split_whitespace().map(|t| t.parse().ok()).collect::<Option<_>>()?;
        let (&m, ids) = ints.split_first()?;
        return (m >= 1 && ids.len() as i64 == m).then(|| (ids.to_vec(), start, end));
    }
    None
}

fn count_tokens(bytes: &[u8]) -> u64 {
    let mut n = 0;
    let mut prev_space = true;
    for &b in bytes {
        let space = is_space(b);
        n += u64::from(prev_space && !space);
        prev_space = space;
    }
    n
}

/// Byte offset of the `k`-th (0-based) token at or after `start`.
fn nth_token_offset(text: &[u8], start: usize, k: u64) -> usize {
    let mut n = 0;
    let mut prev_space = true;
    for (i, &b) in text.iter().enumerate().skip(start) {
        let space = is_space(b);
        if prev_space && !space {
            if n == k {
                return i;
            }
            n += 1;
        }
        prev_space = space;
    }
    text.len()
}

fn token_at(text: &[u8], offset: usize) -> String {
    let end = text[offset..].iter().position(|&b| is_space(b)).map_or(text.len(), |e| offset + e);
    excerpt(&String::from_utf8_lossy(&text[offset..end]))
}

/// Data are parsed in chunks of about this many bytes, in parallel.
const CHUNK_BYTES: usize = 1 << 20;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Fault {
    NotANumber,
    NotFinite,
}

/// A bad token: its byte offset, its index within its chunk, and what is wrong.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BadValue {
    offset: usize,
    index: usize,
    fault: Fault,
}

/// Reads exactly `expected` values from `start` to the end of `text`; `shape` describes the
/// grid for messages.
fn read_values(file: &str, text: &[u8], start: usize, expected: u64, shape: &str) -> Result<Vec<f32>, ParseError> {
    read_values_chunked(file, text, start, expected, shape, CHUNK_BYTES)
}

fn read_values_chunked(
    file: &str,
    text: &[u8],
    start: usize,
    expected: u64,
    shape: &str,
    chunk_bytes: usize,
) -> Result<Vec<f32>, ParseError> {
    let what = || format!("{expected} grid values ({shape})");
    let short = |found: u64| error(file, last_line(text), what(), format!("only {found} before the end of the file"));
    // Every value needs a character and a separator: refuse a grid the data cannot hold
    // before allocating anything for it.
    if expected.saturating_mul(2) > (text.len() - start) as u64 + 1 {
        return Err(short(count_tokens(&text[start..])));
    }

    let ranges = split_chunks(text, start, chunk_bytes);
    let results: Vec<Result<Vec<f32>, BadValue>> = if ranges.len() > 1 {
        ranges.par_iter().map(|&(s, e)| parse_chunk(text, s, e)).collect()
    } else {
        ranges.iter().map(|&(s, e)| parse_chunk(text, s, e)).collect()
    };

    let mut chunks = Vec::with_capacity(results.len());
    let mut before = 0u64;
    for r in results {
        match r {
            Ok(v) => {
                before += v.len() as u64;
                chunks.push(v);
            }
            Err(bad) => {
                let n = before + bad.index as u64 + 1;
                let expected = match bad.fault {
                    Fault::NotANumber => format!("a number (grid value {n} of {expected})"),
                    Fault::NotFinite => format!("a finite number (grid value {n} of {expected})"),
                };
                return Err(error(file, line_at(text, bad.offset), expected, token_at(text, bad.offset)));
            }
        }
    }

    let found = before;
    if found < expected {
        return Err(short(found));
    }
    if found > expected {
        // Find the chunk holding the first extra value, then its offset.
        let mut seen = 0u64;
        let mut offset = text.len();
        for (v, &(s, _)) in chunks.iter().zip(&ranges) {
            if seen + v.len() as u64 > expected {
                offset = nth_token_offset(text, s, expected - seen);
                break;
            }
            seen += v.len() as u64;
        }
        return Err(error(
            file,
            line_at(text, offset),
            what(),
            format!("more: value {} is {}", expected + 1, token_at(text, offset)),
        ));
    }

    if chunks.len() == 1 {
        return Ok(chunks.pop().unwrap_or_default());
    }
    let mut values = Vec::with_capacity(found as usize);
    for c in chunks {
        values.extend_from_slice(&c);
    }
    Ok(values)
}

/// Splits `text[start..]` into ranges of about `chunk_bytes`, each ending at whitespace or
/// the end, so that no token straddles two ranges.
fn split_chunks(text: &[u8], start: usize, chunk_bytes: usize) -> Vec<(usize, usize)> {
    let mut ranges = Vec::with_capacity((text.len() - start) / chunk_bytes.max(1) + 1);
    let mut s = start;
    loop {
        let mut e = s.saturating_add(chunk_bytes.max(1)).min(text.len());
        while e < text.len() && !is_space(text[e]) {
            e += 1;
        }
        ranges.push((s, e));
        if e >= text.len() {
            return ranges;
        }
        s = e;
    }
}

fn parse_chunk(text: &[u8], start: usize, end: usize) -> Result<Vec<f32>, BadValue> {
    let s = &text[start..end];
    let mut out = Vec::with_capacity(s.len() / 10 + 1);
    let mut i = 0;
    while i < s.len() {
        if is_space(s[i]) {
            i += 1;
            continue;
        }
        let (v, used) = match fast_float2::parse_partial::<f32, _>(&s[i..]) {
            Ok((v, used)) if used > 0 && s.get(i + used).is_none_or(|&b| is_space(b)) => (v, used),
            _ => fortran_real(&s[i..]).ok_or(BadValue {
                offset: start + i,
                index: out.len(),
                fault: Fault::NotANumber,
            })?,
        };
        if !v.is_finite() {
            return Err(BadValue { offset: start + i, index: out.len(), fault: Fault::NotFinite });
        }
        out.push(v);
        i += used;
    }
    Ok(out)
}

/// The token at the start of `s` with a Fortran `D` exponent (`1.0D-03`), and its length.
fn fortran_real(s: &[u8]) -> Option<(f32, usize)> {
    let len = s.iter().position(|&b| is_space(b)).unwrap_or(s.len());
    let token = &s[..len];
    if !token.iter().any(|&b| b == b'D' || b == b'd') {
        return None;
    }
    let fixed: Vec<u8> = token.iter().map(|&b| if b == b'D' || b == b'd' { b'E' } else { b }).collect();
    fast_float2::parse::<f32, _>(&fixed).ok().map(|v| (v, len))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn doc(text: &str) -> Document {
        match parse("t.cube", text) {
            Ok(d) => d,
            Err(e) => panic!("{e}"),
        }
    }

    fn err(text: &str) -> ParseError {
        match parse("t.cube", text) {
            Ok(_) => panic!("parsed a bad file:\n{text}"),
            Err(e) => e,
        }
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    /// A 2×2×3 bohr grid with one atom; `data` follows the atom line (line 8 onwards).
    fn small(data: &str) -> String {
        format!(
            "title\ndensity\n    1   -1.0   0.5   2.0\n    2   0.5 0.0 0.0\n    2   0.0 0.4 0.0\n    3   0.0 0.0 0.3\n    8   8.0   0.0 0.0 0.1\n{data}"
        )
    }

    const TWELVE: &str = "  1.0E-01  2.0E-01  3.0E-01  4.0E-01  5.0E-01  6.0E-01\n  7.0E-01  8.0E-01  9.0E-01  1.0E+00  1.1E+00  1.2E+00\n";

    #[test]
    fn bohr_grid() {
        let d = doc(&small(TWELVE));
        assert_eq!(d.title, "title");
        assert_eq!(d.volumes.len(), 1);
        let g = &d.volumes[0];
        assert_eq!(g.label, "density");
        assert_eq!(g.dims, [2, 2, 3]);
        assert!(close(g.origin(), DVec3::new(-1.0, 0.5, 2.0)));
        assert!(close(g.step(0), DVec3::new(0.5, 0.0, 0.0)));
        assert!(close(g.step(2), DVec3::new(0.0, 0.0, 0.3)));
        assert!(g.is_orthogonal());
        assert_eq!(g.value(0, 0, 0), 0.1);
        assert_eq!(g.value(0, 0, 2), 0.3);
        assert_eq!(g.value(0, 1, 0), 0.4);
        assert_eq!(g.value(1, 1, 2), 1.2);
        let a = &d.molecule.atoms[0];
        assert_eq!((a.z, a.charge, a.ghost), (8, 8.0, false));
        assert!(close(a.position, DVec3::new(0.0, 0.0, 0.1)));
    }

    #[test]
    fn angstrom_axes_convert_to_bohr() {
        // All counts negative (Gaussian): axes, origin and atoms in ångström.
        let text = format!(
            "c\nc\n 1  1.0 0.0 0.0\n -2 0.5 0.0 0.0\n -2 0.0 0.25 0.0\n -3 0.0 0.0 0.2\n 1 1.0 0.0 0.0 0.74\n{TWELVE}"
        );
        let d = doc(&text);
        let g = &d.volumes[0];
        assert_eq!(g.dims, [2, 2, 3]);
        assert!((g.step(0).x - 0.5 * BOHR_PER_ANGSTROM).abs() < 1e-12);
        assert!((g.step(1).y - 0.25 * BOHR_PER_ANGSTROM).abs() < 1e-12);
        assert!((g.step(2).z - 0.2 * BOHR_PER_ANGSTROM).abs() < 1e-12);
        assert!(close(g.origin(), DVec3::new(BOHR_PER_ANGSTROM, 0.0, 0.0)));
        assert!(close(d.molecule.atoms[0].position, DVec3::new(0.0, 0.0, 0.74 * BOHR_PER_ANGSTROM)));

        // Only axis 2 flagged: only its vector converts; origin and atoms stay bohr (N1 > 0).
        let text = format!(
            "c\nc\n 1  1.0 0.0 0.0\n 2 0.5 0.0 0.0\n -2 0.0 0.25 0.0\n 3 0.0 0.0 0.2\n 1 1.0 0.0 0.0 0.74\n{TWELVE}"
        );
        let d = doc(&text);
        let g = &d.volumes[0];
        assert!((g.step(0).x - 0.5).abs() < 1e-12);
        assert!((g.step(1).y - 0.25 * BOHR_PER_ANGSTROM).abs() < 1e-12);
        assert!(close(g.origin(), DVec3::new(1.0, 0.0, 0.0)));
        assert!(close(d.molecule.atoms[0].position, DVec3::new(0.0, 0.0, 0.74)));
    }

    #[test]
    fn non_orthogonal_axes_are_a_full_affine_map() {
        let text = format!("c\nc\n 0  -1.0 2.0 0.5\n 2 0.5 0.1 0.0\n 2 0.2 0.4 0.0\n 3 0.0 0.1 0.3\n{TWELVE}");
        let d = doc(&text);
        let g = &d.volumes[0];
        assert!(!g.is_orthogonal());
        assert!(d.molecule.atoms.is_empty());
        let (o, v1, v2, v3) = (
            DVec3::new(-1.0, 2.0, 0.5),
            DVec3::new(0.5, 0.1, 0.0),
            DVec3::new(0.2, 0.4, 0.0),
            DVec3::new(0.0, 0.1, 0.3),
        );
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..3 {
                    let want = o + v1 * i as f64 + v2 * j as f64 + v3 * k as f64;
                    assert!(close(g.point(i, j, k), want), "({i},{j},{k})");
                }
            }
        }
    }

    /// A 2×2×3 grid with `m` interleaved data sets; value = 100·set + point index.
    fn interleaved(natoms: i64, id_line: &str, m: usize) -> String {
        let mut s = format!(
            "MO cube\nMOs\n {natoms}  0.0 0.0 0.0\n 2 1.0 0.0 0.0\n 2 0.0 1.0 0.0\n 3 0.0 0.0 1.0\n 1 1.0 0.0 0.0 0.0\n{id_line}"
        );
        let mut n = 0;
        for p in 0..12 {
            for d in 0..m {
                s.push_str(&format!(" {:12.5E}", (100 * d + p) as f32));
                n += 1;
                if n % 6 == 0 {
                    s.push('\n');
                }
            }
        }
        s.push('\n');
        s
    }

    fn check_interleaved(d: &Document, ids: &[i64]) {
        assert_eq!(d.volumes.len(), ids.len());
        for (s, (g, id)) in d.volumes.iter().zip(ids).enumerate() {
            assert_eq!(g.label, format!("MO {id}"));
            assert_eq!(g.dims, [2, 2, 3]);
            for i in 0..2 {
                for j in 0..2 {
                    for k in 0..3 {
                        assert_eq!(g.value(i, j, k), (100 * s + g.index(i, j, k)) as f32);
                    }
                }
            }
        }
    }

    #[test]
    fn negative_natoms_interleaves_data_sets() {
        let text = interleaved(-1, "    3   6   7   8\n", 3);
        check_interleaved(&doc(&text), &[6, 7, 8]);
        let file = CubeFile::parse("t.cube", &text).unwrap();
        assert_eq!(file.natoms, -1);
        assert_eq!(file.dataset_ids, Some(vec![6, 7, 8]));
        assert_eq!(file.values_per_point(), 3);
        assert_eq!(file.values.len(), 36);
    }

    #[test]
    fn wrapped_id_line() {
        let text = interleaved(-1, "   4  10  11\n  12  13\n", 4);
        check_interleaved(&doc(&text), &[10, 11, 12, 13]);
    }

    #[test]
    fn nval_on_line_three_interleaves() {
        let text = interleaved(1, "", 2).replacen(" 1  0.0 0.0 0.0\n", " 1  0.0 0.0 0.0 2\n", 1);
        let d = doc(&text);
        assert_eq!(d.volumes.len(), 2);
        assert_eq!(d.volumes[1].label, "data set 2");
        assert_eq!(d.volumes[1].value(1, 1, 2), 111.0);
    }

    #[test]
    fn molden_style_id_line_with_positive_natoms() {
        let text = interleaved(1, "    1    6\n", 1);
        let file = CubeFile::parse("t.cube", &text).unwrap();
        assert_eq!(file.dataset_ids, Some(vec![6]));
        check_interleaved(&doc(&text), &[6]);
        let text = interleaved(1, "    2    6    7\n", 2);
        check_interleaved(&doc(&text), &[6, 7]);
    }

    #[test]
    fn integer_data_are_not_an_id_line() {
        // `5 1 2 3 4 5` looks like a data-set line, but the 12 values fit the grid as they are.
        let d = doc(&small("5 1 2 3 4 5\n6 7 8 9 10 11\n"));
        assert_eq!(d.volumes.len(), 1);
        assert_eq!(
            d.volumes[0].values,
            (0..12).map(|v| [5, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11][v] as f32).collect::<Vec<_>>()
        );
        // 2×2×3 with one integer line `1 6` and 12 values: a data-set line.
        let d = doc(&small(&format!("1 6\n{TWELVE}")));
        assert_eq!(d.volumes[0].label, "MO 6");
    }

    #[test]
    fn exponent_forms() {
        let d = doc(&small("1.0E+000 -2.5D-01 3.0d+00 4.0E-001 5e0 6.\n.5 +7.0E+00 8.0e-0 9.0D0 1.0E+001 -0.0\n"));
        assert_eq!(d.volumes[0].values, vec![1.0, -0.25, 3.0, 0.4, 5.0, 6.0, 0.5, 7.0, 8.0, 9.0, 10.0, -0.0]);
    }

    #[test]
    fn blank_and_numeric_comment_lines() {
        let text = small(TWELVE).replacen("title\ndensity\n", "\n  12345  6.0\n", 1);
        let d = doc(&text);
        assert_eq!(d.title, "12345  6.0");
        assert_eq!(d.volumes[0].label, "12345  6.0");
        let text = small(TWELVE).replacen("title\ndensity\n", "\r\n\r\n", 1);
        let d = doc(&text);
        assert_eq!(d.title, "t.cube");
        assert_eq!(d.volumes[0].label, "values");
        assert_eq!(d.volumes[0].values.len(), 12);
    }

    #[test]
    fn the_comment_that_names_the_quantity_labels_the_values() {
        let pyscf = "Molecular electrostatic potential in real space\nPySCF Version: 2.14.0  Date: today\n";
        let d = doc(&small(TWELVE).replacen("title\ndensity\n", pyscf, 1));
        assert_eq!(d.volumes[0].label, "Molecular electrostatic potential in real space");
        let cubegen = "water density and ESP\nElectrostatic potential from Total SCF Density\n";
        let d = doc(&small(TWELVE).replacen("title\ndensity\n", cubegen, 1));
        assert_eq!(d.volumes[0].label, "Electrostatic potential from Total SCF Density");
        let neither = "Generated by a program\n  grid of 12 points\n";
        let d = doc(&small(TWELVE).replacen("title\ndensity\n", neither, 1));
        assert_eq!(d.volumes[0].label, "grid of 12 points");
    }

    #[test]
    fn ghost_atoms() {
        let text = small(TWELVE).replacen(" 1   -1.0", " 2   -1.0", 1).replacen(
            "    8   8.0   0.0 0.0 0.1\n",
            "    8   8.0   0.0 0.0 0.1\n    0   0.0   1.0 0.0 0.0\n",
            1,
        );
        let d = doc(&text);
        let g = &d.molecule.atoms[1];
        assert_eq!((g.z, g.ghost, g.charge), (0, true, 0.0));
        assert!(!d.molecule.atoms[0].ghost);
        assert!(d.molecule.bonds.is_empty());

        let text = text.replacen("    0   0.0", "   -1   0.0", 1);
        let e = err(&text);
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("an atomic number 0..=118"), "{e}");
    }

    #[test]
    fn gzipped_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("small.cube.gz");
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(small(TWELVE).as_bytes()).unwrap();
        std::fs::write(&path, gz.finish().unwrap()).unwrap();
        let d = super::super::load(&path).unwrap();
        assert_eq!(d.volumes[0].values.len(), 12);
        assert_eq!(d.volumes[0].value(1, 1, 2), 1.2);
        assert!(d.source.ends_with("small.cube.gz"));
    }

    #[test]
    fn chunk_boundaries_do_not_matter() {
        // 6×6×6 values, parsed whole and in chunks of many sizes, with errors in late chunks.
        let mut text = String::from("c\nc\n 0 0 0 0\n 6 1 0 0\n 6 0 1 0\n 6 0 0 1\n");
        let mut want = Vec::new();
        for i in 0..216 {
            let v = (i as f32 - 100.0) * 1.234e-3;
            want.push(format!("{v:.5E}").parse::<f32>().unwrap());
            text.push_str(&format!(" {v:.5E}"));
            if i % 6 == 5 {
                text.push('\n');
            }
        }
        let b = text.as_bytes();
        let start = text.find(" -1.23").unwrap();
        for chunk in [1, 2, 7, 13, 64, 1000, CHUNK_BYTES] {
            let v = read_values_chunked("t", b, start, 216, "6×6×6", chunk).unwrap();
            assert_eq!(v, want, "chunk {chunk}");
        }
        // Garbage at value 200 (line 6 + 34), one extra value, one missing.
        let bad = text.replacen(&format!(" {:.5E}", (199.0 - 100.0) * 1.234e-3_f32), " 1.0x", 1);
        let extra = format!("{text} 9.9E-01\n");
        let cut = &text[..text.trim_end().rfind(' ').unwrap()];
        for chunk in [3, 50, CHUNK_BYTES] {
            let e = read_values_chunked("t", bad.as_bytes(), start, 216, "6×6×6", chunk).unwrap_err();
            assert_eq!((e.line, e.found.as_str()), (40, "\"1.0x\""), "chunk {chunk}");
            assert!(e.expected.contains("value 200 of 216"), "{e}");
            let e = read_values_chunked("t", extra.as_bytes(), start, 216, "6×6×6", chunk).unwrap_err();
            assert_eq!(e.line, 43);
            assert!(e.found.contains("value 217"), "{e}");
            let e = read_values_chunked("t", cut.as_bytes(), start, 216, "6×6×6", chunk).unwrap_err();
            assert_eq!(e.line, 42);
            assert!(e.found.contains("only 215"), "{e}");
        }
    }

    // --- malformed files ---

    #[test]
    fn truncated_data() {
        let e = err(&small("  1.0E-01  2.0E-01  3.0E-01  4.0E-01  5.0E-01  6.0E-01\n  7.0E-01\n\n"));
        assert_eq!(e.line, 9);
        assert!(e.expected.contains("12 grid values (2×2×3 points)"), "{e}");
        assert!(e.found.contains("only 7"), "{e}");
        // No data at all: the error names the last header line.
        let e = err(&small(""));
        assert_eq!(e.line, 7);
        assert!(e.found.contains("only 0"), "{e}");
    }

    #[test]
    fn too_many_values() {
        let e = err(&small(&format!("{TWELVE}  1.3E+00\n")));
        assert_eq!(e.line, 10);
        assert!(e.expected.contains("12 grid values"), "{e}");
        assert!(e.found.contains("value 13") && e.found.contains("1.3E+00"), "{e}");
    }

    #[test]
    fn missing_atom_lines() {
        let text = small(TWELVE).replacen(" 1   -1.0", " 3   -1.0", 1);
        let e = err(&text);
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("atom 2 of 3"), "{e}");
        assert!(e.found.contains("1.0E-01"), "{e}");
        // Atom line with a missing column.
        let e = err(&small(TWELVE).replacen("8   8.0   0.0 0.0 0.1", "8   8.0   0.0 0.0", 1));
        assert_eq!(e.line, 7);
        assert!(e.expected.contains("atom 1 of 1 as `Z charge x y z`"), "{e}");
    }

    #[test]
    fn absurd_atom_count() {
        let e = err(&small(TWELVE).replacen(" 1   -1.0", " 999999999999   -1.0", 1));
        assert_eq!(e.line, 3);
        assert!(e.expected.contains("atom count the file can hold"), "{e}");
    }

    #[test]
    fn garbage_token() {
        let e = err(&small("  1.0E-01  2.0E-01  3.0E-01\n  4.0E-01  abc  6.0E-01\n"));
        assert_eq!(e.line, 9);
        assert_eq!(e.found, "\"abc\"");
        assert!(e.expected.contains("a number (grid value 5 of 12)"), "{e}");
        let e = err(&small(&TWELVE.replacen("8.0E-01", "8.0E-01,", 1)));
        assert_eq!((e.line, e.found.as_str()), (9, "\"8.0E-01,\""));
    }

    #[test]
    fn nan_and_infinity() {
        for bad in ["NaN", "nan", "inf", "-Infinity", "1.0E+999"] {
            let e = err(&small(&TWELVE.replacen("9.0E-01", bad, 1)));
            assert_eq!(e.line, 9, "{bad}");
            assert!(e.expected.contains("a finite number (grid value 9 of 12)"), "{e}");
        }
    }

    #[test]
    fn zero_dimension() {
        let e = err(&small(TWELVE).replacen("    2   0.0 0.4", "    0   0.0 0.4", 1));
        assert_eq!(e.line, 5);
        assert!(e.expected.contains("non-zero number of points on axis 2"), "{e}");
    }

    #[test]
    fn huge_dimensions_fail_fast_without_allocating() {
        let text = "c\nc\n 0 0 0 0\n 100000 1 0 0\n 100000 0 1 0\n 100000 0 0 1\n 1.0\n";
        let t = std::time::Instant::now();
        let e = err(text);
        assert!(t.elapsed().as_millis() < 100);
        assert_eq!(e.line, 6);
        assert!(e.expected.contains(&format!("at most {MAX_GRID_VALUES} grid values")), "{e}");
        assert!(e.found.contains("100000×100000×100000"), "{e}");
        // Within the limit but far beyond what the file holds.
        let text = "c\nc\n 0 0 0 0\n 1000 1 0 0\n 1000 0 1 0\n 1000 0 0 1\n 1.0 2.0\n 3.0\n";
        let e = err(text);
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("1000000000 grid values"), "{e}");
        assert!(e.found.contains("only 3"), "{e}");
        // Many data sets.
        let text = "c\nc\n -1 0 0 0\n 1000 1 0 0\n 1000 0 1 0\n 1000 0 0 1\n 1 1 0 0 0\n 2 6 7\n 1.0\n";
        let e = err(text);
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("at most"), "{e}");
    }

    #[test]
    fn negative_natoms_without_id_line() {
        let e = err(&small(TWELVE).replacen(" 1   -1.0", " -1   -1.0", 1));
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("`m id1 … idm`"), "{e}");
        assert!(e.found.contains("1.0E-01"), "{e}");
        // The id line ends early.
        let e = err(&(small("").replacen(" 1   -1.0", " -1   -1.0", 1) + "  3  6  7\n"));
        assert_eq!(e.line, 8);
        assert!(e.expected.contains("data-set id 3 of 3"), "{e}");
    }

    #[test]
    fn empty_and_short_files() {
        for text in ["", "  \n\n \r\n"] {
            let e = err(text);
            assert_eq!(e.line, 1);
            assert!(e.expected.contains("two comment lines"), "{e}");
        }
        // A missing line is reported at the file's last line, as the end of the file.
        let e = err("only a comment\n");
        assert_eq!((e.line, e.found.as_str()), (1, "end of file"));
        let e = err("c\nc\n");
        assert_eq!((e.line, e.found.as_str()), (2, "end of file"));
        assert!(e.expected.contains("NAtoms ox oy oz"), "{e}");
        let e = err("c\nc\n 1 0.0 0.0\n");
        assert_eq!(e.line, 3);
        let e = err("c\nc\n 1 0.0 0.0 0.0\n 2 1 0 0\n 2 0 1 0\n");
        assert_eq!((e.line, e.found.as_str()), (5, "end of file"));
        assert!(e.expected.contains("axis 3"), "{e}");
        let e = err("c\nc\n 1 0.0 0.0 0.0\n 2 1 0 0\n 2.5 0 1 0\n 2 0 0 1\n");
        assert_eq!(e.line, 5);
        assert!(e.expected.contains("axis 2"), "{e}");
    }
}
