//! The NCI plot below the view (Johnson et al., 2010): the reduced density gradient s against
//! sign(λ₂)ρ at the points of a grid over the density, where each non-covalent interaction is a
//! spike reaching down to s = 0 (hydrogen bonds at sign(λ₂)ρ ≈ −0.02 to −0.04, van der Waals
//! contacts near 0, steric clashes positive). It shows while an NCI surface is the selected
//! quantity; the surface's level is the line across it. A drag across the plot picks a range of
//! sign(λ₂)ρ: the surface keeps its colours there only, so a spike is lit where it lies in 3-D.

use egui::RichText;
use egui_plot::{HLine, Plot, PlotPoints, PlotTransform, Points, VLine};

use super::jobs::Latest;
use crate::evaluate::interaction::{self, Kind};
use crate::evaluate::meshes::Evaluating;
use crate::model::Document;
use crate::model::GridSpec;
use crate::model::extent::quantity_box;
use crate::model::nci::{self, DensitySource, NciSettings, WAVEFUNCTION_DENSITY_CUT, WavefunctionDensity};
use crate::model::orbitals::Quantity;
use crate::scene::{Fragments, IsoLevel, QuantityState, Source};

/// The panel's height, points.
const HEIGHT: f32 = 220.0;

/// Grid points along the density box's longest side for the plot's points (fewer than a
/// surface's: a plot of tens of thousands of points reads the same).
const PLOT_POINTS: usize = 40;

/// The plot's axes: sign(λ₂)ρ within ±this (a.u.), s up to [`TOP_S`].
const SIGN_RHO_SPAN: f64 = 0.06;
const TOP_S: f64 = 2.0;

/// The points of an object's NCI plot and the job that makes them.
pub struct NciPlot {
    /// The document the points were made from (its source): another document makes them again.
    made_for: Option<String>,
    job: Latest<Result<Vec<[f64; 2]>, String>>,
    /// (sign(λ₂)ρ, s) of the grid's points below [`TOP_S`] and the density cut.
    pub points: Vec<[f64; 2]>,
    /// Where a drag across the plot began (sign(λ₂)ρ).
    drag_from: Option<f64>,
    /// Where the plot was last drawn (tests drag across it).
    pub transform: Option<PlotTransform>,
    /// (sign(λ₂)ρ, s) at the surface's point under the pointer, marked on the plot.
    pub hovered: Option<[f64; 2]>,
    /// The point it was evaluated at (object frame, bohr).
    hovered_at: Option<glam::Vec3>,
    pub error: Option<String>,
}

impl NciPlot {
    pub fn new(repaint: impl Fn() + Send + Sync + 'static) -> Self {
        Self {
            made_for: None,
            job: Latest::new("making the NCI plot", repaint),
            points: Vec::new(),
            drag_from: None,
            transform: None,
            hovered: None,
            hovered_at: None,
            error: None,
        }
    }

    /// Marks on the plot the point `at` (bohr, in `doc`'s own frame) of the surface under the
    /// pointer, or nothing.
    pub fn hover(&mut self, of: Evaluating, source: Source, at: Option<glam::Vec3>) {
        if at == self.hovered_at {
            return;
        }
        self.hovered_at = at;
        // The wavefunction's density, or a structure's spherical atoms, with its fragments'.
        let d = at.map(glam::Vec3::as_dvec3).and_then(|p| match (kind(source, of.fragments), &of.doc.wavefunction) {
            (Some(kind), _) => interaction::derivatives_at(of.doc, kind, of.fragments, of.others, p),
            (None, Some(wf)) => {
                let mut d = [nci::DensityDerivatives::default()];
                nci::WavefunctionDensity::new(wf).derivatives_at(&[p], &mut d);
                Some(d[0])
            }
            (None, None) => None,
        });
        self.hovered = d.map(|d| [d.sign_lambda2_rho(), d.reduced_gradient()]);
    }

    /// Whether its points are being made.
    pub fn is_busy(&self) -> bool {
        self.job.is_busy()
    }

