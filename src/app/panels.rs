//! The side panel, top bar, status line and error window.

use egui::{ComboBox, RichText, Slider};

use super::Demo;
use super::OrbApp;
use crate::model::orbitals::Quantity;
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::scene::transfer::{Lobe, PRESETS};
use crate::scene::translucency::OpticsTuning;
use crate::scene::{
    AtomColoring, AtomStyle, ClipPlane, DensityScale, IsoLevel, IsosurfaceSettings, OpticsPreset, Shape, SliceMode,
    Source, Transfer, TransferKind, ViewPreset,
};

/// The side panel's width, points.
/// The scene panel's width as it opens, and the widths a drag of its edge may give it.
const SIDE_PANEL_WIDTH: f32 = 240.0;
const SIDE_PANEL_WIDTHS: std::ops::RangeInclusive<f32> = 220.0..=480.0;

pub enum Action {
    None,
    Open,
    SaveSession,
    ReopenLast,
    Screenshot,
    Record,
    ResetView,
    Demo(Demo),
}

pub fn top_bar(ui: &mut egui::Ui, app: &mut OrbApp) -> Action {
    let mut action = Action::None;
    egui::Panel::top("top bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.strong("orbcloud");
            ui.separator();
            if ui
                .button("Open…")
                .on_hover_text("cube, Molden, fchk, wfn, wfx, MKL, a scan or a saved session")
                .clicked()
            {
                action = Action::Open;
            }
            ui.checkbox(&mut app.open_replaces, "replace")
                .on_hover_text("opened and dropped files replace the scene instead of joining it");
            if ui.button("Save session…").on_hover_text("files, representations and camera").clicked() {
                action = Action::SaveSession;
            }
            if app.last_session.as_ref().is_some_and(|p| p.exists())
                && ui.button("Last session").on_hover_text("reopen what was open when orbcloud last closed").clicked()
            {
                action = Action::ReopenLast;
            }
            if ui.button("Save PNG").clicked() {
                action = Action::Screenshot;
            }
            if ui.button("Record…").on_hover_text("a movie: the scan swept, the scene turning, a vibration").clicked()
            {
                action = Action::Record;
            }
            if ui.button("Reset view").clicked() {
                action = Action::ResetView;
            }
            ui.menu_button("Demos", |ui| {
                for demo in Demo::ALL {
                    if ui.button(demo.label()).clicked() {
                        action = Action::Demo(demo);
                    }
                }
            });
            ui.separator();
            // The view takes the room of a closed panel; a drag on a panel's edge resizes it.
            ui.toggle_value(&mut app.view.panels.scene, "Scene").on_hover_text("show or hide the scene panel");
            if app.objects.get(app.active).is_some_and(|o| o.doc.wavefunction.is_some()) {
                ui.toggle_value(&mut app.view.panels.orbitals, "Orbitals")
                    .on_hover_text("show or hide the orbital browser");
            }
            if app.objects.get(app.active).is_some_and(|o| o.scan.is_none() && o.doc.molecule.atoms.len() >= 3) {
                ui.toggle_value(&mut app.plane.open, "Plane map")
                    .on_hover_text("the selected quantity on a plane through three atoms, with contours");
            }
            ui.separator();
            let source = match app.scan_object().and_then(|o| o.scan.as_ref()) {
                Some(s) => s.scan().title.clone(),
                None if app.objects.len() > 1 => format!("{} objects", app.objects.len()),
                None => app.doc().source.clone(),
            };
            ui.label(RichText::new(source).weak());
        });
    });
    action
}

pub fn status_bar(ui: &mut egui::Ui, app: &mut OrbApp) {
    let (mut cancel, mut dismiss) = (false, false);
    status_line(ui, app, &mut cancel, &mut dismiss);
    if cancel {
        app.cancel_jobs();
    }
    if dismiss {
        app.notice = None;
    }
}

