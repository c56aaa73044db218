//! Pictures that stand alone: captions drawn into rendered images, supersampled pictures
//! filtered down, and a transparent background recovered from two renderings. Plain image work
//! on what the renderer read back, so it serves `render`, `scan render`, movies and the viewer's
//! *Save PNG* alike.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use image::{Rgba, RgbaImage};

/// How a picture is made from the renderer's frames: drawn at `scale`× and filtered down, and
/// with a transparent background (drawn twice, over black and over white).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figure {
    pub scale: u32,
    pub transparent: bool,
}

impl Default for Figure {
    fn default() -> Self {
        Self { scale: 1, transparent: false }
    }
}

/// The largest supersampling factor a figure takes.
pub const MAX_SCALE: u32 = 4;

impl Figure {
    /// The size the renderer draws at for a picture of `size`.
    pub fn drawn_size(&self, size: [u32; 2]) -> [u32; 2] {
        size.map(|s| s * self.scale.clamp(1, MAX_SCALE))
    }

    /// The picture: `draw(background)` renders a frame at [`Figure::drawn_size`] over
    /// `background` (linear RGB); called once, or twice for a transparent background.
    pub fn draw<E>(
        &self,
        background: [f32; 3],
        mut draw: impl FnMut([f32; 3]) -> Result<RgbaImage, E>,
    ) -> Result<RgbaImage, E> {
        let drawn = if self.transparent { transparent(&draw([0.0; 3])?, &draw([1.0; 3])?) } else { draw(background)? };
        Ok(downsample(&drawn, self.scale.clamp(1, MAX_SCALE)))
    }
}

/// The typeface captions are set in (the viewer's own).
fn font() -> FontRef<'static> {
    FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT).expect("the bundled font parses")
}

/// The caption height (px) for a picture `height` pixels tall: legible in a slide and small
/// beside the molecule.
pub fn caption_px(height: u32) -> f32 {
    (height as f32 / 22.0).clamp(11.0, 40.0)
}

/// Width in pixels of `text` set at `px`.
pub fn text_width(text: &str, px: f32) -> f32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(px));
    let mut width = 0.0;
    let mut previous = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            width += scaled.kern(p, id);
        }
        width += scaled.h_advance(id);
        previous = Some(id);
    }
    width
}

/// Draws `text` with its top-left corner at (`x`, `y`), `px` tall, in `color` blended over
/// what is there (the coverage of each glyph pixel is its opacity).
pub fn draw_text(img: &mut RgbaImage, text: &str, x: f32, y: f32, px: f32, color: [u8; 3]) {
    let font = font();
    let scale = PxScale::from(px);
    let scaled = font.as_scaled(scale);
    let baseline = y + scaled.ascent();
    let mut pen = x;
    let mut previous = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            pen += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, point(pen, baseline));
        pen += scaled.h_advance(id);
        previous = Some(id);
        let Some(outline) = font.outline_glyph(glyph) else { continue };
        let bounds = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let (px_x, px_y) = (bounds.min.x as i64 + gx as i64, bounds.min.y as i64 + gy as i64);
            if px_x >= 0 && px_y >= 0 && (px_x as u32) < img.width() && (px_y as u32) < img.height() {
                blend(img.get_pixel_mut(px_x as u32, px_y as u32), color, coverage.clamp(0.0, 1.0));
            }
        });
    }
}

/// `over` at opacity `a` over the pixel (straight alpha; the pixel becomes as opaque as the two
/// together).
fn blend(p: &mut Rgba<u8>, over: [u8; 3], a: f32) {
    let below = p.0[3] as f32 / 255.0;
    let out_a = a + below * (1.0 - a);
    if out_a <= 0.0 {
        return;
    }
    for (channel, &o) in p.0.iter_mut().zip(&over) {
        let v = (o as f32 * a + *channel as f32 * below * (1.0 - a)) / out_a;
        *channel = v.round().clamp(0.0, 255.0) as u8;
    }
    p.0[3] = (out_a * 255.0).round() as u8;
}

/// Fills the rectangle at (`x`, `y`) of size `w`×`h` with `color` at opacity `a`.
pub fn shade(img: &mut RgbaImage, x: i64, y: i64, w: i64, h: i64, color: [u8; 3], a: f32) {
    let (x0, y0) = (x.max(0) as u32, y.max(0) as u32);
    let x1 = ((x + w).max(0) as u32).min(img.width());
    let y1 = ((y + h).max(0) as u32).min(img.height());
    for py in y0..y1 {
        for px in x0..x1 {
            blend(img.get_pixel_mut(px, py), color, a);
        }
    }
}

