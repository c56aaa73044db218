//! A molecular surface as a representation of an object: which kind, its grid and probe, and
//! how it looks. Plain, serialisable data; [`crate::model::surface`] builds it.

use serde::{Deserialize, Serialize};

use crate::model::surface::{Sphere, SurfaceKind, SurfaceParams};
use crate::model::units::BOHR_PER_ANGSTROM;

use super::translucency::SurfaceLook;
use super::{AtomColoring, IsosurfaceSettings};

/// Which molecular surface, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum SurfaceChoice {
    #[default]
    Off,
    /// Gaussian density of the atoms (VMD's QuickSurf, Mol*'s default).
    Gaussian,
    /// Solvent-excluded (Connolly's) surface.
    SolventExcluded,
}

impl SurfaceChoice {
    pub const ALL: [SurfaceChoice; 3] = [SurfaceChoice::Off, SurfaceChoice::Gaussian, SurfaceChoice::SolventExcluded];

    pub fn name(self) -> &'static str {
        match self {
            SurfaceChoice::Off => "off",
            SurfaceChoice::Gaussian => "Gaussian",
            SurfaceChoice::SolventExcluded => "solvent-excluded",
        }
    }

    pub fn kind(self) -> Option<SurfaceKind> {
        match self {
            SurfaceChoice::Off => None,
            SurfaceChoice::Gaussian => Some(SurfaceKind::Gaussian),
            SurfaceChoice::SolventExcluded => Some(SurfaceKind::SolventExcluded),
        }
    }
}

/// An object's molecular surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SurfaceSettings {
    pub choice: SurfaceChoice,
    /// Grid spacing, Å; `None` picks one from the molecule's size ([`SurfaceParams::auto`]).
    pub resolution: Option<f32>,
    /// Probe radius of the solvent-excluded surface, Å.
    pub probe: f32,
    /// α of the Gaussian surface.
    pub smoothness: f32,
    /// Linear RGB.
    pub color: [f32; 3],
    /// Translucent with Koide and Miyata's optics, in exact order with every other translucent surface.
    pub translucent: bool,
    /// Lee et al.'s level of detail: parts of the surface smaller than this many pixels on screen
    /// are drawn as points (0: every triangle); the viewer scales it up while the view is
    /// dragged. Opaque surfaces only.
    pub lod_px: f32,
    /// Coloured by the nearest atom (its element, chain, residue, B-factor or secondary
    /// structure); `None`: `color` everywhere.
    pub color_by: Option<AtomColoring>,
    /// Coloured by the object's volume sampled on the surface (an electrostatic potential
    /// cube, an orbital): negative red through white to positive blue, as potentials are
    /// shown; takes precedence over `color_by`.
    pub color_by_volume: bool,
}

impl Default for SurfaceSettings {
    fn default() -> Self {
        Self {
            choice: SurfaceChoice::Off,
            resolution: None,
            probe: 1.4,
            smoothness: SurfaceParams::SMOOTHNESS as f32,
            // A pale blue-grey that shows shape by its shading.
            color: [0.62, 0.68, 0.80],
            translucent: false,
            lod_px: Self::LOD_PX,
            color_by: None,
            color_by_volume: false,
        }
    }
}

impl SurfaceSettings {
    /// What to build for these atoms; `None` when the surface is off.
    pub fn params(&self, spheres: &[Sphere]) -> Option<SurfaceParams> {
        let kind = self.choice.kind()?;
        let mut p = SurfaceParams::auto(kind, spheres);
        if let Some(r) = self.resolution {
            p.resolution = r as f64 * BOHR_PER_ANGSTROM;
        }
        p.probe = self.probe as f64 * BOHR_PER_ANGSTROM;
        p.smoothness = self.smoothness as f64;
        Some(p)
    }

    /// The level of detail's default threshold, pixels: at rest only cells under about a pixel
    /// become points (a coarser version of the mesh costs less than points of cells any bigger;
    /// measured on the 10⁵-atom SES: 3 px drew 1.1× slower than 1 px); while dragging the
    /// threshold grows with the frame time.
    pub const LOD_PX: f32 = 1.0;

    /// How the mesh is drawn: opaque in its colour (with the level of detail), or with the
    /// default translucent optics.
    pub fn look(&self) -> SurfaceLook {
        // Coloured by atoms: the vertices carry the colour.
        let color = if self.color_by.is_some() || self.color_by_volume { [1.0; 3] } else { self.color };
        let look = IsosurfaceSettings { translucent: self.translucent, ..Default::default() }.look(color);
        SurfaceLook { lod_px: (!self.translucent && self.lod_px > 0.0).then_some(self.lod_px), ..look }
    }

    /// Whether a mesh built with `other` serves these settings too (only the look differs).
    pub fn same_geometry(&self, other: &SurfaceSettings) -> bool {
        (self.choice, self.resolution, self.probe, self.smoothness)
            == (other.choice, other.resolution, other.probe, other.smoothness)
    }
}