fn status_line(ui: &mut egui::Ui, app: &OrbApp, cancel: &mut bool, dismiss: &mut bool) {
    egui::Panel::bottom("status").show(ui, |ui| {
        ui.horizontal(|ui| {
            if let Some(notice) = &app.notice {
                ui.label(RichText::new(notice).strong());
                *dismiss = ui.small_button("×").on_hover_text("dismiss").clicked();
                ui.separator();
            }
            if let Some(job) = &app.job {
                let (f, parsing) = job.0.progress();
                let text = if parsing { "parsing…".to_string() } else { format!("reading {:.0}%", 100.0 * f) };
                ui.add(egui::ProgressBar::new(f).desired_width(160.0).text(text));
                ui.label(job.0.path.display().to_string());
                ui.separator();
            }
            if let Some((what, done)) = app.busy() {
                match done {
                    Some(f) => {
                        ui.add(egui::ProgressBar::new(f).desired_width(160.0).text(format!("{:.0}%", 100.0 * f)));
                    }
                    None => {
                        ui.spinner();
                    }
                }
                ui.label(what);
                if ui.button("Cancel").on_hover_text("stop it; what is shown stays").clicked() {
                    *cancel = true;
                }
                ui.separator();
            }
            super::record::record_status(ui, app);
            if let Some(job) = &app.scan_job {
                let (done, total) = job.progress();
                let f = if total == 0 { 0.0 } else { done as f32 / total as f32 };
                ui.add(egui::ProgressBar::new(f).desired_width(160.0).text(format!("key volumes {done}/{total}")));
                ui.label(&job.name);
                if ui.button("Cancel").clicked() {
                    job.cancel();
                }
                ui.separator();
            }
            if let Some(scan) = app.scan_object().and_then(|o| o.scan.as_ref()) {
                let s = scan.scan();
                let c = &s.coordinate;
                ui.label(format!(
                    "{}: {}, {} key frames {}…{}",
                    s.title,
                    c.label(),
                    s.frames.len(),
                    c.value_text(s.range().0),
                    c.value_text(s.range().1)
                ));
                if !app.status.is_empty() {
                    ui.separator();
                    ui.label(RichText::new(&app.status).weak());
                }
                return;
            }
            if app.objects.is_empty() && app.scan_job.is_some() {
                ui.label("its first frame is shown while the orbitals of every key frame are evaluated on the GPU");
                return;
            }
            let m = &app.doc().molecule;
            ui.label(format!("{} atoms ({}), {} bonds", m.atoms.len(), m.formula(), m.bonds.len()));
            let shown = app.shown_atoms();
            if shown < m.atoms.len() {
                ui.label(format!("· {shown} shown"));
            }
            if let Some(note) = app.fragment_note() {
                ui.separator();
                ui.label(RichText::new(note).weak());
            }
            let selected = app.active_object().and_then(|o| o.state.selected_quantity()).map(|q| q.source);
            if let (Some(wf), Some(i)) = (&app.doc().wavefunction, selected.and_then(Source::orbital)) {
                let o = &wf.orbitals[i];
                ui.separator();
                // "HOMO a1 −0.4985 Eh": the spin only where it tells something (unrestricted).
                let spin = match (wf.restricted, o.spin) {
                    (true, _) => "",
                    (false, crate::model::Spin::Alpha) => " α",
                    (false, crate::model::Spin::Beta) => " β",
                };
                let symmetry = if o.symmetry.is_empty() { String::new() } else { format!(" {}", o.symmetry) };
                ui.label(format!(
                    "{}{spin}{symmetry} {}, occupation {:.2}",
                    wf.frontier_label(i, 50).unwrap_or_else(|| format!("MO {}", i + 1)),
                    wf.energy_text(i),
                    o.occupation
                ));
            }
            if let Some(g) = app.shown_values() {
                ui.separator();
                let h: Vec<String> = (0..3).map(|a| format!("{:.3}", g.step(a).length())).collect();
                ui.label(format!(
                    "grid {}×{}×{}, spacing {} bohr, values {:.3e} … {:.3e}",
                    g.dims[0],
                    g.dims[1],
                    g.dims[2],
                    h.join("/"),
                    g.stats.min,
                    g.stats.max
                ));
            }
            if !app.status.is_empty() {
                ui.separator();
                ui.label(RichText::new(&app.status).weak());
            }
        });
    });
}

