//! Evaluating a wavefunction's quantities for display: orbitals filled on the GPU (a 3D texture,
//! read back once for isosurfaces), densities on the CPU, NCI's quantities by the GPU's pass of
//! the density's derivatives on a GPU (the CPU's on a CPU adapter, or when the pass fails), Jang and Varetto's direct mode (no grid: the
//! orbital's range measured from CPU samples, a grid filled only when isosurfaces want one), on
//! grids the device holds; and the opacity a cloud of the values starts with.

pub mod arithmetic;
pub mod interaction;
pub mod meshes;

use crate::gpu::density_hessian::DensityHessianPass;
use crate::gpu::gto::{GtoFillPass, read_volume, volume_from_texture};
use crate::gpu::renderer::Layer;
use crate::gpu::volume::VolumeTexture;
use crate::gpu::{GpuContext, GpuError};
use crate::model::bricks::{BRICK_CELLS, BrickRanges};
use crate::model::cartesian::CartesianExpansion;
use crate::model::extent::quantity_box;
use crate::model::grid::ValueKind;
use crate::model::gto::{GridSpec, PreparedBasis, SampledRange};
use crate::model::orbitals::Quantity;
use crate::model::{Document, VolumeGrid};

/// The grid a wavefunction's `quantity` is evaluated on, `points` per axis: the box where it
/// decays to 1 % of its largest |value| ([`crate::model::extent::quantity_box`]).
pub fn orbital_geometry(doc: &Document, quantity: Quantity, points: usize) -> Option<GridSpec> {
    let (lo, hi) = quantity_box(doc.wavefunction.as_ref()?, &doc.molecule, quantity)?;
    Some(GridSpec::cube(lo, hi, points))
}

/// How to show a quantity of a wavefunction.
#[derive(Debug, Clone, PartialEq)]
pub struct WavefunctionView {
    pub quantity: Quantity,
    /// Jang and Varetto's direct mode (orbitals only): evaluate per slice sample, no grid.
    pub direct: bool,
    /// Points per axis of the evaluation grid.
    pub points: usize,
    /// Per basis function, whether it contributes to an orbital (the atomic-orbital
    /// selector); `None`: all.
    pub functions: Option<Vec<bool>>,
    /// In direct mode, whether the values on a grid are wanted as well (isosurfaces are shown);
    /// without, none is filled. Grid mode always fills one.
    pub grid: bool,
}

/// Lattice points per axis direct mode measures an orbital on (4096 CPU samples).
pub const SAMPLES_PER_AXIS: usize = 16;

/// A wavefunction's quantity evaluated for display, ready for a layer. Made by
/// [`evaluate_wavefunction`], which may run on any thread (the viewer's jobs); shown with
/// [`Evaluated::show`] on the thread that owns the renderer.
pub struct Evaluated {
    pub values: Values,
    cloud: Cloud,
}

/// The values behind an evaluated quantity's picture.
#[derive(Debug, Clone, Default)]
pub struct Values {
    /// The values on the evaluation grid: what isosurfaces are cut from. `None` in direct mode
    /// unless the view asked for a grid.
    pub grid: Option<VolumeGrid>,
    /// Direct mode: the orbital measured at samples (its range, gradient scale and a coarse
    /// lattice of values).
    pub sampled: Option<Sampled>,
}

/// An orbital measured at CPU samples instead of on a grid (direct mode).
#[derive(Debug, Clone)]
pub struct Sampled {
    pub range: SampledRange,
    /// Points per axis of the evaluation grid over the same box (the step k1 refers to).
    pub points: usize,
}

impl Values {
    /// What stands for the quantity's values (its σ, its opacity): the grid, else the samples.
    pub fn shown(&self) -> Option<&VolumeGrid> {
        self.grid.as_ref().or(self.sampled.as_ref().map(|s| &s.range.samples))
    }

    /// Sets `volume.k1` from the grid ([`auto_opacity`]), else from the samples
    /// ([`auto_opacity_sampled`]).
    pub fn auto_opacity(&self, volume: &mut crate::scene::VolumeSettings) {
        match (&self.grid, &self.sampled) {
            (Some(grid), _) => auto_opacity(volume, grid),
            (None, Some(sampled)) => auto_opacity_sampled(volume, sampled),
            (None, None) => {}
        }
    }
}

enum Cloud {
    /// An orbital filled on the GPU, already a texture.
    Texture(VolumeTexture),
    /// Jang and Varetto's direct mode: the orbital evaluated per slice sample, scaled to its measured
    /// (max |ψ|, max |∇ψ|).
    Direct(CartesianExpansion, GridSpec, (f64, f64)),
    /// Values computed on the CPU (densities), uploaded when shown.
    Values,
}

