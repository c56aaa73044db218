//! An offscreen colour + depth target, and reading it back to an image.

use super::{COLOR_FORMAT, GpuError};

pub struct OffscreenTarget {
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    /// The same pixels viewed as plain `Rgba8Unorm`: sampling returns the sRGB-encoded bytes,
    /// which is what egui expects of a user texture.
    pub encoded_view: wgpu::TextureView,
    pub size: [u32; 2],
}

impl OffscreenTarget {
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Self {
        let size = [size[0].max(1), size[1].max(1)];
        let extent = wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 };
        let color = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen colour"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[wgpu::TextureFormat::Rgba8Unorm],
        });
        let color_view = color.create_view(&Default::default());
        let encoded_view = color.create_view(&wgpu::TextureViewDescriptor {
            label: Some("offscreen colour, encoded"),
            format: Some(wgpu::TextureFormat::Rgba8Unorm),
            ..Default::default()
        });
        Self { color, color_view, encoded_view, size }
    }

    /// Copies the colour texture to memory (blocking) as an sRGB RGBA image.
    pub fn read_rgba(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<image::RgbaImage, GpuError> {
        let pixels = super::readback::read_texture(device, queue, &self.color, 4)?;
        image::RgbaImage::from_raw(self.size[0], self.size[1], pixels)
            .ok_or_else(|| GpuError::Readback("size mismatch".into()))
    }
}

/// A 2D target of the frame's `size` in `format`, renderable and usable as `usage` says.
pub fn target_texture(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
        view_formats: &[],
    })
}
