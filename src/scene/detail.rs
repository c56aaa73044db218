//! How much of a picture is drawn: slices per cloud, pixels, the surfaces' level of detail.
//! The window draws less while the user drags (`app::detail`) and, after a change that takes a
//! slow adapter long to draw, a coarse preview at once ([`Detail::PREVIEW`]) while the full
//! picture is drawn band by band.

use super::VolumeSettings;

/// What one view draws in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detail {
    pub max_slices: u32,
    /// At most this many pixels; the view's size is scaled down to fit, keeping its aspect.
    pub max_pixels: u32,
    /// The factor on surfaces' level-of-detail thresholds (Lee et al., docs/references.md).
    pub lod_scale: f32,
    /// At most this many slice planes per texel of a cloud's grid along the view, whatever its
    /// slice count asks: trilinear samples closer than half a texel add time, not detail (the
    /// opacity is corrected for the spacing, so the picture stays the same).
    pub planes_per_texel: f32,
}

impl Detail {
    pub const FULL: Self =
        Self { max_slices: u32::MAX, max_pixels: u32::MAX, lod_scale: 1.0, planes_per_texel: PLANES_PER_TEXEL };

    /// The coarse picture shown at once after a change on a slow adapter: few slices on few
    /// pixels (the texture filter scales it up), big surfaces' parts drawn as points sooner.
    /// Lavapipe on two cores draws three molecules with clouds and translucent surfaces so in
    /// under 200 ms (`orbcloud bench scene`).
    pub const PREVIEW: Self = Self {
        max_slices: PREVIEW_SLICES,
        max_pixels: PREVIEW_PIXELS,
        lod_scale: 4.0,
        planes_per_texel: PLANES_PER_TEXEL,
    };

    /// The size to render a view shown at `size` pixels.
    pub fn render_size(&self, size: [u32; 2]) -> [u32; 2] {
        let pixels = size[0] as f64 * size[1] as f64;
        if pixels <= self.max_pixels as f64 {
            return size;
        }
        let scale = (self.max_pixels as f64 / pixels).sqrt();
        size.map(|s| ((s as f64 * scale).floor() as u32).max(1))
    }

    /// `cloud` with the slice count capped.
    pub fn cloud(&self, mut cloud: VolumeSettings) -> VolumeSettings {
        cloud.slices = cloud.slices.min(self.max_slices);
        cloud
    }
}

/// Slice planes per texel along the view at most: a trilinear field between texels needs
/// little more than one sample each. At 1.75 the demo scene's full picture differs from 2's by
/// at most 4/255 (mean 0.05/255; `bench scene --images`), from the 192 slices' by as little.
pub const PLANES_PER_TEXEL: f32 = 1.75;

/// Slices per cloud in a preview.
pub const PREVIEW_SLICES: u32 = 48;
/// Pixels of a preview at most.
pub const PREVIEW_PIXELS: u32 = 200 * 150;
