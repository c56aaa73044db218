//! `orbcloud._native`: orbcloud's library as a Python extension. The pure-Python package
//! (`python/orbcloud/`) wraps it; nothing here computes what the library does not.

use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use glam::DVec3;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use orbcloud::formats::{self, LoadError, cube_write};
use orbcloud::model::basis::{Basis, Shell, ShellKind};
use orbcloud::model::excited::{ExcitedState, ExcitedStates, Transition};
use orbcloud::model::excited_density::ExcitedDensity;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{MolecularOrbital, OrbitalSpec, Quantity, Spin, Wavefunction};
use orbcloud::model::scan::FrameContent;
use orbcloud::model::{Atom, Document, GridSpec, VolumeGrid};
use orbcloud::scene::Camera;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

// The command line's library: `render` parses and draws exactly as `orbcloud render` does.
use orbcloud::cli;

pyo3::create_exception!(_native, NativeLoadError, pyo3::exceptions::PyException);

/// A load error as `(message, file, line)`: the line when the reader names one.
fn load_error(e: &LoadError) -> PyErr {
    let (file, line) = located(e);
    NativeLoadError::new_err((e.to_string(), file, line))
}

fn located(e: &LoadError) -> (Option<String>, Option<usize>) {
    match e {
        LoadError::Parse(p) => (Some(p.file.clone()), Some(p.line)),
        LoadError::Named { inner, .. } => located(inner),
        LoadError::Io { path, .. } | LoadError::NotText { path, .. } | LoadError::UnknownFormat { path } => {
            (Some(path.clone()), None)
        }
    }
}

fn runtime(e: impl std::fmt::Display) -> PyErr {
    PyRuntimeError::new_err(e.to_string())
}

/// A document (a file's atoms, grids and wavefunction) held by Python.
#[pyclass(name = "Document", module = "orbcloud._native", frozen)]
struct PyDocument {
    doc: Document,
    /// The basis prepared for evaluation, the first time a value is asked for.
    prepared: OnceLock<PreparedBasis>,
}

impl PyDocument {
    fn new(doc: Document) -> Self {
        Self { doc, prepared: OnceLock::new() }
    }

    fn wavefunction(&self) -> PyResult<&Wavefunction> {
        self.doc.wavefunction.as_ref().ok_or_else(|| {
            PyValueError::new_err(format!(
                "{} holds no basis set or orbitals (a Molden, fchk, wfn, wfx, MKL or JSON file is needed)",
                self.doc.source
            ))
        })
    }

    fn prepared(&self) -> PyResult<(&Wavefunction, &PreparedBasis)> {
        let wf = self.wavefunction()?;
        Ok((wf, self.prepared.get_or_init(|| PreparedBasis::new(&wf.basis))))
    }

    /// The quantity `kind` names: "orbital" (`index` into all orbitals), "density",
    /// "spin_density", "esp", "reduced_gradient", "sign_lambda2_rho", "density_laplacian",
    /// "basis_function" (`index` of the function).
    fn quantity(&self, kind: &str, index: usize) -> PyResult<Quantity> {
        let wf = self.wavefunction()?;
        let q = match kind {
            "orbital" if index < wf.orbitals.len() => Quantity::Orbital(index),
            "basis_function" if index < wf.basis.n_functions() => Quantity::BasisFunction(index),
            "density" => Quantity::Density,
            "spin_density" => Quantity::SpinDensity,
            "esp" => Quantity::Potential,
            "reduced_gradient" => Quantity::ReducedGradient,
            "sign_lambda2_rho" => Quantity::SignLambda2Rho,
            "density_laplacian" => Quantity::DensityLaplacian,
            "difference_density" | "attachment" | "detachment" | "excited_density" => {
                if wf.excited.is_none() {
                    return Err(PyValueError::new_err(format!(
                        "{}: the {} needs an excited state's density, and this document holds none",
                        self.doc.source,
                        kind.replace('_', " ")
                    )));
                }
                match kind {
                    "difference_density" => Quantity::DifferenceDensity,
                    "attachment" => Quantity::Attachment,
                    "detachment" => Quantity::Detachment,
                    _ => Quantity::ExcitedDensity,
                }
            }
            _ => return Err(PyValueError::new_err(format!("no {kind} {index} in {}", self.doc.source))),
        };
        Ok(q)
    }
}