pub fn side_panel(ui: &mut egui::Ui, app: &mut OrbApp) {
    // Opening a section never makes the panel jump: its width changes only by a drag on its edge.
    let mut open = app.view.panels.scene;
    egui::Panel::left("controls")
        .resizable(true)
        .default_size(SIDE_PANEL_WIDTH)
        .size_range(SIDE_PANEL_WIDTHS)
        .show_collapsible(ui, &mut open, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
            super::scene_panel::section(ui, app);
            // Before the quantity's editors, which it adds to: never below the fold.
            promolecular_nci(ui, app);
            if !app.objects.is_empty() {
                ui.separator();
            }
            let (grid_sigma, grid_signed) = app.shown_grid();
            let subtractable = app.subtractable();
            let open: Vec<String> = (app.objects.iter().enumerate())
                .filter(|&(n, o)| n != app.active && o.scan.is_none())
                .map(|(_, o)| o.doc.source.clone())
                .collect();
            let mut joined = None;
            if let Some(o) = app.objects.get_mut(app.active) {
                if let Some(scan) = &o.scan {
                    let g = scan.keys.grid.dims;
                    ui.label(format!(
                        "{} key volumes of {}×{}×{} points ({:.1} MiB resident)",
                        scan.keys.slots() * scan.scan().frames.len(),
                        g[0],
                        g[1],
                        g[2],
                        scan.keys.bytes as f64 / 1048576.0
                    ));
                }
                let doc = o.doc.clone();
                let mut subtract = None;
                let state = &mut o.state;
                match state.selected_quantity_mut() {
                    Some(q) => {
                        ui.heading(q.source.name(&doc));
                        if doc.volumes.len() > 1 && matches!(q.source, Source::Volume(_)) {
                            data_set_choice(ui, &doc, &mut q.source);
                        }
                        subtract = minus_choice(ui, &subtractable);
                        joined = fragments_editor(ui, q, &open);
                        // Isosurfaces first: for orbitals the most used, and never below the fold.
                        let colors = super::scene_panel::quantity_choices(&doc);
                        let gradient = matches!(
                            q.source,
                            Source::Wavefunction(Quantity::ReducedGradient | Quantity::NciGradient)
                                | Source::Promolecular(Quantity::ReducedGradient | Quantity::NciGradient)
                        );
                        let levels = LevelsOf { signed: grid_signed, sigma: grid_sigma, gradient };
                        isosurfaces_editor(ui, &mut q.isosurfaces, levels, &colors);
                        ui.separator();
                        ui.heading("Cloud");
                        cloud_editor(ui, &mut q.cloud, grid_signed);
                    }
                    None if doc.wavefunction.is_some() => {
                        ui.label("nothing of the wavefunction is shown: choose it under Orbitals");
                    }
                    None => {}
                }
                ui.separator();
                ui.heading("Atoms");
                let a = &mut state.atoms;
                atoms_editor(ui, &mut a.style, &mut a.colors, &mut a.depth_cue);
                ui.add(Slider::new(&mut a.ball_scale, 0.3..=3.0).text("ball size (×)"));
                ui.add(Slider::new(&mut a.stick_scale, 0.3..=3.0).text("stick radius (×)"));
                ui.separator();
                clip_editor(ui, &mut state.clip);
                if let Some(m) = subtract {
                    app.start_difference(m, ui.ctx());
                }
                // A fragment added stands where its file puts it, as the active object's
                // atoms do: both are drawn as their densities are summed.
                if let Some(file) = joined {
                    let placement = app.objects[app.active].state.placement;
                    if let Some(f) = app.objects.iter_mut().find(|o| o.doc.source == file) {
                        f.state.placement = placement;
                    }
                }
            }
            if let Some(model) = super::models::controls(ui, app) {
                app.show_model(model);
            }
            super::models::selection(ui, app);
            let view = &mut app.view;
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(&mut view.background);
                ui.label("background");
            });
            ui.checkbox(&mut view.labels, "atom labels");
            view_presets(ui, app);
            ui.separator();
            // A scan's measured values follow its value (its skeleton is the scene's atoms); a
            // measurement of a scan is not scanned again.
            let scannable = app.scan_object().is_none();
            if let Some(n) = super::measure::panel(ui, &app.world.molecule, &mut app.measurements, scannable) {
                app.scan_measurement(n);
            }
            // A structure without orbitals offers to compute them (small molecules: PySCF).
            let bare = app.objects.get(app.active).filter(|o| {
                o.scan.is_none() && o.doc.wavefunction.is_none() && (1..=60).contains(&o.doc.molecule.atoms.len())
            });
            if bare.is_some() && ui.button("Compute orbitals…").on_hover_text("with PySCF").clicked() {
                app.orbitals_dialog = Some((app.active, crate::sources::compute::Settings::default()));
            }

            ui.separator();
            ui.collapsing("Atoms in file", |ui| {
                // A scan's atoms where they are at the value: its document's.
                let molecule = &app.doc().molecule;
                // Coordinates in columns of their own, so none is cut off by the panel's edge.
                egui::Grid::new("atoms").striped(true).num_columns(5).show(ui, |ui| {
                    for h in ["", "", "x / Å", "y / Å", "z / Å"] {
                        ui.label(RichText::new(h).strong());
                    }
                    ui.end_row();
                    for (i, a) in molecule.atoms.iter().enumerate().take(500) {
                        let p = a.position * ANGSTROM_PER_BOHR;
                        ui.label(format!("{}", i + 1));
                        ui.label(format!("{}{}", a.element().symbol, if a.ghost { "*" } else { "" }))
                            .on_hover_text(if a.ghost { "ghost atom: basis functions, no nucleus" } else { "" });
                        for c in [p.x, p.y, p.z] {
                            ui.label(RichText::new(format!("{c:.3}")).monospace());
                        }
                        ui.end_row();
                    }
                });
            });
            ui.separator();
            let scan = app.scan_object().and_then(|o| Some((o.scan.as_ref()?, o.state.scan.as_ref()?)));
            let help = match scan {
                Some((s, state)) if state.drag_scans => format!(
                    "drag: {} · right/middle drag: pan · wheel: zoom · arrows: rotate · Space: play · [ ]: key values",
                    super::scan::drag_words(&s.scan().coordinate)
                ),
                Some((s, _)) => format!(
                    "drag: rotate (from the bond: {}) · right/middle drag: pan · wheel: zoom · Space: play",
                    super::scan::drag_words(&s.scan().coordinate)
                ),
                None if app.plane.open => {
                    "drag: rotate · right/middle drag: pan · wheel: zoom · Alt + wheel: move the plane".into()
                }
                None => "drag: rotate · right/middle drag: pan · wheel: zoom · arrows, +/−: keys".into(),
            };
            ui.label(RichText::new(help).small().weak());
        });
        });
    app.view.panels.scene = open;
}

