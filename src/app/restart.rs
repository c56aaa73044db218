//! A lost GPU device: the window closes and opens again on a new device with the scene as it
//! was. Documents are carried in memory (not read again), with every object's state, the
//! camera and the active object.

use std::sync::{Arc, Mutex};

use super::{Opening, OrbApp, ViewState};
use crate::model::Document;
use crate::scene::ObjectState;

/// What the viewer carries from a window whose device was lost to the next one.
pub struct Carried {
    objects: Vec<(Arc<Document>, ObjectState)>,
    active: usize,
    view: ViewState,
    recent: Vec<std::path::PathBuf>,
    /// An open scan and its object: its key volumes lived on the lost device, so they are made
    /// again.
    scan: Option<(super::scan::ScanSource, crate::scene::ObjectState)>,
    /// What the driver said.
    reason: String,
}

/// Where a window leaves its scene for the next one when its device is lost (`run` makes one
/// per process and opens a new window while it holds something).
pub type CarrySlot = Arc<Mutex<Option<Carried>>>;

impl OrbApp {
    /// Leaves the scene in `slot` when the device is lost, and closes the window so that a new
    /// one (on a new device) takes it up.
    pub fn restart_into(&mut self, slot: CarrySlot) {
        self.restart = Some(slot);
    }

    /// The device is lost (`reason`: what the driver said); what the device's handler calls,
    /// and the way to rehearse it.
    pub fn lose_device(&self, reason: &str) {
        self.gpu_errors
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push(format!("{} ({reason})", super::DEVICE_LOST));
    }

    /// Hands the scene to the next window when there is one to hand it to; `false` when the
    /// viewer has no way to open another window (then it only says what happened).
    pub(super) fn carry_away(&mut self, reason: &str, ctx: &egui::Context) -> bool {
        let Some(slot) = self.restart.clone() else { return false };
        let carried = Carried {
            objects: (self.objects.iter().filter(|o| o.scan.is_none()))
                .map(|o| (Arc::clone(&o.doc), o.state.clone()))
                .collect(),
            active: self.active,
            view: self.view,
            recent: self.recent.clone(),
            scan: self.scan_object().and_then(|o| Some((o.scan.as_ref()?.source.clone(), o.state.clone()))),
            reason: reason.to_string(),
        };
        *slot.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(carried);
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        true
    }

    /// Reports the device lost after `seconds` (a rehearsal; `None`: never).
    pub fn rehearse_device_loss(&mut self, seconds: Option<f64>) {
        self.rehearsal = seconds.map(|s| std::time::Instant::now() + std::time::Duration::from_secs_f64(s.max(0.0)));
    }

    /// Reports the rehearsed loss once its time has come.
    pub(super) fn tick_rehearsal(&mut self, ctx: &egui::Context) {
        match self.rehearsal {
            Some(at) if std::time::Instant::now() >= at => {
                self.rehearsal = None;
                self.lose_device("rehearsed with ORBCLOUD_SIMULATE_DEVICE_LOSS");
            }
            Some(at) => ctx.request_repaint_after(at - std::time::Instant::now()),
            None => {}
        }
    }

    /// A window on a new device showing what `carried` held.
    pub fn resume(cc: &eframe::CreationContext<'_>, carried: Carried) -> Self {
        let mut app = Self::empty(cc, Vec::new());
        app.recent = carried.recent;
        for (doc, state) in carried.objects {
            app.add_shared_object(doc, Opening::Restore(Box::new(state)));
        }
        app.select(carried.active);
        app.view = carried.view;
        if let Some((source, state)) = carried.scan {
            app.open_scan(source, &cc.egui_ctx);
            app.restoring_scan = Some((state, Vec::new()));
        }
        app.notice = Some(format!("{} ({}): the scene is back on a new device", super::DEVICE_LOST, carried.reason));
        app
    }

    /// The scene's documents (shared with the window that carried them).
    pub fn documents(&self) -> impl Iterator<Item = &Arc<Document>> {
        self.objects.iter().map(|o| &o.doc)
    }
}
