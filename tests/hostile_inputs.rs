//! Hostile and broken inputs: every one is refused with a typed error naming the file and line,
//! quickly, and with memory bounded by what the file's header honestly implies. The hostile
//! files (decompression bombs among them) are made here.

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use orbcloud::formats::{self, LoadError, MAX_LINE_BYTES, MAX_TRAILING_BYTES, ParseError};

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");
/// AIM `.wfn`/`.wfx` and ORCA `.mkl` fixtures.
const AIM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wfn_wfx_mkl");
const LOG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs/h2_sto3g.log");
const ORCA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs/h2_orca.out");
const LOGS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs");
const SCAN_FCHK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/scan_jobs/h2o2_relaxed_scan.fchk");
/// H₂ as GAMESS-US, NWChem, Psi4 and Q-Chem print it, with the basis and the orbitals.
const NEW_LOGS: [&str; 4] = ["h2_gamess.out", "h2_nwchem.out", "h2_psi4.out", "h2_qchem.out"];

/// A 2×2×3 bohr grid with one oxygen atom (line 7) and its 12 values (lines 8–9).
fn cube(atom: &str, axes: [&str; 3], origin: &str) -> String {
    format!(
        "title\ndensity\n    1   {origin}\n    2   {}\n    2   {}\n    3   {}\n{atom}\n{TWELVE}",
        axes[0], axes[1], axes[2]
    )
}

const AXES: [&str; 3] = ["0.5 0.0 0.0", "0.0 0.4 0.0", "0.0 0.0 0.3"];
const ORIGIN: &str = "-1.0 0.5 2.0";
const OXYGEN: &str = "    8   8.0   0.0 0.0 0.1";
const TWELVE: &str =
    "  1.0E-01  2.0E-01  3.0E-01  4.0E-01  5.0E-01  6.0E-01\n  7.0E-01  8.0E-01  9.0E-01  1.0E+00  1.1E+00  1.2E+00\n";

fn parse_error(e: LoadError) -> ParseError {
    match e {
        LoadError::Parse(p) => p,
        other => panic!("expected a parse error, got {other}"),
    }
}

/// Loads `bytes` as a file named `name` and returns the parse error, checking it came fast.
fn refused(name: &str, bytes: &[u8]) -> ParseError {
    let t = Instant::now();
    let e = match formats::load_bytes(Path::new(name), bytes) {
        Ok(_) => panic!("{name}: a hostile file was accepted"),
        Err(e) => parse_error(e),
    };
    assert!(t.elapsed() < Duration::from_secs(5), "{name}: refused only after {:?}", t.elapsed());
    assert_eq!(e.file, name);
    e
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(data).unwrap();
    gz.finish().unwrap()
}

/// A gzip file that starts with `head` and then inflates to `gib` GiB of `filler` repeated:
/// one compressed 16 MiB member, concatenated (gzip allows members back to back).
fn bomb(head: &str, filler: &[u8], gib: usize) -> Vec<u8> {
    let block: Vec<u8> = filler.iter().copied().cycle().take(16 << 20).collect();
    let member = gzip(&block);
    let mut out = gzip(head.as_bytes());
    for _ in 0..gib * 64 {
        out.extend_from_slice(&member);
    }
    out
}

#[test]
fn a_plain_cube_loads() {
    let d = formats::load_bytes(Path::new("ok.cube"), cube(OXYGEN, AXES, ORIGIN).as_bytes()).unwrap();
    assert_eq!(d.volumes[0].values.len(), 12);
    // Z = 118 and a ghost (Z = 0) are atoms.
    for z in ["118", "0"] {
        let atom = OXYGEN.replacen("8   8.0", &format!("{z}   8.0"), 1);
        formats::load_bytes(Path::new("ok.cube"), cube(&atom, AXES, ORIGIN).as_bytes()).unwrap();
    }
}

#[test]
fn impossible_atomic_numbers_are_refused() {
    for z in ["999", "119", "-1", "-8", "4294967304"] {
        let atom = OXYGEN.replacen("8   8.0", &format!("{z}   8.0"), 1);
        let e = refused("z.cube", cube(&atom, AXES, ORIGIN).as_bytes());
        assert_eq!(e.line, 7, "{z}: {e}");
        assert!(e.expected.contains("0..=118"), "{z}: {e}");
        assert_eq!(e.found, z);
    }
    let molden = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.molden")).unwrap();
    for z in ["999", "119", "-1"] {
        let bad = molden.replacen("O   1   8 ", &format!("O   1   {z} "), 1);
        let e = refused("z.molden", bad.as_bytes());
        assert_eq!(e.line, 4, "{z}: {e}");
        assert!(e.expected.contains("0..=118"), "{z}: {e}");
    }
    let fchk = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.fchk")).unwrap();
    let bad = fchk.replacen("           8           1           1", "         999           1           1", 1);
    assert_ne!(bad, fchk);
    let e = refused("z.fchk", bad.as_bytes());
    assert!(e.expected.contains("0..=118"), "{e}");
    assert_eq!(e.found, "999");
}

