//! The side panel, top bar, status line and error window.

use egui::{ComboBox, RichText, Slider};

use super::OrbApp;
use crate::model::{grid::ValueKind, units::ANGSTROM_PER_BOHR};
use crate::scene::{AtomStyle, SliceMode};

pub enum Action {
    None,
    Open,
    Screenshot,
    ResetView,
}

pub fn top_bar(ui: &mut egui::Ui, app: &OrbApp) -> Action {
    let mut action = Action::None;
    egui::Panel::top("top bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.strong("orbcloud");
            ui.separator();
            if ui.button("Open…").clicked() {
                action = Action::Open;
            }
            if ui.button("Save PNG").clicked() {
                action = Action::Screenshot;
            }
            if ui.button("Reset view").clicked() {
                action = Action::ResetView;
            }
            ui.separator();
            ui.label(RichText::new(&app.doc.source).weak());
        });
    });
    action
}

pub fn status_bar(ui: &mut egui::Ui, app: &OrbApp) {
    egui::Panel::bottom("status").show(ui, |ui| {
        ui.horizontal(|ui| {
            if let Some(job) = &app.job {
                let (f, parsing) = job.progress();
                let text = if parsing { "parsing…".to_string() } else { format!("reading {:.0}%", 100.0 * f) };
                ui.add(egui::ProgressBar::new(f).desired_width(160.0).text(text));
                ui.label(job.path.display().to_string());
                ui.separator();
            }
            let m = &app.doc.molecule;
            ui.label(format!("{} atoms ({}), {} bonds", m.atoms.len(), m.formula(), m.bonds.len()));
            if let Some(g) = app.doc.volumes.get(app.view.volume) {
                ui.separator();
                let h: Vec<String> = (0..3).map(|a| format!("{:.3}", g.step(a).length())).collect();
                ui.label(format!(
                    "grid {}×{}×{}, spacing {} bohr, values {:.3e} … {:.3e}",
                    g.dims[0],
                    g.dims[1],
                    g.dims[2],
                    h.join("/"),
                    g.stats.min,
                    g.stats.max
                ));
            }
            if !app.status.is_empty() {
                ui.separator();
                ui.label(RichText::new(&app.status).weak());
            }
        });
    });
}

pub fn side_panel(ui: &mut egui::Ui, app: &mut OrbApp) {
    egui::Panel::left("controls").default_size(250.0).show(ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            let view = &mut app.view;
            ui.heading("Volume");
            if app.doc.volumes.is_empty() {
                ui.label("no volume in this file");
            } else {
                let label = ui.label("data set");
                ComboBox::from_id_salt("data set")
                    .width(220.0)
                    .selected_text(app.doc.volumes.get(view.volume).map(|v| v.label.as_str()).unwrap_or("?"))
                    .show_ui(ui, |ui| {
                        for (i, v) in app.doc.volumes.iter().enumerate() {
                            ui.selectable_value(&mut view.volume, i, &v.label);
                        }
                    })
                    .response
                    .labelled_by(label.id);
            }
            let vs = &mut view.settings.volume;
            ui.checkbox(&mut vs.visible, "show cloud");
            ui.horizontal(|ui| {
                ui.label("slices");
                ui.selectable_value(&mut vs.mode, SliceMode::ViewAligned, "view-aligned");
                ui.selectable_value(&mut vs.mode, SliceMode::AxisAligned, "axis stacks");
            });
            ui.add(Slider::new(&mut vs.slices, 16..=512).text("slice count"));
            ui.add(Slider::new(&mut vs.k1, 0.0..=1.0).text("k1 (opacity)"));
            ui.add(Slider::new(&mut vs.k2, 0.1..=3.0).text("k2 (shape)"));
            let signed = app.doc.volumes.get(view.volume).is_none_or(|v| v.kind == ValueKind::Signed);
            let (pos, neg) = if signed { ("ψ > 0", "ψ < 0") } else { ("dense", "thin") };
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(&mut vs.positive_color);
                ui.label(pos);
                ui.color_edit_button_rgb(&mut vs.negative_color);
                ui.label(neg);
            });
            ui.label(RichText::new("α = k1·ρ^k2, ρ = ψ² (orbital) or density, scaled to its maximum").small().weak());

            ui.separator();
            ui.heading("Atoms");
            ComboBox::from_label("style")
                .selected_text(match view.settings.atoms {
                    AtomStyle::BallAndStick => "ball and stick",
                    AtomStyle::SpaceFilling => "space filling",
                    AtomStyle::Hidden => "hidden",
                })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut view.settings.atoms, AtomStyle::BallAndStick, "ball and stick");
                    ui.selectable_value(&mut view.settings.atoms, AtomStyle::SpaceFilling, "space filling");
                    ui.selectable_value(&mut view.settings.atoms, AtomStyle::Hidden, "hidden");
                });
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(&mut view.settings.background);
                ui.label("background");
            });

            ui.separator();
            ui.collapsing("Atoms in file", |ui| {
                egui::Grid::new("atoms").striped(true).show(ui, |ui| {
                    for (i, a) in app.doc.molecule.atoms.iter().enumerate().take(500) {
                        let p = a.position * ANGSTROM_PER_BOHR;
                        ui.label(format!("{}", i + 1));
                        ui.label(format!("{}{}", a.element().symbol, if a.ghost { " (ghost)" } else { "" }));
                        ui.label(format!("{:.3} {:.3} {:.3} Å", p.x, p.y, p.z));
                        ui.end_row();
                    }
                });
            });
            ui.separator();
            ui.label(
                RichText::new("drag: rotate · right/middle drag: pan · wheel: zoom · arrows, +/−: keys").small().weak(),
            );
        });
    });
}

pub fn error_window(ui: &mut egui::Ui, app: &mut OrbApp) {
    let Some(message) = app.error.clone() else {
        return;
    };
    let mut open = true;
    egui::Window::new("Could not open").open(&mut open).collapsible(false).show(ui.ctx(), |ui| {
        ui.label(RichText::new(&message).color(ui.visuals().error_fg_color));
        if ui.button("Dismiss").clicked() {
            app.error = None;
        }
    });
    if !open {
        app.error = None;
    }
}
