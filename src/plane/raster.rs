//! A map's figure as pixels: lines and discs anti-aliased by their distance from each pixel's
//! centre, text set by `figure`'s typeface.

use image::{Rgba, RgbaImage};

use super::drawing::{Anchor, Canvas, MapPicture, Rect, Stroke};
use crate::pictures::figure::{draw_text, shade, text_width};

/// Dash and gap of a dashed line, pixels.
const DASH: [f64; 2] = [5.0, 3.5];

/// The figure as an image.
pub fn png(picture: &MapPicture) -> RgbaImage {
    let [w, h] = picture.layout().size;
    let mut canvas = Raster { img: RgbaImage::from_pixel(w, h, Rgba([255, 255, 255, 255])) };
    picture.draw(&mut canvas);
    canvas.img
}

struct Raster {
    img: RgbaImage,
}

impl Raster {
    /// Blends `color` over the pixels in proportion to `coverage` over the box from (x0, y0).
    fn blend(&mut self, x0: i64, y0: i64, width: usize, coverage: &[f32], color: [u8; 3]) {
        for (k, &c) in coverage.iter().enumerate() {
            if c > 0.0 {
                let (x, y) = (x0 + (k % width) as i64, y0 + (k / width) as i64);
                shade(&mut self.img, x, y, 1, 1, color, c);
            }
        }
    }

    /// One unbroken line: each pixel covered by its nearest piece, so joints are not drawn twice.
    fn stroke(&mut self, points: &[[f64; 2]], width: f64, color: [u8; 3]) {
        let reach = 0.5 * width + 1.0;
        let (lo, hi) = points.iter().fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
        });
        let x0 = ((lo[0] - reach).floor() as i64).max(0);
        let y0 = ((lo[1] - reach).floor() as i64).max(0);
        let x1 = ((hi[0] + reach).ceil() as i64).min(self.img.width() as i64);
        let y1 = ((hi[1] + reach).ceil() as i64).min(self.img.height() as i64);
        if x1 <= x0 || y1 <= y0 {
            return;
        }
        let bw = (x1 - x0) as usize;
        let mut coverage = vec![0f32; bw * (y1 - y0) as usize];
        for s in points.windows(2) {
            let (a, b) = (s[0], s[1]);
            let sx0 = ((a[0].min(b[0]) - reach).floor() as i64).max(x0);
            let sx1 = ((a[0].max(b[0]) + reach).ceil() as i64).min(x1);
            let sy0 = ((a[1].min(b[1]) - reach).floor() as i64).max(y0);
            let sy1 = ((a[1].max(b[1]) + reach).ceil() as i64).min(y1);
            for y in sy0..sy1 {
                for x in sx0..sx1 {
                    let d = distance([x as f64 + 0.5, y as f64 + 0.5], a, b);
                    let c = (0.5 * width + 0.5 - d).clamp(0.0, 1.0).min(width) as f32;
                    let k = (y - y0) as usize * bw + (x - x0) as usize;
                    coverage[k] = coverage[k].max(c);
                }
            }
        }
        self.blend(x0, y0, bw, &coverage, color);
    }
}

/// Distance from `p` to the segment a–b.
fn distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// The dashes of a polyline: pieces [`DASH`] long, [`DASH`]'s gap apart, along its length.
fn dashes(points: &[[f64; 2]]) -> Vec<Vec<[f64; 2]>> {
    let mut out = Vec::new();
    let mut current = vec![points[0]];
    let (mut on, mut left) = (true, DASH[0]);
    for s in points.windows(2) {
        let (mut a, b) = (s[0], s[1]);
        let mut length = (b[0] - a[0]).hypot(b[1] - a[1]);
        while length > left {
            let t = left / length;
            let cut = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            if on {
                current.push(cut);
                out.push(std::mem::take(&mut current));
            } else {
                current = vec![cut];
            }
            length -= left;
            a = cut;
            on = !on;
            left = DASH[usize::from(!on)];
        }
        left -= length;
        if on {
            current.push(b);
        }
    }
    if on && current.len() > 1 {
        out.push(current);
    }
    out
}

