//! Adapter, device and queue: which GPU, which features, and what it cannot do.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found ({0}); install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers libvulkan1)"
    )]
    NoAdapter(String),
    #[error(
        "the adapter is {found}, but a {wanted} adapter was required (install mesa-vulkan-drivers libvulkan1 for lavapipe)"
    )]
    WrongAdapter { wanted: String, found: String },
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("the volume is {dims:?} points, but this GPU holds 3D textures of at most {max} per side")]
    VolumeTooLarge { dims: [usize; 3], max: u32 },
    #[error("reading back the frame failed: {0}")]
    Readback(String),
    /// Validation or out-of-memory, caught by [`guarded`] instead of wgpu's default panic.
    #[error("the GPU refused the work: {0}")]
    Rejected(String),
}

/// Runs `work`, catching the validation and out-of-memory errors it causes on `device` (error
/// scopes) as [`GpuError::Rejected`], so a texture over a limit or a full GPU becomes a message
/// in the window instead of a crash. Scopes are per thread: `work` must not hand the device to
/// another thread.
pub fn guarded<T>(device: &wgpu::Device, work: impl FnOnce() -> Result<T, GpuError>) -> Result<T, GpuError> {
    let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = work();
    let invalid = pollster::block_on(validation.pop());
    let full = pollster::block_on(memory.pop());
    match invalid.or(full) {
        Some(e) => Err(GpuError::Rejected(e.to_string())),
        None => result,
    }
}

/// Which adapter to open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AdapterPreference {
    /// The fastest adapter there is (the viewer).
    #[default]
    HighPerformance,
    /// A Vulkan CPU adapter (Mesa lavapipe): reproducible output for tests and golden images.
    LavapipeOnly,
}

/// Handles on one device; cloning gives another handle on the same device (for a background
/// job or a second view).
#[derive(Clone)]
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Format of volume textures: R32Float when it can be filtered, else R16Float.
    pub volume_format: wgpu::TextureFormat,
}

/// 64-bit integers with every storage atomic: the compute rasteriser keeps depth and id in one
/// word where a device has them.
pub const INT64_ATOMICS: wgpu::Features =
    wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS);

/// Features the renderer uses when the adapter has them.
pub fn wanted_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    let features = adapter.features();
    let int64 = if features.contains(INT64_ATOMICS) { INT64_ATOMICS } else { wgpu::Features::empty() };
    (features & wgpu::Features::FLOAT32_FILTERABLE) | int64
}

/// Device descriptor with the features the renderer uses and the adapter's own limits
/// (volumes need big 3D textures and storage buffers; WebGPU defaults are too small).
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("orbcloud device"),
        required_features: wanted_features(adapter),
        required_limits: adapter.limits(),
        ..Default::default()
    }
}

/// The volume texture format a device opened with `features` can filter.
pub fn volume_format_for(features: wgpu::Features) -> wgpu::TextureFormat {
    if features.contains(wgpu::Features::FLOAT32_FILTERABLE) {
        wgpu::TextureFormat::R32Float
    } else {
        wgpu::TextureFormat::R16Float
    }
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?}, driver {})", info.name, info.backend, info.device_type, info.driver_info)
}

impl GpuContext {
    /// Opens a device without a window.
    pub fn headless(pref: AdapterPreference) -> Result<Self, GpuError> {
        let instance = |backends| {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            desc.backends = backends;
            wgpu::Instance::new(desc)
        };
        let adapter = match pref {
            AdapterPreference::LavapipeOnly => {
                let backends = wgpu::Backends::VULKAN;
                let adapters = pollster::block_on(instance(backends).enumerate_adapters(backends));
                let found: Vec<String> = adapters.iter().map(|a| describe(&a.get_info())).collect();
                adapters
                    .into_iter()
                    .find(|a| {
                        let i = a.get_info();
                        i.backend == wgpu::Backend::Vulkan && i.device_type == wgpu::DeviceType::Cpu
                    })
                    .ok_or_else(|| GpuError::WrongAdapter {
                        wanted: "Vulkan CPU (lavapipe)".into(),
                        found: if found.is_empty() { "none".into() } else { found.join("; ") },
                    })?
            }
            AdapterPreference::HighPerformance => {
                let options = wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    ..Default::default()
                };
                // Vulkan, Metal or DirectX 12 first; OpenGL only when none is there. Probing
                // OpenGL starts EGL, which prints warnings of its own (XDG_RUNTIME_DIR, DRI2)
                // wherever there is no display: ssh, cron, CI.
                let primary = pollster::block_on(instance(wgpu::Backends::PRIMARY).request_adapter(&options));
                match primary {
                    Ok(adapter) => adapter,
                    Err(_) => pollster::block_on(instance(wgpu::Backends::all()).request_adapter(&options))
                        .map_err(|e| GpuError::NoAdapter(e.to_string()))?,
                }
            }
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&device_descriptor(&adapter)))
            .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Self::from_parts(adapter, device, queue))
    }

    /// Wraps a device someone else opened (the window's), reading back what it can do.
    pub fn from_parts(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let info = adapter.get_info();
        let volume_format = volume_format_for(device.features());
        log::info!("GPU: {}; volume textures {volume_format:?}", describe(&info));
        Self { adapter, device, queue, info, volume_format }
    }

    /// One line naming the adapter, for logs and `bench` output.
    pub fn describe(&self) -> String {
        describe(&self.info)
    }
}
