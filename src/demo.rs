//! The bundled demo shown when the viewer starts with no file.

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
