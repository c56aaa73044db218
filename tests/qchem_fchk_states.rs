//! A Q-Chem CIS/TDA fchk's excited states and amplitudes (`Alpha Amplitudes`): the states, their
//! natural transition orbitals and transition densities from the file alone. The fixture is
//! PySCF's TDA of formaldehyde written in Q-Chem's layout by
//! scripts/make_qchem_amplitudes_fixture.py, with PySCF's own `get_nto` as the reference; Q-Chem
//! 5.4's real files (cclib's `water_cis` and `dvb_td`, with their logs) are checked against what
//! Q-Chem printed when they lie in the corpus.

mod common;

use std::path::{Path, PathBuf};

use orbcloud::model::Document;
use orbcloud::model::nto;
use orbcloud::model::transition::TransitionDensity;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/excited/formaldehyde_qchem_tda.fchk");
const EXPECTED: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/excited/formaldehyde_qchem_tda.expected.json");

fn load(path: &Path) -> Document {
    orbcloud::formats::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn expected() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(EXPECTED).unwrap()).unwrap()
}

fn points(reference: &serde_json::Value) -> Vec<glam::DVec3> {
    (reference["points_bohr"].as_array().unwrap().iter())
        .map(|p| glam::DVec3::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap(), p[2].as_f64().unwrap()))
        .collect()
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// The largest difference between `ours` and `theirs` up to an overall sign, over the largest
/// |value|.
fn relative_up_to_sign(ours: &[f64], theirs: &[f64]) -> f64 {
    let scale = theirs.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = |sign: f64| ours.iter().zip(theirs).map(|(a, b)| (a - sign * b).abs()).fold(0.0, f64::max);
    worst(1.0).min(worst(-1.0)) / scale
}

/// The file opens with PySCF's six states in order of energy (triplets and singlets mixed, as
/// Q-Chem's log numbers them, though the file lists the triplets first), their energies and
/// oscillator strengths as written, no spins (the file names none, and says so), and every
/// state's natural transition orbitals equal PySCF's `get_nto`: the weights to 1e-6, each pair
/// whose weight stands apart from its neighbours' at 40 points to 1e-6 of its largest value, up
/// to sign.
#[test]
fn a_qchem_tda_fchk_gives_pyscfs_states_and_natural_transition_orbitals() {
    let doc = load(Path::new(FIXTURE));
    assert!(doc.problems.is_empty(), "{:?}", doc.problems);
    let reference = expected();
    let states = doc.excited.as_ref().expect("the file's states");
    let theirs = reference["states"].as_array().unwrap();
    assert_eq!((states.program.as_str(), states.method.as_str()), ("Q-Chem", "CIS/TDA"));
    assert!(states.note.contains("singlets and which triplets"), "{}", states.note);
    assert_eq!(states.states.len(), theirs.len());
    let wf = doc.wavefunction.as_ref().unwrap();
    let prepared = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
    let at = points(&reference);
    let (mut pairs_compared, mut worst_weight, mut worst_orbital) = (0, 0.0f64, 0.0f64);
    for (state, expected) in states.states.iter().zip(theirs) {
        let k = state.number;
        assert!((state.energy_ev - expected["energy_ev"].as_f64().unwrap()).abs() < 1e-6, "state {k}");
        let f = expected["oscillator_strength"].as_f64().unwrap();
        assert!((state.oscillator_strength.unwrap() - f).abs() < 1e-8, "state {k}");
        assert!(state.spin.is_empty(), "state {k}: {}", state.spin);
        let ntos = nto::from_transitions(wf, state).expect("NTOs");
        assert!((ntos.printed_norm - 0.5).abs() < 1e-7, "state {k}: Σc² {}", ntos.printed_norm);
        let pairs = expected["ntos"].as_array().unwrap();
        assert_eq!(ntos.pairs.len(), pairs.len(), "state {k}: the pairs kept");
        let weights: Vec<f64> = pairs.iter().map(|p| p["weight"].as_f64().unwrap()).collect();
        for (j, (ours, theirs)) in ntos.pairs.iter().zip(pairs).enumerate() {
            let w = weights[j];
            worst_weight = worst_weight.max((ours.weight - w).abs());
            assert!((ours.weight - w).abs() < 1e-6, "state {k} pair {}: {} vs {w}", j + 1, ours.weight);
            // A pair's orbitals are defined when its weight stands apart from its neighbours'.
            let apart = weights.iter().enumerate().all(|(i, v)| i == j || (v - w).abs() > 1e-3);
            if !apart {
                continue;
            }
            for (coefficients, key) in [(&ours.hole, "hole"), (&ours.particle, "particle")] {
                let values: Vec<f64> = at.iter().map(|&p| prepared.orbital_value(coefficients, p)).collect();
                let d = relative_up_to_sign(&values, &floats(&theirs[key]));
                worst_orbital = worst_orbital.max(d);
                assert!(d < 1e-6, "state {k} pair {} {key}: {d:.2e}", j + 1);
            }
            pairs_compared += 1;
        }
    }
    eprintln!(
        "{} states, {pairs_compared} pairs' orbitals compared: weights within {worst_weight:.1e}, orbitals within \
         {worst_orbital:.1e} of PySCF's get_nto",
        theirs.len()
    );
    assert!(pairs_compared >= 6, "{pairs_compared}");
}

