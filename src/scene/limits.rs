//! The ranges the values a session (`*.orbcloud.toml`) or the command line gives must lie in
//! (a scan manifest's frames lie in their coordinate's, `model::scan`), [`Session::sanitize`],
//! the one place a session's values are brought into them, and [`within`], the command line's
//! parser that refuses a number outside them. A hand-edited or damaged session could otherwise ask for four billion slices (an
//! allocation that aborts the viewer and loses everything open), a NaN camera (a blank or
//! garbled frame) or an isovalue no grid reaches. Out of range values are clamped and non-finite
//! ones replaced by the default, each with a note naming the key, so a session always opens.

use std::fmt::Display;
use std::ops::RangeInclusive;

use super::camera::PITCH_LIMIT;
use super::excited_view::ExcitedView;
use super::objects::MAX_PANES;
use super::scan_state::{LegacyScan, ScanState};
use super::translucency::OpticsTuning;
use super::vibration::VibrationState;
use super::{
    AtomLook, Camera, ClipPlane, DensityScale, Evaluation, IsoLevel, IsosurfaceSettings, ObjectState, Placement,
    QuantityState, Session, SurfaceSettings, Transfer, VolumeSettings,
};
use crate::model::scan::MAX_SCAN_ORBITALS;

/// Slices through a cloud: beyond a few thousand they add nothing a pixel shows.
pub const SLICES: RangeInclusive<u32> = 1..=4096;
/// Points per axis of an evaluation grid (512³ values is 512 MiB of f32).
pub const GRID_POINTS: RangeInclusive<usize> = 8..=512;
/// Opacity scale k1 and shape k2 of α = k1·ρ^k2.
pub const K1: RangeInclusive<f32> = 0.0..=1000.0;
pub const K2: RangeInclusive<f32> = 0.0..=16.0;
/// The largest |isovalue| (a.u.): far beyond any orbital's or density's values.
pub const ISOVALUE: RangeInclusive<f32> = 0.0..=1e6;
/// An isosurface at a multiple of the grid's σ.
pub const SIGMA: RangeInclusive<f32> = 0.0..=1000.0;
/// Factors on the atom style's ball and stick radii.
pub const ATOM_SCALE: RangeInclusive<f32> = 0.3..=3.0;
/// Fractions: depth cue, boundary enhancement, a lobe's centre, colour channels (linear RGB).
pub const FRACTION: RangeInclusive<f32> = 0.0..=1.0;
/// A shaped transfer function's width (a fraction of max|value|) and peak opacity.
pub const LOBE_WIDTH: RangeInclusive<f32> = 1e-4..=1.0;
pub const LOBE_OPACITY: RangeInclusive<f32> = 0.0..=100.0;
pub const GRADIENT_POWER: RangeInclusive<f32> = 0.0..=16.0;
/// Positions and offsets, bohr: a million bohr is 50 µm, far past any molecule.
pub const POSITION: RangeInclusive<f32> = -1e6..=1e6;
/// The camera's distance from its target, bohr.
pub const DISTANCE: RangeInclusive<f32> = 1e-3..=1e6;
/// The camera's vertical field of view, radians (1° to 170°).
pub const FOV_Y: RangeInclusive<f32> = 0.017_453_292..=2.967_06;
/// The bounds of a logarithmic density scale (a.u.).
pub const DENSITY_BOUND: RangeInclusive<f32> = 1e-12..=1e6;
/// Per-channel factors on a translucent surface's optics.
pub const OPTICS_FACTOR: RangeInclusive<f32> = 0.0..=100.0;
/// A molecular surface's grid spacing and probe radius (Å), its smoothness, its level of
/// detail (pixels).
pub const SURFACE_RESOLUTION: RangeInclusive<f32> = 0.05..=5.0;
pub const PROBE: RangeInclusive<f32> = 0.0..=10.0;
pub const SMOOTHNESS: RangeInclusive<f32> = 0.1..=20.0;
pub const LOD_PX: RangeInclusive<f32> = 0.0..=1000.0;
/// A normal mode's amplitude (bohr), its oscillations per second and the IR bands' FWHM (cm⁻¹).
pub const AMPLITUDE: RangeInclusive<f32> = 0.0..=10.0;
pub const SPEED: RangeInclusive<f32> = 0.0..=100.0;
pub const FWHM: RangeInclusive<f32> = 0.1..=10_000.0;
/// A UV-vis band's full width at half maximum, eV.
pub const FWHM_EV: RangeInclusive<f32> = 0.01..=5.0;
/// Angles the command line turns by (degrees), its zoom factor.
pub const ANGLE_DEG: RangeInclusive<f32> = -1e6..=1e6;
pub const ZOOM: RangeInclusive<f32> = 1e-3..=1e3;
/// A cube's grid spacing and the margin around the atoms, bohr.
pub const SPACING: RangeInclusive<f64> = 1e-3..=10.0;
pub const MARGIN: RangeInclusive<f64> = 0.0..=100.0;
/// The density above which `nci` cuts points (a.u.).
pub const DENSITY_CUT: RangeInclusive<f64> = 1e-6..=10.0;
/// The reduced density gradient `render --nci` draws its surface at.
pub const NCI_LEVEL: RangeInclusive<f32> = 0.01..=2.0;
/// Where `render --nci`'s colours saturate, |sign(λ₂)ρ| (a.u.).
pub const NCI_RANGE: RangeInclusive<f32> = 1e-3..=1.0;
/// The RDG cutoff of `nci`'s -grad cube.
pub const RDG_CUT: RangeInclusive<f64> = 1e-3..=100.0;
/// The most points an `nci` grid may have: its two cubes are held in memory as f32.
pub const NCI_POINTS: u64 = 1 << 27;
/// Frames of a movie, a mode's period or a benchmark, and a movie's frames per second.
pub const FRAMES: RangeInclusive<usize> = 1..=100_000;
pub const FPS: RangeInclusive<f64> = 0.1..=240.0;
/// A scan's animation speed: its coordinate's units per second.
pub const SCAN_SPEED: RangeInclusive<f32> = 1e-6..=1e6;
/// Quantities per object and isosurfaces per quantity: each is a layer of GPU work.
pub const MAX_QUANTITIES: usize = 64;
pub const MAX_ISOSURFACES: usize = 64;

