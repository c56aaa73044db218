//! What a camera frames to show a document whole: its grids, the box a wavefunction's orbitals
//! are evaluated in, or the atoms a selection shows.

use glam::DVec3;

use super::selection::shown_atoms;
use super::{Camera, ViewPreset};
use crate::model::Document;

/// Space (bohr) around the atoms in which orbitals are evaluated.
pub const ORBITAL_MARGIN: f64 = 4.5;

/// A camera that frames everything in the document from the default direction: its grids, or
/// for a wavefunction the box its orbitals are evaluated in.
pub fn default_camera(doc: &Document) -> Camera {
    match framing_box(doc) {
        Some((lo, hi)) => Camera::framing(lo, hi),
        None => Camera::default(),
    }
}

/// The camera a new file opens with: [`default_camera`]'s framing, looking along `preset`'s
/// direction (the principal axes, tilted, for [`ViewPreset::Auto`]).
pub fn camera_for(doc: &Document, preset: ViewPreset) -> Result<Camera, String> {
    let view = preset.direction(&doc.molecule)?;
    let mut camera = default_camera(doc);
    camera.look_along(view.direction, view.up);
    Ok(camera)
}

/// The box a camera frames to show `doc` whole (bohr, the document's own frame).
pub fn framing_box(doc: &Document) -> Option<(glam::Vec3, glam::Vec3)> {
    let bounds = match (&doc.wavefunction, doc.molecule.bounds()) {
        (Some(_), Some((lo, hi))) => Some((lo - DVec3::splat(ORBITAL_MARGIN), hi + DVec3::splat(ORBITAL_MARGIN))),
        _ => doc.bounds(),
    };
    bounds.map(|(lo, hi)| (lo.as_vec3(), hi.as_vec3()))
}

/// [`framing_box`], or the box of the atoms `selection` shows (padded by the largest atom's
/// radius) when it names some of them.
pub fn framing_box_of(doc: &Document, selection: &str) -> Option<(glam::Vec3, glam::Vec3)> {
    let Some(mask) = shown_atoms(doc, selection) else { return framing_box(doc) };
    let shown = doc.molecule.atoms.iter().zip(&mask).filter(|(_, m)| **m).map(|(a, _)| a.position.as_vec3());
    let (lo, hi) = shown.fold(None, |b: Option<(glam::Vec3, glam::Vec3)>, p| {
        Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
    })?;
    Some((lo - glam::Vec3::splat(4.0), hi + glam::Vec3::splat(4.0)))
}