/// Atomic numbers, charges, positions (n × 3) and ghost flags.
type AtomArrays<'py> = (Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Vec<bool>);
/// A grid's values and its world-from-grid matrix.
type GridArrays<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray2<f64>>);
/// NCIPLOT's two grids (100·sign(λ₂)ρ, s) and their world-from-grid matrix.
type NciArrays<'py> = (Bound<'py, PyArray3<f32>>, Bound<'py, PyArray3<f32>>, Bound<'py, PyArray2<f64>>);
/// A scan's frame: the coordinate's value, the value as text, the frame.
type ScanFrame = (f64, String, PyDocument);
/// A shell: atom index, l, pure, exponents, coefficients of normalised primitives.
type ShellParts = (usize, u32, bool, Vec<f64>, Vec<f64>);
/// A transition: from, to (1-based orbital numbers within their spin), coefficient, spin
/// ("alpha", "beta" or ""), whether it is a de-excitation.
type TransitionParts = (usize, usize, f64, String, bool);
/// An excited state: number (1-based), energy (eV), total energy (hartree), oscillator
/// strength, spin, symmetry, ⟨S²⟩, transitions.
type StateParts = (usize, f64, Option<f64>, Option<f64>, String, String, Option<f64>, Vec<TransitionParts>);
/// A state as Python reads it: [`StateParts`] with its wavelength (nm) after the energy.
type StateRow = (usize, f64, f64, Option<f64>, Option<f64>, String, String, Option<f64>, Vec<TransitionParts>);

/// A square matrix of `n` rows as a row-major vector.
fn square(m: &PyReadonlyArray2<'_, f64>, n: usize, what: &str) -> PyResult<Vec<f64>> {
    let a = m.as_array();
    if a.nrows() != n || a.ncols() != n {
        return Err(PyValueError::new_err(format!("{what} has shape {:?}; expected ({n}, {n})", a.shape())));
    }
    Ok(a.iter().copied().collect())
}

fn spin_of(spin: &str) -> PyResult<Spin> {
    match spin {
        "alpha" => Ok(Spin::Alpha),
        "beta" => Ok(Spin::Beta),
        _ => Err(PyValueError::new_err(format!("spin must be \"alpha\" or \"beta\", got {spin:?}"))),
    }
}