/// `range` as a message writes it: `1..=4096`.
fn shown<T: Display>(range: &RangeInclusive<T>) -> String {
    format!("{}..={}", range.start(), range.end())
}

/// Where notes are gathered: each says which key changed, from what, to what.
pub struct Notes<'a> {
    list: &'a mut Vec<String>,
}

impl Notes<'_> {
    fn note(&mut self, key: &str, what: String) {
        self.list.push(format!("{key}: {what}"));
    }

    /// A count or index, clamped into `range`.
    fn count<T: Copy + Ord + Display>(&mut self, key: &str, v: &mut T, range: RangeInclusive<T>) {
        let clamped = (*v).clamp(*range.start(), *range.end());
        if clamped != *v {
            self.note(key, format!("{v} is outside {}; {clamped} used", shown(&range)));
            *v = clamped;
        }
    }

    /// A real: `default` when it is no finite number, else clamped into `range`.
    fn real(&mut self, key: &str, v: &mut f32, range: RangeInclusive<f32>, default: f32) {
        if !v.is_finite() {
            self.note(key, format!("{v} is not a finite number; {default} used"));
            *v = default;
        } else if !range.contains(v) {
            let clamped = v.clamp(*range.start(), *range.end());
            self.note(key, format!("{v} is outside {}; {clamped} used", shown(&range)));
            *v = clamped;
        }
    }

    /// A linear RGB colour, each channel in 0..=1.
    fn color(&mut self, key: &str, c: &mut [f32; 3]) {
        for (k, v) in c.iter_mut().enumerate() {
            self.real(&format!("{key}[{k}]"), v, FRACTION, 0.5);
        }
    }

    /// A point or an offset, bohr.
    fn position(&mut self, key: &str, p: &mut [f32; 3]) {
        for (k, v) in p.iter_mut().enumerate() {
            self.real(&format!("{key}[{k}]"), v, POSITION, 0.0);
        }
    }
}

