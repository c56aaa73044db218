//! The orbital browser (seed 004's orbital UI): every orbital with its spin, symmetry, energy
//! and occupation, HOMO/LUMO labels, the density, and the atomic-orbital selector.

use egui::{RichText, ScrollArea};

use super::state::OrbitalView;
use crate::model::orbitals::Quantity;
use crate::model::orbitals::{Spin, Wavefunction};
use crate::model::units::EV_PER_HARTREE;
use crate::model::{Document, basis::ShellKind};

/// Residual of CᵀSC − I above which the orbitals are flagged as not orthonormal.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-5;

const SHELL_LETTERS: [&str; 6] = ["s", "p", "d", "f", "g", "h"];

/// `scroll_to_frontier` brings the HOMO's row into view once (after a file opens).
pub fn panel(ui: &mut egui::Ui, doc: &Document, view: &mut OrbitalView, scroll_to_frontier: &mut bool) {
    let Some(wf) = &doc.wavefunction else { return };
    egui::Panel::right("orbitals").exact_size(360.0).show(ui, |ui| {
        ui.heading("Orbitals");
        let n = &wf.normalization;
        ui.label(
            RichText::new(format!(
                "{} basis functions, {} orbitals · written by {} · repair: {} · |C^T S C - I| {:.1e}",
                wf.basis.n_functions(),
                wf.orbitals.len(),
                n.program,
                n.repair,
                n.residual
            ))
            .small()
            .weak(),
        );
        if n.residual > ORTHONORMAL_TOLERANCE {
            ui.label(
                RichText::new("⚠ these orbitals are not orthonormal in this basis: the file may be wrong")
                    .color(ui.visuals().warn_fg_color),
            );
        }
        ui.horizontal(|ui| {
            if !wf.restricted {
                ui.selectable_value(&mut view.spin, Spin::Alpha, "α");
                ui.selectable_value(&mut view.spin, Spin::Beta, "β");
                ui.separator();
            }
            ui.selectable_value(&mut view.shown, Quantity::Density, "total density");
            if !wf.restricted {
                ui.selectable_value(&mut view.shown, Quantity::SpinDensity, "spin density");
            }
        });
        ui.horizontal(|ui| {
            ui.label("evaluate");
            ui.selectable_value(&mut view.direct, false, "on a GPU grid").on_hover_text(
                "a compute pass fills a 3D texture; the slices sample it (fast to view, switch in one pass)",
            );
            ui.selectable_value(&mut view.direct, true, "per sample (direct)").on_hover_text(
                "Jang & Varetto's direct mode: every slice fragment evaluates the orbital from the basis functions, no grid",
            );
        });
        keyboard(ui, wf, view);
        orbital_table(ui, wf, view, scroll_to_frontier);
        ao_selector(ui, doc, wf, view);
    });
}

/// Up/down move through the orbitals of the shown spin by energy.
fn keyboard(ui: &egui::Ui, wf: &Wavefunction, view: &mut OrbitalView) {
    if ui.ctx().egui_wants_keyboard_input() {
        return;
    }
    let (up, down) = ui.input(|i| (i.key_pressed(egui::Key::ArrowUp), i.key_pressed(egui::Key::ArrowDown)));
    if !(up || down) || !ui.input(|i| i.modifiers.shift) {
        return;
    }
    let order = wf.by_energy(view.spin_of(wf));
    let Quantity::Orbital(current) = view.shown else { return };
    if let Some(pos) = order.iter().position(|&i| i == current) {
        let next = if up { pos + 1 } else { pos.saturating_sub(1) };
        if let Some(&i) = order.get(next) {
            view.shown = Quantity::Orbital(i);
        }
    }
}

fn orbital_table(ui: &mut egui::Ui, wf: &Wavefunction, view: &mut OrbitalView, scroll_to_frontier: &mut bool) {
    let spin = view.spin_of(wf);
    // Highest energy at the top, as in an orbital diagram.
    let mut order = wf.by_energy(spin);
    order.reverse();
    ui.label(RichText::new("click a row to show it; Shift + up/down arrows to step").small().weak());
    // One monospace line per orbital: the whole row is the button, and the header above the
    // scrolled list lines up with it and stays in view.
    ui.label(RichText::new(row_text("", "", "sym", "E / Eh", "E / eV", "occ")).monospace().strong());
    ScrollArea::vertical().max_height(ui.available_height() * 0.6).show(ui, |ui| {
        for i in order {
            let o = &wf.orbitals[i];
            let number = wf.of_spin(o.spin).position(|(j, _)| j == i).map_or(0, |p| p + 1);
            let selected = view.shown == Quantity::Orbital(i);
            let text = row_text(
                &format!("MO {number}"),
                &wf.frontier_label(i, 5).unwrap_or_default(),
                &o.symmetry,
                &format!("{:.5}", o.energy),
                &format!("{:.3}", o.energy * EV_PER_HARTREE),
                &format!("{:.2}", o.occupation),
            );
            let row = ui.add(
                egui::Button::selectable(selected, RichText::new(text).monospace())
                    .min_size(egui::vec2(ui.available_width(), 0.0)),
            );
            if row.clicked() {
                view.shown = Quantity::Orbital(i);
            }
            if *scroll_to_frontier && Some(i) == wf.homo(spin) {
                row.scroll_to_me(Some(egui::Align::Center));
                *scroll_to_frontier = false;
            }
        }
    });
}

/// One line of the orbital table, columns padded to fixed widths.
fn row_text(name: &str, label: &str, sym: &str, eh: &str, ev: &str, occ: &str) -> String {
    format!("{name:<6}{label:<7}{sym:<4}{eh:>9}{ev:>8}{occ:>5}")
}

/// Seed 004's atomic-orbital selector: restrict the shown orbital to chosen shells.
fn ao_selector(ui: &mut egui::Ui, doc: &Document, wf: &Wavefunction, view: &mut OrbitalView) {
    ui.collapsing("Atomic orbitals", |ui| {
        ui.checkbox(&mut view.ao_filter, "show only the selected shells' part of the orbital");
        if view.shell_mask.len() != wf.basis.shells.len() {
            view.shell_mask = vec![true; wf.basis.shells.len()];
        }
        ScrollArea::vertical().id_salt("ao").max_height(200.0).show(ui, |ui| {
            for (atom_index, atom) in doc.molecule.atoms.iter().enumerate() {
                let shells: Vec<usize> =
                    wf.basis.shells.iter().enumerate().filter(|(_, s)| s.atom == atom_index).map(|(k, _)| k).collect();
                if shells.is_empty() {
                    continue;
                }
                ui.horizontal_wrapped(|ui| {
                    ui.label(format!("{}{}", atom.element().symbol, atom_index + 1));
                    for k in shells {
                        let s = &wf.basis.shells[k];
                        let letter = SHELL_LETTERS.get(s.l as usize).copied().unwrap_or("?");
                        let kind = if s.kind == ShellKind::Pure || s.l < 2 { "" } else { "c" };
                        ui.checkbox(&mut view.shell_mask[k], format!("{letter}{kind}"));
                    }
                });
            }
        });
    });
}