/// An NCI quantity's fragments: the other open files whose densities add to the object's (as
/// NCIPLOT adds its files'), and whether only what lies between them is kept. Returns a file
/// just added.
fn fragments_editor(ui: &mut egui::Ui, q: &mut crate::scene::QuantityState, open: &[String]) -> Option<String> {
    let nci = matches!(
        q.source,
        Source::Promolecular(_)
            | Source::Wavefunction(Quantity::NciGradient | Quantity::NciCloud | Quantity::SignLambda2Rho)
    );
    if !nci || open.is_empty() {
        return None;
    }
    let mut added = None;
    ui.label(RichText::new("fragments: their densities add").small());
    let fragments = &mut q.fragments;
    for file in open {
        let name = file.rsplit(['/', '\\']).next().unwrap_or(file);
        let mut with = fragments.files.contains(file);
        if ui.checkbox(&mut with, format!("+ {name}")).on_hover_text(file.as_str()).changed() {
            match with {
                true => {
                    // The first fragment: what lies between them is what is usually asked.
                    fragments.between_only |= fragments.files.is_empty();
                    fragments.files.push(file.clone());
                    added = Some(file.clone());
                }
                false => fragments.files.retain(|f| f != file),
            }
        }
    }
    if !fragments.files.is_empty() {
        ui.checkbox(&mut fragments.between_only, "only between the fragments").on_hover_text(
            "keep the points where no fragment holds 95 % of the density (NCIPLOT's intermolecular mode)",
        );
    }
    added
}

/// A structure (no wavefunction, no data set) offers the NCI surface of its spherical atoms: of
/// all of them, or between the atoms a selection picks (a ligand) and the rest (its pocket).
fn promolecular_nci(ui: &mut egui::Ui, app: &mut OrbApp) {
    let Some(o) = app.objects.get_mut(app.active) else { return };
    // A structure's (a cube file shows its own field; a wavefunction its NCI under Orbitals).
    let structure = o.doc.wavefunction.is_none() && o.doc.volumes.is_empty();
    if o.scan.is_some() || !structure || o.doc.molecule.atoms.is_empty() {
        return;
    }
    ui.separator();
    ui.label(RichText::new("Non-covalent interactions").strong());
    ui.horizontal(|ui| {
        let label = ui.label("between");
        let edit = egui::TextEdit::singleline(&mut app.nci_between)
            .hint_text("resn LIG (empty: all atoms)")
            .desired_width(150.0);
        ui.add(edit)
            .labelled_by(label.id)
            .on_hover_text("the atoms this selection picks and all the others: a ligand and its pocket");
        ui.label("and the rest");
    });
    let between = Some(app.nci_between.trim().to_string()).filter(|b| !b.is_empty());
    let mut shown = None;
    ui.horizontal(|ui| {
        let hint = "the reduced density gradient of the spherical atoms (s = 0.3 where ρ < 0.07), coloured by \
                    sign(λ₂)ρ: blue hydrogen bonds, green van der Waals contacts, red steric clashes";
        if ui.button("NCI surface").on_hover_text(hint).clicked() {
            shown = Some(crate::scene::QuantityState::promolecular_nci(&app.defaults, between.clone()));
        }
        let hint = "the same interactions as a cloud: blue where λ₂ < 0 (attraction), red where λ₂ > 0";
        if ui.button("NCI cloud").on_hover_text(hint).clicked() {
            let mut cloud = crate::scene::QuantityState::nci_cloud(&app.defaults);
            cloud.source = Source::Promolecular(Quantity::NciCloud);
            cloud.fragments.selection = between.clone();
            shown = Some(cloud);
        }
    });
    let Some(quantity) = shown else { return };
    let surface = quantity.isosurfaces.iter().any(|i| i.visible);
    let state = &mut o.state;
    state.quantities.iter_mut().for_each(|q| q.visible = false);
    state.quantities.push(quantity);
    state.selected = state.quantities.len() - 1;
    if surface {
        app.frame_beside_bar();
    }
}

/// *minus*: another open file whose same quantity is subtracted from this one, as a new data
/// set of the object; the file picked.
fn minus_choice(ui: &mut egui::Ui, files: &[(usize, String)]) -> Option<usize> {
    if files.is_empty() {
        return None;
    }
    let mut picked = None;
    ui.horizontal(|ui| {
        let label = ui.label("minus");
        ComboBox::from_id_salt("minus")
            .selected_text("another file's…")
            .show_ui(ui, |ui| {
                for (m, name) in files {
                    if ui.selectable_label(false, name).clicked() {
                        picked = Some(*m);
                    }
                }
            })
            .response
            .labelled_by(label.id)
            .on_hover_text("this quantity minus the same quantity of another open file, on this one's grid: a new data set (a density difference)");
    });
    picked
}