impl Session {
    /// Brings every value into the ranges above; returns a note per value changed, each naming
    /// its key (`objects[0].quantities[1].cloud.slices`, counting from 0).
    pub fn sanitize(&mut self) -> Vec<String> {
        let mut list = Vec::new();
        let mut n = Notes { list: &mut list };
        self.camera.sanitize("camera", &mut n);
        n.count("panes.count", &mut self.panes.count, 1..=MAX_PANES);
        for (k, camera) in self.panes.cameras.iter_mut().enumerate() {
            camera.sanitize(&format!("panes.cameras[{k}]"), &mut n);
        }
        if let Some(bg) = &mut self.background {
            n.color("background", bg);
        }
        let mut k = 0;
        self.measurements.retain(|m| {
            let fine = crate::model::measure::Measurement::new(&m.atoms).is_some();
            if !fine {
                n.note(
                    &format!("measurements[{k}]"),
                    format!("atoms {:?} are not 2 to 4 distinct atoms; left out", m.atoms),
                );
            }
            k += 1;
            fine
        });
        for (k, object) in self.objects.iter_mut().enumerate() {
            object.sanitize(&format!("objects[{k}]"), &mut n);
        }
        if let Some(scan) = &mut self.scan {
            scan.sanitize("scan", &mut n);
        }
        list
    }
}

impl ScanState {
    /// The value itself is clamped into the scan's range when the scan has opened.
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        if !self.value.is_finite() {
            n.note(&format!("{key}.value"), format!("{} is not a finite number; 0 used", self.value));
            self.value = 0.0;
        }
        let mut speed = self.speed as f32;
        n.real(&format!("{key}.speed"), &mut speed, SCAN_SPEED, 30.0);
        self.speed = f64::from(speed);
        n.count(&format!("{key}.diagram"), &mut self.diagram, 0..=8);
        let orbitals = self.orbitals.len();
        if orbitals > MAX_SCAN_ORBITALS {
            n.note(&format!("{key}.orbitals"), format!("{orbitals} orbitals; the first {MAX_SCAN_ORBITALS} kept"));
            self.orbitals.truncate(MAX_SCAN_ORBITALS);
        }
    }
}

impl LegacyScan {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        self.state.sanitize(key, n);
        let s = &mut self.settings;
        s.volume.sanitize(&format!("{key}.settings.volume"), n);
        s.iso.sanitize(&format!("{key}.settings.iso"), n);
        s.clip.sanitize(&format!("{key}.settings.clip"), n);
        n.color(&format!("{key}.settings.background"), &mut s.background);
        n.real(&format!("{key}.settings.depth_cue"), &mut s.depth_cue, FRACTION, 0.0);
        n.real(&format!("{key}.settings.ball_scale"), &mut s.ball_scale, ATOM_SCALE, 1.0);
        n.real(&format!("{key}.settings.stick_scale"), &mut s.stick_scale, ATOM_SCALE, 1.0);
    }
}

impl Camera {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = Camera::default();
        let mut target = self.target.to_array();
        n.position(&format!("{key}.target"), &mut target);
        self.target = target.into();
        n.real(&format!("{key}.yaw"), &mut self.yaw, -1e6..=1e6, 0.0);
        self.yaw %= std::f32::consts::TAU;
        n.real(&format!("{key}.pitch"), &mut self.pitch, -PITCH_LIMIT..=PITCH_LIMIT, 0.0);
        n.real(&format!("{key}.distance"), &mut self.distance, DISTANCE, default.distance);
        n.real(&format!("{key}.fov_y"), &mut self.fov_y, FOV_Y, default.fov_y);
        let q = self.orientation;
        // Components near f32::MAX overflow the length: no rotation to normalise either.
        if !q.is_finite() || !(1e-6..=1e6).contains(&q.length()) {
            n.note(&format!("{key}.orientation"), format!("{q} is no rotation; none used"));
            self.orientation = glam::Quat::IDENTITY;
        } else {
            self.orientation = q.normalize();
        }
    }
}

