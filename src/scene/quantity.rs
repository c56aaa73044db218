//! The quantities an object shows: each orbital, density or data set of its file with its own
//! representations (a cloud, any number of isosurfaces). Plain, serialisable data.

use serde::{Deserialize, Serialize};

use crate::model::Document;
use crate::model::basis::Basis;
use crate::model::basis_labels::function_name;
use crate::model::orbitals::{Quantity, Spin, Wavefunction};

use super::{AtomColoring, AtomStyle, IsosurfaceSettings, RenderSettings, VolumeSettings};

/// Where a quantity's values come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Source {
    /// A data set of the file (cube files may hold several), by index.
    Volume(usize),
    /// An orbital or density evaluated from the file's wavefunction.
    Wavefunction(Quantity),
    /// View `slot` of the scan the document is a frame of ([`Document::scan`]): its orbital at
    /// the object's value, mixed from the two key volumes around it.
    Scan(usize),
    /// A quantity of the promolecular density (a sum of spherical atoms) of the document's
    /// atoms, for structures without a wavefunction: the NCI surface's s, the NCI cloud,
    /// sign(λ₂)ρ or ρ. [`QuantityState::fragments`] may add other files' or split the atoms.
    Promolecular(Quantity),
}

impl Source {
    /// Whether `doc` holds what this source names.
    pub fn exists_in(self, doc: &Document) -> bool {
        match self {
            Source::Volume(i) => i < doc.volumes.len(),
            Source::Wavefunction(q) => doc.wavefunction.as_ref().is_some_and(|wf| match q {
                Quantity::Orbital(i) => i < wf.orbitals.len(),
                Quantity::BasisFunction(k) => k < wf.basis.n_functions(),
                Quantity::Density | Quantity::Potential => true,
                Quantity::ReducedGradient
                | Quantity::NciGradient
                | Quantity::NciCloud
                | Quantity::SignLambda2Rho
                | Quantity::DensityLaplacian => true,
                Quantity::SpinDensity => !wf.restricted,
                Quantity::DifferenceDensity
                | Quantity::Attachment
                | Quantity::Detachment
                | Quantity::ExcitedDensity => wf.excited.is_some(),
                Quantity::TransitionDensity(n) => {
                    crate::model::transition::TransitionDensity::of_state(doc, n).is_some()
                }
            }),
            Source::Scan(slot) => doc.scan.as_ref().is_some_and(|s| slot < s.orbitals.len()),
            Source::Promolecular(q) => !doc.molecule.atoms.is_empty() && is_promolecular(q),
        }
    }

    /// Whether it is an electrostatic potential: the wavefunction's, or a data set whose
    /// label says so (cubegen's "Electrostatic potential from Total SCF Density", PySCF's
    /// "Molecular electrostatic potential", an "ESP" or "MEP" grid).
    pub fn is_potential(self, doc: &Document) -> bool {
        match self {
            Source::Wavefunction(q) => q == Quantity::Potential,
            Source::Scan(_) | Source::Promolecular(_) => false,
            Source::Volume(i) => doc.volumes.get(i).is_some_and(|v| {
                let label = v.label.to_ascii_lowercase();
                label.contains("potential")
                    || label.split(|c: char| !c.is_ascii_alphanumeric()).any(|w| w == "esp" || w == "mep")
            }),
        }
    }

    /// The orbital it shows, if it is one.
    pub fn orbital(self) -> Option<usize> {
        match self {
            Source::Wavefunction(Quantity::Orbital(i)) => Some(i),
            _ => None,
        }
    }

