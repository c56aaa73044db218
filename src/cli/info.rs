//! `orbcloud info`: what a file holds, as text or as JSON for scripts.

use serde::Serialize;

use crate::model::basis::ShellKind;
use crate::model::excited::Transition;
use crate::model::excited_density::Descriptors;
use crate::model::orbitals::{EnergiesAsOccupations, Normalization, Spin, Wavefunction};
use crate::model::units::EV_PER_HARTREE;
use crate::model::{Document, GridStats, grid::ValueKind, units::ANGSTROM_PER_BOHR};

#[derive(Serialize)]
pub struct AtomInfo {
    pub index: usize,
    pub symbol: &'static str,
    pub z: u32,
    pub ghost: bool,
    pub charge: f64,
    pub position_bohr: [f64; 3],
}

#[derive(Serialize)]
pub struct GridInfo {
    pub index: usize,
    pub label: String,
    pub dims: [usize; 3],
    /// Row-major 4×4 affine map from grid indices (i, j, k, 1) to bohr.
    pub world_from_grid: [[f64; 4]; 4],
    pub orthogonal: bool,
    pub voxel_volume_bohr3: f64,
    pub kind: ValueKind,
    pub stats: GridStats,
}

#[derive(Serialize)]
pub struct OrbitalInfo {
    /// 1-based number within its spin, as programs count.
    pub number: usize,
    pub spin: Spin,
    pub symmetry: String,
    pub energy_hartree: f64,
    pub occupation: f64,
}

#[derive(Serialize)]
pub struct WavefunctionInfo {
    pub basis_functions: usize,
    pub shells: usize,
    pub max_l: u32,
    pub pure_shells: usize,
    pub restricted: bool,
    /// The writer detected, the repair applied and max |CᵀSC − I| after it.
    pub normalization: Normalization,
    pub homo: Option<OrbitalInfo>,
    pub lumo: Option<OrbitalInfo>,
    pub orbitals: Vec<OrbitalInfo>,
    /// Natural orbitals (fractional occupations): HOMO and LUMO are found by occupation.
    pub natural: bool,
    /// The file's "energies" are its occupations: no energies to show.
    pub energies_are_occupations: bool,
    /// How they are: `whole` (as `Occup=`) or `per_spin` (half of it, as Psi4 writes them).
    pub energies_as_occupations: Option<EnergiesAsOccupations>,
}

#[derive(Serialize)]
pub struct ModelInfo {
    /// The number the file gives (MODEL n; frames count from 1).
    pub number: i32,
    pub atoms: usize,
    pub title: String,
    /// The frame's energy (hartree), where the file gives one (a program log's steps).
    pub energy_hartree: Option<f64>,
}

#[derive(Serialize)]
pub struct ChainInfo {
    pub name: String,
    /// 0-based index into `models`.
    pub model: u32,
    pub residues: usize,
    pub atoms: usize,
}

#[derive(Serialize)]
pub struct ResidueInfo {
    pub name: String,
    pub number: i32,
    /// The insertion code, "" when none.
    pub insertion: String,
    /// 0-based index into `chains`.
    pub chain: u32,
    pub hetero: bool,
    pub secondary: crate::model::structure::Secondary,
    pub atoms: usize,
}

/// What a structure file (PDB, mmCIF, XYZ) says beyond atoms: every model, chain and residue
/// (all models), and which model `atoms` lists.
#[derive(Serialize)]
pub struct StructureInfo {
    pub shown_model: usize,
    /// Atoms of every model and alternate location.
    pub all_atoms: usize,
    pub models: Vec<ModelInfo>,
    pub chains: Vec<ChainInfo>,
    pub residues: Vec<ResidueInfo>,
}

#[derive(Serialize)]
pub struct DocumentInfo {
    pub source: String,
    pub title: String,
    pub formula: String,
    pub atoms: Vec<AtomInfo>,
    pub bonds: usize,
    pub grids: Vec<GridInfo>,
    pub wavefunction: Option<WavefunctionInfo>,
    pub structure: Option<StructureInfo>,
    /// Normal modes of vibration, as the file gives them (empty when it has none).
    pub modes: Vec<crate::model::vibrations::NormalMode>,
    /// Where the modes' geometry comes from, when there are modes.
    pub modes_geometry: Option<String>,
    /// Excited states the file lists, and what its excited state's density says.
    pub excited_states: Option<ExcitedInfo>,
    /// The coordinate a scan job varied and its value at each frame (a Gaussian or ORCA relaxed scan).
    pub scan: Option<JobScanInfo>,
    /// Parts of the file left out, each saying where and why.
    pub problems: Vec<String>,
}

