//! Render settings the UI edits and the CLI parses: plain data.

use serde::{Deserialize, Serialize};

use super::opacity::DensityScale;
use super::transfer::{ClipPlane, Transfer};

/// How the volume is cut into slices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum SliceMode {
    /// Planes perpendicular to the view direction, cut from the grid box each frame.
    #[default]
    ViewAligned,
    /// Naka et al.: three stacks along the grid axes; the one facing the viewer is drawn.
    AxisAligned,
}

/// How a frame between two key volumes (a dihedral scan, Naka et al.) mixes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum Interpolation {
    /// Both volumes sampled and mixed per sample, ψ = (1−k)ψA + kψB: the interpolated orbital.
    #[default]
    Exact,
    /// Naka et al.'s real-time approximation: per slice, three blends (attenuate by A_i's
    /// opacity, B_i's past the middle; add (1−k)A_i; add kB_i), drawn as one.
    ThreePass,
    /// Naka et al.'s reference for it: per slice the two samples' colours and opacities mixed,
    /// α = (1−k)α_A + kα_B.
    AlphaMix,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VolumeSettings {
    pub visible: bool,
    pub mode: SliceMode,
    /// Number of slices through the volume.
    pub slices: u32,
    /// Opacity scale k1 in α = k1·ρ^k2 (per grid spacing of travel).
    pub k1: f32,
    /// Opacity shape k2; ρ is ψ² (orbitals) or the density, normalised to its maximum.
    pub k2: f32,
    /// Linear RGB for positive ψ (or the dense end of a density ramp).
    pub positive_color: [f32; 3],
    /// Linear RGB for negative ψ (or the thin end of a density ramp).
    pub negative_color: [f32; 3],
    /// Jang and Varetto's shaped transfer functions, gradient shading and boundary enhancement (when
    /// `transfer.kind` is `Shaped`; k1 and k2 apply to the power law).
    pub transfer: Transfer,
    /// The clipping plane a cloud had before the plane belonged to its object (sessions
    /// written then); read only, carried to the object when such a session opens.
    #[serde(default, rename = "clip", skip_serializing)]
    pub stored_clip: Option<ClipPlane>,
    /// How a density's values are scaled (orbitals: |ψ| / max |ψ| always).
    #[serde(default)]
    pub density_scale: DensityScale,
    /// Whether k1 is chosen from each grid shown ([`super::opacity::auto_k1`]); editing k1
    /// turns it off.
    #[serde(default = "yes")]
    pub auto_k1: bool,
    /// Whether slices are cut only through the bricks of the grid the transfer function shows
    /// (the same picture, fewer fragments); off draws every slice whole.
    #[serde(default = "yes")]
    pub skip_empty: bool,
}

fn yes() -> bool {
    true
}

impl Default for VolumeSettings {
    fn default() -> Self {
        Self {
            visible: true,
            mode: SliceMode::ViewAligned,
            slices: 192,
            k1: 0.2,
            k2: 0.6,
            positive_color: [0.90, 0.12, 0.10],
            negative_color: [0.10, 0.30, 0.95],
            transfer: Transfer::default(),
            stored_clip: None,
            density_scale: DensityScale::default(),
            auto_k1: true,
            skip_empty: true,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum AtomStyle {
    #[default]
    BallAndStick,
    SpaceFilling,
    /// Bonds as sticks, atoms as caps of the same radius.
    Sticks,
    /// Thick sticks with caps (proteins read well this way).
    Licorice,
    /// Bonds as one-pixel lines, unbonded atoms as small balls: the lightest for big structures.
    Lines,
    Hidden,
}

impl AtomStyle {
    pub const ALL: [AtomStyle; 6] = [
        AtomStyle::BallAndStick,
        AtomStyle::SpaceFilling,
        AtomStyle::Sticks,
        AtomStyle::Licorice,
        AtomStyle::Lines,
        AtomStyle::Hidden,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AtomStyle::BallAndStick => "ball and stick",
            AtomStyle::SpaceFilling => "space filling",
            AtomStyle::Sticks => "sticks",
            AtomStyle::Licorice => "licorice",
            AtomStyle::Lines => "lines",
            AtomStyle::Hidden => "hidden",
        }
    }
}

/// What colours the atoms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum AtomColoring {
    /// Jmol's CPK colours.
    #[default]
    Element,
    Chain,
    /// Each amino acid and nucleotide its own colour (Jmol's "amino" and "nucleic" schemes).
    Residue,
    /// Blue (lowest) through white to red (highest B-factor).
    BFactor,
    /// Helices magenta, strands yellow, the rest white, as the file declares them.
    Secondary,
}

impl AtomColoring {
    pub const ALL: [AtomColoring; 5] = [
        AtomColoring::Element,
        AtomColoring::Chain,
        AtomColoring::Residue,
        AtomColoring::BFactor,
        AtomColoring::Secondary,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AtomColoring::Element => "element",
            AtomColoring::Chain => "chain",
            AtomColoring::Residue => "residue",
            AtomColoring::BFactor => "B-factor",
            AtomColoring::Secondary => "secondary structure",
        }
    }
}