fn points_of(points: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<DVec3>> {
    let a = points.as_array();
    if a.ncols() != 3 {
        return Err(PyValueError::new_err(format!("points must have shape (n, 3), got {:?}", a.shape())));
    }
    Ok(a.rows().into_iter().map(|r| DVec3::new(r[0], r[1], r[2])).collect())
}

/// `quantity` at every point, on all cores.
fn values_at(doc: &Document, prepared: &PreparedBasis, q: Quantity, points: &[DVec3]) -> Vec<f64> {
    match &doc.wavefunction {
        Some(wf) => prepared.quantity_at_points(wf, &doc.molecule, q, points),
        None => vec![f64::NAN; points.len()],
    }
}

/// The grid `quantity` is shown on: `points` per side over the box where it decays.
fn grid_spec(doc: &Document, wf: &Wavefunction, q: Quantity, points: usize) -> PyResult<GridSpec> {
    let (lo, hi) = orbcloud::model::extent::quantity_box(wf, &doc.molecule, q)
        .ok_or_else(|| PyValueError::new_err(format!("{}: no atoms", doc.source)))?;
    let spec = GridSpec::cube(lo, hi, points.clamp(2, 1024));
    if spec.dims.iter().map(|&d| d as u64).product::<u64>() > formats::MAX_GRID_VALUES {
        return Err(PyValueError::new_err(format!("a {:?} grid is too large", spec.dims)));
    }
    Ok(spec)
}

#[pymethods]
impl PyDocument {
    #[getter]
    fn source(&self) -> &str {
        &self.doc.source
    }

    #[getter]
    fn title(&self) -> &str {
        &self.doc.title
    }

    /// Atomic numbers, nuclear charges, positions (bohr, n × 3) and ghost flags.
    fn atoms<'py>(&self, py: Python<'py>) -> AtomArrays<'py> {
        let atoms = &self.doc.molecule.atoms;
        let z: Vec<u32> = atoms.iter().map(|a| a.z).collect();
        let charge: Vec<f64> = atoms.iter().map(|a| a.charge).collect();
        let xyz = Array2::from_shape_fn((atoms.len(), 3), |(i, k)| atoms[i].position[k]);
        let ghost = atoms.iter().map(|a| a.ghost).collect();
        (z.into_pyarray(py), charge.into_pyarray(py), xyz.into_pyarray(py), ghost)
    }

    /// Bonds as pairs of atom indices.
    fn bonds(&self) -> Vec<(u32, u32)> {
        self.doc.molecule.bonds.iter().map(|b| (b.a, b.b)).collect()
    }

    /// Whether the document has a basis set and orbitals.
    #[getter]
    fn has_wavefunction(&self) -> bool {
        self.doc.wavefunction.is_some()
    }

    /// Every orbital, alpha first: (energy, occupation, spin, label).
    fn orbitals(&self) -> Vec<(f64, f64, &'static str, String)> {
        let Some(wf) = &self.doc.wavefunction else { return Vec::new() };
        wf.orbitals
            .iter()
            .map(|o| {
                let spin = if o.spin == Spin::Alpha { "alpha" } else { "beta" };
                (o.energy, o.occupation, spin, o.symmetry.clone())
            })
            .collect()
    }

    #[getter]
    fn restricted(&self) -> Option<bool> {
        self.doc.wavefunction.as_ref().map(|wf| wf.restricted)
    }

    /// The writer recognised, the repair applied and max |CᵀSC − I| after it.
    fn normalization(&self) -> Option<(String, String, f64)> {
        let n = &self.doc.wavefunction.as_ref()?.normalization;
        Some((n.program.clone(), n.repair.clone(), n.residual))
    }

    #[getter]
    fn n_basis(&self) -> usize {
        self.doc.wavefunction.as_ref().map_or(0, |wf| wf.basis.n_functions())
    }

    /// Names of the basis functions, as `--basis-function` takes them ("O1 2px").
    fn basis_function_names(&self) -> Vec<String> {
        let Some(wf) = &self.doc.wavefunction else { return Vec::new() };
        (0..wf.basis.n_functions())
            .map(|k| orbcloud::model::basis_labels::function_name(&self.doc.molecule, &wf.basis, k).unwrap_or_default())
            .collect()
    }

    /// The orbitals' coefficients over the basis functions (n_orbitals × n_basis), in orbcloud's
    /// basis order (unit-normalised functions).
    fn coefficients<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let wf = self.wavefunction()?;
        let n = wf.basis.n_functions();
        let c = Array2::from_shape_fn((wf.orbitals.len(), n), |(i, k)| wf.orbitals[i].coefficients[k]);
        Ok(c.into_pyarray(py))
    }

    /// Data sets of the file (cube volumes): their names.
    fn volume_names(&self) -> Vec<String> {
        self.doc.volumes.iter().map(|v| v.label.clone()).collect()
    }

    /// Messages about parts of the file that could not be read while the rest opened.
    fn problems(&self) -> Vec<String> {
        self.doc.problems.clone()
    }

    /// The index (into all orbitals) of `spec` ("homo", "lumo+1", "homo-2", or a 1-based number
    /// of that spin) of `spin`.
    fn resolve(&self, spec: &str, spin: &str) -> PyResult<usize> {
        let wf = self.wavefunction()?;
        let parsed: OrbitalSpec = spec.parse().map_err(|e| PyValueError::new_err(format!("orbital {spec:?}: {e}")))?;
        let spin = spin_of(spin)?;
        wf.resolve(parsed, spin).ok_or_else(|| {
            PyValueError::new_err(format!("no orbital {spec:?} of spin {spin:?} in {}", self.doc.source))
        })
    }

    /// Values of a quantity at `points` (bohr, n × 3), computed without the GIL on all cores.
    fn values<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        kind: &str,
        index: usize,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.quantity(kind, index)?;
        let points = points_of(&points)?;
        let (_, prepared) = self.prepared()?;
        let values = py.detach(|| values_at(&self.doc, prepared, q, &points));
        Ok(values.into_pyarray(py))
    }

    /// A quantity on a grid of `points` per side over the box where it decays: the values
    /// (x slowest) and the grid's 4 × 4 world-from-grid matrix (bohr).
    fn grid<'py>(&self, py: Python<'py>, kind: &str, index: usize, points: usize) -> PyResult<GridArrays<'py>> {
        let q = self.quantity(kind, index)?;
        let (wf, prepared) = self.prepared()?;
        let spec = grid_spec(&self.doc, wf, q, points)?;
        let values = py.detach(|| prepared.quantity_grid(wf, &self.doc.molecule, q, &spec));
        let [nx, ny, nz] = spec.dims;
        let values = Array3::from_shape_vec((nx, ny, nz), values).map_err(runtime)?;
        let m = spec.world_from_grid.to_cols_array_2d();
        let matrix = Array2::from_shape_fn((4, 4), |(r, c)| m[c][r]);
        Ok((values.into_pyarray(py), matrix.into_pyarray(py)))
    }

    /// The excited states the document lists: (program, method, the state whose density it
    /// holds, states), `None` when it lists none.
    fn states(&self) -> Option<(String, String, Option<usize>, Vec<StateRow>)> {
        let x = self.doc.excited.as_ref()?;
        let states = (x.states.iter())
            .map(|s| {
                let transitions = (s.transitions.iter())
                    .map(|t| (t.from, t.to, t.coefficient, t.spin.clone(), t.deexcitation))
                    .collect();
                (
                    s.number,
                    s.energy_ev,
                    s.wavelength_nm(),
                    s.total_energy_hartree,
                    s.oscillator_strength,
                    s.spin.clone(),
                    s.symmetry.clone(),
                    s.s_squared,
                    transitions,
                )
            })
            .collect();
        let density_of = self.density_state();
        Some((x.program.clone(), x.method.clone(), density_of, states))
    }

    /// The excited state whose density the document holds (1-based), if any.
    #[getter]
    fn density_state(&self) -> Option<usize> {
        Some(self.doc.wavefunction.as_ref()?.excited.as_ref()?.state)
    }

    /// The electrons the held excited state's density moves: the attachment's and the
    /// detachment's integrals (Σ λ over λ > 0, −Σ λ over λ < 0).
    fn electrons_moved(&self) -> Option<(f64, f64)> {
        let e = self.doc.wavefunction.as_ref()?.excited.as_ref()?;
        Some((e.electrons_moved(), e.electrons_detached()))
    }

    /// This document with the excited states `states` listed, as a program's (`program`,
    /// `method`) would be.
    fn with_states(&self, program: String, method: String, states: Vec<StateParts>) -> PyDocument {
        let states = states
            .into_iter()
            .map(|(number, energy_ev, total, f, spin, symmetry, s_squared, transitions)| ExcitedState {
                number,
                energy_ev,
                total_energy_hartree: total,
                oscillator_strength: f,
                spin,
                symmetry,
                s_squared,
                transitions: transitions
                    .into_iter()
                    .map(|(from, to, coefficient, spin, deexcitation)| Transition {
                        from,
                        to,
                        coefficient,
                        spin,
                        deexcitation,
                    })
                    .collect(),
                // PySCF's restricted amplitudes are normalised to ½.
                amplitudes_normalised_to_one: false,
            })
            .collect();
        let mut doc = self.doc.clone();
        let density_of = self.density_state();
        doc.excited = Some(ExcitedStates { program, method, states, density_of, note: String::new() });
        PyDocument::new(doc)
    }

    /// This document holding excited state `state`'s density: the ground state's and the
    /// excited state's total density matrices (n_basis × n_basis, over orbcloud's functions in
    /// its order), their difference diagonalised as Head-Gordon's attachment and detachment.
    fn with_state_density(
        &self,
        py: Python<'_>,
        state: usize,
        source: String,
        ground: PyReadonlyArray2<'_, f64>,
        excited: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<PyDocument> {
        let wf = self.wavefunction()?;
        let n = wf.basis.n_functions();
        let (ground, excited) = (square(&ground, n, "ground")?, square(&excited, n, "excited")?);
        let density = py
            .detach(|| ExcitedDensity::new(state, &source, &wf.basis, ground, excited))
            .map_err(PyValueError::new_err)?;
        let mut doc = self.doc.clone();
        if let Some(wf) = doc.wavefunction.as_mut() {
            wf.excited = Some(std::sync::Arc::new(density));
        }
        if let Some(x) = doc.excited.as_mut() {
            x.density_of = Some(state);
        }
        Ok(PyDocument::new(doc))
    }

    /// What `orbcloud info` prints of the document, or its `--json` form.
    fn info(&self, py: Python<'_>, json: bool) -> PyResult<String> {
        py.detach(|| {
            if json {
                serde_json::to_string_pretty(&cli::info::describe(&self.doc)).map_err(runtime)
            } else {
                Ok(cli::info::text(&self.doc))
            }
        })
    }

    /// Writes a quantity on a grid of `points` per side as a Gaussian cube file.
    fn write_cube(&self, py: Python<'_>, path: PathBuf, kind: &str, index: usize, points: usize) -> PyResult<()> {
        let q = self.quantity(kind, index)?;
        let (wf, prepared) = self.prepared()?;
        let spec = grid_spec(&self.doc, wf, q, points)?;
        let values = py.detach(|| orbcloud::evaluate::quantity_grid(&self.doc, prepared, q, &spec));
        let label = match q {
            Quantity::Orbital(i) => {
                let o = &wf.orbitals[i];
                let n = wf.of_spin(o.spin).position(|(j, _)| j == i).map_or(0, |p| p + 1);
                format!("MO {n} ({:?}) E={:.6} Eh occ={:.3} {}", o.spin, o.energy, o.occupation, o.symmetry)
            }
            Quantity::Density => "total electron density".into(),
            Quantity::SpinDensity => "spin density".into(),
            Quantity::Potential => "electrostatic potential (a.u.)".into(),
            Quantity::BasisFunction(k) => format!("basis function {k}"),
            Quantity::ReducedGradient => "reduced density gradient".into(),
            Quantity::NciGradient => "NCI reduced density gradient".into(),
            Quantity::NciCloud => "NCI cloud".into(),
            Quantity::SignLambda2Rho => "sign(lambda2)*rho (a.u.)".into(),
            Quantity::DensityLaplacian => "Laplacian of the electron density (a.u.)".into(),
            Quantity::DifferenceDensity | Quantity::Attachment | Quantity::Detachment | Quantity::ExcitedDensity => {
                let state = wf.excited.as_ref().map_or(0, |e| e.state);
                let what = match q {
                    Quantity::DifferenceDensity => "difference density",
                    Quantity::Attachment => "attachment density",
                    Quantity::Detachment => "detachment density",
                    _ => "excited-state density",
                };
                format!("{what} (state {state})")
            }
            Quantity::TransitionDensity(n) => format!("transition density (state {n})"),
        };
        let id = match q {
            Quantity::Orbital(i) => wf.of_spin(wf.orbitals[i].spin).position(|(j, _)| j == i).map_or(0, |p| p + 1),
            _ => 0,
        };
        let grid = VolumeGrid::new(&label, spec.dims, spec.world_from_grid, values);
        let written = std::fs::File::create(&path).and_then(|file| {
            let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
            let title = format!("{} {label}", self.doc.source);
            cube_write::write_to(&mut w, &title, &label, &self.doc.molecule, &[(&grid, id as i64)])
        });
        written.map_err(|e| pyo3::exceptions::PyOSError::new_err(format!("writing {}: {e}", path.display())))
    }
}

