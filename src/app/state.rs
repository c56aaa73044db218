//! What the user has set: plain data, separate from what owns GPU resources.

use serde::{Deserialize, Serialize};

use crate::scene::{Camera, Panes, RenderSettings};

/// What the window shows of the scene as a whole: the camera, the background and whether
/// atoms are labelled. Each object's settings live in its own state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ViewState {
    pub camera: Camera,
    /// Linear RGB.
    pub background: [f32; 3],
    /// Element and number beside every atom.
    #[serde(default)]
    pub labels: bool,
    /// How the view is split into panes.
    #[serde(default)]
    pub panes: Panes,
    /// Which side panels are open (the view takes the room of a closed one).
    #[serde(skip)]
    pub panels: SidePanels,
}

/// The side panels shown beside the view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SidePanels {
    /// The scene and its representations (left).
    pub scene: bool,
    /// The orbital browser (right).
    pub orbitals: bool,
}

impl Default for SidePanels {
    fn default() -> Self {
        Self { scene: true, orbitals: true }
    }
}

impl Default for ViewState {
    fn default() -> Self {
        Self {
            camera: Camera::default(),
            background: RenderSettings::default().background,
            labels: false,
            panes: Panes::default(),
            panels: SidePanels::default(),
        }
    }
}

/// Keyboard rotation step, radians.
pub const KEY_ROTATE: f32 = 5.0 * std::f32::consts::PI / 180.0;
/// Keyboard zoom factor per press.
pub const KEY_ZOOM: f32 = 1.1;
/// Mouse orbit, radians per point dragged.
pub const DRAG_ROTATE: f32 = 0.008;
