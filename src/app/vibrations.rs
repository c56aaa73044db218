//! The normal modes of the active object's file: the list (frequency, IR intensity, imaginary
//! ones marked), the mode animated with its amplitude, speed and arrows, and the IR spectrum,
//! wavenumbers descending as chemists plot them, where a click on a band picks its mode.

use egui::{RichText, ScrollArea, Slider};
use egui_plot::{Line, Plot, PlotPoint, PlotTransform, VLine};

use crate::model::Document;
use crate::model::vibrations::Vibrations;
use crate::scene::vibration::VibrationState;

/// The panel's height, points.
const HEIGHT: f32 = 260.0;

/// Shows the panel when `doc` has modes, editing `v` in place; `spectrum` keeps where the
/// spectrum was drawn (for tests to click its bands).
pub fn panel(ui: &mut egui::Ui, doc: &Document, v: &mut VibrationState, spectrum: &mut Option<PlotTransform>) {
    let Some(modes) = &doc.vibrations else {
        *spectrum = None;
        return;
    };
    egui::Panel::bottom("vibrations").exact_size(HEIGHT).show(ui, |ui| {
        ui.columns(2, |columns| {
            controls(&mut columns[0], modes, v);
            *spectrum = Some(ir_spectrum(&mut columns[1], modes, v));
        });
    });
}

fn controls(ui: &mut egui::Ui, modes: &Vibrations, v: &mut VibrationState) {
    ui.heading("Vibrations");
    let imaginary = modes.modes.iter().filter(|m| m.is_imaginary()).count();
    let what = match imaginary {
        0 => "a minimum".to_string(),
        1 => "1 imaginary: a transition state".to_string(),
        n => format!("{n} imaginary"),
    };
    ui.label(
        RichText::new(format!("{} modes, {what}; geometry from {}", modes.modes.len(), modes.geometry_from))
            .small()
            .weak(),
    );
    ui.horizontal(|ui| {
        if ui.selectable_label(v.mode.is_none(), "none").on_hover_text("the atoms at the file's geometry").clicked() {
            v.mode = None;
        }
        let label = if v.playing { "pause" } else { "play" };
        if ui.button(label).clicked() {
            v.playing = !v.playing;
        }
        ui.checkbox(&mut v.arrows, "arrows");
    });
    ui.horizontal_wrapped(|ui| {
        ui.spacing_mut().slider_width = 70.0;
        ui.add(Slider::new(&mut v.amplitude, 0.05..=1.5).text("bohr"))
            .on_hover_text("the largest atom's displacement at the turning points");
        ui.add(Slider::new(&mut v.speed, 0.1..=3.0).text("/s")).on_hover_text("oscillations per second");
    });
    // The mode shown, named: what plays in the view.
    if let Some((k, m)) = v.mode.and_then(|k| modes.modes.get(k).map(|m| (k, m))) {
        let intensity = m.ir_intensity.map_or(String::new(), |i| format!(", {i:.1} km/mol"));
        let name = match m.is_imaginary() {
            true => format!("mode {}: {:.1}i cm-1{intensity} (imaginary: along the reaction)", k + 1, -m.frequency_cm1),
            false => format!("mode {}: {:.1} cm-1{intensity}", k + 1, m.frequency_cm1),
        };
        ui.label(RichText::new(name).strong());
    }
    ui.label(RichText::new(format!("{:>4} {:>11} {:>9}", "mode", "cm-1", "km/mol")).monospace().strong());
    // The list scrolls to the mode shown whenever it changes (a click on the spectrum picks
    // one the list may not show).
    let scrolled_id = ui.scope_id().with("modes scrolled to");
    let scrolled_to = ui.data(|d| d.get_temp::<Option<usize>>(scrolled_id)).flatten();
    ScrollArea::vertical().id_salt("modes").show(ui, |ui| {
        for (k, m) in modes.modes.iter().enumerate() {
            let frequency = match m.is_imaginary() {
                true => format!("{:.2}i", -m.frequency_cm1),
                false => format!("{:.2}", m.frequency_cm1),
            };
            let intensity = m.ir_intensity.map_or("—".to_string(), |i| format!("{i:.1}"));
            let mut row = RichText::new(format!("{:>4} {:>11} {:>9}", k + 1, frequency, intensity)).monospace();
            if m.is_imaginary() {
                row = row.color(ui.visuals().warn_fg_color);
            }
            let button =
                egui::Button::selectable(v.mode == Some(k), row).min_size(egui::vec2(ui.available_width(), 0.0));
            let response = ui.add(button);
            if response.clicked() {
                v.mode = Some(k);
            }
            if v.mode == Some(k) && scrolled_to != Some(k) {
                response.scroll_to_me(Some(egui::Align::Center));
            }
        }
    });
    ui.data_mut(|d| d.insert_temp(scrolled_id, v.mode));
}

