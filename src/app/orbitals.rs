//! The orbital browser (Jang and Varetto's orbital UI): every orbital with its spin, symmetry, energy
//! and occupation, HOMO/LUMO labels, the density, and the atomic-orbital selector (single basis
//! functions: an orbital restricted to them, or one alone).

use egui::{RichText, ScrollArea};

use crate::model::Document;
use crate::model::basis_labels::{atom_name, function_labels};
use crate::model::orbitals::Quantity;
use crate::model::orbitals::{EnergiesAsOccupations, Spin, Wavefunction};
use crate::model::units::EV_PER_HARTREE;
use crate::scene::{Camera, IsoLevel, ObjectState, Panes, QuantityState, RenderSettings, Source};

/// The level (a.u.) of an excited state's difference, attachment or detachment density surfaces
/// as they open.
const STATE_DENSITY_LEVEL: f32 = 0.002;

/// Residual of CᵀSC − I above which the orbitals are flagged as not orthonormal.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-5;

/// The orbital browser's width, points: a row (its + and the 41 monospace columns) fits.
/// The orbital browser's width as it opens, and the widths a drag of its edge may give it.
const ORBITALS_PANEL_WIDTH: f32 = 350.0;
const ORBITALS_PANEL_WIDTHS: std::ops::RangeInclusive<f32> = 260.0..=640.0;

/// What a click in the browser (or the excited states' list) does with a wavefunction quantity.
pub(crate) enum Pick {
    /// The selected quantity shows it instead (or the object's first, when it has none).
    Switch(Quantity),
    /// It joins the object as another quantity, selected.
    Add(Quantity),
    /// It joins the object in a new pane beside what is shown.
    Beside(Quantity),
    /// The density surface ρ = 0.002 coloured by the electrostatic potential joins the object
    /// and is what it shows.
    EspMap,
    /// The NCI surface (s = 0.5 where ρ < 0.05, coloured by sign(λ₂)ρ) joins the object and is
    /// what it shows.
    NciSurface,
    /// The NCI cloud (sign(λ₂)ρ where s is low, blue and red) joins the object and is what it
    /// shows.
    NciCloud,
}

/// How the view frames what a pick in the browser changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reframe {
    None,
    /// An ESP map: beside its colour bar.
    BesideBar,
    /// A pane was added: the molecule fills each pane's width.
    Panes,
}

