//! The program logs of ../shared/refdata/real-world/logs (Gaussian 09 runs of divinylbenzene,
//! see its MANIFEST.md): the single point's orbitals agree with its fchk twin's within what 5
//! printed decimals allow, the optimisation opens as frames with their energies, the frequency
//! job's modes are the log's; ORCA 6's single point opens with its printed orbitals; the
//! GAMESS-US, NWChem, Psi4 and Q-Chem single points open with theirs: the Hartree–Fock ones
//! (NWChem, Psi4) give PySCF's density on their printed geometry
//! (tests/fixtures/logs/hf_log_reference.json, made by scripts/log_reference.py), the B3LYP ones
//! (GAMESS, Q-Chem) their printed orbital energies and 70 electrons.

use std::path::{Path, PathBuf};

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{Spin, Wavefunction};
use orbcloud::model::overlap::overlap_matrix;

mod common;

fn logs(test: &str) -> Option<PathBuf> {
    common::refdata(test).map(|d| d.join("logs"))
}

fn load(path: &Path) -> Document {
    formats::load(path).unwrap_or_else(|e| panic!("{e}"))
}

/// The nuclei (where core orbitals peak) and points around them (bohr).
fn points(doc: &Document) -> Vec<DVec3> {
    let atoms = &doc.molecule.atoms;
    let around = (0..40).map(|k| {
        let a = atoms[(k * 7) % atoms.len()].position;
        a + DVec3::new((k as f64 * 1.1).sin(), (k as f64 * 0.7).cos(), 0.3 * ((k % 5) as f64 - 2.0)) * 0.9
    });
    atoms.iter().map(|a| a.position).chain(around).collect()
}

fn density(wf: &Wavefunction, at: &[DVec3]) -> Vec<f64> {
    let pb = PreparedBasis::new(&wf.basis);
    at.iter()
        .map(|&p| wf.orbitals.iter().map(|o| o.occupation * pb.orbital_value(&o.coefficients, p).powi(2)).sum())
        .collect()
}

