//! One entry per reader: the bytes of a file named as that reader expects. A reader may refuse
//! any input with an error; a panic, a hang or an allocation beyond the bound is a finding.

use std::path::Path;
use std::sync::LazyLock;

use glam::DVec3;
use orbcloud::model::{Atom, Document, Molecule};

/// Reads `data` as a file named `name` (the extension picks the reader; `.gz` inflates first).
/// Wavefunctions are read without the orthonormality check: its analytic overlaps cost
/// milliseconds per file, a hundred times the parse, and it sees only what a reader accepted
/// (the test suite's mutation run covers it).
pub fn read_as(name: &str, data: &[u8]) {
    let _ = orbcloud::formats::load_bytes_with(Path::new(name), data, None);
}

/// A frame every manifest's files load as: H–O–O–H, so dihedrals of its four atoms are valid.
static FRAME: LazyLock<Document> = LazyLock::new(|| {
    let atom = |z, x, y, w| Atom { z, charge: z as f64, position: DVec3::new(x, y, w), ghost: false };
    Document {
        source: "frame".into(),
        title: "frame".into(),
        molecule: Molecule::new(vec![
            atom(1, -1.8, 1.5, 0.0),
            atom(8, -1.4, 0.0, 0.0),
            atom(8, 1.4, 0.0, 0.0),
            atom(1, 1.8, 1.5, 0.5),
        ]),
        ..Document::default()
    }
});

/// Parses `data` as a scan manifest whose frames all load as [`FRAME`].
pub fn read_manifest(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = orbcloud::formats::scan::parse_scan(Path::new("fuzz.scan.toml"), text, &mut |_| Ok(FRAME.clone()));
}

/// Parses `data` as a session. One that opens must be drawable: a second pass of the range
/// checks finds nothing to change, and every camera projects to finite points.
pub fn read_session(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(read) = orbcloud::sources::session::parse("fuzz.orbcloud.toml", text) else { return };
    let mut session = read.session;
    let cameras: Vec<_> = std::iter::once(session.camera).chain(session.panes.cameras).collect();
    for camera in cameras {
        assert!(camera.clip_from_world(1.5, 10.0).is_finite() && camera.eye().is_finite(), "{camera:?}");
    }
    let again = session.sanitize();
    assert!(again.is_empty(), "values still out of range: {again:?}");
}