/// Lines of text at the top left of the region `x0..x0 + width` of `img`, light on a dark band
/// so they read over any cloud: what a pane shows (orbital, energy, the coordinate's value).
pub fn caption(img: &mut RgbaImage, x0: u32, width: u32, lines: &[String]) {
    let px = caption_px(img.height());
    let pad = (px * 0.35).ceil();
    let line_height = (px * 1.2).ceil();
    let widest = lines.iter().map(|l| text_width(l, px)).fold(0.0, f32::max);
    if lines.is_empty() || widest == 0.0 {
        return;
    }
    let band_w = (widest + 2.0 * pad).min(width as f32);
    let band_h = line_height * lines.len() as f32 + pad;
    shade(img, x0 as i64, 0, band_w.ceil() as i64, band_h.ceil() as i64, [0, 0, 0], 0.55);
    for (n, line) in lines.iter().enumerate() {
        draw_text(img, line, x0 as f32 + pad, pad * 0.5 + n as f32 * line_height, px, [235, 235, 235]);
    }
}

/// A vertical colour bar at the right edge of `img`: `color(t)` (sRGB) for t from −1 at the
/// bottom to 1 at the top, `ticks` (bottom, middle, top) written beside it and `title` above.
pub fn color_bar(img: &mut RgbaImage, color: impl Fn(f32) -> [u8; 3], ticks: [&str; 3], title: &str) {
    let (w, h) = (img.width() as f32, img.height() as f32);
    let px = caption_px(img.height());
    let pad = (px * 0.5).ceil();
    let bar_w = (px * 0.8).ceil();
    let bar_h = (h * 0.55).round();
    let title_w = text_width(title, px);
    let panel_w = color_bar_width(img.height(), ticks, title) - pad;
    let (x0, y0) = (w - panel_w - pad, (h - bar_h) * 0.5 - px * 1.4);
    let panel_h = bar_h + px * 1.4 + px + 2.0 * pad;
    shade(img, x0 as i64, (y0 - pad) as i64, panel_w.ceil() as i64, panel_h.ceil() as i64, [0, 0, 0], 0.55);
    draw_text(img, title, x0 + panel_w - pad - title_w, y0, px, [235, 235, 235]);
    let bar_x = x0 + panel_w - pad - bar_w;
    let bar_top = y0 + px * 1.4;
    for row in 0..bar_h as i64 {
        let t = 1.0 - 2.0 * row as f32 / (bar_h - 1.0).max(1.0);
        let c = color(t);
        shade(img, bar_x as i64, (bar_top as i64) + row, bar_w as i64, 1, c, 1.0);
    }
    for (n, tick) in ticks.iter().enumerate() {
        // Bottom, middle, top; each label centred on its place along the bar.
        let y = bar_top + bar_h * (1.0 - n as f32 * 0.5) - px * 0.6;
        draw_text(img, tick, bar_x - pad * 0.6 - text_width(tick, px), y, px, [235, 235, 235]);
    }
}

/// How much of an image `height` pixels tall [`color_bar`] covers from its right edge, its
/// margin included (pixels): what a picture's framing leaves free for it.
pub fn color_bar_width(height: u32, ticks: [&str; 3], title: &str) -> f32 {
    let px = caption_px(height);
    let pad = (px * 0.5).ceil();
    let bar_w = (px * 0.8).ceil();
    let label_w = ticks.iter().map(|t| text_width(t, px)).fold(0.0, f32::max);
    (label_w + bar_w + 3.0 * pad).max(text_width(title, px) + 2.0 * pad) + pad
}