#[test]
fn singular_and_non_finite_grids_are_refused() {
    let singular = [
        ["0 0 0", "0 0 0", "0 0 0"],
        ["0.5 0 0", "0 0 0", "0 0 0.3"],
        ["0.5 0 0", "1.0 0 0", "0 0 0.3"],
        ["0.5 0 0", "0 0.4 0", "0.5 0.4 0"],
        ["0.5 0 0", "0 0.4 0", "0.5 0.4 1e-9"],
        ["1e200 0 0", "0 1e200 0", "0 0 1e200"],
    ];
    for axes in singular {
        let e = refused("singular.cube", cube(OXYGEN, axes, ORIGIN).as_bytes());
        assert_eq!(e.line, 6, "{axes:?}: {e}");
        assert!(e.expected.contains("linearly independent"), "{axes:?}: {e}");
    }
    // Sheared but not singular.
    let sheared = ["0.5 0.1 0", "0.2 0.4 0", "0 0.1 0.3"];
    formats::load_bytes(Path::new("ok.cube"), cube(OXYGEN, sheared, ORIGIN).as_bytes()).unwrap();

    for bad in ["NaN", "inf", "-Infinity", "1e999"] {
        let e = refused("axis.cube", cube(OXYGEN, ["0.5 0 0", &format!("0 {bad} 0"), "0 0 0.3"], ORIGIN).as_bytes());
        assert_eq!(e.line, 5, "{bad}: {e}");
        let e = refused("origin.cube", cube(OXYGEN, AXES, &format!("-1.0 {bad} 2.0")).as_bytes());
        assert_eq!(e.line, 3, "{bad}: {e}");
        let e = refused("atom.cube", cube(&format!("    8   8.0   0.0 {bad} 0.1"), AXES, ORIGIN).as_bytes());
        assert_eq!(e.line, 7, "{bad}: {e}");
        let e = refused("charge.cube", cube(&format!("    8   {bad}   0.0 0.0 0.1"), AXES, ORIGIN).as_bytes());
        assert_eq!(e.line, 7, "{bad}: {e}");
    }
}

#[test]
fn data_beyond_the_declared_values_are_refused() {
    let text = cube(OXYGEN, AXES, ORIGIN);
    for (name, bytes) in [
        ("more.cube", format!("{text} 1.3E+00\n").into_bytes()),
        ("more.cube.gz", gzip(format!("{text}0.0\n").as_bytes())),
    ] {
        let e = refused(name, &bytes);
        assert_eq!(e.line, 10, "{e}");
        assert!(e.found.contains("value 13"), "{e}");
    }
    // Trailing blank lines are fine.
    formats::load_bytes(Path::new("ok.cube.gz"), &gzip(format!("{text}\n\n   \n").as_bytes())).unwrap();
}

#[test]
fn gzip_bombs_are_refused_once_the_declared_values_are_read() {
    let head = cube(OXYGEN, AXES, ORIGIN);
    // 4 GiB of further values: refused at the first one.
    let e = refused("values.cube.gz", &bomb(&head, b"0.0 ", 4));
    assert_eq!(e.line, 10, "{e}");
    assert!(e.found.contains("value 13"), "{e}");
    // 4 GiB of blank space: refused after a bounded amount of it.
    let e = refused("blank.cube.gz", &bomb(&head, b"  \n", 4));
    assert!(e.found.contains(&format!("more than {MAX_TRAILING_BYTES} bytes")), "{e}");
    // 4 GiB of NUL bytes, and of one endless line, after a valid header.
    let e = refused("nul.cube.gz", &bomb(&head, b"\0", 4));
    assert!(e.found.contains("control byte 0x00"), "{e}");
    assert_eq!(e.line, 10);
    // Endless digits are one more value; an endless comment line is refused at its length.
    let e = refused("digits.cube.gz", &bomb(&head, b"1", 4));
    assert!(e.found.contains("more than the 12 values"), "{e}");
    let e = refused("line.cube.gz", &bomb("title ", b"x", 4));
    assert!(e.expected.contains(&format!("at most {MAX_LINE_BYTES} bytes")), "{e}");
    assert_eq!(e.line, 1);
    // A header that declares a grid too large for any GPU: refused without reading the data.
    let big =
        head.replacen("    2   0.5", "    100000   0.5", 1).replacen("    2   0.0 0.4", "    100000   0.0 0.4", 1);
    let e = refused("big.cube.gz", &bomb(&big, b"0.0 ", 4));
    assert_eq!(e.line, 6, "{e}");
    assert!(e.expected.contains("at most"), "{e}");
}

#[test]
fn wavefunction_gzip_bombs_are_refused() {
    let molden = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.molden")).unwrap();
    let fchk = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.fchk")).unwrap();
    let wfn = std::fs::read_to_string(format!("{AIM}/oh_rohf.wfn")).unwrap();
    let wfx = std::fs::read_to_string(format!("{AIM}/oh_rohf.wfx")).unwrap();
    let mkl = std::fs::read_to_string(format!("{AIM}/oh_rohf.mkl")).unwrap();
    for (name, head) in [
        ("bomb.molden.gz", &molden),
        ("bomb.fchk.gz", &fchk),
        ("bomb.wfn.gz", &wfn),
        ("bomb.wfx.gz", &wfx),
        ("bomb.mkl.gz", &mkl),
    ] {
        let e = refused(name, &bomb(head, b"\n", 4));
        assert!(e.found.contains("decompression bomb"), "{name}: {e}");
    }
}

#[test]
fn absurd_counts_are_refused() {
    let e = refused(
        "atoms.cube",
        cube(OXYGEN, AXES, ORIGIN).replacen("    1   -1.0", "    99999999999   -1.0", 1).as_bytes(),
    );
    assert_eq!(e.line, 3, "{e}");
    let molden = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.molden")).unwrap();
    let e = refused("nprim.molden", molden.replacen(" s    6 1.00", " s    999999999999 1.00", 1).as_bytes());
    assert_eq!(e.line, 9, "{e}");
    assert!(e.expected.contains("primitive count"), "{e}");
    let at = molden.find("[MO]").unwrap();
    let line = 1 + molden[..at].matches('\n').count();
    let index = at + molden[at..].find("\n   1 ").unwrap() + 1;
    let bad = format!("{}99999999999999{}", &molden[..index], &molden[index + 4..]);
    let e = refused("index.molden", bad.as_bytes());
    assert!(e.line > line, "{e}");
    assert!(e.expected.contains("coefficient indices"), "{e}");
    let fchk = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.fchk")).unwrap();
    let bad = regex_free_replace(&fchk, "Shell types", "N=", "N=  999999999999");
    let e = refused("count.fchk", bad.as_bytes());
    assert!(e.expected.contains("array length"), "{e}");
}

