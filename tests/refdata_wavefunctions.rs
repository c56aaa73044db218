//! The Molden and fchk files of ../shared/refdata/real-world (written by ORCA, Psi4, Turbomole,
//! CFOUR, Molpro, Molden, Gaussian and Q-Chem) load with the expected sizes, and the writer quirks
//! its MANIFEST.md lists are detected and repaired.
//!
//! The readers check orbitals with the analytic overlap of `model::overlap`; a plain, independent
//! reference overlap (tests/fixtures/readers/ref_overlap.rs) cross-checks it. HOMO, LUMO and
//! density values are compared with the corpus's expected tables (IOData + GBasis).

use std::path::{Path, PathBuf};

use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::basis::{Basis, ShellKind};
use orbcloud::model::orbitals::Spin;

#[path = "fixtures/readers/ref_overlap.rs"]
mod ref_overlap;

mod common;

/// The corpus; every test first asks `common::refdata`, which says when it is absent.
fn dir() -> PathBuf {
    common::refdata_dir()
}

fn load(path: &Path) -> Document {
    match formats::load(path) {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    }
}

struct Expected {
    name: &'static str,
    atoms: usize,
    ghosts: usize,
    basis_functions: usize,
    orbitals: usize,
    /// The program the repair is attributed to, `None` when the file needs no repair.
    repaired_for: Option<&'static str>,
}

const EXPECTED: &[Expected] = &[
    Expected {
        name: "nh3_orca.molden",
        atoms: 4,
        ghosts: 0,
        basis_functions: 50,
        orbitals: 50,
        repaired_for: Some("ORCA"),
    },
    Expected {
        name: "h2o_psi4_1.3.2_6-31G_d_cart.molden",
        atoms: 3,
        ghosts: 0,
        basis_functions: 19,
        orbitals: 19,
        repaired_for: Some("Psi4 <= 1.3.2"),
    },
    Expected {
        name: "nh3_turbomole.molden",
        atoms: 4,
        ghosts: 0,
        basis_functions: 52,
        orbitals: 50,
        repaired_for: Some("Turbomole"),
    },
    Expected {
        name: "h2o_ccpvdz_cfour.molden",
        atoms: 1,
        ghosts: 0,
        basis_functions: 15,
        orbitals: 15,
        repaired_for: Some("CFOUR"),
    },
    Expected {
        name: "nh3_molpro2012.molden",
        atoms: 4,
        ghosts: 0,
        basis_functions: 52,
        orbitals: 50,
        repaired_for: None,
    },
    Expected {
        name: "he2_ghost_psi4_1.0.molden",
        atoms: 2,
        ghosts: 1,
        basis_functions: 4,
        orbitals: 4,
        repaired_for: None,
    },
    Expected {
        name: "nh3_molden_pure.molden",
        atoms: 4,
        ghosts: 0,
        basis_functions: 50,
        orbitals: 50,
        repaired_for: None,
    },
    Expected {
        name: "o2_cc_pvtz_cart.fchk",
        atoms: 2,
        ghosts: 0,
        basis_functions: 70,
        orbitals: 70,
        repaired_for: None,
    },
    Expected {
        name: "water_hf_sto3g_qchem5.2.fchk",
        atoms: 3,
        ghosts: 0,
        basis_functions: 7,
        orbitals: 7,
        repaired_for: None,
    },
    Expected {
        name: "water_dimer_ghost.fchk",
        atoms: 6,
        ghosts: 3,
        basis_functions: 14,
        orbitals: 14,
        repaired_for: None,
    },
];

#[test]
fn every_wavefunction_file_is_covered() {
    if common::refdata("refdata_wavefunctions::every_wavefunction_file_is_covered").is_none() {
        return;
    }
    let mut names: Vec<String> = std::fs::read_dir(dir())
        .expect("read refdata dir")
        .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".molden") || n.ends_with(".fchk"))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no Molden or fchk files in {}", dir().display());
    for n in &names {
        assert!(EXPECTED.iter().any(|e| e.name == n), "{n} has no expectation in this test");
    }
}

