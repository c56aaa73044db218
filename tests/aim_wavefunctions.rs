//! The AIM (`.wfn`, `.wfx`) and ORCA (`.mkl`) fixtures of tests/fixtures/wfn_wfx_mkl, written
//! by scripts/make_wfn_wfx_mkl_fixtures.py from PySCF wavefunctions in each program's own layout,
//! open with the orbitals of the same wavefunction's Molden file (PySCF's writer, itself checked
//! against PySCF in tests/fixture_wavefunctions.rs): every orbital's value at 300 points (signs
//! included), the density and spin density there, energies, occupations, spins, HOMO and LUMO.
//! The basis (cc-pVDZ with an f and a g function on O) has s to g functions; the `.wfn` and
//! `.wfx` files expand it into cartesian primitives, the `.mkl` files keep it pure with ORCA's
//! normalisation and sign quirks, which the reader must undo.

mod common;

use std::path::PathBuf;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{Spin, Wavefunction};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wfn_wfx_mkl");
const POINTS: usize = 300;

/// One fixture and what it is held to.
struct Case {
    file: &'static str,
    /// The Molden file of the same wavefunction.
    molden: &'static str,
    /// Orbital values: |ψ − ψ_molden| ≤ tol · max(1, |ψ_molden|).
    value_tol: f64,
    /// Energies: the precision the format writes them with.
    energy_tol: f64,
    /// Only the occupied orbitals are in the file (as Gaussian writes ROHF wfn and wfx files).
    occupied_only: bool,
    /// The writer the orbitals' check names, and whether a repair was needed.
    program: &'static str,
    repaired: bool,
    /// What `Document::problems` must say, if anything.
    problem: Option<&'static str>,
}

/// Tolerances follow what each layout writes: `.wfn` files give coordinates to 1e-8 bohr
/// (F12.8), which alone moves a core orbital by up to 4e-8 of its value near the nucleus
/// (measured: 1.4e-8 to 1.8e-8 here), coefficients with 8 (Gaussian's D16.8) or 9 (PySCF's
/// %15.8E) significant digits and energies to 1e-6 (Gaussian) or 1e-8 (PySCF); AIMAll's `.wfx`
/// 13 digits; the `.mkl` fixtures 10 decimals (ORCA's own 7 would hide the reader's errors below
/// 1e-7). Molden's energies have 10 digits.
fn cases() -> [Case; 12] {
    [
        case("h2o_rhf.wfn", "h2o_rhf.molden", 5e-8, 6e-7, false, None),
        case("h2o_rhf_pyscf.wfn", "h2o_rhf.molden", 5e-8, 1e-8, false, None),
        case("h2o_rhf.wfx", "h2o_rhf.molden", 1e-8, 1e-9, false, None),
        case("h2o_rhf.mkl", "h2o_rhf.molden", 1e-8, 1e-9, false, None),
        case("oh_uhf.wfn", "oh_uhf.molden", 5e-8, 6e-7, false, Some("read as alpha and 36–70 as beta")),
        case("oh_uhf.wfx", "oh_uhf.molden", 1e-8, 1e-9, false, None),
        case("oh_uhf.mkl", "oh_uhf.molden", 1e-8, 1e-9, false, None),
        case("oh_rohf.wfn", "oh_rohf.molden", 5e-8, 6e-7, true, None),
        case("oh_rohf.wfx", "oh_rohf.molden", 1e-8, 1e-9, true, None),
        case("oh_rohf.mkl", "oh_rohf.molden", 1e-8, 1e-9, false, None),
        // The same files gzipped open the same.
        case("h2o_rhf.wfx.gz", "h2o_rhf.molden", 1e-8, 1e-9, false, None),
        case("oh_uhf.mkl.gz", "oh_uhf.molden", 1e-8, 1e-9, false, None),
    ]
}