/// NCIPLOT's two grids of documents whose densities add, as `orbcloud nci` writes them:
/// 100·sign(λ₂)ρ and s (x slowest, both 100 at the points cut) and the grid's 4 × 4
/// world-from-grid matrix (bohr). `step` and `margin` in Å; `grid_like`: a cube file whose grid
/// is taken.
#[pyfunction]
#[pyo3(signature = (docs, promolecular=false, step=None, margin=None, cut=None, rdg_cut=None, intermolecular=false, grid_like=None))]
#[allow(clippy::too_many_arguments, reason = "the Python function's keyword arguments, one each")]
fn nci<'py>(
    py: Python<'py>,
    docs: Vec<Bound<'py, PyDocument>>,
    promolecular: bool,
    step: Option<f64>,
    margin: Option<f64>,
    cut: Option<f64>,
    rdg_cut: Option<f64>,
    intermolecular: bool,
    grid_like: Option<PathBuf>,
) -> PyResult<NciArrays<'py>> {
    let grid = match grid_like {
        Some(path) => {
            let doc = py.detach(|| formats::load(&path)).map_err(|e| load_error(&e))?;
            let grid = doc
                .volumes
                .first()
                .ok_or_else(|| PyValueError::new_err(format!("{}: no grid in it", path.display())))?;
            Some(GridSpec { dims: grid.dims, world_from_grid: grid.world_from_grid })
        }
        None => None,
    };
    let docs: Vec<&Document> = docs.iter().map(|d| &d.get().doc).collect();
    let names: Vec<String> = docs.iter().map(|d| d.source.clone()).collect();
    let options = cli::NciOptions { promolecular, step, margin, grid, cut, rdg_cut, intermolecular };
    let result =
        py.detach(|| cli::nci_of(&docs, &names, &options)).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    let [nx, ny, nz] = result.spec.dims;
    let dens = Array3::from_shape_vec((nx, ny, nz), result.grids.dens).map_err(runtime)?;
    let grad = Array3::from_shape_vec((nx, ny, nz), result.grids.grad).map_err(runtime)?;
    let m = result.spec.world_from_grid.to_cols_array_2d();
    let matrix = Array2::from_shape_fn((4, 4), |(r, c)| m[c][r]);
    Ok((dens.into_pyarray(py), grad.into_pyarray(py), matrix.into_pyarray(py)))
}