/// Where an isosurface lies: an absolute value (atomic units: ψ in bohr^−3/2, ρ in bohr^−3) or
/// a multiple of the grid's standard deviation σ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum IsoLevel {
    Absolute(f32),
    Sigma(f32),
}

impl IsoLevel {
    /// The absolute value for a grid whose values have standard deviation `sigma`.
    pub fn value(self, sigma: f64) -> f32 {
        match self {
            IsoLevel::Absolute(v) => v.abs(),
            IsoLevel::Sigma(s) => (s.abs() as f64 * sigma) as f32,
        }
    }
}

/// Opaque isosurfaces of the volume shown: ψ = ±v for an orbital in the two sign colours, ρ = v
/// for a density.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IsosurfaceSettings {
    pub visible: bool,
    pub level: IsoLevel,
    /// Linear RGB of the ψ = +v surface.
    pub positive_color: [f32; 3],
    /// Linear RGB of the ψ = −v surface.
    pub negative_color: [f32; 3],
    /// Linear RGB of a density's surface.
    pub density_color: [f32; 3],
    /// Drawn translucent with Koide and Miyata's optics, in exact depth order with every other
    /// translucent surface.
    #[serde(default)]
    pub translucent: bool,
    #[serde(default)]
    pub optics: super::OpticsPreset,
    /// Per-channel factors on the preset's coefficients.
    #[serde(default)]
    pub tuning: super::translucency::OpticsTuning,
    /// Coloured by another quantity of the object at each vertex (the electrostatic potential
    /// on a density surface), on a diverging map, instead of its own colour.
    #[serde(default)]
    pub color_by: Option<super::Source>,
    /// The |value| at which those colours saturate (a.u.); automatic (the 98th percentile of
    /// |value| over the vertices) when `None`.
    #[serde(default)]
    pub color_range: Option<f32>,
    /// The map those colours are taken from.
    #[serde(default)]
    pub color_scheme: super::coloring::ColorScheme,
    /// Only the vertices whose colouring value lies in this range keep their colours; the rest
    /// are grey (an NCI plot's brushed spike lit on its surface).
    #[serde(default)]
    pub color_window: Option<[f32; 2]>,
}

impl Default for IsosurfaceSettings {
    fn default() -> Self {
        Self {
            visible: false,
            // The value Avogadro, Jmol and GaussView open orbitals at.
            level: IsoLevel::Absolute(0.05),
            positive_color: [0.85, 0.10, 0.08],
            negative_color: [0.08, 0.25, 0.85],
            density_color: [0.55, 0.62, 0.75],
            translucent: false,
            optics: super::OpticsPreset::default(),
            tuning: Default::default(),
            color_by: None,
            color_range: None,
            color_scheme: Default::default(),
            color_window: None,
        }
    }
}

impl IsosurfaceSettings {
    /// The `n`-th (from the smallest value) of `count` nested levels at `level`, told apart by
    /// colour: an orbital's two colours paler inward, a density's shells along a ramp from
    /// cool outside to warm inside.
    pub fn nested(&self, level: IsoLevel, n: usize, count: usize) -> Self {
        const RAMP: [[f32; 3]; 5] =
            [[0.15, 0.35, 0.95], [0.1, 0.75, 0.85], [0.2, 0.8, 0.3], [0.95, 0.8, 0.15], [0.9, 0.2, 0.1]];
        let pale = |c: [f32; 3]| c.map(|v| v + (1.0 - v) * (1.0 - 0.6f32.powi(n as i32)));
        let density_color = match count {
            0 | 1 => self.density_color,
            _ => {
                let t = n as f32 / (count - 1) as f32 * (RAMP.len() - 1) as f32;
                let (i, f) = ((t as usize).min(RAMP.len() - 2), t.fract());
                let f = if t as usize >= RAMP.len() - 1 { 1.0 } else { f };
                std::array::from_fn(|k| RAMP[i][k] + (RAMP[i + 1][k] - RAMP[i][k]) * f)
            }
        };
        Self {
            visible: true,
            level,
            positive_color: pale(self.positive_color),
            negative_color: pale(self.negative_color),
            density_color,
            ..*self
        }
    }

