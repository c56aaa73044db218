//! *minus*: the selected quantity minus another open file's same quantity (a density
//! difference: two states, two methods, a complex minus its parts), made in the background on
//! the quantity's grid and added to the object as a data set of its own.

use std::sync::Arc;

use super::jobs::{Pending, spawn};
use super::{OrbApp, SceneObject};
use crate::evaluate::arithmetic::{counterpart, difference};
use crate::model::{Document, VolumeGrid};
use crate::scene::objects::AddedVolume;
use crate::scene::{QuantityState, Source};

/// A difference being made: for the object whose document is `of` (if it still holds that
/// document when the job ends).
pub struct DifferenceJob {
    of: Arc<Document>,
    added: AddedVolume,
    result: Pending<Result<VolumeGrid, String>>,
}

impl OrbApp {
    /// The other objects read from a file whose file holds what the active object's selected
    /// quantity can be subtracted from: (object, name).
    pub fn subtractable(&self) -> Vec<(usize, String)> {
        let Some(o) = self.objects.get(self.active) else { return Vec::new() };
        let Some(q) = o.state.selected_quantity() else { return Vec::new() };
        let name = |other: &SceneObject| other.doc.source.rsplit(['/', '\\']).next().unwrap_or_default().to_string();
        (self.objects.iter().enumerate())
            .filter(|(m, other)| {
                *m != self.active && other.state.path.is_some() && counterpart(&o.doc, q.source, &other.doc).is_some()
            })
            .map(|(m, other)| (m, name(other)))
            .collect()
    }

    /// Starts making the active object's selected quantity minus object `m`'s.
    pub fn start_difference(&mut self, m: usize, ctx: &egui::Context) {
        let (Some(o), Some(other)) = (self.objects.get(self.active), self.objects.get(m)) else { return };
        let (Some(q), Some(minus)) = (o.state.selected_quantity(), other.state.path.clone()) else { return };
        let added = AddedVolume::Difference { of: q.source, minus, points: o.state.evaluation.grid_points };
        let (of, theirs, source, points) = (o.doc.clone(), other.doc.clone(), q.source, o.state.evaluation.grid_points);
        let work = {
            let of = of.clone();
            move || difference(&of, source, points, &theirs)
        };
        let repaint = ctx.clone();
        self.status = format!("subtracting {} …", other.doc.source);
        self.difference =
            Some(DifferenceJob { of, added, result: spawn("subtracting", work, move || repaint.request_repaint()) });
    }

    /// A finished difference joins its object as a new quantity, selected.
    pub(super) fn poll_difference(&mut self) {
        let Some(job) = &self.difference else { return };
        let Some(result) = job.result.poll() else { return };
        let Some(job) = self.difference.take() else { return };
        let grid = match result.and_then(|r| r) {
            Ok(grid) => grid,
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        let Some(n) = self.objects.iter().position(|o| Arc::ptr_eq(&o.doc, &job.of)) else {
            self.status = "the object changed while subtracting: subtract again".into();
            return;
        };
        let object = &mut self.objects[n];
        let mut doc = (*object.doc).clone();
        self.status = format!("made {}", grid.label);
        doc.volumes.push(grid);
        let source = Source::Volume(doc.volumes.len() - 1);
        let state = &mut object.state;
        state.added.push(job.added);
        let joining = QuantityState::joining(source, &self.defaults, &state.quantities);
        state.quantities.push(joining);
        state.selected = state.quantities.len() - 1;
        object.doc = Arc::new(doc);
    }
}
