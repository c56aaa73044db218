//! The excited states of the active object's file: the list (energy in eV and nm, oscillator
//! strength, spin, main transition), the UV-vis spectrum where a click on a band picks its state,
//! and what a picked state shows. Where the file holds the state's density, its difference
//! density (excited − ground) as a two-coloured cloud, its attachment and detachment a click
//! away; else, where the file has orbitals, its main transition's orbitals side by side (the
//! orbital the electron leaves | the one it goes to).

use egui::{RichText, ScrollArea, Slider};
use egui_plot::{Line, Plot, PlotPoint, PlotTransform, VLine};

use super::orbitals::Pick;
use crate::model::Document;
use crate::model::excited::{EV_NM, ExcitedState, ExcitedStates, Transition};
use crate::model::orbitals::{OrbitalSpec, Quantity, Spin, Wavefunction};
use crate::scene::excited_view::ExcitedView;

/// The panel's height, points.
const HEIGHT: f32 = 240.0;

/// What a click in the panel asks for.
#[derive(Default)]
pub struct Asked {
    /// What the object shows, in order.
    pub picks: Vec<Pick>,
    /// The state (index into the list) whose natural transition orbitals are shown, hole |
    /// particle in panes ([`crate::model::nto`]).
    pub ntos: Option<usize>,
}

/// Shows the panel when `doc` lists excited states, editing `view` in place; `spectrum` keeps
/// where the spectrum was drawn (for tests to click its bands). Returns what a click asks for.
pub fn panel(ui: &mut egui::Ui, doc: &Document, view: &mut ExcitedView, spectrum: &mut Option<PlotTransform>) -> Asked {
    let Some(states) = doc.excited.as_ref().filter(|s| !s.states.is_empty()) else {
        *spectrum = None;
        return Asked::default();
    };
    let before = view.state;
    let mut asked = Asked::default();
    egui::Panel::bottom("excited states").exact_size(HEIGHT).show(ui, |ui| {
        ui.columns(2, |columns| {
            asked = list(&mut columns[0], doc, states, view);
            *spectrum = Some(uv_vis(&mut columns[1], states, view));
        });
    });
    let mut picks = std::mem::take(&mut asked.picks);
    // A state picked on the spectrum or in the list shows at once what it can.
    if view.state != before
        && picks.is_empty()
        && let Some(k) = view.state
    {
        picks = shown_for(doc, states, k, Quantity::DifferenceDensity);
    }
    Asked { picks, ..asked }
}

/// What picking state `k` shows: `density` (difference, attachment, detachment) where the file
/// holds that state's density; else its main transition's orbitals side by side.
fn shown_for(doc: &Document, states: &ExcitedStates, k: usize, density: Quantity) -> Vec<Pick> {
    let Some(state) = states.states.get(k) else { return Vec::new() };
    let Some(wf) = &doc.wavefunction else { return Vec::new() };
    if holds_density(doc, states, state) {
        return vec![Pick::Switch(density)];
    }
    match state.main_transitions(1).first().and_then(|t| transition_orbitals(wf, t)) {
        Some((from, to)) => vec![Pick::Switch(Quantity::Orbital(from)), Pick::Beside(Quantity::Orbital(to))],
        None => Vec::new(),
    }
}

/// Whether the document's wavefunction holds `state`'s density.
fn holds_density(doc: &Document, states: &ExcitedStates, state: &ExcitedState) -> bool {
    let has = doc.wavefunction.as_ref().is_some_and(|wf| wf.excited.is_some());
    has && states.density_of == Some(state.number)
}

/// The orbitals (indices into the wavefunction's) a transition leaves and goes to.
fn transition_orbitals(wf: &Wavefunction, t: &Transition) -> Option<(usize, usize)> {
    let spin = if t.spin == "beta" { Spin::Beta } else { Spin::Alpha };
    Some((wf.resolve(OrbitalSpec::Index(t.from), spin)?, wf.resolve(OrbitalSpec::Index(t.to), spin)?))
}

/// "5.629 eV  220.3 nm  f 0.0018  Singlet-Bu  34 → 36 (0.70)".
fn row_text(s: &ExcitedState) -> String {
    let f = s.oscillator_strength.map_or("—".to_string(), |f| format!("{f:.4}"));
    let kind = [s.spin.as_str(), s.symmetry.as_str()].iter().filter(|t| !t.is_empty()).copied().collect::<Vec<_>>();
    let main = s.main_transitions(1).first().map_or(String::new(), |t| {
        let arrow = if t.deexcitation { "←" } else { "→" };
        format!("{} {arrow} {} ({:.2})", t.from, t.to, t.coefficient)
    });
    format!("{:>3} {:>7.3} {:>6.1} {:>7} {} {main}", s.number, s.energy_ev, s.wavelength_nm(), f, kind.join("-"))
}