/// AIM `.wfn`/`.wfx` and ORCA `.mkl` files: counts that would allocate, type codes past AIMAll's
/// table, truncated blocks and fields that are not numbers are refused at their line, fast.
#[test]
fn aim_and_mkl_files_refuse_hostile_contents() {
    let line_of = |text: &str, needle: &str| 1 + text[..text.find(needle).unwrap()].matches('\n').count();
    let wfn = std::fs::read_to_string(format!("{AIM}/oh_rohf.wfn")).unwrap();
    let header = wfn.lines().nth(1).unwrap().to_string();
    // Header counts of 10^12 primitives or orbitals, or of nuclei: refused on the header line
    // before anything is sized by them.
    for (what, count) in [("MOL ORBITALS", "999999999999"), ("PRIMITIVES", "999999999999"), ("NUCLEI", "99999999")] {
        let at = header.find(what).unwrap();
        let start = header[..at].trim_end().rfind(' ').unwrap() + 1;
        let bad_header = format!("{}{count} {}", &header[..start], &header[at..]);
        let e = refused("count.wfn", wfn.replacen(&header, &bad_header, 1).as_bytes());
        assert_eq!(e.line, 2, "{what}: {e}");
        assert!(e.expected.contains("can hold"), "{what}: {e}");
    }
    let types = line_of(&wfn, "TYPE ASSIGNMENTS");
    let e = refused("type.wfn", wfn.replacen("TYPE ASSIGNMENTS      1", "TYPE ASSIGNMENTS     57", 1).as_bytes());
    assert_eq!((e.line, e.found.as_str()), (types, "57"), "{e}");
    assert!(e.expected.contains("1..=56"), "{e}");
    let exponents = line_of(&wfn, "EXPONENTS");
    let e = refused("exp.wfn", wfn.replacen("EXPONENTS  0.", "EXPONENTS  x.", 1).as_bytes());
    assert_eq!(e.line, exponents, "{e}");
    // Cut inside the second orbital's coefficients.
    let mo2 = wfn.find("MO    2").unwrap();
    let cut = &wfn[..mo2 + wfn[mo2..].find('\n').unwrap() + 200];
    let cut = &cut[..cut.rfind('\n').unwrap() + 1];
    let e = refused("cut.wfn", cut.as_bytes());
    assert!(e.expected.contains("coefficients of orbital 2"), "{e}");
    assert_eq!(e.line, cut.lines().count(), "{e}");

    let wfx = std::fs::read_to_string(format!("{AIM}/oh_rohf.wfx")).unwrap();
    let e = refused(
        "count.wfx",
        wfx.replacen("<Number of Primitives>\n ", "<Number of Primitives>\n 99999999999", 1).as_bytes(),
    );
    assert!(e.expected.contains("99999999999") && e.expected.contains("values in <Primitive Centers>"), "{e}");
    let types = line_of(&wfx, "<Primitive Types>") + 1;
    let e = refused(
        "type.wfx",
        wfx.replacen("<Primitive Types>\n                   1", "<Primitive Types>\n                  99", 1)
            .as_bytes(),
    );
    assert_eq!((e.line, e.found.as_str()), (types, "\"99\""), "{e}");
    let cut = &wfx[..wfx.find("</Molecular Orbital Primitive Coefficients>").unwrap()];
    let e = refused("cut.wfx", cut.as_bytes());
    assert!(e.expected.contains("closing tag </Molecular Orbital Primitive Coefficients>"), "{e}");
    let energies = line_of(&wfx, "<Molecular Orbital Energies>") + 1;
    let e = refused(
        "nan.wfx",
        wfx.replacen("<Molecular Orbital Energies>\n ", "<Molecular Orbital Energies>\n NaN", 1).as_bytes(),
    );
    assert_eq!(e.line, energies, "{e}");

    let mkl = std::fs::read_to_string(format!("{AIM}/oh_rohf.mkl")).unwrap();
    let e = refused("shell.mkl", mkl.replacen(" 5 D 1.0", " 5000 D 1.0", 1).as_bytes());
    assert_eq!(e.line, line_of(&mkl, " 5 D 1.0"), "{e}");
    let e = refused("g.mkl", mkl.replacen(" 9 G 1.0", " 9 K 1.0", 1).as_bytes());
    assert_eq!(e.line, line_of(&mkl, " 9 G 1.0"), "{e}");
    let end = mkl.find(" $END\n\n$OCC_ALPHA").unwrap();
    let short = format!("{}{}", &mkl[..mkl[..end - 1].rfind('\n').unwrap() + 1], &mkl[end..]);
    let e = refused("short.mkl", short.as_bytes());
    assert!(e.expected.contains("coefficient rows"), "{e}");
    let e = refused("text.mkl", mkl.replacen(" a1g", " a1g\n  low", 1).as_bytes());
    assert!(e.expected.contains("energies"), "{e}");
}

/// Replaces the first `key…` field on the line of `label` by `with` (the rest of the line goes).
fn regex_free_replace(text: &str, label: &str, key: &str, with: &str) -> String {
    let at = text.find(label).unwrap();
    let k = at + text[at..].find(key).unwrap();
    let end = k + text[k..].find('\n').unwrap();
    format!("{}{with}{}", &text[..k], &text[end..])
}

