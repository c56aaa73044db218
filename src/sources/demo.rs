//! The bundled demos: the formaldehyde cube, the PSB3 scan the viewer starts with, and the
//! diene + SO₂ scene of translucent orbitals.

use std::path::Path;

use crate::formats::scan::ScanFile;
use crate::formats::{self, LoadError};
use crate::model::Document;
use crate::model::orbitals::{Quantity, Spin};
use crate::scene::{IsoLevel, IsosurfaceSettings, ObjectState, OpticsPreset, QuantityState, Source, VolumeSettings};

/// Formaldehyde's HOMO on a 48³ grid, written by scripts/make_assets.py (PySCF).
const DEMO_CUBE_GZ: &[u8] = include_bytes!("../../assets/demo.cube.gz");
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
const SCAN_MANIFEST: &str = include_str!("../../assets/psb3/psb3.scan.toml");
pub const SCAN_NAME: &str = "psb3.scan.toml (PSB3 twist, bundled)";
macro_rules! frames {
    ($($name:literal),* $(,)?) => {
        &[$(($name, include_bytes!(concat!("../../assets/psb3/", $name)))),*]
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

/// The diene + SO₂ demo (Koide and Miyata's picture): s-cis butadiene and SO₂ placed as in a
/// cheletropic approach, RHF/6-31G*, written by scripts/make_cycloaddition_demo.py (PySCF).
const BUTADIENE_MOLDEN_GZ: &[u8] = include_bytes!("../../assets/cycloaddition/butadiene.molden.gz");
const SO2_MOLDEN_GZ: &[u8] = include_bytes!("../../assets/cycloaddition/so2.molden.gz");
pub const CYCLOADDITION_NAME: &str = "diene + SO₂ (bundled)";
/// How the demo is first seen, as yaw and pitch (radians) from the camera that frames it: from
/// the side and a little above, the diene's π lobes rising to SO₂'s.
pub const CYCLOADDITION_VIEW: (f32, f32) = (0.5, -1.35);

/// The diene + SO₂ scene as Koide & Miyata draw it: each molecule its own object in one frame,
/// showing its total density and its frontier orbital (butadiene's HOMO, SO₂'s LUMO) as
/// translucent isosurfaces, no clouds; where the orbitals meet they glow.
pub fn cycloaddition() -> Result<Vec<(Document, ObjectState)>, LoadError> {
    let parts = [
        ("butadiene.molden.gz", BUTADIENE_MOLDEN_GZ, false, [0.9, 0.2, 0.12], [0.15, 0.35, 0.95]),
        ("so2.molden.gz", SO2_MOLDEN_GZ, true, [0.95, 0.7, 0.15], [0.2, 0.8, 0.4]),
    ];
    parts
        .into_iter()
        .map(|(name, bytes, lumo, positive, negative)| {
            let doc = formats::load_bytes(Path::new(name), bytes)?;
            let wf = doc.wavefunction.as_ref();
            let orbital = wf.and_then(|wf| if lumo { wf.lumo(Spin::Alpha) } else { wf.homo(Spin::Alpha) });
            let state = density_and_orbital(orbital, positive, negative);
            Ok((doc, state))
        })
        .collect()
}

/// An object showing its total density and orbital `orbital` (when given) as translucent
/// surfaces that glow where they meet another molecule's, coloured `positive` and `negative`
/// (the demo's look); their clouds hidden.
pub fn density_and_orbital(orbital: Option<usize>, positive: [f32; 3], negative: [f32; 3]) -> ObjectState {
    let surface = |level, positive_color, negative_color, density_color| IsosurfaceSettings {
        visible: true,
        level: IsoLevel::Absolute(level),
        positive_color,
        negative_color,
        density_color,
        translucent: true,
        optics: OpticsPreset::Koide,
        ..IsosurfaceSettings::default()
    };
    let quantity = |source, iso| QuantityState {
        source,
        visible: true,
        cloud: VolumeSettings { visible: false, ..VolumeSettings::default() },
        isosurfaces: vec![iso],
        pane: None,
        fragments: Default::default(),
    };
    let density = quantity(
        Source::Wavefunction(Quantity::Density),
        surface(DEMO_DENSITY_LEVEL, positive, negative, [0.62, 0.66, 0.72]),
    );
    let mut state = ObjectState { quantities: vec![density], ..ObjectState::default() };
    if let Some(i) = orbital {
        let iso = surface(DEMO_ORBITAL_LEVEL, positive, negative, positive);
        state.quantities.push(quantity(Source::Wavefunction(Quantity::Orbital(i)), iso));
        state.selected = 1;
    }
    state
}

/// The demo's density surface (a.u.): close around the nuclei, so the orbitals' lobes stand out
/// of it.
const DEMO_DENSITY_LEVEL: f32 = 0.08;
/// The demo's orbital surfaces, ψ = ±value (a.u.).
const DEMO_ORBITAL_LEVEL: f32 = 0.03;
