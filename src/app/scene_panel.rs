//! The scene panel: every object with its representations (atoms, cloud, isosurfaces), shown
//! or hidden, added and removed, and its placement. The active object's atoms, cloud and first
//! isosurface are the side panel's working copy (`app.view.settings`); its further isosurfaces
//! and every placement are edited here directly.

use egui::{ComboBox, DragValue, RichText, Slider};

use super::OrbApp;
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};
use crate::scene::{AtomColoring, AtomStyle, IsoLevel, IsosurfaceSettings, Placement, SurfaceChoice, SurfaceSettings};

/// What the user asked for in the panel this frame, applied after it is drawn.
enum Edit {
    Select(usize),
    Remove(usize),
    Visible(usize, bool),
    Place(usize, Placement),
    Isosurfaces,
}

pub fn section(ui: &mut egui::Ui, app: &mut OrbApp) {
    if app.scan.is_some() || app.objects.is_empty() {
        return;
    }
    ui.heading("Scene");
    let mut edits = Vec::new();
    for (n, object) in app.objects.iter().enumerate() {
        ui.horizontal(|ui| {
            let mut visible = object.state.visible;
            if ui.checkbox(&mut visible, "").on_hover_text("show or hide the whole object").changed() {
                edits.push(Edit::Visible(n, visible));
            }
            let name = object.doc.source.rsplit(['/', '\\']).next().unwrap_or("object");
            if ui.selectable_label(n == app.active, format!("{} {name}", n + 1)).clicked() && n != app.active {
                edits.push(Edit::Select(n));
            }
            if ui.small_button("×").on_hover_text("remove from the scene").clicked() {
                edits.push(Edit::Remove(n));
            }
        });
    }
    let n = app.active;
    if let Some(object) = app.objects.get_mut(n) {
        ui.indent("representations", |ui| {
            let s = &mut app.view.settings;
            ui.horizontal(|ui| {
                let mut shown = s.atoms != AtomStyle::Hidden;
                let checkbox = ui.checkbox(&mut shown, "atoms");
                if checkbox.changed() {
                    s.atoms = if shown { AtomStyle::BallAndStick } else { AtomStyle::Hidden };
                }
                atom_style(ui, &mut s.atoms, checkbox.id);
            });
            ui.checkbox(&mut s.volume.visible, "cloud");
            ui.checkbox(&mut s.iso.visible, format!("isosurface {}", level_text(s.iso.level)));
            let mut remove = None;
            let mut changed = false;
            for (k, iso) in object.state.isosurfaces.iter_mut().enumerate() {
                ui.horizontal(|ui| {
                    changed |= ui.checkbox(&mut iso.visible, "").changed();
                    changed |= level_slider(ui, &mut iso.level);
                    changed |= ui.color_edit_button_rgb(&mut iso.positive_color).changed();
                    changed |= ui.color_edit_button_rgb(&mut iso.negative_color).changed();
                    changed |= super::panels::translucency_editor(ui, iso);
                    if ui.small_button("×").on_hover_text("remove this isosurface").clicked() {
                        remove = Some(k);
                    }
                });
            }
            if let Some(k) = remove {
                object.state.isosurfaces.remove(k);
                changed = true;
            }
            if ui.button("+ isosurface").on_hover_text("another value of the same volume (nested shells)").clicked() {
                object.state.isosurfaces.push(another_isosurface(s.iso, &object.state.isosurfaces));
                changed = true;
            }
            changed |= surface_editor(ui, &mut object.state.surface);
            if changed {
                edits.push(Edit::Isosurfaces);
            }
            if let Some(p) = placement_editor(ui, object.state.placement) {
                edits.push(Edit::Place(n, p));
            }
        });
    }
    ui.label(RichText::new("opened files join the scene beside it (tick “replace” to swap)").small().weak());
    for edit in edits {
        match edit {
            Edit::Select(k) => app.select(k),
            Edit::Remove(k) => app.remove_object(k),
            Edit::Visible(k, v) => app.set_visible(k, v),
            Edit::Place(k, p) => app.place(k, p),
            Edit::Isosurfaces => app.refresh_isosurfaces(n),
        }
    }
}