impl ObjectState {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        self.placement.sanitize(&format!("{key}.placement"), n);
        self.atoms.sanitize(&format!("{key}.atoms"), n);
        if self.quantities.len() > MAX_QUANTITIES {
            n.note(
                &format!("{key}.quantities"),
                format!(
                    "{} quantities, more than {MAX_QUANTITIES}; the first {MAX_QUANTITIES} kept",
                    self.quantities.len()
                ),
            );
            self.quantities.truncate(MAX_QUANTITIES);
        }
        for (k, q) in self.quantities.iter_mut().enumerate() {
            q.sanitize(&format!("{key}.quantities[{k}]"), n);
        }
        let last = self.quantities.len().saturating_sub(1);
        n.count(&format!("{key}.selected"), &mut self.selected, 0..=last);
        self.evaluation.sanitize(&format!("{key}.evaluation"), n);
        self.surface.sanitize(&format!("{key}.surface"), n);
        self.vibration.sanitize(&format!("{key}.vibration"), n);
        let default = ExcitedView::default();
        n.real(&format!("{key}.excited.fwhm_ev"), &mut self.excited.fwhm_ev, FWHM_EV, default.fwhm_ev);
        self.clip.sanitize(&format!("{key}.clip"), n);
        if let Some(scan) = &mut self.scan {
            scan.sanitize(&format!("{key}.scan"), n);
        }
    }
}

impl Placement {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        n.position(&format!("{key}.offset"), &mut self.offset);
        for (k, angle) in self.rotation_deg.iter_mut().enumerate() {
            n.real(&format!("{key}.rotation_deg[{k}]"), angle, -1e6..=1e6, 0.0);
            *angle %= 360.0;
        }
    }
}

impl AtomLook {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        n.real(&format!("{key}.depth_cue"), &mut self.depth_cue, FRACTION, 0.0);
        n.real(&format!("{key}.ball_scale"), &mut self.ball_scale, ATOM_SCALE, 1.0);
        n.real(&format!("{key}.stick_scale"), &mut self.stick_scale, ATOM_SCALE, 1.0);
    }
}

impl QuantityState {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        self.cloud.sanitize(&format!("{key}.cloud"), n);
        if self.isosurfaces.len() > MAX_ISOSURFACES {
            n.note(
                &format!("{key}.isosurfaces"),
                format!(
                    "{} isosurfaces, more than {MAX_ISOSURFACES}; the first {MAX_ISOSURFACES} kept",
                    self.isosurfaces.len()
                ),
            );
            self.isosurfaces.truncate(MAX_ISOSURFACES);
        }
        for (k, iso) in self.isosurfaces.iter_mut().enumerate() {
            iso.sanitize(&format!("{key}.isosurfaces[{k}]"), n);
        }
        if let Some(p) = &mut self.pane {
            n.count(&format!("{key}.pane"), p, 0..=MAX_PANES - 1);
        }
    }
}

impl VolumeSettings {
    /// Brings a cloud's values into range (the command line's settings pass here too).
    pub fn sanitize_into(&mut self, key: &str, notes: &mut Vec<String>) {
        self.sanitize(key, &mut Notes { list: notes });
    }

    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = VolumeSettings::default();
        n.count(&format!("{key}.slices"), &mut self.slices, SLICES);
        n.real(&format!("{key}.k1"), &mut self.k1, K1, default.k1);
        n.real(&format!("{key}.k2"), &mut self.k2, K2, default.k2);
        n.color(&format!("{key}.positive_color"), &mut self.positive_color);
        n.color(&format!("{key}.negative_color"), &mut self.negative_color);
        self.transfer.sanitize(&format!("{key}.transfer"), n);
        if let Some(clip) = &mut self.stored_clip {
            clip.sanitize(&format!("{key}.clip"), n);
        }
        if let DensityScale::Log { lo, hi } = &mut self.density_scale {
            let (lo0, hi0) = match DensityScale::default() {
                DensityScale::Log { lo, hi } => (lo, hi),
                DensityScale::Linear => (1e-3, 1.0),
            };
            n.real(&format!("{key}.density_scale.lo"), lo, DENSITY_BOUND, lo0);
            n.real(&format!("{key}.density_scale.hi"), hi, DENSITY_BOUND, hi0);
            if *hi <= *lo {
                n.note(&format!("{key}.density_scale"), format!("hi {hi} is not above lo {lo}; {lo0}..{hi0} used"));
                (*lo, *hi) = (lo0, hi0);
            }
        }
    }
}