#[test]
fn wavefunctions_load_with_expected_sizes_and_repairs() {
    if common::refdata("refdata_wavefunctions::wavefunctions_load_with_expected_sizes_and_repairs").is_none() {
        return;
    }
    let mut report = String::new();
    for e in EXPECTED {
        let path = dir().join(e.name);
        let doc = load(&path);
        let wf = doc.wavefunction.as_ref().expect("a wavefunction");
        let atoms = &doc.molecule.atoms;
        let nbf = wf.basis.n_functions();
        let norm = &wf.normalization;
        report.push_str(&format!(
            "{:38} atoms={} nbf={} mos={} program={} residual={:.1e} repair={}\n",
            e.name,
            atoms.len(),
            nbf,
            wf.orbitals.len(),
            norm.program,
            norm.residual,
            norm.repair
        ));
        assert_eq!(atoms.len(), e.atoms, "{}: atoms", e.name);
        assert_eq!(atoms.iter().filter(|a| a.ghost).count(), e.ghosts, "{}: ghosts", e.name);
        assert_eq!(nbf, e.basis_functions, "{}: basis functions", e.name);
        assert_eq!(wf.orbitals.len(), e.orbitals, "{}: orbitals", e.name);
        assert!(wf.orbitals.iter().all(|o| o.coefficients.len() == nbf), "{}: coefficient rows", e.name);
        match e.repaired_for {
            Some(program) => {
                assert_eq!(norm.program, program, "{}: {norm:?}", e.name);
                assert_ne!(norm.repair, "none", "{}", e.name);
            }
            None => assert_eq!(norm.repair, "none", "{}: {norm:?}", e.name),
        }
        assert!(norm.residual <= 1e-4, "{}: {norm:?}", e.name);
        // Every function of the model is unit-normalised.
        let s = ref_overlap::reference_overlap(&wf.basis);
        for i in 0..nbf {
            assert!((s[i * nbf + i] - 1.0).abs() < 1e-6, "{}: function {i} has norm² {}", e.name, s[i * nbf + i]);
        }
        assert!(wf.homo(Spin::Alpha).is_some(), "{}: no HOMO", e.name);
    }
    eprintln!("{report}");
}

#[test]
fn ghost_atoms_keep_their_element() {
    if common::refdata("refdata_wavefunctions::ghost_atoms_keep_their_element").is_none() {
        return;
    }
    let doc = load(&dir().join("he2_ghost_psi4_1.0.molden"));
    let a = &doc.molecule.atoms;
    assert!(a[0].ghost && a[0].z == 2 && a[0].charge == 0.0);
    assert!(!a[1].ghost && a[1].z == 2);
    let doc = load(&dir().join("water_dimer_ghost.fchk"));
    let ghosts: Vec<u32> = doc.molecule.atoms.iter().filter(|a| a.ghost).map(|a| a.z).collect();
    assert_eq!(ghosts, vec![1, 8, 1]);
}

#[test]
fn shell_kinds_follow_the_tags() {
    if common::refdata("refdata_wavefunctions::shell_kinds_follow_the_tags").is_none() {
        return;
    }
    let kinds = |name: &str| -> Vec<(u32, ShellKind)> {
        let doc = load(&dir().join(name));
        let basis: &Basis = &doc.wavefunction.as_ref().expect("wavefunction").basis;
        let mut k: Vec<_> = basis.shells.iter().map(|s| (s.l, s.kind)).collect();
        k.sort_by_key(|&(l, kind)| (l, kind == ShellKind::Pure));
        k.dedup();
        k
    };
    // [5D10F]: pure d.
    assert!(kinds("nh3_molden_pure.molden").contains(&(2, ShellKind::Pure)));
    // [5D] [9G] after [GTO]: pure d and f.
    assert!(kinds("nh3_orca.molden").contains(&(2, ShellKind::Pure)));
    // No tag: cartesian.
    assert!(kinds("nh3_turbomole.molden").iter().all(|&(l, kind)| l < 2 || kind == ShellKind::Cartesian));
}

/// One `x y z value` line of expected/NAME.KIND.tsv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpectedValue {
    pub point: [f64; 3],
    pub value: f64,
}

/// Reads expected/NAME.KIND.tsv (KIND homo, lumo or density): points in bohr, values in atomic
/// units, as computed by an independent reader and evaluator.
pub fn expected_values(name: &str, kind: &str) -> Vec<ExpectedValue> {
    let path = dir().join("expected").join(format!("{name}.{kind}.tsv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|(i, l)| {
            let v: Vec<f64> = l
                .split_whitespace()
                .map(|t| t.parse().unwrap_or_else(|_| panic!("{}:{}: not a number: {t}", path.display(), i + 1)))
                .collect();
            assert_eq!(v.len(), 4, "{}:{}: expected `x y z value`", path.display(), i + 1);
            ExpectedValue { point: [v[0], v[1], v[2]], value: v[3] }
        })
        .collect()
}

#[test]
fn expected_value_tables_are_readable() {
    if common::refdata("refdata_wavefunctions::expected_value_tables_are_readable").is_none() {
        return;
    }
    for e in EXPECTED {
        for kind in ["homo", "lumo", "density"] {
            let v = expected_values(e.name, kind);
            assert_eq!(v.len(), 200, "{} {kind}", e.name);
            assert!(v.iter().all(|x| x.value.is_finite()));
        }
    }
}

#[test]
fn every_wavefunction_extension_dispatches_also_gzipped() {
    if common::refdata("refdata_wavefunctions::every_wavefunction_extension_dispatches_also_gzipped").is_none() {
        return;
    }
    use std::io::Write;
    let tmp = tempfile::tempdir().expect("tempdir");
    for (src, names) in [
        ("he2_ghost_psi4_1.0.molden", &["a.molden", "a.molden.input", "a.mold", "a.MOLDEN.gz"][..]),
        ("water_dimer_ghost.fchk", &["b.fchk", "b.fch", "b.fchk.gz"][..]),
    ] {
        let bytes = std::fs::read(dir().join(src)).expect("read");
        for name in names {
            let path = tmp.path().join(name);
            let data = if name.ends_with(".gz") {
                let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
                gz.write_all(&bytes).expect("gzip");
                gz.finish().expect("gzip")
            } else {
                bytes.clone()
            };
            std::fs::write(&path, data).expect("write");
            let doc = formats::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(doc.wavefunction.is_some(), "{name}");
        }
    }
}