/// sRGB-encoded byte to linear light.
fn linear(v: u8) -> f32 {
    let c = v as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Linear light to an sRGB-encoded byte.
pub fn encoded(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let v = if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

/// A picture drawn at `k`× the size, filtered down by averaging each k×k block in linear light
/// (colours weighted by opacity), so impostor edges and thin sticks come out smooth.
pub fn downsample(img: &RgbaImage, k: u32) -> RgbaImage {
    if k <= 1 {
        return img.clone();
    }
    let (w, h) = (img.width() / k, img.height() / k);
    let n = (k * k) as f32;
    RgbaImage::from_fn(w, h, |x, y| {
        let (mut rgb, mut alpha) = ([0.0f32; 3], 0.0f32);
        for dy in 0..k {
            for dx in 0..k {
                let p = img.get_pixel(x * k + dx, y * k + dy).0;
                let a = p[3] as f32 / 255.0;
                for c in 0..3 {
                    rgb[c] += linear(p[c]) * a;
                }
                alpha += a;
            }
        }
        if alpha <= 0.0 {
            return Rgba([0, 0, 0, 0]);
        }
        Rgba([encoded(rgb[0] / alpha), encoded(rgb[1] / alpha), encoded(rgb[2] / alpha), encoded_alpha(alpha / n)])
    })
}

fn encoded_alpha(a: f32) -> u8 {
    (a.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The picture with a transparent background, from the same frame drawn over black and over
/// white: everything the renderer draws is composited over the background linearly
/// (out = C + (1 − α)·B), so the two give each pixel's opacity α = 1 − (white − black) and its
/// colour C/α, whatever the passes that drew it.
pub fn transparent(on_black: &RgbaImage, on_white: &RgbaImage) -> RgbaImage {
    RgbaImage::from_fn(on_black.width(), on_black.height(), |x, y| {
        let (b, w) = (on_black.get_pixel(x, y).0, on_white.get_pixel(x, y).0);
        let lb = [linear(b[0]), linear(b[1]), linear(b[2])];
        let lw = [linear(w[0]), linear(w[1]), linear(w[2])];
        // The three channels each measure 1 − α; their mean is the least noisy.
        let a = (1.0 - (0..3).map(|c| lw[c] - lb[c]).sum::<f32>() / 3.0).clamp(0.0, 1.0);
        if a < 1.0 / 512.0 {
            return Rgba([0, 0, 0, 0]);
        }
        Rgba([encoded(lb[0] / a), encoded(lb[1] / a), encoded(lb[2] / a), encoded_alpha(a)])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn captions_draw_light_text_on_a_dark_band() {
        let mut img = RgbaImage::from_pixel(200, 100, Rgba([40, 80, 160, 255]));
        caption(&mut img, 0, 200, &["HOMO  −0.3012 Eh".into()]);
        let lit = img.pixels().filter(|p| p.0[0] > 150 && p.0[1] > 150).count();
        assert!(lit > 20, "the glyphs are drawn ({lit} light pixels)");
        assert_eq!(img.get_pixel(199, 99).0, [40, 80, 160, 255], "outside the band nothing changes");
        assert!(text_width("HOMO", 20.0) > text_width("H", 20.0));
    }

    #[test]
    fn a_colour_bar_runs_from_its_bottom_colour_to_its_top_colour() {
        let mut img = RgbaImage::from_pixel(300, 200, Rgba([0, 0, 0, 255]));
        let color = |t: f32| if t < 0.0 { [255, 0, 0] } else { [0, 0, 255] };
        color_bar(&mut img, color, ["-0.05", "0", "+0.05"], "ψ (a.u.)");
        let column: Vec<[u8; 4]> = (0..200).map(|y| img.get_pixel(img.width() - 16, y).0).collect();
        let top = column.iter().position(|p| p[2] == 255 && p[0] == 0).expect("blue at the top");
        let bottom = column.iter().rposition(|p| p[0] == 255 && p[2] == 0).expect("red at the bottom");
        assert!(top < bottom);
        assert_eq!(img.get_pixel(5, 5).0, [0, 0, 0, 255], "the left of the picture is untouched");
    }

    #[test]
    fn downsampling_averages_blocks_in_linear_light() {
        // Black and white pixels in a 2×2 block average to half the light: sRGB 188, not 128.
        let img = RgbaImage::from_fn(4, 2, |x, _| if x % 2 == 0 { Rgba([0, 0, 0, 255]) } else { Rgba([255; 4]) });
        let small = downsample(&img, 2);
        assert_eq!(small.dimensions(), (2, 1));
        assert_eq!(small.get_pixel(0, 0).0, [188, 188, 188, 255]);
        // A transparent half counts only in the opacity.
        let img = RgbaImage::from_fn(2, 2, |x, _| if x == 0 { Rgba([255, 0, 0, 255]) } else { Rgba([0; 4]) });
        assert_eq!(downsample(&img, 2).get_pixel(0, 0).0, [255, 0, 0, 128]);
    }

    #[test]
    fn two_backgrounds_give_opacity_and_colour() {
        // A half-opaque red over black and over white, composited as the renderer does.
        let over = |bg: f32| {
            let c = [0.5 * 1.0 + 0.5 * bg, 0.5 * bg, 0.5 * bg];
            Rgba([encoded(c[0]), encoded(c[1]), encoded(c[2]), 255])
        };
        let black = RgbaImage::from_pixel(1, 1, over(0.0));
        let white = RgbaImage::from_pixel(1, 1, over(1.0));
        let p = transparent(&black, &white).get_pixel(0, 0).0;
        assert_eq!(p[0], 255);
        assert!(p[1] <= 1 && p[2] <= 1);
        assert!((p[3] as i32 - 128).abs() <= 1, "alpha {}", p[3]);
        // The background itself is fully transparent.
        let bg = transparent(
            &RgbaImage::from_pixel(1, 1, Rgba([0, 0, 0, 255])),
            &RgbaImage::from_pixel(1, 1, Rgba([255; 4])),
        );
        assert_eq!(bg.get_pixel(0, 0).0[3], 0);
    }
}
