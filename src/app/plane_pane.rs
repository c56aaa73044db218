//! The plane map beside the 3-D view: the active object's selected quantity on a plane through
//! three of its atoms, at an offset along the plane's normal, evaluated exactly from its
//! wavefunction (a cube's values interpolated) with contour lines and a colour bar
//! ([`crate::plane`]). The plane's outline is drawn in the view; a change of the plane, the
//! quantity or the file makes the map again in the background, a coarse one first so the pane
//! follows a dragged offset at once. *Save map* writes the figure as PNG or SVG.

use std::path::Path;
use std::sync::Arc;

use egui::RichText;

use super::jobs::Latest;
use glam::DVec3;

use crate::model::Document;
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::plane::{self, ColorScale, Frame, Levels, MapPicture, PlaneMap};
use crate::scene::Source;

/// Points per side of the map drawn while the plane moves, before the full one.
const COARSE_POINTS: usize = 60;
/// The map's points per side a user may choose.
const POINT_CHOICES: [usize; 4] = [100, 200, 300, 500];
/// How far the plane may be moved from the atoms (Å).
const MAX_OFFSET: f64 = 10.0;

/// Which plane: through three atoms (1-based), or by a point and a normal (bohr, the object's
/// frame: the plane the view faced when asked).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Through {
    Atoms([usize; 3]),
    Facing { origin: DVec3, normal: DVec3 },
}

/// What a map is of: a document's quantity on a plane moved `offset` Å along its normal, at
/// `points` per side.
#[derive(Clone)]
struct Asked {
    doc: Arc<Document>,
    source: Source,
    through: Through,
    offset: f64,
    points: usize,
    gradient_lines: bool,
}

impl PartialEq for Asked {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.doc, &other.doc)
            && (self.source, self.through, self.offset.to_bits(), self.points, self.gradient_lines)
                == (other.source, other.through, other.offset.to_bits(), other.points, other.gradient_lines)
    }
}

/// A map made, with what its figure says.
pub struct Made {
    asked: Asked,
    map: PlaneMap,
    levels: Vec<f64>,
    caption: Vec<String>,
    unit: String,
    scale: Option<ColorScale>,
    figure: egui::ColorImage,
}

impl Made {
    /// The values on the plane's points.
    pub fn map(&self) -> &PlaneMap {
        &self.map
    }

    /// The plane's offset from the atoms it passes through (Å).
    pub fn offset(&self) -> f64 {
        self.asked.offset
    }

    fn picture(&self) -> MapPicture<'_> {
        MapPicture {
            map: &self.map,
            molecule: &self.asked.doc.molecule,
            levels: &self.levels,
            caption: self.caption.clone(),
            unit: self.unit.clone(),
            scale: self.scale,
            gradient_lines: self.asked.gradient_lines,
            bohr: false,
        }
    }
}

/// The pane's state: the plane asked for and the map shown.
pub struct PlanePane {
    pub open: bool,
    /// The plane (of the active object).
    pub through: Through,
    /// Along the plane's normal, Å.
    pub offset: f64,
    pub points: usize,
    /// Gradient lines from the atoms near the plane.
    pub gradient_lines: bool,
    jobs: Latest<Result<Made, String>>,
    /// The map shown, and its texture.
    shown: Option<(Made, egui::TextureHandle)>,
    /// The last map asked for (coarse or full), so a change is asked once.
    asked: Option<Asked>,
    pub error: Option<String>,
}

impl PlanePane {
    pub fn new(repaint: impl Fn() + Send + Sync + 'static) -> Self {
        Self {
            open: false,
            through: Through::Atoms([1, 2, 3]),
            offset: 0.0,
            points: 200,
            gradient_lines: false,
            jobs: Latest::new("making the plane map", repaint),
            shown: None,
            asked: None,
            error: None,
        }
    }

    /// Moves the plane `angstrom` along its normal, within the offsets the pane allows.
    pub fn nudge(&mut self, angstrom: f64) {
        self.offset = (self.offset + angstrom).clamp(-MAX_OFFSET, MAX_OFFSET);
    }

    /// The map shown, once one is made.
    pub fn made(&self) -> Option<&Made> {
        self.shown.as_ref().map(|(m, _)| m)
    }

    /// Whether a map is being made.
    pub fn is_busy(&self) -> bool {
        self.jobs.is_busy()
    }

