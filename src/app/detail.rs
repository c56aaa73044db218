//! How much a view draws while the user drags or the animation plays (Kikuchi et al.'s dynamic level
//! of detail): fewer slices on every adapter, more of a big surface as points (Lee et al., docs/references.md), and on
//! a CPU rasteriser fewer pixels too, which the texture filter scales up. The full picture
//! returns with the first frame after.

pub use crate::scene::detail::Detail;

/// Slices per view at most while interacting.
pub const INTERACTIVE_SLICES: u32 = 64;

/// Pixels drawn at most, over all views together, while interacting on a CPU adapter. Lavapipe
/// on two cores takes about 33 ms for 256² pixels of 64 slices, so two views of 256² answer a
/// drag ~12 times a second; the time is linear in pixels × slices.
pub const CPU_INTERACTIVE_PIXELS: u32 = 2 * 256 * 256;

/// How much coarser a big surface's level of detail starts while interacting: parts up to this
/// many times the threshold's size on screen are drawn as points. [`LodBudget`] then moves it
/// to keep frames within [`LOD_FRAME_BUDGET_MS`].
pub const INTERACTIVE_LOD_SCALE: f32 = 4.0;

/// The frame time a dragged view aims for, ms.
pub const LOD_FRAME_BUDGET_MS: f64 = 50.0;

/// The level of detail tied to the frame time while interacting (Lee et al.'s threshold "tied
/// to the frame-time budget"): each picture slower than the budget makes points of bigger
/// parts, each one well within it (under half) makes them smaller again; still frames are
/// drawn at the threshold itself. The scale carries over from one drag to the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LodBudget {
    pub scale: f32,
}

impl Default for LodBudget {
    fn default() -> Self {
        Self { scale: INTERACTIVE_LOD_SCALE }
    }
}

impl LodBudget {
    /// The largest factor on the threshold.
    pub const MAX: f32 = 16.0;

    /// The scale for this frame; `picture_ms`: how long the last picture drawn while
    /// interacting took, once, when it is complete.
    pub fn next(&mut self, interacting: bool, picture_ms: Option<f64>) -> f32 {
        if !interacting {
            return 1.0;
        }
        if let Some(ms) = picture_ms {
            self.scale = adjust(self.scale, ms);
        }
        self.scale
    }
}

/// One step of [`LodBudget`]: ×1.5 over budget, ÷1.5 under half of it, within 1..=MAX.
pub fn adjust(scale: f32, frame_ms: f64) -> f32 {
    let next = if frame_ms > LOD_FRAME_BUDGET_MS {
        scale * 1.5
    } else if frame_ms < 0.5 * LOD_FRAME_BUDGET_MS {
        scale / 1.5
    } else {
        scale
    };
    next.clamp(1.0, LodBudget::MAX)
}

impl Detail {
    /// The detail for each of `views` views: full when `interacting` is false.
    pub fn for_frame(interacting: bool, adapter: wgpu::DeviceType, views: usize) -> Self {
        if !interacting {
            return Self::FULL;
        }
        let max_pixels = match adapter {
            wgpu::DeviceType::Cpu => CPU_INTERACTIVE_PIXELS / views.max(1) as u32,
            _ => u32::MAX,
        };
        Self { max_slices: INTERACTIVE_SLICES, max_pixels, lod_scale: INTERACTIVE_LOD_SCALE, ..Self::FULL }
    }
}

/// Whether the views are being interacted with: a button held anywhere (a drag in a view, a
/// slider in a panel) or the animation running.
pub fn interacting(ctx: &egui::Context, playing: bool) -> bool {
    playing || ctx.input(|i| i.pointer.any_down())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::VolumeSettings;

    #[test]
    fn still_frames_are_full() {
        let d = Detail::for_frame(false, wgpu::DeviceType::Cpu, 2);
        assert_eq!(d, Detail::FULL);
        assert_eq!(d.render_size([1000, 700]), [1000, 700]);
        assert_eq!(d.cloud(VolumeSettings::default()).slices, VolumeSettings::default().slices);
    }

    #[test]
    fn a_cpu_adapter_draws_fewer_pixels_while_interacting() {
        let d = Detail::for_frame(true, wgpu::DeviceType::Cpu, 2);
        assert_eq!(d.cloud(VolumeSettings::default()).slices, INTERACTIVE_SLICES);
        let [w, h] = d.render_size([510, 510]);
        assert!(w * h <= CPU_INTERACTIVE_PIXELS / 2 && w * h > CPU_INTERACTIVE_PIXELS / 2 - 2 * 256, "{w}x{h}");
        assert_eq!(w, h, "aspect kept");
        let [w, h] = d.render_size([800, 200]);
        assert!((w as f32 / h as f32 - 4.0).abs() < 0.05, "aspect kept: {w}x{h}");
        assert_eq!(d.render_size([100, 100]), [100, 100], "small views stay sharp");
    }

    #[test]
    fn the_level_of_detail_follows_the_frame_time_while_interacting() {
        assert_eq!(adjust(4.0, 120.0), 6.0, "slow: bigger points");
        assert_eq!(adjust(4.0, 10.0), 4.0 / 1.5, "fast: smaller points");
        assert_eq!(adjust(4.0, 40.0), 4.0, "within budget: kept");
        assert_eq!(adjust(1.0, 1.0), 1.0, "never finer than the threshold");
        assert_eq!(adjust(LodBudget::MAX, 500.0), LodBudget::MAX);
        let mut budget = LodBudget::default();
        assert_eq!(budget.next(true, None), INTERACTIVE_LOD_SCALE, "first frame of a drag");
        let slow = budget.next(true, Some(200.0));
        assert!(slow > INTERACTIVE_LOD_SCALE);
        assert_eq!(budget.next(false, Some(300.0)), 1.0, "still: full detail");
        assert_eq!(budget.next(true, None), slow, "a new drag starts where the last one ended");
    }

    #[test]
    fn a_gpu_draws_every_pixel_with_fewer_slices() {
        let d = Detail::for_frame(true, wgpu::DeviceType::DiscreteGpu, 1);
        assert_eq!(d.render_size([2560, 1440]), [2560, 1440]);
        assert_eq!(d.cloud(VolumeSettings::default()).slices, INTERACTIVE_SLICES);
    }
}
