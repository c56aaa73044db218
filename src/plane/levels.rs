//! Contour levels: listed, or a signed geometric series as chemists read plane maps (±0.001,
//! ±0.002, ±0.004, … and zero for quantities of both signs), so each line is twice the next.

use std::str::FromStr;

/// The series' first level when the values reach it: 0.001 a.u., the outermost contour of the
/// maps in the literature.
const FIRST: f64 = 0.001;

/// At most this many levels of each sign, however far the values reach (a density's cusp at a
/// heavy nucleus would otherwise add lines no one can tell apart).
const MAX_PER_SIGN: usize = 24;

/// Which contour levels a map draws.
#[derive(Debug, Clone, PartialEq)]
pub enum Levels {
    /// The geometric series up to the largest |value| ([`auto_levels`]).
    Auto,
    /// These values.
    Listed(Vec<f64>),
}

impl Levels {
    /// The levels for values whose largest magnitude is `max_abs`; `signed` quantities get
    /// negative levels and zero too. Sorted ascending.
    pub fn resolve(&self, max_abs: f64, signed: bool) -> Vec<f64> {
        match self {
            Levels::Auto => auto_levels(max_abs, signed),
            Levels::Listed(v) => {
                let mut v = v.clone();
                v.sort_by(f64::total_cmp);
                v.dedup();
                v
            }
        }
    }
}

impl FromStr for Levels {
    type Err = String;

    /// `auto`, or values separated by commas.
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim().eq_ignore_ascii_case("auto") {
            return Ok(Levels::Auto);
        }
        let values: Vec<f64> = s
            .split(',')
            .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| format!("expected `auto` or values separated by commas, got {s:?}"))?;
        Ok(Levels::Listed(values))
    }
}

/// The series first·2^k for k = 0, 1, … up to `max_abs`, with their negatives and zero when
/// `signed`. Values that never reach 0.001 start their series lower: at a power of ten a
/// hundredth of their largest magnitude, so a faint quantity still has lines.
pub fn auto_levels(max_abs: f64, signed: bool) -> Vec<f64> {
    if !(max_abs.is_finite() && max_abs > 0.0) {
        return if signed { vec![0.0] } else { Vec::new() };
    }
    let first = if max_abs >= FIRST { FIRST } else { 10f64.powf((max_abs.log10() - 2.0).floor()) };
    let positive: Vec<f64> =
        (0..MAX_PER_SIGN).map(|k| first * 2f64.powi(k as i32)).take_while(|&l| l <= max_abs).collect();
    if !signed {
        return positive;
    }
    positive.iter().rev().map(|l| -l).chain(std::iter::once(0.0)).chain(positive.iter().copied()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn automatic_levels_double_from_a_thousandth_up_to_the_largest_value() {
        let levels = auto_levels(0.3, true);
        let positive = [0.001, 0.002, 0.004, 0.008, 0.016, 0.032, 0.064, 0.128, 0.256];
        let expected: Vec<f64> = positive.iter().rev().map(|l| -l).chain([0.0]).chain(positive).collect();
        assert_eq!(levels.len(), expected.len());
        for (a, b) in levels.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-15, "{levels:?}");
        }
        // A density has no negative levels and no zero.
        assert_eq!(auto_levels(0.3, false).len(), positive.len());
        assert!(auto_levels(0.3, false).iter().all(|&l| l > 0.0));
        // A cusp far above the series is capped.
        assert_eq!(auto_levels(1e9, false).len(), MAX_PER_SIGN);
    }

    #[test]
    fn faint_values_start_their_series_lower() {
        let levels = auto_levels(2.5e-5, false);
        assert!((levels[0] - 1e-7).abs() < 1e-20, "{levels:?}");
        assert!(levels.iter().all(|&l| l <= 2.5e-5));
        assert!(levels.len() >= 7);
        assert_eq!(auto_levels(0.0, true), [0.0]);
        assert!(auto_levels(f64::NAN, false).is_empty());
    }

    #[test]
    fn listed_levels_are_parsed_and_sorted() {
        let l: Levels = "0.05, -0.05,0".parse().unwrap();
        assert_eq!(l.resolve(1.0, true), [-0.05, 0.0, 0.05]);
        assert_eq!("AUTO".parse::<Levels>().unwrap(), Levels::Auto);
        assert!("0.1,x".parse::<Levels>().is_err());
        assert!("0.1,inf".parse::<Levels>().is_err());
    }
}