    /// Shows the plot when `quantity`, of `doc`, is an NCI surface; a drag across it sets the
    /// surface's colour window.
    pub fn panel(
        &mut self,
        ui: &mut egui::Ui,
        doc: &Document,
        others: &[std::sync::Arc<Document>],
        quantity: Option<&mut QuantityState>,
    ) {
        let Some(q) = quantity.filter(|q| is_nci_surface(q.source)) else {
            self.transform = None;
            return;
        };
        self.refresh(doc, others, q);
        let cut = match q.source {
            Source::Promolecular(_) => nci::PROMOLECULAR_DENSITY_CUT,
            _ => WAVEFUNCTION_DENSITY_CUT,
        };
        let Some(iso) = q.isosurfaces.first_mut() else { return };
        egui::Panel::bottom("nci plot").exact_size(HEIGHT).show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.heading("NCI plot");
                let how = match (&self.error, self.job.is_busy()) {
                    (Some(e), _) => e.clone(),
                    (None, true) => "computing s and sign(λ₂)ρ on a grid…".to_string(),
                    (None, false) => format!("{} points with ρ < {cut}", self.points.len()),
                };
                ui.label(RichText::new(how).small().weak());
                if iso.color_window.is_some() && ui.small_button("show all").clicked() {
                    iso.color_window = None;
                }
            });
            ui.label(
                RichText::new("drag across the plot to light that range of sign(λ₂)ρ on the surface").small().weak(),
            );
            let level = match iso.level {
                IsoLevel::Absolute(v) => Some(f64::from(v)),
                IsoLevel::Sigma(_) => None,
            };
            let points = self.points.clone();
            let window = iso.color_window;
            let hovered = self.hovered;
            let response = Plot::new("nci plot")
                .x_axis_label("sign(λ₂)ρ (a.u.)")
                .y_axis_label("s")
                .allow_zoom(false)
                .allow_drag(false)
                .allow_scroll(false)
                .allow_boxed_zoom(false)
                .include_x(-SIGN_RHO_SPAN)
                .include_x(SIGN_RHO_SPAN)
                .include_y(0.0)
                .include_y(TOP_S)
                .show(ui, |plot| {
                    plot.points(Points::new("points", PlotPoints::new(points)).radius(1.0));
                    if let Some(level) = level {
                        plot.hline(HLine::new("surface", level));
                    }
                    if let Some(p) = hovered.filter(|p| p[0].abs() <= SIGN_RHO_SPAN && p[1] <= TOP_S) {
                        let mark = Points::new("under the pointer", vec![p]).radius(5.0).color(egui::Color32::YELLOW);
                        plot.points(mark);
                    }
                    if let Some([lo, hi]) = window {
                        plot.vline(VLine::new("from", f64::from(lo)));
                        plot.vline(VLine::new("to", f64::from(hi)));
                    }
                    let r = plot.response();
                    (r.drag_started(), r.dragged() || r.drag_stopped(), plot.pointer_coordinate())
                });
            self.transform = Some(response.transform);
            let (started, dragging, at) = response.inner;
            if let Some(at) = at {
                if started {
                    self.drag_from = Some(at.x);
                }
                if dragging && let Some(from) = self.drag_from {
                    let (lo, hi) = (from.min(at.x), from.max(at.x));
                    iso.color_window = Some([lo as f32, hi as f32]);
                }
            }
            if !dragging {
                self.drag_from = None;
            }
        });
    }

    /// Starts making the points when they were made for another document or surface; takes
    /// them when made.
    fn refresh(&mut self, doc: &Document, others: &[std::sync::Arc<Document>], q: &QuantityState) {
        if let Some(result) = self.job.poll() {
            match result.and_then(|r| r) {
                Ok(points) => (self.points, self.error) = (points, None),
                Err(e) => (self.points, self.error) = (Vec::new(), Some(e)),
            }
        }
        let key = format!("{} {:?} {:?}", doc.source, q.source, q.fragments);
        if self.made_for.as_deref() == Some(key.as_str()) {
            return;
        }
        self.made_for = Some(key);
        self.points.clear();
        let (doc, source, fragments, others) = (doc.clone(), q.source, q.fragments.clone(), others.to_vec());
        self.job
            .request(move |_| plot_points(Evaluating { doc: &doc, fragments: &fragments, others: &others }, source));
    }
}

/// Whether `source` is an NCI surface's: a wavefunction's, or a structure's spherical atoms'.
pub fn is_nci_surface(source: Source) -> bool {
    matches!(source, Source::Wavefunction(Quantity::NciGradient) | Source::Promolecular(Quantity::NciGradient))
}

/// The interaction `source` with `fragments` evaluates, when it is one ([`interaction`]).
fn kind(source: Source, fragments: &Fragments) -> Option<Kind> {
    interaction::of_source(source, fragments).map(|(kind, _)| kind)
}

/// (sign(λ₂)ρ, s) at the points of a grid over the density of `source` (a wavefunction's, or
/// spherical atoms', with `of`'s fragments) where ρ is below the cut and s below [`TOP_S`].
pub fn plot_points(of: Evaluating, source: Source) -> Result<Vec<[f64; 2]>, String> {
    let doc = of.doc;
    let grids = match kind(source, of.fragments) {
        Some(kind) => interaction::nci_grids(doc, kind, of.fragments, of.others, PLOT_POINTS)?,
        None => {
            let wf = doc.wavefunction.as_ref().ok_or("an NCI plot needs a wavefunction")?;
            let (lo, hi) = quantity_box(wf, &doc.molecule, Quantity::Density).ok_or("the molecule has no atoms")?;
            let grid = GridSpec::cubic_voxels(lo, hi, PLOT_POINTS);
            let density = WavefunctionDensity::new(wf);
            // Every s kept (the plot's own top cuts it): NCIPLOT's s > 1 cut is for its cubes.
            let settings = NciSettings {
                density_cut: WAVEFUNCTION_DENSITY_CUT,
                rdg_cut: nci::CUT_VALUE as f64,
                intermolecular: None,
            };
            nci::nci_grid(&[&density], &grid, settings)
        }
    };
    Ok((grids.dens.iter().zip(&grids.grad))
        .filter(|&(&d, &s)| d != nci::CUT_VALUE && f64::from(s) < TOP_S)
        .map(|(&d, &s)| [f64::from(d) / 100.0, f64::from(s)])
        .collect())
}
