//! Excited states of ../shared/refdata/real-world/logs (divinylbenzene's TD-DFT in Gaussian 09,
//! ORCA 6 and Q-Chem 5.1, and CO's Gaussian TD checkpoint; see its MANIFEST.md): the states
//! each file lists, and the difference, attachment and detachment densities of the Gaussian TD
//! fchk files, whose electrons moved the two densities share on the grid as in the trace.

use std::path::{Path, PathBuf};

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::excited_density::StatePart;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::Quantity;

mod common;

fn logs(test: &str) -> Option<PathBuf> {
    common::refdata(test).map(|d| d.join("logs"))
}

fn load(path: &Path) -> Document {
    formats::load(path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn td_fchk_files_hold_their_states_and_one_excited_density() {
    let Some(dir) = logs("excited_states::td_fchk_files_hold_their_states_and_one_excited_density") else { return };
    // The grid's integrals: a 0.2 bohr grid sums STO-3G's smooth valence densities almost
    // exactly, but CO's 6-311++G(d,p) detachment density peaks at 1.2 a.u. on the nuclei
    // (functions 0.01 bohr wide) and its attachment reaches past the grid's 6 bohr margin
    // through the diffuse functions: there the grid is good to 1 %, the trace is exact.
    for (name, count, grid_error) in
        [("basicGaussian09_dvb_td.fchk", 5, 1e-4), ("basicGaussian09_CO_TD_delta.fchk", 24, 1e-2)]
    {
        let doc = load(&dir.join(name));
        assert!(doc.problems.is_empty(), "{name}: {:?}", doc.problems);
        let states = doc.excited.as_ref().expect("states");
        assert_eq!(states.states.len(), count, "{name}");
        assert_eq!(states.density_of, Some(1), "{name}");
        let wf = doc.wavefunction.as_ref().expect("orbitals");
        let excited = wf.excited.as_ref().expect("an excited density");
        let moved = excited.electrons_moved();
        let detached = excited.electrons_detached();
        eprintln!("{name}: electrons moved {moved:.6}, detached {detached:.6}");
        // tr(ΔP S) = 0: the excitation keeps the electron count.
        assert!((moved - detached).abs() < 1e-6, "{name}: {moved} vs {detached}");
        assert!(moved > 0.5 && moved < 2.0, "{name}: {moved}");
        let prepared = PreparedBasis::new(&wf.basis);
        let g = excited.grid_descriptors(&prepared, &doc.molecule).expect("atoms");
        eprintln!("{name}: {g:?}");
        for (what, integral) in [("attachment", g.attachment_integral), ("detachment", g.detachment_integral)] {
            let error = (integral - moved).abs() / moved;
            assert!(error < grid_error, "{name}: {what} integrates to {integral}, trace {moved}");
        }
        assert!(!excited.sets(StatePart::Attachment).is_empty());
    }
}

#[test]
fn centroids_from_dipole_integrals_agree_with_the_grid() {
    let Some(dir) = logs("excited_states::centroids_from_dipole_integrals_agree_with_the_grid") else { return };
    let doc = load(&dir.join("basicGaussian09_dvb_td.fchk"));
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    let d = wf.excited.as_ref().expect("density").descriptors(&wf.basis, &doc.molecule).expect("atoms");
    eprintln!("{d:?}");
    for (exact, grid) in [
        (d.attachment_centroid_bohr, d.grid.attachment_centroid),
        (d.detachment_centroid_bohr, d.grid.detachment_centroid),
    ] {
        for k in 0..3 {
            assert!((exact[k] - grid[k]).abs() < 1e-3, "{exact:?} vs {grid:?}");
        }
    }
}

/// What scripts/excited_reference.py computes from an fchk file with numpy and PySCF alone.
#[derive(serde::Deserialize)]
struct Reference {
    points: Vec<[f64; 3]>,
    rho_excited: Vec<f64>,
    difference: Vec<f64>,
    attachment: Vec<f64>,
    detachment: Vec<f64>,
    electrons_moved: f64,
    electrons_detached: f64,
    trace_delta_s: f64,
    attachment_centroid: [f64; 3],
    detachment_centroid: [f64; 3],
}

fn reference(fchk: &Path) -> Reference {
    let python = orbcloud::sources::compute::python();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/excited_reference.py");
    let out = std::process::Command::new(&python)
        .arg(&script)
        .arg(fchk)
        .output()
        .unwrap_or_else(|e| panic!("running `{python}`: {e} (scripts/test sets ORBCLOUD_PYTHON)"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("the script's JSON")
}

/// The four densities of both Gaussian TD checkpoints at 340 points agree with PySCF's
/// evaluation of the file's own matrices (its own Löwdin diagonalisation for attachment and
/// detachment) within 1e-6 of the largest value, and so do the electrons moved and centroids.
#[test]
fn state_densities_equal_an_independent_evaluation() {
    let Some(dir) = logs("excited_states::state_densities_equal_an_independent_evaluation") else { return };
    for name in ["basicGaussian09_dvb_td.fchk", "basicGaussian09_CO_TD_delta.fchk"] {
        let path = dir.join(name);
        let r = reference(&path);
        let doc = load(&path);
        let wf = doc.wavefunction.as_ref().expect("orbitals");
        let excited = wf.excited.as_ref().expect("an excited density");
        let points: Vec<DVec3> = r.points.iter().map(|p| DVec3::from_array(*p)).collect();
        let prepared = PreparedBasis::new(&wf.basis);
        for (quantity, expected) in [
            (Quantity::DifferenceDensity, &r.difference),
            (Quantity::Attachment, &r.attachment),
            (Quantity::Detachment, &r.detachment),
            (Quantity::ExcitedDensity, &r.rho_excited),
        ] {
            let got = prepared.quantity_at_points(wf, &doc.molecule, quantity, &points);
            let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = got.iter().zip(expected).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            eprintln!("{name} {quantity:?}: max |orbcloud − PySCF| = {worst:.2e} (max |value| {scale:.3e})");
            assert!(worst <= 1e-6 * scale, "{name} {quantity:?}: {worst:e} over {scale:e}");
        }
        eprintln!(
            "{name}: electrons moved {:.9} (PySCF {:.9}), tr(ΔP S) = {:.1e}",
            excited.electrons_moved(),
            r.electrons_moved,
            r.trace_delta_s
        );
        assert!((excited.electrons_moved() - r.electrons_moved).abs() < 1e-8);
        assert!((excited.electrons_detached() - r.electrons_detached).abs() < 1e-8);
        let moments = orbcloud::model::overlap::moment_matrices(&wf.basis);
        for (ours, theirs) in [
            (excited.centroid(StatePart::Attachment, &moments).to_array(), r.attachment_centroid),
            (excited.centroid(StatePart::Detachment, &moments).to_array(), r.detachment_centroid),
        ] {
            for k in 0..3 {
                assert!((ours[k] - theirs[k]).abs() < 1e-6, "{name}: centroid {ours:?} vs PySCF {theirs:?}");
            }
        }
    }
}

/// (number, eV, f) of a state, for comparing with the printed tables.
fn summary(s: &orbcloud::model::excited::ExcitedState) -> (usize, f64, Option<f64>) {
    (s.number, s.energy_ev, s.oscillator_strength)
}

/// The TD tables of the three dvb logs: the state count, the first and last states' energies
/// and oscillator strengths as printed, their spin, and the main transition in Gaussian's
/// numbering (ORCA's orbitals count from 0, Q-Chem's virtuals after the 35 occupied).
#[test]
fn td_logs_list_their_states_as_printed() {
    let Some(dir) = logs("excited_states::td_logs_list_their_states_as_printed") else { return };
    let cases = [
        (
            "basicGaussian09_dvb_td.out",
            5,
            (1, 5.6287, Some(0.0018)),
            (5, 7.0797, Some(0.1551)),
            ("Singlet", "A"),
            (34, 36, 0.52587),
        ),
        (
            "basicORCA6.0_dvb_td.out",
            10,
            (1, 5.352154, Some(0.005038390)),
            (10, 5.298129, Some(0.0)),
            ("Singlet", "Bu"),
            (34, 36, 0.75002079),
        ),
        (
            "basicQChem5.1_dvb_td.out",
            10,
            (1, 3.6052, Some(0.0)),
            (10, 7.5567, Some(0.0)),
            ("Triplet", ""),
            (35, 36, 0.9266),
        ),
    ];
    for (name, count, first, last, (spin, symmetry), main) in cases {
        let doc = load(&dir.join(name));
        assert_eq!(doc.molecule.atoms.len(), 20, "{name}");
        let states = doc.excited.as_ref().unwrap_or_else(|| panic!("{name}: no states"));
        assert_eq!(states.states.len(), count, "{name}");
        let (a, b) = (states.states.first().unwrap(), states.states.last().unwrap());
        assert_eq!((summary(a), summary(b)), (first, last), "{name}");
        assert_eq!((a.spin.as_str(), a.symmetry.as_str()), (spin, symmetry), "{name}");
        let t = a.main_transitions(1)[0];
        assert_eq!((t.from, t.to, t.coefficient), main, "{name}");
        assert!((a.wavelength_nm() - 1239.841984 / first.1).abs() < 1e-9);
        // Each program's normalisation, read off its own numbers (the transition density needs
        // it): Gaussian's amplitudes square-sum to ½, ORCA's c and Q-Chem's log's to 1.
        for s in &states.states {
            let sum: f64 = s.transitions.iter().filter(|t| !t.deexcitation).map(|t| t.coefficient.powi(2)).sum();
            let whole = if s.amplitudes_normalised_to_one { 1.0 } else { 0.5 };
            eprintln!("{name} state {}: Σc² = {sum:.4} of {whole}", s.number);
            assert!(sum > 0.6 * whole && sum < 1.1 * whole, "{name} state {}: Σc² = {sum} against {whole}", s.number);
        }
    }
    // The strongest states, as each program prints them.
    let strongest = |name: &str| {
        let doc = load(&dir.join(name));
        let s = doc.excited.unwrap().states;
        let f = |x: &orbcloud::model::excited::ExcitedState| x.oscillator_strength.unwrap_or(-1.0);
        let best = s.iter().max_by(|x, y| f(x).total_cmp(&f(y))).unwrap();
        (best.number, best.oscillator_strength)
    };
    assert_eq!(strongest("basicGaussian09_dvb_td.out"), (2, Some(0.5880)));
    assert_eq!(strongest("basicORCA6.0_dvb_td.out"), (2, Some(1.170940055)));
    assert_eq!(strongest("basicQChem5.1_dvb_td.out"), (7, Some(0.9407714761)));
}

/// The fchk's states: ΔE from `ETran state values` and `SCF Energy`, f = ⅔ ΔE |μ|², equal to
/// the twin log's printed values: the energies within their last digit; f within 3e-4 of its
/// value besides, since the fchk's transition dipoles differ from the log's in the fourth digit
/// (state 2: |μ|² = 3.9585 from the fchk, 3.9588 printed, f 0.58790 and 0.5880).
#[test]
fn the_td_fchk_states_match_the_logs_print() {
    let Some(dir) = logs("excited_states::the_td_fchk_states_match_the_logs_print") else { return };
    let fchk = load(&dir.join("basicGaussian09_dvb_td.fchk")).excited.expect("states");
    let log = load(&dir.join("basicGaussian09_dvb_td.out")).excited.expect("states");
    assert_eq!(fchk.states.len(), log.states.len());
    for (f, l) in fchk.states.iter().zip(&log.states) {
        eprintln!(
            "state {}: fchk {:.5} eV f={:.5}, log {} eV f={:?}",
            f.number,
            f.energy_ev,
            f.oscillator_strength.unwrap(),
            l.energy_ev,
            l.oscillator_strength
        );
        assert!((f.energy_ev - l.energy_ev).abs() < 1e-4, "{f:?} vs {l:?}");
        let (ff, lf) = (f.oscillator_strength.unwrap(), l.oscillator_strength.unwrap());
        assert!((ff - lf).abs() <= 0.5e-4 + 3e-4 * lf, "{f:?} vs {l:?}");
        assert_eq!(f.spin, l.spin);
    }
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud")
}

/// `info --json` lists the TD fchk's states and its density's electrons moved, centroids'
/// distance and overlap; the text lists the states too.
#[test]
fn info_lists_states_and_the_electrons_moved() {
    let Some(dir) = logs("excited_states::info_lists_states_and_the_electrons_moved") else { return };
    let path = dir.join("basicGaussian09_dvb_td.fchk");
    let out = orbcloud(&["info", "--json", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let x = &json["excited_states"];
    let states = x["states"].as_array().expect("states");
    assert_eq!(states.len(), 5);
    assert!((states[0]["energy_ev"].as_f64().unwrap() - 5.6287).abs() < 1e-4, "{}", states[0]);
    assert!((states[0]["wavelength_nm"].as_f64().unwrap() - 220.27).abs() < 0.01);
    assert_eq!(states[1]["spin"], "Singlet");
    let d = &x["density"];
    let doc = load(&path);
    let wf = doc.wavefunction.as_ref().unwrap();
    let moved = wf.excited.as_ref().unwrap().electrons_moved();
    assert_eq!(d["state"], 1);
    assert!((d["electrons_moved"].as_f64().unwrap() - moved).abs() < 1e-12, "{d}");
    let distance = d["centroid_distance_bohr"].as_f64().unwrap();
    let overlap = d["grid"]["overlap"].as_f64().unwrap();
    assert!(distance > 0.1 && distance < 1.0 && overlap > 0.5 && overlap < 1.0, "{d}");

    let log = dir.join("basicGaussian09_dvb_td.out");
    let out = orbcloud(&["info", log.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("5 excited states") && text.contains("220.27 nm"), "{text}");
    assert!(text.contains("35 -> 36 0.67354"), "state 2's main transition: {text}");
}

/// `cube --attachment` writes the attachment density (positive, its electrons those moved);
/// `eval --difference-density` prints the library's values; files without an excited density
/// are refused naming the file, and a state the file has no density of is refused naming it.
#[test]
fn cube_and_eval_of_state_densities_and_refusals() {
    let Some(dir) = logs("excited_states::cube_and_eval_of_state_densities_and_refusals") else { return };
    let td = dir.join("basicGaussian09_dvb_td.fchk");
    let tmp = tempfile::tempdir().unwrap();
    let cube = tmp.path().join("attachment.cube");
    let out =
        orbcloud(&["cube", td.to_str().unwrap(), "--attachment", "--spacing", "0.25", "-o", cube.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let grid = &load(&cube).volumes[0];
    let electrons: f64 = grid.values.iter().map(|&v| f64::from(v)).sum::<f64>() * grid.voxel_volume();
    eprintln!("attachment cube: {:?}, {electrons:.5} electrons", grid.dims);
    assert!(grid.stats.min >= 0.0, "{:?}", grid.stats);
    assert!((electrons - 1.00113).abs() < 2e-3, "{electrons}");

    let points = tmp.path().join("points.txt");
    std::fs::write(&points, "0 0 0\n1.5 -0.5 0.3\n-2.6 0.4 0.2\n").unwrap();
    let out = orbcloud(&["eval", td.to_str().unwrap(), "--difference-density", "--points", points.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    let doc = load(&td);
    let wf = doc.wavefunction.as_ref().unwrap();
    let at = [DVec3::ZERO, DVec3::new(1.5, -0.5, 0.3), DVec3::new(-2.6, 0.4, 0.2)];
    let want = PreparedBasis::new(&wf.basis).quantity_at_points(wf, &doc.molecule, Quantity::DifferenceDensity, &at);
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 1e-12 + 1e-9 * w.abs(), "{got:?} vs {want:?}");
    }

    let refused = |args: &[&str], wanted: &[&str]| {
        let out = orbcloud(args);
        let e = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!out.status.success() && wanted.iter().all(|w| e.contains(w)), "{args:?}: {e}");
    };
    let sp = dir.join("basicGaussian09_dvb_sp.fchk");
    let out_cube = tmp.path().join("no.cube");
    refused(
        &["cube", sp.to_str().unwrap(), "--attachment", "-o", out_cube.to_str().unwrap()],
        &["basicGaussian09_dvb_sp.fchk", "--attachment needs an excited state's density"],
    );
    assert!(!out_cube.exists());
    refused(
        &["eval", td.to_str().unwrap(), "--detachment", "--state", "2", "--points", points.to_str().unwrap()],
        &["basicGaussian09_dvb_td.fchk", "--state 2", "state 1 only"],
    );
    let orca = dir.join("basicORCA6.0_dvb_td.out");
    refused(
        &["eval", orca.to_str().unwrap(), "--difference-density", "--points", points.to_str().unwrap()],
        &["basicORCA6.0_dvb_td.out", "needs an excited state's density", "it lists 10 excited states"],
    );
    refused(&["cube", td.to_str().unwrap(), "--attachment", "--density", "-o", "x.cube"], &["cannot be used with"]);
}

/// An independent reading of a Gaussian TD log's printed amplitudes and its fchk twin's
/// orbitals (numpy): each state's NTO weights (σ² of the amplitude matrix's SVD over Σσ²) and its
/// first hole and particle over the basis functions (C_occ U₁, C_virt V₁, each vector's largest
/// MO coefficient positive).
const NTO_SCRIPT: &str = r#"
import json, re, sys
import numpy as np
log, fchk = sys.argv[1], sys.argv[2]
text = open(fchk).read()
def record(name):
    m = re.search(r"^" + re.escape(name) + r"\s+R\s+N=\s+(\d+)\n", text, re.M)
    n = int(m.group(1))
    return np.array(text[m.end():].split()[:n], dtype=float)
nbf = int(re.search(r"^Number of basis functions\s+I\s+(\d+)", text, re.M).group(1))
c = record("Alpha MO coefficients").reshape(-1, nbf)
states, current = [], None
for line in open(log):
    if line.startswith(" Excited State"):
        current = []
        states.append(current)
    elif current is not None:
        m = re.match(r"^\s+(\d+)\s*->\s*(\d+)\s+(-?\d+\.\d+)\s*$", line)
        if m:
            current.append((int(m.group(1)), int(m.group(2)), float(m.group(3))))
        elif not re.match(r"^\s+(\d+)\s*<-\s*(\d+)", line):
            current = None
out = []
for tr in states:
    occ = sorted({t[0] for t in tr}); vir = sorted({t[1] for t in tr})
    t = np.zeros((len(occ), len(vir)))
    for i, a, x in tr:
        t[occ.index(i), vir.index(a)] += x
    u, s, vt = np.linalg.svd(t / np.linalg.norm(t))
    u1, v1 = u[:, 0], vt[0]
    u1 = u1 * np.sign(u1[np.argmax(np.abs(u1))]); v1 = v1 * np.sign(v1[np.argmax(np.abs(v1))])
    hole = sum(w * c[i - 1] for w, i in zip(u1, occ))
    particle = sum(w * c[a - 1] for w, a in zip(v1, vir))
    out.append({"weights": (s**2).tolist(), "hole": hole.tolist(), "particle": particle.tolist()})
print(json.dumps(out))
"#;

/// Natural transition orbitals from a TD log's printed amplitudes over its fchk twin's orbitals
/// (what Multiwfn's hole–electron analysis reads): the weights and the first pair equal an
/// independent SVD of the same printed numbers, the orbitals are normalised, the hole's and the
/// electron's centroids from the dipole integrals are those of a grid, and the document made of
/// them names its orbitals `hole 1`, `particle 1`, … occupied by their weights.
#[test]
fn ntos_from_a_td_logs_amplitudes_equal_an_independent_svd() {
    use orbcloud::model::nto;
    let Some(dir) = logs("excited_states::ntos_from_a_td_logs_amplitudes_equal_an_independent_svd") else { return };
    let (log, fchk) = (dir.join("basicGaussian09_dvb_td.out"), dir.join("basicGaussian09_dvb_td.fchk"));
    let doc = load(&fchk);
    let states = load(&log).excited.expect("the log's states");
    let wf = doc.wavefunction.as_ref().unwrap();
    let out = std::process::Command::new(orbcloud::sources::compute::python())
        .args(["-c", NTO_SCRIPT])
        .arg(&log)
        .arg(&fchk)
        .output()
        .expect("python (scripts/test sets ORBCLOUD_PYTHON)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(reference.len(), states.states.len());
    let overlap = orbcloud::model::overlap::overlap_matrix(&wf.basis);
    let n = wf.basis.n_functions();
    let norm = |c: &[f64]| (0..n).map(|i| (0..n).map(|j| c[i] * overlap[i * n + j] * c[j]).sum::<f64>()).sum::<f64>();
    for (state, expected) in states.states.iter().zip(&reference) {
        let ntos = nto::from_transitions(wf, state).expect("NTOs");
        let weights: Vec<f64> = expected["weights"].as_array().unwrap().iter().map(|w| w.as_f64().unwrap()).collect();
        eprintln!(
            "state {}: printed Σc² {:.5}, weights {:?}",
            state.number,
            ntos.printed_norm,
            ntos.pairs.iter().map(|p| format!("{:.4}", p.weight)).collect::<Vec<_>>()
        );
        for (p, w) in ntos.pairs.iter().zip(&weights) {
            assert!((p.weight - w).abs() < 1e-10, "state {}: {} vs {w}", state.number, p.weight);
        }
        let first = &ntos.pairs[0];
        for (ours, key) in [(&first.hole, "hole"), (&first.particle, "particle")] {
            let theirs: Vec<f64> = expected[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            let worst = ours.iter().zip(&theirs).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-8, "state {} {key}: {worst}", state.number);
            assert!((norm(ours) - 1.0).abs() < 1e-4, "state {} {key} is normalised: {}", state.number, norm(ours));
        }
        // Gaussian prints amplitudes down to 0.01 here: most of each singlet's 0.5.
        assert!(ntos.printed_norm > 0.45 && ntos.printed_norm < 0.55, "{}", ntos.printed_norm);
        // The hole and electron: the centroids from the dipole integrals are the grid's, and
        // each density integrates to the pairs' weight.
        let he = ntos.hole_electron(&wf.basis, &doc.molecule).expect("atoms");
        let total: f64 = ntos.pairs.iter().map(|p| p.weight).sum();
        eprintln!(
            "state {}: D {:.3} bohr (grid {:.3}), Sr {:.3}, ∫ hole {:.4}, ∫ electron {:.4} of {total:.4}",
            state.number,
            he.distance_bohr,
            he.grid.centroid_distance_bohr,
            he.overlap,
            he.grid.detachment_integral,
            he.grid.attachment_integral
        );
        assert!((he.distance_bohr - he.grid.centroid_distance_bohr).abs() < 0.02, "{he:?}");
        for integral in [he.grid.attachment_integral, he.grid.detachment_integral] {
            assert!((integral - total).abs() < 1e-3 * total, "{integral} of {total}");
        }
        assert!(he.overlap > 0.2 && he.overlap < 1.0, "Sr {}", he.overlap);
        let made = ntos.document(&doc).expect("a document");
        let orbitals = &made.wavefunction.as_ref().unwrap().orbitals;
        assert_eq!(orbitals[0].symmetry, "hole 1");
        assert_eq!(orbitals[1].symmetry, "particle 1");
        assert_eq!(orbitals[0].occupation, first.weight);
    }
}

/// `info --transitions LOG` joins a TD log's printed transitions to its checkpoint's states and
/// lists each state's NTO weights and hole–electron distance and overlap; a file without
/// transitions is refused by name.
#[test]
fn info_with_a_logs_transitions_lists_each_states_ntos() {
    let Some(dir) = logs("excited_states::info_with_a_logs_transitions_lists_each_states_ntos") else { return };
    let (log, fchk) = (dir.join("basicGaussian09_dvb_td.out"), dir.join("basicGaussian09_dvb_td.fchk"));
    let out = orbcloud(&["info", "--json", fchk.to_str().unwrap(), "--transitions", log.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let states = info["excited_states"]["states"].as_array().unwrap();
    assert_eq!(states.len(), 5);
    let second = &states[1]["ntos"];
    let weight = second["weights"][0].as_f64().unwrap();
    assert!((weight - 0.9722).abs() < 1e-3, "{second}");
    let distance = second["hole_electron"]["distance_bohr"].as_f64().unwrap();
    let sr = second["hole_electron"]["overlap"].as_f64().unwrap();
    assert!((distance - 0.328).abs() < 0.01 && (sr - 0.927).abs() < 0.01, "{second}");
    assert!(
        info["problems"].as_array().unwrap().is_empty(),
        "the log's own problems stay its own: {}",
        info["problems"]
    );
    let text = orbcloud(&["info", fchk.to_str().unwrap(), "--transitions", log.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("NTO weights 0.972"));
    let sp = dir.join("basicGaussian09_dvb_sp.fchk");
    let bad = orbcloud(&["info", fchk.to_str().unwrap(), "--transitions", sp.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && e.contains("basicGaussian09_dvb_sp.fchk") && e.contains("no excited states"),
        "{e}"
    );
}

/// PySCF's TDA (HF/6-31G*) of water: the SCF as Molden, then per state its energy (eV, by
/// PySCF's constant), oscillator strength and every amplitude X_ia (1-based orbital numbers).
const TDA_SCRIPT: &str = r#"
import json, sys
import numpy as np
from pyscf import gto, scf, tdscf
from pyscf.data import nist
from pyscf.tools import molden
mol = gto.M(atom="O 0 0 0.1173; H 0 0.7572 -0.4692; H 0 -0.7572 -0.4692", basis="6-31g*", verbose=0)
mf = scf.RHF(mol).run(conv_tol=1e-11)
molden.from_scf(mf, sys.argv[1])
td = tdscf.TDA(mf)
td.nstates = 5
td.conv_tol = 1e-10
td.kernel()
nocc = int((mf.mo_occ > 0).sum())
f = td.oscillator_strength(gauge="length")
states = []
for k, (x, _) in enumerate(td.xy):
    amplitudes = [[int(i) + 1, int(nocc + a) + 1, float(x[i, a])] for i in range(x.shape[0]) for a in range(x.shape[1])]
    states.append({"ev": float(td.e[k] * nist.HARTREE2EV), "f": float(f[k]), "x": amplitudes})
print(json.dumps(states))
"#;

#[test]
fn a_tda_states_transition_density_gives_pyscfs_oscillator_strength() {
    use orbcloud::model::excited::{ExcitedState, ExcitedStates, Transition};
    use orbcloud::model::transition::TransitionDensity;
    let dir = tempfile::tempdir().unwrap();
    let molden = dir.path().join("water.molden");
    let out = std::process::Command::new(orbcloud::sources::compute::python())
        .args(["-c", TDA_SCRIPT])
        .arg(&molden)
        .output()
        .expect("python (scripts/test sets ORBCLOUD_PYTHON)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    let mut doc = load(&molden);
    let states = reference
        .iter()
        .enumerate()
        .map(|(k, s)| ExcitedState {
            number: k + 1,
            energy_ev: s["ev"].as_f64().unwrap(),
            spin: "Singlet".into(),
            transitions: (s["x"].as_array().unwrap().iter())
                .map(|t| Transition {
                    from: t[0].as_u64().unwrap() as usize,
                    to: t[1].as_u64().unwrap() as usize,
                    coefficient: t[2].as_f64().unwrap(),
                    spin: String::new(),
                    deexcitation: false,
                })
                .collect(),
            ..ExcitedState::default()
        })
        .collect();
    doc.excited = Some(ExcitedStates { program: "PySCF".into(), method: "TDA".into(), states, ..Default::default() });
    let wf = doc.wavefunction.clone().unwrap();
    let moments = orbcloud::model::overlap::moment_matrices(&wf.basis);
    let prepared = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
    let mut bright = 0;
    for (k, expected) in reference.iter().enumerate() {
        let t = TransitionDensity::of_state(&doc, k + 1).expect("a transition density");
        let (ev, printed) = (expected["ev"].as_f64().unwrap(), expected["f"].as_f64().unwrap());
        let f = t.oscillator_strength(&wf, &moments, ev);
        eprintln!("state {}: f {f:.8} here, {printed:.8} PySCF's", k + 1);
        assert!((f - printed).abs() < 1e-6 * printed.max(1e-3), "state {}: f {f} against PySCF's {printed}", k + 1);
        // The same amplitudes as ORCA's and Q-Chem's logs print them, normalised to 1 (√2 ×
        // PySCF's): the same strength.
        let mut as_logs = doc.clone();
        for state in &mut as_logs.excited.as_mut().unwrap().states {
            state.amplitudes_normalised_to_one = true;
            state.transitions.iter_mut().for_each(|t| t.coefficient *= std::f64::consts::SQRT_2);
        }
        let scaled = TransitionDensity::of_state(&as_logs, k + 1).unwrap().oscillator_strength(&wf, &moments, ev);
        assert!(
            (scaled - printed).abs() < 1e-6 * printed.max(1e-3),
            "state {}: f {scaled} from amplitudes normalised to 1",
            k + 1
        );
        bright += (printed > 0.01) as usize;
        // ∫ ρ₀ₙ = 0 (orthogonal orbitals), and its dipole on a grid is the matrices' one.
        let (lo, hi) = doc.molecule.bounds().unwrap();
        let pad = glam::DVec3::splat(7.0);
        let grid = orbcloud::model::GridSpec::cube(lo - pad, hi + pad, 80);
        let values = t.grid(&wf, &prepared, &grid);
        let dv = grid.step(0).x * grid.step(1).y * grid.step(2).z;
        let [nx, ny, nz] = grid.dims;
        let (mut total, mut mu) = (0.0, glam::DVec3::ZERO);
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let v = f64::from(values[(i * ny + j) * nz + k]) * dv;
                    total += v;
                    mu += v * grid.point(i, j, k);
                }
            }
        }
        let exact = glam::DVec3::from_array(t.dipole(&wf, &moments));
        assert!(total.abs() < 2e-3, "state {}: ∫ρ₀ₙ = {total}", k + 1);
        assert!((mu - exact).length() < 0.01 + 0.02 * exact.length(), "state {}: μ {mu} on the grid, {exact}", k + 1);
        // At points, as on the grid.
        let p = [grid.point(nx / 2, ny / 3, nz / 2)];
        let at = t.at_points(&wf, &prepared, &p)[0];
        let on = f64::from(values[((nx / 2) * ny + ny / 3) * nz + nz / 2]);
        assert!((at - on).abs() < 1e-5 * (1.0 + at.abs()), "state {}: {at} at the point, {on} on the grid", k + 1);
    }
    assert!(bright >= 1, "no bright state among {}", reference.len());
}

#[test]
fn cube_writes_a_states_transition_density_from_a_td_logs_amplitudes_joined_to_its_checkpoint() {
    let Some(dir) = logs("excited_states::cube_writes_a_states_transition_density") else { return };
    let (log, fchk) = (dir.join("basicGaussian09_dvb_td.out"), dir.join("basicGaussian09_dvb_td.fchk"));
    let out_dir = tempfile::tempdir().unwrap();
    let cube = out_dir.path().join("t2.cube");
    let run = |extra: &[&str], output: &Path| {
        let mut args: Vec<String> = vec!["cube".into(), fchk.display().to_string()];
        args.extend(extra.iter().map(ToString::to_string));
        args.extend(["--grid".into(), "40".into(), "-o".into(), output.display().to_string()]);
        std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(&args).output().unwrap()
    };
    let log_arg = log.display().to_string();
    let out = run(&["--transitions", &log_arg, "--transition-density", "--state", "2"], &cube);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let written = load(&cube);
    let grid = &written.volumes[0];
    assert!(grid.label.contains("transition density (state 2)"), "{}", grid.label);
    // Signed, like an orbital, and summing to about nothing (∫ρ₀ₙ = 0).
    let (lo, hi) = (grid.stats.min, grid.stats.max);
    assert!(lo < -1e-3 && hi > 1e-3, "values {lo} … {hi}");
    // Refusals name what is missing: a state not listed; the amplitudes without a log.
    let out = run(&["--transitions", &log_arg, "--transition-density", "--state", "99"], &cube);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("no excited state 99"), "{err}");
    let out = run(&["--transition-density", "--state", "2"], &cube);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("state 2"), "{err}");
}

#[test]
fn eval_gives_a_states_natural_transition_orbitals_by_their_labels() {
    let Some(dir) = logs("excited_states::eval_gives_a_states_natural_transition_orbitals") else { return };
    let (log, fchk) = (dir.join("basicGaussian09_dvb_td.out"), dir.join("basicGaussian09_dvb_td.fchk"));
    let out_dir = tempfile::tempdir().unwrap();
    let points_file = out_dir.path().join("points.txt");
    let points: Vec<glam::DVec3> =
        (0..12).map(|i| glam::DVec3::new(0.7 * i as f64 - 4.0, 1.1 * (0.5 * i as f64).sin(), 0.9)).collect();
    std::fs::write(&points_file, points.iter().map(|p| format!("{} {} {}\n", p.x, p.y, p.z)).collect::<String>())
        .unwrap();
    let (log, fchk, pts) = (log.display().to_string(), fchk.display().to_string(), points_file.display().to_string());
    let eval = |orbital: &str| {
        let out =
            orbcloud(&["eval", &fchk, "--transitions", &log, "--state", "2", "--orbital", orbital, "--points", &pts]);
        assert!(out.status.success(), "{orbital}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        text.lines().map(|l| l.split_whitespace().nth(3).unwrap().parse::<f64>().unwrap()).collect::<Vec<_>>()
    };
    // The same pair made here from the same two files.
    let mut doc = load(Path::new(&fchk));
    doc.join(load(Path::new(&log))).unwrap();
    let state = doc.excited.as_ref().unwrap().states.iter().find(|s| s.number == 2).unwrap().clone();
    let wf = doc.wavefunction.as_ref().unwrap();
    let ntos = orbcloud::model::nto::from_transitions(wf, &state).unwrap();
    let prepared = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
    for (label, coefficients) in [("hole 1", &ntos.pairs[0].hole), ("particle 1", &ntos.pairs[0].particle)] {
        let values = eval(label);
        for (p, v) in points.iter().zip(&values) {
            let expected = prepared.orbital_value(coefficients, *p);
            assert!((v - expected).abs() < 1e-9 * (1.0 + expected.abs()), "{label} at {p}: {v} against {expected}");
        }
    }
    // Refusals name what is missing.
    let out = orbcloud(&["eval", &fchk, "--orbital", "hole 1", "--points", &pts]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--state N"), "{err}");
    let out = orbcloud(&["eval", &fchk, "--state", "2", "--orbital", "hole 1", "--points", &pts]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("prints no transition"), "{err}");
}