/// Which of a file's data sets a quantity shows (cube files with several).
fn data_set_choice(ui: &mut egui::Ui, doc: &crate::model::Document, source: &mut Source) {
    let label = ui.label("data set");
    let Source::Volume(shown) = source else { return };
    ComboBox::from_id_salt("data set")
        .width(220.0)
        .selected_text(doc.volumes.get(*shown).map_or("?", |v| v.label.as_str()))
        .show_ui(ui, |ui| {
            for (i, v) in doc.volumes.iter().enumerate() {
                ui.selectable_value(shown, i, &v.label);
            }
        })
        .response
        .labelled_by(label.id);
}

/// A cloud's settings: shown or not, slicing, opacity law, colours and transfer function.
/// `signed`: an orbital's two signs (else a density's scale).
fn cloud_editor(ui: &mut egui::Ui, vs: &mut crate::scene::VolumeSettings, signed: bool) {
    ui.checkbox(&mut vs.visible, "show cloud");
    ui.horizontal(|ui| {
        ui.label("slices");
        ui.selectable_value(&mut vs.mode, SliceMode::ViewAligned, "view-aligned");
        ui.selectable_value(&mut vs.mode, SliceMode::AxisAligned, "axis stacks");
    });
    ui.add(Slider::new(&mut vs.slices, 16..=512).text("slice count"));
    ui.horizontal(|ui| {
        // Room for the value, the name and the auto box within the panel.
        ui.spacing_mut().slider_width = 70.0;
        let k1 = ui.add(Slider::new(&mut vs.k1, 0.0..=2.0).logarithmic(true).text("k1 (opacity)"));
        if k1.changed() {
            vs.auto_k1 = false;
        }
        ui.checkbox(&mut vs.auto_k1, "auto")
            .on_hover_text("k1 from the grid: its densest lines of sight reach an optical depth of 2.5");
    });
    ui.add(Slider::new(&mut vs.k2, 0.1..=3.0).text("k2 (shape)"));
    if !signed {
        density_scale_editor(ui, &mut vs.density_scale);
    }
    let (pos, neg) = if signed { ("ψ > 0", "ψ < 0") } else { ("dense", "thin") };
    ui.horizontal(|ui| {
        ui.color_edit_button_rgb(&mut vs.positive_color);
        ui.label(pos);
        ui.color_edit_button_rgb(&mut vs.negative_color);
        ui.label(neg);
    });
    let law = if signed {
        "α = k1·ρ^k2 per grid step, ρ = ψ² scaled to its maximum"
    } else {
        "α = k1·t^k2 per grid step, t = the density on the scale above"
    };
    ui.label(RichText::new(law).small().weak());
    ComboBox::from_label("colour preset").selected_text("choose…").show_ui(ui, |ui| {
        for (name, pos, neg) in PRESETS {
            if ui.selectable_label(false, *name).clicked() {
                vs.positive_color = *pos;
                vs.negative_color = *neg;
            }
        }
    });
    transfer_editor(ui, &mut vs.transfer, signed);
}

/// What an isosurface's level is a level of: a signed field's (ψ = ±v), a density's (ρ = v) or
/// a reduced density gradient's (s = v, levels around 0.5, not a density's around 0.002);
/// `sigma`: the grid's standard deviation, where levels may be given in it.
#[derive(Clone, Copy)]
struct LevelsOf {
    signed: bool,
    sigma: Option<f64>,
    gradient: bool,
}

/// Every isosurface of a quantity, each with its own controls, and *+ isosurface*.
fn isosurfaces_editor(
    ui: &mut egui::Ui,
    list: &mut Vec<IsosurfaceSettings>,
    levels: LevelsOf,
    colors: &[(Source, String)],
) {
    ui.heading("Isosurfaces");
    let mut remove = None;
    for (k, iso) in list.iter_mut().enumerate() {
        ui.push_id(k, |ui| {
            egui::Frame::group(ui.style()).show(ui, |ui| {
                isosurface_editor(ui, iso, levels);
                color_by_editor(ui, iso, colors);
                if ui.small_button("remove").on_hover_text("remove this isosurface").clicked() {
                    remove = Some(k);
                }
            });
        });
    }
    if let Some(k) = remove {
        list.remove(k);
    }
    if ui.button("+ isosurface").on_hover_text("another value of the same quantity (nested shells)").clicked() {
        list.push(another_isosurface(list));
    }
}