/// A singlet's transition density, made from the file's amplitudes and orbitals, gives the
/// oscillator strength the file records (PySCF's) to 1e-6.
#[test]
fn a_qchem_fchk_singlets_transition_density_gives_its_recorded_oscillator_strength() {
    let doc = load(Path::new(FIXTURE));
    let wf = doc.wavefunction.as_ref().unwrap();
    let moments = orbcloud::model::overlap::moment_matrices(&wf.basis);
    let reference = expected();
    let mut bright = 0;
    for (state, expected) in doc.excited.as_ref().unwrap().states.iter().zip(reference["states"].as_array().unwrap()) {
        if expected["spin"] != "Singlet" {
            continue;
        }
        let t = TransitionDensity::of_state(&doc, state.number).expect("a transition density");
        let f = t.oscillator_strength(wf, &moments, state.energy_ev);
        let recorded = state.oscillator_strength.unwrap();
        eprintln!("state {}: f {f:.8} from the amplitudes, {recorded:.8} recorded", state.number);
        assert!((f - recorded).abs() < 1e-6 * recorded.max(1e-2), "state {}: {f} vs {recorded}", state.number);
        bright += (recorded > 0.01) as usize;
    }
    assert_eq!(bright, 1);
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().unwrap()
}

/// The command line needs no log: `info --json` lists each state's NTO weights and what the file
/// leaves unsaid, `eval --state N --orbital "hole 1"` gives PySCF's hole, and `cube
/// --transition-density` writes the state's transition density.
#[test]
fn the_command_line_reads_the_states_amplitudes_from_the_fchk_alone() {
    let out = orbcloud(&["info", "--json", FIXTURE]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let listed = &info["excited_states"];
    assert!(listed["note"].as_str().unwrap().contains("Alpha Amplitudes"), "{listed}");
    let reference = expected();
    let fifth = &reference["states"][4];
    let w = listed["states"][4]["ntos"]["weights"][0].as_f64().unwrap();
    assert!((w - fifth["ntos"][0]["weight"].as_f64().unwrap()).abs() < 1e-6, "{w}");
    let text = String::from_utf8(orbcloud(&["info", FIXTURE]).stdout).unwrap();
    assert!(text.contains("6 excited states (CIS/TDA) from Q-Chem") && text.contains("NTO weights 0.866"), "{text}");

    let dir = tempfile::tempdir().unwrap();
    let points_file = dir.path().join("points.txt");
    let at = points(&reference);
    std::fs::write(&points_file, at.iter().map(|p| format!("{} {} {}\n", p.x, p.y, p.z)).collect::<String>()).unwrap();
    let pts = points_file.display().to_string();
    let out = orbcloud(&["eval", FIXTURE, "--state", "5", "--orbital", "hole 1", "--points", &pts]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let values: Vec<f64> = (String::from_utf8(out.stdout).unwrap().lines())
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    let d = relative_up_to_sign(&values, &floats(&fifth["ntos"][0]["hole"]));
    assert!(d < 1e-6, "hole 1 of state 5: {d:.2e}");

    let cube = dir.path().join("t5.cube");
    let out = orbcloud(&[
        "cube",
        FIXTURE,
        "--transition-density",
        "--state",
        "5",
        "--grid",
        "30",
        "-o",
        cube.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let grid = &load(&cube).volumes[0];
    assert!(grid.label.contains("transition density (state 5)"), "{}", grid.label);
    assert!(grid.stats.min < -1e-3 && grid.stats.max > 1e-3, "{} … {}", grid.stats.min, grid.stats.max);
}

/// Q-Chem 5.4's real CIS and TDA checkpoints (cclib's regression data, commit 21daa96:
/// `data/FChk/basicQChem5.4/{water_cis,dvb_td}.fchk` and their `data/QChem/basicQChem5.4` logs,
/// kept in the corpus as `basicQChem5.4_NAME.fchk` and `.out`), where they lie in it: each state's
/// energy is the log's (4 decimals) under the log's number; every transition the log prints is
/// the file's amplitude × √2 (Q-Chem's log normalises to 1, the file to ½); a singlet's transition
/// density gives the oscillator strength Q-Chem recorded (TDA and CIS: exact); joined to its log,
/// each state takes the log's spin and keeps the file's amplitudes.
#[test]
fn qchem_54s_real_checkpoints_agree_with_their_logs() {
    let Some(dir) = common::refdata("qchem_fchk_states::qchem_54s_real_checkpoints_agree_with_their_logs") else {
        return;
    };
    for name in ["water_cis", "dvb_td"] {
        let (fchk, log): (PathBuf, PathBuf) =
            (dir.join(format!("logs/basicQChem5.4_{name}.fchk")), dir.join(format!("logs/basicQChem5.4_{name}.out")));
        if !fchk.is_file() || !log.is_file() {
            eprintln!("{name}: not run: {} or its log is not in the corpus", fchk.display());
            continue;
        }
        let mut doc = load(&fchk);
        assert!(doc.problems.is_empty(), "{name}: {:?}", doc.problems);
        let printed = load(&log).excited.expect("the log's states");
        let listed = doc.excited.clone().expect("the file's states");
        assert_eq!(listed.states.len(), printed.states.len(), "{name}");
        let wf = doc.wavefunction.clone().unwrap();
        let moments = orbcloud::model::overlap::moment_matrices(&wf.basis);
        let (mut transitions, mut worst, mut worst_f) = (0, 0.0f64, 0.0f64);
        for (ours, theirs) in listed.states.iter().zip(&printed.states) {
            assert_eq!(ours.number, theirs.number, "{name}");
            assert!((ours.energy_ev - theirs.energy_ev).abs() < 6e-5, "{name} state {}", ours.number);
            for t in &theirs.transitions {
                let c = (ours.transitions.iter())
                    .find(|o| o.from == t.from && o.to == t.to)
                    .map_or(0.0, |o| o.coefficient * std::f64::consts::SQRT_2);
                worst = worst.max((c - t.coefficient).abs());
                assert!((c - t.coefficient).abs() < 6e-5, "{name} state {} {t}: {c:.5} here", ours.number);
                transitions += 1;
            }
            if theirs.spin == "Singlet" {
                let td = TransitionDensity::of_state(&doc, ours.number).expect("a transition density");
                let f = td.oscillator_strength(&wf, &moments, ours.energy_ev);
                let recorded = ours.oscillator_strength.unwrap();
                worst_f = worst_f.max((f - recorded).abs() / recorded.max(1e-2));
                assert!(
                    (f - recorded).abs() < 1e-4 * recorded.max(1e-2),
                    "{name} state {}: f {f} vs {recorded}",
                    ours.number
                );
            }
        }
        eprintln!(
            "{name}: {} states, {transitions} printed transitions within {worst:.1e} of the file's √2·X; singlets' f \
             within {worst_f:.1e} (relative) of Q-Chem's",
            listed.states.len()
        );
        doc.join(load(&log)).unwrap();
        let joined = doc.excited.as_ref().unwrap();
        assert!(joined.note.is_empty(), "{name}: every state named: {}", joined.note);
        let (mut kept, mut printed_count) = (0, 0);
        for (ours, theirs) in joined.states.iter().zip(&printed.states) {
            assert_eq!(ours.spin, theirs.spin, "{name} state {}", ours.number);
            assert!(ours.transitions.len() >= theirs.transitions.len(), "{name} state {}", ours.number);
            (kept, printed_count) = (kept + ours.transitions.len(), printed_count + theirs.transitions.len());
        }
        assert!(kept > printed_count, "{name}: the file's own amplitudes kept ({kept}, printed {printed_count})");
    }
}

#[test]
fn real_qchem_and_gaussian_checkpoints_without_amplitudes_open_as_before() {
    // The amplitude records are read only where a file has them: the corpus's real Q-Chem 5.2
    // ground-state fchk lists no states and no problems, and Gaussian's real TD checkpoint keeps
    // its states (from `ETran`) without transitions, which its log supplies.
    let Some(dir) = common::refdata("qchem_fchk_states::real_checkpoints_without_amplitudes") else { return };
    let qchem = load(&dir.join("water_hf_sto3g_qchem5.2.fchk"));
    assert!(qchem.excited.is_none(), "{:?}", qchem.excited);
    assert!(qchem.problems.is_empty(), "{:?}", qchem.problems);
    let gaussian = load(&dir.join("logs/basicGaussian09_dvb_td.fchk"));
    let states = gaussian.excited.expect("Gaussian's TD states");
    assert_eq!(states.states.len(), 5);
    assert!(states.states.iter().all(|s| s.transitions.is_empty() && !s.amplitudes_normalised_to_one));
}
