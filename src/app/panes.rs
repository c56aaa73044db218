//! A view split into panes side by side (HOMO beside LUMO): what each pane is labelled with,
//! and the controls that split the view and link the panes' cameras.

use egui::RichText;

use super::SceneObject;
use crate::scene::objects::MAX_PANES;
use crate::scene::{Camera, Panes, QuantityState};

/// What pane `pane` of `count` shows, in words: each quantity drawn there with its energy
/// ("HOMO  E = -0.24666 Eh (-6.712 eV)"), objects named when the scene has several.
pub fn label(objects: &[SceneObject], pane: usize, count: usize) -> String {
    let several = objects.len() > 1;
    let lines: Vec<String> = objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.state.visible)
        .flat_map(|(n, o)| {
            o.state.quantities.iter().filter(move |q| q.visible && q.in_pane(pane, count)).map(move |q| {
                let what = describe(o, q);
                if several { format!("{} · {what}", n + 1) } else { what }
            })
        })
        .collect();
    if lines.is_empty() { "atoms".into() } else { lines.join("\n") }
}

/// A quantity's name, with an orbital's energy and occupation (a scan's view: its energy and
/// the coordinate at the value).
fn describe(o: &SceneObject, q: &QuantityState) -> String {
    if let (crate::scene::Source::Scan(slot), Some(scan), Some(state)) = (q.source, &o.scan, &o.state.scan) {
        return super::scan::view_label(scan, slot, state.value);
    }
    let name = q.source.name(&o.doc);
    match (q.source.orbital(), &o.doc.wavefunction) {
        // A natural transition orbital: its pair's weight, no energy.
        (Some(i), Some(wf)) if crate::model::nto::is_nto_label(&wf.orbitals[i].symmetry) => {
            format!("{name}  weight {:.3} · {}", wf.orbitals[i].occupation, o.doc.title)
        }
        (Some(i), Some(wf)) => {
            format!("{name}  {}, occ {:.2}", wf.energy_text(i), wf.orbitals[i].occupation)
        }
        _ => name,
    }
}

/// How many panes, and whether they share the camera.
pub fn controls(ui: &mut egui::Ui, panes: &mut Panes, camera: &Camera) {
    ui.horizontal(|ui| {
        ui.label("panes");
        for n in 1..=MAX_PANES {
            if ui.selectable_label(panes.count == n, n.to_string()).clicked() {
                while panes.count < n {
                    panes.add(*camera);
                }
                panes.count = n;
            }
        }
        if panes.count > 1 {
            ui.checkbox(&mut panes.linked, "one camera").on_hover_text("turn and zoom every pane together");
        }
    });
    if panes.count > 1 {
        ui.label(RichText::new("each quantity is drawn in the pane chosen beside it").small().weak());
    }
}

/// Which pane a quantity is drawn in: every pane, or one.
pub fn choice(ui: &mut egui::Ui, q: &mut QuantityState, count: usize) {
    if count < 2 {
        return;
    }
    let text = |p: Option<usize>| p.map_or("all panes".to_string(), |p| format!("pane {}", p + 1));
    egui::ComboBox::from_id_salt(ui.next_auto_id())
        .width(70.0)
        .selected_text(text(q.pane.map(|p| p.min(count - 1))))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut q.pane, None, text(None));
            for p in 0..count {
                ui.selectable_value(&mut q.pane, Some(p), text(Some(p)));
            }
        });
}
