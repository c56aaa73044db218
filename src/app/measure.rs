//! Picking atoms in the view and measuring between them: the atom under the pointer is ringed
//! and named, a click selects an atom, Shift-click adds to the selection, and 2, 3 or 4 selected
//! atoms give a distance, an angle or a dihedral, kept in a list and drawn in the view.

use egui::{Color32, RichText, Stroke};

use super::World;
use super::viewport::{Click, Viewport};
use crate::gpu::frame::PickId;
use crate::model::Molecule;
use crate::model::measure::Measurement;
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::scene::Camera;

/// The picked atoms and the measurements kept: plain data.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Measurements {
    /// Atoms picked, in order (at most four).
    pub selection: Vec<usize>,
    pub list: Vec<Measurement>,
}

impl Measurements {
    /// Applies a click; returns a status line describing what was picked.
    pub fn click(&mut self, click: Click, world: &World) -> String {
        let molecule = &world.molecule;
        let Some(PickId::Atom { object, index }) = click.picked else {
            if click.picked.is_none() && !click.shift {
                self.selection.clear();
            }
            return match click.picked {
                Some(PickId::Surface { index, .. }) => format!("isosurface {}", index + 1),
                _ => String::new(),
            };
        };
        let Some(atom) = world.atom(object as usize, index as usize) else { return String::new() };
        let Some(a) = molecule.atoms.get(atom) else { return String::new() };
        let extends = click.shift && self.selection.len() < 4 && !self.selection.contains(&atom);
        if !extends {
            self.selection.clear();
        }
        self.selection.push(atom);
        if let Some(m) = Measurement::new(&self.selection) {
            // Growing a selection turns its distance into an angle, then a dihedral.
            let grown = self.list.last().is_some_and(|last| self.selection.starts_with(&last.atoms));
            if grown {
                self.list.pop();
            }
            let label = m.label(molecule);
            self.list.push(m);
            return label;
        }
        let p = a.position * ANGSTROM_PER_BOHR;
        let about = world.annotation(object as usize, index as usize).map(|s| format!(" ({s})")).unwrap_or_default();
        format!("atom {} {}{about} at {:.3} {:.3} {:.3} Å", atom + 1, a.element().symbol, p.x, p.y, p.z)
    }
}

const COLOR: Color32 = Color32::from_rgb(255, 220, 90);
/// Atoms labelled at most (beyond that the labels are unreadable anyway).
const MAX_LABELS: usize = 2000;

/// Draws the selection and the measurements over the view, and with `labels` every atom's
/// element and number.
pub fn overlay(ui: &egui::Ui, vp: &Viewport, camera: &Camera, world: &World, m: &Measurements, labels: bool) {
    let painter = ui.painter();
    let molecule = &world.molecule;
    let screen = |i: usize| molecule.atoms.get(i).and_then(|a| vp.to_screen(camera, a.position.as_vec3()));
    if labels {
        for (i, atom) in molecule.atoms.iter().enumerate().take(MAX_LABELS) {
            if let Some(p) = screen(i) {
                painter.text(
                    p + egui::vec2(7.0, -7.0),
                    egui::Align2::LEFT_BOTTOM,
                    format!("{}{}", atom.element().symbol, i + 1),
                    egui::FontId::proportional(13.0),
                    Color32::from_white_alpha(220),
                );
            }
        }
    }
    if let Some(PickId::Atom { object, index: own }) = vp.hovered
        && let Some(index) = world.atom(object as usize, own as usize)
        && let (Some(p), Some(atom)) = (screen(index), molecule.atoms.get(index))
    {
        painter.circle_stroke(p, 11.0, Stroke::new(1.5, Color32::from_white_alpha(160)));
        let about = world.annotation(object as usize, own as usize).map(|s| format!("  {s}")).unwrap_or_default();
        painter.text(
            p + egui::vec2(12.0, 10.0),
            egui::Align2::LEFT_TOP,
            format!("{}{}{about}", atom.element().symbol, index + 1),
            egui::FontId::proportional(14.0),
            Color32::WHITE,
        );
    }
    for &i in &m.selection {
        if let Some(p) = screen(i) {
            painter.circle_stroke(p, 9.0, Stroke::new(2.0, COLOR));
        }
    }
    for measurement in &m.list {
        let points: Option<Vec<egui::Pos2>> = measurement.atoms.iter().map(|&i| screen(i)).collect();
        let Some(points) = points else { continue };
        painter.add(egui::Shape::dashed_line(&points, Stroke::new(1.5, COLOR), 6.0, 4.0));
        let mid = points.iter().fold(egui::Vec2::ZERO, |s, p| s + p.to_vec2()) / points.len() as f32;
        let text = measurement.label(molecule);
        let value = text.rsplit_once(' ').map_or(text.as_str(), |(_, v)| v).to_string();
        painter.text(
            mid.to_pos2() + egui::vec2(6.0, -6.0),
            egui::Align2::LEFT_BOTTOM,
            value,
            egui::FontId::proportional(15.0),
            COLOR,
        );
    }
}