    /// A short name: "HOMO", "LUMO+1 β", "MO 12", "total density", "C3 2pz" (a bare basis
    /// function), a data set's label.
    pub fn name(self, doc: &Document) -> String {
        match self {
            Source::Volume(i) => doc.volumes.get(i).map_or_else(|| format!("data set {}", i + 1), |v| v.label.clone()),
            Source::Scan(slot) => doc.scan.as_ref().map_or_else(|| format!("view {}", slot + 1), |s| s.slot_name(slot)),
            Source::Promolecular(Quantity::NciGradient) => "NCI of spherical atoms (s where ρ ≤ 0.07)".into(),
            Source::Promolecular(Quantity::NciCloud) => "NCI cloud of spherical atoms".into(),
            // What its colour bar says: the same quantity as a wavefunction's.
            Source::Promolecular(Quantity::SignLambda2Rho) => "sign(λ₂)ρ".into(),
            Source::Promolecular(Quantity::ReducedGradient) => "reduced gradient of spherical atoms".into(),
            Source::Promolecular(_) => "density of spherical atoms".into(),
            Source::Wavefunction(Quantity::Density) => "total density".into(),
            Source::Wavefunction(Quantity::SpinDensity) => "spin density".into(),
            Source::Wavefunction(Quantity::Potential) => "electrostatic potential".into(),
            Source::Wavefunction(Quantity::ReducedGradient) => "reduced density gradient".into(),
            Source::Wavefunction(Quantity::NciGradient) => "NCI (s where ρ ≤ 0.05)".into(),
            Source::Wavefunction(Quantity::NciCloud) => "NCI cloud".into(),
            Source::Wavefunction(Quantity::SignLambda2Rho) => "sign(λ₂)ρ".into(),
            Source::Wavefunction(Quantity::DensityLaplacian) => "density Laplacian".into(),
            Source::Wavefunction(Quantity::DifferenceDensity) => "difference density".into(),
            Source::Wavefunction(Quantity::Attachment) => "attachment density".into(),
            Source::Wavefunction(Quantity::Detachment) => "detachment density".into(),
            Source::Wavefunction(Quantity::ExcitedDensity) => "excited-state density".into(),
            Source::Wavefunction(Quantity::TransitionDensity(n)) => format!("transition density (state {n})"),
            Source::Wavefunction(Quantity::Orbital(i)) => match &doc.wavefunction {
                Some(wf) => orbital_name(wf, i),
                None => format!("MO {}", i + 1),
            },
            Source::Wavefunction(Quantity::BasisFunction(k)) => doc
                .wavefunction
                .as_ref()
                .and_then(|wf| function_name(&doc.molecule, &wf.basis, k))
                .unwrap_or_else(|| format!("basis function {}", k + 1)),
        }
    }
}

/// Whether the promolecular density gives `quantity` ([`Source::Promolecular`]): those of
/// the density and its derivatives that need no wavefunction.
pub fn is_promolecular(quantity: Quantity) -> bool {
    matches!(
        quantity,
        Quantity::Density
            | Quantity::ReducedGradient
            | Quantity::NciGradient
            | Quantity::NciCloud
            | Quantity::SignLambda2Rho
    )
}

/// "HOMO", "LUMO+2", or "MO 12" away from the frontier; " β" after a beta orbital of an
/// unrestricted wavefunction.
pub fn orbital_name(wf: &Wavefunction, i: usize) -> String {
    let Some(o) = wf.orbitals.get(i) else { return format!("MO {}", i + 1) };
    let number = wf.of_spin(o.spin).position(|(j, _)| j == i).map_or(0, |p| p + 1);
    // Natural transition orbitals go by their labels ("hole 1"), not by the frontier.
    let nto = crate::model::nto::is_nto_label(&o.symmetry).then(|| o.symmetry.clone());
    let name = nto.or_else(|| wf.frontier_label(i, 5)).unwrap_or_else(|| format!("MO {number}"));
    match (wf.restricted, o.spin) {
        (false, Spin::Beta) => format!("{name} β"),
        (false, Spin::Alpha) => format!("{name} α"),
        _ => name,
    }
}

/// One quantity of an object and how it is shown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuantityState {
    pub source: Source,
    /// Whether any of its representations is drawn.
    #[serde(default = "yes")]
    pub visible: bool,
    /// Its cloud (hidden with `cloud.visible`).
    #[serde(default)]
    pub cloud: VolumeSettings,
    /// Every isosurface of it, shown or not (an orbital's ±v pairs, a density's nested shells).
    #[serde(default)]
    pub isosurfaces: Vec<IsosurfaceSettings>,
    /// The pane of a split view it is drawn in (`None`: every pane; past the last pane: the last).
    #[serde(default)]
    pub pane: Option<usize>,
    /// The fragments an NCI quantity's density is made of besides the object's own.
    #[serde(default, skip_serializing_if = "Fragments::is_empty")]
    pub fragments: Fragments,
}

/// What an NCI quantity's density is made of besides the object's own, as NCIPLOT makes it:
/// other files' densities added (fragments), or the object's atoms split in two.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Fragments {
    /// A selection of a structure's atoms (a ligand: `resn LIG`): it and all the other atoms
    /// (its pocket) are two parts, and only what lies between them is kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<String>,
    /// Other open files whose densities add, by path, each at its file's coordinates (as
    /// NCIPLOT reads them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<String>,
    /// With files: only the points where no fragment holds 95 % of the density are kept
    /// (NCIPLOT's intermolecular mode).
    #[serde(default)]
    pub between_only: bool,
}