/// The molecular surface: which kind, its grid spacing and probe or smoothness, its colour
/// and translucency. Whether anything changed.
fn surface_editor(ui: &mut egui::Ui, s: &mut SurfaceSettings) -> bool {
    let before = *s;
    ui.horizontal(|ui| {
        let label = ui.label("surface");
        ComboBox::from_id_salt("scene molecular surface")
            .selected_text(s.choice.name())
            .show_ui(ui, |ui| {
                for c in SurfaceChoice::ALL {
                    ui.selectable_value(&mut s.choice, c, c.name());
                }
            })
            .response
            .labelled_by(label.id)
            .on_hover_text("Gaussian: the atoms' blended density (VMD's QuickSurf); solvent-excluded: where a probe cannot reach (Connolly's)");
        if s.choice != SurfaceChoice::Off && s.color_by.is_none() && !s.color_by_volume {
            ui.color_edit_button_rgb(&mut s.color);
        }
    });
    if s.choice != SurfaceChoice::Off {
        ui.horizontal(|ui| {
            let label = ui.label("colour by");
            let shown =
                if s.color_by_volume { "the volume" } else { s.color_by.map_or("one colour", AtomColoring::name) };
            ComboBox::from_id_salt("scene surface colouring")
                .selected_text(shown)
                .show_ui(ui, |ui| {
                    let mut choice = (s.color_by_volume, s.color_by);
                    ui.selectable_value(&mut choice, (false, None), "one colour");
                    for c in AtomColoring::ALL {
                        ui.selectable_value(&mut choice, (false, Some(c)), c.name());
                    }
                    ui.selectable_value(&mut choice, (true, None), "the volume")
                        .on_hover_text("the values of the cube, orbital or density shown: negative red, positive blue");
                    (s.color_by_volume, s.color_by) = choice;
                })
                .response
                .labelled_by(label.id)
                .on_hover_text("the nearest atom's colour");
        });
    }
    if s.choice != SurfaceChoice::Off {
        ui.horizontal(|ui| {
            let mut auto = s.resolution.is_none();
            if ui.checkbox(&mut auto, "auto grid").on_hover_text("0.25 Å, coarser for big molecules").changed() {
                s.resolution = if auto { None } else { Some(0.5) };
            }
            if let Some(r) = &mut s.resolution {
                ui.add(DragValue::new(r).speed(0.01).range(0.1..=3.0).suffix(" Å").max_decimals(2));
            }
        });
        if !s.translucent {
            ui.horizontal(|ui| {
                ui.add(DragValue::new(&mut s.lod_px).speed(0.1).range(0.0..=30.0).prefix("points under ").suffix(" px"))
                    .on_hover_text("seed 002's level of detail: parts smaller than this on screen are drawn as points (0: every triangle); larger while you drag, to keep the view moving");
            });
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut s.translucent, "translucent");
            match s.choice {
                SurfaceChoice::SolventExcluded => {
                    ui.add(DragValue::new(&mut s.probe).speed(0.02).range(0.0..=3.0).prefix("probe ").suffix(" Å"));
                }
                _ => {
                    ui.add(DragValue::new(&mut s.smoothness).speed(0.05).range(0.3..=5.0).prefix("α "));
                }
            }
        });
    }
    *s != before
}

fn atom_style(ui: &mut egui::Ui, style: &mut AtomStyle, label: egui::Id) {
    ComboBox::from_id_salt("scene atom style")
        .selected_text(style.name())
        .show_ui(ui, |ui| {
            for s in AtomStyle::ALL {
                ui.selectable_value(style, s, s.name());
            }
        })
        .response
        .labelled_by(label);
}

fn level_text(level: IsoLevel) -> String {
    match level {
        IsoLevel::Absolute(v) => format!("{v:.3} a.u."),
        IsoLevel::Sigma(s) => format!("{s:.2} σ"),
    }
}

fn level_slider(ui: &mut egui::Ui, level: &mut IsoLevel) -> bool {
    match level {
        IsoLevel::Absolute(v) => ui.add(Slider::new(v, 1e-4..=0.5).logarithmic(true).text("a.u.")).changed(),
        IsoLevel::Sigma(s) => ui.add(Slider::new(s, 0.1..=20.0).logarithmic(true).text("σ")).changed(),
    }
}

/// A new isosurface at half the value of the last one (the next shell out), shown.
fn another_isosurface(first: IsosurfaceSettings, more: &[IsosurfaceSettings]) -> IsosurfaceSettings {
    let last = more.last().copied().unwrap_or(first);
    let level = match last.level {
        IsoLevel::Absolute(v) => IsoLevel::Absolute(v * 0.5),
        IsoLevel::Sigma(s) => IsoLevel::Sigma(s * 0.5),
    };
    IsosurfaceSettings { visible: true, level, ..last }
}

/// Offset (Å) and rotation (degrees) of an object; the new placement when it was edited.
fn placement_editor(ui: &mut egui::Ui, mut p: Placement) -> Option<Placement> {
    let before = p;
    ui.collapsing("placement", |ui| {
        ui.horizontal(|ui| {
            ui.label("move Å");
            for (c, axis) in p.offset.iter_mut().zip(["x ", "y ", "z "]) {
                let mut a = *c * ANGSTROM_PER_BOHR as f32;
                if ui.add(DragValue::new(&mut a).speed(0.05).prefix(axis).max_decimals(2)).changed() {
                    *c = a * BOHR_PER_ANGSTROM as f32;
                }
            }
        });
        ui.horizontal(|ui| {
            ui.label("turn °");
            for (c, axis) in p.rotation_deg.iter_mut().zip(["x ", "y ", "z "]) {
                ui.add(DragValue::new(c).speed(1.0).range(-180.0..=180.0).prefix(axis).max_decimals(1));
            }
        });
        if ui.button("back to where it was read").clicked() {
            p = Placement::default();
        }
    });
    (p != before).then_some(p)
}
