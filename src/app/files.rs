//! Choosing files without the system's file dialog: where there is no dialog backend (no
//! portal, no zenity: a bare X server, a session over SSH) the native dialog returns at once with
//! nothing, and the window offers this instead: a path field, the folder's entries, and the
//! files opened recently.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::RichText;

/// What the chosen file is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    Open,
    SaveSession,
    SavePng,
    /// A plane map's figure, PNG or SVG.
    SaveMap,
}

impl Purpose {
    fn title(self) -> &'static str {
        match self {
            Purpose::Open => "Open a file",
            Purpose::SaveSession => "Save the session",
            Purpose::SavePng => "Save the picture",
            Purpose::SaveMap => "Save the plane map",
        }
    }

    /// Whether a file of this name is listed (folders always are).
    fn lists(self, name: &str) -> bool {
        let name = name.to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        match self {
            Purpose::Open => {
                crate::formats::extensions().chain([".scan.toml"]).any(|e| name.ends_with(e))
                    || name.ends_with(crate::scene::objects::SESSION_SUFFIX)
            }
            Purpose::SaveSession => name.ends_with(crate::scene::objects::SESSION_SUFFIX),
            Purpose::SavePng => name.ends_with(".png"),
            Purpose::SaveMap => name.ends_with(".png") || name.ends_with(".svg"),
        }
    }
}

/// The system's dialog for `purpose`, `None` when it was cancelled or there is none. A dialog
/// that answers in less than this was not shown: no person cancels that fast.
pub const NO_DIALOG: Duration = Duration::from_millis(250);

/// What the system's file dialog answered.
#[derive(Debug, Clone, PartialEq)]
pub enum Native {
    /// A path, or `None` when the user cancelled.
    Answered(Option<PathBuf>),
    /// It answered too fast to have been shown: there is no dialog here.
    Missing,
}

/// Asks the system's file dialog.
pub fn native(purpose: Purpose, file_name: &str) -> Native {
    let start = Instant::now();
    let dialog = rfd::FileDialog::new();
    let chosen = match purpose {
        Purpose::Open => dialog
            .add_filter(
                "Cube, Molden, fchk, wfn, wfx, MKL, PDB, mmCIF, XYZ, Gaussian/ORCA log, scan, session",
                &crate::formats::extensions()
                    .filter_map(|e| e.rsplit('.').next())
                    .chain(["toml", "gz"])
                    .collect::<Vec<_>>(),
            )
            .pick_file(),
        Purpose::SaveSession => dialog.add_filter("orbcloud session", &["toml"]).set_file_name(file_name).save_file(),
        Purpose::SavePng => dialog.add_filter("PNG image", &["png"]).set_file_name(file_name).save_file(),
        Purpose::SaveMap => {
            dialog.add_filter("PNG or SVG figure", &["png", "svg"]).set_file_name(file_name).save_file()
        }
    };
    if chosen.is_none() && start.elapsed() < NO_DIALOG { Native::Missing } else { Native::Answered(chosen) }
}

/// The in-window file chooser.
pub struct FileBrowser {
    pub purpose: Purpose,
    pub dir: PathBuf,
    /// The path field: a name in `dir` or a whole path.
    pub name: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

/// What the user did in the browser this frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Choice {
    None,
    Chosen(PathBuf),
    Closed,
}

impl FileBrowser {
    pub fn new(purpose: Purpose, dir: PathBuf, name: &str) -> Self {
        let mut browser = Self { purpose, dir, name: name.into(), entries: Vec::new(), error: None };
        browser.refresh();
        browser
    }