impl Fragments {
    /// Whether the object's density is all there is.
    pub fn is_empty(&self) -> bool {
        self.selection.is_none() && self.files.is_empty()
    }
}

fn yes() -> bool {
    true
}

impl QuantityState {
    /// A quantity as `defaults` shows a new one: their cloud and one isosurface (hidden unless
    /// they show it).
    pub fn new(source: Source, defaults: &RenderSettings) -> Self {
        Self {
            source,
            visible: true,
            cloud: defaults.volume,
            isosurfaces: vec![defaults.iso],
            pane: None,
            fragments: Fragments::default(),
        }
    }

    /// Whether its values on a grid are wanted: an isosurface of it is shown (direct mode fills
    /// no grid otherwise).
    pub fn wants_grid(&self) -> bool {
        self.isosurfaces.iter().any(|i| i.visible)
    }

    /// Whether it is drawn in pane `pane` of a view split into `count`.
    pub fn in_pane(&self, pane: usize, count: usize) -> bool {
        self.pane.is_none_or(|p| p.min(count.max(1) - 1) == pane)
    }

    /// A new quantity of an object that already shows `others`: the cloud and isosurface
    /// colours of the first preset whose colours are all unlike theirs, so each quantity reads
    /// as its own (a density beside an orbital is not the orbital's red: red / white, the next
    /// preset, shares red / blue's red).
    pub fn joining(source: Source, defaults: &RenderSettings, others: &[QuantityState]) -> Self {
        let mut q = Self::new(source, defaults);
        let taken: Vec<[f32; 3]> =
            others.iter().flat_map(|o| [o.cloud.positive_color, o.cloud.negative_color]).collect();
        let alike = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f32>() < 0.1;
        let free = |c: [f32; 3]| !taken.iter().any(|&t| alike(c, t));
        if let Some(&(_, positive, negative)) = super::transfer::PRESETS.iter().find(|&&(_, p, n)| free(p) && free(n))
            && !others.is_empty()
        {
            (q.cloud.positive_color, q.cloud.negative_color) = (positive, negative);
            for iso in &mut q.isosurfaces {
                (iso.positive_color, iso.negative_color, iso.density_color) = (positive, negative, positive);
            }
        }
        q
    }
}

/// The density (a.u.) whose surface an ESP map colours: ρ = 0.002 a.u. encloses about 97% of
/// the electrons and is where the potential is conventionally read.
pub const ESP_MAP_DENSITY: f32 = 0.002;

impl QuantityState {
    /// An *ESP map*: the surface ρ = [`ESP_MAP_DENSITY`] of `density` coloured by `potential`
    /// on the diverging map, opaque, without a cloud.
    pub fn esp_map(density: Source, potential: Source, defaults: &RenderSettings) -> Self {
        let mut map = Self::new(density, defaults);
        map.cloud.visible = false;
        map.isosurfaces = vec![IsosurfaceSettings {
            visible: true,
            level: super::IsoLevel::Absolute(ESP_MAP_DENSITY),
            translucent: false,
            color_by: Some(potential),
            ..Default::default()
        }];
        map
    }

    /// An *NCI surface* (Johnson et al., 2010): the reduced density gradient's surface s =
    /// [`NCI_LEVEL`] where ρ is below NCIPLOT's cut, coloured by sign(λ₂)ρ from −[`NCI_RANGE`]
    /// (blue, attraction) through green to +[`NCI_RANGE`] (red, repulsion), opaque, without a
    /// cloud.
    pub fn nci_surface(defaults: &RenderSettings) -> Self {
        let mut nci = Self::new(Source::Wavefunction(Quantity::NciGradient), defaults);
        nci.cloud.visible = false;
        nci.isosurfaces = vec![IsosurfaceSettings {
            visible: true,
            level: super::IsoLevel::Absolute(NCI_LEVEL),
            translucent: false,
            color_by: Some(Source::Wavefunction(Quantity::SignLambda2Rho)),
            color_range: Some(NCI_RANGE),
            color_scheme: super::coloring::ColorScheme::BlueGreenRed,
            ..Default::default()
        }];
        nci
    }

    /// The NCI surface of a structure's spherical atoms ([`Source::Promolecular`]): s =
    /// [`PROMOLECULAR_NCI_LEVEL`] where ρ is below NCIPLOT's promolecular cut, coloured as
    /// [`Self::nci_surface`]; between the atoms `between` selects and the rest when given.
    pub fn promolecular_nci(defaults: &RenderSettings, between: Option<String>) -> Self {
        let mut nci = Self::nci_surface(defaults);
        nci.source = Source::Promolecular(Quantity::NciGradient);
        nci.fragments.selection = between;
        for iso in &mut nci.isosurfaces {
            iso.level = super::IsoLevel::Absolute(PROMOLECULAR_NCI_LEVEL);
            iso.color_by = Some(Source::Promolecular(Quantity::SignLambda2Rho));
        }
        nci
    }
}

