//! A map's figure as SVG text: the colour fill an embedded PNG, everything else vector
//! elements (each contour line a `<polyline class="contour">`, negative ones dashed), so a
//! figure scales and its lines can be edited.

use std::fmt::Write;

use image::RgbaImage;

use super::drawing::{Anchor, Canvas, MapPicture, Rect, Stroke};

/// The figure as an SVG document.
pub fn svg(picture: &MapPicture) -> String {
    let [w, h] = picture.layout().size;
    let mut canvas = Svg { out: String::new() };
    let _ = writeln!(
        canvas.out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Ubuntu, DejaVu Sans, Helvetica, Arial, sans-serif">"#
    );
    picture.draw(&mut canvas);
    canvas.out.push_str("</svg>\n");
    canvas.out
}

struct Svg {
    out: String,
}

fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// `text` with the characters XML gives a meaning escaped.
fn escaped(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

impl Canvas for Svg {
    fn raster(&mut self, [x, y, w, h]: Rect, pixels: &RgbaImage) {
        let mut png = Vec::new();
        let encoder = image::codecs::png::PngEncoder::new(&mut png);
        let (pw, ph) = pixels.dimensions();
        if image::ImageEncoder::write_image(encoder, pixels.as_raw(), pw, ph, image::ExtendedColorType::Rgba8).is_err()
        {
            return;
        }
        let _ = writeln!(
            self.out,
            r#"<image x="{x:.2}" y="{y:.2}" width="{w:.2}" height="{h:.2}" preserveAspectRatio="none" href="data:image/png;base64,{}"/>"#,
            base64(&png)
        );
    }

    fn polyline(&mut self, points: &[[f64; 2]], stroke: Stroke, class: &str) {
        let mut coordinates = String::with_capacity(points.len() * 14);
        for p in points {
            let _ = write!(coordinates, "{:.2},{:.2} ", p[0], p[1]);
        }
        let dash = if stroke.dashed { r#" stroke-dasharray="5 3.5""# } else { "" };
        let _ = writeln!(
            self.out,
            r#"<polyline class="{class}" points="{}" fill="none" stroke="{}" stroke-width="{}" stroke-linejoin="round"{dash}/>"#,
            coordinates.trim_end(),
            hex(stroke.color),
            stroke.width
        );
    }

    fn disc(&mut self, centre: [f64; 2], radius: f64, fill: [u8; 3], outline: [u8; 3]) {
        let _ = writeln!(
            self.out,
            r#"<circle class="atom" cx="{:.2}" cy="{:.2}" r="{radius}" fill="{}" stroke="{}"/>"#,
            centre[0],
            centre[1],
            hex(fill),
            hex(outline)
        );
    }

    fn text(&mut self, at: [f64; 2], px: f64, anchor: Anchor, color: [u8; 3], text: &str) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let _ = writeln!(
            self.out,
            r#"<text x="{:.2}" y="{:.2}" font-size="{px}" text-anchor="{anchor}" dominant-baseline="central" fill="{}">{}</text>"#,
            at[0],
            at[1],
            hex(color),
            escaped(text)
        );
    }

    fn rect(&mut self, [x, y, w, h]: Rect, fill: Option<([u8; 3], f64)>, outline: Option<[u8; 3]>) {
        let fill = fill.map_or("none".to_string(), |(c, a)| format!(r#"{}" fill-opacity="{a}"#, hex(c)));
        let stroke = outline.map_or("none".to_string(), hex);
        let _ = writeln!(
            self.out,
            r#"<rect x="{x:.2}" y="{y:.2}" width="{w:.2}" height="{h:.2}" fill="{fill}" stroke="{stroke}"/>"#
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_pads_as_the_standard_says() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(escaped("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }
}
