//! Molecular orbitals over a basis: coefficients, energies, occupations, spin.

use serde::{Deserialize, Serialize};

use super::basis::Basis;
use super::excited_density::{ExcitedDensity, StatePart};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Spin {
    Alpha,
    Beta,
}

/// What a natural-orbital file writes as its orbitals' energies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergiesAsOccupations {
    /// Each orbital's occupation, as written in `Occup=`.
    Whole,
    /// Each orbital's occupation per spin: half of `Occup=` (Psi4's natural orbitals).
    PerSpin,
}

impl EnergiesAsOccupations {
    /// What the energies are, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Whole => "the file's energies are its occupations",
            Self::PerSpin => "the file's energies are its occupations per spin (half of Occup=)",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct MolecularOrbital {
    /// Energy in hartree (NaN when the file gives none).
    pub energy: f64,
    /// Electrons in the orbital: 0..2 for restricted, 0..1 for unrestricted.
    pub occupation: f64,
    pub spin: Spin,
    /// Symmetry label as written ("" when none).
    pub symmetry: String,
    /// One coefficient per basis function, in the basis's function order.
    pub coefficients: Vec<f64>,
}

/// How a file's coefficients were made to describe orthonormal orbitals.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Normalization {
    /// The writer the reader recognised ("ORCA", "Turbomole", "unknown", …).
    pub program: String,
    /// The repair applied, if any ("none" when the file was right as written).
    pub repair: String,
    /// max |CᵀSC − I| over the orbitals after the repair.
    pub residual: f64,
    /// Decimals the coefficients were printed to, when they come from a program's log (Gaussian
    /// prints 5, ORCA 6): the residual is then of the print's size and no repair is looked for.
    pub printed_decimals: Option<u32>,
}

impl Normalization {
    /// Where the coefficients come from, when that limits their precision: "coefficients
    /// printed to 5 decimals (a log)".
    pub fn precision_note(&self) -> Option<String> {
        self.printed_decimals.map(|d| format!("coefficients printed to {d} decimals (a log)"))
    }

    /// The residual the coefficients' precision accounts for: 1e-5 for files that write them in
    /// full, 100 units of the last printed decimal for a log (rounding errors of every
    /// coefficient of an orbital add up in CᵀSC).
    pub fn expected_residual(&self) -> f64 {
        self.printed_decimals.map_or(1e-5, |d| 100.0 * 10f64.powi(-(d.min(16) as i32)))
    }
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Wavefunction {
    pub basis: Basis,
    /// Alpha orbitals first (all orbitals of a restricted calculation are alpha), then beta.
    pub orbitals: Vec<MolecularOrbital>,
    /// True when alpha and beta share spatial orbitals.
    pub restricted: bool,
    pub normalization: Normalization,
    /// An excited state's density beside the ground state's, when the file holds one (a
    /// Gaussian TD fchk): shared, since it is large and never edited.
    pub excited: Option<std::sync::Arc<ExcitedDensity>>,
}

impl Wavefunction {
    /// Orbitals of one spin, with their indices into `orbitals`, in file order.
    pub fn of_spin(&self, spin: Spin) -> impl Iterator<Item = (usize, &MolecularOrbital)> {
        self.orbitals.iter().enumerate().filter(move |(_, o)| o.spin == spin)
    }

    /// Whether the orbitals of `spin` are natural orbitals (of a CI or CC density): some
    /// occupation is fractional, not 0, 1 or 2.
    pub fn natural(&self, spin: Spin) -> bool {
        self.of_spin(spin).any(|(_, o)| [0.0, 1.0, 2.0].iter().all(|&n| (o.occupation - n).abs() > 1e-3))
    }

    /// How the file's "energies" hold its occupations, when they do (natural-orbital files write
    /// them in place of energies): then they are no energies to show.
    pub fn energies_as_occupations(&self) -> Option<EnergiesAsOccupations> {
        if self.orbitals.is_empty() {
            return None;
        }
        let all = |f: &dyn Fn(&MolecularOrbital) -> bool| self.orbitals.iter().all(f);
        if all(&|o| (o.energy - o.occupation).abs() < 1e-9) {
            return Some(EnergiesAsOccupations::Whole);
        }
        // Psi4 writes a restricted density's natural orbitals with `Ene=` the occupation of one
        // spin, in [0, 1], and `Occup=` that of both.
        let per_spin = |o: &MolecularOrbital| {
            (-1e-9..=1.0 + 1e-9).contains(&o.energy) && (2.0 * o.energy - o.occupation).abs() < 1e-9
        };
        (self.restricted && all(&per_spin)).then_some(EnergiesAsOccupations::PerSpin)
    }