impl Canvas for Raster {
    fn raster(&mut self, [x, y, w, h]: Rect, pixels: &RgbaImage) {
        let (pw, ph) = pixels.dimensions();
        for py in (y.round() as u32)..((y + h).round() as u32).min(self.img.height()) {
            for px in (x.round() as u32)..((x + w).round() as u32).min(self.img.width()) {
                let sx = (((px as f64 + 0.5 - x) / w * pw as f64) as u32).min(pw - 1);
                let sy = (((py as f64 + 0.5 - y) / h * ph as f64) as u32).min(ph - 1);
                self.img.put_pixel(px, py, *pixels.get_pixel(sx, sy));
            }
        }
    }

    fn polyline(&mut self, points: &[[f64; 2]], stroke: Stroke, _class: &str) {
        if points.len() < 2 {
            return;
        }
        if stroke.dashed {
            for dash in dashes(points) {
                self.stroke(&dash, stroke.width, stroke.color);
            }
        } else {
            self.stroke(points, stroke.width, stroke.color);
        }
    }

    fn disc(&mut self, centre: [f64; 2], radius: f64, fill: [u8; 3], outline: [u8; 3]) {
        let reach = radius + 1.5;
        let (x0, y0) = ((centre[0] - reach).floor() as i64, (centre[1] - reach).floor() as i64);
        let n = (2.0 * reach).ceil() as usize + 1;
        let mut inner = vec![0f32; n * n];
        let mut ring = vec![0f32; n * n];
        for k in 0..n * n {
            let (x, y) = (x0 + (k % n) as i64, y0 + (k / n) as i64);
            let d = (x as f64 + 0.5 - centre[0]).hypot(y as f64 + 0.5 - centre[1]);
            inner[k] = (radius + 0.5 - d).clamp(0.0, 1.0) as f32;
            ring[k] = (1.2 - (d - radius).abs()).clamp(0.0, 1.0) as f32;
        }
        self.blend(x0, y0, n, &inner, fill);
        self.blend(x0, y0, n, &ring, outline);
    }

    fn text(&mut self, at: [f64; 2], px: f64, anchor: Anchor, color: [u8; 3], text: &str) {
        let px = px as f32;
        let width = text_width(text, px);
        let x = match anchor {
            Anchor::Start => at[0] as f32,
            Anchor::Middle => at[0] as f32 - 0.5 * width,
            Anchor::End => at[0] as f32 - width,
        };
        // The typeface's capitals stand about 0.7 px above its baseline, which sits at 0.8 px.
        draw_text(&mut self.img, text, x, at[1] as f32 - 0.45 * px, px, color);
    }

    fn rect(&mut self, [x, y, w, h]: Rect, fill: Option<([u8; 3], f64)>, outline: Option<[u8; 3]>) {
        if let Some((color, a)) = fill {
            shade(
                &mut self.img,
                x.round() as i64,
                y.round() as i64,
                w.round() as i64,
                h.round() as i64,
                color,
                a as f32,
            );
        }
        if let Some(color) = outline {
            let corners = [[x, y], [x + w, y], [x + w, y + h], [x, y + h], [x, y]];
            self.stroke(&corners, 1.0, color);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashes_alternate_along_the_line() {
        let pieces = dashes(&[[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]]);
        let spans: Vec<[f64; 2]> = pieces.iter().map(|p| [p[0][0], p[p.len() - 1][0]]).collect();
        assert_eq!(spans, [[0.0, 5.0], [8.5, 13.5], [17.0, 20.0]]);
    }

    #[test]
    fn a_stroke_darkens_the_pixels_along_it_only() {
        let mut r = Raster { img: RgbaImage::from_pixel(20, 20, Rgba([255; 4])) };
        r.polyline(&[[2.0, 10.5], [18.0, 10.5]], Stroke { color: [0, 0, 0], width: 1.0, dashed: false }, "t");
        assert_eq!(r.img.get_pixel(10, 10).0, [0, 0, 0, 255]);
        assert_eq!(r.img.get_pixel(10, 3).0, [255; 4]);
        assert_eq!(r.img.get_pixel(0, 10).0, [255; 4]);
    }
}
