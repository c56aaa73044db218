//! Writing Gaussian cube files (what `orbcloud cube` produces; PySCF, VMD and this crate's reader
//! read them back).

use std::fmt::Write as _;
use std::io::Write;

use rayon::prelude::*;

use super::e_format;
use crate::model::{GridSpec, Molecule, VolumeGrid};

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
    let spec = GridSpec { dims: first.dims, world_from_grid: first.world_from_grid };
    let values: Vec<(&[f32], i64)> = grids.iter().map(|(g, id)| (&g.values[..], *id)).collect();
    write_values_to(w, title, description, molecule, &spec, &values)
}

/// [`write_to`] for bare values on `spec` (cube order), which need no [`VolumeGrid`] and its
/// statistics.
///
/// Panics if `grids` is empty or a grid's length is not the spec's.
pub fn write_values_to(
    w: &mut impl Write,
    title: &str,
    description: &str,
    molecule: &Molecule,
    spec: &GridSpec,
    grids: &[(&[f32], i64)],
) -> std::io::Result<()> {
    assert!(!grids.is_empty() && grids.iter().all(|(g, _)| g.len() == spec.len()), "values fill the grid");
    let mut out = String::with_capacity(4096);
    let line = |s: &str| s.replace(['\n', '\r'], " ");
    let _ = writeln!(out, "{}", line(title));
    let _ = writeln!(out, "{}", line(description));
    let o = spec.origin();
    let natoms = molecule.atoms.len() as i64;
    let signed_natoms = if grids.len() > 1 { -natoms } else { natoms };
    // Ten decimals, not the customary six: a six-decimal spacing misplaces the last points of
    // an 80-point axis by ~1e-5 bohr, visible in the values read back.
    let _ = writeln!(out, "{signed_natoms:5} {:16.10} {:16.10} {:16.10}", o.x, o.y, o.z);
    for axis in 0..3 {
        let v = spec.step(axis);
        let _ = writeln!(out, "{:5} {:16.10} {:16.10} {:16.10}", spec.dims[axis], v.x, v.y, v.z);
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
    let nz = spec.dims[2].max(1);
    // Every row has the same layout, so rows are formatted straight into their place in a block
    // of rows (in parallel when there are threads) and each block is written at once. A block
    // of about 256 KiB stays in the cache between formatting and the write that copies it out,
    // and its pages are reused block after block; it passes a `BufWriter` of less by.
    let row_bytes = e_format::text_len(nz * grids.len());
    let rows = spec.len() / nz;
    let block_rows = (BLOCK / row_bytes).clamp(1, rows.max(1));
    let mut block = vec![0u8; block_rows * row_bytes];
    for start in (0..rows).step_by(block_rows) {
        let n = block_rows.min(rows - start);
        let bytes = &mut block[..n * row_bytes];
        if rayon::current_num_threads() > 1 {
            bytes.par_chunks_mut(row_bytes).enumerate().for_each_init(
                || (Vec::new(), Vec::new()),
                |(values, words), (r, out)| format_row(out, grids, start + r, nz, values, words),
            );
        } else {
            // One thread: on this one, rather than handing each block to the pool's only worker
            // and waiting for it to wake.
            let (values, words) = (&mut Vec::new(), &mut Vec::new());
            for (r, out) in bytes.chunks_mut(row_bytes).enumerate() {
                format_row(out, grids, start + r, nz, values, words);
            }
        }
        w.write_all(bytes)?;
    }
    w.flush()
}

/// Bytes of cube text written at a time (see [`write_values_to`]).
pub const BLOCK: usize = 256 << 10;

/// Row `row` (`nz` values of each grid, interleaved per point) into `out`, six values a line;
/// `values` holds the interleaved values of several grids, `words` the formatter's scratch.
fn format_row(
    out: &mut [u8],
    grids: &[(&[f32], i64)],
    row: usize,
    nz: usize,
    values: &mut Vec<f32>,
    words: &mut Vec<[u64; 2]>,
) {
    let points = row * nz..(row + 1) * nz;
    let row_values = match grids {
        [(g, _)] => &g[points],
        _ => {
            values.clear();
            values.extend(points.flat_map(|k| grids.iter().map(move |(g, _)| g[k])));
            &values[..]
        }
    };
    e_format::write_lines(row_values, out, words);
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::model::Atom;

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
