//! A costly picture drawn over several UI frames: in bands of rows sized to a time budget, with
//! a coarse preview standing in while they fill in, so the window answers within about 100 ms
//! whatever the view shows. The viewport draws; this decides when and how much.

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
}

impl Default for Progressive {
    fn default() -> Self {
        Self { bands: None, band_rows: 8, previewing: false, last_full_slow: true, started: None, ms: None }
    }
}

impl Progressive {
    /// A new picture: drawn in bands when `banded`, else at once. Returns whether a coarse
    /// preview should stand in now: a full-detail picture (`full`) that is `costly`, or after
    /// one that was slow.
    pub fn start(&mut self, banded: bool, full: bool, costly: bool) -> bool {
        self.started = Some(Instant::now());
        self.bands = banded.then_some(Bands { next_row: 0, rows: self.band_rows });
        self.previewing = banded && full && (self.last_full_slow || costly);
        self.previewing
    }

    /// The picture was drawn whole at once.
    pub fn finished_whole(&mut self) {
        self.ms = self.started.take().map(|t| t.elapsed().as_secs_f64() * 1e3);
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
            let per_row = band.elapsed().as_secs_f64() / f64::from(rows);
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
            self.finished_whole();
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