/// A scan job's coordinate: `coordinate` as chemists write it ("dihedral 3-4-9-10", atoms
/// 1-based), its kind and atoms (1-based), its unit, its value at each frame, and where the job
/// names it.
#[derive(Serialize)]
pub struct JobScanInfo {
    pub coordinate: String,
    pub kind: String,
    pub atoms: Vec<usize>,
    pub unit: String,
    pub values: Vec<f64>,
    pub from: String,
}

#[derive(Serialize)]
pub struct StateInfo {
    pub number: usize,
    pub energy_ev: f64,
    pub wavelength_nm: f64,
    pub oscillator_strength: Option<f64>,
    pub spin: String,
    pub symmetry: String,
    pub s_squared: Option<f64>,
    pub total_energy_hartree: Option<f64>,
    /// The largest transitions (at most 5), orbitals numbered from 1 within their spin.
    pub main_transitions: Vec<Transition>,
    /// Its natural transition orbitals, where the file has orbitals and the state its printed
    /// transitions ([`crate::model::nto`]).
    pub ntos: Option<NtoInfo>,
}

/// A state's natural transition orbitals: the pairs' weights, the printed amplitudes' Σc², and
/// the hole and electron densities' centroids, distance D and overlap Sr.
#[derive(Serialize)]
pub struct NtoInfo {
    pub weights: Vec<f64>,
    pub printed_norm: f64,
    pub hole_electron: Option<crate::model::nto::HoleElectron>,
}

#[derive(Serialize)]
pub struct ExcitedInfo {
    pub program: String,
    pub method: String,
    pub states: Vec<StateInfo>,
    /// The state whose density the file holds, and what its attachment and detachment
    /// densities say: `electrons_moved`, their centroids and distance (exact, from dipole
    /// integrals), their overlap and integrals on a grid.
    pub density: Option<Descriptors>,
    /// Where that density comes from ("Total CI Rho(1) Density").
    pub density_source: Option<String>,
    /// What the file leaves unsaid about its states (Q-Chem's fchk names no spins), "" when
    /// nothing.
    pub note: String,
}

fn excited_info(doc: &Document) -> Option<ExcitedInfo> {
    let wf = doc.wavefunction.as_ref();
    let density = wf.and_then(|wf| Some((wf, wf.excited.as_ref()?)));
    if doc.excited.is_none() && density.is_none() {
        return None;
    }
    let listed = doc.excited.clone().unwrap_or_default();
    let states = (listed.states.iter())
        .map(|s| StateInfo {
            number: s.number,
            energy_ev: s.energy_ev,
            wavelength_nm: s.wavelength_nm(),
            oscillator_strength: s.oscillator_strength,
            spin: s.spin.clone(),
            symmetry: s.symmetry.clone(),
            s_squared: s.s_squared,
            total_energy_hartree: s.total_energy_hartree,
            main_transitions: s.main_transitions(5).into_iter().cloned().collect(),
            ntos: wf.and_then(|wf| crate::model::nto::from_transitions(wf, s)).map(|n| NtoInfo {
                weights: n.pairs.iter().map(|p| p.weight).collect(),
                printed_norm: n.printed_norm,
                hole_electron: wf.and_then(|wf| n.hole_electron(&wf.basis, &doc.molecule)),
            }),
        })
        .collect();
    Some(ExcitedInfo {
        program: listed.program,
        method: listed.method,
        states,
        density: density.and_then(|(wf, e)| e.descriptors(&wf.basis, &doc.molecule)),
        density_source: density.map(|(_, e)| e.source.clone()),
        note: listed.note,
    })
}

