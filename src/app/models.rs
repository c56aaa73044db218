//! Models of a structure (an NMR ensemble's, an XYZ trajectory's frames): which one the active
//! object shows, and playing them in turn like a scan's the value; and which of its atoms are shown
//! (a selection by chain, residue number and residue name).

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui::{RichText, Slider};

use super::{OrbApp, World};
use crate::scene::selection::Selection;

/// Time each model stays on screen while playing.
const STEP: Duration = Duration::from_millis(120);

#[derive(Debug, Default)]
pub struct Player {
    pub playing: bool,
    last: Option<Instant>,
    /// Where the frames' energy plot was last drawn (tests click its points).
    pub energy_plot: Option<egui_plot::PlotTransform>,
}

/// The slider and play button, when the active object has more than one model; the model
/// chosen, if the user moved to another.
pub fn controls(ui: &mut egui::Ui, app: &mut OrbApp) -> Option<usize> {
    let view = app.objects.get(app.active)?.doc.structure.as_ref()?;
    let count = view.structure.models.len();
    if count < 2 {
        return None;
    }
    let mut shown = view.model + 1;
    let model = &view.structure.models[view.model];
    let mut chosen = None;
    ui.horizontal(|ui| {
        if ui.add(Slider::new(&mut shown, 1..=count).text("model")).changed() {
            chosen = Some(shown - 1);
        }
        let label = if app.models.playing { "pause" } else { "play" };
        if ui.button(label).clicked() {
            app.models.playing = !app.models.playing;
            app.models.last = None;
        }
    });
    let title = if model.title.is_empty() { format!("MODEL {}", model.number) } else { model.title.clone() };
    ui.label(RichText::new(title).small().weak());
    let energies: Vec<Option<f64>> = view.structure.models.iter().map(|m| m.energy).collect();
    // A scan job's frames (a Gaussian or ORCA relaxed scan) lie along the coordinate it scanned: the
    // plot is against its values, and their orbitals can be computed to make a scan of them.
    let doc = &app.objects[app.active].doc;
    let job = doc.job_scan.as_ref().filter(|j| j.values.len() == count);
    let axis = match job {
        Some(j) => (j.values.clone(), format!("{} ({})", j.coordinate.label(), j.coordinate.unit().trim())),
        None => ((1..=count).map(|k| k as f64).collect(), "frame".to_string()),
    };
    let mut compute = false;
    if let Some(j) = job {
        ui.label(format!(
            "{} = {} (the job's scan)",
            j.coordinate.label(),
            j.coordinate.value_text(j.values[view.model])
        ));
        compute = ui
            .button("Compute orbitals for these frames…")
            .on_hover_text("a single point at each frame's geometry with PySCF, opened as a scan of its coordinate")
            .clicked();
    }
    let (picked, transform) = energy_plot(ui, &energies, &axis, view.model).unzip();
    app.models.energy_plot = transform;
    if compute {
        app.scan_dialog = super::compute::ScanDialog::for_job(app.active, &app.objects[app.active].doc);
    }
    picked.flatten().or(chosen)
}

/// Height of the frames' energy plot, points.
const ENERGY_PLOT_HEIGHT: f32 = 120.0;

