//! The figure of a map, laid out once and drawn on any [`Canvas`] (the PNG's pixels, the SVG's
//! elements): the colour-filled values, contour lines (negative ones dashed, zero heavier),
//! the bonds projected into the plane (grey where they leave it), the atoms near the plane
//! marked and labelled, axes in ångström, a colour bar with the levels on it, and a caption.

use image::{Rgba, RgbaImage};

use super::colors::{ColorScale, label};
use super::contour::contour;
use super::values::{PlaneMap, Sampling, VANISHING};
use crate::model::Molecule;
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};

/// Atoms this close to the plane (bohr) are marked and labelled; bonds between two of them are
/// drawn as in the plane.
pub const NEAR_PLANE: f64 = 0.5 * BOHR_PER_ANGSTROM;

/// The longer side of the map itself, in pixels.
const PLOT: f64 = 640.0;
const LEFT: f64 = 92.0;
const RIGHT: f64 = 150.0;
const BOTTOM: f64 = 60.0;
const TEXT: f64 = 14.0;
const CAPTION_LINE: f64 = 19.0;

const INK: [u8; 3] = [30, 30, 30];
const FAINT: [u8; 3] = [150, 150, 150];
const WHITE: [u8; 3] = [255, 255, 255];

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    pub color: [u8; 3],
    pub width: f64,
    pub dashed: bool,
}

/// Where text sits on its point: its start, middle or end there, centred vertically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    Start,
    Middle,
    End,
}

/// A rectangle in pixels: left, top, width, height.
pub type Rect = [f64; 4];

/// What the figure is drawn with; coordinates in pixels from the top left.
pub trait Canvas {
    /// `pixels` stretched over `rect`.
    fn raster(&mut self, rect: Rect, pixels: &RgbaImage);
    /// A line through `points`; `class` names what it is (`contour`, `bond`, `axis`).
    fn polyline(&mut self, points: &[[f64; 2]], stroke: Stroke, class: &str);
    fn disc(&mut self, centre: [f64; 2], radius: f64, fill: [u8; 3], outline: [u8; 3]);
    fn text(&mut self, at: [f64; 2], px: f64, anchor: Anchor, color: [u8; 3], text: &str);
    /// A rectangle filled with `fill` at its opacity, and outlined.
    fn rect(&mut self, rect: Rect, fill: Option<([u8; 3], f64)>, outline: Option<[u8; 3]>);
}

/// A map with what its figure says about it.
pub struct MapPicture<'a> {
    pub map: &'a PlaneMap,
    pub molecule: &'a Molecule,
    /// Contour levels, ascending.
    pub levels: &'a [f64],
    /// Caption lines: the file and quantity, the plane.
    pub caption: Vec<String>,
    /// The colour bar's title: the quantity and its unit.
    pub unit: String,
    /// The colour scale, when not the one the values suggest ([`ColorScale::for_values`]).
    pub scale: Option<ColorScale>,
    /// Gradient lines from the atoms near the plane over the contours.
    pub gradient_lines: bool,
    /// The axes in bohr (else ångström).
    pub bohr: bool,
}

/// Where the parts of a figure go.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    pub size: [u32; 2],
    /// The map itself.
    pub plot: Rect,
    pub bar: Rect,
}