    /// Whether the file's "energies" are its occupations, whole or per spin.
    pub fn energies_are_occupations(&self) -> bool {
        self.energies_as_occupations().is_some()
    }

    /// Orbital `i`'s energy (hartree), when the file gives one: not when its "energies" are
    /// occupations, nor when it wrote none.
    pub fn energy(&self, i: usize) -> Option<f64> {
        let e = self.orbitals.get(i)?.energy;
        (e.is_finite() && !self.energies_are_occupations()).then_some(e)
    }

    /// Orbital `i`'s energy in words: "E = -0.31269 Eh (-8.509 eV)", or that the file gives none.
    pub fn energy_text(&self, i: usize) -> String {
        match self.energy(i) {
            Some(e) => format!("E = {e:.5} Eh ({:.3} eV)", e * super::units::EV_PER_HARTREE),
            None if self.energies_are_occupations() => "no energy (natural orbitals)".into(),
            None => "no energy in the file".into(),
        }
    }

    /// The occupation above which a natural orbital counts as occupied: half of what the
    /// orbital can hold.
    fn half_filled(&self) -> f64 {
        if self.restricted { 1.0 } else { 0.5 }
    }

    /// Index of the highest occupied orbital of a spin, if any: by energy; for natural orbitals
    /// the least occupied of those holding more than half an orbital's electrons.
    pub fn homo(&self, spin: Spin) -> Option<usize> {
        if self.natural(spin) {
            let half = self.half_filled();
            return (self.of_spin(spin).filter(|(_, o)| o.occupation > half))
                .min_by(|a, b| a.1.occupation.total_cmp(&b.1.occupation))
                .map(|(i, _)| i);
        }
        self.of_spin(spin)
            .filter(|(_, o)| o.occupation > 1e-6)
            .max_by(|a, b| a.1.energy.total_cmp(&b.1.energy))
            .map(|(i, _)| i)
    }

    /// Index of the lowest unoccupied orbital of a spin, if any: by energy; for natural orbitals
    /// the most occupied of those holding at most half.
    pub fn lumo(&self, spin: Spin) -> Option<usize> {
        if self.natural(spin) {
            let half = self.half_filled();
            return (self.of_spin(spin).filter(|(_, o)| o.occupation <= half))
                .max_by(|a, b| a.1.occupation.total_cmp(&b.1.occupation))
                .map(|(i, _)| i);
        }
        self.of_spin(spin)
            .filter(|(_, o)| o.occupation <= 1e-6)
            .min_by(|a, b| a.1.energy.total_cmp(&b.1.energy))
            .map(|(i, _)| i)
    }
}

/// What of a wavefunction is evaluated or shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Quantity {
    /// An orbital, by index into `Wavefunction::orbitals`.
    Orbital(usize),
    /// The total electron density Σ occ |φ|².
    #[default]
    Density,
    /// α − β density.
    SpinDensity,
    /// A bare basis function (an atomic orbital, normalised as the basis defines it), by index
    /// into the basis's functions: coefficient 1 on it, 0 elsewhere.
    BasisFunction(usize),
    /// The electrostatic potential of the nuclei and the electrons (a.u.).
    Potential,
    /// The reduced density gradient s = |∇ρ| / (2(3π²)^{1/3} ρ^{4/3}) (NCI).
    ReducedGradient,
    /// The reduced density gradient where ρ is at most NCIPLOT's cut for a wavefunction's
    /// density (0.05 a.u.), and 100 where it is above: what NCI surfaces (s = 0.5) are cut from,
    /// so that the small s near the nuclei draws nothing.
    NciGradient,
    /// An NCI cloud's field: sign(λ₂)ρ weighted by how far s lies below the NCI level,
    /// sign(λ₂)ρ · (1 − s/0.5) where s < 0.5 and ρ ≤ 0.05 a.u., 0 elsewhere. Drawn as a signed
    /// cloud: its opacity grows with the interaction's density and its depth below the level,
    /// its colour is the sign (blue attraction, red repulsion).
    NciCloud,
    /// sign(λ₂)·ρ, λ₂ the middle eigenvalue of the density's Hessian (NCI, a.u.).
    SignLambda2Rho,
    /// ∇²ρ, the Laplacian of the total density (a.u.).
    DensityLaplacian,
    /// ρ_exc − ρ_gs: the excited state's density minus the ground state's (an excited-state
    /// file's, [`Wavefunction::excited`]).
    DifferenceDensity,
    /// Where an excitation's electrons go: the positive part of the difference density's
    /// natural orbitals (Head-Gordon's attachment density).
    Attachment,
    /// Where they come from: the negative part, as a positive density (the detachment density).
    Detachment,
    /// The excited state's own density.
    ExcitedDensity,
    /// State n's transition density ρ₀ₙ (its number as the program prints it), from the
    /// amplitudes the document lists ([`super::transition`]): signed, like an orbital.
    TransitionDensity(usize),
}