/// A new isosurface at half the value of the last one (the next shell out), shown.
pub fn another_isosurface(list: &[IsosurfaceSettings]) -> IsosurfaceSettings {
    let last = list.last().copied().unwrap_or_default();
    let level = match last.level {
        IsoLevel::Absolute(v) if list.is_empty() => IsoLevel::Absolute(v),
        IsoLevel::Absolute(v) => IsoLevel::Absolute(v * 0.5),
        IsoLevel::Sigma(s) => IsoLevel::Sigma(s * 0.5),
    };
    IsosurfaceSettings { visible: true, level, ..last }
}

/// How atoms are drawn: style, colouring, depth cue.
fn atoms_editor(ui: &mut egui::Ui, style: &mut AtomStyle, colors: &mut AtomColoring, depth_cue: &mut f32) {
    ComboBox::from_label("style").selected_text(style.name()).show_ui(ui, |ui| {
        for s in AtomStyle::ALL {
            ui.selectable_value(style, s, s.name());
        }
    });
    ComboBox::from_label("colour by").selected_text(colors.name()).show_ui(ui, |ui| {
        for coloring in AtomColoring::ALL {
            ui.selectable_value(colors, coloring, coloring.name());
        }
    });
    ui.add(Slider::new(depth_cue, 0.0..=1.0).text("depth cue"))
        .on_hover_text("Darkens atoms with depth, so the front of a big structure reads from its back");
}

/// The view presets: as a new file opens, along the axes, down a bond or onto a plane of the
/// selected atoms.
fn view_presets(ui: &mut egui::Ui, app: &mut OrbApp) {
    let selected = app.measurements.selection.clone();
    let mut preset = None;
    ui.horizontal_wrapped(|ui| {
        ui.label("view");
        for (name, p, hint) in [
            ("auto", ViewPreset::Auto, "the principal axes, tilted so no bond points at you"),
            ("x", ViewPreset::AlongX, "along the x axis"),
            ("y", ViewPreset::AlongY, "along the y axis"),
            ("z", ViewPreset::AlongZ, "along the z axis"),
        ] {
            if ui.button(name).on_hover_text(hint).clicked() {
                preset = Some(p);
            }
        }
        let bond = ui.add_enabled(selected.len() >= 2, egui::Button::new("down bond"));
        if bond.on_hover_text("from the first selected atom down its bond to the second").clicked() {
            preset = Some(ViewPreset::Bond(selected[0], selected[1]));
        }
        let plane = ui.add_enabled(selected.len() >= 3, egui::Button::new("onto plane"));
        if plane.on_hover_text("perpendicular to the plane of the three selected atoms").clicked() {
            preset = Some(ViewPreset::Plane(selected[0], selected[1], selected[2]));
        }
    });
    if let Some(p) = preset {
        app.look(p);
    }
}

pub fn error_window(ui: &mut egui::Ui, app: &mut OrbApp) {
    let Some(message) = app.error.clone() else {
        return;
    };
    let mut open = true;
    egui::Window::new("Could not open").open(&mut open).collapsible(false).show(ui.ctx(), |ui| {
        ui.label(RichText::new(&message).color(ui.visuals().error_fg_color));
        ui.horizontal(|ui| {
            if let Some((source, fits)) = app.scan_retry.clone()
                && ui.button(format!("Open with {fits} points")).on_hover_text("a coarser common grid").clicked()
            {
                app.scan_points = fits;
                app.error = None;
                app.scan_retry = None;
                app.open_scan(source, ui.ctx());
            }
            if ui.button("Dismiss").clicked() {
                app.error = None;
                app.scan_retry = None;
            }
        });
    });
    if !open {
        app.error = None;
        app.scan_retry = None;
    }
}

/// One lobe's shape, centre, width and opacity, and its curve over the signed value: 0 … 1 for
/// ψ > 0 (and densities), −1 … 0 for ψ < 0 (`sign` −1), as Jang and Varetto draws its shapes.
fn lobe_editor(ui: &mut egui::Ui, label: &str, lobe: &mut Lobe, sign: f32) {
    ui.horizontal(|ui| {
        ui.label(label);
        ComboBox::from_id_salt(label).selected_text(lobe.shape.name()).show_ui(ui, |ui| {
            for shape in Shape::ALL {
                ui.selectable_value(&mut lobe.shape, shape, shape.name());
            }
        });
    });
    let width_label = if lobe.shape == Shape::Sinusoidal { "spacing" } else { "width" };
    ui.add(Slider::new(&mut lobe.center, 0.0..=1.0).text("centre (× max)"));
    ui.add(Slider::new(&mut lobe.width, 0.005..=0.5).logarithmic(true).text(width_label));
    ui.add(Slider::new(&mut lobe.opacity, 0.0..=2.0).text("opacity"));
    let (rect, _) = ui.allocate_exact_size(egui::vec2(ui.available_width().min(220.0), 36.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, ui.visuals().extreme_bg_color);
    let points: Vec<egui::Pos2> = (0..=100)
        .map(|i| {
            let x = i as f32 / 100.0;
            // Left to right: 0 … 1 for the positive lobe, −1 … 0 for the negative one.
            let s = if sign > 0.0 { x } else { x - 1.0 };
            let f = lobe.factor(s, sign);
            egui::pos2(rect.left() + x * rect.width(), rect.bottom() - f * (rect.height() - 2.0))
        })
        .collect();
    painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, ui.visuals().strong_text_color())));
}

