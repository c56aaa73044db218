//! A Gaussian relaxed scan's log (`opt=modredundant` with an `S` line) opens as a scan of
//! geometries: one frame per point with its energy, the coordinate read from the echoed
//! ModRedundant section and measured in each point's geometry, reported by `info` and `info
//! --json`, and computed frame by frame into a scan manifest by `scan compute LOG --frames`.
//!
//! The fixture, tests/fixtures/logs/h2o2_scan.log, is written by
//! scripts/make_scan_log_fixtures.py (PySCF) in the layout of cclib's regression files
//! data/Gaussian/basicGaussian09/dvb_scan_relaxed.log and dvb_scan.log (Gaussian 09 D.01 and
//! A.02), read line by line; nothing is copied from them. An ORCA relaxed surface scan of the
//! same dihedral (tests/fixtures/logs/h2o2_scan_orca.out, the same script, in the layout of
//! cclib's data/ORCA/basicORCA6.0/dvb_scan_relaxed.out) opens the same way.

use std::path::{Path, PathBuf};
use std::process::Command;

use orbcloud::formats;
use orbcloud::model::scan::Coordinate;

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/logs/h2o2_scan.log")
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).env("NODEVICE_SELECT", "1").output().expect("run")
}

/// The energies the fixture prints after `SCF Done:`, in file order.
fn printed_energies(text: &str) -> Vec<f64> {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("SCF Done:"))
        .map(|l| l.split('=').nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn a_relaxed_scan_opens_its_points_with_the_coordinate_it_scanned() {
    let doc = formats::load(&fixture()).unwrap();
    let models = &doc.structure.as_ref().expect("frames").structure.models;
    assert_eq!(models.len(), 5, "one frame per point (two optimisation steps each)");
    // Each point's energy is its converged (second) step's.
    let printed = printed_energies(&std::fs::read_to_string(fixture()).unwrap());
    assert_eq!(printed.len(), 10);
    let energies: Vec<f64> = models.iter().map(|m| m.energy.unwrap()).collect();
    let converged: Vec<f64> = printed.iter().skip(1).step_by(2).copied().collect();
    assert_eq!(energies, converged);

    let job = doc.job_scan.as_ref().expect("the scan's coordinate");
    assert_eq!(job.coordinate, Coordinate::Dihedral([2, 0, 1, 3]), "D 3 1 2 4, 0-based");
    assert_eq!(job.coordinate.label(), "dihedral 3-1-2-4");
    assert!(job.from.starts_with("line 19: D 3 1 2 4 S 4 60.000"), "{}", job.from);
    // 120° in four steps of 60°, run on past 180° as the job stepped them (not −120°, −60°, 0°).
    let expected = [120.0, 180.0, 240.0, 300.0, 360.0];
    assert_eq!(job.values.len(), 5);
    for (v, e) in job.values.iter().zip(expected) {
        assert!((v - e).abs() < 1e-3, "{:?}", job.values);
    }
}

/// `info --json` of a scan job of H₂O₂'s dihedral 3-1-2-4 (atoms reported from 1): its `scan`
/// object and one value per frame.
fn info_json_scan(path: &Path) -> (serde_json::Value, Vec<f64>) {
    let out = orbcloud(&["info", "--json", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let scan = json["scan"].clone();
    assert_eq!(scan["coordinate"], "dihedral 3-1-2-4");
    assert_eq!(scan["kind"], "dihedral");
    assert_eq!(scan["atoms"], serde_json::json!([3, 1, 2, 4]));
    assert_eq!(scan["unit"], "°");
    let values: Vec<f64> = scan["values"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(values.len(), json["structure"]["models"].as_array().unwrap().len());
    (scan, values)
}

#[test]
fn info_reports_the_scan_and_each_frames_value() {
    let path = fixture();
    let (_, values) = info_json_scan(&path);
    assert!((values[4] - 360.0).abs() < 1e-3, "{values:?}");

    let out = orbcloud(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("scan of dihedral 3-1-2-4 (line 19:"), "{text}");
    assert!(text.contains("frame   5: E = ") && text.contains(", 360.0°"), "{text}");
}

/// The fixture with its ModRedundant line replaced, opened.
fn with_line(line: &str) -> orbcloud::model::Document {
    let text = std::fs::read_to_string(fixture()).unwrap();
    let echoed = text.lines().find(|l| l.trim_start().starts_with("D       3")).unwrap();
    let changed = text.replacen(echoed, line, 1);
    formats::load_bytes(Path::new("scan.log"), changed.as_bytes()).unwrap()
}

#[test]
fn a_malformed_or_unsupported_scan_line_leaves_the_coordinate_out_saying_where() {
    for (line, expected) in [
        (" D       3       1       2 S   4 60.000", "4 atom numbers"),
        (" B       1       x S   4 0.1", "2 atom numbers"),
        (" D       3       1       2       4 S   4", "a number of steps and a step size"),
        (" D       3       1       2       4 S   0 60.0", "a number of steps and a step size"),
        (" L       3       1       2 S   4 60.000", "only bonds, angles and dihedrals"),
        (" D       3       1       2       9 S   4 60.000", "atoms among the 4 of the molecule"),
        (" D       3       0       2       4 S   4 60.000", "atoms numbered from 1"),
        (" D       3       1       2       4 S   4 60.000\n B 1 2 S 3 0.1", "one scanned coordinate"),
    ] {
        let doc = with_line(line);
        assert!(doc.job_scan.is_none(), "{line}");
        assert_eq!(doc.structure.as_ref().unwrap().structure.models.len(), 5, "the frames open: {line}");
        let p = doc.problems.iter().find(|p| p.contains("coordinate left out")).unwrap_or_else(|| panic!("{line}"));
        assert!(p.contains("scan.log:19:") || p.contains("scan.log:20:"), "file and line: {p}");
        assert!(p.contains(expected), "{line}: {p}");
    }
    // Lines that scan nothing (a frozen bond) are no scan, and type letters may be left out.
    let doc = with_line(" B       1       2 F\n 3 1 2 4 S 4 60.0");
    assert_eq!(
        doc.job_scan.as_ref().map(|j| j.coordinate),
        Some(Coordinate::Dihedral([2, 0, 1, 3])),
        "{:?}",
        doc.problems
    );
    let doc = with_line(" B       1       2 F");
    assert!(doc.job_scan.is_none() && !doc.problems.iter().any(|p| p.contains("coordinate")), "{:?}", doc.problems);
}

#[test]
fn a_rigid_zmatrix_scan_keeps_its_frames_and_says_its_coordinate_is_not_read() {
    // The layout of cclib's water-pes.g09 (a `Scan` job over two Z-matrix variables), written
    // here: every point is a frame.
    let text = std::fs::read_to_string(fixture()).unwrap();
    let start = text.find(" The following ModRedundant").unwrap();
    let end = start + text[start..].find("\n \n").unwrap() + 3;
    let rigid = format!(
        "{}{}{}",
        &text[..start].replace("opt=modredundant", "scan"),
        " Scan the potential surface.\n Variable   Value     No. Steps Step-Size\n",
        &text[end..].replace(" Optimization completed.\n", "")
    );
    let doc = formats::load_bytes(Path::new("rigid.log"), rigid.as_bytes()).unwrap();
    assert_eq!(doc.structure.as_ref().unwrap().structure.models.len(), 10, "every point a frame");
    assert!(doc.job_scan.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("rigid.log:") && p.contains("Z-matrix")), "{:?}", doc.problems);
}

/// Fails at once, saying what to install, when the computing Python lacks PySCF.
fn require_pyscf() {
    let python = orbcloud::sources::compute::python();
    let ok = Command::new(&python).args(["-c", "import pyscf"]).output().is_ok_and(|o| o.status.success());
    assert!(ok, "`{python}` cannot import pyscf: run scripts/test (it sets ORBCLOUD_PYTHON) or pip install pyscf");
}

#[test]
fn scan_compute_of_the_log_writes_a_manifest_of_its_frames_at_their_values() {
    require_pyscf();
    let dir = tempfile::tempdir().unwrap();
    let log = fixture();
    let out = orbcloud(&[
        "scan",
        "compute",
        log.to_str().unwrap(),
        "--frames",
        "--method",
        "hf",
        "--basis",
        "sto-3g",
        "--workers",
        "2",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let manifest = dir.path().join("h2o2_scan.scan.toml");
    let loaded = formats::scan::load_scan(&manifest).unwrap();
    assert_eq!(loaded.scan.coordinate, Coordinate::Dihedral([2, 0, 1, 3]));
    let values = loaded.scan.values();
    for (v, e) in values.iter().zip([120.0, 180.0, 240.0, 300.0, 360.0]) {
        assert!((v - e).abs() < 1e-3, "{values:?}");
    }
    let computed = loaded.computed.expect("the record");
    assert!(computed.relaxed && computed.input.ends_with("h2o2_scan.log"), "{computed:?}");
    // Each frame is the log's geometry at that point, and its energy the log's (the same level).
    let doc = formats::load(&log).unwrap();
    let printed: Vec<f64> =
        doc.structure.as_ref().unwrap().structure.models.iter().map(|m| m.energy.unwrap()).collect();
    let geometries = orbcloud::sources::compute::frame_molecules(&doc);
    for (k, frame) in loaded.scan.frames.iter().enumerate() {
        let d = frame.molecule.atoms.iter().zip(&geometries[k].atoms).map(|(a, b)| a.position.distance(b.position));
        assert!(d.fold(0.0, f64::max) < 1e-4, "frame {k}'s geometry is the log's");
    }
    let log_text = std::fs::read_to_string(dir.path().join("compute-log.jsonl")).unwrap();
    let energies: Vec<f64> = log_text
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter_map(|v| v["energy"].as_f64())
        .collect();
    assert_eq!(energies.len(), 5, "{log_text}");
    for e in energies {
        assert!(printed.iter().any(|p| (p - e).abs() < 1e-6), "{e} among {printed:?}");
    }
}

#[test]
fn a_relaxed_scan_fchk_opens_its_points_with_their_energies() {
    // Written by scripts/make_scan_log_fixtures.py beside the log: the same job's checkpoint.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scan_jobs/h2o2_relaxed_scan.fchk");
    let doc = formats::load(&path).unwrap();
    assert!(doc.wavefunction.is_none(), "the orbitals are the last point's only");
    let models = &doc.structure.as_ref().expect("frames").structure.models;
    assert_eq!(models.len(), 5, "one frame per `Opt point N` record");
    let log = formats::load(&fixture()).unwrap();
    let log_models = &log.structure.as_ref().unwrap().structure.models;
    for (m, l) in models.iter().zip(log_models) {
        // The fchk's eight significant digits against the log's.
        assert!((m.energy.unwrap() - l.energy.unwrap()).abs() < 1e-5, "{:?} vs {:?}", m.energy, l.energy);
    }
    // Each frame the point's converged (last) step: the log's geometry of that point.
    let frames = orbcloud::sources::compute::frame_molecules(&doc);
    let log_frames = orbcloud::sources::compute::frame_molecules(&log);
    for (a, b) in frames.iter().zip(&log_frames) {
        let d = a.atoms.iter().zip(&b.atoms).map(|(p, q)| p.position.distance(q.position)).fold(0.0, f64::max);
        assert!(d < 1e-5, "{d}");
    }
    assert!(doc.problems.iter().any(|p| p.contains("relaxed scan's 5 points") && p.contains("last point only")));

    // A results record of the wrong length leaves that point's energy out, not the frames.
    let text = std::fs::read_to_string(&path).unwrap();
    let header = "Opt point       2 Results for each geome   R   N=           4";
    let at = text.find(header).unwrap();
    let (row, end) = (at + header.len() + 1, at + header.len() + 1 + text[at + header.len() + 1..].find('\n').unwrap());
    // Three values (16 columns each) where there were four.
    let bad = format!(
        "{}{}\n{}{}",
        &text[..at],
        header.replace("N=           4", "N=           3"),
        &text[row..end - 16],
        &text[end..]
    );
    let doc = formats::load_bytes(Path::new("bad.fchk"), bad.as_bytes()).unwrap();
    let energies: Vec<bool> = doc.structure.unwrap().structure.models.iter().map(|m| m.energy.is_some()).collect();
    assert_eq!(energies, [true, false, true, true, true]);
}

// ORCA's relaxed surface scan (`%geom Scan D 2 0 1 3 = 120, 360, 5 end end`): the fixture,
// tests/fixtures/logs/h2o2_scan_orca.out, is written by scripts/make_scan_log_fixtures.py in the
// layout of cclib's data/ORCA/basicORCA6.0/dvb_scan_relaxed.out (ORCA 6.0.1).

fn orca_fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/logs/h2o2_scan_orca.out")
}

/// The energy printed last before each "*** OPTIMIZATION RUN DONE ***", and the final table's
/// rows (value, energy) under "The Calculated Surface using the 'Actual Energy'".
fn orca_points(text: &str) -> (Vec<f64>, Vec<(f64, f64)>) {
    let mut last = None;
    let mut done = Vec::new();
    for l in text.lines() {
        if let Some(e) = l.strip_prefix("FINAL SINGLE POINT ENERGY") {
            last = Some(e.trim().parse::<f64>().unwrap());
        } else if l.contains("*** OPTIMIZATION RUN DONE ***") {
            done.push(last.take().unwrap());
        }
    }
    let table = text
        .lines()
        .skip_while(|l| !l.starts_with("The Calculated Surface using the 'Actual Energy'"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            (v[0], v[1])
        })
        .collect();
    (done, table)
}

#[test]
fn an_orca_relaxed_scan_opens_its_points_with_the_coordinate_it_scanned() {
    let text = std::fs::read_to_string(orca_fixture()).unwrap();
    let doc = formats::load(&orca_fixture()).unwrap();
    let models = &doc.structure.as_ref().expect("frames").structure.models;
    assert_eq!(models.len(), 5, "one frame per point (two cycles and a final evaluation each)");
    let (done, table) = orca_points(&text);
    assert_eq!(done.len(), 5);
    let energies: Vec<f64> = models.iter().map(|m| m.energy.unwrap()).collect();
    assert_eq!(energies, done, "each point's energy is the one before its OPTIMIZATION RUN DONE");

    let job = doc.job_scan.as_ref().expect("the scan's coordinate");
    assert_eq!(job.coordinate, Coordinate::Dihedral([2, 0, 1, 3]), "D 2 0 1 3: ORCA numbers atoms from 0");
    assert_eq!(job.coordinate.label(), "dihedral 3-1-2-4");
    assert!(job.from.starts_with("line 15: D 2 0 1 3 = 120, 360, 5"), "{}", job.from);
    // Measured in each frame's geometry, run on past 180°: the final table's values, and its
    // energies to its 8 decimals.
    assert_eq!(table.len(), 5);
    for ((v, e), (tv, te)) in job.values.iter().zip(&energies).zip(&table) {
        assert!((v - tv).abs() < 1e-3, "{:?} vs {table:?}", job.values);
        assert!((e - te).abs() < 1e-8, "{e} vs {te}");
    }
}

#[test]
fn info_reports_the_orca_scan_and_each_frames_value() {
    let (scan, values) = info_json_scan(&orca_fixture());
    for (v, e) in values.iter().zip([120.0, 180.0, 240.0, 300.0, 360.0]) {
        assert!((v - e).abs() < 1e-3, "{values:?}");
    }
    assert!(scan["from"].as_str().unwrap().starts_with("line 15:"), "{scan}");
}

/// The ORCA fixture with `old` replaced by `new`, opened as `scan.out`.
fn orca_with(old: &str, new: &str) -> orbcloud::model::Document {
    let text = std::fs::read_to_string(orca_fixture()).unwrap();
    assert!(text.contains(old), "{old}");
    formats::load_bytes(Path::new("scan.out"), text.replacen(old, new, 1).as_bytes()).unwrap()
}

const ORCA_SCAN_LINE: &str = "|  4> D 2 0 1 3 = 120, 360, 5";

#[test]
fn an_unreadable_or_unsupported_orca_scan_block_leaves_the_coordinate_out_saying_where() {
    for (new, at, expected) in [
        ("|  4> D 2 0 1 = 120, 360, 5", 15, "4 atom numbers, then `=`"),
        ("|  4> B 0 x = 1.3, 1.5, 5", 15, "2 atom numbers"),
        ("|  4> D 2 0 1 3 = 120, 360", 15, "a number of points"),
        ("|  4> D 2 0 1 3 = 120, 360, 1", 15, "a number of points"),
        ("|  4> D 2 0 1 3 = [120 180", 15, "two or more values between `[` and `]`"),
        ("|  4> D 2 0 1 3 = [120]", 15, "two or more values"),
        ("|  4> C 2 = 1, 2, 3", 15, "only bonds, angles and dihedrals"),
        ("|  4> D 2 0 1 9 = 120, 360, 5", 15, "atoms among the 4 of the molecule"),
        ("|  4> D 2 0 1 3 = 120, 360, 5\n|  4> B 0 1 = 1.3, 1.5, 5", 16, "one scanned coordinate (line 15"),
        ("|  4> D 2 0 1 3 = 120, 360, 5 *", 15, "`end` closing the `%geom Scan` block"),
        ("|  4> D 2 -1 1 3 = 120, 360, 5", 15, "4 atom numbers"),
    ] {
        let doc = orca_with(ORCA_SCAN_LINE, new);
        assert!(doc.job_scan.is_none(), "{new}");
        assert_eq!(doc.structure.as_ref().unwrap().structure.models.len(), 5, "the frames open: {new}");
        let p = doc.problems.iter().find(|p| p.contains("coordinate left out")).unwrap_or_else(|| panic!("{new}"));
        assert!(p.contains(&format!("scan.out:{at}:")), "file and line: {p}");
        assert!(p.contains(expected), "{new}: {p}");
    }
    // A scan whose input is not echoed: the frames open, the coordinate is missed, saying so.
    let doc = orca_with("|  3> %geom Scan\n", "");
    assert!(doc.job_scan.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("a `%geom Scan … end` block")), "{:?}", doc.problems);
}

#[test]
fn the_orca_scan_block_may_list_its_values_or_stand_on_one_line() {
    let values = |doc: &orbcloud::model::Document| doc.job_scan.as_ref().map(|j| (j.coordinate, j.values.len()));
    let d = Some((Coordinate::Dihedral([2, 0, 1, 3]), 5));
    let doc = orca_with(ORCA_SCAN_LINE, "|  4> d 2 0 1 3 = [120.0 180.0 240.0 300.0 360.0]  # listed");
    assert_eq!(values(&doc), d, "{:?}", doc.problems);
    let doc = orca_with(
        "|  3> %geom Scan\n|  4> D 2 0 1 3 = 120, 360, 5\n|  5> end\n|  6> end\n",
        "|  3> %geom scan D 2 0 1 3 = 120, 360, 5 end end\n",
    );
    assert_eq!(values(&doc), d, "{:?}", doc.problems);
    let from = doc.job_scan.unwrap().from;
    assert!(from.starts_with("line 14: %geom scan D 2 0 1 3 = 120, 360, 5 end end"), "{from}");
    // Another `%geom` setting before the block, a bond scanned.
    let doc = orca_with(
        "|  3> %geom Scan\n|  4> D 2 0 1 3 = 120, 360, 5",
        "|  3> %geom MaxIter 50 Scan\n|  4> B 0 1 = 1.3, 1.5, 5",
    );
    assert_eq!(values(&doc), Some((Coordinate::Distance([0, 1]), 5)), "{:?}", doc.problems);
}

#[test]
fn an_orca_scan_cut_off_or_unconverged_says_so() {
    let text = std::fs::read_to_string(orca_fixture()).unwrap();
    // Cut off in step 4, before its first geometry: three points of five.
    let cut = &text[..text.find("RELAXED SURFACE SCAN STEP   4").unwrap()];
    let doc = formats::load_bytes(Path::new("cut.out"), cut.as_bytes()).unwrap();
    let job = doc.job_scan.as_ref().expect("the coordinate");
    assert_eq!(job.values.len(), 3);
    assert!(job.from.ends_with("(3 of its 5 points)"), "{}", job.from);
    // One point only: no series to measure.
    let cut = &text[..text.find("RELAXED SURFACE SCAN STEP   2").unwrap()];
    let doc = formats::load_bytes(Path::new("cut.out"), cut.as_bytes()).unwrap();
    assert!(doc.job_scan.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("cut.out:15:") && p.contains("at least two")), "{:?}", doc.problems);
    // A step whose optimisation gave up keeps its last geometry, and says so.
    let step2 = text.find("RELAXED SURFACE SCAN STEP   2").unwrap();
    let at = step2 + text[step2..].find("                 *** FINAL ENERGY EVALUATION").unwrap();
    let gave_up = format!(
        "{}The optimization did not converge but reached the maximum number of\noptimization cycles.\n{}",
        &text[..at],
        &text[at..]
    );
    let doc = formats::load_bytes(Path::new("gave_up.out"), gave_up.as_bytes()).unwrap();
    assert_eq!(doc.job_scan.as_ref().unwrap().values.len(), 5);
    assert!(doc.problems.iter().any(|p| p.contains("step 2 did not converge")), "{:?}", doc.problems);
}

#[test]
fn an_orca_dihedral_scan_reads_from_the_value_it_asked_for() {
    // The same geometries asked for a whole turn lower or higher: the measured values follow.
    for (line, first) in [("|  4> D 2 0 1 3 = -240, 0, 5", -240.0), ("|  4> D 2 0 1 3 = [480 540 600 660 720]", 480.0)]
    {
        let doc = orca_with(ORCA_SCAN_LINE, line);
        let values = &doc.job_scan.as_ref().unwrap().values;
        for (k, v) in values.iter().enumerate() {
            assert!((v - (first + 60.0 * k as f64)).abs() < 1e-3, "{line}: {values:?}");
        }
    }
    // A bond is as measured whatever the input says.
    let doc = orca_with("|  4> D 2 0 1 3 = 120, 360, 5", "|  4> B 0 1 = 9.0, 9.5, 5");
    let values = &doc.job_scan.as_ref().unwrap().values;
    assert!(values.iter().all(|v| (1.3..1.5).contains(v)), "{values:?}");
}
