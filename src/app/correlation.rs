//! The scan's correlation diagram under its views: HOMO−k … LUMO+k against the coordinate, each
//! line one orbital followed by its character ([`crate::model::correlation`]), occupied ones
//! solid and empty ones dashed, crossings marked, each line named at its right end (no legend
//! to cover the curves). Dragging on the plot scrubs the coordinate; a click on a line shows
//! that orbital in the first view.

use egui::{Color32, RichText};
use egui_plot::{Line, LineStyle, MarkerShape, Plot, PlotPoint, Points, Text, VLine};

use crate::model::correlation::{Diagram, correlation};
use crate::model::scan::Scan;
use crate::model::units::EV_PER_HARTREE;

/// How many orbitals below the HOMO and above the LUMO the diagram shows, and the diagram
/// made for that many (made again when it changes).
pub struct DiagramView {
    pub window: usize,
    made: Option<(usize, Option<Diagram>)>,
}

impl Default for DiagramView {
    fn default() -> Self {
        Self { window: 2, made: None }
    }
}

impl DiagramView {
    /// The diagram for the current window (None for cube series or files without energies).
    pub fn diagram(&mut self, scan: &Scan) -> Option<&Diagram> {
        if self.made.as_ref().is_none_or(|(w, _)| *w != self.window) {
            self.made = Some((self.window, correlation(scan, self.window, self.window)));
        }
        self.made.as_ref().and_then(|(_, d)| d.as_ref())
    }
}

/// A line's name as a scan manifest names orbitals: "HOMO−1" → "homo-1".
fn manifest_name(label: &str) -> Option<String> {
    let name = label.replace('−', "-").to_lowercase();
    (!name.contains('β') && !name.contains(' ')).then_some(name)
}

/// The energy of `line` at `x` (eV), linearly between its frames.
fn energy_at(points: &[(f64, f64, usize)], x: f64) -> Option<f64> {
    let w = points.windows(2).find(|w| (w[0].0..=w[1].0).contains(&x))?;
    let k = (x - w[0].0) / (w[1].0 - w[0].0).max(1e-12);
    Some((w[0].1 + k * (w[1].1 - w[0].1)) * EV_PER_HARTREE)
}

/// What a drag or click on the diagram asks of its scan.
#[derive(Default)]
pub struct Asked {
    /// The orbital (as manifests name it) whose line was clicked.
    pub orbital: Option<String>,
    /// The coordinate's value dragged to, or clicked away from every line (within the scan).
    pub value: Option<f64>,
}

