//! The bundled demo shown when the viewer starts with no file.

use std::path::Path;

use crate::formats::scan::ScanFile;
use crate::formats::{self, LoadError};
use crate::model::Document;

/// Formaldehyde's HOMO on a 48³ grid, written by scripts/make_assets.py (PySCF).
const DEMO_CUBE_GZ: &[u8] = include_bytes!("../assets/demo.cube.gz");
pub const DEMO_NAME: &str = "demo.cube.gz (formaldehyde HOMO, bundled)";

pub fn document() -> Result<Document, LoadError> {
    let text = formats::gunzip_text(DEMO_NAME, DEMO_CUBE_GZ)?;
    let mut doc = formats::cube::parse(DEMO_NAME, &text)?;
    doc.source = DEMO_NAME.to_string();
    Ok(doc)
}

/// The bundled scan: the PSB3 cation (retinal model) twisted about its central C=C at seed
/// 000's 15 angles, RHF/6-31G*, written by scripts/make_psb3_scan.py (PySCF). Embedded, so the
/// viewer needs no files beside it.
const SCAN_MANIFEST: &str = include_str!("../assets/psb3/psb3.scan.toml");
pub const SCAN_NAME: &str = "psb3.scan.toml (PSB3 twist, bundled)";
macro_rules! frames {
    ($($name:literal),* $(,)?) => {
        &[$(($name, include_bytes!(concat!("../assets/psb3/", $name)))),*]
    };
}
const SCAN_FRAMES: &[(&str, &[u8])] = frames![
    "psb3_m180.molden.gz",
    "psb3_m150.molden.gz",
    "psb3_m120.molden.gz",
    "psb3_m110.molden.gz",
    "psb3_m105.molden.gz",
    "psb3_m100.molden.gz",
    "psb3_m095.molden.gz",
    "psb3_m090.molden.gz",
    "psb3_m085.molden.gz",
    "psb3_m080.molden.gz",
    "psb3_m075.molden.gz",
    "psb3_m070.molden.gz",
    "psb3_m060.molden.gz",
    "psb3_m030.molden.gz",
    "psb3_000.molden.gz",
];

/// The bundled PSB3 scan, read from the embedded manifest and Molden files.
pub fn scan() -> Result<ScanFile, LoadError> {
    let mut load = |path: &Path| {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        match SCAN_FRAMES.iter().find(|(n, _)| *n == name) {
            Some((_, bytes)) => formats::load_bytes(path, bytes),
            None => formats::load(path),
        }
    };
    formats::scan::parse_scan(Path::new(SCAN_NAME), SCAN_MANIFEST, &mut load)
}