impl Transfer {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = super::transfer::Lobe::default();
        for (name, lobe) in [("positive", &mut self.positive), ("negative", &mut self.negative)] {
            n.real(&format!("{key}.{name}.center"), &mut lobe.center, FRACTION, default.center);
            n.real(&format!("{key}.{name}.width"), &mut lobe.width, LOBE_WIDTH, default.width);
            n.real(&format!("{key}.{name}.opacity"), &mut lobe.opacity, LOBE_OPACITY, default.opacity);
        }
        n.real(&format!("{key}.gradient_power"), &mut self.gradient_power, GRADIENT_POWER, 0.0);
        n.real(&format!("{key}.boundary"), &mut self.boundary, FRACTION, 0.0);
    }
}

impl IsosurfaceSettings {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = IsosurfaceSettings::default();
        match &mut self.level {
            IsoLevel::Absolute(v) => {
                let v0 = match default.level {
                    IsoLevel::Absolute(v) => v,
                    IsoLevel::Sigma(_) => 0.05,
                };
                n.real(&format!("{key}.level.Absolute"), v, -*ISOVALUE.end()..=*ISOVALUE.end(), v0);
            }
            IsoLevel::Sigma(s) => n.real(&format!("{key}.level.Sigma"), s, SIGMA, 2.0),
        }
        n.color(&format!("{key}.positive_color"), &mut self.positive_color);
        n.color(&format!("{key}.negative_color"), &mut self.negative_color);
        n.color(&format!("{key}.density_color"), &mut self.density_color);
        self.tuning.sanitize(&format!("{key}.tuning"), n);
        if let Some(r) = self.color_range
            && !(r.is_finite() && r > 0.0 && r <= *ISOVALUE.end())
        {
            n.note(&format!("{key}.color_range"), format!("{r} is not in (0, {}]; automatic used", ISOVALUE.end()));
            self.color_range = None;
        }
    }
}

impl OpticsTuning {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        for name in Self::NAMES {
            if let Some(factors) = self.factors_mut(name) {
                for (k, v) in factors.iter_mut().enumerate() {
                    n.real(&format!("{key}.{name}[{k}]"), v, OPTICS_FACTOR, 1.0);
                }
            }
        }
    }
}

impl Evaluation {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        n.count(&format!("{key}.grid_points"), &mut self.grid_points, GRID_POINTS);
    }
}

impl SurfaceSettings {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = SurfaceSettings::default();
        if let Some(r) = &mut self.resolution {
            if r.is_finite() {
                n.real(&format!("{key}.resolution"), r, SURFACE_RESOLUTION, *SURFACE_RESOLUTION.start());
            } else {
                n.note(&format!("{key}.resolution"), format!("{r} is not a finite number; automatic used"));
                self.resolution = None;
            }
        }
        n.real(&format!("{key}.probe"), &mut self.probe, PROBE, default.probe);
        n.real(&format!("{key}.smoothness"), &mut self.smoothness, SMOOTHNESS, default.smoothness);
        n.real(&format!("{key}.lod_px"), &mut self.lod_px, LOD_PX, default.lod_px);
        n.color(&format!("{key}.color"), &mut self.color);
    }
}

impl VibrationState {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let default = VibrationState::default();
        n.real(&format!("{key}.amplitude"), &mut self.amplitude, AMPLITUDE, default.amplitude);
        n.real(&format!("{key}.speed"), &mut self.speed, SPEED, default.speed);
        n.real(&format!("{key}.fwhm"), &mut self.fwhm, FWHM, default.fwhm);
    }
}

impl ClipPlane {
    fn sanitize(&mut self, key: &str, n: &mut Notes) {
        let v = glam::Vec3::from(self.normal);
        if !v.is_finite() || !(1e-6..=1e6).contains(&v.length()) {
            let normal = ClipPlane::default().normal;
            n.note(&format!("{key}.normal"), format!("{:?} is no direction; {normal:?} used", self.normal));
            self.normal = normal;
        }
        n.real(&format!("{key}.offset"), &mut self.offset, POSITION, 0.0);
    }
}

/// A command-line value parser (clap takes any `Fn(&str) -> Result`) for numbers in `range`.
pub fn within<T>(range: RangeInclusive<T>) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static
where
    T: std::str::FromStr + PartialOrd + Display + Copy + Send + Sync + 'static,
    T::Err: Display,
{
    move |s: &str| parse_in(s, &range)
}

/// `range` in f64, for options read as f64: each bound the decimal it was written as (0.05,
/// not 0.05000000074505806), so messages show it so.
pub fn wide(range: RangeInclusive<f32>) -> RangeInclusive<f64> {
    let wide = |x: f32| x.to_string().parse::<f64>().unwrap_or(f64::from(x));
    wide(*range.start())..=wide(*range.end())
}