#[test]
fn empty_binary_and_endless_files_are_refused_in_every_format() {
    // Deterministic pseudo-random bytes (a linear congruential generator).
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let garbage: Vec<u8> = (0..1 << 16)
        .map(|_| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 56) as u8
        })
        .collect();
    let long_line = vec![b'7'; 3 * MAX_LINE_BYTES];
    for ext in [
        "cube",
        "molden",
        "fchk",
        "wfn",
        "wfx",
        "mkl",
        "log",
        "cube.gz",
        "molden.gz",
        "fchk.gz",
        "wfn.gz",
        "wfx.gz",
        "mkl.gz",
        "out.gz",
    ] {
        let name = format!("hostile.{ext}");
        let e = refused(&name, b"");
        assert!(e.found.contains("empty file"), "{name}: {e}");
        let e = refused(&name, b" \n\n\t\n");
        assert!(e.found.contains("empty file") || e.found.contains("end of file"), "{name}: {e}");
        // Binary garbage, plain and gzipped, never reaches a parser.
        for bytes in [garbage.clone(), gzip(&garbage)] {
            match formats::load_bytes(Path::new(&name), &bytes) {
                Ok(_) => panic!("{name}: garbage accepted"),
                Err(LoadError::Parse(e)) => assert!(e.found.contains("control byte"), "{name}: {e}"),
                Err(LoadError::NotText { .. }) => {}
                Err(e) => panic!("{name}: {e}"),
            }
        }
        let e = refused(&name, &long_line);
        assert!(e.expected.contains(&format!("at most {MAX_LINE_BYTES} bytes")), "{name}: {e}");
        assert_eq!(e.line, 1);
    }
}

#[test]
fn truncated_files_never_panic() {
    let cube = cube(OXYGEN, AXES, ORIGIN);
    let molden = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.molden")).unwrap();
    let fchk = std::fs::read_to_string(format!("{FIXTURES}/h2o_cart_631gs.fchk")).unwrap();
    let aim = |name: &str| std::fs::read_to_string(format!("{AIM}/{name}")).unwrap();
    let (wfn, wfx, mkl) = (aim("oh_rohf.wfn"), aim("oh_rohf.wfx"), aim("oh_rohf.mkl"));
    let json_dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/json");
    let orca_json = std::fs::read_to_string(format!("{json_dir}/h2o_cation.orca.json")).unwrap();
    let qcschema = std::fs::read_to_string(format!("{json_dir}/h2o_cart.qcschema.json")).unwrap();
    let log = std::fs::read_to_string(LOG).unwrap();
    let orca = std::fs::read_to_string(ORCA).unwrap();
    let [gamess, nwchem, psi4, qchem] = NEW_LOGS.map(|name| std::fs::read_to_string(format!("{LOGS}/{name}")).unwrap());
    let orca_freq = std::fs::read_to_string(format!("{LOGS}/h2o_orca_freq.out")).unwrap();
    let [gamess_freq, nwchem_freq, psi4_freq, qchem_freq] = ["gamess", "nwchem", "psi4", "qchem"]
        .map(|p| std::fs::read_to_string(format!("{LOGS}/h2o_{p}_freq.out")).unwrap());
    let scan_log = std::fs::read_to_string(format!("{LOGS}/h2o2_scan.log")).unwrap();
    let scan_fchk = std::fs::read_to_string(SCAN_FCHK).unwrap();
    for (name, text) in [
        ("t.log", &scan_log),
        ("t.fchk", &scan_fchk),
        ("t.out", &orca),
        ("t.out", &orca_freq),
        ("t.out", &gamess_freq),
        ("t.out", &nwchem_freq),
        ("t.out", &psi4_freq),
        ("t.out", &qchem_freq),
        ("t.out", &gamess),
        ("t.out", &nwchem),
        ("t.out", &psi4),
        ("t.out", &qchem),
        ("t.cube", &cube),
        ("t.molden", &molden),
        ("t.fchk", &fchk),
        ("t.wfn", &wfn),
        ("t.wfx", &wfx),
        ("t.mkl", &mkl),
        ("t.json", &orca_json),
        ("t.json", &qcschema),
        ("t.log", &log),
    ] {
        let step = (text.len() / 97).max(1);
        for cut in (0..text.len()).step_by(step) {
            if let Ok(cut_text) = std::str::from_utf8(&text.as_bytes()[..cut]) {
                let _ = formats::load_bytes(Path::new(name), cut_text.as_bytes());
            }
        }
    }
}