fn case(
    file: &'static str,
    molden: &'static str,
    value_tol: f64,
    energy_tol: f64,
    occupied_only: bool,
    problem: Option<&'static str>,
) -> Case {
    // The titles name PySCF; the .mkl files name ORCA and carry its quirks, which are undone.
    let mkl = file.contains(".mkl");
    let program = if mkl { "ORCA" } else { "PySCF" };
    Case { file, molden, value_tol, energy_tol, occupied_only, program, repaired: mkl, problem }
}

fn load(name: &str) -> Document {
    let path = PathBuf::from(DIR).join(name);
    if let Some(plain) = name.strip_suffix(".gz") {
        // Gzipped in memory: the reader is picked by the name, the bytes inflated first.
        let bytes = std::fs::read(PathBuf::from(DIR).join(plain))
            .unwrap_or_else(|e| panic!("{plain}: {e} (run scripts/make_wfn_wfx_mkl_fixtures.py)"));
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        std::io::Write::write_all(&mut gz, &bytes).expect("gzip");
        let gz = gz.finish().expect("gzip");
        return formats::load_bytes(&path, &gz).unwrap_or_else(|e| panic!("{e}"));
    }
    assert!(path.is_file(), "fixture missing: {} (run scripts/make_wfn_wfx_mkl_fixtures.py)", path.display());
    formats::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn points(doc: &Document) -> Vec<DVec3> {
    common::points_around(doc, POINTS)
}

/// Checks one case; returns the values that are off (structural differences panic).
fn check(c: &Case) -> Vec<String> {
    let doc = load(c.file);
    let reference = load(c.molden);
    let file = c.file;
    let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("{file}: no wavefunction"));
    let want = reference.wavefunction.as_ref().expect("the Molden file's wavefunction");

    // Atoms.
    assert_eq!(doc.molecule.atoms.len(), reference.molecule.atoms.len(), "{file}: atoms");
    for (a, b) in doc.molecule.atoms.iter().zip(&reference.molecule.atoms) {
        assert_eq!((a.z, a.charge, a.ghost), (b.z, b.charge, b.ghost), "{file}: atom");
        assert!((a.position - b.position).length() < 2e-8, "{file}: atom at {} vs {}", a.position, b.position);
    }

    // The orbitals' check and what was said.
    let n = &wf.normalization;
    assert_eq!(n.program, c.program, "{file}: {n:?}");
    assert_eq!(n.repair != "none", c.repaired, "{file}: {n:?}");
    assert!(n.residual < 1e-6, "{file}: residual {:e}", n.residual);
    match c.problem {
        Some(p) => assert!(doc.problems.iter().any(|q| q.contains(p)), "{file}: {:?}", doc.problems),
        None => assert!(doc.problems.is_empty(), "{file}: {:?}", doc.problems),
    }

    // Orbitals, spin by spin, in file order.
    assert_eq!(wf.restricted, want.restricted, "{file}: restricted");
    let pa = PreparedBasis::new(&wf.basis);
    let pb = PreparedBasis::new(&want.basis);
    let pts = points(&doc);
    let (mut worst_value, mut worst_energy) = (0.0f64, 0.0f64);
    let mut failures = Vec::new();
    for spin in [Spin::Alpha, Spin::Beta] {
        let got: Vec<_> = wf.of_spin(spin).map(|(_, o)| o).collect();
        let exp: Vec<_> =
            want.of_spin(spin).map(|(_, o)| o).filter(|o| !c.occupied_only || o.occupation > 0.0).collect();
        assert_eq!(got.len(), exp.len(), "{file}: {spin:?} orbitals");
        for (k, (a, b)) in got.iter().zip(&exp).enumerate() {
            let de = (a.energy - b.energy).abs();
            worst_energy = worst_energy.max(de);
            if de > c.energy_tol + 1e-9 * b.energy.abs() {
                failures.push(format!("{spin:?} orbital {}: energy {} vs {}", k + 1, a.energy, b.energy));
            }
            if (a.occupation - b.occupation).abs() > 1e-9 {
                failures.push(format!("{spin:?} orbital {}: occupation {} vs {}", k + 1, a.occupation, b.occupation));
            }
            for &p in &pts {
                let (va, vb) = (pa.orbital_value(&a.coefficients, p), pb.orbital_value(&b.coefficients, p));
                let d = (va - vb).abs() / vb.abs().max(1.0);
                worst_value = worst_value.max(d);
                if d > c.value_tol {
                    failures.push(format!("{spin:?} orbital {} at {p}: {va:e} vs {vb:e}", k + 1));
                }
            }
        }
        // Frontier orbitals: the same energies (indices differ where the file keeps fewer).
        let e = |w: &Wavefunction, i: Option<usize>| i.map(|i| w.orbitals[i].energy);
        if spin == Spin::Alpha || !want.restricted {
            let homo = (e(wf, wf.homo(spin)), e(want, want.homo(spin)));
            assert!(
                matches!(homo, (Some(x), Some(y)) if (x - y).abs() <= c.energy_tol + 1e-8),
                "{file}: {spin:?} HOMO {homo:?}"
            );
            let lumo = (e(wf, wf.lumo(spin)), e(want, want.lumo(spin)));
            match (c.occupied_only, lumo) {
                (true, (None, Some(_))) => {}
                (false, (Some(x), Some(y))) if (x - y).abs() <= c.energy_tol + 1e-8 => {}
                _ => panic!("{file}: {spin:?} LUMO {lumo:?}"),
            }
        }
    }
    // Densities.
    let mut worst_density = 0.0f64;
    for &p in &pts {
        for (label, a, b) in [
            ("density", pa.density(wf, p), pb.density(want, p)),
            ("spin density", pa.spin_density(wf, p), pb.spin_density(want, p)),
        ] {
            let d = (a - b).abs() / b.abs().max(1.0);
            worst_density = worst_density.max(d);
            if d > 2.0 * c.value_tol {
                failures.push(format!("{label} at {p}: {a:e} vs {b:e}"));
            }
        }
    }
    eprintln!(
        "{file}: residual {:.1e}, worst orbital value {worst_value:.1e}, density {worst_density:.1e}, energy {worst_energy:.1e}",
        n.residual
    );
    failures.into_iter().map(|f| format!("{file}: {f}")).collect()
}

