//! A cube of the same atoms as an open cube joins that object instead of opening beside it: the
//! density and potential cubes cubegen or orca_plot write for one molecule become two
//! quantities of one object, and a potential joining a density is shown as an ESP map.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{Opening, OrbApp};
use crate::model::Document;
use crate::scene::objects::AddedVolume;
use crate::scene::{QuantityState, Source};

impl OrbApp {
    /// Adds a loaded document as `how` says, or joins it to an open object of the same atoms
    /// when both are grid-only files and it is added (not replacing, not restored).
    pub(super) fn add_or_join(&mut self, doc: Document, how: Opening) {
        match self.join_target(&doc, &how) {
            Some(n) => self.join_object(n, doc),
            None => self.add_object(doc, how),
        }
    }

    /// The object `doc` would join: the active one when it matches, else the last that does
    /// (objects read from a file only).
    fn join_target(&self, doc: &Document, how: &Opening) -> Option<usize> {
        if *how != Opening::Add || !(doc.is_grid_only() || doc.carries_transitions()) {
            return None;
        }
        // Not onto the bundled demo (sessions leave it out, and what joined it with it), and
        // not a file onto itself: opened again, a file is a second object.
        let same_file = |a: &Path| same_path(a, Path::new(&doc.source));
        let fits = |n: &usize| {
            let o = &self.objects[*n];
            let files = o.state.path.iter().chain(o.state.added.iter().filter_map(|a| match a {
                AddedVolume::Joined { path } => Some(path),
                AddedVolume::Difference { .. } => None,
            }));
            o.state.path.is_some() && !files.map(PathBuf::as_path).any(same_file) && o.doc.joins(doc)
        };
        std::iter::once(self.active).chain((0..self.objects.len()).rev()).filter(|n| *n < self.objects.len()).find(fits)
    }

    /// Appends `doc`'s data sets to object `n`'s as new quantities (a potential joining a
    /// density: an ESP map of the two, taking the view).
    fn join_object(&mut self, n: usize, doc: Document) {
        let added = doc.volumes.len() + 1;
        if self.viewport.as_ref().is_some_and(|vp| vp.room() < added) {
            self.error = Some(format!("{}: the scene is full (no room for its quantities)", doc.source));
            return;
        }
        let path = PathBuf::from(&doc.source);
        let name = doc.source.clone();
        let states = doc.carries_transitions();
        let object = &mut self.objects[n];
        let mut merged = (*object.doc).clone();
        let first = match merged.join(doc) {
            Ok(first) => first,
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        let state = &mut object.state;
        if path.exists() {
            state.added.push(AddedVolume::Joined { path });
        }
        let defaults = self.defaults;
        let density = state.quantities.iter().map(|q| q.source).find(|s| !s.is_potential(&merged));
        for i in first..merged.volumes.len() {
            let source = Source::Volume(i);
            let mut joining = QuantityState::joining(source, &defaults, &state.quantities);
            match density.filter(|_| source.is_potential(&merged)) {
                Some(density) => {
                    // The potential itself stays listed, hidden; the map takes the view.
                    joining.visible = false;
                    state.quantities.iter_mut().for_each(|q| q.visible = false);
                    state.quantities.push(joining);
                    state.quantities.push(QuantityState::esp_map(density, source, &defaults));
                    self.notice = Some(format!(
                        "{name} joined {} (same atoms): an ESP map, ρ = {} coloured by its potential",
                        object.doc.source,
                        crate::scene::ESP_MAP_DENSITY
                    ));
                }
                None => {
                    state.quantities.push(joining);
                    self.notice = Some(format!("{name} joined {} as a quantity (same atoms)", object.doc.source));
                }
            }
        }
        if states {
            let count =
                merged.excited.as_ref().map_or(0, |e| e.states.iter().filter(|s| !s.transitions.is_empty()).count());
            self.notice = Some(format!(
                "{name} joined {} (the same molecule): {count} states' transitions over its orbitals; pick a \
                 state for its natural transition orbitals (hole | particle)",
                object.doc.source
            ));
        }
        // A joined data set is the one the panels edit; joined states leave the selection.
        if !states {
            state.selected = state.quantities.len() - 1;
        }
        object.doc = Arc::new(merged);
        self.active = n;
    }
}

/// Whether two paths name one file (compared resolved where they exist).
fn same_path(a: &Path, b: &Path) -> bool {
    let resolved = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    resolved(a) == resolved(b)
}