impl Quantity {
    /// Whether the quantity is made of the total density's first and second derivatives
    /// (evaluated by [`super::nci`]).
    pub fn from_density_derivatives(self) -> bool {
        matches!(
            self,
            Self::ReducedGradient | Self::NciGradient | Self::NciCloud | Self::SignLambda2Rho | Self::DensityLaplacian
        )
    }

    /// Which of an excited state's densities the quantity is, if it is one.
    pub fn state_part(self) -> Option<StatePart> {
        match self {
            Self::DifferenceDensity => Some(StatePart::Difference),
            Self::Attachment => Some(StatePart::Attachment),
            Self::Detachment => Some(StatePart::Detachment),
            Self::ExcitedDensity => Some(StatePart::Excited),
            _ => None,
        }
    }
}

/// Which orbital a user means: `homo`, `lumo`, `homo-2`, `lumo+1`, or a 1-based index into the
/// orbitals of the chosen spin (as programs number them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrbitalSpec {
    /// HOMO − n.
    Homo(usize),
    /// LUMO + n.
    Lumo(usize),
    /// 1-based index within the spin's orbitals.
    Index(usize),
    /// A natural transition orbital by its label: pair n's hole ("hole 1") or particle.
    Hole(usize),
    Particle(usize),
}

impl std::str::FromStr for OrbitalSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim().to_ascii_lowercase().replace('−', "-");
        let offset = |rest: &str, sign: char| -> Result<usize, String> {
            if rest.is_empty() {
                return Ok(0);
            }
            rest.strip_prefix(sign)
                .and_then(|n| n.parse::<usize>().ok())
                .ok_or_else(|| format!("expected homo, lumo, homo-N, lumo+N or an index, got {s:?}"))
        };
        // "hole 1", "particle2": a natural transition orbital's label.
        for (word, make) in [("hole", Self::Hole as fn(usize) -> Self), ("particle", Self::Particle)] {
            if let Some(rest) = t.strip_prefix(word) {
                return match rest.trim().parse::<usize>() {
                    Ok(n) if n >= 1 => Ok(make(n)),
                    _ => Err(format!("expected {word} N (a natural transition orbital, N from 1), got {s:?}")),
                };
            }
        }
        if let Some(rest) = t.strip_prefix("homo") {
            Ok(Self::Homo(offset(rest, '-')?))
        } else if let Some(rest) = t.strip_prefix("lumo") {
            Ok(Self::Lumo(offset(rest, '+')?))
        } else {
            match t.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(Self::Index(n)),
                _ => Err(format!("expected homo, lumo, homo-N, lumo+N or a 1-based index, got {s:?}")),
            }
        }
    }
}

impl std::fmt::Display for OrbitalSpec {
    /// As a user writes it: "homo", "homo-2", "lumo+1", "12".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Homo(0) => write!(f, "homo"),
            Self::Homo(k) => write!(f, "homo-{k}"),
            Self::Lumo(0) => write!(f, "lumo"),
            Self::Lumo(k) => write!(f, "lumo+{k}"),
            Self::Index(n) => write!(f, "{n}"),
            Self::Hole(n) => write!(f, "hole {n}"),
            Self::Particle(n) => write!(f, "particle {n}"),
        }
    }
}