/// The frames' energies (an optimisation's, an IRC's, a scan's, as the log printed them),
/// relative to the lowest, in kcal/mol against the frame's number, the frame shown marked; a
/// click picks the frame nearest it. Nothing when fewer than two frames have an energy.
fn energy_plot(
    ui: &mut egui::Ui,
    energies: &[Option<f64>],
    (xs, x_label): &(Vec<f64>, String),
    shown: usize,
) -> Option<(Option<usize>, egui_plot::PlotTransform)> {
    const KCAL_PER_HARTREE: f64 = 627.509_474;
    let known: Vec<(usize, f64)> = energies.iter().enumerate().filter_map(|(k, e)| Some((k, (*e)?))).collect();
    if known.len() < 2 {
        return None;
    }
    let lowest = known.iter().map(|&(_, e)| e).fold(f64::INFINITY, f64::min);
    let x = |k: usize| xs.get(k).copied().unwrap_or((k + 1) as f64);
    let points: Vec<[f64; 2]> = known.iter().map(|&(k, e)| [x(k), (e - lowest) * KCAL_PER_HARTREE]).collect();
    let marked: Vec<[f64; 2]> = known.iter().zip(&points).filter(|((k, _), _)| *k == shown).map(|(_, p)| *p).collect();
    // Room past the last frame: the panel's edge (where it is resized) lies beside it.
    let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
    let room = (hi - lo) / (points.len() - 1) as f64 * 0.5;
    let response = egui_plot::Plot::new("frames' energies")
        .height(ENERGY_PLOT_HEIGHT)
        .x_axis_label(x_label.as_str())
        .y_axis_label("ΔE (kcal/mol)")
        .include_x(hi + room)
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .show(ui, |plot| {
            plot.line(egui_plot::Line::new("energy", points.clone()));
            plot.points(egui_plot::Points::new("frames", points).radius(2.0));
            plot.points(egui_plot::Points::new("shown", marked).radius(5.0).color(egui::Color32::YELLOW));
            plot.response().clicked().then(|| plot.pointer_coordinate()).flatten()
        });
    let picked = response.inner.and_then(|at| {
        let distance = |k: usize| (x(k) - at.x).abs();
        known.iter().map(|&(k, _)| k).min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
    });
    Some((picked, response.transform))
}

/// The *show* field of a structure: which of its atoms are drawn (`chain A resi 30-50`,
/// `not resn HOH`; empty: all). A query that does not parse shows what it expected.
pub fn selection(ui: &mut egui::Ui, app: &mut OrbApp) {
    let Some(o) = app.objects.get_mut(app.active).filter(|o| o.doc.structure.is_some()) else { return };
    let mut query = o.state.selection.clone();
    let (changed, done) = ui
        .horizontal(|ui| {
            let edit = egui::TextEdit::singleline(&mut query).hint_text("chain A resi 30-50").desired_width(170.0);
            let field = ui.add(edit);
            ui.label("show");
            (field.changed(), field.lost_focus())
        })
        .inner;
    let (total, shown) = (o.doc.molecule.atoms.len(), o.shown_atoms);
    if shown < total {
        ui.label(RichText::new(format!("{shown} of {total} atoms shown")).small().weak());
    }
    if let Err(expected) = Selection::parse(&query) {
        ui.label(RichText::new(format!("expected {expected}")).small().color(ui.visuals().error_fg_color));
    }
    if changed {
        // The frame's changes restyle the atoms and wrap the molecular surface around them.
        o.state.selection = query;
    }
    // The view frames what is shown once the query is entered (not at every key).
    if done && Selection::parse(&o.state.selection).is_ok() {
        app.reframe();
    }
}

/// The next model while playing, when its time has come; asks for the repaint that comes back.
pub fn tick(ctx: &egui::Context, app: &mut OrbApp) -> Option<usize> {
    if !app.models.playing {
        return None;
    }
    let view = app.objects.get(app.active)?.doc.structure.as_ref()?;
    let count = view.structure.models.len();
    ctx.request_repaint_after(STEP);
    let now = Instant::now();
    if app.models.last.is_some_and(|t| now - t < STEP) || count < 2 {
        return None;
    }
    app.models.last = Some(now);
    Some((view.model + 1) % count)
}

impl OrbApp {
    /// Shows model `model` of the active object's structure: its atoms, bonds and picks.
    pub fn show_model(&mut self, model: usize) {
        let n = self.active;
        // The scene's atoms hold the documents too: let go first so the document is not copied.
        self.world = World::default();
        let Some(o) = self.objects.get_mut(n) else { return };
        let doc = Arc::make_mut(&mut o.doc);
        if let Some(view) = &mut doc.structure {
            doc.molecule = view.show(model);
        }
        self.measurements.selection.clear();
        self.measurements.list.clear();
        if let Some(vp) = &mut self.viewport {
            let o = &self.objects[n];
            vp.set_atoms(n, &o.doc, &o.state);
            if o.state.surface.choice != crate::scene::SurfaceChoice::Off {
                vp.update_surface(n, &o.doc, &o.state);
            }
        }
        self.objects[n].count_shown_atoms();
        self.world = World::of(&self.objects);
    }
}