/// The orbital browser of the object `state` describes: it edits `state` in place (the
/// selected quantity's orbital or density, the spin listed, how orbitals are evaluated).
/// `scroll_to_frontier` brings the HOMO's row into view once (after a file opens). Returns
/// how the view should frame what the pick changed.
pub fn panel(
    ui: &mut egui::Ui,
    doc: &Document,
    state: &mut ObjectState,
    defaults: &RenderSettings,
    (panes, camera): (&mut Panes, &Camera),
    scroll_to_frontier: &mut bool,
    open: &mut bool,
) -> Reframe {
    let Some(wf) = &doc.wavefunction else { return Reframe::None };
    let mut pick = None;
    egui::Panel::right("orbitals")
        .resizable(true)
        .default_size(ORBITALS_PANEL_WIDTH)
        .size_range(ORBITALS_PANEL_WIDTHS)
        .show_collapsible(ui, open, |ui| {
            ui.heading("Orbitals");
            let n = &wf.normalization;
            ui.label(
                RichText::new(format!(
                    "{} basis functions, {} orbitals · written by {} · repair: {} · |C^T S C - I| {:.1e}{}",
                    wf.basis.n_functions(),
                    wf.orbitals.len(),
                    n.program,
                    n.repair,
                    n.residual,
                    n.precision_note().map_or(String::new(), |p| format!(" · {p}"))
                ))
                .small()
                .weak(),
            );
            if n.residual > ORTHONORMAL_TOLERANCE.max(n.expected_residual()) {
                ui.label(
                    RichText::new("Warning: these orbitals are not orthonormal in this basis: the file may be wrong")
                        .color(ui.visuals().warn_fg_color),
                );
            }
            let shown = shown_quantity(state);
            // The list is of the shown orbital's spin (a session reopened on a β orbital lists β).
            if let Some(o) = shown.and_then(|q| match q {
                Quantity::Orbital(i) => wf.orbitals.get(i),
                _ => None,
            }) {
                state.evaluation.spin = o.spin;
            }
            if !wf.restricted {
                ui.horizontal(|ui| {
                    ui.label("orbitals of spin");
                    for (spin, name) in [(Spin::Alpha, "α"), (Spin::Beta, "β")] {
                        if ui.selectable_label(state.evaluation.spin == spin, name).clicked()
                            && state.evaluation.spin != spin
                        {
                            state.evaluation.spin = spin;
                            // The orbital shown follows: the same place relative to the frontier.
                            if let Some(Quantity::Orbital(i)) = shown
                                && let Some(j) = same_role(wf, i, spin)
                            {
                                pick = Some(Pick::Switch(Quantity::Orbital(j)));
                            }
                        }
                    }
                });
            }
            let mut densities = vec![(Quantity::Density, "total density")];
            if !wf.restricted {
                densities.push((Quantity::SpinDensity, "spin density"));
            }
            densities.push((Quantity::Potential, "electrostatic potential"));
            ui.horizontal_wrapped(|ui| {
                ui.label("show");
                for &(q, name) in &densities {
                    if ui.selectable_label(shown == Some(q), name).clicked() {
                        pick = Some(Pick::Switch(q));
                    }
                }
            });
            ui.horizontal(|ui| {
            let hint = "the density surface ρ = 0.002 coloured by the electrostatic potential: red where the molecule \
                        attracts a positive charge, blue where it repels one";
            if ui.button("ESP map").on_hover_text(hint).clicked() {
                pick = Some(Pick::EspMap);
            }
            let hint = "non-covalent interactions: where the reduced density gradient s is low between atoms \
                        (s = 0.5, ρ < 0.05), coloured by sign(λ₂)ρ: blue hydrogen bonds, green van der Waals \
                        contacts, red steric clashes";
            if ui.button("NCI surface").on_hover_text(hint).clicked() {
                pick = Some(Pick::NciSurface);
            }
            let hint = "the same interactions as a cloud: opaque where s lies deep below 0.5 and the density is \
                        high, blue where λ₂ < 0 (attraction), red where λ₂ > 0 (repulsion)";
            if ui.button("NCI cloud").on_hover_text(hint).clicked() {
                pick = Some(Pick::NciCloud);
            }
        });
            ui.horizontal_wrapped(|ui| {
                ui.label("add");
                for &(q, name) in &densities {
                    let hint = format!("the {name} joins what is shown (an orbital inside its density)");
                    if ui.button(format!("+ {name}")).on_hover_text(hint).clicked() {
                        pick = Some(Pick::Add(q));
                    }
                }
            });
            ui.horizontal_wrapped(|ui| {
                let e = &mut state.evaluation;
                ui.label("evaluate");
                ui.selectable_value(&mut e.direct, false, "on a GPU grid").on_hover_text(
                    "a compute pass fills a 3D texture; the slices sample it (fast to view, switch in one pass)",
                );
                ui.selectable_value(&mut e.direct, true, "per sample (direct)")
                    .on_hover_text("every slice fragment evaluates the orbital from the basis functions, no grid");
            });
            if let Some(p) = keyboard(ui, wf, state.evaluation.spin, shown) {
                pick = Some(p);
            }
            if let Some(p) = orbital_table(ui, wf, state.evaluation.spin, shown, scroll_to_frontier) {
                pick = Some(p);
            }
            if let Some(p) = ao_selector(ui, doc, wf, state) {
                pick = Some(p);
            }
        });
    pick.map_or(Reframe::None, |p| apply(p, state, defaults, (panes, camera)))
}