impl QuantityState {
    /// An *NCI cloud*: [`Quantity::NciCloud`] as a signed cloud, blue where λ₂ < 0 (attraction)
    /// and red where λ₂ > 0 (repulsion), opaque where the interaction's density is high and s
    /// lies deep below the level; no surfaces.
    pub fn nci_cloud(defaults: &RenderSettings) -> Self {
        let mut nci = Self::new(Source::Wavefunction(Quantity::NciCloud), defaults);
        nci.cloud.visible = true;
        (nci.cloud.positive_color, nci.cloud.negative_color) = ([0.9, 0.1, 0.05], [0.05, 0.25, 0.95]);
        nci.isosurfaces.iter_mut().for_each(|iso| iso.visible = false);
        nci
    }
}

/// The reduced density gradient an NCI surface of a wavefunction's density is drawn at
/// (NCIPLOT's default for SCF densities).
pub const NCI_LEVEL: f32 = 0.5;

/// The reduced gradient a promolecular NCI surface is drawn at: lower than a wavefunction's
/// ([`NCI_LEVEL`]), since spherical atoms' s runs lower between them (NCIPLOT's promolecular
/// pictures use 0.3).
pub const PROMOLECULAR_NCI_LEVEL: f32 = 0.3;

/// The |sign(λ₂)ρ| (a.u.) where an NCI surface's colours saturate (NCIPLOT's −0.05…0.05).
pub const NCI_RANGE: f32 = 0.05;

/// How an object's atoms are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AtomLook {
    pub style: AtomStyle,
    pub colors: AtomColoring,
    /// How much the farthest atoms darken (0: off).
    pub depth_cue: f32,
    /// Factors on the style's ball and stick radii (1: as the style draws them).
    pub ball_scale: f32,
    pub stick_scale: f32,
}

impl Default for AtomLook {
    fn default() -> Self {
        Self::of(&RenderSettings::default())
    }
}

impl AtomLook {
    /// The atoms of `settings`.
    pub fn of(settings: &RenderSettings) -> Self {
        Self {
            style: settings.atoms,
            colors: settings.atom_colors,
            depth_cue: settings.depth_cue,
            ball_scale: settings.ball_scale,
            stick_scale: settings.stick_scale,
        }
    }

    /// `settings` with these atoms.
    pub fn onto(self, settings: RenderSettings) -> RenderSettings {
        RenderSettings {
            atoms: self.style,
            atom_colors: self.colors,
            depth_cue: self.depth_cue,
            ball_scale: self.ball_scale,
            stick_scale: self.stick_scale,
            ..settings
        }
    }
}

/// How an object's wavefunction is evaluated for display (the orbital browser's options).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Evaluation {
    /// Whose orbitals the browser lists (unrestricted wavefunctions).
    pub spin: Spin,
    /// Evaluate orbitals per slice sample instead of on a GPU-filled grid.
    pub direct: bool,
    /// Restrict orbitals to the basis functions ticked in `functions` (Jang and Varetto's
    /// atomic-orbital selector).
    pub ao_filter: bool,
    /// Per basis function (the model's order), whether it contributes when the filter is on.
    /// Sessions from when the selector picked shells stored one entry per shell here.
    #[serde(alias = "shell_mask")]
    pub functions: Vec<bool>,
    /// Points per axis of the evaluation grid.
    pub grid_points: usize,
}

impl Default for Evaluation {
    fn default() -> Self {
        Self { spin: Spin::Alpha, direct: false, ao_filter: false, functions: Vec::new(), grid_points: 72 }
    }
}

impl Evaluation {
    /// The functions ticked, one entry per basis function of `basis`: as stored, or a stored
    /// per-shell selection spread over each shell's functions; all of them when neither fits.
    pub fn ticked(&self, basis: &Basis) -> Vec<bool> {
        let n = basis.n_functions();
        if self.functions.len() == n {
            return self.functions.clone();
        }
        if self.functions.len() == basis.shells.len() {
            return basis.shells.iter().zip(&self.functions).flat_map(|(s, &on)| vec![on; s.n_functions()]).collect();
        }
        vec![true; n]
    }