/// Reads a file as the viewer opens it.
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyDocument> {
    let doc = py.detach(|| formats::load(&path)).map_err(|e| load_error(&e))?;
    Ok(PyDocument::new(doc))
}

/// A document from a wavefunction given in orbcloud's conventions (`model::basis`): atoms
/// (Z, charge, bohr positions), shells (atom, l, pure, exponents, coefficients of normalised
/// primitives), orbitals' coefficients over unit-normalised functions (n_orbitals × n_basis),
/// energies, occupations and spins. The contractions are normalised here and the orbitals
/// checked (CᵀSC) as a file's are.
#[pyfunction]
#[allow(clippy::too_many_arguments, reason = "the Python function's keyword arguments, one each")]
fn from_parts(
    source: String,
    program: String,
    z: Vec<u32>,
    charges: Vec<f64>,
    positions: PyReadonlyArray2<'_, f64>,
    shells: Vec<ShellParts>,
    coefficients: PyReadonlyArray2<'_, f64>,
    energies: PyReadonlyArray1<'_, f64>,
    occupations: PyReadonlyArray1<'_, f64>,
    spins: Vec<String>,
    labels: Vec<String>,
    restricted: bool,
) -> PyResult<PyDocument> {
    let positions = points_of(&positions)?;
    if z.len() != positions.len() || charges.len() != positions.len() {
        return Err(PyValueError::new_err("atomic numbers, charges and positions differ in length"));
    }
    let atoms: Vec<Atom> = z
        .iter()
        .zip(&charges)
        .zip(&positions)
        .map(|((&z, &charge), &position)| Atom { z, charge, position, ghost: z == 0 })
        .collect();
    let mut basis = Basis::default();
    for (atom, l, pure, exponents, coefficients) in shells {
        let center = atoms
            .get(atom)
            .map(|a| a.position)
            .ok_or_else(|| PyValueError::new_err(format!("a shell on atom {atom}, of {}", atoms.len())))?;
        if l > orbcloud::model::basis::MAX_L || exponents.len() != coefficients.len() || exponents.is_empty() {
            return Err(PyValueError::new_err(format!("unsupported shell on atom {atom}: l={l}")));
        }
        let kind = if pure && l >= 2 { ShellKind::Pure } else { ShellKind::Cartesian };
        basis.shells.push(Shell { atom, center, l, kind, exponents, coefficients });
    }
    // Unit-normalised contractions: the coefficients given refer to unit-normalised functions.
    let mut wf = Wavefunction { basis, orbitals: Vec::new(), restricted, ..Default::default() };
    formats::wavefunction::normalize_contractions(&mut wf);
    let c = coefficients.as_array();
    let (energies, occupations) = (energies.as_array(), occupations.as_array());
    let n = wf.basis.n_functions();
    if c.ncols() != n {
        return Err(PyValueError::new_err(format!("coefficients have {} columns for {n} basis functions", c.ncols())));
    }
    let count = c.nrows();
    if [energies.len(), occupations.len(), spins.len(), labels.len()].iter().any(|&m| m != count) {
        return Err(PyValueError::new_err("energies, occupations, spins and labels must have one entry per orbital"));
    }
    for i in 0..count {
        wf.orbitals.push(MolecularOrbital {
            energy: energies[i],
            occupation: occupations[i],
            spin: spin_of(&spins[i])?,
            symmetry: labels[i].clone(),
            coefficients: c.row(i).to_vec(),
        });
    }
    let doc = formats::wavefunction::wavefunction_document(
        &source,
        &source,
        atoms,
        wf,
        Some(&program),
        formats::DEFAULT_OVERLAP,
    );
    Ok(PyDocument::new(doc))
}

