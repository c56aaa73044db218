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
    chosen
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
