//! Normal modes of vibration: each mode's frequency, IR intensity and the Cartesian
//! displacement of every atom, as a frequency calculation gives them; the geometry they belong
//! to; a mode's displaced geometry and the IR spectrum they make.

use glam::DVec3;

use super::spectrum;
use serde::Serialize;

/// One normal mode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NormalMode {
    /// Wavenumber in cm⁻¹; an imaginary frequency is negative (as Molden and Gaussian write it).
    pub frequency_cm1: f64,
    /// IR intensity in km/mol, where the file gives it.
    pub ir_intensity: Option<f64>,
    /// Each atom's displacement, as the file gives it (Cartesian, in the file's normalisation).
    #[serde(serialize_with = "as_triples")]
    pub displacement: Vec<DVec3>,
}

fn as_triples<S: serde::Serializer>(v: &[DVec3], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(v.iter().map(glam::DVec3::to_array))
}

impl NormalMode {
    /// A transition state's mode (or a wrong minimum's): an imaginary frequency.
    pub fn is_imaginary(&self) -> bool {
        self.frequency_cm1 < 0.0
    }

    /// The largest displacement of any atom (what an amplitude is measured against).
    pub fn largest_displacement(&self) -> f64 {
        self.displacement.iter().map(|d| d.length()).fold(0.0, f64::max)
    }
}

/// The normal modes of a molecule and the geometry (bohr) they were computed at.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Vibrations {
    pub modes: Vec<NormalMode>,
    /// The geometry the modes belong to (bohr); one position per atom of the molecule.
    pub geometry: Vec<DVec3>,
    /// Where the geometry comes from ("[FR-COORD]", "the molecule's"), for the user.
    pub geometry_from: String,
}

impl Vibrations {
    /// The geometry displaced along mode `mode` at `phase` (radians) of its oscillation, the
    /// largest atom's displacement `amplitude` bohr at the turning points; `None` for a mode that
    /// is not there.
    pub fn displaced(&self, mode: usize, phase: f64, amplitude: f64) -> Option<Vec<DVec3>> {
        let m = self.modes.get(mode)?;
        let scale = amplitude * phase.sin() / m.largest_displacement().max(1e-12);
        Some(self.geometry.iter().zip(&m.displacement).map(|(p, d)| *p + *d * scale).collect())
    }

    /// The real mode whose band is nearest wavenumber `x`, within `tolerance` cm⁻¹ (a click on
    /// a spectrum).
    pub fn mode_at(&self, x: f64, tolerance: f64) -> Option<usize> {
        (self.modes.iter().enumerate())
            .filter(|(_, m)| !m.is_imaginary() && (m.frequency_cm1 - x).abs() <= tolerance)
            .min_by(|a, b| (a.1.frequency_cm1 - x).abs().total_cmp(&(b.1.frequency_cm1 - x).abs()))
            .map(|(k, _)| k)
    }

    /// The mode whose band is highest at wavenumber `x` in the spectrum broadened as
    /// [`Self::ir_spectrum`] says ([`spectrum::tallest_at`]). Without intensities (or where no
    /// band rises), the nearest real mode within `tolerance` cm⁻¹.
    pub fn band_at(&self, x: f64, fwhm: f64, lorentzian: bool, tolerance: f64) -> Option<usize> {
        spectrum::tallest_at(&self.lines(), x, fwhm, lorentzian, tolerance).or_else(|| self.mode_at(x, tolerance))
    }

    /// The IR spectrum from `from` to `to` cm⁻¹ in `points` steps: every mode with an intensity
    /// broadened to a Lorentzian (or a Gaussian) of full width `fwhm` cm⁻¹ at half maximum and
    /// peak height its intensity. Imaginary modes are left out.
    pub fn ir_spectrum(&self, range: (f64, f64), points: usize, fwhm: f64, lorentzian: bool) -> Vec<[f64; 2]> {
        let lines: Vec<spectrum::Line> = self.lines().into_iter().flatten().collect();
        spectrum::broadened(&lines, range, points, fwhm, lorentzian)
    }

