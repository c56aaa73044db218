//! Saving and reopening what the user had open (`*.orbcloud.toml`: files, representations,
//! placements, camera), and the session kept between runs.

use std::path::{Path, PathBuf};

use super::{Opening, OrbApp};
use crate::scene::Session;
pub use crate::sources::session::{Read, add_volume, last_session_path, parse, read, with_suffix, write};

impl OrbApp {
    /// The scene as a session: every object read from a file or made from a scan (the bundled
    /// cube demo is left out), the camera and the background.
    pub fn session(&mut self) -> Session {
        Session {
            camera: self.view.camera,
            panes: self.view.panes,
            measurements: self.measurements.list.clone(),
            background: Some(self.view.background),
            objects: (self.objects.iter())
                .filter(|o| o.state.path.is_some() || o.state.scan.is_some())
                .map(|o| o.state.clone())
                .collect(),
            recent: self.recent.clone(),
            scan: None,
        }
    }

    /// Saves the scene to `path`, saying so in the status line (or the error window).
    pub fn save_session(&mut self, path: &Path) {
        let session = self.session();
        match write(path, &session) {
            Ok(()) => self.status = format!("saved {} ({} objects)", path.display(), session.objects.len()),
            Err(e) => self.error = Some(e),
        }
    }

    /// Replaces the scene with a saved one: its files load one after another, each restored
    /// with its representations and placement; the camera is the saved one. A session that
    /// cannot be read leaves the scene as it was.
    pub fn open_session(&mut self, path: &Path, ctx: &egui::Context) {
        let (session, notes) = match read(path) {
            Ok(read) => (read.session, read.notes),
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        // Out of range values were replaced; the session opens, and says which.
        if !notes.is_empty() {
            self.error = Some(format!("{}: values out of range were replaced:\n{}", path.display(), notes.join("\n")));
        }
        // A scan opens as an object in place of the others (sessions before scans were objects
        // kept it beside them).
        let scan = (session.objects.iter().find(|o| o.scan.is_some()).cloned())
            .or_else(|| session.scan.map(|legacy| legacy.into_object(0)));
        let files: Vec<(PathBuf, Opening)> = match scan {
            Some(_) => Vec::new(),
            None => (session.objects.into_iter())
                .filter_map(|state| Some((state.path.clone()?, Opening::Restore(Box::new(state)))))
                .collect(),
        };
        if files.is_empty() && scan.is_none() {
            self.error = Some(format!("{}: the session names no file", path.display()));
            return;
        }
        self.clear_scene();
        self.view.camera = session.camera;
        self.view.panes = session.panes;
        match scan {
            // A scan's measurements number its atoms: they come back with it once its key
            // volumes are made.
            Some(object) => {
                let playback = object.scan.clone().unwrap_or_default();
                let source = playback.manifest.map_or(super::scan::ScanSource::Demo, super::scan::ScanSource::File);
                let orbitals = (!playback.orbitals.is_empty()).then_some(playback.orbitals);
                self.open_scan_with(source, Some(playback.follow), orbitals, ctx);
                self.restoring_scan = Some((object, session.measurements));
            }
            // Measurements number the scene's atoms: they come back once every file has loaded.
            None => self.restoring_measurements = Some(session.measurements),
        }
        if let Some(bg) = session.background {
            self.view.background = bg;
        }
        super::files::remember(&mut self.recent, path, super::RECENT_FILES);
        self.queue.extend(files.into_iter().rev());
        self.status = format!("opening session {}", path.display());
        ctx.request_repaint();
    }

    /// Empties the scene (what is loading still arrives).
    pub fn clear_scene(&mut self) {
        self.objects.clear();
        self.applied.clear();
        self.active = 0;
        self.measurements = Default::default();
        if let Some(vp) = &mut self.viewport {
            vp.clear();
        }
        self.world = super::World::default();
    }

    /// Starts keeping the session between runs in `path`: the settings new objects start with
    /// come from the session saved there (its last object's), and the scene is saved there when
    /// the window closes.
    pub fn keep_session_in(&mut self, path: PathBuf) {
        if let Ok(Read { session, notes }) = read(&path) {
            for note in notes {
                log::warn!("{note}");
            }
            if let Some(last) = session.objects.last() {
                self.defaults = last.render_settings(last.selected, self.defaults.background);
                // New files open without the last file's isosurfaces or hidden cloud.
                self.defaults.iso.visible = false;
                self.defaults.volume.visible = true;
            }
            if let Some(bg) = session.background {
                self.view.background = bg;
                self.defaults.background = bg;
            }
            self.recent = session.recent;
        }
        self.last_session = Some(path);
    }

    /// Saves the scene where [`Self::keep_session_in`] said (on closing the window).
    pub fn save_last_session(&mut self) {
        let Some(path) = self.last_session.clone() else { return };
        let session = self.session();
        if let Err(e) = write(&path, &session) {
            log::warn!("could not keep the session: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::orbitals::Quantity;
    use crate::scene::objects::SESSION_SUFFIX;
    use crate::scene::{
        AtomLook, IsoLevel, IsosurfaceSettings, ObjectState, Placement, QuantityState, RenderSettings, Source,
    };

    #[test]
    fn sessions_round_trip_through_toml() {
        let mut object = ObjectState { path: Some("/data/water.molden".into()), ..Default::default() };
        object.placement = Placement { offset: [8.0, 0.0, -1.5], rotation_deg: [0.0, 90.0, 0.0] };
        object.atoms.ball_scale = 1.6;
        object.atoms.stick_scale = 0.5;
        let shell = IsosurfaceSettings { visible: true, level: IsoLevel::Sigma(2.5), ..Default::default() };
        let homo = Source::Wavefunction(crate::model::orbitals::Quantity::Orbital(4));
        let mut orbital = QuantityState::new(homo, &RenderSettings::default());
        orbital.isosurfaces = vec![shell, Default::default()];
        orbital.cloud.visible = false;
        let density = Source::Wavefunction(crate::model::orbitals::Quantity::Density);
        object.quantities = vec![QuantityState::new(density, &RenderSettings::default()), orbital];
        object.selected = 1;
        let session = Session { background: Some([1.0, 1.0, 1.0]), objects: vec![object], ..Default::default() };
        let dir = std::env::temp_dir().join(format!("orbcloud-session-{}", std::process::id()));
        let path = dir.join(format!("scene{SESSION_SUFFIX}"));
        write(&path, &session).unwrap();
        assert_eq!(read(&path).unwrap(), Read { session, notes: Vec::new() });
        std::fs::write(&path, "objects = 3").unwrap();
        let e = read(&path).unwrap_err();
        assert!(e.contains("scene.orbcloud.toml") && e.contains("line 1"), "{e}");
        std::fs::remove_dir_all(dir).ok();
        assert_eq!(with_suffix("a/b.toml".into()), PathBuf::from("a/b.orbcloud.toml"));
        assert_eq!(with_suffix("b".into()), PathBuf::from("b.orbcloud.toml"));
        assert_eq!(with_suffix("b.orbcloud.toml".into()), PathBuf::from("b.orbcloud.toml"));
    }

    /// A session as written, with `edits` (line, replacement) made to its text.
    fn edited_session(edits: &[(&str, &str)]) -> String {
        let mut quantity = QuantityState::new(Source::Volume(0), &RenderSettings::default());
        quantity.isosurfaces[0].visible = true;
        let object =
            ObjectState { path: Some("/data/water.cube".into()), quantities: vec![quantity], ..Default::default() };
        let mut text = toml::to_string_pretty(&Session { objects: vec![object], ..Default::default() }).unwrap();
        for (line, replacement) in edits {
            assert!(text.contains(line), "{line} not in the session");
            text = text.replacen(line, replacement, 1);
        }
        text
    }

    #[test]
    fn absurd_sessions_open_with_their_values_in_range_and_say_which_were_not() {
        let text = edited_session(&[
            ("slices = 192", "slices = 4000000000"),
            ("distance = 20.0", "distance = nan"),
            ("fov_y = 0.5235988", "fov_y = inf"),
            ("yaw = 0.0", "yaw = -inf"),
            ("count = 1", "count = 99"),
            ("k1 = 0.2", "k1 = -inf"),
            ("Absolute = 0.05", "Absolute = nan"),
            ("selected = 0", "selected = 12"),
            ("grid_points = 72", "grid_points = 100000"),
            ("ball_scale = 1.0", "ball_scale = 1e30"),
        ]);
        let Read { session, notes } = parse("absurd.orbcloud.toml", &text).expect("an absurd session still opens");
        for key in [
            "objects[0].quantities[0].cloud.slices: 4000000000 is outside 1..=4096",
            "camera.distance: NaN is not a finite number",
            "camera.fov_y: inf",
            "camera.yaw: -inf",
            "panes.count: 99",
            "objects[0].quantities[0].cloud.k1: -inf",
            "objects[0].quantities[0].isosurfaces[0].level.Absolute: NaN",
            "objects[0].selected: 12",
            "objects[0].evaluation.grid_points: 100000",
            "objects[0].atoms.ball_scale: 1000000000000000000000000000000 is outside 0.3..=3",
        ] {
            let line = format!("absurd.orbcloud.toml: {key}");
            assert!(notes.iter().any(|n| n.starts_with(&line)), "no note {line:?} in {notes:#?}");
        }
        assert_eq!(notes.len(), 10, "{notes:#?}");
        let cloud = &session.objects[0].quantities[0].cloud;
        let box_ = crate::scene::slicing::GridBox {
            origin: glam::Vec3::ZERO,
            edges: [glam::Vec3::X * 4.0, glam::Vec3::Y * 4.0, glam::Vec3::Z * 4.0],
        };
        let slices = box_.view_aligned(cloud.slices, session.camera.view_from_world().row(2).truncate());
        assert_eq!(slices.depths.len(), 4096);
        assert!(slices.vertices.iter().all(|v| v.is_finite()));
        assert!(session.camera.clip_from_world(1.5, 10.0).is_finite());
        assert!(session.camera.eye().is_finite());
        assert_eq!(session.objects[0].quantities[0].isosurfaces[0].level, IsoLevel::Absolute(0.05));
        // Written back, it reads without a note.
        let again = toml::to_string_pretty(&session).unwrap();
        assert_eq!(parse("again.orbcloud.toml", &again).unwrap(), Read { session, notes: Vec::new() });
        // A number no field can hold is refused, naming the file and the line.
        let e = parse("huge.orbcloud.toml", &edited_session(&[("slices = 192", "slices = 5000000000")])).unwrap_err();
        let line = edited_session(&[]).lines().position(|l| l == "slices = 192").unwrap() + 1;
        assert!(
            e.starts_with("huge.orbcloud.toml: not an orbcloud session") && e.contains(&format!("line {line}")),
            "{e}"
        );
    }

    /// An object as sessions wrote it before objects held several quantities: one cloud, the
    /// first isosurface in `settings.iso`, the rest in `isosurfaces`, the orbital in `quantity`.
    #[derive(serde::Serialize, Default)]
    struct OldObject {
        path: PathBuf,
        visible: bool,
        placement: Placement,
        settings: RenderSettings,
        isosurfaces: Vec<IsosurfaceSettings>,
        volume: usize,
        quantity: Option<Quantity>,
        selection: String,
    }

    fn old_session_object() -> String {
        let mut settings =
            RenderSettings { atoms: crate::scene::AtomStyle::Licorice, depth_cue: 0.25, ..Default::default() };
        settings.volume.visible = false;
        settings.volume.slices = 128;
        settings.volume.k1 = 0.3;
        settings.iso = IsosurfaceSettings { visible: true, level: IsoLevel::Sigma(2.5), ..Default::default() };
        let shell = IsosurfaceSettings {
            visible: true,
            level: IsoLevel::Absolute(0.02),
            translucent: true,
            ..Default::default()
        };
        toml::to_string_pretty(&OldObject {
            path: "/data/water.molden".into(),
            visible: true,
            placement: Placement { offset: [8.0, 0.0, -1.5], rotation_deg: [0.0, 90.0, 0.0] },
            settings,
            isosurfaces: vec![shell],
            volume: 0,
            quantity: Some(Quantity::Orbital(4)),
            selection: String::new(),
        })
        .unwrap()
    }

    #[test]
    fn an_object_saved_before_quantities_opens_as_one_quantity_with_all_its_isosurfaces() {
        let old: ObjectState = toml::from_str(&old_session_object()).expect("an old session object reads");
        assert_eq!(
            old.atoms,
            AtomLook { style: crate::scene::AtomStyle::Licorice, depth_cue: 0.25, ..Default::default() }
        );
        assert_eq!(old.placement.offset, [8.0, 0.0, -1.5]);
        assert_eq!(old.quantities.len(), 1);
        let q = &old.quantities[0];
        assert_eq!(q.source, Source::Wavefunction(Quantity::Orbital(4)));
        assert!(!q.cloud.visible && q.cloud.slices == 128 && q.cloud.k1 == 0.3);
        let levels: Vec<_> = q.isosurfaces.iter().map(|i| (i.level, i.translucent)).collect();
        assert_eq!(levels, [(IsoLevel::Sigma(2.5), false), (IsoLevel::Absolute(0.02), true)]);
        // Written again, it is today's form and reads back the same.
        let text = toml::to_string_pretty(&old).unwrap();
        assert!(!text.contains("[settings") && text.contains("[[quantities]]"), "{text}");
        assert_eq!(toml::from_str::<ObjectState>(&text).unwrap(), old);
    }

    /// Sessions written while each cloud had its own clipping plane: the plane on becomes the
    /// object's, and is written back as the object's.
    #[test]
    fn a_cloud_s_clipping_plane_becomes_its_object_s() {
        let defaults = RenderSettings::default();
        let quantity = |q| crate::scene::QuantityState::new(Source::Wavefunction(q), &defaults);
        let state = ObjectState {
            quantities: vec![quantity(Quantity::Orbital(3)), quantity(Quantity::Density)],
            ..Default::default()
        };
        // The same object as such a session wrote it: a plane in each cloud, none of its own.
        let mut old = toml::Value::try_from(&state).unwrap();
        let table = old.as_table_mut().unwrap();
        table.remove("clip");
        let plane = |on: bool, normal: [f64; 3], offset: f64| {
            let normal = toml::Value::Array(normal.iter().map(|&x| toml::Value::Float(x)).collect());
            let mut t = toml::Table::new();
            t.insert("enabled".into(), toml::Value::Boolean(on));
            t.insert("normal".into(), normal);
            t.insert("offset".into(), toml::Value::Float(offset));
            toml::Value::Table(t)
        };
        let clouds = table["quantities"].as_array_mut().unwrap();
        let planes = [plane(false, [1.0, 0.0, 0.0], 0.0), plane(true, [0.0, 1.0, 0.0], -1.5)];
        for (q, p) in clouds.iter_mut().zip(planes) {
            q["cloud"].as_table_mut().unwrap().insert("clip".into(), p);
        }
        let text = toml::to_string_pretty(&old).unwrap();
        assert!(text.contains("[quantities.cloud.clip]"), "{text}");
        let read: ObjectState = toml::from_str(&text).unwrap();
        let on = crate::scene::ClipPlane { enabled: true, normal: [0.0, 1.0, 0.0], offset: -1.5, atoms: false };
        assert_eq!(read.clip, on);
        assert!(read.quantities.iter().all(|q| q.cloud.stored_clip.is_none()));
        assert_eq!(read.quantities, state.quantities);
        let again = toml::to_string_pretty(&read).unwrap();
        assert!(again.contains("[clip]") && !again.contains("cloud.clip"), "{again}");
        assert_eq!(toml::from_str::<ObjectState>(&again).unwrap(), read);
        // Before quantities: the one cloud's plane in `settings.volume`.
        let mut older = toml::Value::try_from(OldObject::default()).unwrap();
        let volume = older["settings"]["volume"].as_table_mut().unwrap();
        volume.insert("clip".into(), plane(true, [0.0, 0.0, 2.0], 0.5));
        let read: ObjectState = toml::from_str(&toml::to_string_pretty(&older).unwrap()).unwrap();
        assert_eq!(read.clip, crate::scene::ClipPlane { normal: [0.0, 0.0, 2.0], offset: 0.5, ..on });
    }
}
