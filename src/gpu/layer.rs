//! One object of the scene on the GPU ([`Layer`]) and the registry of what a layer draws
//! ([`Representations`]): a new kind of drawing is its own file implementing
//! [`Representation`] and one line in the `representations!` list below. The renderer walks the
//! registry in every phase; it names no representation except to place a cloud's walk.

use std::ops::{Deref, DerefMut};

use glam::{Mat4, Vec3};

use super::arrows::ArrowsPass;
use super::atoms::AtomsPass;
use super::frame::{Draw, Representation, Shared};
use super::isosurface::IsosurfacePass;
use super::plane_frame::PlaneFramePass;
use super::volume::{VolumePass, VolumeTexture};
use super::{GpuContext, GpuError};
use crate::model::GridSpec;
use crate::model::cartesian::CartesianExpansion;
use crate::model::octree::box_corners;
use crate::model::{Molecule, VolumeGrid};
use crate::scene::{AtomColors, AtomStyle, ClipPlane};

/// Makes [`Representations`] from a list of `name: Pass` lines: each pass made once per
/// renderer, instanced per layer, cleared with it, and drawn in the listed order within a phase.
macro_rules! representations {
    ($($(#[$doc:meta])* $name:ident: $pass:ty,)*) => {
        /// What a layer draws, each a long-lived instance of its pass.
        pub struct Representations {
            $($(#[$doc])* pub $name: $pass,)*
        }

        impl Representations {
            /// The first layer's: every pass made, its pipelines built against `shared`.
            pub(super) fn new(ctx: &GpuContext, shared: &Shared<'_>) -> Self {
                Self { $($name: <$pass as Representation>::new(ctx, shared),)* }
            }

            /// Empty passes sharing these ones' pipelines.
            pub(super) fn instance(&self, ctx: &GpuContext) -> Self {
                Self { $($name: Representation::instance(&self.$name, ctx),)* }
            }

            fn clear(&mut self, ctx: &GpuContext) {
                $(Representation::clear(&mut self.$name, ctx);)*
            }

            /// Every pass, in the order they draw within a phase.
            pub(super) fn drawers(&self) -> Vec<&dyn Draw> {
                vec![$(&self.$name as &dyn Draw,)*]
            }

            pub(super) fn drawers_mut(&mut self) -> Vec<&mut dyn Draw> {
                vec![$(&mut self.$name as &mut dyn Draw,)*]
            }
        }
    };
}

representations! {
    atoms: AtomsPass,
    /// Arrows (a normal mode's displacements) drawn with the atoms.
    arrows: ArrowsPass,
    surfaces: IsosurfacePass,
    volume: VolumePass,
    /// The plane map's frame where the plane lies.
    plane_frame: PlaneFramePass,
}

/// One object of the scene on the GPU: its representations, drawn where `world_from_object`
/// places them. Its index in the renderer is the object number its pick ids carry.
pub struct Layer {
    pub representations: Representations,
    /// A rigid placement (rotation and translation).
    pub world_from_object: Mat4,
    /// Whether the layer is drawn at all.
    pub visible: bool,
    /// The molecule's bounds in the object's frame, padded by the largest atom.
    molecule_bounds: Option<(Vec3, Vec3)>,
    /// The object's clipping plane, its offset measured from `clip_centre` (object frame).
    pub clip: ClipPlane,
    pub clip_centre: Vec3,
}

/// A layer's passes are reached as its own fields: `layer.atoms`, `layer.volume`.
impl Deref for Layer {
    type Target = Representations;
    fn deref(&self) -> &Representations {
        &self.representations
    }
}

impl DerefMut for Layer {
    fn deref_mut(&mut self) -> &mut Representations {
        &mut self.representations
    }
}

impl Layer {
    pub(super) fn new(representations: Representations) -> Self {
        Self {
            representations,
            world_from_object: Mat4::IDENTITY,
            visible: true,
            molecule_bounds: None,
            clip: ClipPlane::default(),
            clip_centre: Vec3::ZERO,
        }
    }

    /// Shows a molecule's atoms in a style, coloured by element.
    pub fn set_molecule(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle) {
        self.set_atoms(ctx, molecule, style, None);
    }

    /// Shows a molecule's atoms in a style and colours (by element when `None`).
    pub fn set_atoms(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle, colors: Option<&AtomColors>) {
        self.atoms.set_molecule(ctx, molecule, style, colors);
        self.molecule_bounds = padded_bounds(molecule);
    }

    /// Moves the layer's atoms to `molecule`'s positions in place when only they changed (the
    /// same atoms and bonds); false when they must be uploaded anew with [`Self::set_atoms`].
    pub fn move_atoms(&mut self, ctx: &GpuContext, molecule: &Molecule) -> bool {
        let moved = self.atoms.move_atoms(ctx, molecule);
        if moved {
            self.molecule_bounds = padded_bounds(molecule);
        }
        moved
    }

    /// Shows `grid` as the layer's cloud. A grid over this device's limits is shown at every
    /// `step`-th point instead ([`super::volume::fitting_step`]); returns the step (1: whole).
    pub fn set_volume(&mut self, ctx: &GpuContext, grid: Option<&VolumeGrid>) -> Result<usize, GpuError> {
        let step = grid.map_or(1, |g| {
            super::volume::fitting_step(g.dims, super::volume::texel_bytes(ctx.volume_format), &ctx.device.limits())
        });
        match grid {
            Some(g) if step > 1 => self.volume.set_volume(ctx, Some(&g.subsampled(step)))?,
            _ => self.volume.set_volume(ctx, grid)?,
        }
        Ok(step)
    }

    /// Shows a volume already on the GPU (a filled GTO grid).
    pub fn set_volume_texture(&mut self, ctx: &GpuContext, volume: VolumeTexture) {
        self.volume.set_texture(ctx, Some(volume));
    }

    /// Shows a value between two key volumes of a scan (Naka et al., docs/references.md), mixed (1−k):k.
    pub fn set_morph(
        &mut self,
        ctx: &GpuContext,
        a: VolumeTexture,
        b: VolumeTexture,
        k: f32,
        mode: crate::scene::Interpolation,
    ) {
        self.volume.set_morph(ctx, a, b, k, mode);
    }

    /// Shows an orbital evaluated per fragment from its basis functions (Jang and Varetto's direct mode),
    /// its opacity and gradient scaled to `(max |ψ|, max |∇ψ|)`.
    pub fn set_direct(
        &mut self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        geometry: &GridSpec,
        scale: (f64, f64),
    ) {
        self.volume.set_direct(ctx, expansion, geometry, scale);
    }

    /// Empties the layer (it draws nothing), keeping its pipelines.
    pub fn clear(&mut self, ctx: &GpuContext) {
        self.representations.clear(ctx);
        self.molecule_bounds = None;
    }

    /// The world-space box around everything the layer draws.
    pub(super) fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let volume = self.volume.volume().map(|v| v.grid_box.corners().to_vec()).unwrap_or_default();
        let atoms = self.molecule_bounds.map(|(lo, hi)| box_corners(lo, hi).to_vec()).unwrap_or_default();
        let points: Vec<Vec3> =
            volume.into_iter().chain(atoms).map(|p| self.world_from_object.transform_point3(p)).collect();
        let first = *points.first()?;
        Some(points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
    }
}

/// `molecule`'s box padded by the largest space-filling radius, so that the near and far planes
/// never clip an atom.
fn padded_bounds(molecule: &Molecule) -> Option<(Vec3, Vec3)> {
    molecule.bounds().map(|(lo, hi)| (lo.as_vec3() - 4.5, hi.as_vec3() + 4.5))
}
