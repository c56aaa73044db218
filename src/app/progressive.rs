//! A costly picture drawn over several UI frames: in bands of rows sized to a time budget, with
//! a coarse preview standing in while they fill in, so the window answers within about 100 ms
//! whatever the view shows. The viewport draws; this decides when and how much.
//!
//! Bands cost: each repeats the frame's fixed part (its set-up, every slice's triangles, the
//! wait for the GPU), which on a GPU can be most of a band's time (a scene of clouds drawn in
//! 32-row bands took six times as long as at once on one). So on a GPU a picture is drawn in
//! bands only when the last one took longer, drawn at once or estimated from its bands, than
//! a turn of bands may ([`AT_ONCE_MS`]); on a CPU rasteriser always, as the window must never
//! wait on a slow picture there and an at-once picture is only known to be slow after it.

use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use crate::gpu::renderer::Tile;

/// How long one UI frame may spend drawing bands of a costly frame.
const FRAME_BUDGET: Duration = Duration::from_millis(80);
/// The same while a coarse picture stands in: the window's own drawing between turns costs tens
/// of ms on a CPU rasteriser, so longer turns finish the picture sooner.
const REFINE_BUDGET: Duration = Duration::from_millis(250);
/// How long one band should take.
const BAND_TIME: Duration = Duration::from_millis(40);
/// The most bands a picture is drawn in.
const MAX_BANDS: u32 = 32;
/// A full picture slower than this gets a coarse preview at once after the next change.
const PREVIEW_AFTER_MS: f64 = 300.0;
/// A picture that takes no longer than this at once holds the window no longer than a turn of
/// bands with a preview standing in ([`REFINE_BUDGET`]): on a GPU it is drawn at once.
pub const AT_ONCE_MS: f64 = 250.0;
/// A picture still being drawn after this shows its progress.
const PROGRESS_AFTER: Duration = Duration::from_millis(150);

/// A picture being drawn in bands: the first row not drawn yet, and rows per band.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bands {
    next_row: u32,
    rows: u32,
}

/// What a turn of [`Progressive::turn`] left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// The picture is whole.
    Done,
    /// Bands remain: draw again next frame.
    More,
    /// Bands remain and will take long: a coarse preview should stand in from now.
    WantPreview,
}

/// The schedule of the picture being drawn.
#[derive(Debug)]
pub struct Progressive {
    bands: Option<Bands>,
    /// Rows the last band drew: the next picture starts with bands of this size.
    band_rows: u32,
    /// Whether a coarse picture stands in while the bands fill in.
    previewing: bool,
    /// Whether the last full picture took long enough to want a preview at once.
    last_full_slow: bool,
    /// When the picture being drawn was started, and how long the last whole one took (ms,
    /// taken once).
    started: Option<Instant>,
    ms: Option<f64>,
    /// How long the last picture took drawn at once (ms): measured when it was, else estimated
    /// from its bands ([`whole_from_bands`]).
    whole_ms: Option<f64>,
    /// This picture's bands so far: seconds each.
    band_times: Vec<f64>,
    /// A picture drawn at once whose GPU work is not known to be done yet: set when it is.
    pending: Option<Arc<OnceLock<Instant>>>,
}

impl Default for Progressive {
    fn default() -> Self {
        Self {
            bands: None,
            band_rows: 8,
            previewing: false,
            last_full_slow: true,
            started: None,
            ms: None,
            whole_ms: None,
            band_times: Vec::new(),
            pending: None,
        }
    }
}

impl Progressive {
    /// A new picture: drawn in bands when `banded`, else at once. Returns whether a coarse
    /// preview should stand in now: a full-detail picture (`full`) that is `costly`, or after
    /// one that was slow.
    pub fn start(&mut self, banded: bool, full: bool, costly: bool) -> bool {
        self.started = Some(Instant::now());
        self.band_times.clear();
        self.pending = None;
        self.bands = banded.then_some(Bands { next_row: 0, rows: self.band_rows });
        self.previewing = banded && full && (self.last_full_slow || costly);
        self.previewing
    }

    /// Whether the next picture should be drawn in bands: always on a CPU adapter (`cpu`); on
    /// a GPU when the last picture took longer than [`AT_ONCE_MS`] at once, or, before any was
    /// timed, when it is `costly` (orbitals evaluated per sample).
    pub fn bands_needed(&self, cpu: bool, costly: bool) -> bool {
        cpu || self.whole_ms.map_or(costly, |ms| ms > AT_ONCE_MS)
    }

