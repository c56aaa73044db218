//! Writing Gaussian cube files (what `orbcloud cube` produces; PySCF, VMD and this crate's reader
//! read them back).

use std::fmt::Write as _;
use std::io::Write;

use rayon::prelude::*;

use crate::model::{Molecule, VolumeGrid};

/// Cube text for one or more grids of identical geometry over `molecule` (all bohr); see
/// [`write_to`].
pub fn write(title: &str, description: &str, molecule: &Molecule, grids: &[(&VolumeGrid, i64)]) -> String {
    let mut bytes = Vec::new();
    // Writing to memory cannot fail; everything written is ASCII.
    let _ = write_to(&mut bytes, title, description, molecule, grids);
    String::from_utf8(bytes).unwrap_or_default()
}

/// Writes a cube file for one or more grids of identical geometry over `molecule` (all bohr).
/// Several grids are written as a multi-orbital cube: negative atom count, the id line, values
/// interleaved per point.
///
/// Panics if `grids` is empty or their geometries differ (a caller's bug, not input).
pub fn write_to(
    w: &mut impl Write,
    title: &str,
    description: &str,
    molecule: &Molecule,
    grids: &[(&VolumeGrid, i64)],
) -> std::io::Result<()> {
    let (first, _) = grids.first().expect("at least one grid");
    assert!(
        grids.iter().all(|(g, _)| g.dims == first.dims && g.world_from_grid == first.world_from_grid),
        "grids of one cube file share their geometry"
    );
    let mut out = String::with_capacity(4096);
    let line = |s: &str| s.replace(['\n', '\r'], " ");
    let _ = writeln!(out, "{}", line(title));
    let _ = writeln!(out, "{}", line(description));
    let o = first.origin();
    let natoms = molecule.atoms.len() as i64;
    let signed_natoms = if grids.len() > 1 { -natoms } else { natoms };
    // Ten decimals, not the customary six: a six-decimal spacing misplaces the last points of
    // an 80-point axis by ~1e-5 bohr, visible in the values read back.
    let _ = writeln!(out, "{signed_natoms:5} {:16.10} {:16.10} {:16.10}", o.x, o.y, o.z);
    for axis in 0..3 {
        let v = first.step(axis);
        let _ = writeln!(out, "{:5} {:16.10} {:16.10} {:16.10}", first.dims[axis], v.x, v.y, v.z);
    }
    for a in &molecule.atoms {
        let p = a.position;
        let _ = writeln!(out, "{:5} {:16.10} {:16.10} {:16.10} {:16.10}", a.z, a.charge, p.x, p.y, p.z);
    }
    if grids.len() > 1 {
        let ids: Vec<String> = grids.iter().map(|(_, id)| id.to_string()).collect();
        let _ = writeln!(out, "{:5} {}", grids.len(), ids.join(" "));
    }
    w.write_all(out.as_bytes())?;
    let nz = first.dims[2].max(1);
    // Every row has the same layout, so rows are formatted straight into their place in a block
    // of rows (in parallel when there are threads) and each block is written at once: blocks of
    // at least a megabyte pass a `BufWriter` by.
    let row_bytes = row_len(nz * grids.len());
    let rows = first.values.len() / nz;
    let block_rows = ((2 << 20) / row_bytes).clamp(1, rows.max(1));
    let mut block = vec![0u8; block_rows * row_bytes];
    for start in (0..rows).step_by(block_rows) {
        let n = block_rows.min(rows - start);
        let bytes = &mut block[..n * row_bytes];
        bytes
            .par_chunks_mut(row_bytes)
            .enumerate()
            .for_each_init(Vec::new, |scratch, (r, out)| format_row(out, grids, start + r, nz, scratch));
        w.write_all(bytes)?;
    }
    w.flush()
}

/// Bytes of a row of `n` values: 13 per value, six values per line.
fn row_len(n: usize) -> usize {
    n * 13 + n.div_ceil(6)
}

/// Row `row` (`nz` values of each grid, interleaved per point) into `out`, six values a line;
/// `scratch` holds the interleaved values of several grids.
fn format_row(out: &mut [u8], grids: &[(&VolumeGrid, i64)], row: usize, nz: usize, scratch: &mut Vec<f32>) {
    let pow10 = pow10_table();
    let points = row * nz..(row + 1) * nz;
    let values = match grids {
        [(g, _)] => &g.values[points],
        _ => {
            scratch.clear();
            scratch.extend(points.flat_map(|k| grids.iter().map(move |(g, _)| g.values[k])));
            &scratch[..]
        }
    };
    for (line, six) in out.chunks_mut(6 * 13 + 1).zip(values.chunks(6)) {
        for (slot, &v) in line.chunks_exact_mut(13).zip(six) {
            slot.copy_from_slice(&scientific(v, pow10));
        }
        line[six.len() * 13] = b'\n';
    }
}

/// Powers of ten 10^k for k in [`POW10_LO`]..=60: an f32 with six digits never needs more.
const POW10_LO: i32 = -60;

fn pow10_table() -> &'static [f64] {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    // Parsed, not multiplied, so each entry is the correctly rounded power.
    TABLE.get_or_init(|| (POW10_LO..=60).map(|k| format!("1e{k}").parse().unwrap_or(0.0)).collect())
}

/// The two decimal digits of `n` < 100.
fn digit_pair(n: u32) -> &'static [u8] {
    const PAIRS: [u8; 200] = {
        let mut t = [0u8; 200];
        let mut i = 0;
        while i < 100 {
            t[2 * i] = b'0' + (i / 10) as u8;
            t[2 * i + 1] = b'0' + (i % 10) as u8;
            i += 1;
        }
        t
    };
    &PAIRS[2 * n as usize..2 * n as usize + 2]
}

