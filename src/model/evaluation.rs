//! A wavefunction's quantities on points and grids: orbitals, densities, the spin density and the
//! electrostatic potential, each sent to the evaluator that serves it best (the axis-separated
//! sums of [`super::separable`] on axis-aligned grids, row by row otherwise, [`super::esp`] for
//! the potential, [`super::nci`] for the quantities of the density's first and second
//! derivatives). The evaluators build on [`PreparedBasis`]; this layer above them chooses.

use glam::DVec3;
use rayon::prelude::*;

use super::esp::Potential;
use super::gto::{GridSpec, PreparedBasis, spin_weight};
use super::molecule::Molecule;
use super::nci::{self, WavefunctionDensity};
use super::orbitals::{Quantity, Wavefunction};
use super::separable;

impl PreparedBasis {
    /// An orbital (or any combination of basis functions) on a grid, cube order.
    pub fn eval_grid(&self, coefficients: &[f64], grid: &GridSpec) -> Vec<f64> {
        self.grid_sum(&[(coefficients, 1.0)], false, grid)
    }

    /// As [`Self::eval_grid`], stored as f32 (what [`super::VolumeGrid`] holds).
    pub fn eval_grid_f32(&self, coefficients: &[f64], grid: &GridSpec) -> Vec<f32> {
        if separable::is_axis_aligned(grid) {
            return separable::grid_sum(self, &[(coefficients, 1.0)], false, grid);
        }
        self.eval_grid(coefficients, grid).into_iter().map(|v| v as f32).collect()
    }

    /// Only the basis functions in `subset` of an orbital, on a grid.
    pub fn eval_grid_subset(&self, coefficients: &[f64], subset: &[usize], grid: &GridSpec) -> Vec<f64> {
        self.eval_grid(&self.masked_coefficients(coefficients, subset), grid)
    }

    /// Electron density on a grid.
    pub fn density_grid(&self, wf: &Wavefunction, grid: &GridSpec) -> Vec<f64> {
        let sets: Vec<(&[f64], f64)> = wf
            .orbitals
            .iter()
            .filter(|o| o.occupation != 0.0)
            .map(|o| (o.coefficients.as_slice(), o.occupation))
            .collect();
        self.grid_sum(&sets, true, grid)
    }

    /// Σ w ψ² of orbitals with weights (any sign) on a grid: a density given by its natural
    /// orbitals, such as an excited state's ([`super::excited_density`]).
    pub fn weighted_density_grid(&self, sets: &[(&[f64], f64)], grid: &GridSpec) -> Vec<f64> {
        self.grid_sum(sets, true, grid)
    }

    /// `quantity` at each of `points` (bohr), in parallel: what `eval` prints and what colours a
    /// surface by a wavefunction's quantity.
    pub fn quantity_at_points(
        &self,
        wf: &Wavefunction,
        molecule: &Molecule,
        quantity: Quantity,
        points: &[DVec3],
    ) -> Vec<f64> {
        if quantity == Quantity::Potential {
            return Potential::new(molecule, wf).at_points(points);
        }
        if quantity.from_density_derivatives() {
            let source = WavefunctionDensity::with_basis(self.clone(), wf);
            return nci::quantity_at_points(&source, quantity, points);
        }
        points.par_chunks(1024).flat_map_iter(|chunk| self.quantity_at(wf, quantity, chunk)).collect()
    }

    /// An orbital, the total density, the spin density or the electrostatic potential (of
    /// `molecule`'s nuclei and `wf`'s electrons) on a grid.
    pub fn quantity_grid(
        &self,
        wf: &Wavefunction,
        molecule: &Molecule,
        quantity: Quantity,
        grid: &GridSpec,
    ) -> Vec<f64> {
        match quantity {
            Quantity::Potential => Potential::new(molecule, wf).on_grid(grid),
            Quantity::Orbital(i) => self.eval_grid(&wf.orbitals[i].coefficients, grid),
            Quantity::BasisFunction(k) => self.eval_grid(&self.unit_coefficients(k), grid),
            Quantity::Density => self.density_grid(wf, grid),
            Quantity::SpinDensity => self.spin_density_grid(wf, grid),
            Quantity::DifferenceDensity | Quantity::Attachment | Quantity::Detachment | Quantity::ExcitedDensity => {
                self.grid_sum(&state_sets(wf, quantity), true, grid)
            }
            // Made of the document's listed transitions, not of the wavefunction alone:
            // `crate::evaluate::quantity_grid` evaluates it.
            Quantity::TransitionDensity(_) => vec![f64::NAN; grid.len()],
            Quantity::ReducedGradient
            | Quantity::NciGradient
            | Quantity::NciCloud
            | Quantity::SignLambda2Rho
            | Quantity::DensityLaplacian => {
                let points: Vec<DVec3> = (0..grid.dims[0])
                    .flat_map(|i| (0..grid.dims[1]).flat_map(move |j| (0..grid.dims[2]).map(move |k| (i, j, k))))
                    .map(|(i, j, k)| grid.point(i, j, k))
                    .collect();
                let source = WavefunctionDensity::with_basis(self.clone(), wf);
                nci::quantity_at_points(&source, quantity, &points)
            }
        }
    }

    /// [`Self::quantity_grid`] in single precision (an orbital evaluated straight to f32).
    pub fn quantity_grid_f32(
        &self,
        wf: &Wavefunction,
        molecule: &Molecule,
        quantity: Quantity,
        grid: &GridSpec,
    ) -> Vec<f32> {
        match quantity {
            Quantity::Orbital(i) => self.eval_grid_f32(&wf.orbitals[i].coefficients, grid),
            Quantity::BasisFunction(k) => self.eval_grid_f32(&self.unit_coefficients(k), grid),
            _ => self.quantity_grid(wf, molecule, quantity, grid).iter().map(|&v| v as f32).collect(),
        }
    }

    /// Spin density on a grid.
    pub fn spin_density_grid(&self, wf: &Wavefunction, grid: &GridSpec) -> Vec<f64> {
        let sets: Vec<(&[f64], f64)> = wf
            .orbitals
            .iter()
            .map(|o| (o.coefficients.as_slice(), spin_weight(wf, o.occupation, o.spin)))
            .filter(|(_, w)| *w != 0.0)
            .collect();
        self.grid_sum(&sets, true, grid)
    }

    /// Σ_s w_s ψ_s (or Σ_s w_s ψ_s² when `square`) on a grid: separated along the axes when
    /// the grid's steps run along them ([`separable`]), row by row otherwise.
    fn grid_sum(&self, sets: &[(&[f64], f64)], square: bool, grid: &GridSpec) -> Vec<f64> {
        if separable::is_axis_aligned(grid) {
            return separable::grid_sum(self, sets, square, grid);
        }
        self.grid_sum_rows(sets, square, grid)
    }
}

/// The orbitals and weights of an excited-state quantity of `wf` (none when `wf` holds no
/// excited state, or `quantity` is no such quantity: its values are then 0).
pub(super) fn state_sets(wf: &Wavefunction, quantity: Quantity) -> Vec<(&[f64], f64)> {
    match (&wf.excited, quantity.state_part()) {
        (Some(excited), Some(part)) => excited.sets(part),
        _ => Vec::new(),
    }
}
