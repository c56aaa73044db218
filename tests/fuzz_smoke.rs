//! A short mutation fuzz of every reader in the test suite (a few seconds each): the fixtures,
//! mutated byte by byte and line by line, must be read or refused with an error, never panic,
//! and each input must be done fast. The long, coverage-guided run is `scripts/fuzz.sh` (AFL++).

use std::path::Path;
use std::time::{Duration, Instant};

use glam::DVec3;
use orbcloud::model::{Atom, Document, Molecule};

/// The AFL++ targets' entries, compiled here too so the test build checks them.
#[allow(dead_code, reason = "only the session entry runs here; the readers' are called directly")]
#[path = "../fuzz/src/lib.rs"]
mod fuzz_targets;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");
/// How long each reader is fuzzed.
const BUDGET: Duration = Duration::from_secs(3);
/// The slowest one input may be read (a debug build, two cores shared with other tests).
const SLOWEST: Duration = Duration::from_secs(2);

/// xorshift64*: deterministic, so a failure reproduces.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// One to four mutations of `input`: flipped bits, bytes that matter to these formats, deleted,
/// duplicated or swapped spans, numbers made huge, negative or not a number.
fn mutate(rng: &mut Rng, input: &[u8]) -> Vec<u8> {
    const BYTES: &[u8] = b"0123456789-+.eE \n\t[]=\"#,\x00\xff";
    const WORDS: &[&[u8]] = &[b"-1", b"0", b"99999999999", b"NaN", b"inf", b"1e308", b"-2147483649", b"[", b"]\n"];
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(out.len() + 1);
        match rng.below(6) {
            0 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] ^= 1 << rng.below(8);
            }
            1 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] = BYTES[rng.below(BYTES.len())];
            }
            2 => {
                let end = (at + 1 + rng.below(64)).min(out.len());
                out.drain(at.min(end)..end);
            }
            3 => {
                let end = (at + 1 + rng.below(256)).min(out.len());
                let span = out[at.min(end)..end].to_vec();
                let to = rng.below(out.len() + 1);
                out.splice(to..to, span);
            }
            4 => {
                let word = WORDS[rng.below(WORDS.len())];
                out.splice(at..at, word.iter().copied());
            }
            _ => {
                // Swap two lines.
                let lines: Vec<&[u8]> = out.split(|&b| b == b'\n').collect();
                if lines.len() > 2 {
                    let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                    let mut l: Vec<Vec<u8>> = lines.iter().map(|x| x.to_vec()).collect();
                    l.swap(a, b);
                    out = l.join(&b'\n');
                }
            }
        }
    }
    out
}

/// Feeds mutations of `seeds` to `read` for [`BUDGET`]; returns how many inputs were read.
fn fuzz(name: &str, seeds: &[Vec<u8>], read: impl Fn(&[u8])) -> usize {
    assert!(!seeds.is_empty(), "{name}: no seeds");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ name.len() as u64);
    let start = Instant::now();
    let mut count = 0;
    while start.elapsed() < BUDGET {
        let seed = rng.below(seeds.len());
        let input = mutate(&mut rng, &seeds[seed]);
        let one = Instant::now();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read(&input)));
        let took = one.elapsed();
        if outcome.is_err() || took > SLOWEST {
            let kept = std::env::temp_dir().join(format!("orbcloud-fuzz-{name}-{count}"));
            std::fs::write(&kept, &input).ok();
            panic!(
                "{name}: input {count} {} (kept in {})",
                if outcome.is_err() { "panicked" } else { "took too long" },
                kept.display()
            );
        }
        count += 1;
    }
    eprintln!("{name}: {count} mutated inputs in {BUDGET:?}, none panicked");
    count
}

fn files(ext: &str) -> Vec<Vec<u8>> {
    files_in(FIXTURES, ext)
}

fn files_in(dir: &str, ext: &str) -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() < 60_000))
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    seeds.sort();
    seeds
}

fn cube_seed() -> Vec<u8> {
    let demo = orbcloud::sources::demo::document().unwrap();
    let small = demo.volumes[0].subsampled(10);
    orbcloud::formats::cube_write::write("demo", "every tenth point", &demo.molecule, &[(&small, 1)]).into_bytes()
}

fn read(name: &'static str) -> impl Fn(&[u8]) {
    move |data| {
        let _ = orbcloud::formats::load_bytes(Path::new(name), data);
    }
}

#[test]
fn structure_readers_survive_mutated_fixtures() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures");
    fuzz("pdb", &files_in(dir, "pdb"), read("fuzz.pdb"));
    fuzz("mmcif", &files_in(dir, "cif"), read("fuzz.cif"));
    fuzz("xyz", &files_in(dir, "xyz"), read("fuzz.xyz"));
}