/// Does what `pick` asks of the object `state` describes; returns how the view should frame it.
pub(crate) fn apply(
    pick: Pick,
    state: &mut ObjectState,
    defaults: &RenderSettings,
    (panes, camera): (&mut Panes, &Camera),
) -> Reframe {
    let mut reframe = Reframe::None;
    match pick {
        Pick::Switch(q) => {
            match state.selected_quantity_mut().filter(|s| matches!(s.source, Source::Wavefunction(_))) {
                Some(selected) => selected.source = Source::Wavefunction(q),
                None => add(state, q, defaults),
            }
            // An excited state's densities are small beside an orbital's values: their
            // surfaces at the level chemists draw them, which an orbital's level would miss.
            if q.state_part().is_some()
                && let Some(selected) = state.selected_quantity_mut()
            {
                selected.isosurfaces.iter_mut().for_each(|iso| iso.level = IsoLevel::Absolute(STATE_DENSITY_LEVEL));
            }
        }
        Pick::Add(q) => add(state, q, defaults),
        Pick::EspMap => {
            reframe = Reframe::BesideBar;
            let map = QuantityState::esp_map(
                Source::Wavefunction(Quantity::Density),
                Source::Wavefunction(Quantity::Potential),
                defaults,
            );
            take_view(state, map);
        }
        Pick::NciSurface => {
            reframe = Reframe::BesideBar;
            take_view(state, QuantityState::nci_surface(defaults));
        }
        Pick::NciCloud => take_view(state, QuantityState::nci_cloud(defaults)),
        Pick::Beside(q) => {
            reframe = Reframe::Panes;
            if panes.count == 1 {
                // What was shown stays in the first pane; the new one goes beside it.
                state.quantities.iter_mut().filter(|q| q.pane.is_none()).for_each(|q| q.pane = Some(0));
            }
            // In a pane of its own, drawn as the orbital it is compared with is drawn (cloud,
            // isosurfaces, colours): the two panes differ only in the orbital.
            let pane = panes.add(*camera);
            let mut beside =
                QuantityState { pane: Some(pane), ..QuantityState::new(Source::Wavefunction(q), defaults) };
            if let Some(shown) = state.quantities.get(state.selected).filter(|s| s.source.orbital().is_some()) {
                (beside.cloud, beside.isosurfaces) = (shown.cloud, shown.isosurfaces.clone());
            }
            state.quantities.push(beside);
            state.selected = state.quantities.len() - 1;
        }
    }
    reframe
}

/// Adds `quantity` to the object as what it shows: what was shown stays listed, hidden, a tick
/// away.
fn take_view(state: &mut ObjectState, quantity: QuantityState) {
    state.quantities.iter_mut().for_each(|q| q.visible = false);
    state.quantities.push(quantity);
    state.selected = state.quantities.len() - 1;
}

/// Adds `q` to the object as a new quantity, selected.
fn add(state: &mut ObjectState, q: Quantity, defaults: &RenderSettings) {
    // In the same pane as the others: colours of its own.
    let joining = QuantityState::joining(Source::Wavefunction(q), defaults, &state.quantities);
    state.quantities.push(joining);
    state.selected = state.quantities.len() - 1;
}

/// The wavefunction quantity the selected quantity shows, if it is one.
fn shown_quantity(state: &ObjectState) -> Option<Quantity> {
    match state.selected_quantity()?.source {
        Source::Wavefunction(q) => Some(q),
        Source::Volume(_) | Source::Scan(_) | Source::Promolecular(_) => None,
    }
}

/// The orbital of `spin` at the same place relative to the frontier as orbital `i` (HOMO−1 α →
/// HOMO−1 β).
fn same_role(wf: &Wavefunction, i: usize, spin: Spin) -> Option<usize> {
    let from = wf.orbitals.get(i)?.spin;
    let (homo_from, homo_to) = (wf.homo(from)?, wf.homo(spin)?);
    let (a, b) = (wf.by_energy(from), wf.by_energy(spin));
    let offset = a.iter().position(|&k| k == i)? as isize - a.iter().position(|&k| k == homo_from)? as isize;
    let target = b.iter().position(|&k| k == homo_to)? as isize + offset;
    b.get(target.clamp(0, b.len() as isize - 1) as usize).copied()
}

/// Shift + up/down move through the orbitals of the listed spin by energy.
fn keyboard(ui: &egui::Ui, wf: &Wavefunction, spin: Spin, shown: Option<Quantity>) -> Option<Pick> {
    if ui.ctx().egui_wants_keyboard_input() {
        return None;
    }
    let (up, down) = ui.input(|i| (i.key_pressed(egui::Key::ArrowUp), i.key_pressed(egui::Key::ArrowDown)));
    if !(up || down) || !ui.input(|i| i.modifiers.shift) {
        return None;
    }
    let order = wf.by_energy(spin_of(wf, spin));
    let Some(Quantity::Orbital(current)) = shown else { return None };
    let pos = order.iter().position(|&i| i == current)?;
    let next = if up { pos + 1 } else { pos.saturating_sub(1) };
    order.get(next).map(|&i| Pick::Switch(Quantity::Orbital(i)))
}

/// The spin whose orbitals are listed (restricted wavefunctions have only alpha).
fn spin_of(wf: &Wavefunction, spin: Spin) -> Spin {
    if wf.restricted { Spin::Alpha } else { spin }
}