/// ` ±d.dddddE±XX` (13 bytes), the Fortran layout cube files use, six significant digits —
/// without `format!`, which dominates writing a large grid.
fn scientific(v: f32, pow10: &[f64]) -> [u8; 13] {
    if v == 0.0 || !v.is_finite() {
        return *b"  0.00000E+00";
    }
    let a = v.abs() as f64;
    let p = |k: i32| pow10[(k - POW10_LO).clamp(0, pow10.len() as i32 - 1) as usize];
    // The decimal exponent from the binary one (log10 2 ≈ 0.30103), then corrected by one
    // against the table.
    let binary = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    // ⌊binary · log10 2⌋ with log10 2 ≈ 1233/4096; the arithmetic shift floors negatives too.
    // (Integer arithmetic: `floor` and `round` are library calls on baseline x86-64.)
    let mut e = (binary * 1233) >> 12;
    // Branch-free: which way the estimate is off depends on the value, unpredictably.
    e += (a >= p(e + 1)) as i32 - (a < p(e)) as i32;
    // Round half up: within an ulp of a tie this may differ from exact decimal rounding in the
    // sixth digit, which a cube file's precision does not notice.
    let mut m = (a * p(5 - e) + 0.5) as i64 as u32;
    // Rounding may carry into a seventh digit (9.999996 → 10.0000).
    if m >= 1_000_000 {
        m = (m + 5) / 10;
        e += 1;
    }
    let mut b = *b"  0.00000E+00";
    b[1] = if v < 0.0 { b'-' } else { b' ' };
    let first = m / 100_000;
    let rest = m - first * 100_000;
    let (pair1, rest) = (rest / 1000, rest % 1000);
    let (pair2, last) = (rest / 10, rest % 10);
    b[2] = b'0' + first as u8;
    b[4..6].copy_from_slice(digit_pair(pair1));
    b[6..8].copy_from_slice(digit_pair(pair2));
    b[8] = b'0' + last as u8;
    b[10] = if e < 0 { b'-' } else { b'+' };
    b[11..13].copy_from_slice(digit_pair(e.unsigned_abs().min(99)));
    // f32 exponents stay within ±45: two digits always suffice.
    b
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::model::Atom;

    #[test]
    fn scientific_digits_are_correctly_rounded() {
        let mut s = 0x2545F4914F6CDD1Du64;
        for i in 0..20_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let exp = (s % 70) as i32 - 40;
            let mantissa = (s >> 11) as f64 / (1u64 << 53) as f64 * 9.0 + 1.0;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let v = (sign * mantissa * 10f64.powi(exp)) as f32;
            let text = String::from_utf8(scientific(v, pow10_table()).to_vec()).unwrap();
            // Exact decimal rounding may differ in the last digit when the value sits within an
            // ulp of a tie; anything more is a bug.
            let expected: f64 = format!("{:.5E}", v as f64).parse().unwrap();
            let got: f64 = text.trim().parse().unwrap();
            assert!((got - expected).abs() <= 1.01e-5 * expected.abs(), "{v:e} → {text}");
            assert_eq!(text.len(), 13, "{text}");
        }
        for (v, text) in [(1.0f32, "  1.00000E+00"), (-0.000123456, " -1.23456E-04"), (9.999996e-3, "  1.00000E-02")] {
            assert_eq!(String::from_utf8(scientific(v, pow10_table()).to_vec()).unwrap(), text);
        }
    }

    #[test]
    fn written_cubes_read_back() {
        let world = VolumeGrid::affine(
            DVec3::new(-1.0, 0.5, 2.0),
            [DVec3::new(0.3, 0.0, 0.0), DVec3::new(0.1, 0.25, 0.0), DVec3::new(0.0, 0.0, 0.2)],
        );
        let dims = [3, 4, 7];
        let n = dims.iter().product::<usize>();
        let a = VolumeGrid::new("a", dims, world, (0..n).map(|i| (i as f32 - 40.0) * 1.5e-3).collect());
        let b = VolumeGrid::new("b", dims, world, (0..n).map(|i| (i as f32).sin()).collect());
        let molecule = Molecule::new(vec![
            Atom { z: 8, charge: 8.0, position: DVec3::new(0.0, 1.0, 2.5), ghost: false },
            Atom { z: 1, charge: 1.0, position: DVec3::new(1.4, 1.0, 3.5), ghost: false },
        ]);
        for grids in [vec![(&a, 7)], vec![(&a, 7), (&b, 9)]] {
            let text = write("t", "d", &molecule, &grids);
            let doc = crate::formats::cube::parse("written.cube", &text).unwrap();
            assert_eq!(doc.volumes.len(), grids.len());
            assert_eq!(doc.molecule.atoms.len(), 2);
            assert!((doc.molecule.atoms[1].position - molecule.atoms[1].position).length() < 1e-6);
            for (read, (orig, _)) in doc.volumes.iter().zip(&grids) {
                assert_eq!(read.dims, dims);
                assert!((read.world_from_grid - world).abs_diff_eq(glam::DMat4::ZERO, 1e-6));
                for (x, y) in read.values.iter().zip(&orig.values) {
                    assert!((x - y).abs() <= 1e-5 * y.abs().max(1e-30), "{x} vs {y}");
                }
            }
        }
    }
}
