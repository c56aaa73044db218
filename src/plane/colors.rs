//! How a map's values become colours: a diverging scale (blue, white, red) symmetric about zero
//! for quantities of both signs, a sequential one on a log scale for densities, whose values
//! span orders of magnitude from the nuclei outwards.

/// Blue through white to red (ColorBrewer's RdBu), from −1 to 1.
const DIVERGING: [[u8; 3]; 5] = [[33, 102, 172], [103, 169, 207], [247, 247, 247], [239, 138, 98], [178, 24, 43]];

/// Pale yellow through orange to dark red (ColorBrewer's YlOrRd), from 0 to 1: light where the
/// density is low, so the contour lines read over it everywhere.
const SEQUENTIAL: [[u8; 3]; 5] = [[255, 255, 204], [254, 217, 118], [253, 141, 60], [227, 26, 28], [128, 0, 38]];

/// The share of the map's points whose colour saturates: a few points at a nucleus (where the
/// potential and core orbitals peak) do not wash out the rest of the map.
const SATURATED: f64 = 0.005;

/// The colour scale of a map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ColorScale {
    /// Linear from −limit (blue) to +limit (red).
    Diverging { limit: f64 },
    /// Logarithmic from `low` (pale) to `high` (dark).
    Sequential { low: f64, high: f64 },
}

impl ColorScale {
    /// The scale for `values` (NaN where unknown): diverging when `signed`, its limit the
    /// magnitude that all but [`SATURATED`] of the values stay within; else sequential from
    /// `low` (the lowest contour level, or a thousandth of the top) to the largest value.
    pub fn for_values(values: &[f64], signed: bool, low: Option<f64>) -> Self {
        let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if signed {
            finite.iter_mut().for_each(|v| *v = v.abs());
            let limit = quantile(&mut finite, 1.0 - SATURATED);
            return ColorScale::Diverging { limit: if limit > 0.0 { limit } else { 1.0 } };
        }
        let high = finite.iter().copied().fold(0.0, f64::max);
        let high = if high > 0.0 { high } else { 1.0 };
        let low = low.filter(|&l| l > 0.0 && l < high).unwrap_or(high * 1e-3);
        ColorScale::Sequential { low, high }
    }

    /// Where `value` lies on the scale: −1…1 (diverging) or 0…1 (sequential), clamped.
    pub fn position(&self, value: f64) -> f64 {
        match *self {
            ColorScale::Diverging { limit } => (value / limit).clamp(-1.0, 1.0),
            ColorScale::Sequential { low, high } => {
                if value <= low {
                    0.0
                } else {
                    ((value / low).ln() / (high / low).ln()).clamp(0.0, 1.0)
                }
            }
        }
    }

    /// The value at `position` (the inverse of [`Self::position`]).
    pub fn value(&self, position: f64) -> f64 {
        match *self {
            ColorScale::Diverging { limit } => position * limit,
            ColorScale::Sequential { low, high } => low * (high / low).powf(position),
        }
    }

    /// The scale's ends as positions: (−1, 1) or (0, 1).
    pub fn range(&self) -> (f64, f64) {
        match self {
            ColorScale::Diverging { .. } => (-1.0, 1.0),
            ColorScale::Sequential { .. } => (0.0, 1.0),
        }
    }

    /// The colour at a position on the scale (sRGB).
    pub fn color_at(&self, position: f64) -> [u8; 3] {
        match self {
            ColorScale::Diverging { .. } => ramp(&DIVERGING, 0.5 * (position + 1.0)),
            ColorScale::Sequential { .. } => ramp(&SEQUENTIAL, position),
        }
    }

    /// The colour of `value` (light grey where it is unknown).
    pub fn color(&self, value: f64) -> [u8; 3] {
        if value.is_nan() { [215, 215, 215] } else { self.color_at(self.position(value)) }
    }

    /// Values to label along a colour bar: both ends, halves and zero (diverging), or the
    /// powers of ten in between (sequential) with both ends.
    pub fn ticks(&self) -> Vec<f64> {
        match *self {
            ColorScale::Diverging { limit } => vec![-limit, -0.5 * limit, 0.0, 0.5 * limit, limit],
            ColorScale::Sequential { low, high } => {
                let mut ticks = vec![low];
                let mut e = low.log10().floor() as i32 + 1;
                while 10f64.powi(e) < high / 1.5 {
                    if 10f64.powi(e) > low * 1.5 {
                        ticks.push(10f64.powi(e));
                    }
                    e += 1;
                }
                ticks.push(high);
                ticks
            }
        }
    }
}

/// Linear interpolation between evenly spaced colour stops, `t` in 0…1.
fn ramp(stops: &[[u8; 3]], t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let k = (x.floor() as usize).min(stops.len() - 2);
    let f = x - k as f64;
    std::array::from_fn(|c| (stops[k][c] as f64 * (1.0 - f) + stops[k + 1][c] as f64 * f).round() as u8)
}

/// The `q` quantile of `values` (reordered in place); 0 when empty.
fn quantile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let k = ((values.len() - 1) as f64 * q).round() as usize;
    *values.select_nth_unstable_by(k, f64::total_cmp).1
}

/// A number as a label: three significant figures, in exponent form when very small or large.
pub fn label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        let text = format!("{v:.2e}");
        // 1.00e-3 reads as 1e-3.
        return text.replace(".00e", "e").replace("0e", "e");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_values_are_blue_white_red_and_saturate_past_the_outliers() {
        let mut values: Vec<f64> = (0..1000).map(|k| (k as f64 / 999.0 - 0.5) * 0.2).collect();
        values[0] = -50.0; // a nucleus
        let scale = ColorScale::for_values(&values, true, None);
        let ColorScale::Diverging { limit } = scale else { panic!("{scale:?}") };
        assert!((0.09..0.11).contains(&limit), "{limit}");
        assert_eq!(scale.color(0.0), [247, 247, 247]);
        assert_eq!(scale.color(-50.0), DIVERGING[0]);
        assert_eq!(scale.color(limit * 2.0), DIVERGING[4]);
        assert_eq!(scale.color(f64::NAN), [215, 215, 215]);
        assert!((scale.value(scale.position(0.03)) - 0.03).abs() < 1e-15);
    }

    #[test]
    fn densities_run_on_a_log_scale_from_the_lowest_level() {
        let scale = ColorScale::for_values(&[0.0, 1e-4, 0.01, 100.0], false, Some(1e-3));
        assert_eq!(scale, ColorScale::Sequential { low: 1e-3, high: 100.0 });
        assert!((scale.position(0.1) - 0.4).abs() < 1e-12, "a decade of five is a fifth");
        assert_eq!(scale.position(1e-5), 0.0);
        assert_eq!(scale.color(1e-5), SEQUENTIAL[0]);
        assert_eq!(scale.ticks(), [1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0]);
    }

    #[test]
    fn labels_keep_three_figures() {
        assert_eq!(label(0.05), "0.05");
        assert_eq!(label(-0.1234), "-0.123");
        assert_eq!(label(12.5), "12.5");
        assert_eq!(label(0.001), "0.001");
        assert_eq!(label(0.00879), "0.00879");
        assert_eq!(label(1e-4), "1e-4");
        assert_eq!(label(2.5e-5), "2.5e-5");
        assert_eq!(label(0.0), "0");
    }
}