/// The IR spectrum with its bands broadened as `v` says and a stick per mode; a click picks the
/// mode of the band under it. Returns where it was drawn.
fn ir_spectrum(ui: &mut egui::Ui, modes: &Vibrations, v: &mut VibrationState) -> PlotTransform {
    ui.horizontal(|ui| {
        ui.spacing_mut().slider_width = 70.0;
        ui.add(Slider::new(&mut v.fwhm, 2.0..=100.0).text("FWHM"))
            .on_hover_text("the bands' full width at half maximum, cm-1");
        ui.selectable_value(&mut v.lorentzian, true, "Lorentz");
        ui.selectable_value(&mut v.lorentzian, false, "Gauss");
    });
    let top = modes.modes.iter().map(|m| m.frequency_cm1).fold(1000.0, f64::max) + 200.0;
    // Wavenumbers fall from left to right, as spectra are drawn: the plot's x is the negated
    // wavenumber, labelled as the wavenumber (egui_plot's own inverted axis labels only its 0).
    let curve: Vec<[f64; 2]> =
        modes.ir_spectrum((0.0, top), 1200, v.fwhm as f64, v.lorentzian).into_iter().map(|[x, y]| [-x, y]).collect();
    let peak = curve.iter().map(|p| p[1]).fold(1.0, f64::max);
    // Labels at every 1000 cm-1 however narrow the panel: egui_plot's default spacing hides
    // labels closer than 60 points, which left this axis with its 0 alone.
    let axis = egui_plot::AxisHints::new_x()
        .label("wavenumber (cm-1)")
        .formatter(|mark, _| format!("{:.0}", (-mark.value).abs()))
        .label_spacing(32.0..=48.0);
    // The intensity axis labelled at a few heights, not its 0 alone.
    let intensity = egui_plot::AxisHints::new_y().label("IR (km/mol)").label_spacing(14.0..=24.0).min_thickness(28.0);
    let response = Plot::new("ir spectrum")
        .custom_x_axes(vec![axis])
        .custom_y_axes(vec![intensity])
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .include_x(0.0)
        .include_x(-top)
        .include_y(0.0)
        .include_y(peak * 1.1)
        .show(ui, |plot| {
            plot.line(Line::new("spectrum", curve));
            for m in modes.modes.iter().filter(|m| !m.is_imaginary()) {
                let i = m.ir_intensity.unwrap_or(0.0);
                plot.line(Line::new("", vec![[-m.frequency_cm1, 0.0], [-m.frequency_cm1, i]]).width(1.0));
            }
            if let Some(m) = v.mode.and_then(|k| modes.modes.get(k)).filter(|m| !m.is_imaginary()) {
                plot.vline(VLine::new("shown", -m.frequency_cm1));
            }
            let clicked = plot.response().clicked();
            clicked.then(|| plot.pointer_coordinate()).flatten()
        });
    if let Some(PlotPoint { x, .. }) = response.inner
        && let Some(k) = modes.band_at(-x, v.fwhm as f64, v.lorentzian, (v.fwhm as f64).max(top / 100.0))
    {
        v.mode = Some(k);
    }
    response.transform
}
