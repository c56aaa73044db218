//! The colour bar over the view when a surface is coloured by a volume's values: the map's
//! colours from −range to +range with the values at its ends and middle, as `render` draws it
//! into images.

use egui::{Color32, Pos2, Rect, vec2};

use crate::scene::coloring::ValueMap;

/// How much of the view's width (points, from its right edge) the bar and its labels take:
/// what a map framed beside it leaves free.
pub const BAR_ROOM: f32 = 130.0;

/// Draws `map`'s bar at the right edge of `rect`, titled with the quantity `name`.
pub fn value_bar(ui: &mut egui::Ui, rect: Rect, map: &ValueMap, name: &str) {
    let painter = ui.painter_at(rect);
    let (bar_w, bar_h) = (14.0, (rect.height() * 0.5).clamp(80.0, 320.0));
    let top = Pos2::new(rect.right() - 24.0 - bar_w, rect.center().y - bar_h * 0.5);
    let panel = Rect::from_min_max(top - vec2(80.0, 28.0), top + vec2(bar_w + 12.0, bar_h + 12.0));
    painter.rect_filled(panel, 4.0, Color32::from_black_alpha(150));
    let steps = 64;
    for i in 0..steps {
        let t = 1.0 - 2.0 * (i as f32 + 0.5) / steps as f32;
        let [r, g, b] = map.at(t).map(crate::pictures::figure::encoded);
        let y = top.y + bar_h * i as f32 / steps as f32;
        let cell = Rect::from_min_size(Pos2::new(top.x, y), vec2(bar_w, bar_h / steps as f32 + 0.5));
        painter.rect_filled(cell, 0.0, Color32::from_rgb(r, g, b));
    }
    let font = egui::FontId::proportional(12.0);
    let color = Color32::from_gray(235);
    let [lo, mid, hi] = map.ticks();
    for (y, label) in [(top.y, hi), (top.y + bar_h * 0.5, mid), (top.y + bar_h, lo)] {
        painter.text(Pos2::new(top.x - 6.0, y), egui::Align2::RIGHT_CENTER, label, font.clone(), color);
    }
    let title = ValueMap::title(name);
    painter.text(Pos2::new(top.x + bar_w, top.y - 8.0), egui::Align2::RIGHT_BOTTOM, title, font, color);
}
