//! The electrostatic potential of files written by other programs (ORCA, CFOUR, Gaussian, Psi4,
//! Turbomole, Molpro, Molden, Q-Chem; ghost atoms among them) against an independent chain:
//! IOData reads each file of ../shared/refdata/real-world and repairs its writer's
//! normalisation, GBasis integrates (tests/fixtures/esp/real_world_esp.tsv, written by
//! scripts/make_esp_reference.py: 40 random points per file, 0.3 to 4 bohr from the atoms).

use std::path::Path;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::esp::Potential;

mod common;

const TABLE: &str = include_str!("fixtures/esp/real_world_esp.tsv");
/// Agreement with IOData + GBasis (a.u.).
const TOL: f64 = 1e-6;

/// The table's points and values, file by file in the table's order.
fn reference() -> Vec<(String, Vec<(DVec3, f64)>)> {
    let mut files: Vec<(String, Vec<(DVec3, f64)>)> = Vec::new();
    for line in TABLE.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
        let cols: Vec<&str> = line.split('\t').collect();
        assert_eq!(cols.len(), 5, "{line}");
        let num = |i: usize| cols[i].parse::<f64>().unwrap_or_else(|e| panic!("{line}: {e}"));
        let row = (DVec3::new(num(1), num(2), num(3)), num(4));
        match files.last_mut() {
            Some((name, rows)) if name == cols[0] => rows.push(row),
            _ => files.push((cols[0].to_string(), vec![row])),
        }
    }
    files
}

#[test]
fn potential_of_real_world_files_matches_iodata_and_gbasis() {
    let Some(dir) = common::refdata("esp_real_world::potential_of_real_world_files_matches_iodata_and_gbasis") else {
        return;
    };
    let files = reference();
    for writer in ["nh3_orca.molden", "h2o_ccpvdz_cfour.molden", "o2_cc_pvtz_cart.fchk"] {
        assert!(files.iter().any(|(name, _)| name == writer), "{writer} missing from the table");
    }
    for (name, rows) in &files {
        let path: &Path = &dir.join(name);
        let doc = formats::load(path).unwrap_or_else(|e| panic!("{e}"));
        let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("{name}: no wavefunction"));
        let points: Vec<DVec3> = rows.iter().map(|r| r.0).collect();
        let got = Potential::new(&doc.molecule, wf).at_points(&points);
        let mut worst: f64 = 0.0;
        for (i, ((p, want), v)) in rows.iter().zip(&got).enumerate() {
            let diff = (v - want).abs();
            assert!(diff < TOL, "{name}, point {i} ({:.6}, {:.6}, {:.6}) bohr: {v} against {want} a.u.", p.x, p.y, p.z);
            worst = worst.max(diff);
        }
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "{name}: {} points, largest difference {worst:.1e} a.u.", rows.len());
    }
}