fn list(ui: &mut egui::Ui, doc: &Document, states: &ExcitedStates, view: &mut ExcitedView) -> Asked {
    let mut picks = Vec::new();
    let mut ntos = None;
    ui.heading("Excited states");
    let method = if states.method.is_empty() { String::new() } else { format!(" {}", states.method) };
    let density = match states.density_of {
        Some(n) if doc.wavefunction.as_ref().is_some_and(|wf| wf.excited.is_some()) => {
            format!("; the file holds state {n}'s density")
        }
        _ => String::new(),
    };
    ui.label(
        RichText::new(format!("{} states from {}{method}{density}", states.states.len(), states.program))
            .small()
            .weak(),
    );
    // What the file leaves unsaid (Q-Chem's fchk names no spins).
    if !states.note.is_empty() {
        ui.label(RichText::new(&states.note).small().weak());
    }
    // The state picked, named, and what it can show.
    if let Some(s) = view.state.and_then(|k| states.states.get(k)) {
        ui.label(
            RichText::new(format!("state {}: {:.3} eV, {:.1} nm", s.number, s.energy_ev, s.wavelength_nm())).strong(),
        );
        if holds_density(doc, states, s)
            && let Some(excited) = doc.wavefunction.as_ref().and_then(|wf| wf.excited.as_ref())
        {
            ui.label(RichText::new(format!("{:.3} electrons move", excited.electrons_moved())).small());
            ui.horizontal(|ui| {
                for (q, name, hint) in [
                    (
                        Quantity::DifferenceDensity,
                        "difference",
                        "ρ(excited) − ρ(ground): where the electron goes (+) and whence (−)",
                    ),
                    (
                        Quantity::Attachment,
                        "attachment",
                        "where the electrons go: the difference density's positive part",
                    ),
                    (Quantity::Detachment, "detachment", "where the electron comes from"),
                ] {
                    if ui.button(name).on_hover_text(hint).clicked() {
                        picks = vec![Pick::Switch(q)];
                    }
                }
            });
        }
        // Its printed amplitudes over the file's orbitals: the natural transition orbitals.
        if doc.wavefunction.is_some()
            && s.transitions.iter().any(|t| !t.deexcitation)
            && ui
                .button("hole | particle")
                .on_hover_text(
                    "the state's natural transition orbitals from its printed amplitudes: where the electron \
                     leaves | where it goes, side by side, each pair's weight in its caption",
                )
                .clicked()
        {
            ntos = view.state;
        }
        // The same amplitudes make its transition density (a singlet's, from the ground state).
        if crate::model::transition::TransitionDensity::of_state(doc, s.number).is_some()
            && ui
                .button("transition density")
                .on_hover_text(
                    "where the density oscillates as light drives the transition: 2 Σ X φ_occ φ_virt from the \
                     printed amplitudes, signed; its dipole gives the oscillator strength",
                )
                .clicked()
        {
            picks = vec![Pick::Switch(Quantity::TransitionDensity(s.number))];
        }
    }
    let transitions = states.states.iter().any(|s| !s.transitions.is_empty());
    let header =
        format!("{:>3} {:>7} {:>6} {:>7} {}", "#", "eV", "nm", "f", if transitions { "spin  main" } else { "spin" });
    ui.add(egui::Label::new(RichText::new(header).monospace().strong()).wrap_mode(egui::TextWrapMode::Truncate));
    let scrolled_id = ui.scope_id().with("states scrolled to");
    let scrolled_to = ui.data(|d| d.get_temp::<Option<usize>>(scrolled_id)).flatten();
    ScrollArea::vertical().id_salt("states").show(ui, |ui| {
        for (k, s) in states.states.iter().enumerate() {
            let row = RichText::new(row_text(s)).monospace();
            let button =
                egui::Button::selectable(view.state == Some(k), row).min_size(egui::vec2(ui.available_width(), 0.0));
            let response = ui.add(button);
            if response.clicked() {
                view.state = Some(k);
            }
            if view.state == Some(k) && scrolled_to != Some(k) {
                response.scroll_to_me(Some(egui::Align::Center));
            }
        }
    });
    ui.data_mut(|d| d.insert_temp(scrolled_id, view.state));
    Asked { picks, ntos }
}

