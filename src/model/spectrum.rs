//! Spectra drawn from lines: an IR spectrum from normal modes, a UV-vis spectrum from excited
//! states. Each line (a position and a height) is broadened to a band; a click on the plot picks
//! the line whose band is highest under it.

/// A line of a spectrum: where it lies (cm⁻¹, eV, …) and its height (an intensity, an
/// oscillator strength).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    pub position: f64,
    pub height: f64,
}

/// A band's shape, 1 at its centre: a Lorentzian or a Gaussian of full width `fwhm` at half
/// maximum, of the distance from the centre.
pub fn band_shape(fwhm: f64, lorentzian: bool) -> impl Fn(f64) -> f64 {
    let half = (fwhm * 0.5).max(1e-6);
    move |dx: f64| match lorentzian {
        true => half * half / (dx * dx + half * half),
        false => (-std::f64::consts::LN_2 * (dx / half).powi(2)).exp(),
    }
}

/// The spectrum from `from` to `to` in `points` steps: every line broadened to a band of full
/// width `fwhm` at half maximum and peak height its height.
pub fn broadened(lines: &[Line], (from, to): (f64, f64), points: usize, fwhm: f64, lorentzian: bool) -> Vec<[f64; 2]> {
    let shape = band_shape(fwhm, lorentzian);
    let n = points.max(2);
    (0..n)
        .map(|k| {
            let x = from + (to - from) * k as f64 / (n - 1) as f64;
            [x, lines.iter().map(|l| l.height * shape(x - l.position)).sum()]
        })
        .collect()
}

/// Which of `lines` (each `Some` where it has a height to plot, indexed as its owner numbers
/// them) has the highest band at `x`, among those within `tolerance` (or two widths) of it: the
/// band under a click, so a click on a tall band picks it, not a weak neighbour a little nearer.
/// The first of equal bands (a degenerate pair) wins.
pub fn tallest_at(lines: &[Option<Line>], x: f64, fwhm: f64, lorentzian: bool, tolerance: f64) -> Option<usize> {
    let shape = band_shape(fwhm, lorentzian);
    (lines.iter().enumerate())
        .filter_map(|(k, l)| Some((k, (*l)?)))
        .filter(|(_, l)| (l.position - x).abs() <= tolerance.max(2.0 * fwhm))
        .map(|(k, l)| (k, l.height * shape(x - l.position)))
        .filter(|&(_, height)| height > 0.0)
        .reduce(|best, c| if c.1 > best.1 { c } else { best })
        .map(|(k, _)| k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_peak_at_their_heights_and_halve_at_half_width() {
        let lines = [Line { position: 2.0, height: 0.5 }];
        for lorentzian in [true, false] {
            let shape = band_shape(0.4, lorentzian);
            assert!((shape(0.0) - 1.0).abs() < 1e-12 && (shape(0.2) - 0.5).abs() < 1e-12);
            let s = broadened(&lines, (1.0, 3.0), 201, 0.4, lorentzian);
            let top = s.iter().fold([0.0, 0.0], |a, p| if p[1] > a[1] { *p } else { a });
            assert!((top[0] - 2.0).abs() < 1e-9 && (top[1] - 0.5).abs() < 1e-9, "{top:?}");
        }
    }

    #[test]
    fn a_click_picks_the_tallest_band_under_it_not_the_nearest_line() {
        let lines = [Some(Line { position: 3.0, height: 0.02 }), None, Some(Line { position: 3.3, height: 1.0 })];
        assert_eq!(tallest_at(&lines, 3.05, 0.4, false, 0.1), Some(2), "the strong band covers the weak line");
        assert_eq!(tallest_at(&lines, 1.0, 0.4, false, 0.1), None, "nothing there");
    }
}