/// A Molden file cut inside `[MO]` (PySCF's layout: every coefficient written) is refused at
/// its last line, saying how many coefficients or orbitals were expected; before, a partial
/// orbital opened as if whole (benzene cut at 30 kB: 52 of its 96 coefficients).
#[test]
fn molden_files_cut_inside_their_orbitals_are_refused() {
    let benzene = std::fs::read_to_string(format!("{FIXTURES}/benzene_631gs.molden")).unwrap();
    let whole = formats::load_bytes(Path::new("whole.molden"), benzene.as_bytes()).expect("the whole file opens");
    let n = whole.wavefunction.as_ref().unwrap().basis.n_functions();
    let mo = benzene.find("[MO]").unwrap();
    // Mid-line, at 30 kB, and at the end of the line before it.
    let mid_line = &benzene[..30_000];
    let at_line_end = &mid_line[..mid_line.rfind('\n').unwrap() + 1];
    assert!(mo < at_line_end.len() && !at_line_end.trim_end().ends_with("Occup=    2.00000"));
    for cut in [mid_line, at_line_end] {
        let e = refused("cut.molden", cut.as_bytes());
        assert_eq!(e.line, cut.lines().count(), "{e}");
        assert!(e.expected.contains(&format!("{n} coefficients")), "{e}");
        assert!(e.found.contains("cut short"), "{e}");
    }
    // Cut inside the next orbital's header: an orbital with no coefficients.
    let header = &benzene[..benzene[mo..].find(" Ene=").map(|k| mo + k).unwrap()];
    let header = &benzene[..benzene[header.len() + 1..].find(" Ene=").unwrap() + header.len() + 1];
    let e = refused("cut.molden", header.as_bytes());
    assert!(e.expected.contains("coefficient lines"), "{e}");
    // An unrestricted file cut between two of its beta orbitals.
    let uhf = std::fs::read_to_string(format!("{FIXTURES}/h2o_cation_uhf_631gs.molden")).unwrap();
    let second_beta = uhf
        .match_indices(" Sym=")
        .map(|(k, _)| k)
        .filter(|&k| uhf[k..].lines().nth(2).unwrap().contains("Beta"))
        .nth(1)
        .unwrap();
    let e = refused("cut.molden", &uhf.as_bytes()[..second_beta]);
    assert!(e.expected.contains("Beta orbitals, as many as the Alpha ones") && e.found.starts_with("1,"), "{e}");
    // Whole files with trailing blank lines still open, every orbital in them.
    for (name, text) in [("benzene.molden", &benzene), ("uhf.molden", &uhf)] {
        let padded = format!("{text}\n\n   \n\n");
        let doc = formats::load_bytes(Path::new(name), padded.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
        let whole = formats::load_bytes(Path::new(name), text.as_bytes()).unwrap();
        assert_eq!(doc.wavefunction.unwrap().orbitals.len(), whole.wavefunction.unwrap().orbitals.len());
    }
}

/// `orbcloud info` on a 4 GiB gzip bomb (a valid header, then blank space, the case read
/// furthest): refused with a message, within 5 s and 200 MB of resident memory.
#[test]
fn info_on_a_gzip_bomb_stays_small_and_fast() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bomb.cube.gz");
    std::fs::write(&path, bomb(&cube(OXYGEN, AXES, ORIGIN), b"  \n", 4)).unwrap();
    let exe = env!("CARGO_BIN_EXE_orbcloud");
    let (status, stderr, rss_kb, wall) = if Path::new("/usr/bin/time").exists() {
        let t = Instant::now();
        let out = std::process::Command::new("/usr/bin/time")
            .arg("-v")
            .args([exe, "info"])
            .arg(&path)
            .output()
            .expect("run /usr/bin/time");
        let wall = t.elapsed();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let rss = stderr
            .lines()
            .find_map(|l| l.trim().strip_prefix("Maximum resident set size (kbytes):"))
            .and_then(|v| v.trim().parse::<u64>().ok())
            .unwrap_or_else(|| panic!("no maximum RSS in /usr/bin/time's output:\n{stderr}"));
        (out.status, stderr, rss, wall)
    } else {
        // Without GNU time: poll the child's high-water mark of resident memory.
        let t = Instant::now();
        let mut child = std::process::Command::new(exe)
            .arg("info")
            .arg(&path)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut rss = 0;
        let status = loop {
            if let Ok(s) = std::fs::read_to_string(format!("/proc/{}/status", child.id())) {
                let hwm = s
                    .lines()
                    .find_map(|l| l.strip_prefix("VmHWM:"))
                    .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok());
                rss = rss.max(hwm.unwrap_or(0));
            }
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        let mut stderr = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
        (status, stderr, rss, t.elapsed())
    };
    println!("orbcloud info on a 4 GiB gzip bomb: {wall:.2?}, max RSS {} MB", rss_kb / 1024);
    assert!(!status.success(), "the bomb was accepted:\n{stderr}");
    assert!(stderr.contains("bomb.cube.gz") && stderr.contains("more than"), "{stderr}");
    assert!(rss_kb < 200 * 1024, "max RSS {rss_kb} kB");
    assert!(wall < Duration::from_secs(5), "took {wall:?}");
}

/// Fuzzing findings (scripts/fuzz.sh), each kept as the input that found it.
#[test]
fn fuzzing_findings_stay_fixed() {
    // AFL++, cube target: an atom 4e20 bohr away put its bond-search cell at the i64 limit, and
    // the neighbouring cell's index overflowed (a panic in a build with overflow checks).
    let far_atom = "h2\n MO 1 and 2, angstrom\n   -2   -0.5 -0.5 -0.5\n   -2    0.5 0.0 0.0\n   -2    0.0 0.5 0.0\n   -2    0.0 0.0 0.5\n    1    1.0 0.0 0.0 0444444444444444444444.37\n    1    1.0 0.0 0.0 -0.37\n    2    1    2\n 1.0E-02 -2.0E-02 3.0E-02 -4.0E-02 5.0E-02 -6.0E-02\n 7.0E-02 -8.0E-02 9.0E-02 -1.0E-01 1.1E-01 -1.2E-01\n 1.3E-01 -1.4E-01 1.5E-01 -1.6E-01\n";
    let doc = formats::load_bytes(Path::new("far.cube"), far_atom.as_bytes());
    assert!(doc.is_ok_and(|d| d.molecule.bonds.is_empty()), "read, no bond to an atom that far");
    // AFL++, mmCIF target: a token of multi-byte characters was cut at byte 5 to look for
    // `data_` (a panic inside a character); and the same inside an atom_site loop.
    for (name, text) in [
        ("nbsp.cif", "\u{a0}\u{a0}\u{a0}".to_string()),
        ("loop.cif", "data_x\nloop_\n_atom_site.id\n_atom_site.Cartn_x\n02\u{7f0}\u{7f7}V0 1.0\n".to_string()),
    ] {
        let err = formats::load_bytes(Path::new(name), text.as_bytes()).expect_err("no atoms to show");
        assert!(err.to_string().contains(name), "{err}");
    }
}

