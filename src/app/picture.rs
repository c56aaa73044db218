//! *Save PNG*: a picture of what the window shows at any size, supersampled, with a transparent
//! background if asked; a scan's views captioned as the window labels them. The name proposed
//! comes from the file and what it shows (`benzene_homo.png`), in the folder last saved to.

use std::path::Path;

use super::{OrbApp, files};
use crate::gpu::GpuError;
use crate::pictures::figure::{Figure, MAX_SCALE};
use crate::pictures::shots::caption_views;

/// The choices of the *Save PNG* window.
pub struct PictureDialog {
    pub open: bool,
    /// The picture's size (each view's, for a scan); the view's own when none is chosen.
    pub size: Option<[u32; 2]>,
    pub scale: u32,
    pub transparent: bool,
}

impl Default for PictureDialog {
    fn default() -> Self {
        Self { open: false, size: None, scale: 1, transparent: false }
    }
}

/// A file-name word from a quantity's name: "HOMO β" → "homo_beta", "LUMO+1" → "lumo+1".
fn name_word(name: &str) -> String {
    let word: String = name
        .replace('β', "beta")
        .replace('α', "alpha")
        .chars()
        .map(|c| if c.is_alphanumeric() || c == '+' || c == '-' { c.to_ascii_lowercase() } else { '_' })
        .collect();
    word.trim_matches('_').to_string()
}

/// The stem of a file name without its extensions (`benzene.molden.gz` → `benzene`).
pub fn file_stem(source: &str) -> String {
    let name = Path::new(source).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    name.split('.').next().filter(|s| !s.is_empty()).unwrap_or("orbcloud").to_string()
}

/// A name for a picture of `source`'s quantity: `benzene_homo.png`.
pub fn picture_name(source: &str, quantity: Option<&str>) -> String {
    let stem = file_stem(source);
    match quantity.map(name_word).filter(|w| !w.is_empty()) {
        Some(q) => format!("{stem}_{q}.png"),
        None => format!("{stem}.png"),
    }
}

impl OrbApp {
    /// The size of the view on screen.
    fn shown_size(&self) -> [u32; 2] {
        self.viewport.as_ref().and_then(super::viewport::Viewport::size).unwrap_or([1280, 800])
    }

    /// Opens the *Save PNG* window at the view's size.
    pub fn open_picture_dialog(&mut self) {
        self.picture.size = Some(self.shown_size());
        self.picture.open = true;
    }

    /// The name *Save PNG* proposes: the file and its orbital, or a scan's title and value.
    fn proposed_picture_name(&self) -> String {
        match self.scan_object().and_then(|o| Some((o.scan.as_ref()?, o.state.scan.as_ref()?))) {
            Some((scan, state)) => picture_name(&scan.scan().title, Some(&format!("{:.0}deg", state.value))),
            None => {
                let quantity = (self.objects.get(self.active))
                    .and_then(|o| o.state.quantities.get(o.state.selected).map(|q| q.source.name(&o.doc)));
                picture_name(&self.doc().source, quantity.as_deref())
            }
        }
    }

    /// Asks where to save the picture (cancelling writes nothing).
    fn choose_picture_file(&mut self) {
        let name = self.proposed_picture_name();
        if let Some(path) = self.choose(files::Purpose::SavePng, &name) {
            self.save_png(&path);
        }
    }

    /// Renders the current view (each scan view side by side, captioned) as the *Save PNG*
    /// window says and writes it to `path` as PNG.
    pub fn save_png(&mut self, path: &Path) {
        let size = self.picture.size.unwrap_or_else(|| self.shown_size()).map(|s| s.clamp(16, 8192));
        // A scan's panes are captioned as the window labels them (its view `p` in pane `p`).
        let scan = self.scan_object().and_then(|o| Some((o.scan.as_ref()?.keys.clone(), o.state.scan.as_ref()?.value)));
        let Some(vp) = &mut self.viewport else { return };
        let d = &self.picture;
        let figure = Figure { scale: d.scale.clamp(1, MAX_SCALE), transparent: d.transparent };
        let drawn = figure.drawn_size(size);
        let mut view = self.view;
        let background = view.background;
        let shot: Result<image::RgbaImage, GpuError> = match () {
            // A split view: its panes side by side, as drawn.
            () if !vp.pane_sizes().is_empty() => {
                let pictures: Result<Vec<_>, _> = (0..vp.pane_sizes().len()).map(|p| vp.pane_picture(p)).collect();
                pictures.map(|pictures| {
                    let (w, h) = pictures.first().map_or((1, 1), image::ImageBuffer::dimensions);
                    let mut out = image::RgbaImage::new(w * pictures.len() as u32, h);
                    for (n, picture) in pictures.iter().enumerate() {
                        image::imageops::replace(&mut out, picture, (n as u32 * w) as i64, 0);
                    }
                    if let Some((keys, value)) = &scan {
                        let slots: Vec<usize> = (0..pictures.len().min(keys.slots())).collect();
                        caption_views(&mut out, keys, &slots, *value, w);
                    }
                    out
                })
            }
            () => figure.draw(background, |bg| {
                view.background = bg;
                vp.snapshot(&view, drawn)
            }),
        };
        match shot.map(|img| img.save(path)) {
            Ok(Ok(())) => {
                self.status = format!("saved {}", path.display());
                self.last_folder = path.parent().map(Path::to_path_buf);
            }
            Ok(Err(e)) => self.error = Some(format!("{}: {e}", path.display())),
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

/// The *Save PNG* window: size, supersampling, a transparent background, then where.
pub fn picture_window(ctx: &egui::Context, app: &mut OrbApp) {
    if !app.picture.open {
        return;
    }
    let mut open = true;
    let mut save = false;
    let shown = app.shown_size();
    let panes = app.viewport.as_ref().is_some_and(|v| !v.pane_sizes().is_empty());
    egui::Window::new("Save PNG").open(&mut open).resizable(false).show(ctx, |ui| {
        let d = &mut app.picture;
        let size = d.size.get_or_insert(shown);
        ui.add_enabled_ui(!panes, |ui| {
            egui::Grid::new("picture options").num_columns(2).show(ui, |ui| {
                ui.label("size");
                ui.horizontal(|ui| {
                    ui.add(egui::DragValue::new(&mut size[0]).range(16..=8192));
                    ui.label("×");
                    ui.add(egui::DragValue::new(&mut size[1]).range(16..=8192));
                });
                ui.end_row();
                ui.label("supersampling");
                ui.add(egui::DragValue::new(&mut d.scale).range(1..=MAX_SCALE).suffix("×"))
                    .on_hover_text("drawn larger and filtered down: smooth edges");
                ui.end_row();
                ui.label("");
                ui.checkbox(&mut d.transparent, "transparent background");
                ui.end_row();
            });
        });
        if panes {
            ui.label(egui::RichText::new("panes are saved as drawn").weak().small());
        }
        save = ui.button("Save…").clicked();
    });
    app.picture.open &= open && !save;
    if save {
        app.choose_picture_file();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_come_from_the_file_and_the_quantity() {
        assert_eq!(picture_name("/x/benzene.molden.gz", Some("HOMO")), "benzene_homo.png");
        assert_eq!(picture_name("water.fchk", Some("LUMO+1 β")), "water_lumo+1_beta.png");
        assert_eq!(picture_name("a.cube", None), "a.png");
        assert_eq!(file_stem(""), "orbcloud");
    }
}
