//! A scan as an object's state: where its coordinate stands, how frames between its key volumes
//! are mixed, and how it plays. The scan itself ([`crate::model::scan::Scan`]) is the object's
//! document's; its views are the object's quantities ([`super::Source::Scan`]).

use serde::{Deserialize, Serialize};

use super::quantity::{AtomLook, QuantityState, Source};
use super::{Interpolation, ObjectState, RenderSettings};
use crate::model::scan::{Follow, Scan};

/// A scan's coordinate and playback, saved in sessions with its object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ScanState {
    /// Its manifest (`*.scan.toml`); `None`: the bundled PSB3 scan.
    pub manifest: Option<std::path::PathBuf>,
    /// The coordinate's value in its unit (degrees, Å, or a path's length).
    pub value: f64,
    pub mode: Interpolation,
    /// Whether the value moves on by itself.
    pub playing: bool,
    /// Bounce between the ends when playing (else stop at the end).
    pub looping: bool,
    /// Animation speed, the coordinate's units per second.
    pub speed: f64,
    /// A horizontal drag changes the value (else it orbits and only a drag on the bond does).
    pub drag_scans: bool,
    /// The orbitals its key volumes were made for, as manifests name them (empty: the
    /// manifest's own).
    pub orbitals: Vec<String>,
    /// How orbitals are followed across frames.
    pub follow: Follow,
    /// How many orbitals below the HOMO and above the LUMO the correlation diagram shows.
    pub diagram: usize,
    /// Playing towards the lower end.
    #[serde(skip)]
    pub backwards: bool,
}

impl Default for ScanState {
    fn default() -> Self {
        Self {
            manifest: None,
            value: 0.0,
            mode: Interpolation::default(),
            playing: false,
            looping: true,
            speed: 30.0,
            drag_scans: true,
            orbitals: Vec::new(),
            follow: Follow::default(),
            diagram: 2,
            backwards: false,
        }
    }
}

impl ScanState {
    /// A scan as it opens: at the key frame nearest the middle of its range (where the picture
    /// says most), exactly interpolated, sweeping the range in six seconds when played.
    pub fn opening(scan: &Scan, manifest: Option<std::path::PathBuf>) -> Self {
        let (lo, hi) = scan.range();
        let value = scan.frames.get(scan.nearest_frame(0.5 * (lo + hi))).map_or(lo, |f| f.at);
        Self {
            manifest,
            value,
            mode: Interpolation::Exact,
            speed: ((hi - lo) / 6.0).max(1e-3),
            orbitals: scan.orbitals.clone(),
            ..Self::default()
        }
    }

    /// Sets the value, clamped into the scan's range.
    pub fn set_value(&mut self, scan: &Scan, value: f64) {
        let (lo, hi) = scan.range();
        if value.is_finite() {
            self.value = value.clamp(lo, hi);
        }
    }

    /// Moves the value on by `dt` seconds of animation: back and forth between the ends when
    /// looping, else stopping at the end.
    pub fn advance(&mut self, scan: &Scan, dt: f64) {
        let (lo, hi) = scan.range();
        let direction = if self.backwards { -1.0 } else { 1.0 };
        let mut t = self.value + direction * self.speed * dt;
        if t >= hi || t <= lo {
            if self.looping {
                self.backwards = !self.backwards;
            } else {
                self.playing = false;
            }
            t = t.clamp(lo, hi);
        }
        self.value = t;
    }

    /// Moves to the key frame before (`dir` < 0) or after the value.
    pub fn step_key(&mut self, scan: &Scan, dir: i32) {
        let values = scan.values();
        let next = if dir > 0 {
            values.iter().copied().find(|&a| a > self.value + 1e-6)
        } else {
            values.iter().rev().copied().find(|&a| a < self.value - 1e-6)
        };
        if let Some(a) = next {
            self.value = a;
        }
    }
}

/// A scan as sessions kept it before scans were objects: its playback, and one set of render
/// settings every view drew with.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LegacyScan {
    #[serde(flatten)]
    pub state: ScanState,
    pub settings: RenderSettings,
}

impl LegacyScan {
    /// The object it is now: one quantity per view, each drawn with the old settings, in a pane
    /// of its own.
    pub fn into_object(self, views: usize) -> ObjectState {
        let quantities = (0..views)
            .map(|slot| QuantityState { pane: Some(slot), ..QuantityState::new(Source::Scan(slot), &self.settings) })
            .collect();
        ObjectState {
            atoms: AtomLook::of(&self.settings),
            clip: self.settings.clip,
            quantities,
            scan: Some(self.state),
            ..ObjectState::default()
        }
    }
}