/// A Gaussian log whose counts lie: a shell of 10¹¹ primitives, an orbital block whose rows stop,
/// an orientation without its closing dashes. Each is refused at its line, nothing is allocated
/// from a count, and a log of another program is refused naming what was looked for.
#[test]
fn gaussian_logs_with_lying_counts_are_refused_at_their_line() {
    let log = std::fs::read_to_string(LOG).unwrap();
    assert!(formats::load_bytes(Path::new("h2.log"), log.as_bytes()).is_ok());
    let line_of = |text: &str, needle: &str| text.lines().position(|l| l.contains(needle)).unwrap() + 1;

    let bad = log.replacen(" S   3 1.00", " S   99999999999 1.00", 1);
    let start = Instant::now();
    let e = refused("count.log", bad.as_bytes());
    assert!(start.elapsed() < Duration::from_secs(10));
    assert!(e.expected.contains("primitive"), "{e}");

    let bad = log.replacen("   2 2   H  1S          0.54884  -1.21245\n", "", 1);
    let e = refused("rows.log", bad.as_bytes());
    assert_eq!(e.line, line_of(&bad, "Molecular Orbital Coefficients:"), "{e}");
    assert!(e.expected.contains("2 rows of coefficients (the basis set's functions)"), "{e}");

    let cut = &log[..log.find(" Standard basis").unwrap()];
    let bad = cut.trim_end().rsplit_once('\n').unwrap().0.to_string() + "\n";
    let e = refused("cut.log", bad.as_bytes());
    assert!(e.expected.contains("dashes that close the orientation table"), "{e}");

    let e = refused("molpro.out", b" PROGRAM SYSTEM MOLPRO\n Molpro calculation of H2\n");
    assert!(e.expected.contains("Entering Gaussian System") && e.expected.contains("GAMESS VERSION"), "{e}");
    assert_eq!(e.line, 1);
    // A GAMESS banner and nothing else: refused for want of its geometry.
    let e = refused("gamess.out", b" GAMESS VERSION = 30 SEP 2017 (R1)\n EXECUTION OF GAMESS BEGUN\n");
    assert!(e.expected.contains("COORDINATES (BOHR)"), "{e}");
}

/// A relaxed scan's ModRedundant line whose numbers lie (atoms and steps past any count, a step
/// that is no number) leaves the coordinate out saying where, the frames open; a scan fchk whose
/// results claim more values than it holds is refused at its line.
#[test]
fn scan_jobs_with_lying_numbers_open_their_frames_or_are_refused() {
    let log = std::fs::read_to_string(format!("{LOGS}/h2o2_scan.log")).unwrap();
    let line = log.lines().find(|l| l.trim_start().starts_with("D       3")).unwrap();
    for lie in [
        " D 99999999999999999999999 1 2 4 S 4 60.0",
        " D 3 1 2 18446744073709551615 S 4 60.0",
        " D 3 1 2 4 S 99999999999999999999 60.0",
        " D 3 1 2 4 S 4 nan",
        " D 3 1 2 4 S 4 1e999",
        " D 3 1 2 4 S -4 60.0",
        " * * * * S 4 60.0",
        " D 3 1 2 4 S 4 60.0\n D 3 1 2 4 S 4 60.0",
    ] {
        let bad = log.replacen(line, lie, 1);
        let doc = formats::load_bytes(Path::new("lie.log"), bad.as_bytes()).unwrap_or_else(|e| panic!("{lie}: {e}"));
        assert!(doc.job_scan.is_none(), "{lie}");
        assert_eq!(doc.structure.as_ref().unwrap().structure.models.len(), 5, "{lie}");
        let left_out = doc.problems.iter().any(|p| p.contains("coordinate left out") && p.contains("lie.log:"));
        assert!(left_out, "{lie}: {:?}", doc.problems);
    }
    // A line that names no coordinate ends the section: no scan, nothing to say.
    let doc = formats::load_bytes(Path::new("lie.log"), log.replacen(line, " S S S S S S", 1).as_bytes()).unwrap();
    assert!(doc.job_scan.is_none() && !doc.problems.iter().any(|p| p.contains("coordinate")));
    let fchk = std::fs::read_to_string(SCAN_FCHK).unwrap();
    let header = "Opt point       3 Results for each geome   R   N=           4";
    let bad = fchk.replacen(header, &header.replace("N=           4", "N= 99999999999"), 1);
    let start = Instant::now();
    let e = refused("lie.fchk", bad.as_bytes());
    assert!(start.elapsed() < Duration::from_secs(10));
    assert_eq!(e.line, bad.lines().position(|l| l.starts_with("Opt point       3 Results")).unwrap() + 1, "{e}");
}

/// An ORCA output whose shell claims 10¹¹ primitives, or whose orbital rows name the wrong atom,
/// is refused at its line.
#[test]
fn orca_outputs_with_lying_counts_are_refused_at_their_line() {
    let orca = std::fs::read_to_string(ORCA).unwrap();
    assert!(formats::load_bytes(Path::new("h2.out"), orca.as_bytes()).is_ok());
    let bad = orca.replacen(" S 3 ", " S 99999999999 ", 1);
    let e = refused("count.out", bad.as_bytes());
    assert!(e.expected.contains("primitive"), "{e}");
    let bad = orca.replacen("  1H   1s", "  0H   1s", 1);
    let e = refused("atom.out", bad.as_bytes());
    assert_eq!(e.line, bad.lines().position(|l| l.starts_with("  0H") && l.contains('-')).unwrap() + 1, "{e}");
    assert!(e.expected.contains("function of atom 1"), "{e}");
}