impl MapPicture<'_> {
    /// The caption as drawn: the lines given, and a note when the values are interpolated.
    pub fn caption_lines(&self) -> Vec<String> {
        let mut lines = self.caption.clone();
        if self.map.vanishes() {
            lines.push(format!("zero on this plane: |value| < {VANISHING:e} everywhere (a nodal plane); no contours"));
        }
        if let Sampling::Trilinear { outside } = self.map.sampling {
            let mut note =
                "values interpolated trilinearly between the cube file's grid points (not exact)".to_string();
            if outside > 0 {
                note.push_str("; grey: outside its grid");
            }
            lines.push(note);
        }
        lines
    }

    pub fn layout(&self) -> Layout {
        let [su, sv] = self.map.plane.size;
        let scale = PLOT / su.max(sv);
        let (w, h) = ((su * scale).round().max(120.0), (sv * scale).round().max(120.0));
        let top = 22.0 + CAPTION_LINE * self.caption_lines().len() as f64;
        let plot = [LEFT, top, w, h];
        let bar = [LEFT + w + 30.0, top, 20.0, h];
        let size = [(LEFT + w + RIGHT) as u32, (top + h + BOTTOM) as u32];
        Layout { size, plot, bar }
    }

    /// The colour scale: diverging or sequential as the quantity's sign says, sequential from
    /// the lowest positive contour level.
    pub fn scale(&self) -> ColorScale {
        if let Some(scale) = self.scale {
            return scale;
        }
        if self.map.vanishes() {
            return ColorScale::Diverging { limit: VANISHING };
        }
        let low = self.levels.iter().copied().find(|&l| l > 0.0);
        ColorScale::for_values(&self.map.values, self.map.signed, low)
    }

    /// The whole figure on `canvas`.
    pub fn draw(&self, canvas: &mut impl Canvas) {
        let layout = self.layout();
        let [_, _, w, h] = layout.plot;
        canvas.rect([0.0, 0.0, layout.size[0] as f64, layout.size[1] as f64], Some((WHITE, 1.0)), None);
        for (n, line) in self.caption_lines().iter().enumerate() {
            canvas.text([LEFT, 16.0 + CAPTION_LINE * n as f64], TEXT, Anchor::Start, INK, line);
        }
        let scale = self.scale();
        canvas.raster(layout.plot, &self.fill(&scale, [w as u32, h as u32]));
        self.contours(canvas, layout.plot);
        if self.gradient_lines {
            self.gradient(canvas, layout.plot);
        }
        self.atoms(canvas, layout.plot);
        canvas.rect(layout.plot, None, Some(INK));
        self.axes(canvas, layout.plot);
        self.color_bar(canvas, &scale, layout.bar);
    }

    /// The values coloured at each pixel, bilinear between the map's points.
    fn fill(&self, scale: &ColorScale, [w, h]: [u32; 2]) -> RgbaImage {
        let n = self.map.plane.points;
        let last = (n - 1) as f64;
        let values = &self.map.values;
        RgbaImage::from_fn(w, h, |px, py| {
            let gx = (px as f64 + 0.5) / w as f64 * last;
            let gy = (1.0 - (py as f64 + 0.5) / h as f64) * last;
            let (i, j) = ((gx.floor() as usize).min(n - 2), (gy.floor() as usize).min(n - 2));
            let (fx, fy) = (gx - i as f64, gy - j as f64);
            let at = |i: usize, j: usize| values[j * n + i];
            let v = (at(i, j) * (1.0 - fx) + at(i + 1, j) * fx) * (1.0 - fy)
                + (at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx) * fy;
            let [r, g, b] = scale.color(v);
            Rgba([r, g, b, 255])
        })
    }

    fn contours(&self, canvas: &mut impl Canvas, [x0, y0, w, h]: Rect) {
        if self.map.vanishes() {
            return;
        }
        let n = self.map.plane.points;
        let last = (n - 1) as f64;
        let faint = self.faint();
        for &level in self.levels {
            let stroke = Stroke { color: INK, width: if level == 0.0 { 1.6 } else { 0.9 }, dashed: level < 0.0 };
            // Where the quantity has all but vanished its sign follows the tails' last digits:
            // the zero line there says nothing.
            let floor = if level == 0.0 { faint } else { 0.0 };
            for line in contour(&self.map.values, n, n, level, floor) {
                let points: Vec<[f64; 2]> =
                    line.points.iter().map(|p| [x0 + p[0] / last * w, y0 + (1.0 - p[1] / last) * h]).collect();
                canvas.polyline(&points, stroke, "contour");
            }
        }
    }

    /// Gradient lines from the atoms within [`NEAR_PLANE`] of the plane, thin and grey.
    fn gradient(&self, canvas: &mut impl Canvas, plot: Rect) {
        if self.map.vanishes() {
            return;
        }
        let n = self.map.plane.points;
        let last = (n - 1) as f64;
        let [x0, y0, w, h] = plot;
        let centres: Vec<[f64; 2]> = (self.molecule.atoms.iter())
            .filter_map(|a| {
                let ([u, v], d) = self.map.plane.project(a.position);
                let [su, sv] = self.map.plane.size;
                (d.abs() <= NEAR_PLANE).then_some([(u / su + 0.5) * last, (v / sv + 0.5) * last])
            })
            .collect();
        let stroke = Stroke { color: FAINT, width: 0.7, dashed: false };
        for line in super::gradient::gradient_lines(&self.map.values, n, &centres) {
            let points: Vec<[f64; 2]> =
                line.iter().map(|p| [x0 + p[0] / last * w, y0 + (1.0 - p[1] / last) * h]).collect();
            canvas.polyline(&points, stroke, "gradient");
        }
    }

    /// Cells whose values all stay below this magnitude have no zero contour: a thousandth of
    /// the smallest nonzero level (a millionth of the largest value when zero is the only level).
    fn faint(&self) -> f64 {
        let smallest = self.levels.iter().map(|l| l.abs()).filter(|&l| l > 0.0).fold(f64::INFINITY, f64::min);
        if smallest.is_finite() { 1e-3 * smallest } else { 1e-6 * self.map.max_abs() }
    }

    /// A point in space as pixels of the plot, and its distance from the plane (bohr).
    fn to_plot(&self, p: glam::DVec3, [x0, y0, w, h]: Rect) -> ([f64; 2], f64) {
        let ([u, v], d) = self.map.plane.project(p);
        let [su, sv] = self.map.plane.size;
        ([x0 + (u / su + 0.5) * w, y0 + (0.5 - v / sv) * h], d)
    }

    fn atoms(&self, canvas: &mut impl Canvas, plot: Rect) {
        let atoms = &self.molecule.atoms;
        let placed: Vec<([f64; 2], bool)> = atoms
            .iter()
            .map(|a| {
                let (p, d) = self.to_plot(a.position, plot);
                (p, d.abs() <= NEAR_PLANE)
            })
            .collect();
        // Bonds leaving the plane first, so the ones in it are drawn over them.
        for in_plane in [false, true] {
            for bond in &self.molecule.bonds {
                let (a, b) = (placed[bond.a as usize], placed[bond.b as usize]);
                if (a.1 && b.1) != in_plane {
                    continue;
                }
                let stroke = if in_plane {
                    Stroke { color: INK, width: 2.4, dashed: false }
                } else {
                    Stroke { color: FAINT, width: 1.4, dashed: false }
                };
                if let Some(segment) = clip(a.0, b.0, plot) {
                    canvas.polyline(&segment, stroke, "bond");
                }
            }
        }
        for (n, (atom, &(p, near))) in atoms.iter().zip(&placed).enumerate() {
            if !near || !inside(p, plot) {
                continue;
            }
            let element = atom.element();
            canvas.disc(p, 4.5, element.color, INK);
            let text = format!("{}{}", element.symbol, n + 1);
            let at = [p[0] + 7.0, p[1] - 10.0];
            let width = crate::pictures::figure::text_width(&text, (TEXT - 1.0) as f32) as f64;
            canvas.rect([at[0] - 2.0, at[1] - 8.0, width + 4.0, 16.0], Some((WHITE, 0.75)), None);
            canvas.text(at, TEXT - 1.0, Anchor::Start, INK, &text);
        }
    }

    fn axes(&self, canvas: &mut impl Canvas, [x0, y0, w, h]: Rect) {
        let (per_bohr, unit) = if self.bohr { (1.0, "bohr") } else { (ANGSTROM_PER_BOHR, "Å") };
        let [su, sv] = self.map.plane.size.map(|s| s * per_bohr);
        let step = nice_step(su.max(sv) / 6.0);
        let stroke = Stroke { color: INK, width: 1.0, dashed: false };
        for value in ticks(su * 0.5, step) {
            let x = x0 + (value / su + 0.5) * w;
            canvas.polyline(&[[x, y0 + h], [x, y0 + h + 5.0]], stroke, "axis");
            canvas.text([x, y0 + h + 16.0], TEXT - 1.0, Anchor::Middle, INK, &label(value));
        }
        for value in ticks(sv * 0.5, step) {
            let y = y0 + (0.5 - value / sv) * h;
            canvas.polyline(&[[x0, y], [x0 - 5.0, y]], stroke, "axis");
            canvas.text([x0 - 9.0, y], TEXT - 1.0, Anchor::End, INK, &label(value));
        }
        canvas.text([x0 + 0.5 * w, y0 + h + 42.0], TEXT, Anchor::Middle, INK, &format!("u ({unit})"));
        canvas.text([x0 - 66.0, y0 + 0.5 * h], TEXT, Anchor::Middle, INK, &format!("v ({unit})"));
    }

    fn color_bar(&self, canvas: &mut impl Canvas, scale: &ColorScale, [x, y, w, h]: Rect) {
        let (lo, hi) = scale.range();
        let rows = 256u32;
        let gradient = RgbaImage::from_fn(1, rows, |_, r| {
            let t = hi - (r as f64 + 0.5) / rows as f64 * (hi - lo);
            let [r, g, b] = scale.color_at(t);
            Rgba([r, g, b, 255])
        });
        canvas.raster([x, y, w, h], &gradient);
        let y_of = |value: f64| y + (hi - scale.position(value)) / (hi - lo) * h;
        // The contour levels on the bar, as on the map.
        for &level in self.levels {
            let t = scale.position(level);
            if t > lo && t < hi {
                let yy = y_of(level);
                canvas.polyline(&[[x, yy], [x + w, yy]], Stroke { color: INK, width: 0.6, dashed: false }, "level");
            }
        }
        canvas.rect([x, y, w, h], None, Some(INK));
        for value in scale.ticks() {
            let yy = y_of(value);
            canvas.polyline(
                &[[x + w, yy], [x + w + 4.0, yy]],
                Stroke { color: INK, width: 1.0, dashed: false },
                "axis",
            );
            canvas.text([x + w + 7.0, yy], TEXT - 1.0, Anchor::Start, INK, &label(value));
        }
        canvas.text([x, y - 12.0], TEXT, Anchor::Start, INK, &self.unit);
    }
}