#[test]
fn wavefunction_files_match_their_molden_files() {
    let failures: Vec<String> = cases().iter().flat_map(check).collect();
    assert!(failures.is_empty(), "{} checks off:\n{}", failures.len(), failures.join("\n"));
}

/// Every fixture in the directory is one of the cases.
#[test]
fn every_fixture_is_checked() {
    let mut names: Vec<String> = std::fs::read_dir(DIR)
        .unwrap_or_else(|e| panic!("{DIR}: {e}"))
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| !n.ends_with(".molden"))
        .collect();
    names.sort();
    let mut listed: Vec<String> = cases().iter().map(|c| c.file.to_string()).filter(|f| !f.ends_with(".gz")).collect();
    listed.sort();
    assert_eq!(names, listed);
}

/// The three readers agree with one another where their files hold the same orbitals.
#[test]
fn the_formats_agree_with_each_other() {
    let docs: Vec<Document> = ["h2o_rhf.wfn", "h2o_rhf.wfx", "h2o_rhf.mkl"].iter().map(|f| load(f)).collect();
    let wfs: Vec<&Wavefunction> = docs.iter().map(|d| d.wavefunction.as_ref().expect("wf")).collect();
    let prepared: Vec<PreparedBasis> = wfs.iter().map(|w| PreparedBasis::new(&w.basis)).collect();
    // The wfn and wfx files expand the same 40 orbitals into the same primitives.
    assert_eq!(wfs[0].basis.n_functions(), wfs[1].basis.n_functions());
    assert_eq!(wfs[2].basis.n_functions(), 40, "pure functions");
    for p in points(&docs[0]).into_iter().take(50) {
        let rho: Vec<f64> = (0..3).map(|k| prepared[k].density(wfs[k], p)).collect();
        assert!(
            (rho[0] - rho[1]).abs() <= 1e-7 * rho[1].max(1.0) && (rho[2] - rho[1]).abs() <= 1e-8 * rho[1].max(1.0),
            "{p}: {rho:?}"
        );
    }
}