/// How a density maps onto the transfer function: log between bounds (a.u.) or its maximum.
fn density_scale_editor(ui: &mut egui::Ui, scale: &mut DensityScale) {
    ui.horizontal(|ui| {
        ui.label("density scale");
        let log = matches!(scale, DensityScale::Log { .. });
        if ui.selectable_label(log, "log").on_hover_text("shows the valence shell and the molecule's surface").clicked()
        {
            *scale = DensityScale::default();
        }
        if ui.selectable_label(!log, "linear").on_hover_text("ρ / max ρ: the nuclear cusps dominate").clicked() {
            *scale = DensityScale::Linear;
        }
    });
    if let DensityScale::Log { lo, hi } = scale {
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(lo).speed(0.0001).range(1e-8..=1.0).prefix("from ").suffix(" a.u."));
            ui.add(egui::DragValue::new(hi).speed(0.01).range(1e-6..=1e4).prefix("to ").suffix(" a.u."));
        });
    }
}

fn transfer_editor(ui: &mut egui::Ui, t: &mut Transfer, signed: bool) {
    ui.collapsing("Transfer function", |ui| {
        ui.horizontal(|ui| {
            ui.selectable_value(&mut t.kind, TransferKind::PowerLaw, "power law (k1, k2)");
            ui.selectable_value(&mut t.kind, TransferKind::Shaped, "shapes");
        });
        if t.kind == TransferKind::Shaped {
            if signed
                && ui
                    .button("nested cores")
                    .on_hover_text("left half on ψ > 0, right half on ψ < 0, peaked at the extremes: the nested cores")
                    .clicked()
            {
                t.nested_cores();
            }
            if signed {
                lobe_editor(ui, "ψ > 0", &mut t.positive, 1.0);
                lobe_editor(ui, "ψ < 0", &mut t.negative, -1.0);
            } else {
                lobe_editor(ui, "density", &mut t.positive, 1.0);
            }
        }
        ui.checkbox(&mut t.shading, "shading from the gradient");
        ui.add(Slider::new(&mut t.boundary, 0.0..=1.0).text("boundary enhancement"));
        ui.add(Slider::new(&mut t.gradient_power, 0.0..=3.0).text("gradient weight (2D)"));
    });
}

/// The object's clipping plane: on or off, its normal and offset, and whether it cuts atoms.
fn clip_editor(ui: &mut egui::Ui, clip: &mut ClipPlane) {
    ui.collapsing("Clipping plane", |ui| {
        ui.checkbox(&mut clip.enabled, "clip")
            .on_hover_text("cut the clouds, isosurfaces and molecular surface on the far side of the plane");
        ui.checkbox(&mut clip.atoms, "cut atoms and bonds too");
        ui.horizontal(|ui| {
            ui.label("normal");
            for (c, name) in clip.normal.iter_mut().zip(["x", "y", "z"]) {
                ui.add(egui::DragValue::new(c).speed(0.02).range(-1.0..=1.0).prefix(name));
            }
        });
        ui.horizontal(|ui| {
            for (name, n) in [("x", [1.0, 0.0, 0.0]), ("y", [0.0, 1.0, 0.0]), ("z", [0.0, 0.0, 1.0])] {
                if ui.button(format!("normal {name}")).clicked() {
                    clip.normal = n;
                }
            }
        });
        ui.add(Slider::new(&mut clip.offset, -15.0..=15.0).text("offset (bohr)"))
            .on_hover_text("from the centre of the object's bounds, along the normal");
        ui.label(RichText::new("Ctrl + drag in the view moves the plane").small().weak());
    });
}

