//! Atom colours: a small palette and one palette index per atom, so that recolouring a million
//! atoms rewrites four bytes each and nothing else.

use crate::model::elements::ELEMENTS;
use crate::model::structure::Secondary;
use crate::model::{Molecule, StructureView};

use super::settings::AtomColoring;

/// sRGB palette and, per atom of the molecule, an index into it and whether the atom is shown
/// (a selection's mask; empty: every atom).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AtomColors {
    pub palette: Vec<[u8; 3]>,
    pub index: Vec<u16>,
    pub shown: Vec<bool>,
}

/// An sRGB colour as linear RGB.
/// A map of values symmetric about zero, what a surface coloured by a volume and its colour bar
/// both use: diverging as the `scheme` says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValueMap {
    /// The |value| at which the colours saturate.
    pub range: f64,
    pub scheme: ColorScheme,
}

/// How a [`ValueMap`] colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum ColorScheme {
    /// −range red, zero white, +range blue: the convention of electrostatic potentials on
    /// surfaces.
    #[default]
    RedWhiteBlue,
    /// −range blue, zero green, +range red: NCI surfaces coloured by sign(λ₂)ρ as NCIPLOT's VMD
    /// scripts colour them (blue attraction, green van der Waals, red repulsion).
    BlueGreenRed,
}

impl ValueMap {
    const NEGATIVE: [f32; 3] = [0.85, 0.08, 0.06];
    const POSITIVE: [f32; 3] = [0.06, 0.2, 0.85];
    const NCI: [[f32; 3]; 3] = [[0.0, 0.1, 0.9], [0.05, 0.75, 0.1], [0.9, 0.05, 0.03]];

    /// The red-white-blue map saturating at `range`.
    pub fn diverging(range: f64) -> Self {
        Self { range, scheme: ColorScheme::RedWhiteBlue }
    }

    /// Linear RGB of `value`.
    pub fn color(&self, value: f64) -> [f32; 3] {
        self.at((value / self.range.max(1e-30)).clamp(-1.0, 1.0) as f32)
    }

    /// A colour bar's labels, bottom to top: "−0.022", "0", "+0.022" (three figures in
    /// scientific notation under 0.01).
    pub fn ticks(&self) -> [String; 3] {
        let r = self.range;
        let text = if r.abs() >= 0.01 { format!("{r:.3}") } else { format!("{r:.2e}") };
        [format!("−{text}"), "0".into(), format!("+{text}")]
    }

    /// A colour bar's title: the quantity's name, in atomic units.
    pub fn title(name: &str) -> String {
        if name.is_empty() { "value (a.u.)".to_string() } else { format!("{name} (a.u.)") }
    }

    /// Linear RGB at `t` in −1..1 of the range.
    pub fn at(&self, t: f32) -> [f32; 3] {
        let f = t.abs().min(1.0);
        match self.scheme {
            ColorScheme::RedWhiteBlue => {
                let end = if t < 0.0 { Self::NEGATIVE } else { Self::POSITIVE };
                std::array::from_fn(|k| 1.0 + (end[k] - 1.0) * f)
            }
            ColorScheme::BlueGreenRed => {
                let [blue, green, red] = Self::NCI;
                let end = if t < 0.0 { blue } else { red };
                std::array::from_fn(|k| green[k] + (end[k] - green[k]) * f)
            }
        }
    }
}

pub fn linear(srgb: [u8; 3]) -> [f32; 3] {
    srgb.map(|c| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    })
}

/// Ghost centres are grey whatever the colouring.
const GHOST: [u8; 3] = [90, 90, 90];

/// Twenty colours far apart, for chains (Mol*'s "many distinct" idea, simplified).
const DISTINCT: [[u8; 3]; 20] = [
    [230, 159, 0],
    [86, 180, 233],
    [0, 158, 115],
    [240, 228, 66],
    [0, 114, 178],
    [213, 94, 0],
    [204, 121, 167],
    [170, 170, 170],
    [144, 238, 144],
    [255, 105, 180],
    [138, 43, 226],
    [255, 215, 0],
    [64, 224, 208],
    [255, 127, 80],
    [154, 205, 50],
    [100, 149, 237],
    [220, 20, 60],
    [0, 206, 209],
    [244, 164, 96],
    [186, 85, 211],
];

/// Jmol's "amino" colours, then its nucleic-acid colours.
const RESIDUES: [(&str, [u8; 3]); 30] = [
    ("ALA", [200, 200, 200]),
    ("ARG", [20, 90, 255]),
    ("ASN", [0, 220, 220]),
    ("ASP", [230, 10, 10]),
    ("CYS", [230, 230, 0]),
    ("GLN", [0, 220, 220]),
    ("GLU", [230, 10, 10]),
    ("GLY", [235, 235, 235]),
    ("HIS", [130, 130, 210]),
    ("ILE", [15, 130, 15]),
    ("LEU", [15, 130, 15]),
    ("LYS", [20, 90, 255]),
    ("MET", [230, 230, 0]),
    ("PHE", [50, 50, 170]),
    ("PRO", [220, 150, 130]),
    ("SER", [250, 150, 0]),
    ("THR", [250, 150, 0]),
    ("TRP", [180, 90, 180]),
    ("TYR", [50, 50, 170]),
    ("VAL", [15, 130, 15]),
    ("A", [160, 160, 255]),
    ("DA", [160, 160, 255]),
    ("G", [255, 112, 112]),
    ("DG", [255, 112, 112]),
    ("C", [255, 140, 75]),
    ("DC", [255, 140, 75]),
    ("U", [255, 128, 128]),
    ("DT", [160, 255, 160]),
    ("HOH", [255, 40, 40]),
    ("WAT", [255, 40, 40]),
];
/// Anything else (ligands, ions).
const OTHER_RESIDUE: [u8; 3] = [190, 160, 110];