    /// Lists `dir`: folders first, then the files this purpose can use, each by name.
    fn refresh(&mut self) {
        self.entries.clear();
        match std::fs::read_dir(&self.dir) {
            Ok(read) => {
                for entry in read.flatten() {
                    let name = entry.file_name().to_string_lossy().into_owned();
                    let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
                    if !name.starts_with('.') && (is_dir || self.purpose.lists(&name)) {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.to_lowercase().cmp(&b.0.to_lowercase())));
                self.error = None;
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }

    fn enter(&mut self, dir: PathBuf) {
        self.dir = dir;
        self.refresh();
    }

    /// The path the field names: itself when absolute, else inside `dir`.
    pub fn typed_path(&self) -> PathBuf {
        let typed = Path::new(self.name.trim());
        if typed.is_absolute() { typed.to_path_buf() } else { self.dir.join(typed) }
    }

    /// Shows the chooser; `recent` lists files opened before (newest first).
    pub fn show(&mut self, ctx: &egui::Context, recent: &[PathBuf]) -> Choice {
        let mut choice = Choice::None;
        let mut open = true;
        egui::Window::new(self.purpose.title()).open(&mut open).collapsible(false).default_width(460.0).show(
            ctx,
            |ui| {
                ui.horizontal(|ui| {
                    if ui.button("up").on_hover_text("the folder above").clicked()
                        && let Some(parent) = self.dir.parent()
                    {
                        let parent = parent.to_path_buf();
                        self.enter(parent);
                    }
                    ui.label(RichText::new(self.dir.display().to_string()).weak());
                });
                let field = ui.horizontal(|ui| {
                    ui.label("path");
                    let field = ui.add(egui::TextEdit::singleline(&mut self.name).desired_width(300.0));
                    let go = ui.button(if self.purpose == Purpose::Open { "Open" } else { "Save" });
                    (field, go)
                });
                let (field, go) = field.inner;
                let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                if (entered || go.clicked()) && !self.name.trim().is_empty() {
                    let path = self.typed_path();
                    if path.is_dir() {
                        self.name.clear();
                        self.enter(path);
                    } else if self.purpose == Purpose::Open && !path.exists() {
                        self.error = Some(format!("{}: no such file", path.display()));
                    } else {
                        choice = Choice::Chosen(path);
                    }
                }
                if let Some(e) = &self.error {
                    ui.label(RichText::new(e).color(ui.visuals().error_fg_color));
                }
                ui.separator();
                egui::ScrollArea::vertical().max_height(300.0).id_salt("entries").show(ui, |ui| {
                    let mut go_into = None;
                    for (name, is_dir) in &self.entries {
                        let label = if *is_dir { format!("{name}/") } else { name.clone() };
                        if ui.selectable_label(false, label).clicked() {
                            if *is_dir {
                                go_into = Some(self.dir.join(name));
                            } else if self.purpose == Purpose::Open {
                                choice = Choice::Chosen(self.dir.join(name));
                            } else {
                                self.name = name.clone();
                            }
                        }
                    }
                    if self.entries.is_empty() {
                        ui.label(RichText::new("no files here that orbcloud reads").weak());
                    }
                    if let Some(dir) = go_into {
                        self.enter(dir);
                    }
                });
                if self.purpose == Purpose::Open && !recent.is_empty() {
                    ui.separator();
                    ui.label("recent");
                    for path in recent {
                        if ui.selectable_label(false, path.display().to_string()).clicked() {
                            choice = Choice::Chosen(path.clone());
                        }
                    }
                }
            },
        );
        if !open { Choice::Closed } else { choice }
    }
}

/// Keeps `path` first in `recent`, at most `keep` entries.
pub fn remember(recent: &mut Vec<PathBuf>, path: &Path, keep: usize) {
    let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    recent.retain(|p| p != &path);
    recent.insert(0, path);
    recent.truncate(keep);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_folders_and_readable_files_and_remembers_recent_ones() {
        let dir = std::env::temp_dir().join(format!("orbcloud-files-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        for name in ["b.molden", "a.cube.gz", "notes.txt", "scene.orbcloud.toml", "x.scan.toml", "shot.png"] {
            std::fs::write(dir.join(name), "").unwrap();
        }
        let browser = FileBrowser::new(Purpose::Open, dir.clone(), "");
        let names: Vec<&str> = browser.entries.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["sub", "a.cube.gz", "b.molden", "scene.orbcloud.toml", "x.scan.toml"]);
        let pngs = FileBrowser::new(Purpose::SavePng, dir.clone(), "x.png");
        assert_eq!(pngs.entries.len(), 2, "the folder and shot.png");
        assert_eq!(pngs.typed_path(), dir.join("x.png"));
        let mut recent = Vec::new();
        for name in ["a.cube.gz", "b.molden", "a.cube.gz"] {
            remember(&mut recent, &dir.join(name), 2);
        }
        assert_eq!(recent.len(), 2);
        assert!(recent[0].ends_with("a.cube.gz") && recent[1].ends_with("b.molden"));
        std::fs::remove_dir_all(dir).ok();
    }
}