    /// How a surface of this setting in `color` is drawn.
    pub fn look(&self, color: [f32; 3]) -> super::translucency::SurfaceLook {
        let optics = self.translucent.then(|| self.tuning.apply(self.optics.optics(color)));
        super::translucency::SurfaceLook { color, optics, lod_px: None }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    pub volume: VolumeSettings,
    pub atoms: AtomStyle,
    pub atom_colors: AtomColoring,
    pub iso: IsosurfaceSettings,
    /// Linear RGB background.
    pub background: [f32; 3],
    /// How much the farthest atoms darken (0: off; big structures open at
    /// [`BIG_STRUCTURE_DEPTH_CUE`]).
    pub depth_cue: f32,
    /// Factors on the atom style's ball and stick radii (1: as the style draws them).
    pub ball_scale: f32,
    pub stick_scale: f32,
    /// The clipping plane, its offset from the centre of what is drawn.
    pub clip: ClipPlane,
}

/// Above this many atoms a file opens space filling (ball and stick is sub-pixel noise at that
/// scale), depth cued and, when it has several chains, coloured by chain.
pub const BIG_STRUCTURE_ATOMS: usize = 20_000;
/// The depth cue a big structure opens with: front reads from back without hiding the back.
pub const BIG_STRUCTURE_DEPTH_CUE: f32 = 0.6;

impl RenderSettings {
    /// These settings as a file of `atoms` atoms in `chains` chains first opens with them.
    pub fn for_structure(mut self, atoms: usize, chains: usize) -> Self {
        if atoms > BIG_STRUCTURE_ATOMS && self.atoms == AtomStyle::BallAndStick {
            self.atoms = AtomStyle::SpaceFilling;
            self.depth_cue = self.depth_cue.max(BIG_STRUCTURE_DEPTH_CUE);
            if chains > 1 && self.atom_colors == AtomColoring::Element {
                self.atom_colors = AtomColoring::Chain;
            }
        }
        self
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            volume: VolumeSettings::default(),
            atoms: AtomStyle::default(),
            atom_colors: AtomColoring::default(),
            iso: IsosurfaceSettings::default(),
            background: [0.02, 0.02, 0.03],
            depth_cue: 0.0,
            ball_scale: 1.0,
            stick_scale: 1.0,
            clip: ClipPlane::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn big_structures_open_space_filling_depth_cued_and_by_chain() {
        let small = RenderSettings::default().for_structure(BIG_STRUCTURE_ATOMS, 4);
        assert_eq!(small, RenderSettings::default());
        let big = RenderSettings::default().for_structure(BIG_STRUCTURE_ATOMS + 1, 4);
        assert_eq!((big.atoms, big.atom_colors), (AtomStyle::SpaceFilling, AtomColoring::Chain));
        assert_eq!(big.depth_cue, BIG_STRUCTURE_DEPTH_CUE);
        // What the user chose stays: a style other than the default, a stronger cue.
        let chosen = RenderSettings { atoms: AtomStyle::Licorice, depth_cue: 0.9, ..RenderSettings::default() };
        assert_eq!(chosen.for_structure(1_000_000, 4), chosen);
        let one_chain = RenderSettings::default().for_structure(BIG_STRUCTURE_ATOMS + 1, 1);
        assert_eq!(one_chain.atom_colors, AtomColoring::Element);
    }

    #[test]
    fn nested_levels_run_from_cool_to_warm_for_a_density_and_pale_for_an_orbital() {
        let base = IsosurfaceSettings { translucent: true, ..Default::default() };
        let outer = base.nested(IsoLevel::Absolute(0.01), 0, 4);
        let inner = base.nested(IsoLevel::Absolute(0.3), 3, 4);
        assert!(outer.visible && outer.translucent && outer.level == IsoLevel::Absolute(0.01));
        assert!(outer.density_color[2] > outer.density_color[0], "outside blue: {:?}", outer.density_color);
        assert!(inner.density_color[0] > inner.density_color[2], "inside red: {:?}", inner.density_color);
        assert_eq!(outer.positive_color, base.positive_color);
        assert!(inner.positive_color.iter().zip(base.positive_color).all(|(p, b)| *p >= b));
        assert_eq!(base.nested(IsoLevel::Sigma(2.0), 0, 1).density_color, base.density_color);
    }
}