const HELIX: [u8; 3] = [255, 0, 128];
const SHEET: [u8; 3] = [255, 200, 0];
const COIL: [u8; 3] = [255, 255, 255];

/// Steps of the B-factor ramp.
const RAMP: usize = 64;

/// Blue → white → red at `t` in 0..=1.
fn ramp(t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f32, b: f32, s: f32| (a + (b - a) * s).round() as u8;
    if t < 0.5 {
        let s = 2.0 * t;
        [mix(40.0, 255.0, s), mix(60.0, 255.0, s), 255]
    } else {
        let s = 2.0 * t - 1.0;
        [255, mix(255.0, 30.0, s), mix(255.0, 30.0, s)]
    }
}

/// The colours of `molecule`'s atoms by `coloring`; colourings that need residues, chains or
/// B-factors fall back to elements for a file without them.
pub fn atom_colors(molecule: &Molecule, structure: Option<&StructureView>, coloring: AtomColoring) -> AtomColors {
    let by_element = || {
        let mut palette: Vec<[u8; 3]> = ELEMENTS.iter().map(|e| e.color).collect();
        palette.push(GHOST);
        let ghost = (palette.len() - 1) as u16;
        let index = molecule.atoms.iter().map(|a| if a.ghost { ghost } else { a.z.min(118) as u16 }).collect();
        AtomColors { palette, index, shown: Vec::new() }
    };
    let Some(view) = structure.filter(|v| v.atoms.len() == molecule.atoms.len()) else { return by_element() };
    let s = &view.structure;
    let residue_of = |k: usize| &s.residues[s.residue[view.atoms[k] as usize] as usize];
    let per_atom = |palette: Vec<[u8; 3]>, f: &dyn Fn(usize) -> u16| AtomColors {
        index: (0..molecule.atoms.len()).map(f).collect(),
        palette,
        shown: Vec::new(),
    };
    match coloring {
        AtomColoring::Element => by_element(),
        AtomColoring::Chain => {
            // Chains of the same name share a colour (in every model).
            let mut names: Vec<&str> = Vec::new();
            let chain_color: Vec<u16> = s
                .chains
                .iter()
                .map(|c| {
                    let n = names.iter().position(|&x| x == c.name.as_str()).unwrap_or_else(|| {
                        names.push(c.name.as_str());
                        names.len() - 1
                    });
                    (n % DISTINCT.len()) as u16
                })
                .collect();
            per_atom(DISTINCT.to_vec(), &|k| chain_color[residue_of(k).chain as usize])
        }
        AtomColoring::Residue => {
            let mut palette: Vec<[u8; 3]> = RESIDUES.iter().map(|(_, c)| *c).collect();
            palette.push(OTHER_RESIDUE);
            per_atom(palette, &|k| {
                let name = residue_of(k).name.as_str();
                RESIDUES.iter().position(|(n, _)| *n == name).unwrap_or(RESIDUES.len()) as u16
            })
        }
        AtomColoring::BFactor => {
            let b = |k: usize| s.b_factor[view.atoms[k] as usize];
            let (lo, hi) =
                (0..molecule.atoms.len()).map(b).fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v), h.max(v)));
            let span = (hi - lo).max(1e-6);
            let palette = (0..RAMP).map(|i| ramp(i as f32 / (RAMP - 1) as f32)).collect();
            per_atom(palette, &|k| (((b(k) - lo) / span) * (RAMP - 1) as f32).round() as u16)
        }
        AtomColoring::Secondary => per_atom(vec![COIL, HELIX, SHEET], &|k| match residue_of(k).secondary {
            Secondary::None => 0,
            Secondary::Helix => 1,
            Secondary::Sheet => 2,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_runs_blue_white_red() {
        assert_eq!(ramp(0.0), [40, 60, 255]);
        assert_eq!(ramp(0.5), [255, 255, 255]);
        assert_eq!(ramp(1.0), [255, 30, 30]);
    }

    #[test]
    fn plain_molecules_fall_back_to_elements() {
        use crate::model::Atom;
        let atom = |z| Atom { z, charge: z as f64, position: glam::DVec3::ZERO, ghost: z == 0 };
        let m = Molecule { atoms: vec![atom(8), atom(1), atom(0)], bonds: vec![] };
        let c = atom_colors(&m, None, AtomColoring::Chain);
        assert_eq!(c.palette[c.index[0] as usize], ELEMENTS[8].color);
        assert_eq!(c.palette[c.index[2] as usize], GHOST);
    }
}