    /// How long the last picture took, or would have taken, drawn at once (ms).
    pub fn whole_ms(&self) -> Option<f64> {
        self.whole_ms
    }

    /// The picture was drawn whole at once and has been waited for.
    pub fn finished_whole(&mut self) {
        self.ms = self.started.take().map(|t| t.elapsed().as_secs_f64() * 1e3);
        self.whole_ms = self.ms;
    }

    /// The picture was submitted whole at once; `done` is set when the GPU has finished it
    /// (a queue's work-done callback), which [`Self::poll_whole`] reads.
    pub fn submitted_whole(&mut self, done: Arc<OnceLock<Instant>>) {
        self.pending = Some(done);
    }

    /// Takes the time of a picture drawn at once once its GPU work is done.
    pub fn poll_whole(&mut self) {
        let Some(done) = self.pending.as_ref().and_then(|d| d.get().copied()) else { return };
        self.pending = None;
        self.ms = self.started.take().map(|t| done.saturating_duration_since(t).as_secs_f64() * 1e3);
        self.whole_ms = self.ms;
    }

    /// Draws bands of a picture of `size` with `draw` (which waits for the GPU) until this
    /// frame's budget is spent. `full`: the picture is at full detail (a slow one then asks for
    /// a preview).
    pub fn turn(&mut self, size: [u32; 2], full: bool, mut draw: impl FnMut(Tile)) -> Turn {
        let Some(p) = &mut self.bands else { return Turn::Done };
        let [width, height] = size;
        let start = Instant::now();
        // With a preview standing in the window loses nothing to longer turns.
        let budget = if self.previewing { REFINE_BUDGET } else { FRAME_BUDGET };
        let mut want_preview = false;
        while p.next_row < height && start.elapsed() < budget {
            let rows = p.rows.min(height - p.next_row);
            let band = Instant::now();
            draw(Tile { rect: [0, p.next_row, width, rows], first: p.next_row == 0 });
            let seconds = band.elapsed().as_secs_f64();
            self.band_times.push(seconds);
            let per_row = seconds / f64::from(rows);
            p.next_row += rows;
            p.rows = next_band_rows(rows, height, per_row);
            // The rest will take long: a coarse picture stands in from now.
            let rest_ms = per_row * f64::from(height - p.next_row) * 1e3;
            if !self.previewing && full && rest_ms > PREVIEW_AFTER_MS {
                want_preview = true;
                break;
            }
        }
        self.band_rows = p.rows;
        if p.next_row >= height {
            self.bands = None;
            self.ms = self.started.take().map(|t| t.elapsed().as_secs_f64() * 1e3);
            self.whole_ms = whole_from_bands(&self.band_times);
            if full {
                self.last_full_slow = self.ms.is_some_and(|ms| ms > PREVIEW_AFTER_MS);
            }
            Turn::Done
        } else if want_preview {
            Turn::WantPreview
        } else {
            Turn::More
        }
    }

    /// A preview now stands in; it drew through the renderer's own targets, so the full
    /// picture starts again from its first band.
    pub fn preview_drawn(&mut self) {
        self.previewing = true;
        if let Some(p) = &mut self.bands {
            p.next_row = 0;
        }
    }

    /// Leaves the picture unfinished (the view was split into panes, which draw whole).
    pub fn stop(&mut self) {
        self.bands = None;
        self.previewing = false;
    }

    /// Whether bands remain to be drawn.
    pub fn drawing(&self) -> bool {
        self.bands.is_some()
    }

    /// Rows of the picture drawn so far, while it is drawn in bands.
    pub fn rows_drawn(&self) -> Option<u32> {
        self.bands.map(|p| p.next_row)
    }

    /// Whether a coarse picture stands in while the full one is drawn.
    pub fn is_previewing(&self) -> bool {
        self.previewing && self.bands.is_some()
    }

    /// Whether the picture under way has taken long enough to show its progress.
    pub fn shows_progress(&self) -> bool {
        self.bands.is_some() && (self.previewing || self.started.is_some_and(|t| t.elapsed() > PROGRESS_AFTER))
    }

    /// How long the last whole picture took (ms), once.
    pub fn take_ms(&mut self) -> Option<f64> {
        self.ms.take()
    }
}