/// Parses a command-line number in `range`, refusing what is not a finite number or lies
/// outside it.
pub fn parse_in<T>(s: &str, range: &RangeInclusive<T>) -> Result<T, String>
where
    T: std::str::FromStr + PartialOrd + Display + Copy,
    T::Err: Display,
{
    let v: T = s.trim().parse().map_err(|e| format!("{s:?} is not a number: {e}"))?;
    // NaN fails every comparison, so it is refused here with the infinities.
    if !range.contains(&v) {
        return Err(format!("{s} is outside {}", shown(range)));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_values_are_clamped_or_replaced_with_a_note_naming_their_key() {
        let mut s = Session::default();
        s.camera.distance = f32::NAN;
        s.camera.fov_y = 1e9;
        s.camera.orientation = glam::Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        s.panes.count = 1000;
        let mut object = ObjectState::opening(&crate::model::Document::default(), &Default::default());
        let mut q = QuantityState::new(super::super::Source::Volume(0), &Default::default());
        q.cloud.slices = 4_000_000_000;
        q.cloud.k1 = f32::INFINITY;
        q.isosurfaces[0].level = IsoLevel::Absolute(f32::NAN);
        object.quantities = vec![q];
        object.selected = 7;
        object.evaluation.grid_points = usize::MAX;
        object.clip.normal = [0.0; 3];
        s.objects.push(object);
        let state = ScanState { value: f64::NAN, speed: f64::INFINITY, diagram: 100, ..Default::default() };
        let mut scan = LegacyScan { state, ..Default::default() };
        scan.state.orbitals = vec!["homo".into(); 40];
        scan.settings.volume.slices = 4_000_000_000;
        s.scan = Some(scan);
        let notes = s.sanitize();
        let has = |key: &str| notes.iter().any(|n| n.starts_with(&format!("{key}: ")));
        for key in [
            "camera.distance",
            "camera.fov_y",
            "camera.orientation",
            "panes.count",
            "objects[0].quantities[0].cloud.slices",
            "objects[0].quantities[0].cloud.k1",
            "objects[0].quantities[0].isosurfaces[0].level.Absolute",
            "objects[0].selected",
            "objects[0].evaluation.grid_points",
            "objects[0].clip.normal",
            "scan.value",
            "scan.speed",
            "scan.diagram",
            "scan.orbitals",
            "scan.settings.volume.slices",
        ] {
            assert!(has(key), "no note for {key}: {notes:#?}");
        }
        assert_eq!(notes.len(), 15, "{notes:#?}");
        let q = &s.objects[0].quantities[0];
        let scan = s.scan.as_ref().unwrap();
        let state = &scan.state;
        assert!(state.value.is_finite() && state.speed.is_finite() && state.orbitals.len() == MAX_SCAN_ORBITALS);
        assert_eq!((scan.state.diagram, scan.settings.volume.slices), (8, *SLICES.end()));
        assert_eq!((q.cloud.slices, s.panes.count, s.objects[0].selected), (*SLICES.end(), MAX_PANES, 0));
        assert_eq!(q.isosurfaces[0].level, IsosurfaceSettings::default().level);
        assert_eq!(s.camera.distance, Camera::default().distance);
        assert!(s.camera.clip_from_world(1.5, 10.0).is_finite());
        // What is already in range passes untouched and unremarked.
        let before = s.clone();
        assert!(s.sanitize().is_empty());
        assert_eq!(s, before);
    }

    #[test]
    fn command_line_numbers_are_refused_outside_their_range() {
        assert_eq!(parse_in("192", &SLICES), Ok(192));
        assert!(parse_in("4000000000", &SLICES).unwrap_err().contains("1..=4096"));
        assert!(parse_in::<f32>("NaN", &K1).is_err());
        assert!(parse_in::<f32>("inf", &POSITION).is_err());
        assert!(parse_in::<f32>("-0.5", &FRACTION).is_err());
        assert!(parse_in::<f32>("x", &FRACTION).unwrap_err().contains("not a number"));
        assert_eq!(wide(SURFACE_RESOLUTION), 0.05..=5.0);
    }
}