/// Evaluates what `view` asks for of `doc`'s wavefunction: orbitals on the GPU (a filled
/// texture, read back once for the grid's values; in direct mode only when `view.grid` asks),
/// densities on the CPU. `None` when the document has no wavefunction.
pub fn evaluate_wavefunction(
    ctx: &GpuContext,
    fill: &GtoFillPass,
    doc: &Document,
    view: &WavefunctionView,
) -> Result<Option<Evaluated>, GpuError> {
    let (Some(wf), Some(geometry)) = (&doc.wavefunction, orbital_geometry(doc, view.quantity, view.points)) else {
        return Ok(None);
    };
    let prepared = PreparedBasis::new(&wf.basis);
    // An orbital (restricted to the chosen functions) or a bare basis function: a combination
    // of basis functions, filled on the GPU.
    let combination = match view.quantity {
        Quantity::Orbital(i) => Some(restricted(&wf.orbitals[i].coefficients, view.functions.as_deref())),
        Quantity::BasisFunction(k) => Some(prepared.unit_coefficients(k)),
        // Densities and the potential are evaluated on the CPU, the quantities of the
        // density's derivatives by the GPU's pass where it is faster ([`derivatives_on_gpu`]).
        Quantity::Density
        | Quantity::SpinDensity
        | Quantity::Potential
        | Quantity::ReducedGradient
        | Quantity::NciGradient
        | Quantity::NciCloud
        | Quantity::SignLambda2Rho
        | Quantity::DensityLaplacian
        | Quantity::DifferenceDensity
        | Quantity::Attachment
        | Quantity::Detachment
        | Quantity::ExcitedDensity
        | Quantity::TransitionDensity(_) => None,
    };
    match combination {
        Some(coefficients) => {
            let expansion = CartesianExpansion::from_coefficients(&prepared, &coefficients);
            if view.direct {
                // The shader evaluates ψ and its analytic gradient per sample; what scales them
                // is measured on the CPU, so no grid is filled unless its values are wanted.
                let range = prepared.sampled_range(&coefficients, &geometry, SAMPLES_PER_AXIS);
                let grid = if view.grid {
                    let texture = fill.fill(ctx, &expansion, &geometry)?;
                    Some(VolumeGrid::new(
                        "orbital",
                        geometry.dims,
                        geometry.world_from_grid,
                        read_volume(ctx, &texture)?,
                    ))
                } else {
                    None
                };
                let cloud = Cloud::Direct(expansion, geometry, (range.max_abs, range.max_grad));
                let sampled = Some(Sampled { range, points: geometry.dims[0] });
                return Ok(Some(Evaluated { values: Values { grid, sampled }, cloud }));
            }
            let texture = fill.fill(ctx, &expansion, &geometry)?;
            // The filled values give the range that scales the opacity (and the gradient scale).
            let grid = VolumeGrid::new("orbital", geometry.dims, geometry.world_from_grid, read_volume(ctx, &texture)?);
            let mut volume = volume_from_texture(texture, &geometry, grid.stats.max_abs);
            volume.max_grad = grid.max_gradient().max(1e-30) as f32;
            volume.bricks = Some(std::sync::Arc::new(BrickRanges::of(&grid, BRICK_CELLS)));
            let values = Values { grid: Some(grid), sampled: None };
            Ok(Some(Evaluated { values, cloud: Cloud::Texture(volume) }))
        }
        None => {
            let label = crate::scene::Source::Wavefunction(view.quantity).name(doc);
            let values = match view.quantity.from_density_derivatives() && derivatives_on_gpu(ctx) {
                true => derivative_quantity_on_gpu(ctx, doc, view.quantity, &geometry),
                false => quantity_grid(doc, &prepared, view.quantity, &geometry),
            };
            let grid = VolumeGrid::new(label, geometry.dims, geometry.world_from_grid, values);
            let values = Values { grid: Some(grid), sampled: None };
            Ok(Some(Evaluated { values, cloud: Cloud::Values }))
        }
    }
}

/// `quantity` of `doc` on `grid` (its wavefunction's basis `prepared`): what
/// [`PreparedBasis::quantity_grid_f32`] gives, and a state's transition density from the
/// document's listed transitions (NaN where the document has none for it: callers check
/// [`crate::scene::Source::exists_in`]).
pub fn quantity_grid(doc: &Document, prepared: &PreparedBasis, quantity: Quantity, grid: &GridSpec) -> Vec<f32> {
    let Some(wf) = &doc.wavefunction else { return vec![f32::NAN; grid.len()] };
    match quantity {
        Quantity::TransitionDensity(n) => match crate::model::transition::TransitionDensity::of_state(doc, n) {
            Some(t) => t.grid(wf, prepared, grid),
            None => vec![f32::NAN; grid.len()],
        },
        _ => prepared.quantity_grid_f32(wf, &doc.molecule, quantity, grid),
    }
}

/// Whether the quantities of the density's derivatives (NCI's) are evaluated by the GPU's pass
/// ([`DensityHessianPass`]) on `ctx`'s device: on a GPU, not on a CPU adapter (lavapipe), where
/// the CPU reference on every thread is faster than the same cores running the pass
/// (docs/performance.md).
pub fn derivatives_on_gpu(ctx: &GpuContext) -> bool {
    ctx.info.device_type != wgpu::DeviceType::Cpu
}