fn structure_info(view: &crate::model::StructureView) -> StructureInfo {
    let s = &view.structure;
    let len = |r: &std::ops::Range<u32>| (r.end - r.start) as usize;
    StructureInfo {
        shown_model: view.model,
        all_atoms: s.len(),
        models: s
            .models
            .iter()
            .map(|m| ModelInfo {
                number: m.number,
                atoms: len(&m.atoms),
                title: m.title.clone(),
                energy_hartree: m.energy,
            })
            .collect(),
        chains: s
            .chains
            .iter()
            .map(|c| ChainInfo {
                name: c.name.to_string(),
                model: c.model,
                residues: len(&c.residues),
                atoms: s.residues[c.residues.start as usize..c.residues.end as usize]
                    .iter()
                    .map(|r| len(&r.atoms))
                    .sum(),
            })
            .collect(),
        residues: s
            .residues
            .iter()
            .map(|r| ResidueInfo {
                name: r.name.to_string(),
                number: r.number,
                insertion: if r.insertion == 0 { String::new() } else { (r.insertion as char).to_string() },
                chain: r.chain,
                hetero: r.hetero,
                secondary: r.secondary,
                atoms: len(&r.atoms),
            })
            .collect(),
    }
}

fn orbital_info(wf: &Wavefunction, i: usize) -> OrbitalInfo {
    let o = &wf.orbitals[i];
    OrbitalInfo {
        number: wf.of_spin(o.spin).position(|(j, _)| j == i).map_or(0, |p| p + 1),
        spin: o.spin,
        symmetry: o.symmetry.clone(),
        energy_hartree: o.energy,
        occupation: o.occupation,
    }
}

fn wavefunction_info(wf: &Wavefunction) -> WavefunctionInfo {
    WavefunctionInfo {
        basis_functions: wf.basis.n_functions(),
        shells: wf.basis.shells.len(),
        max_l: wf.basis.shells.iter().map(|s| s.l).max().unwrap_or(0),
        pure_shells: wf.basis.shells.iter().filter(|s| s.kind == ShellKind::Pure).count(),
        restricted: wf.restricted,
        normalization: wf.normalization.clone(),
        homo: wf.homo(Spin::Alpha).map(|i| orbital_info(wf, i)),
        lumo: wf.lumo(Spin::Alpha).map(|i| orbital_info(wf, i)),
        orbitals: (0..wf.orbitals.len()).map(|i| orbital_info(wf, i)).collect(),
        natural: wf.natural(Spin::Alpha),
        energies_are_occupations: wf.energies_are_occupations(),
        energies_as_occupations: wf.energies_as_occupations(),
    }
}

pub fn describe(doc: &Document) -> DocumentInfo {
    DocumentInfo {
        source: doc.source.clone(),
        title: doc.title.clone(),
        formula: doc.molecule.formula(),
        atoms: doc
            .molecule
            .atoms
            .iter()
            .enumerate()
            .map(|(index, a)| AtomInfo {
                index,
                symbol: a.element().symbol,
                z: a.z,
                ghost: a.ghost,
                charge: a.charge,
                position_bohr: a.position.to_array(),
            })
            .collect(),
        bonds: doc.molecule.bonds.len(),
        grids: doc
            .volumes
            .iter()
            .enumerate()
            .map(|(index, g)| GridInfo {
                index,
                label: g.label.clone(),
                dims: g.dims,
                world_from_grid: g.world_from_grid.transpose().to_cols_array_2d(),
                orthogonal: g.is_orthogonal(),
                voxel_volume_bohr3: g.voxel_volume(),
                kind: g.kind,
                stats: g.stats,
            })
            .collect(),
        wavefunction: doc.wavefunction.as_ref().map(wavefunction_info),
        structure: doc.structure.as_ref().map(structure_info),
        modes: doc.vibrations.as_ref().map(|v| v.modes.clone()).unwrap_or_default(),
        modes_geometry: doc.vibrations.as_ref().map(|v| v.geometry_from.clone()),
        excited_states: excited_info(doc),
        scan: doc.job_scan.as_ref().map(|j| JobScanInfo {
            coordinate: j.coordinate.label(),
            kind: j.coordinate.kind().to_string(),
            atoms: j.coordinate.atoms().iter().map(|a| a + 1).collect(),
            unit: j.coordinate.unit().trim().to_string(),
            values: j.values.clone(),
            from: j.from.clone(),
        }),
        problems: doc.problems.clone(),
    }
}