fn orbital_table(
    ui: &mut egui::Ui,
    wf: &Wavefunction,
    spin: Spin,
    shown: Option<Quantity>,
    scroll_to_frontier: &mut bool,
) -> Option<Pick> {
    let spin = spin_of(wf, spin);
    let mut pick = None;
    // Highest energy at the top, as in an orbital diagram.
    let mut order = wf.by_energy(spin);
    order.reverse();
    ui.label(
        RichText::new("click a row to show it, + to add it to what is shown, right-click to show it beside in a pane of its own; Shift + up/down arrows to step")
            .small()
            .weak(),
    );
    // One monospace line per orbital: the whole row is the button, and the header above the
    // scrolled list lines up with it and stays in view.
    let as_occupations = wf.energies_as_occupations();
    if wf.natural(spin) {
        let energies = as_occupations.map_or(String::new(), |e| format!(": {}", e.describe()));
        ui.label(RichText::new(format!("natural orbitals, by occupation{energies}")).strong());
    }
    let [eh_header, ev_header] = energy_headers(as_occupations);
    // One label on every orbital (a file without symmetry: "A" throughout) says nothing: the
    // column is left out and the rows fit a narrower panel.
    let symmetries = order.first().map(|&i| &wf.orbitals[i].symmetry);
    let sym_column = order.iter().any(|&i| Some(&wf.orbitals[i].symmetry) != symmetries);
    let sym = |s: &str| if sym_column { format!("{s:<4}") } else { String::new() };
    // A panel narrower than the rows scrolls them sideways rather than growing past the window.
    let height = ui.available_height() * 0.6;
    ScrollArea::horizontal().id_salt("orbital rows").show(ui, |ui| {
        ui.label(RichText::new(row_text("", "", &sym("sym"), eh_header, ev_header, "occ")).monospace().strong());
        ScrollArea::vertical().max_height(height).show(ui, |ui| {
            for i in order {
                let o = &wf.orbitals[i];
                let number = wf.of_spin(o.spin).position(|(j, _)| j == i).map_or(0, |p| p + 1);
                let selected = shown == Some(Quantity::Orbital(i));
                let [eh, ev] = energy_cells(o.energy, as_occupations);
                let text = row_text(
                    &format!("MO {number}"),
                    &wf.frontier_label(i, 5).unwrap_or_default(),
                    &sym(&o.symmetry),
                    &eh,
                    &ev,
                    &format!("{:.2}", o.occupation),
                );
                ui.horizontal(|ui| {
                    let add = ui.small_button("+").on_hover_text("add this orbital to the object beside what it shows");
                    let row = ui.add(
                        egui::Button::selectable(selected, RichText::new(text).monospace())
                            .min_size(egui::vec2(ui.available_width(), 0.0)),
                    );
                    if row.clicked() {
                        pick = Some(Pick::Switch(Quantity::Orbital(i)));
                    }
                    row.context_menu(|ui| {
                        if ui.button("show beside (a pane of its own)").clicked() {
                            pick = Some(Pick::Beside(Quantity::Orbital(i)));
                            ui.close();
                        }
                        if ui.button("add to this view").clicked() {
                            pick = Some(Pick::Add(Quantity::Orbital(i)));
                            ui.close();
                        }
                    });
                    if add.clicked() {
                        pick = Some(Pick::Add(Quantity::Orbital(i)));
                    }
                    if *scroll_to_frontier && Some(i) == wf.homo(spin) {
                        row.scroll_to_me(Some(egui::Align::Center));
                        *scroll_to_frontier = false;
                    }
                });
            }
        });
    });
    pick
}

/// The headers of the orbital table's two energy columns. Energies that are occupations are
/// labelled as what they are, not as hartree.
fn energy_headers(as_occupations: Option<EnergiesAsOccupations>) -> [&'static str; 2] {
    match as_occupations {
        Some(EnergiesAsOccupations::Whole) => ["Ene=occ", ""],
        Some(EnergiesAsOccupations::PerSpin) => ["Ene=occ/2", ""],
        None => ["E / Eh", "E / eV"],
    }
}

/// An orbital's cells under [`energy_headers`]: the file's value as an occupation when it is
/// one, else hartree and eV (dashes when the file gave none).
fn energy_cells(energy: f64, as_occupations: Option<EnergiesAsOccupations>) -> [String; 2] {
    match as_occupations {
        Some(_) => [format!("{energy:.5}"), String::new()],
        None if energy.is_finite() => [format!("{energy:.5}"), format!("{:.3}", energy * EV_PER_HARTREE)],
        None => ["—".into(), "—".into()],
    }
}