/// The multiples of `step` from −`half` to `half`.
fn ticks(half: f64, step: f64) -> Vec<f64> {
    let first = (-half / step - 1e-9).ceil() as i64;
    (first..).map(|k| k as f64 * step).take_while(|&v| v <= half + 1e-9 * step).collect()
}

/// 1, 2 or 5 times a power of ten, the nearest at or above `raw`.
fn nice_step(raw: f64) -> f64 {
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * p).find(|&s| s >= raw * 0.999).unwrap_or(10.0 * p)
}

fn inside(p: [f64; 2], [x, y, w, h]: Rect) -> bool {
    p[0] >= x && p[0] <= x + w && p[1] >= y && p[1] <= y + h
}

/// The part of the segment a–b inside `rect` (Liang–Barsky), if any.
fn clip(a: [f64; 2], b: [f64; 2], [x, y, w, h]: Rect) -> Option<[[f64; 2]; 2]> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d[0], a[0] - x), (d[0], x + w - a[0]), (-d[1], a[1] - y), (d[1], y + h - a[1])] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 < t1).then(|| [t0, t1].map(|t| [a[0] + t * d[0], a[1] + t * d[1]]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_clipped_to_the_plot() {
        let rect = [0.0, 0.0, 10.0, 10.0];
        assert_eq!(clip([-5.0, 5.0], [15.0, 5.0], rect), Some([[0.0, 5.0], [10.0, 5.0]]));
        assert_eq!(clip([2.0, 2.0], [3.0, 3.0], rect), Some([[2.0, 2.0], [3.0, 3.0]]));
        assert_eq!(clip([-5.0, -5.0], [-1.0, 20.0], rect), None);
        assert_eq!(nice_step(1.3), 2.0);
        assert_eq!(nice_step(0.04), 0.05);
    }
}