    /// Each mode's line (wavenumber, intensity); none for an imaginary mode or one without an
    /// intensity.
    fn lines(&self) -> Vec<Option<spectrum::Line>> {
        (self.modes.iter())
            .map(|m| {
                let height = m.ir_intensity.filter(|_| !m.is_imaginary())?;
                Some(spectrum::Line { position: m.frequency_cm1, height })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn water() -> Vibrations {
        let mode = |f, i, d: [[f64; 3]; 3]| NormalMode {
            frequency_cm1: f,
            ir_intensity: i,
            displacement: d.iter().map(|&v| DVec3::from(v)).collect(),
        };
        Vibrations {
            modes: vec![
                mode(-250.0, Some(5.0), [[0.0, 0.0, 0.1], [0.0, 0.0, -0.5], [0.0, 0.0, -0.5]]),
                mode(1600.0, Some(60.0), [[0.0, 0.0, -0.07], [0.0, 0.43, 0.56], [0.0, -0.43, 0.56]]),
                mode(3700.0, Some(10.0), [[0.0, 0.0, 0.05], [0.0, -0.58, -0.40], [0.0, 0.58, -0.40]]),
            ],
            geometry: vec![DVec3::new(0.0, 0.0, 0.22), DVec3::new(0.0, 1.43, -0.89), DVec3::new(0.0, -1.43, -0.89)],
            geometry_from: "[FR-COORD]".into(),
        }
    }

    #[test]
    fn a_mode_displaces_the_geometry_by_its_amplitude() {
        let v = water();
        assert!(v.modes[0].is_imaginary() && !v.modes[1].is_imaginary());
        let rest = v.displaced(1, 0.0, 0.3).unwrap();
        assert_eq!(rest, v.geometry, "phase 0: the geometry itself");
        let turned = v.displaced(1, std::f64::consts::FRAC_PI_2, 0.3).unwrap();
        let moved: Vec<f64> = turned.iter().zip(&v.geometry).map(|(a, b)| (*a - *b).length()).collect();
        let most = moved.iter().cloned().fold(0.0, f64::max);
        assert!((most - 0.3).abs() < 1e-12, "the largest move is the amplitude: {moved:?}");
        assert!(v.displaced(7, 0.0, 0.3).is_none());
    }

    #[test]
    fn the_spectrum_peaks_at_each_real_mode_with_its_intensity() {
        let v = water();
        let spectrum = v.ir_spectrum((0.0, 4000.0), 4001, 20.0, true);
        let at = |x: f64| spectrum[x.round() as usize][1];
        assert!((at(1600.0) - 60.0).abs() < 0.1, "{}", at(1600.0));
        assert!((at(3700.0) - 10.0).abs() < 0.1);
        assert!((at(1610.0) - 30.0).abs() < 0.2, "half height at half the width: {}", at(1610.0));
        assert!(at(250.0) < 0.1, "the imaginary mode makes no peak");
        let gauss = v.ir_spectrum((1500.0, 1700.0), 201, 20.0, false);
        assert!((gauss[100][1] - 60.0).abs() < 1e-6 && (gauss[110][1] - 30.0).abs() < 1e-6);
        assert_eq!(v.mode_at(1590.0, 20.0), Some(1), "the band nearest the click");
        assert_eq!(v.mode_at(2500.0, 20.0), None, "nothing within the tolerance");
        assert_eq!(v.mode_at(-250.0, 20.0), None, "imaginary modes have no band");
    }

    #[test]
    fn a_click_picks_the_band_under_it_not_the_nearest_weak_one() {
        // A weak band 30 cm-1 from a tall one, 40 cm-1 wide: on the tall band's flank, nearer
        // the weak one's centre, the tall band is what the curve shows.
        let mut v = water();
        v.modes[2] = NormalMode { frequency_cm1: 1630.0, ir_intensity: Some(2.0), ..v.modes[2].clone() };
        assert_eq!(v.mode_at(1622.0, 20.0), Some(2), "the nearest centre is the weak band's");
        assert_eq!(v.band_at(1622.0, 40.0, true, 20.0), Some(1), "the band under the click is the tall one");
        assert_eq!(v.band_at(1630.0, 4.0, true, 20.0), Some(2), "narrow bands: each its own peak");
        assert_eq!(v.band_at(2500.0, 20.0, true, 20.0), None, "nothing under it");
        // Without intensities: the nearest mode.
        v.modes.iter_mut().for_each(|m| m.ir_intensity = None);
        assert_eq!(v.band_at(1622.0, 40.0, true, 20.0), Some(2));
    }
}