/// The UV-vis spectrum: a stick per state at its energy, as high as its oscillator strength, and
/// the states broadened to Gaussians; the axis in eV or nm (energy grows to the right either
/// way: nm are labelled on the energy axis). A click picks the state of the band under it.
/// Returns where it was drawn.
fn uv_vis(ui: &mut egui::Ui, states: &ExcitedStates, view: &mut ExcitedView) -> PlotTransform {
    ui.horizontal(|ui| {
        ui.spacing_mut().slider_width = 70.0;
        ui.add(Slider::new(&mut view.fwhm_ev, 0.05..=1.0).text("FWHM eV"))
            .on_hover_text("the bands' full width at half maximum (Gaussian bands)");
        ui.selectable_value(&mut view.nanometres, false, "eV");
        ui.selectable_value(&mut view.nanometres, true, "nm");
    });
    let fwhm = view.fwhm_ev as f64;
    let energies = states.states.iter().map(|s| s.energy_ev);
    let lo = (energies.clone().fold(f64::INFINITY, f64::min) - 3.0 * fwhm).max(0.5);
    let hi = energies.fold(0.0, f64::max) + 3.0 * fwhm;
    let curve = states.uv_vis((lo, hi), 600, fwhm);
    let peak = curve.iter().map(|p| p[1]).fold(1e-3, f64::max);
    let nanometres = view.nanometres;
    let axis = egui_plot::AxisHints::new_x()
        .label(if nanometres { "wavelength (nm)" } else { "energy (eV)" })
        .formatter(move |mark, _| match nanometres {
            true if mark.value > 0.0 => format!("{:.0}", EV_NM / mark.value),
            true => String::new(),
            false => format!("{:.1}", mark.value),
        })
        .label_spacing(40.0..=60.0);
    let response = Plot::new("uv-vis spectrum")
        .custom_x_axes(vec![axis])
        .y_axis_label("f")
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .include_x(lo)
        .include_x(hi)
        .include_y(0.0)
        .include_y(peak * 1.1)
        .show(ui, |plot| {
            plot.line(Line::new("spectrum", curve));
            for s in &states.states {
                let f = s.oscillator_strength.unwrap_or(0.0);
                plot.line(Line::new("", vec![[s.energy_ev, 0.0], [s.energy_ev, f]]).width(1.0));
            }
            if let Some(s) = view.state.and_then(|k| states.states.get(k)) {
                plot.vline(VLine::new("picked", s.energy_ev));
            }
            let clicked = plot.response().clicked();
            clicked.then(|| plot.pointer_coordinate()).flatten()
        });
    if let Some(PlotPoint { x, .. }) = response.inner
        && let Some(k) = states.band_at(x, fwhm, fwhm.max((hi - lo) / 100.0))
    {
        view.state = Some(k);
    }
    response.transform
}

impl super::OrbApp {
    /// Shows state `k` of object `n` as its natural transition orbitals: an object of its own
    /// beside the file's (in its place, which it hides), hole 1 in the first pane and particle 1
    /// in the second, one camera; a state's NTOs shown before make way.
    pub fn show_ntos(&mut self, n: usize, k: usize) {
        let Some(parent) = self.objects.get(n) else { return };
        let doc = parent.doc.clone();
        let (Some(wf), Some(state)) = (&doc.wavefunction, doc.excited.as_ref().and_then(|e| e.states.get(k))) else {
            return;
        };
        let Some(ntos) = crate::model::nto::from_transitions(wf, state) else {
            self.status = format!("state {}: no printed transition names orbitals of {}", state.number, doc.source);
            return;
        };
        let Some(made) = ntos.document(&doc) else { return };
        // One state's NTOs at a time: the ones shown before go (the file moves down when they
        // stood before it).
        let before = format!("{} (state ", doc.source);
        let mut n = n;
        if let Some(old) = self.objects.iter().position(|o| o.doc.source.starts_with(&before)) {
            self.remove_object(old);
            n -= usize::from(old < n);
        }
        let Some(parent) = self.objects.get_mut(n) else { return };
        parent.state.visible = false;
        let defaults = self.defaults;
        let mut shown = crate::scene::ObjectState {
            placement: parent.state.placement,
            atoms: parent.state.atoms,
            ..crate::scene::ObjectState::default()
        };
        for (orbital, pane) in [(0, 0), (1, 1)] {
            let source = crate::scene::Source::Wavefunction(Quantity::Orbital(orbital));
            let mut q =
                crate::scene::QuantityState { pane: Some(pane), ..crate::scene::QuantityState::new(source, &defaults) };
            // Readable at once, as an orbital opens: its ± surfaces over the cloud.
            for iso in &mut q.isosurfaces {
                iso.visible = true;
                iso.translucent = true;
            }
            shown.quantities.push(q);
        }
        let weights: Vec<String> = ntos.pairs.iter().map(|p| format!("{:.2}", p.weight)).collect();
        // How far the electron moves: the hole's and the electron's centroids, from the dipole
        // integrals (exact and quick; their overlap needs a grid).
        let (hole, electron) = ntos.centroids(&wf.basis);
        let distance = hole.distance(electron) * crate::model::units::ANGSTROM_PER_BOHR;
        let camera = self.view.camera;
        self.add_shared_object(std::sync::Arc::new(made), super::Opening::Restore(Box::new(shown)));
        while self.view.panes.count < 2 {
            self.view.panes.add(camera);
        }
        self.view.panes.linked = true;
        // The file stays the one the panels edit: its states' list picks the next state.
        self.active = n;
        self.frame_panes();
        self.status = format!(
            "state {}: natural transition orbitals of the printed amplitudes (Σc² {:.4}), weights {}; the \
             electron moves {distance:.2} Å from the hole's centroid to its own",
            state.number,
            ntos.printed_norm,
            weights.join(", ")
        );
    }
}