    /// Asks for the map of `doc`'s `source` on the current plane when it is not the one shown
    /// or coming: a coarse map first, then (when it arrives) the full one.
    fn ask(&mut self, doc: &Arc<Document>, source: Source) {
        let full = Asked {
            doc: doc.clone(),
            source,
            through: self.through,
            offset: self.offset,
            points: self.points,
            gradient_lines: self.gradient_lines,
        };
        let coarse = Asked { points: COARSE_POINTS.min(self.points), ..full.clone() };
        let shown = self.shown.as_ref().map(|(m, _)| &m.asked);
        if shown == Some(&full) || self.asked.as_ref() == Some(&full) {
            return;
        }
        // The coarse map of this plane is shown or coming: the full one is next.
        let next = if shown == Some(&coarse) || self.asked.as_ref() == Some(&coarse) { full } else { coarse };
        self.asked = Some(next.clone());
        self.jobs.request(move |_| make(next));
    }

    /// Takes a map that was made.
    fn poll(&mut self, ctx: &egui::Context) {
        match self.jobs.poll() {
            Some(Ok(Ok(made))) => {
                let texture = ctx.load_texture("plane map", made.figure.clone(), egui::TextureOptions::LINEAR);
                self.shown = Some((made, texture));
                self.error = None;
            }
            Some(Ok(Err(e)) | Err(e)) => {
                self.error = Some(e);
                // Asked again only when the plane or the quantity changes.
            }
            None => {}
        }
    }

    /// Writes the map shown as `path` (PNG or SVG by its name).
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let made = self.made().ok_or("no map has been made yet")?;
        let picture = made.picture();
        let name = path.display();
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("svg") => std::fs::write(path, plane::svg(&picture)).map_err(|e| format!("{name}: {e}")),
            Some("png") => plane::png(&picture).save(path).map_err(|e| format!("{name}: {e}")),
            _ => Err(format!("{name}: a map is saved as PNG or SVG (a .png or .svg name)")),
        }
    }
}

/// Makes the map `asked` names, and its figure.
fn make(asked: Asked) -> Result<Made, String> {
    let doc = &asked.doc;
    let m = &doc.molecule;
    let name = |i: usize| m.atoms.get(i - 1).map_or(String::new(), |a| format!("{}{i}", a.element().symbol));
    let (frame, keep_origin, how) = match asked.through {
        Through::Atoms(atoms) => {
            let [a, b, c] = atoms;
            (Frame::through_atoms(m, atoms), false, format!("plane through {} {} {}", name(a), name(b), name(c)))
        }
        Through::Facing { origin, normal } => (Frame::from_normal(origin, normal), true, "the view's plane".into()),
    };
    let plane = frame
        .and_then(|f| f.offset(asked.offset * BOHR_PER_ANGSTROM).rectangle(m, None, asked.points, keep_origin))
        .map_err(|e| e.to_string())?;
    let map = plane::evaluate(doc, asked.source, &plane).map_err(|e| e.to_string())?;
    let levels = if map.vanishes() { Vec::new() } else { Levels::Auto.resolve(map.max_abs(), map.signed) };
    let file = Path::new(&doc.source).file_name().map_or(doc.source.clone(), |n| n.to_string_lossy().into_owned());
    let caption = vec![format!("{file} · {}", asked.source.name(doc)), plane::where_text(&how, &plane, asked.offset)];
    let scale = plane::scale_for(asked.source, &map);
    let unit = plane::unit(asked.source).to_string();
    let picture = MapPicture {
        map: &map,
        molecule: m,
        levels: &levels,
        caption: caption.clone(),
        unit: unit.clone(),
        scale,
        gradient_lines: asked.gradient_lines,
        bohr: false,
    };
    let image = plane::png(&picture);
    let figure =
        egui::ColorImage::from_rgba_unmultiplied([image.width() as usize, image.height() as usize], image.as_raw());
    Ok(Made { asked, map, levels, caption, unit, scale, figure })
}