pub fn text(doc: &Document) -> String {
    use std::fmt::Write;
    let info = describe(doc);
    let mut s = String::new();
    let _ = writeln!(s, "{}: {}", info.source, info.title);
    let _ = writeln!(s, "{} atoms ({}), {} bonds", info.atoms.len(), info.formula, info.bonds);
    if let Some(st) = &info.structure {
        let _ = writeln!(
            s,
            "structure: {} models (model {} shown), {} chains, {} residues, {} atoms with every model and alternate location",
            st.models.len(),
            st.models.get(st.shown_model).map_or(1, |m| m.number),
            st.chains.len(),
            st.residues.len(),
            st.all_atoms
        );
    }
    if let Some(st) = &info.structure
        && st.models.iter().any(|m| m.energy_hartree.is_some())
    {
        if let Some(j) = &doc.job_scan {
            let _ = writeln!(s, "scan of {} ({})", j.coordinate.label(), j.from);
        }
        for (k, m) in st.models.iter().enumerate() {
            let e = m.energy_hartree.map_or("no energy".to_string(), |e| format!("E = {e:.9} Eh"));
            let at =
                doc.job_scan.as_ref().and_then(|j| Some(format!(", {}", j.coordinate.value_text(*j.values.get(k)?))));
            let _ = writeln!(s, "  frame {:>3}: {e}{}", m.number, at.unwrap_or_default());
        }
    }
    for a in &info.atoms {
        let p = a.position_bohr;
        let ang = p.map(|v| v * ANGSTROM_PER_BOHR);
        let _ = writeln!(
            s,
            "  {:>4} {:<2}{} {:>12.6} {:>12.6} {:>12.6} bohr  ({:.4} {:.4} {:.4} Å)",
            a.index + 1,
            a.symbol,
            if a.ghost { "*" } else { " " },
            p[0],
            p[1],
            p[2],
            ang[0],
            ang[1],
            ang[2]
        );
    }
    for g in &info.grids {
        let _ = writeln!(
            s,
            "grid {} \"{}\": {}×{}×{} {:?}, {}orthogonal, voxel {:.5} bohr³",
            g.index,
            g.label,
            g.dims[0],
            g.dims[1],
            g.dims[2],
            g.kind,
            if g.orthogonal { "" } else { "non-" },
            g.voxel_volume_bohr3
        );
        for row in &g.world_from_grid[..3] {
            let _ = writeln!(s, "    [{:>11.6} {:>11.6} {:>11.6} | {:>11.6}]", row[0], row[1], row[2], row[3]);
        }
        let st = g.stats;
        let _ = writeln!(s, "    min {:.6e}  max {:.6e}  mean {:.6e}  σ {:.6e}", st.min, st.max, st.mean, st.sigma);
    }
    if let Some(w) = &info.wavefunction {
        let n = &w.normalization;
        let _ = writeln!(
            s,
            "basis: {} functions in {} shells (max l = {}, {} pure), {}",
            w.basis_functions,
            w.shells,
            w.max_l,
            w.pure_shells,
            if w.restricted { "restricted" } else { "unrestricted" }
        );
        let _ = writeln!(
            s,
            "written by {}; repair: {}; max |CᵀSC − I| = {:.2e}{}{}",
            n.program,
            n.repair,
            n.residual,
            n.precision_note().map_or(String::new(), |p| format!("; {p}")),
            if n.residual > n.expected_residual() { "  ⚠ not orthonormal" } else { "" }
        );
        if w.natural {
            let energies = w.energies_as_occupations.map_or(String::new(), |e| format!("; {}", e.describe()));
            let _ = writeln!(s, "natural orbitals: HOMO and LUMO by occupation{energies}");
        }
        for (name, o) in [("HOMO", &w.homo), ("LUMO", &w.lumo)] {
            if let Some(o) = o {
                let energy = match w.energies_are_occupations {
                    true => "no energy".to_string(),
                    false => format!("E = {:.6} Eh ({:.3} eV)", o.energy_hartree, o.energy_hartree * EV_PER_HARTREE),
                };
                let _ = writeln!(
                    s,
                    "{name}: MO {} {:?} {} {energy}, occupation {:.3}",
                    o.number, o.spin, o.symmetry, o.occupation
                );
            }
        }
    }
    if let Some(from) = &info.modes_geometry {
        let imaginary = info.modes.iter().filter(|m| m.is_imaginary()).count();
        let _ = writeln!(
            s,
            "{} normal modes ({imaginary} imaginary: {}), geometry from {from}",
            info.modes.len(),
            match imaginary {
                0 => "a minimum",
                1 => "a transition state",
                _ => "a higher-order saddle point",
            }
        );
        for (k, m) in info.modes.iter().enumerate() {
            let intensity = m.ir_intensity.map_or("—".to_string(), |i| format!("{i:.2}"));
            let mark =
                if m.is_imaginary() { format!("{:.2}i", -m.frequency_cm1) } else { format!("{:.2}", m.frequency_cm1) };
            let _ = writeln!(s, "  mode {:>3} {:>12} cm⁻¹  IR {:>10} km/mol", k + 1, mark, intensity);
        }
    } else if info
        .wavefunction
        .as_ref()
        .is_some_and(|w| w.normalization.program == "Q-Chem" && w.normalization.printed_decimals.is_none())
    {
        let _ = writeln!(s, "no normal modes: Q-Chem's fchk files carry none");
    }
    if let Some(x) = &info.excited_states {
        excited_text(&mut s, x);
    }
    for p in &info.problems {
        let _ = writeln!(s, "⚠ {p}");
    }
    s
}