/// A quantity of the density's derivatives of `doc`'s wavefunction on `grid` by the GPU's pass
/// (in its own error scopes), or by the CPU, with a warning in the log, when the pass fails.
pub fn derivative_quantity_on_gpu(ctx: &GpuContext, doc: &Document, quantity: Quantity, grid: &GridSpec) -> Vec<f32> {
    let Some(wf) = &doc.wavefunction else {
        return vec![f32::NAN; grid.len()];
    };
    let gpu = crate::gpu::context::guarded(&ctx.device, || {
        DensityHessianPass::new(ctx).quantity_grid(ctx, wf, quantity, grid)
    });
    gpu.unwrap_or_else(|e| {
        log::warn!("{}: the GPU's density derivatives failed ({e}); evaluated on the CPU", doc.source);
        PreparedBasis::new(&wf.basis).quantity_grid_f32(wf, &doc.molecule, quantity, grid)
    })
}

/// An orbital's coefficients with those of the functions not in `keep` set to 0 (the orbital
/// restricted to the chosen atomic orbitals); all of them without a selection.
pub fn restricted(coefficients: &[f64], keep: Option<&[bool]>) -> Vec<f64> {
    match keep {
        Some(keep) => coefficients
            .iter()
            .zip(keep.iter().chain(std::iter::repeat(&true)))
            .map(|(&c, &on)| if on { c } else { 0.0 })
            .collect(),
        None => coefficients.to_vec(),
    }
}

/// [`evaluate_wavefunction`] on a grid this device holds: `view.points` per side, or fewer when
/// that many are over `limits` or the device refuses the memory, with a note saying so. Runs
/// its GPU work in error scopes on the calling thread.
pub fn evaluate_within(
    ctx: &GpuContext,
    fill: &GtoFillPass,
    doc: &Document,
    view: &WavefunctionView,
    limits: &wgpu::Limits,
) -> Result<(Option<Evaluated>, Option<String>), GpuError> {
    let requested = view.points;
    // p³ R32Float values must fit both the 3D texture's side and the memory budget.
    let mut points = requested;
    while points > 8 && crate::gpu::volume::fitting_step([points; 3], 4, limits) > 1 {
        points = points * 7 / 8;
    }
    loop {
        let attempt = WavefunctionView { points, ..view.clone() };
        match crate::gpu::context::guarded(&ctx.device, || evaluate_wavefunction(ctx, fill, doc, &attempt)) {
            Err(GpuError::Rejected(_) | GpuError::VolumeTooLarge { .. }) if points > 16 => points = points * 3 / 4,
            result => {
                let note = (points < requested).then(|| {
                    format!(
                        "{}: {requested} points per side are more than this GPU holds; evaluated on {points}",
                        doc.source
                    )
                });
                return result.map(|e| (e, note));
            }
        }
    }
}

impl Evaluated {
    /// Values computed on the CPU, shown as a cloud uploaded from them.
    pub fn of_values(grid: VolumeGrid) -> Self {
        Self { values: Values { grid: Some(grid), sampled: None }, cloud: Cloud::Values }
    }

    /// Shows the cloud in `layer`; returns the values behind it.
    pub fn show(self, ctx: &GpuContext, layer: &mut Layer) -> Result<Values, GpuError> {
        match self.cloud {
            Cloud::Texture(volume) => layer.set_volume_texture(ctx, volume),
            Cloud::Direct(expansion, geometry, scale) => layer.set_direct(ctx, &expansion, &geometry, scale),
            Cloud::Values => {
                layer.set_volume(ctx, self.values.grid.as_ref())?;
            }
        }
        Ok(self.values)
    }
}

/// Sets `volume.k1` from `grid` ([`crate::scene::opacity::auto_k1`]) when `volume.auto_k1`
/// asks for it: the first picture of any grid has contrast.
pub fn auto_opacity(volume: &mut crate::scene::VolumeSettings, grid: &VolumeGrid) {
    if volume.auto_k1 {
        let signed = grid.kind == ValueKind::Signed;
        let max = grid.stats.max_abs as f32;
        volume.k1 =
            crate::scene::opacity::auto_k1(&grid.values, grid.dims, signed, max, volume.density_scale, volume.k2);
    }
}

/// [`auto_opacity`] from direct mode's samples: the law summed along the sample lattice's lines,
/// scaled to the evaluation grid's step (lines through it hold (points − 1)/(n − 1) times as
/// many points), the law normalised to the measured max |ψ| as the shader does.
pub fn auto_opacity_sampled(volume: &mut crate::scene::VolumeSettings, sampled: &Sampled) {
    if volume.auto_k1 {
        let samples = &sampled.range.samples;
        let signed = samples.kind == ValueKind::Signed;
        let max = sampled.range.max_abs as f32;
        let k1 =
            crate::scene::opacity::auto_k1(&samples.values, samples.dims, signed, max, volume.density_scale, volume.k2);
        let finer = (sampled.points.max(2) - 1) as f32 / (samples.dims[0].max(2) - 1) as f32;
        volume.k1 = (k1 / finer).clamp(0.005, 2.0);
    }
}