#[test]
fn readers_survive_mutated_fixtures() {
    fuzz("cube", &[cube_seed()], read("fuzz.cube"));
    fuzz("molden", &files("molden"), read("fuzz.molden"));
    fuzz("fchk", &files("fchk"), read("fuzz.fchk"));
    // A relaxed scan's fchk: its `Opt point N` records open as frames.
    let scans = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/scan_jobs");
    fuzz("scan fchk", &files_in(scans, "fchk"), read("fuzz.fchk"));
    // A Q-Chem CIS/TDA fchk: its states and every state's amplitudes.
    let excited = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/excited");
    fuzz("qchem td fchk", &files_in(excited, "fchk"), read("fuzz.fchk"));
    let gz = {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(&cube_seed()).unwrap();
        e.finish().unwrap()
    };
    fuzz("cube.gz", &[gz], read("fuzz.cube.gz"));
}

#[test]
fn aim_and_mkl_readers_survive_mutated_fixtures() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wfn_wfx_mkl");
    fuzz("wfn", &files_in(dir, "wfn"), read("fuzz.wfn"));
    fuzz("wfx", &files_in(dir, "wfx"), read("fuzz.wfx"));
    fuzz("mkl", &files_in(dir, "mkl"), read("fuzz.mkl"));
}

#[test]
fn the_json_reader_survives_mutated_fixtures() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/json");
    fuzz("json", &files_in(dir, "json"), read("fuzz.json"));
}

#[test]
fn the_log_reader_survives_mutated_fixtures() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs");
    fuzz("log", &files_in(dir, "log"), read("fuzz.log"));
    fuzz("out", &files_in(dir, "out"), read("fuzz.out"));
}

#[test]
fn scan_manifests_survive_mutations() {
    let atom = |z, x, y, w| Atom { z, charge: z as f64, position: DVec3::new(x, y, w), ghost: false };
    let frame = Document {
        source: "frame".into(),
        title: "frame".into(),
        molecule: Molecule::new(vec![
            atom(1, -1.8, 1.5, 0.0),
            atom(8, -1.4, 0.0, 0.0),
            atom(8, 1.4, 0.0, 0.0),
            atom(1, 1.8, 1.5, 0.5),
        ]),
        ..Document::default()
    };
    let manifest = br#"title = "HOOH"
dihedral = [1, 2, 3, 4]
orbitals = ["homo", "lumo"]

[[frame]]
angle = -90
file = "a.molden"

[[frame]]
angle = 0
file = "b.molden"
"#
    .to_vec();
    let psb3 = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/psb3/psb3.scan.toml")).unwrap();
    fuzz("scan manifest", &[manifest, psb3], |data| {
        let Ok(text) = std::str::from_utf8(data) else { return };
        let _ = orbcloud::formats::scan::parse_scan(Path::new("fuzz.scan.toml"), text, &mut |_| Ok(frame.clone()));
    });
}

/// Sessions, mutated: one that parses must come out of its range checks drawable, with every
/// camera finite and nothing left for a second pass to change (the AFL++ target's check).
#[test]
fn sessions_survive_mutations() {
    use orbcloud::scene::{IsoLevel, ObjectState, QuantityState, RenderSettings, Session, Source};
    let mut quantity = QuantityState::new(Source::Volume(0), &RenderSettings::default());
    quantity.isosurfaces[0].visible = true;
    quantity
        .isosurfaces
        .push(orbcloud::scene::IsosurfaceSettings { level: IsoLevel::Sigma(2.0), ..Default::default() });
    quantity.pane = Some(1);
    let mut object = ObjectState { path: Some("water.cube".into()), quantities: vec![quantity], ..Default::default() };
    object.clip.enabled = true;
    object.placement.offset = [1.0, 0.0, -2.0];
    let mut session = Session { background: Some([0.1, 0.1, 0.1]), objects: vec![object], ..Default::default() };
    session.panes.count = 2;
    let seed = toml::to_string(&session).unwrap().into_bytes();
    let opened = std::sync::atomic::AtomicUsize::new(0);
    fuzz("session", &[seed], |data| {
        if std::str::from_utf8(data).is_ok_and(|t| orbcloud::sources::session::parse("fuzz.orbcloud.toml", t).is_ok()) {
            opened.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        fuzz_targets::read_session(data);
    });
    assert!(opened.into_inner() > 0, "no mutated session opened: the check saw nothing");
}
