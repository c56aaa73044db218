//! Normal modes of GAMESS-US, NWChem, Psi4 and Q-Chem frequency jobs read back what PySCF
//! computed (scripts/make_log_mode_fixtures.py: water and planar ammonia, RHF/STO-3G, written in
//! each program's layout) to the precision each program prints, 3N − 6 of them, imaginary ones
//! negative; a damaged section leaves the modes out, naming its line, and the file still opens.

use std::path::Path;

use glam::DVec3;

const LOGS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs");

struct Expected {
    frequency: Vec<f64>,
    intensity: Vec<f64>,
    unit_displacement: Vec<Vec<DVec3>>,
    geometry: Vec<DVec3>,
}

fn expected(molecule: &str) -> Expected {
    let text = std::fs::read_to_string(format!("{LOGS}/{molecule}_freq.expected.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let list = |k: &str| v[k].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>();
    let point = |x: &serde_json::Value| {
        let a: Vec<f64> = x.as_array().unwrap().iter().map(|c| c.as_f64().unwrap()).collect();
        DVec3::new(a[0], a[1], a[2])
    };
    let points = |x: &serde_json::Value| x.as_array().unwrap().iter().map(point).collect::<Vec<_>>();
    Expected {
        frequency: list("frequency_cm1"),
        intensity: list("ir_intensity_km_mol"),
        unit_displacement: v["displacement_unit"].as_array().unwrap().iter().map(points).collect(),
        geometry: points(&v["geometry_bohr"]),
    }
}

/// What each program prints: (frequency, intensity, displacement after normalising, geometry in
/// bohr) tolerances, half a unit of the last printed digit (the displacement's and the
/// intensity's grown by their rescaling).
fn tolerances(program: &str) -> (f64, f64, f64, f64) {
    match program {
        // F10.2; F12.5 in D²/(amu·Å²) × 42.26; F12.8; F20.10 bohr.
        "gamess" => (0.005, 5e-6 * 42.3, 1e-6, 5e-10),
        // F12.2; KM/mol F14.3; F12.5; F15.8 Å.
        "nwchem" => (0.005, 5e-4, 3e-5, 1e-8),
        // 4 decimals; 4 decimals; F6.2 normalised; F19.12 bohr.
        "psi4" => (5e-5, 5e-5, 0.012, 5e-12),
        // F.2; F.3; F7.3 normalised; F17.10 Å.
        "qchem" => (0.005, 5e-4, 1.5e-3, 1e-10),
        _ => unreachable!(),
    }
}

fn check(molecule: &str, program: &str) {
    let name = format!("{molecule}_{program}_freq.out");
    let doc = orbcloud::formats::load(Path::new(&format!("{LOGS}/{name}"))).unwrap_or_else(|e| panic!("{e}"));
    assert!(doc.problems.iter().all(|p| p.contains("no orbitals to draw")), "{name}: {:?}", doc.problems);
    let v = doc.vibrations.as_ref().unwrap_or_else(|| panic!("{name}: no modes"));
    let e = expected(molecule);
    let atoms = e.geometry.len();
    assert_eq!(v.modes.len(), 3 * atoms - 6, "{name}: 3N − 6 modes");
    assert_eq!(v.modes.len(), e.frequency.len(), "{name}");
    let (df, di, dd, dg) = tolerances(program);
    for (k, m) in v.modes.iter().enumerate() {
        assert!(
            (m.frequency_cm1 - e.frequency[k]).abs() <= df,
            "{name} mode {k}: {} vs {}",
            m.frequency_cm1,
            e.frequency[k]
        );
        assert_eq!(m.is_imaginary(), e.frequency[k] < 0.0, "{name} mode {k}");
        let i = m.ir_intensity.unwrap_or_else(|| panic!("{name} mode {k}: no intensity"));
        assert!((i - e.intensity[k]).abs() <= di, "{name} mode {k}: intensity {i} vs {}", e.intensity[k]);
        assert_eq!(m.displacement.len(), atoms, "{name} mode {k}");
        // The programs normalise differently (Σ m·|d|² or Σ |d|² = 1) and choose signs freely.
        let norm = m.displacement.iter().map(|d| d.length_squared()).sum::<f64>().sqrt();
        let off = |sign: f64| {
            m.displacement
                .iter()
                .zip(&e.unit_displacement[k])
                .map(|(d, x)| (*d / norm - *x * sign).abs().max_element())
                .fold(0.0, f64::max)
        };
        let worst = off(1.0).min(off(-1.0));
        assert!(worst <= dd, "{name} mode {k}: displacements off by {worst}");
    }
    assert_eq!(v.geometry.len(), atoms);
    for (p, x) in v.geometry.iter().zip(&e.geometry) {
        assert!((*p - *x).abs().max_element() <= dg * 1.9, "{name}: geometry {p} vs {x}");
    }
    // The modes belong to the geometry the document shows.
    let shown = &doc.molecule.atoms;
    assert_eq!(shown.len(), atoms);
    for (a, p) in shown.iter().zip(&v.geometry) {
        assert!(a.position.distance(*p) < 1e-9, "{name}: the shown atom {:?} vs the modes' {p}", a.position);
    }
}

#[test]
fn the_four_programs_modes_agree_with_pyscf_to_the_printed_precision() {
    for program in ["gamess", "nwchem", "psi4", "qchem"] {
        check("h2o", program);
    }
    // Planar ammonia: the inversion's transition state, `1081.38 I` (GAMESS-US), `1081.3768i`
    // (Psi4), `-1081.38` (Q-Chem); with GAMESS-US its rigid modes are modes 2 to 7.
    for program in ["gamess", "psi4", "qchem"] {
        check("nh3_planar", program);
        let name = format!("{LOGS}/nh3_planar_{program}_freq.out");
        let doc = orbcloud::formats::load(Path::new(&name)).unwrap();
        let modes = &doc.vibrations.unwrap().modes;
        assert_eq!(modes.iter().filter(|m| m.is_imaginary()).count(), 1, "{program}");
        assert!(modes[0].frequency_cm1 < -1000.0 && modes[0].ir_intensity.unwrap() > 500.0, "{program}");
    }
}

/// Each fixture's first block of displacements: the 0-based index of its last row, and a row to
/// insert after it that an atom more would print.
fn last_row_of_first_block(program: &str, lines: &[&str]) -> (usize, Vec<String>) {
    let find = |f: &dyn Fn(&str) -> bool| lines.iter().position(|l| f(l)).unwrap();
    match program {
        "gamess" => {
            let at = find(&|l| l.starts_with("  3   H            X"));
            let extra = [
                "  4   H            X  0.00000000  0.00000000  0.00000000  0.00000000  0.00000000",
                "                   Y  0.00000000  0.00000000  0.00000000  0.00000000  0.00000000",
                "                   Z  0.00000000  0.00000000  0.00000000  0.00000000  0.00000000",
            ];
            (at + 2, extra.map(String::from).to_vec())
        }
        "nwchem" => {
            let at = find(&|l| l.starts_with("           9 "));
            (at, vec![format!("{:12}{}", 10, "     0.00000".repeat(6))])
        }
        "psi4" => {
            (find(&|l| l.starts_with("      3   H")), vec![format!("      4   H               {}", "  0.00".repeat(9))])
        }
        "qchem" => {
            let first = find(&|l| l.starts_with(" H "));
            (first + 1, vec![format!(" H         {}", " 0.000".repeat(9))])
        }
        _ => unreachable!(),
    }
}

#[test]
fn a_block_cut_short_or_an_atom_too_many_leaves_the_modes_out_naming_the_line() {
    for program in ["gamess", "nwchem", "psi4", "qchem"] {
        let name = format!("h2o_{program}_freq.out");
        let text = std::fs::read_to_string(format!("{LOGS}/{name}")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let (last, extra) = last_row_of_first_block(program, &lines);
        let mut short: Vec<String> = lines.iter().map(ToString::to_string).collect();
        short.remove(last);
        let mut long: Vec<String> = lines.iter().map(ToString::to_string).collect();
        for (k, row) in extra.into_iter().enumerate() {
            long.insert(last + 1 + k, row);
        }
        // The short block stops where its last row was; the long one at the row too many.
        for (what, text, line) in
            [("cut short", short.join("\n"), last + 1), ("an atom too many", long.join("\n"), last + 2)]
        {
            let doc = orbcloud::formats::load_bytes(Path::new(&name), text.as_bytes())
                .unwrap_or_else(|e| panic!("{name} {what}: the file still opens: {e}"));
            assert!(doc.vibrations.is_none(), "{name} {what}");
            let problem = doc.problems.iter().find(|p| p.starts_with("normal modes left out"));
            let problem = problem.unwrap_or_else(|| panic!("{name} {what}: {:?}", doc.problems));
            assert!(problem.contains(&format!("{name}:{line}:")), "{name} {what}: {problem}");
            assert!(problem.contains("3 atoms") || problem.contains("3 × 3 atoms"), "{name} {what}: {problem}");
        }
        // Cut anywhere inside the section: never a panic, the modes whole or left out.
        let start = lines
            .iter()
            .position(|l| l.contains("Frequenc") || l.contains("FREQUENC") || l.contains("Freq ["))
            .unwrap();
        for cut in start..lines.len() {
            let cut_text = lines[..cut].join("\n");
            let doc = orbcloud::formats::load_bytes(Path::new(&name), cut_text.as_bytes()).unwrap();
            if let Some(v) = &doc.vibrations {
                assert!(v.modes.len() == 3 && v.modes.iter().all(|m| m.displacement.len() == 3), "{name} cut at {cut}");
            }
        }
    }
}

/// Psi4's finite differences print a geometry per displacement; the modes belong to the
/// reference: the last geometry computed before `FINDIF` (Psi4 1.3), or the first after it when
/// none was (1.7), never the last displaced one before the analysis.
#[test]
fn psi4_finite_difference_modes_belong_to_the_reference_geometry() {
    let text = std::fs::read_to_string(format!("{LOGS}/h2o_psi4_freq.out")).unwrap();
    let (head, rest) = text.split_at(text.find("  ==> Geometry <==").unwrap());
    let (table, analysis) = rest.split_at(rest.find("  ==> Harmonic Vibrational Analysis <==").unwrap());
    // The oxygen moved by 0.005 bohr along x, as a displacement would.
    let o_row = table.lines().find(|l| l.trim_start().starts_with("O ")).unwrap();
    let x: f64 = o_row.split_whitespace().nth(1).unwrap().parse().unwrap();
    let displaced = table.replacen(o_row, &o_row.replacen(&format!("{x:.12}"), &format!("{:.12}", x + 0.005), 1), 1);
    assert_ne!(displaced, table);
    let banner = "                                   FINDIF\n";
    let reference = expected("h2o").geometry[0];
    for (version, text) in [
        ("1.3", format!("{head}{table}{banner}{displaced}{displaced}{analysis}")),
        ("1.7", format!("{head}{banner}{table}{displaced}{displaced}{analysis}")),
    ] {
        let doc = orbcloud::formats::load_bytes(Path::new("findif.out"), text.as_bytes()).unwrap();
        let v = doc.vibrations.unwrap_or_else(|| panic!("{version}: {:?}", doc.problems));
        assert!(v.geometry[0].distance(reference) < 1e-9, "{version}: {} from {}", v.geometry[0], v.geometry_from);
    }
}