/// Draws `view`'s diagram of `scan`, the coordinate at `value` marked.
pub fn plot(ui: &mut egui::Ui, view: &mut DiagramView, scan: &Scan, value: f64) -> Asked {
    let shown = &scan.orbitals;
    let c = scan.coordinate;
    let x_label = match c.unit().trim() {
        "" => c.label(),
        u => format!("{} ({u})", c.label()),
    };
    let (lo, hi) = scan.range();
    // Borrowed, not copied: the diagram is drawn every frame.
    let Some(diagram) = view.diagram(scan) else {
        ui.label(RichText::new("no orbital energies in these files").weak());
        return Asked::default();
    };
    let mut clicked = None;
    let mut scrub = None;
    let ev = |e: f64| e * EV_PER_HARTREE;
    let extents: Vec<(f64, f64)> = (diagram.lines.iter())
        .map(|l| l.points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(ev(p.1)), b.max(ev(p.1)))))
        .collect();
    let (y_lo, y_hi) = y_range(&extents);
    let pad = 0.06 * (y_hi - y_lo).max(1e-3);
    // Each line's name at its right end, moved apart where lines meet (degenerate orbitals),
    // within the plot; a line above it is named at its top edge.
    let ends: Vec<f64> = diagram.lines.iter().map(|l| l.points.last().map_or(0.0, |p| ev(p.1)).min(y_hi)).collect();
    let labels = spread_labels(&ends, 0.07 * (y_hi - y_lo + 2.0 * pad));
    // The plot keeps its first bounds: a scan whose range grows (frames still being computed)
    // or another scan is a new plot.
    Plot::new(("correlation diagram", lo.to_bits(), hi.to_bits()))
        .x_axis_label(x_label)
        .y_axis_label("orbital energy (eV)")
        .allow_scroll(false)
        .allow_drag(false)
        .allow_zoom(false)
        // The data's span only, with room after the last frame for the lines' names.
        .default_x_bounds(lo, hi + 0.18 * (hi - lo).max(1e-9))
        .default_y_bounds(y_lo - pad, y_hi + pad)
        .show(ui, |plot| {
            for line in &diagram.lines {
                let points: Vec<[f64; 2]> = line.points.iter().map(|&(x, e, _)| [x, e * EV_PER_HARTREE]).collect();
                let in_view = manifest_name(&line.label).is_some_and(|n| shown.contains(&n));
                let style = if line.occupied { LineStyle::Solid } else { LineStyle::dashed_loose() };
                let color =
                    if line.occupied { Color32::from_rgb(90, 150, 255) } else { Color32::from_rgb(255, 120, 90) };
                plot.line(Line::new(line.label.clone(), points.clone()).style(style).color(color).width(if in_view {
                    3.0
                } else {
                    1.5
                }));
                let crossings: Vec<[f64; 2]> = line.crossings.iter().map(|&f| points[f]).collect();
                if !crossings.is_empty() {
                    plot.points(
                        Points::new(format!("{} crossings", line.label), crossings)
                            .shape(MarkerShape::Diamond)
                            .radius(4.0)
                            .color(Color32::from_rgb(250, 210, 80)),
                    );
                }
            }
            for (k, line) in diagram.lines.iter().enumerate() {
                let color =
                    if line.occupied { Color32::from_rgb(90, 150, 255) } else { Color32::from_rgb(255, 120, 90) };
                let above = extents[k].0 > y_hi;
                let name = if above { format!(" {} ↑", line.label) } else { format!(" {}", line.label) };
                plot.text(
                    Text::new(line.label.clone(), PlotPoint::new(hi, labels[k]), name)
                        .anchor(egui::Align2::LEFT_CENTER)
                        .color(color),
                );
            }
            plot.vline(VLine::new(c.kind(), value));
            let response = plot.response();
            let pointer = plot.pointer_coordinate();
            if let Some(p) = pointer.filter(|_| response.dragged()) {
                scrub = Some(p.x);
            }
            if let Some(p) = pointer.filter(|_| response.clicked()) {
                // The line nearest the click at its x, within half an eV.
                let nearest = (diagram.lines.iter())
                    .filter_map(|l| Some((energy_at(&l.points, p.x)? - p.y).abs()).map(|d| (d, l)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                match nearest {
                    Some((d, l)) if d < 0.5 => clicked = manifest_name(&l.label),
                    _ => scrub = Some(p.x),
                }
            }
        });
    Asked { orbital: clicked, value: scrub.map(|x| x.clamp(lo, hi)) }
}

/// The energies a diagram shows (eV), from each line's lowest and highest: all of them, but
/// for a line wholly far above the rest (more than the rest span above the next one), which would
/// squeeze the others into a band of the plot: it runs off the top, named there.
fn y_range(extents: &[(f64, f64)]) -> (f64, f64) {
    let lo = extents.iter().map(|e| e.0).fold(f64::MAX, f64::min);
    let mut by_top = extents.to_vec();
    by_top.sort_by(|a, b| a.1.total_cmp(&b.1));
    let hi = match by_top[..] {
        // The highest line lies wholly above the next by more than the rest span.
        [.., (_, second), (bottom, _)] if extents.len() >= 3 && bottom - second > second - lo => second,
        [.., (_, top)] => top,
        [] => return (0.0, 1.0),
    };
    if hi > lo { (lo, hi) } else { (lo - 0.5, lo + 0.5) }
}

/// Heights for labels wanted at `ys`, each at least `gap` from the next (in the same order as
/// `ys`): labels of lines that end together are stacked around where they end.
fn spread_labels(ys: &[f64], gap: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..ys.len()).collect();
    order.sort_by(|&a, &b| ys[a].total_cmp(&ys[b]));
    let mut placed = ys.to_vec();
    for w in 1..order.len() {
        let (below, here) = (order[w - 1], order[w]);
        placed[here] = placed[here].max(placed[below] + gap);
    }
    // Centred on the group's own heights: the stack does not only grow upwards.
    let shift = (ys.iter().sum::<f64>() - placed.iter().sum::<f64>()) / ys.len().max(1) as f64;
    placed.iter().map(|p| p + shift.min(0.0)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_lines_get_labels_apart_and_an_outlier_does_not_squeeze_the_plot() {
        let placed = spread_labels(&[-5.0, -5.0, -3.0], 0.5);
        assert!((placed[1] - placed[0]).abs() >= 0.5 - 1e-9, "{placed:?}");
        assert!(placed[2] - placed[0].max(placed[1]) >= 0.5 - 1e-9);
        assert!(placed.iter().all(|p| (p - -4.3).abs() < 1.5), "near where the lines end: {placed:?}");
        // Three lines within 2 eV and one 20 eV above: the plot spans the three.
        let (lo, hi) = y_range(&[(-6.0, -5.0), (-5.5, -4.5), (-4.2, -4.0), (14.0, 16.0)]);
        assert_eq!((lo, hi), (-6.0, -4.0));
        assert_eq!(y_range(&[(-6.0, -5.0), (-5.5, -4.5), (-4.2, -1.0)]), (-6.0, -1.0), "no outlier: all");
    }
}