/// A scan manifest's frames as documents (each frame's first file, its geometry as the scan
/// aligns it): the title, the coordinate ("angle 2-1-3") and each frame's value as text.
#[pyfunction]
fn load_scan(py: Python<'_>, path: PathBuf) -> PyResult<(String, String, Vec<ScanFrame>)> {
    let scan = py.detach(|| formats::scan::load_scan(&path)).map_err(|e| load_error(&e))?.scan;
    let frames = scan
        .frames
        .iter()
        .map(|f| {
            let (wavefunction, volumes) = match &f.content {
                FrameContent::Wavefunctions(w) => (w.first().cloned(), Vec::new()),
                FrameContent::Volumes(v) => (None, v.clone()),
            };
            let doc = Document {
                source: f.source.clone(),
                title: f.source.clone(),
                molecule: f.molecule.clone(),
                wavefunction,
                volumes,
                ..Default::default()
            };
            (f.at, scan.coordinate.value_text(f.at), PyDocument::new(doc))
        })
        .collect();
    Ok((scan.title.clone(), scan.coordinate.label(), frames))
}

fn rgba<'py>(py: Python<'py>, img: image::RgbaImage) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let (w, h) = img.dimensions();
    let a = Array3::from_shape_vec((h as usize, w as usize, 4), img.into_raw()).map_err(runtime)?;
    Ok(a.into_pyarray(py))
}