/// The side-panel list of measurements, each removable.
/// The list of measurements; with `scannable`, each has *Scan this…*, whose measurement's
/// index is returned when clicked.
pub fn panel(ui: &mut egui::Ui, molecule: &Molecule, m: &mut Measurements, scannable: bool) -> Option<usize> {
    ui.heading("Measurements");
    if m.list.is_empty() {
        ui.label(RichText::new("click an atom; Shift-click 2, 3 or 4 atoms to measure").small().weak());
    }
    let (mut remove, mut scan) = (None, None);
    for (n, measurement) in m.list.iter().enumerate() {
        ui.horizontal(|ui| {
            if ui.small_button("×").on_hover_text("remove").clicked() {
                remove = Some(n);
            }
            ui.label(measurement.label(molecule));
            if scannable && ui.small_button("Scan this…").on_hover_text("compute a scan of it with PySCF").clicked() {
                scan = Some(n);
            }
        });
    }
    if let Some(n) = remove {
        m.list.remove(n);
    }
    scan
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;
    use glam::DVec3;

    #[test]
    fn shift_clicks_grow_a_distance_into_an_angle_and_a_dihedral() {
        let atom = |x: f64, y: f64, z: f64| Atom { z: 6, charge: 6.0, position: DVec3::new(x, y, z), ghost: false };
        let mol =
            Molecule::new(vec![atom(0.0, 2.0, 0.0), atom(0.0, 0.0, 0.0), atom(2.8, 0.0, 0.0), atom(2.8, 0.0, 2.0)]);
        let mol = World { molecule: mol, offsets: vec![0], docs: Vec::new() };
        let mut m = Measurements::default();
        let pick = |i: u32, shift| Click { picked: Some(PickId::Atom { object: 0, index: i }), shift };
        assert!(m.click(pick(0, false), &mol).starts_with("atom 1 C"));
        assert!(m.click(pick(1, true), &mol).ends_with("Å"));
        m.click(pick(2, true), &mol);
        let label = m.click(pick(3, true), &mol);
        assert_eq!(m.list.len(), 1, "one dihedral, not a distance, an angle and a dihedral");
        assert_eq!(m.list[0].atoms, vec![0, 1, 2, 3]);
        assert!(label.ends_with("90.0°"), "{label}");
        // A plain click starts again; the kept dihedral stays.
        m.click(pick(2, false), &mol);
        m.click(pick(1, true), &mol);
        assert_eq!(m.list.len(), 2);
        m.click(Click { picked: None, shift: false }, &mol);
        assert!(m.selection.is_empty());
    }

    #[test]
    fn picks_in_a_second_object_number_through_the_scene() {
        let atom = |x: f64| Atom { z: 8, charge: 8.0, position: DVec3::new(x, 0.0, 0.0), ghost: false };
        let world = World {
            molecule: Molecule { atoms: vec![atom(0.0), atom(2.0), atom(10.0)], bonds: vec![] },
            offsets: vec![0, 2],
            docs: Vec::new(),
        };
        let mut m = Measurements::default();
        let pick = |object, index, shift| Click { picked: Some(PickId::Atom { object, index }), shift };
        assert!(m.click(pick(1, 0, false), &world).starts_with("atom 3 O"), "object 1's first atom is atom 3");
        let label = m.click(pick(0, 1, true), &world);
        assert!(label.ends_with(&format!("{:.3} Å", 8.0 * crate::model::units::ANGSTROM_PER_BOHR)), "{label}");
        assert_eq!(m.click(pick(1, 5, false), &world), "", "no such atom");
    }
}