/// The states as a table, their main transitions, and the density's descriptors.
fn excited_text(s: &mut String, x: &ExcitedInfo) {
    use std::fmt::Write;
    let method = if x.method.is_empty() { String::new() } else { format!(" ({})", x.method) };
    let _ = writeln!(s, "{} excited states{method} from {}:", x.states.len(), x.program);
    if !x.note.is_empty() {
        let _ = writeln!(s, "  ({})", x.note);
    }
    for st in &x.states {
        let f = st.oscillator_strength.map_or("—".to_string(), |f| format!("{f:.4}"));
        let label =
            [st.spin.as_str(), st.symmetry.as_str()].iter().filter(|w| !w.is_empty()).copied().collect::<Vec<_>>();
        let transitions: Vec<String> = st.main_transitions.iter().take(3).map(ToString::to_string).collect();
        let _ = writeln!(
            s,
            "  state {:>3} {:>9.4} eV {:>8.2} nm  f = {f:>7}  {:<12} {}",
            st.number,
            st.energy_ev,
            st.wavelength_nm,
            label.join(" "),
            transitions.join(", ")
        );
        if let Some(n) = &st.ntos {
            let weights: Vec<String> = n.weights.iter().map(|w| format!("{w:.3}")).collect();
            let moved = n.hole_electron.map_or(String::new(), |h| {
                format!(
                    "; hole and electron {:.3} Å apart (D), overlap Sr {:.3}",
                    h.distance_bohr * ANGSTROM_PER_BOHR,
                    h.overlap
                )
            });
            let _ = writeln!(s, "      NTO weights {}{moved}", weights.join(", "));
        }
    }
    if let Some(d) = &x.density {
        let g = &d.grid;
        let _ = writeln!(
            s,
            "state {} density ({}): {:.4} electrons moved (detachment {:.4}); attachment and detachment centroids {:.3} bohr apart ({:.3} Å), overlap {:.3}",
            d.state,
            x.density_source.as_deref().unwrap_or(""),
            d.electrons_moved,
            d.electrons_detached,
            d.centroid_distance_bohr,
            d.centroid_distance_bohr * ANGSTROM_PER_BOHR,
            g.overlap
        );
        let _ = writeln!(
            s,
            "  on a {}×{}×{} grid ({} bohr): attachment {:.4}, detachment {:.4} electrons",
            g.grid_points[0],
            g.grid_points[1],
            g.grid_points[2],
            g.spacing_bohr,
            g.attachment_integral,
            g.detachment_integral
        );
    }
}