    /// The functions an orbital of `basis` is restricted to, when the filter is on.
    pub fn restriction(&self, basis: &Basis) -> Option<Vec<bool>> {
        self.ao_filter.then(|| self.ticked(basis))
    }

    /// What decides the restriction, to tell whether it changed.
    pub fn selection(&self) -> (bool, &[bool]) {
        (self.ao_filter, if self.ao_filter { &self.functions } else { &[] })
    }
}

/// What a file shows first: a wavefunction's HOMO (α), a cube's first data set, nothing for a
/// structure.
pub fn first_source(doc: &Document) -> Option<Source> {
    if doc.scan.as_ref().is_some_and(|s| !s.orbitals.is_empty()) {
        return Some(Source::Scan(0));
    }
    if let Some(wf) = &doc.wavefunction {
        return Some(Source::Wavefunction(wf.homo(Spin::Alpha).map_or(Quantity::Density, Quantity::Orbital)));
    }
    (!doc.volumes.is_empty()).then_some(Source::Volume(0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::VolumeGrid;
    use crate::model::orbitals::MolecularOrbital;

    fn wavefunction(restricted: bool) -> Wavefunction {
        let orbital = |energy, occupation, spin| MolecularOrbital {
            energy,
            occupation,
            spin,
            symmetry: String::new(),
            coefficients: vec![],
        };
        let mut orbitals = vec![orbital(-0.5, 1.0, Spin::Alpha), orbital(0.1, 0.0, Spin::Alpha)];
        if !restricted {
            orbitals.extend([orbital(-0.4, 1.0, Spin::Beta), orbital(0.2, 0.0, Spin::Beta)]);
        }
        Wavefunction { orbitals, restricted, ..Default::default() }
    }

    #[test]
    fn sources_name_what_they_show_and_know_whether_a_file_holds_them() {
        let doc = Document { wavefunction: Some(wavefunction(false)), ..Default::default() };
        assert_eq!(first_source(&doc), Some(Source::Wavefunction(Quantity::Orbital(0))));
        assert_eq!(Source::Wavefunction(Quantity::Orbital(0)).name(&doc), "HOMO α");
        assert_eq!(Source::Wavefunction(Quantity::Orbital(3)).name(&doc), "LUMO β");
        assert!(Source::Wavefunction(Quantity::SpinDensity).exists_in(&doc));
        assert!(!Source::Wavefunction(Quantity::Orbital(4)).exists_in(&doc));
        assert!(!Source::Volume(0).exists_in(&doc));
        let closed = Document { wavefunction: Some(wavefunction(true)), ..Default::default() };
        assert_eq!(Source::Wavefunction(Quantity::Orbital(1)).name(&closed), "LUMO");
        assert!(!Source::Wavefunction(Quantity::SpinDensity).exists_in(&closed));
        let grid = VolumeGrid::new("MO 7", [2, 2, 2], glam::DMat4::IDENTITY, vec![0.0; 8]);
        let cube = Document { volumes: vec![grid], ..Default::default() };
        assert_eq!(first_source(&cube), Some(Source::Volume(0)));
        assert_eq!(Source::Volume(0).name(&cube), "MO 7");
        assert_eq!(first_source(&Document::default()), None);
    }

    #[test]
    fn a_quantity_joining_others_takes_colours_none_of_them_uses() {
        let defaults = RenderSettings::default();
        let first = QuantityState::joining(Source::Volume(0), &defaults, &[]);
        assert_eq!(first.cloud.positive_color, defaults.volume.positive_color, "alone: the defaults");
        let second = QuantityState::joining(Source::Volume(1), &defaults, std::slice::from_ref(&first));
        let third = QuantityState::joining(Source::Volume(2), &defaults, &[first.clone(), second.clone()]);
        let colours: Vec<[f32; 3]> =
            [&first, &second, &third].iter().flat_map(|q| [q.cloud.positive_color, q.cloud.negative_color]).collect();
        // No two of the six colours alike: the density beside a HOMO is not its red.
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                let d: f32 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
                assert!(d > 0.1, "{a:?} and {b:?} look alike: {colours:?}");
            }
        }
        assert_eq!(second.isosurfaces[0].positive_color, second.cloud.positive_color);
    }

    #[test]
    fn atom_looks_move_between_render_settings() {
        let settings = RenderSettings { atoms: AtomStyle::Licorice, depth_cue: 0.4, ..RenderSettings::default() };
        let look = AtomLook::of(&settings);
        assert_eq!(look.style, AtomStyle::Licorice);
        assert_eq!(look.onto(RenderSettings::default()), settings);
    }
}