#[test]
fn the_analytic_overlap_agrees_with_the_reference_overlap() {
    if common::refdata("refdata_wavefunctions::the_analytic_overlap_agrees_with_the_reference_overlap").is_none() {
        return;
    }
    for e in EXPECTED {
        let doc = load(&dir().join(e.name));
        let basis = &doc.wavefunction.as_ref().expect("wavefunction").basis;
        let ours = orbcloud::model::overlap::overlap_matrix_as_written(basis);
        let reference = ref_overlap::reference_overlap(basis);
        let worst = ours.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{}: overlap matrices differ by {worst:e}", e.name);
    }
}

#[test]
fn orbitals_and_densities_match_the_expected_values() {
    if common::refdata("refdata_wavefunctions::orbitals_and_densities_match_the_expected_values").is_none() {
        return;
    }
    use orbcloud::model::gto::PreparedBasis;
    let mut report = String::new();
    for e in EXPECTED {
        let doc = load(&dir().join(e.name));
        let wf = doc.wavefunction.as_ref().expect("wavefunction");
        let prepared = PreparedBasis::new(&wf.basis);
        let mut worst = [0.0f64; 3];
        for (k, kind) in ["homo", "lumo", "density"].iter().enumerate() {
            let table = expected_values(e.name, kind);
            let orbital = match *kind {
                "homo" => wf.homo(Spin::Alpha),
                "lumo" => wf.lumo(Spin::Alpha),
                _ => None,
            };
            for x in &table {
                let p = glam::DVec3::from(x.point);
                let (ours, err) = match orbital {
                    Some(i) => {
                        let v = prepared.orbital_value(&wf.orbitals[i].coefficients, p);
                        (v, (v - x.value).abs())
                    }
                    None => {
                        let v = prepared.density(wf, p);
                        (v, (v - x.value).abs() / x.value.abs().max(1e-12))
                    }
                };
                worst[k] = worst[k].max(err);
                let tolerance = if orbital.is_some() { 1e-6 } else { 1e-5 };
                assert!(err <= tolerance, "{} {kind} at {:?}: {ours:.9e}, expected {:.9e}", e.name, x.point, x.value);
            }
        }
        report.push_str(&format!(
            "{:38} homo {:.1e}  lumo {:.1e}  density (rel) {:.1e}\n",
            e.name, worst[0], worst[1], worst[2]
        ));
    }
    eprintln!("{report}");
}

#[test]
fn fchk_files_name_their_writer() {
    if common::refdata("refdata_wavefunctions::fchk_files_name_their_writer").is_none() {
        return;
    }
    for (file, writer) in [
        ("o2_cc_pvtz_cart.fchk", "Gaussian"),
        ("water_dimer_ghost.fchk", "Gaussian"),
        ("water_hf_sto3g_qchem5.2.fchk", "Q-Chem"),
    ] {
        let doc = load(&dir().join(file));
        assert_eq!(doc.wavefunction.unwrap().normalization.program, writer, "{file}");
    }
}

/// Every real Molden file, cut before the last line of its last orbital (sections after `[MO]`
/// cut away too), is refused at the end of what is left, naming the coefficients it expected; with blank lines added at its end it
/// still opens whole.
#[test]
fn real_molden_files_cut_inside_their_last_orbital_are_refused() {
    if common::refdata("refdata_wavefunctions::real_molden_files_cut_inside_their_last_orbital_are_refused").is_none() {
        return;
    }
    let mut names: Vec<String> = std::fs::read_dir(dir())
        .expect("read refdata dir")
        .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".molden"))
        .collect();
    names.sort();
    assert!(!names.is_empty());
    for name in names {
        let text = std::fs::read_to_string(dir().join(&name)).unwrap();
        let whole = load(&dir().join(&name));
        let n = whole.wavefunction.as_ref().unwrap().basis.n_functions();
        // [MO] up to the next section (Molden's own files go on with others).
        let mo = text.find("[MO]").expect("an [MO] section");
        let mo_end = text[mo + 4..].find("\n[").map_or(text.len(), |k| mo + 4 + k + 1);
        let body = text[..mo_end].trim_end();
        let cut = &body[..body.rfind('\n').unwrap() + 1];
        match formats::load_bytes(Path::new(&name), cut.as_bytes()) {
            Ok(_) => panic!("{name} cut before its last line opened"),
            Err(e) => {
                let message = e.to_string();
                assert!(message.starts_with(&format!("{name}:{}:", cut.lines().count())), "{message}");
                assert!(message.contains(&format!("{n} coefficients")), "{message}");
            }
        }
        let padded = format!("{text}\n \n\n");
        let doc = formats::load_bytes(Path::new(&name), padded.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(doc.wavefunction.unwrap().orbitals.len(), whole.wavefunction.unwrap().orbitals.len(), "{name}");
    }
}
