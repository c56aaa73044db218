//! What to draw and how: camera and render settings. Plain, serialisable data; no wgpu.

pub mod camera;
pub mod coloring;
pub mod detail;
pub mod excited_view;
pub mod framing;
pub mod limits;
pub mod molsurface;
pub mod objects;
pub mod occupancy;
pub mod opacity;
pub mod quantity;
pub mod scan_state;
pub mod selection;
pub mod settings;
pub mod slicing;
pub mod transfer;
pub mod translucency;
pub mod vibration;
pub mod view;

pub use camera::Camera;
pub use coloring::AtomColors;
pub use molsurface::{SurfaceChoice, SurfaceSettings};
pub use objects::{Changes, ObjectState, Panes, Placement, QuantityChanges, Session, changes};
pub use opacity::DensityScale;
pub use quantity::{AtomLook, ESP_MAP_DENSITY, Evaluation, Fragments, QuantityState, Source};
pub use scan_state::{LegacyScan, ScanState};
pub use settings::{
    AtomColoring, AtomStyle, Interpolation, IsoLevel, IsosurfaceSettings, RenderSettings, SliceMode, VolumeSettings,
};
pub use transfer::{ClipPlane, Shape, Transfer, TransferKind};
pub use translucency::{Optics, OpticsPreset};
pub use view::{ViewDirection, ViewPreset};