/// Isosurface controls: shown or not, the value (absolute, or in σ of a cube's grid), colours.
fn isosurface_editor(ui: &mut egui::Ui, iso: &mut IsosurfaceSettings, levels: LevelsOf) {
    let LevelsOf { signed, sigma, gradient } = levels;
    let what = match (signed, gradient) {
        (_, true) => "show s = value",
        (true, false) => "show ψ = ±value",
        (false, false) => "show ρ = value",
    };
    ui.checkbox(&mut iso.visible, what);
    ui.horizontal(|ui| {
        let absolute = matches!(iso.level, IsoLevel::Absolute(_));
        if ui.selectable_label(absolute, "atomic units").clicked() && !absolute {
            iso.level = IsoLevel::Absolute(iso.level.value(sigma.unwrap_or(1.0)).max(1e-4));
        }
        if let Some(sigma) = sigma.filter(|s| *s > 0.0)
            && ui.selectable_label(!absolute, "× σ of the grid").clicked()
            && absolute
        {
            iso.level = IsoLevel::Sigma((iso.level.value(sigma) as f64 / sigma) as f32);
        }
    });
    match &mut iso.level {
        IsoLevel::Absolute(v) if gradient => {
            ui.add(Slider::new(v, 0.05..=2.0).text("value"))
                .on_hover_text("s is dimensionless: NCI surfaces are drawn at 0.3 to 0.6");
        }
        IsoLevel::Absolute(v) => {
            ui.add(Slider::new(v, 1e-4..=0.5).logarithmic(true).text("value (a.u.)"));
        }
        IsoLevel::Sigma(s) => {
            ui.add(Slider::new(s, 0.1..=20.0).logarithmic(true).text("σ"));
        }
    }
    ui.horizontal(|ui| {
        if signed {
            ui.color_edit_button_rgb(&mut iso.positive_color);
            ui.label("+");
            ui.color_edit_button_rgb(&mut iso.negative_color);
            ui.label("−");
        } else {
            ui.color_edit_button_rgb(&mut iso.density_color);
            ui.label("surface");
        }
    });
    translucency_editor(ui, iso);
}

/// Colouring an isosurface by another quantity of its object (the electrostatic potential on a
/// density surface), and the range of the map.
fn color_by_editor(ui: &mut egui::Ui, iso: &mut IsosurfaceSettings, choices: &[(Source, String)]) {
    let name = |s: Option<Source>| match s {
        None => "its own colour".to_string(),
        Some(s) => choices.iter().find(|(c, _)| *c == s).map_or("another quantity".into(), |(_, n)| n.clone()),
    };
    ui.horizontal(|ui| {
        let label = ui.label("colour by");
        // A data set's long label (a cube's comment line) is cut to the box, not wrapped.
        ComboBox::from_id_salt("colour by")
            .width(150.0)
            .wrap_mode(egui::TextWrapMode::Truncate)
            .selected_text(name(iso.color_by))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut iso.color_by, None, name(None));
                for (source, label) in choices {
                    ui.selectable_value(&mut iso.color_by, Some(*source), label);
                }
            })
            .response
            .labelled_by(label.id);
    });
    if iso.color_by.is_some() {
        ui.horizontal(|ui| {
            let mut automatic = iso.color_range.is_none();
            if ui
                .checkbox(&mut automatic, "automatic range")
                .on_hover_text("±98th percentile of |value| on the surface")
                .changed()
            {
                iso.color_range = if automatic { None } else { Some(0.05) };
            }
            if let Some(r) = &mut iso.color_range {
                ui.add(Slider::new(r, 1e-4..=1.0).logarithmic(true).text("± (a.u.)"));
            }
        });
    }
}

/// Translucent or opaque, and the look of a translucent surface (Koide and Miyata's optics).
pub fn translucency_editor(ui: &mut egui::Ui, iso: &mut IsosurfaceSettings) -> bool {
    ui.horizontal(|ui| {
        let mut changed = ui
            .checkbox(&mut iso.translucent, "translucent")
            .on_hover_text("see every surface through the others, in exact depth order; overlaps with other objects' surfaces glow")
            .changed();
        if iso.translucent {
            let optics =
                egui::ComboBox::from_id_salt(ui.next_auto_id()).selected_text(iso.optics.label()).show_ui(ui, |ui| {
                    for preset in OpticsPreset::ALL {
                        changed |= ui.selectable_value(&mut iso.optics, preset, preset.label()).changed();
                    }
                });
            optics.response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "optics"));
        }
        changed
    })
    .inner
        | (iso.translucent && coefficients_editor(ui, &mut iso.tuning))
}

/// Koide and Miyata's coefficients of a translucent surface, per R, G, B, as factors on its preset.
fn coefficients_editor(ui: &mut egui::Ui, tuning: &mut OpticsTuning) -> bool {
    let mut changed = false;
    egui::CollapsingHeader::new("coefficients").id_salt(ui.next_auto_id()).show(ui, |ui| {
        ui.label(
            RichText::new("× the preset's, per R G B: a diffuse, b c n highlight, d f emission, g thickness; glow_: inside another object's surface")
                .small()
                .weak(),
        );
        egui::Grid::new(ui.next_auto_id()).num_columns(4).show(ui, |ui| {
            for name in OpticsTuning::NAMES {
                ui.label(name);
                if let Some(factors) = tuning.factors_mut(name) {
                    for k in factors.iter_mut() {
                        changed |= ui.add(egui::DragValue::new(k).speed(0.01).range(0.0..=10.0)).changed();
                    }
                }
                ui.end_row();
            }
        });
        if ui.button("preset as it is").clicked() {
            *tuning = OpticsTuning::default();
            changed = true;
        }
    });
    changed
}