#[test]
fn the_single_point_log_gives_its_fchk_twins_orbitals() {
    let Some(dir) = logs("refdata_logs::the_single_point_log_gives_its_fchk_twins_orbitals") else { return };
    let log = load(&dir.join("basicGaussian09_dvb_sp.out"));
    let fchk = load(&dir.join("basicGaussian09_dvb_sp.fchk"));
    assert!(log.same_atoms(&fchk), "the log's standard orientation is the fchk's geometry");
    let (lw, fw) = (log.wavefunction.as_ref().expect("orbitals"), fchk.wavefunction.as_ref().expect("orbitals"));
    assert_eq!(lw.basis.n_functions(), fw.basis.n_functions());
    assert_eq!(lw.orbitals.len(), fw.orbitals.len());
    let n = &lw.normalization;
    eprintln!("sp log: max |CᵀSC − I| = {:.2e} (fchk {:.2e})", n.residual, fw.normalization.residual);
    assert_eq!((n.program.as_str(), n.repair.as_str(), n.printed_decimals), ("Gaussian", "none", Some(5)));
    assert!(n.residual > fw.normalization.residual, "rounding to 5 decimals shows: {n:?}");
    assert!(n.residual < n.expected_residual(), "{n:?}");

    // The twin's geometry differs from the printed one in the 6th decimal (1e-5 bohr), so its
    // orbitals are not the log's to the last printed digit: each coefficient agrees within 5
    // units of the 5th decimal, up to the orbital's sign. Orbitals within 1e-4 Eh of each other
    // (C 1s pairs) may mix: the density below covers them.
    let at = points(&log);
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..lw.orbitals.len() {
        let (l, f) = (&lw.orbitals[i], &fw.orbitals[i]);
        // Within one unit of the 5th decimal: Gaussian does not always round to nearest.
        assert!((l.energy - f.energy).abs() <= 1e-5, "orbital {}: {} and {}", i + 1, l.energy, f.energy);
        assert_eq!(l.occupation, f.occupation, "orbital {}", i + 1);
        match groups.last_mut() {
            Some(g) if (fw.orbitals[g[g.len() - 1]].energy - f.energy).abs() < 1e-4 => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    let mut worst: f64 = 0.0;
    for g in groups.iter().filter(|g| g.len() == 1) {
        let (a, b) = (&lw.orbitals[g[0]].coefficients, &fw.orbitals[g[0]].coefficients);
        let sign = if a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() < 0.0 { -1.0 } else { 1.0 };
        let diff = a.iter().zip(b).map(|(x, y)| (sign * x - y).abs()).fold(0.0, f64::max);
        assert!(diff <= 5e-5, "orbital {}: coefficients differ by {diff:e}", g[0] + 1);
        worst = worst.max(diff);
    }
    eprintln!("sp log: coefficients within {worst:.1e} of the fchk's");

    let (a, b) = (density(lw, &at), density(fw, &at));
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
    assert!(diff < 1e-4, "density differs by {diff:e} of its largest value");
    assert_eq!(lw.homo(Spin::Alpha), fw.homo(Spin::Alpha));
}

/// `SCF Done` energies of a log, read here on their own.
fn scf_energies(text: &str) -> Vec<f64> {
    text.lines()
        .filter(|l| l.trim_start().starts_with("SCF Done:"))
        .map(|l| l.split('=').nth(1).and_then(|r| r.split_whitespace().next()).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn the_optimisation_opens_as_frames_with_their_energies() {
    let Some(dir) = logs("refdata_logs::the_optimisation_opens_as_frames_with_their_energies") else { return };
    let path = dir.join("basicGaussian09_dvb_gopt.out");
    let doc = load(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    let energies = scf_energies(&text);
    let s = &doc.structure.as_ref().expect("a trajectory").structure;
    assert_eq!(s.models.len(), 5);
    assert_eq!(s.models.len(), energies.len(), "one frame per SCF energy");
    for (m, e) in s.models.iter().zip(&energies) {
        assert_eq!(m.energy, Some(*e), "{}", m.title);
        assert_eq!((m.atoms.end - m.atoms.start) as usize, 20);
    }
    assert!(doc.wavefunction.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("pop=full gfinput")), "{:?}", doc.problems);
    // The frames move: an optimisation's first and last geometries differ.
    let first = &s.position[s.models[0].atoms.start as usize..s.models[0].atoms.end as usize];
    let last = &s.position[s.models[4].atoms.start as usize..s.models[4].atoms.end as usize];
    assert!(first.iter().zip(last).any(|(a, b)| a.distance(*b) > 1e-3));
}

#[test]
fn the_frequency_log_has_its_54_modes() {
    let Some(dir) = logs("refdata_logs::the_frequency_log_has_its_54_modes") else { return };
    let path = dir.join("basicGaussian09_dvb_ir.out");
    let doc = load(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    // The three-column blocks' frequencies and intensities, read here on their own.
    let column = |key: &str| -> Vec<f64> {
        text.lines()
            .filter(|l| l.trim_start().starts_with(key) && !l.contains("---"))
            .flat_map(|l| l.split("--").nth(1).unwrap().split_whitespace().map(|v| v.parse::<f64>().unwrap()))
            .collect()
    };
    let (freqs, ir) = (column("Frequencies --"), column("IR Inten"));
    let v = doc.vibrations.as_ref().expect("modes");
    assert_eq!(v.modes.len(), 54);
    assert_eq!(freqs.len(), 54);
    for (k, m) in v.modes.iter().enumerate() {
        assert_eq!(m.frequency_cm1, freqs[k], "mode {}", k + 1);
        assert!((m.ir_intensity.unwrap() - ir[k]).abs() < 1e-9, "mode {}", k + 1);
        assert_eq!(m.displacement.len(), 20);
    }
    assert_eq!(v.geometry.len(), doc.molecule.atoms.len());
}

#[test]
fn a_td_log_without_printed_orbitals_opens_as_its_atoms_naming_the_keywords() {
    let Some(dir) = logs("refdata_logs::a_td_log_without_printed_orbitals_opens_as_its_atoms_naming_the_keywords")
    else {
        return;
    };
    // Q-Chem's TD job prints neither basis nor orbitals: it opens as its atoms (and its states).
    let qchem = load(&dir.join("basicQChem5.1_dvb_td.out"));
    assert_eq!(qchem.molecule.atoms.len(), 20);
    assert!(
        qchem.wavefunction.is_none()
            && qchem.problems.iter().any(|p| p.contains("no orbitals") && p.contains("print_orbitals = true")),
        "{:?}",
        qchem.problems
    );
    assert!(qchem.excited.is_some());
}

#[test]
fn the_orca_single_point_opens_with_its_printed_orbitals() {
    let Some(dir) = logs("refdata_logs::the_orca_single_point_opens_with_its_printed_orbitals") else { return };
    let path = dir.join("basicORCA6.0_dvb_sp_dft.out");
    let doc = load(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    // The ORBITAL ENERGIES table, read here on its own: `NO OCC E(Eh) E(eV) Irrep`.
    let table: Vec<(f64, f64)> = text
        .lines()
        .skip_while(|l| l.trim() != "ORBITAL ENERGIES")
        .skip(4)
        .map_while(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            (t.len() >= 4).then(|| (t[1].parse().ok(), t[2].parse().ok())).and_then(|(o, e)| Some((o?, e?)))
        })
        .collect();
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert_eq!(doc.molecule.atoms.len(), 20);
    assert_eq!(wf.basis.n_functions(), 60);
    // The table lists the occupied orbitals and the first virtual ones; the blocks print all.
    assert_eq!(wf.orbitals.len(), 60);
    assert!(table.len() > 35, "{} rows in ORBITAL ENERGIES", table.len());
    for (k, (o, (occupation, energy))) in wf.orbitals.iter().zip(&table).enumerate() {
        assert_eq!(o.occupation, *occupation, "orbital {k}");
        assert!((o.energy - energy).abs() <= 1e-5, "orbital {k}: {} and {energy}", o.energy);
    }
    let electrons: f64 = wf.orbitals.iter().map(|o| o.occupation).sum();
    assert_eq!(electrons, 70.0);
    let n = &wf.normalization;
    eprintln!("ORCA sp: max |CᵀSC − I| = {:.2e}", n.residual);
    assert_eq!((n.program.as_str(), n.repair.as_str(), n.printed_decimals), ("ORCA", "none", Some(6)));
    // Orthonormal to the print's precision only with the p functions taken as z, x, y.
    assert!(n.residual > 0.0 && n.residual < n.expected_residual(), "{n:?}");
    assert!(doc.title.contains("b3lyp"), "{}", doc.title);
}

/// Electrons in the density: tr(PS), the density's integral, from the analytic overlap.
fn electrons(wf: &Wavefunction) -> f64 {
    let s = overlap_matrix(&wf.basis);
    let n = wf.basis.n_functions();
    wf.orbitals
        .iter()
        .map(|o| {
            let c = &o.coefficients;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    sum += c[i] * s[i * n + j] * c[j];
                }
            }
            o.occupation * sum
        })
        .sum()
}

/// The HOMO's and LUMO's energies (alpha).
fn frontier(wf: &Wavefunction) -> (f64, f64) {
    let (h, l) = (wf.homo(Spin::Alpha).expect("a HOMO"), wf.lumo(Spin::Alpha).expect("a LUMO"));
    (wf.orbitals[h].energy, wf.orbitals[l].energy)
}

#[test]
fn the_hartree_fock_logs_give_pyscfs_density() {
    let Some(dir) = logs("refdata_logs::the_hartree_fock_logs_give_pyscfs_density") else { return };
    let reference: serde_json::Value =
        serde_json::from_str(include_str!("fixtures/logs/hf_log_reference.json")).unwrap();
    let reference = reference.as_object().unwrap();
    assert_eq!(reference.len(), 2);
    for (name, r) in reference {
        let path = dir.join(name);
        let doc = load(&path);
        let text = std::fs::read_to_string(&path).unwrap();
        let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("{name}: orbitals, {:?}", doc.problems));
        assert_eq!((doc.molecule.atoms.len(), wf.basis.n_functions(), wf.orbitals.len()), (20, 60, 60), "{name}");
        let at: Vec<DVec3> = r["points_bohr"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let p: Vec<f64> = p.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
                DVec3::new(p[0], p[1], p[2])
            })
            .collect();
        let want: Vec<f64> = r["density"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        // The reference's points begin at the nuclei PySCF was given, read from the log on its own.
        for (a, p) in doc.molecule.atoms.iter().zip(&at) {
            assert!(a.position.distance(*p) < 1e-5, "{name}: atom at {} and {p}", a.position);
        }
        let got = density(wf, &at);
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let deviation = got.iter().zip(&want).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
        let n = &wf.normalization;
        eprintln!(
            "{name}: max |CᵀSC − I| = {:.2e} ({} decimals); density within {deviation:.1e} of PySCF's largest value; {:.6} electrons",
            n.residual,
            n.printed_decimals.unwrap(),
            electrons(wf)
        );
        assert_eq!(n.repair, "none", "{name}");
        assert!(n.residual < n.expected_residual(), "{name}: {n:?}");
        assert!(deviation < 1e-4, "{name}: density differs by {deviation:e} of its largest value");
        assert!((electrons(wf) - 70.0).abs() < 1e-3, "{name}");
        // HOMO and LUMO: the log's printed energies (read here on their own) and PySCF's.
        let (homo, lumo) = frontier(wf);
        let printed = printed_frontier(name, &text);
        assert!(
            (homo - printed.0).abs() < 1e-6 && (lumo - printed.1).abs() < 1e-6,
            "{name}: {homo} {lumo} {printed:?}"
        );
        let (h, l) = (r["homo"].as_f64().unwrap(), r["lumo"].as_f64().unwrap());
        assert!((homo - h).abs() < 2e-5 && (lumo - l).abs() < 2e-5, "{name}: {homo} {lumo}, PySCF {h} {l}");
    }
}

/// The HOMO's and LUMO's energies as the log prints them outside the orbital blocks: NWChem's
/// orbital analysis (`Vector 35 Occ=2.000000D+00 E=-2.221902D-01`), Psi4's `Orbital Energies`
/// table (the last doubly occupied one and the first virtual one).
fn printed_frontier(name: &str, text: &str) -> (f64, f64) {
    let number = |s: &str| s.replace('D', "E").parse::<f64>().unwrap();
    if name.contains("NWChem") {
        let energy = |n: usize| {
            let key = format!("Vector{n:>5}");
            let line = text.lines().rfind(|l| l.trim_start().starts_with(&key)).unwrap();
            number(line.split("E=").nth(1).unwrap().split_whitespace().next().unwrap())
        };
        (energy(35), energy(36))
    } else {
        let table: Vec<&str> = text.lines().skip_while(|l| !l.contains("Doubly Occupied:")).collect();
        let values = |rows: &[&str]| -> Vec<f64> {
            rows.iter()
                .take_while(|l| !l.trim().is_empty())
                .flat_map(|l| l.split_whitespace().skip(1).step_by(2).map(number).collect::<Vec<_>>())
                .collect()
        };
        let occupied = values(&table[2..]);
        let virtual_at = table.iter().position(|l| l.contains("Virtual:")).unwrap();
        let virtuals = values(&table[virtual_at + 2..]);
        (*occupied.last().unwrap(), virtuals[0])
    }
}

#[test]
fn the_b3lyp_logs_give_their_printed_orbital_energies_and_70_electrons() {
    let Some(dir) = logs("refdata_logs::the_b3lyp_logs_give_their_printed_orbital_energies_and_70_electrons") else {
        return;
    };
    // ORCA's table prints 6 decimals, its orbital blocks 5; the others print the same numbers.
    for (name, program, decimals, orbitals, within) in [
        ("basicGAMESS-US2017_dvb_sp.out", "GAMESS", 6, 60, 1e-9),
        ("basicQChem5.1_dvb_sp.out", "Q-Chem", 5, 40, 1e-9),
        ("basicORCA6.0_dvb_sp_dft.out", "ORCA", 6, 60, 1e-5),
    ] {
        let path = dir.join(name);
        let doc = load(&path);
        let text = std::fs::read_to_string(&path).unwrap();
        let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("{name}: orbitals, {:?}", doc.problems));
        assert_eq!((doc.molecule.atoms.len(), wf.basis.n_functions(), wf.orbitals.len()), (20, 60, orbitals), "{name}");
        let n = &wf.normalization;
        let count = electrons(wf);
        eprintln!("{name}: max |CᵀSC − I| = {:.2e} ({decimals} decimals); {count:.6} electrons", n.residual);
        assert_eq!((n.program.as_str(), n.repair.as_str(), n.printed_decimals), (program, "none", Some(decimals)));
        assert!(n.residual < n.expected_residual(), "{name}: {n:?}");
        assert!((count - 70.0).abs() < 1e-3, "{name}: {count} electrons");
        let occupied: f64 = wf.orbitals.iter().map(|o| o.occupation).sum();
        assert_eq!(occupied, 70.0, "{name}");
        let printed = printed_energies(name, &text);
        assert!(printed.len() >= 36, "{name}: {} printed energies", printed.len());
        for (k, (o, e)) in wf.orbitals.iter().zip(&printed).enumerate() {
            assert!((o.energy - e).abs() <= within, "{name}: orbital {}: {} and {e}", k + 1, o.energy);
        }
        let (homo, lumo) = frontier(wf);
        assert!((homo - printed[34]).abs() <= within && (lumo - printed[35]).abs() <= within, "{name}");
    }
}

/// Orbital energies as a log lists them apart from the coefficients: GAMESS's first orbital
/// print (the energy lines under the numbers of each `EIGENVECTORS` block), Q-Chem's `Orbital
/// Energies (a.u.)` table (alpha, occupied then virtual), ORCA's `ORBITAL ENERGIES` table.
fn printed_energies(name: &str, text: &str) -> Vec<f64> {
    let lines: Vec<&str> = text.lines().collect();
    let numbers = |l: &str| -> Option<Vec<f64>> { l.split_whitespace().map(|t| t.parse().ok()).collect() };
    if name.contains("GAMESS") {
        let start = lines.iter().position(|l| l.trim() == "EIGENVECTORS").unwrap();
        let mut out = Vec::new();
        for (k, l) in lines.iter().enumerate().skip(start) {
            if l.contains("END OF RHF CALCULATION") {
                break;
            }
            let header = l.split_whitespace().map(|t| t.parse::<usize>().ok()).collect::<Option<Vec<_>>>();
            if header.is_some_and(|h| !h.is_empty() && h[0] == out.len() + 1) {
                out.extend(numbers(lines[k + 1]).unwrap());
            }
        }
        out
    } else if name.contains("QChem") {
        let start = lines.iter().position(|l| l.trim() == "Alpha MOs, Restricted").unwrap();
        lines[start..].iter().take_while(|l| !l.trim().is_empty()).filter_map(|l| numbers(l)).flatten().collect()
    } else {
        lines
            .iter()
            .skip_while(|l| l.trim() != "ORBITAL ENERGIES")
            .skip(4)
            .map_while(|l| {
                let t: Vec<&str> = l.split_whitespace().collect();
                (t.len() >= 4).then(|| t[2].parse::<f64>().ok()).flatten()
            })
            .collect()
    }
}