/// How long a picture would take at once, from its bands' seconds, in ms: the bands'
/// sum less the fixed part each band after the first repeated, which is at most the quickest
/// band's time (rows cost unevenly, clouds in some and background in others, so no line through
/// the bands' times would do). A low estimate at worst: a picture then drawn at once and found
/// slow is timed, and banded again the next time.
fn whole_from_bands(bands: &[f64]) -> Option<f64> {
    let total: f64 = bands.iter().sum();
    let quickest = bands.iter().copied().reduce(f64::min)?;
    Some((total - quickest * (bands.len() - 1) as f64) * 1e3)
}

/// Rows for the band after one of `rows` that took `per_row_s` seconds a row, in a picture of
/// `height` rows: what fits [`BAND_TIME`], at most twice the band before (one band measured
/// fast, its GPU work overlapping the last, must not turn the rest into one band that holds the
/// window for seconds) and at least 1/[`MAX_BANDS`] of the picture (a band also costs a fixed
/// part: the frame's set-up, every slice's triangles).
fn next_band_rows(rows: u32, height: u32, per_row_s: f64) -> u32 {
    let most = (2 * rows).clamp(1, height.max(1));
    let least = (height / MAX_BANDS).clamp(1, most);
    ((BAND_TIME.as_secs_f64() / per_row_s.max(1e-6)) as u32).clamp(least, most)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_picture_is_estimated_without_the_bands_fixed_part() {
        // 5 ms a band plus the rows' own: 50 ms of rows, four bands, 15 ms of fixed parts.
        let bands = [0.005, 0.025, 0.02, 0.02];
        let ms = whole_from_bands(&bands).unwrap();
        assert!((ms - 55.0).abs() < 1e-9, "{ms}");
        assert_eq!(whole_from_bands(&[]), None);
    }

    #[test]
    fn a_gpu_bands_only_pictures_that_were_slow() {
        let mut p = Progressive::default();
        assert!(p.bands_needed(true, false), "a CPU adapter always bands");
        assert!(!p.bands_needed(false, false) && p.bands_needed(false, true), "untimed: costly ones");
        p.whole_ms = Some(AT_ONCE_MS * 0.5);
        assert!(!p.bands_needed(false, true), "a costly picture that was quick is drawn at once");
        p.whole_ms = Some(AT_ONCE_MS * 2.0);
        assert!(p.bands_needed(false, false), "a slow picture is banded on a GPU too");
        let done = Arc::new(OnceLock::new());
        p.start(false, true, false);
        p.submitted_whole(done.clone());
        p.poll_whole();
        assert_eq!(p.whole_ms, Some(AT_ONCE_MS * 2.0), "not done yet");
        done.set(Instant::now()).unwrap();
        p.poll_whole();
        assert!(p.whole_ms.is_some_and(|ms| ms < AT_ONCE_MS) && !p.bands_needed(false, false));
    }

    #[test]
    fn bands_fit_their_time_within_bounds() {
        // 1 ms a row: 40 rows fit, but a band grows at most twofold.
        assert_eq!(next_band_rows(8, 600, 1e-3), 16);
        assert_eq!(next_band_rows(32, 600, 1e-3), 40);
        // Very slow rows: never below 1/32 of the picture.
        assert_eq!(next_band_rows(32, 640, 1.0), 20);
        // Very fast rows on a short picture: at most the picture.
        assert_eq!(next_band_rows(500, 100, 1e-9), 100);
    }

    #[test]
    fn a_banded_picture_is_drawn_band_by_band_to_its_last_row() {
        let mut p = Progressive::default();
        assert!(p.start(true, true, false), "after a slow picture (the first) a preview stands in");
        let mut tiles = Vec::new();
        let mut turns = 0;
        while p.turn([64, 100], true, |t| tiles.push(t)) != Turn::Done {
            turns += 1;
            assert!(turns < 1000, "the picture ends");
        }
        assert!(tiles[0].first && tiles.iter().skip(1).all(|t| !t.first));
        let rows: u32 = tiles.iter().map(|t| t.rect[3]).sum();
        assert_eq!(rows, 100, "every row once");
        assert!(tiles.windows(2).all(|w| w[1].rect[1] == w[0].rect[1] + w[0].rect[3]), "in order");
        assert!(!p.drawing() && p.take_ms().is_some() && p.take_ms().is_none());
        assert!(!p.start(true, true, false), "a quick full picture wants no preview the next time");
        assert!(!p.start(false, true, true), "a picture drawn at once wants none");
    }
}
