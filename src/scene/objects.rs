//! A scene of objects: each opened file with its own placement and representations. Plain,
//! serialisable data; what owns GPU resources lives in the viewer and the renderer's layers.

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::model::orbitals::Quantity;

use super::{Camera, IsosurfaceSettings, RenderSettings, SurfaceSettings};

/// Where an object sits in the scene: a rigid placement (rotation about the object's own
/// origin, then a translation), so distances and the clouds' opacity per path are unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Placement {
    /// Translation, bohr.
    pub offset: [f32; 3],
    /// Rotation about x, then y, then z, degrees.
    pub rotation_deg: [f32; 3],
}

impl Placement {
    pub fn world_from_object(&self) -> Mat4 {
        let [x, y, z] = self.rotation_deg.map(f32::to_radians);
        Mat4::from_rotation_translation(Quat::from_euler(EulerRot::ZYX, z, y, x), Vec3::from(self.offset))
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::default()
    }

    /// The offset along x that puts a box `lo..hi` (object frame) `gap` beyond `right_edge`
    /// (the scene's largest x): a second molecule placed beside the first.
    pub fn beside(right_edge: f32, lo: Vec3, gap: f32) -> Self {
        Self { offset: [right_edge + gap - lo.x, 0.0, 0.0], rotation_deg: [0.0; 3] }
    }
}

/// What an object shows and how: plain data, saved in sessions.
///
/// `settings` holds the object's atoms (style, `AtomStyle::Hidden` to hide them), its cloud
/// (`settings.volume`, hidden with `visible`) and its first isosurface (`settings.iso`);
/// `isosurfaces` holds any further ones (nested density shells, several orbital values).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ObjectState {
    /// The file it was read from; `None` for the bundled demo.
    pub path: Option<std::path::PathBuf>,
    /// Whether the object is drawn at all.
    pub visible: bool,
    pub placement: Placement,
    pub settings: RenderSettings,
    pub isosurfaces: Vec<IsosurfaceSettings>,
    /// Which of the file's volumes is shown (cube files with several).
    pub volume: usize,
    /// The orbital, density or spin density shown, for files with a wavefunction (`None`: the
    /// HOMO, as a new file opens).
    pub quantity: Option<Quantity>,
    /// Which atoms of a structure are shown ([`super::selection::Selection`]; empty: all).
    pub selection: String,
    /// A molecular surface around the atoms shown.
    pub surface: SurfaceSettings,
}

impl Default for ObjectState {
    fn default() -> Self {
        Self {
            path: None,
            visible: true,
            placement: Placement::default(),
            settings: RenderSettings::default(),
            isosurfaces: Vec::new(),
            volume: 0,
            quantity: None,
            selection: String::new(),
            surface: SurfaceSettings::default(),
        }
    }
}

impl ObjectState {
    /// Every isosurface of the object, shown or not: the first, then the further ones.
    pub fn all_isosurfaces(&self) -> impl Iterator<Item = &IsosurfaceSettings> {
        std::iter::once(&self.settings.iso).chain(&self.isosurfaces)
    }
}

/// A saved scene (`*.orbcloud.toml`): the camera, the background and every object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Session {
    pub camera: Camera,
    /// Linear RGB.
    pub background: Option<[f32; 3]>,
    pub objects: Vec<ObjectState>,
    /// Files opened recently, newest first (the session kept between runs).
    pub recent: Vec<std::path::PathBuf>,
}

/// What a session file is called.
pub const SESSION_SUFFIX: &str = ".orbcloud.toml";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placements_are_rigid_and_place_beside() {
        let p = Placement { offset: [1.0, 2.0, 3.0], rotation_deg: [30.0, -45.0, 90.0] };
        let m = p.world_from_object();
        let (a, b) = (Vec3::new(0.3, -1.0, 2.0), Vec3::new(-2.0, 0.5, 1.0));
        let moved = |v| m.transform_point3(v);
        assert!(((moved(a) - moved(b)).length() - (a - b).length()).abs() < 1e-5, "distances kept");
        assert!((moved(Vec3::ZERO) - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        let z90 = Placement { rotation_deg: [0.0, 0.0, 90.0], ..Default::default() }.world_from_object();
        assert!((z90.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-6, "z rotation is counter-clockwise");
        let beside = Placement::beside(5.0, Vec3::new(-3.0, 0.0, 0.0), 4.0);
        assert_eq!(beside.offset, [12.0, 0.0, 0.0], "the new box starts 4 bohr past x = 5");
        assert!(Placement::default().is_identity() && !p.is_identity());
    }
}