/// The pane beside the view: the plane's controls and its map. `doc` and `source` are the
/// active object's and its selected quantity's; `measured` the atoms of the last measurement
/// (1-based, of this object); `facing` the plane the view faces (its target and line of
/// sight, in the object's frame). Returns whether *Save map* was pressed.
pub fn panel(
    ui: &mut egui::Ui,
    pane: &mut PlanePane,
    (doc, source): (&Arc<Document>, Option<Source>),
    measured: Option<[usize; 3]>,
    facing: Through,
) -> bool {
    pane.poll(ui.ctx());
    let mut save = false;
    let mut open = pane.open;
    egui::Panel::right("plane map").resizable(true).default_size(420.0).size_range(360.0..=900.0).show_collapsible(
        ui,
        &mut open,
        |ui| {
            ui.heading("Plane map");
            let Some(source) = source else {
                ui.label("choose a quantity of the object to map");
                return;
            };
            let n = doc.molecule.atoms.len();
            if n < 3 {
                ui.label("a plane through three atoms needs a molecule of three atoms or more");
                return;
            }
            ui.label(RichText::new(source.name(doc)).strong());
            ui.horizontal_wrapped(|ui| {
                ui.label("through atoms");
                let mut atoms = match pane.through {
                    Through::Atoms(atoms) => atoms,
                    Through::Facing { .. } => [1, 2, 3],
                };
                let mut changed = false;
                for a in &mut atoms {
                    changed |= ui.add(egui::DragValue::new(a).range(1..=n)).changed();
                }
                if changed || matches!(pane.through, Through::Atoms(_)) {
                    pane.through = Through::Atoms(atoms);
                }
                if let Some(atoms) = measured
                    && ui
                        .button("the atoms measured")
                        .on_hover_text("the plane through the last angle or dihedral measured")
                        .clicked()
                {
                    pane.through = Through::Atoms(atoms);
                }
                if ui
                    .selectable_label(matches!(pane.through, Through::Facing { .. }), "the view's plane")
                    .on_hover_text("the plane through the view's centre facing the viewer, as the view is now")
                    .clicked()
                {
                    pane.through = facing;
                }
            });
            ui.horizontal_wrapped(|ui| {
                ui.add(
                    egui::Slider::new(&mut pane.offset, -MAX_OFFSET..=MAX_OFFSET)
                        .suffix(" Å")
                        .text("offset")
                        .fixed_decimals(2),
                )
                .on_hover_text("move the plane along its normal (a π orbital 0.5 Å above a ring)");
            });
            ui.horizontal_wrapped(|ui| {
                ui.label("points");
                for p in POINT_CHOICES {
                    ui.selectable_value(&mut pane.points, p, p.to_string());
                }
                ui.checkbox(&mut pane.gradient_lines, "gradient lines")
                    .on_hover_text("paths down the quantity's gradient from the atoms in the plane");
            });
            pane.ask(doc, source);
            if let Some(e) = &pane.error {
                ui.colored_label(ui.visuals().warn_fg_color, e);
            }
            if let Some((made, texture)) = &pane.shown {
                let size = texture.size_vec2();
                let width = ui.available_width().min(size.x.max(1.0) * 2.0);
                ui.image((texture.id(), size * (width / size.x.max(1.0))));
                let note = if made.asked.points < pane.points && pane.is_busy() {
                    format!("{0}×{0} points; the full map is on its way", made.asked.points)
                } else {
                    match made.map.sampling {
                        plane::Sampling::Exact => "exact from the wavefunction at every point".into(),
                        plane::Sampling::Trilinear { .. } => "a cube file's values, interpolated".into(),
                    }
                };
                ui.label(RichText::new(note).small().weak());
                save = ui.button("Save map…").on_hover_text("the figure as PNG or SVG").clicked();
            } else if pane.is_busy() {
                ui.spinner();
            }
        },
    );
    pane.open = open;
    save
}

/// The plane's frame in the view, in its object's frame: the map's rectangle and a diagonal
/// (none before a map is made). The renderer draws it where the plane lies
/// ([`crate::gpu::plane_frame`]), so atoms in front of the plane hide it.
pub fn frame_lines(pane: &PlanePane) -> Vec<[glam::Vec3; 2]> {
    let Some(made) = pane.made() else { return Vec::new() };
    let plane = &made.map.plane;
    let [w, h] = plane.size.map(|s| s * 0.5);
    let corners = [(-w, -h), (w, -h), (w, h), (-w, h)]
        .map(|(x, y)| (plane.center + plane.frame.u * x + plane.frame.v * y).as_vec3());
    let mut lines: Vec<[glam::Vec3; 2]> = (0..4).map(|k| [corners[k], corners[(k + 1) % 4]]).collect();
    lines.push([corners[0], corners[2]]);
    lines
}
