//! What the user has set: plain data, separate from what owns GPU resources.

use serde::{Deserialize, Serialize};

use crate::scene::{Camera, RenderSettings};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct ViewState {
    pub camera: Camera,
    pub settings: RenderSettings,
    /// Which volume of the document is shown.
    pub volume: usize,
}

/// Keyboard rotation step, radians.
pub const KEY_ROTATE: f32 = 5.0 * std::f32::consts::PI / 180.0;
/// Keyboard zoom factor per press.
pub const KEY_ZOOM: f32 = 1.1;
/// Mouse orbit, radians per point dragged.
pub const DRAG_ROTATE: f32 = 0.008;