impl Wavefunction {
    /// What orbitals of `spin` there are, for a request that named none: "the file has 12
    /// orbitals (1–12), the HOMO is 9".
    pub fn available(&self, spin: Spin) -> String {
        let spin = self.effective_spin(spin);
        let n = self.of_spin(spin).count();
        let which = if self.restricted { String::new() } else { format!(" {spin:?}").to_lowercase() };
        let homo = (self.homo(spin).and_then(|h| self.of_spin(spin).position(|(i, _)| i == h)))
            .map_or(String::new(), |p| format!(", the HOMO is {}", p + 1));
        format!("the file has {n}{which} orbitals (1–{n}){homo}")
    }

    /// Indices into `orbitals` of one spin, sorted by energy (stable for equal energies); natural
    /// orbitals, whose energies mean nothing, by falling occupation (the most occupied "lowest").
    pub fn by_energy(&self, spin: Spin) -> Vec<usize> {
        let mut v: Vec<usize> = self.of_spin(spin).map(|(i, _)| i).collect();
        let o = &self.orbitals;
        match self.natural(spin) {
            true => v.sort_by(|&a, &b| o[b].occupation.total_cmp(&o[a].occupation)),
            false => v.sort_by(|&a, &b| o[a].energy.total_cmp(&o[b].energy)),
        }
        v
    }

    /// The spin a request for `spin` falls back to: beta asks of a restricted wavefunction
    /// mean its (alpha) spatial orbitals.
    fn effective_spin(&self, spin: Spin) -> Spin {
        if self.restricted { Spin::Alpha } else { spin }
    }

    /// Resolves a user's orbital request to an index into `orbitals`.
    pub fn resolve(&self, spec: OrbitalSpec, spin: Spin) -> Option<usize> {
        let spin = self.effective_spin(spin);
        match spec {
            OrbitalSpec::Index(n) => self.of_spin(spin).nth(n - 1).map(|(i, _)| i),
            OrbitalSpec::Homo(k) => {
                let order = self.by_energy(spin);
                let h = order.iter().position(|&i| Some(i) == self.homo(spin))?;
                h.checked_sub(k).map(|p| order[p])
            }
            OrbitalSpec::Lumo(k) => {
                let order = self.by_energy(spin);
                let l = order.iter().position(|&i| Some(i) == self.lumo(spin))?;
                order.get(l + k).copied()
            }
            OrbitalSpec::Hole(_) | OrbitalSpec::Particle(_) => {
                let label = spec.to_string();
                self.of_spin(spin).find(|(_, o)| o.symmetry == label).map(|(i, _)| i)
            }
        }
    }