/// `orbcloud render`'s picture (height × width × 4, RGBA) of `doc`, or of the file `words`
/// name, with `words` the command's options.
#[pyfunction]
#[pyo3(signature = (doc, words))]
fn render<'py>(
    py: Python<'py>,
    doc: Option<&Bound<'py, PyDocument>>,
    words: Vec<String>,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let doc = doc.map(|d| d.get().doc.clone());
    let img = py.detach(|| -> anyhow::Result<image::RgbaImage> {
        match cli::render_drawing(doc, &words)? {
            cli::Drawing::Drawn(img, _) => Ok(img),
            cli::Drawing::Scene(mut picture) => picture.draw(&picture.camera.clone()),
        }
    });
    rgba(py, img.map_err(|e| PyValueError::new_err(format!("{e:#}")))?)
}

/// One quantity's scene as `render` draws it, kept on the GPU and drawn again from a camera the
/// caller turns (the notebook viewer, whose events may arrive on another thread than the one
/// that made it).
#[pyclass(module = "orbcloud._native", frozen)]
struct Scene {
    state: Mutex<SceneState>,
}

struct SceneState {
    picture: Box<cli::Picture>,
    camera: Camera,
}

impl Scene {
    fn state(&self) -> std::sync::MutexGuard<'_, SceneState> {
        // A panic while drawing leaves the scene as it was: keep using it.
        self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (doc, words))]
    fn new(py: Python<'_>, doc: Option<&Bound<'_, PyDocument>>, words: Vec<String>) -> PyResult<Self> {
        let doc = doc.map(|d| d.get().doc.clone());
        let drawing = py.detach(|| cli::render_drawing(doc, &words).map_err(|e| format!("{e:#}")));
        match drawing.map_err(PyValueError::new_err)? {
            cli::Drawing::Scene(picture) => {
                Ok(Self { state: Mutex::new(SceneState { camera: picture.camera, picture }) })
            }
            cli::Drawing::Drawn(..) => {
                Err(PyValueError::new_err("the interactive view shows one quantity (no --beside, no second quantity)"))
            }
        }
    }

    /// Turns the camera about its target (radians).
    fn orbit(&self, d_yaw: f32, d_pitch: f32) {
        self.state().camera.orbit(d_yaw, d_pitch);
    }

    /// Moves the camera closer (factor < 1) or away.
    fn zoom(&self, factor: f32) {
        self.state().camera.zoom(factor);
    }

    /// Back to the camera the options ask for.
    fn reset(&self) {
        let mut state = self.state();
        state.camera = state.picture.camera;
    }

    /// The camera as JSON (target, yaw, pitch, distance, fov_y, orientation).
    #[getter]
    fn get_camera(&self) -> PyResult<String> {
        serde_json::to_string(&self.state().camera).map_err(runtime)
    }

    #[setter]
    fn set_camera(&self, json: &str) -> PyResult<()> {
        self.state().camera = serde_json::from_str(json).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(())
    }

    /// The picture from the current camera (height × width × 4, RGBA), drawn without the GIL.
    fn draw<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let img = py.detach(|| {
            let mut state = self.state();
            let camera = state.camera;
            state.picture.draw(&camera).map_err(|e| format!("{e:#}"))
        });
        rgba(py, img.map_err(PyRuntimeError::new_err)?)
    }
}

/// Runs the `orbcloud` command line `words` (after the program's name) in this process, the
/// GIL released: what it prints goes to this process's output.
#[pyfunction]
fn run_cli(py: Python<'_>, words: Vec<String>) -> PyResult<()> {
    let line = std::iter::once("orbcloud".to_string()).chain(words).map(Into::into).collect();
    py.detach(|| cli::run_words(line)).map_err(|e| PyRuntimeError::new_err(format!("{e:#}")))
}

/// Runs the desktop viewer on `files` (blocks until its window closes).
#[pyfunction]
fn run_viewer(py: Python<'_>, files: Vec<PathBuf>) -> PyResult<()> {
    py.detach(|| orbcloud::app::run(files, None)).map_err(runtime)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyDocument>()?;
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(from_parts, m)?)?;
    m.add_function(wrap_pyfunction!(load_scan, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(nci, m)?)?;
    m.add_function(wrap_pyfunction!(run_viewer, m)?)?;
    m.add_function(wrap_pyfunction!(run_cli, m)?)?;
    m.add("NativeLoadError", m.py().get_type::<NativeLoadError>())?;
    Ok(())
}