/// GAMESS-US, NWChem, Psi4 and Q-Chem outputs cut inside their orbital blocks are refused naming
/// the file and a line, never opened with part of an orbital; a shell claiming 10¹¹ primitives
/// (Psi4, Q-Chem: GAMESS and NWChem print one primitive a line, no count) allocates nothing.
#[test]
fn other_programs_outputs_cut_inside_their_orbitals_are_refused_at_a_line() {
    for name in NEW_LOGS {
        let text = std::fs::read_to_string(format!("{LOGS}/{name}")).unwrap();
        let doc = formats::load_bytes(Path::new(name), text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
        assert!(doc.wavefunction.is_some(), "{name}");
        // Cut after each line of the orbital section's last rows: every cut either refuses the
        // file at a line or opens whole orbitals (2 coefficients each).
        let lines: Vec<&str> = text.lines().collect();
        let last_row = lines.iter().rposition(|l| l.contains("-1.21245")).unwrap();
        let first_row = lines.iter().position(|l| l.contains("1.21245")).unwrap();
        for cut in first_row..=last_row {
            let cut_text = lines[..cut].join("\n") + "\n";
            match formats::load_bytes(Path::new(name), cut_text.as_bytes()) {
                Err(e) => {
                    let e = parse_error(e);
                    assert_eq!(e.file, name);
                    assert!(e.line >= 1 && e.line <= cut.max(1), "{name} cut at {cut}: {e}");
                }
                Ok(doc) => {
                    let wf = doc.wavefunction.unwrap_or_else(|| panic!("{name} cut at {cut}: opened without orbitals"));
                    assert!(wf.orbitals.iter().all(|o| o.coefficients.len() == 2), "{name} cut at {cut}");
                }
            }
        }
    }
    for (name, from, to) in [
        ("h2_psi4.out", "    S   3 1.00", "    S   99999999999 1.00"),
        ("h2_qchem.out", "S    3    1.000000", "S    99999999999    1.000000"),
    ] {
        let text = std::fs::read_to_string(format!("{LOGS}/{name}")).unwrap().replacen(from, to, 1);
        let start = Instant::now();
        let e = refused(name, text.as_bytes());
        assert!(start.elapsed() < Duration::from_secs(2), "{name}");
        assert!(e.line > 1, "{name}: {e}");
    }
}

/// A Q-Chem CIS/TDA fchk whose excited-state records lie (a state count past its energies, an
/// energy that is no excitation, amplitudes too few or not normalised, a count the file cannot
/// hold) opens its orbitals and leaves the states out, naming the file and the line, or is
/// refused at its line; a full TD-DFT's X and Y amplitudes list the states without transitions.
#[test]
fn qchem_excited_state_records_that_lie_leave_the_states_out() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/excited/formaldehyde_qchem_tda.fchk");
    let fchk = std::fs::read_to_string(path).unwrap();
    let line_of = |text: &str, label: &str| text.lines().position(|l| l.starts_with(label)).unwrap() + 1;
    let first_value = |label: &str| fchk.lines().nth(line_of(&fchk, label)).unwrap().to_string();
    let energies = first_value("Excitation Energies");
    let e1 = energies.split_whitespace().next().unwrap();
    let amplitudes = first_value("Alpha Amplitudes");
    let amplitude_header = fchk.lines().find(|l| l.starts_with("Alpha Amplitudes")).unwrap().to_string();
    let cut_header = amplitude_header.replace("N=         672", "N=         671");
    let cut_values = amplitudes.split_at(amplitudes.len() - 16).0.to_string();
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "count",
            fchk.replacen(
                "Number of Excited States                   I                6",
                "Number of Excited States                   I     999999999999",
                1,
            ),
            "Excitation Energies",
        ),
        (
            "energy",
            fchk.replacen(&energies, &energies.replacen(&format!(" {e1}"), &format!("-{e1}"), 1), 1),
            "Excitation Energies",
        ),
        ("zero", fchk.replacen(&energies, &energies.replacen(e1, "0.00000000E+00", 1), 1), "Excitation Energies"),
        ("norm", fchk.replacen(&amplitudes, &amplitudes.replacen("E-", "E+", 1), 1), "Alpha Amplitudes"),
        (
            "few",
            fchk.replacen(&amplitude_header, &cut_header, 1).replacen(&amplitudes, &cut_values, 1),
            "Alpha Amplitudes",
        ),
    ];
    assert_eq!(amplitude_header.split_whitespace().last(), Some("672"), "6 states × 8 occupied × 14 virtual");
    for (what, bad, label) in cases {
        assert_ne!(bad, fchk, "{what}");
        let start = Instant::now();
        let doc = formats::load_bytes(Path::new("lie.fchk"), bad.as_bytes()).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(start.elapsed() < Duration::from_secs(5), "{what}");
        assert!(doc.wavefunction.is_some() && doc.excited.is_none(), "{what}");
        let at = format!("lie.fchk:{}:", line_of(&bad, label));
        assert!(
            doc.problems.iter().any(|p| p.starts_with("excited states left out") && p.contains(&at)),
            "{what}: {:?} (expected {at})",
            doc.problems
        );
    }
    // A count the rest of the file cannot hold: refused at its line before anything is allocated.
    let bad = fchk.replacen(&amplitude_header, &amplitude_header.replace("N=         672", "N= 99999999999"), 1);
    let e = refused("lie.fchk", bad.as_bytes());
    assert_eq!(e.line, line_of(&bad, "Alpha Amplitudes"), "{e}");
    // A full TD-DFT's records (not read): the states, without transitions, saying so.
    let xy = fchk.replacen("Alpha Amplitudes  ", "Alpha X Amplitudes", 1).replacen(
        "Beta Amplitudes   ",
        "Alpha Y Amplitudes",
        1,
    );
    let doc = formats::load_bytes(Path::new("xy.fchk"), xy.as_bytes()).unwrap();
    let states = doc.excited.as_ref().expect("the states");
    assert!(states.states.len() == 6 && states.states.iter().all(|s| s.transitions.is_empty()));
    assert!(doc.problems.iter().any(|p| p.contains("X Amplitudes") && p.contains("not read")), "{:?}", doc.problems);
}