    /// "HOMO", "HOMO−2", "LUMO+1" for orbitals near the frontier (within `range`), else None.
    pub fn frontier_label(&self, index: usize, range: usize) -> Option<String> {
        let spin = self.orbitals.get(index)?.spin;
        let order = self.by_energy(spin);
        let pos = order.iter().position(|&i| i == index)?;
        let homo = self.homo(spin).and_then(|h| order.iter().position(|&i| i == h));
        let lumo = self.lumo(spin).and_then(|l| order.iter().position(|&i| i == l));
        match (homo, lumo) {
            (Some(h), _) if pos <= h && h - pos <= range => {
                Some(if pos == h { "HOMO".into() } else { format!("HOMO-{}", h - pos) })
            }
            (_, Some(l)) if pos >= l && pos - l <= range => {
                Some(if pos == l { "LUMO".into() } else { format!("LUMO+{}", pos - l) })
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_orbitals_have_their_frontier_by_occupation() {
        // A CASSCF-like set: the "energies" are the occupations, in no useful order.
        let occ = [1.99, 0.02, 1.6, 0.4, 1.95, 0.05];
        let w = wf(&occ, &occ);
        assert!(w.natural(Spin::Alpha) && w.energies_are_occupations());
        assert_eq!(w.homo(Spin::Alpha), Some(2), "the last above 1");
        assert_eq!(w.lumo(Spin::Alpha), Some(3), "the first below");
        assert_eq!(w.by_energy(Spin::Alpha), [0, 4, 2, 3, 5, 1], "by falling occupation");
        assert_eq!(w.resolve(OrbitalSpec::Homo(1), Spin::Alpha), Some(4));
        assert_eq!(w.resolve(OrbitalSpec::Lumo(1), Spin::Alpha), Some(5));
        assert_eq!(w.frontier_label(4, 3).as_deref(), Some("HOMO-1"));
        // Psi4's natural orbitals of a restricted density: Ene= is half of Occup=.
        let halves: Vec<f64> = occ.iter().map(|o| o / 2.0).collect();
        let psi4 = wf(&occ, &halves);
        assert_eq!(psi4.energies_as_occupations(), Some(EnergiesAsOccupations::PerSpin));
        assert_eq!((psi4.energy(0), psi4.homo(Spin::Alpha)), (None, Some(2)));
        assert_eq!(w.energies_as_occupations(), Some(EnergiesAsOccupations::Whole));
        let unrestricted = Wavefunction { restricted: false, ..psi4.clone() };
        assert!(!unrestricted.energies_are_occupations(), "per spin only for a restricted set");
        let mut one_off = psi4;
        one_off.orbitals[3].energy += 1e-6;
        assert!(!one_off.energies_are_occupations() && one_off.energy(3).is_some());
        // A Hartree–Fock set is not natural, its energies are energies.
        let hf = wf(&[2.0, 2.0, 0.0], &[-0.5, -0.3, 0.1]);
        assert!(!hf.natural(Spin::Alpha) && !hf.energies_are_occupations());
        assert_eq!((hf.homo(Spin::Alpha), hf.lumo(Spin::Alpha)), (Some(1), Some(2)));
    }

    fn wf(occupations: &[f64], energies: &[f64]) -> Wavefunction {
        Wavefunction {
            orbitals: occupations
                .iter()
                .zip(energies)
                .map(|(&occupation, &energy)| MolecularOrbital {
                    energy,
                    occupation,
                    spin: Spin::Alpha,
                    symmetry: String::new(),
                    coefficients: vec![],
                })
                .collect(),
            restricted: true,
            ..Default::default()
        }
    }

    #[test]
    fn specs_parse() {
        assert_eq!("homo".parse(), Ok(OrbitalSpec::Homo(0)));
        assert_eq!("HOMO-2".parse(), Ok(OrbitalSpec::Homo(2)));
        assert_eq!("lumo+1".parse(), Ok(OrbitalSpec::Lumo(1)));
        assert_eq!("7".parse(), Ok(OrbitalSpec::Index(7)));
        assert_eq!("hole 1".parse(), Ok(OrbitalSpec::Hole(1)));
        assert_eq!("Particle2".parse(), Ok(OrbitalSpec::Particle(2)));
        assert!("hole".parse::<OrbitalSpec>().is_err() && "particle 0".parse::<OrbitalSpec>().is_err());
        assert!("0".parse::<OrbitalSpec>().is_err());
        assert!("homo+1".parse::<OrbitalSpec>().is_err());
        assert!("banana".parse::<OrbitalSpec>().is_err());
    }

    #[test]
    fn frontier_orbitals_by_energy_not_file_order() {
        // File order scrambled; energies decide.
        let w = wf(&[2.0, 0.0, 2.0, 2.0, 0.0], &[-0.5, 0.3, -1.0, -0.2, 0.1]);
        assert_eq!(w.homo(Spin::Alpha), Some(3));
        assert_eq!(w.lumo(Spin::Alpha), Some(4));
        assert_eq!(w.resolve(OrbitalSpec::Homo(1), Spin::Alpha), Some(0));
        assert_eq!(w.resolve(OrbitalSpec::Homo(2), Spin::Alpha), Some(2));
        assert_eq!(w.resolve(OrbitalSpec::Homo(3), Spin::Alpha), None);
        assert_eq!(w.resolve(OrbitalSpec::Lumo(1), Spin::Beta), Some(1));
        assert_eq!(w.resolve(OrbitalSpec::Index(2), Spin::Alpha), Some(1));
        assert_eq!(w.frontier_label(0, 3).as_deref(), Some("HOMO-1"));
        assert_eq!(w.frontier_label(1, 3).as_deref(), Some("LUMO+1"));
        assert_eq!(w.frontier_label(2, 1), None);
    }
}