/// One line of the orbital table, columns padded to fixed widths (`sym` comes padded, or empty
/// when the column is left out).
fn row_text(name: &str, label: &str, sym: &str, eh: &str, ev: &str, occ: &str) -> String {
    // Wide enough that a core orbital's energies (-20.57911, -559.986) stay apart.
    format!("{name:<6}{label:<7}{sym}{eh:>9}{ev:>9}{occ:>5}")
}

/// Jang and Varetto's atomic-orbital selector (its Fig. 9): tick single basis functions — 2px apart
/// from 2py, one d component — to restrict the shown orbitals to them, or show one alone as a
/// quantity of its own (right-click).
fn ao_selector(ui: &mut egui::Ui, doc: &Document, wf: &Wavefunction, state: &mut ObjectState) -> Option<Pick> {
    let mut pick = None;
    let view = &mut state.evaluation;
    let n = wf.basis.n_functions();
    if view.functions.len() != n {
        view.functions = view.ticked(&wf.basis);
    }
    ui.collapsing("Atomic orbitals", |ui| {
        ui.checkbox(&mut view.ao_filter, "show only the ticked functions' part of the orbitals");
        let before = view.functions.clone();
        ui.horizontal(|ui| {
            let ticked = view.functions.iter().filter(|&&on| on).count();
            ui.label(format!("{ticked} of {n} ticked"));
            if ui.small_button("all").clicked() {
                view.functions.fill(true);
            }
            if ui.small_button("none").clicked() {
                view.functions.fill(false);
            }
        });
        ui.label(
            RichText::new("an atom's button ticks or unticks its functions; right-click a function to show it alone")
                .small()
                .weak(),
        );
        let labels = function_labels(&wf.basis);
        ScrollArea::vertical().id_salt("ao").max_height(220.0).show(ui, |ui| {
            for atom in 0..doc.molecule.atoms.len() {
                let functions: Vec<usize> = (0..labels.len()).filter(|&k| labels[k].atom == atom).collect();
                if functions.is_empty() {
                    continue;
                }
                let atom_label = atom_name(&doc.molecule, atom);
                ui.horizontal_wrapped(|ui| {
                    if ui.button(&atom_label).clicked() {
                        let all = functions.iter().all(|&k| view.functions[k]);
                        functions.iter().for_each(|&k| view.functions[k] = !all);
                    }
                    for &k in &functions {
                        let orbital = labels[k].orbital();
                        let full = format!("{atom_label} {orbital}");
                        ui.checkbox(&mut view.functions[k], orbital).context_menu(|ui| {
                            let bare = Quantity::BasisFunction(k);
                            if ui.button(format!("show {full} alone")).clicked() {
                                pick = Some(Pick::Switch(bare));
                                ui.close();
                            }
                            if ui.button(format!("add {full} to this view")).clicked() {
                                pick = Some(Pick::Add(bare));
                                ui.close();
                            }
                            if ui.button(format!("show {full} beside (a pane of its own)")).clicked() {
                                pick = Some(Pick::Beside(bare));
                                ui.close();
                            }
                        });
                    }
                });
            }
        });
        // Ticking is choosing: a changed selection applies at once.
        if view.functions != before {
            view.ao_filter = true;
        }
    });
    pick
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_core_orbitals_energies_stay_apart() {
        let row = super::row_text("MO 1", "", "", "-20.57911", "-559.986", "2.00");
        assert!(row.contains("-20.57911 ") && row.contains(" -559.986"), "{row:?}");
    }

    #[test]
    fn energies_that_are_occupations_are_labelled_so() {
        use super::{EnergiesAsOccupations, energy_cells, energy_headers};
        assert_eq!(energy_headers(Some(EnergiesAsOccupations::PerSpin)), ["Ene=occ/2", ""]);
        assert_eq!(energy_headers(None), ["E / Eh", "E / eV"]);
        assert_eq!(energy_cells(0.98765, Some(EnergiesAsOccupations::PerSpin)), ["0.98765".to_string(), String::new()]);
        assert_eq!(energy_cells(-0.5, None)[1], format!("{:.3}", -0.5 * crate::model::units::EV_PER_HARTREE));
        assert_eq!(energy_cells(f64::NAN, None), ["—".to_string(), "—".to_string()]);
    }
}