/// ORCA's and QCSchema's JSON wavefunctions: values of the wrong type, counts that do not match,
/// shells past h, a basis too big for its overlap matrix, files cut short, other JSON and deep
/// nesting are refused with the path of the value at fault (or the line of a syntax error),
/// fast; a valid file on one line longer than the line limit opens.
#[test]
fn json_wavefunctions_refuse_hostile_contents() {
    use serde_json::{Value, json};
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/json");
    let orca: Value = serde_json::from_slice(&std::fs::read(format!("{dir}/h2o_cation.orca.json")).unwrap()).unwrap();
    let qcs: Value = serde_json::from_slice(&std::fs::read(format!("{dir}/h2o_cart.qcschema.json")).unwrap()).unwrap();
    let with = |base: &Value, pointer: &str, value: Value| {
        let mut v = base.clone();
        *v.pointer_mut(pointer).unwrap_or_else(|| panic!("{pointer}")) = value;
        serde_json::to_vec(&v).unwrap()
    };
    let check = |name: &str, bytes: &[u8], expected: &str| {
        let e = refused(name, bytes);
        assert!(e.expected.contains(expected), "{name}: {e}");
        e
    };
    // Wrong types.
    check("coords.json", &with(&orca, "/Molecule/Atoms/1/Coords", json!("0 0 0")), "Molecule.Atoms[1].Coords as");
    check(
        "mo.json",
        &with(&orca, "/Molecule/MolecularOrbitals/MOs/3/MOCoefficients/2", json!("x")),
        "MOs[3].MOCoefficients[2] as a finite number",
    );
    check(
        "occ.json",
        &with(&orca, "/Molecule/MolecularOrbitals/MOs/0/Occupancy", json!("1")),
        "Occupancy as a finite number",
    );
    check("shell.json", &with(&orca, "/Molecule/Atoms/0/Basis/0/Shell", json!("k")), "Shell as a shell letter");
    check(
        "units.json",
        &with(&orca, "/Molecule/CoordinateUnits", json!("nm")),
        "CoordinateUnits as \"Bohrs\" or \"Angs\"",
    );
    check(
        "ht.json",
        &with(&qcs, "/wavefunction/basis/center_data/6-31G*_O1/electron_shells/0/harmonic_type", json!("polar")),
        "harmonic_type as",
    );
    check(
        "l.json",
        &with(&qcs, "/wavefunction/basis/center_data/6-31G*_O1/electron_shells/0/angular_momentum", json!([7])),
        "angular_momentum[0] as a whole number 0..=5",
    );
    check("restricted.json", &with(&qcs, "/wavefunction/restricted", json!(1)), "restricted as true or false");
    check(
        "nan.json",
        &with(&qcs, "/wavefunction/scf_eigenvalues_a/0", json!("NaN")),
        "scf_eigenvalues_a[0] as a finite number",
    );
    // Counts that do not match.
    check(
        "count.json",
        &with(&orca, "/Molecule/MolecularOrbitals/MOs/5/MOCoefficients", json!([1.0, 2.0])),
        "24 coefficients",
    );
    let mut odd = orca.clone();
    odd.pointer_mut("/Molecule/MolecularOrbitals/MOs").unwrap().as_array_mut().unwrap().pop();
    check("odd.json", &serde_json::to_vec(&odd).unwrap(), "an even number");
    check("map.json", &with(&qcs, "/wavefunction/basis/atom_map", json!(["6-31G*_O1"])), "3 names");
    check(
        "exps.json",
        &with(&qcs, "/wavefunction/basis/center_data/6-31G*_O1/electron_shells/0/exponents", json!([1.0])),
        "one per exponent",
    );
    check(
        "orbs.json",
        &with(&qcs, "/wavefunction/scf_orbitals_a", Value::from(vec![0.5; 20])),
        "a multiple of 19 coefficients",
    );
    check("eigen.json", &with(&qcs, "/wavefunction/scf_eigenvalues_a", json!([0.5])), "19 orbital energies");
    check("geometry.json", &with(&qcs, "/molecule/geometry", json!([0.0, 1.0])), "9 coordinates");
    check("nalpha.json", &with(&qcs, "/properties/calcinfo_nalpha", json!(1e15)), "a whole number 0..=1000000");
    // A basis whose overlap matrix would be huge: 20 000 h shells on one atom, one orbital.
    let shell = json!({"Coefficients": [1.0], "Exponents": [1.0], "Shell": "h"});
    let mut big = with(&orca, "/Molecule/Atoms/0/Basis", Value::Array(vec![shell; 20_000]));
    let mut v: Value = serde_json::from_slice(&big).unwrap();
    v["Molecule"]["Atoms"][1]["Basis"] = json!([]);
    v["Molecule"]["Atoms"][2]["Basis"] = json!([]);
    big = serde_json::to_vec(&v).unwrap();
    check("big.json", &big, "a basis of at most");
    // Cut short anywhere: a syntax error at the line where the text ends.
    let text = serde_json::to_string_pretty(&orca).unwrap();
    for cut in [1, text.len() / 3, text.len() - 2] {
        let e = refused("cut.json", &text.as_bytes()[..cut]);
        assert!(e.found.contains("truncated"), "{e}");
        assert_eq!(e.line, text[..cut].matches('\n').count() + 1, "{e}");
    }
    let e = refused("empty.json", b" \n");
    assert_eq!(e.found, "an empty file", "{e}");
    // Other JSON: what was expected is named.
    let wrapper = serde_json::to_vec(&json!({"input": {}, "result": qcs})).unwrap();
    check("wrapper.json", &wrapper, "QCSchema result");
    let mut no_wfn = qcs.clone();
    no_wfn.as_object_mut().unwrap().remove("wavefunction");
    check("nowfn.json", &serde_json::to_vec(&no_wfn).unwrap(), "protocols");
    // serde_json's recursion limit: a deep nest is an error, not a stack overflow.
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    check("deep.json", deep.as_bytes(), "JSON text");
    // A gzip bomb of blanks after a valid head.
    let e = refused("bomb.json.gz", &bomb("{\"Molecule\": ", b" ", 4));
    assert!(e.found.contains("decompression bomb"), "{e}");
    // One line longer than the line limit (QCElemental writes a whole file on one line).
    let mut long = qcs.clone();
    long["stdout"] = Value::String("x".repeat(3 * MAX_LINE_BYTES));
    let doc = formats::load_bytes(Path::new("long.json"), &serde_json::to_vec(&long).unwrap()).unwrap();
    assert_eq!(doc.wavefunction.unwrap().basis.n_functions(), 19);
}
