//! The scene panel: every object with its quantities (each shown or hidden, selected for the
//! side panel, added and removed), its atoms, molecular surface and placement. Everything is
//! edited in the objects' states in place; adding or removing objects waits for the frame's
//! end ([`super::SceneEdit`]).

use egui::{ComboBox, DragValue, RichText};

use super::{OrbApp, SceneEdit};
use crate::model::Document;
use crate::model::orbitals::{Quantity, Spin};
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};
use crate::scene::{
    AtomColoring, AtomStyle, ObjectState, Placement, QuantityState, RenderSettings, Source, SurfaceChoice,
    SurfaceSettings,
};

pub fn section(ui: &mut egui::Ui, app: &mut OrbApp) {
    if app.objects.is_empty() {
        return;
    }
    ui.heading("Scene");
    let active = app.active;
    for (n, object) in app.objects.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            // The remove button first: a long file name never pushes it out of the panel.
            if ui.small_button("×").on_hover_text("remove from the scene").clicked() {
                app.pending.push(SceneEdit::Remove(n));
            }
            ui.checkbox(&mut object.state.visible, "").on_hover_text("show or hide the whole object");
            let name = object.doc.source.rsplit(['/', '\\']).next().unwrap_or("object");
            let label = egui::Button::selectable(n == active, format!("{} {name}", n + 1)).truncate();
            if ui.add(label).on_hover_text(&object.doc.source).clicked() && n != active {
                app.pending.push(SceneEdit::Select(n));
            }
        });
    }
    let defaults = app.defaults;
    let view = &mut app.view;
    super::panes::controls(ui, &mut view.panes, &view.camera);
    let panes = view.panes.count;
    if let Some(object) = app.objects.get_mut(active) {
        let doc = object.doc.clone();
        let state = &mut object.state;
        ui.indent("representations", |ui| {
            quantities(ui, &doc, state, &defaults, panes);
            ui.horizontal(|ui| {
                let s = &mut state.atoms.style;
                let mut shown = *s != AtomStyle::Hidden;
                let checkbox = ui.checkbox(&mut shown, "atoms");
                if checkbox.changed() {
                    *s = if shown { AtomStyle::BallAndStick } else { AtomStyle::Hidden };
                }
                atom_style(ui, s, checkbox.id);
            });
            surface_editor(ui, &mut state.surface);
            if let Some(p) = placement_editor(ui, state.placement) {
                state.placement = p;
            }
        });
    }
    ui.label(RichText::new("opened files join the scene beside it (tick “replace” to swap)").small().weak());
}

/// The object's quantities: each shown or hidden, selected (the side panel edits it),
/// removed; *+ quantity* adds another of the file's.
fn quantities(ui: &mut egui::Ui, doc: &Document, state: &mut ObjectState, defaults: &RenderSettings, panes: usize) {
    let mut remove = None;
    for (k, q) in state.quantities.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            if ui.small_button("×").on_hover_text("remove this quantity").clicked() {
                remove = Some(k);
            }
            ui.checkbox(&mut q.visible, "").on_hover_text("show or hide its cloud and isosurfaces");
            super::panes::choice(ui, q, panes);
            let what = representations(q);
            let text = format!("{} · {what}", q.source.name(doc));
            if ui.add(egui::Button::selectable(k == state.selected, text).truncate()).clicked() {
                state.selected = k;
            }
        });
    }
    if let Some(k) = remove {
        state.quantities.remove(k);
        state.selected = state.selected.min(state.quantities.len().saturating_sub(1));
    }
    let choices = quantity_choices(doc);
    if choices.is_empty() {
        return;
    }
    let added = ComboBox::from_id_salt("add quantity").selected_text("+ quantity").show_ui(ui, |ui| {
        for (source, name) in choices {
            if ui.selectable_label(false, name).clicked() {
                let joining = QuantityState::joining(source, defaults, &state.quantities);
                state.quantities.push(joining);
                state.selected = state.quantities.len() - 1;
            }
        }
    });
    added.response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "add a quantity"));
}

/// What a quantity draws, in words: "cloud", "cloud + 2 isosurfaces", "hidden".
fn representations(q: &QuantityState) -> String {
    let surfaces = q.isosurfaces.iter().filter(|i| i.visible).count();
    let parts: Vec<String> = [
        q.cloud.visible.then(|| "cloud".to_string()),
        (surfaces > 0).then(|| format!("{surfaces} isosurface{}", if surfaces > 1 { "s" } else { "" })),
    ]
    .into_iter()
    .flatten()
    .collect();
    if parts.is_empty() || !q.visible { "hidden".into() } else { parts.join(" + ") }
}

/// What a file offers to add as a quantity: its data sets, or its wavefunction's frontier
/// orbitals and densities.
pub fn quantity_choices(doc: &Document) -> Vec<(Source, String)> {
    let mut choices: Vec<(Source, String)> =
        (0..doc.volumes.len()).map(|i| (Source::Volume(i), Source::Volume(i).name(doc))).collect();
    // A scan's views, each again (a second representation of one orbital in another pane).
    if let Some(scan) = &doc.scan {
        choices.extend((0..scan.orbitals.len()).map(|slot| (Source::Scan(slot), scan.slot_name(slot))));
    }
    if let Some(wf) = &doc.wavefunction {
        let spins: &[Spin] = if wf.restricted { &[Spin::Alpha] } else { &[Spin::Alpha, Spin::Beta] };
        for &spin in spins {
            // HOMO−1, HOMO, LUMO, LUMO+1 of each spin.
            let order = wf.by_energy(spin);
            let at = |i: Option<usize>| i.and_then(|i| order.iter().position(|&k| k == i));
            let (homo, lumo) = (at(wf.homo(spin)), at(wf.lumo(spin)));
            for p in [homo.and_then(|p| p.checked_sub(1)), homo, lumo, lumo.map(|p| p + 1)].into_iter().flatten() {
                if let Some(&i) = order.get(p) {
                    let source = Source::Wavefunction(Quantity::Orbital(i));
                    choices.push((source, source.name(doc)));
                }
            }
        }
        choices.push((Source::Wavefunction(Quantity::Density), "total density".into()));
        if !wf.restricted {
            choices.push((Source::Wavefunction(Quantity::SpinDensity), "spin density".into()));
        }
        choices.push((Source::Wavefunction(Quantity::Potential), "electrostatic potential".into()));
        // From the density's second derivatives: shell structure, and the NCI quantities.
        for q in [Quantity::DensityLaplacian, Quantity::ReducedGradient, Quantity::SignLambda2Rho] {
            let source = Source::Wavefunction(q);
            choices.push((source, source.name(doc)));
        }
    }
    choices
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
            .on_hover_text("Gaussian: the atoms' blended density (VMD's QuickSurf); solvent-excluded: where a probe sphere rolled over the atoms cannot reach");
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
                    .on_hover_text("level of detail: parts smaller than this on screen are drawn as points (0: every triangle); larger while you drag, to keep the view moving");
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
