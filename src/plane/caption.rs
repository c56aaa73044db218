//! What a map's figure says besides its values: the colour bar's title, the plane in words,
//! and the colour scale a potential needs. The command line and the window caption alike.

use super::{ColorScale, Plane, PlaneMap};
use crate::model::orbitals::Quantity;
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::scene::Source;

/// The colour bar's title: the quantity's symbol and unit.
pub fn unit(source: Source) -> &'static str {
    match source {
        Source::Wavefunction(Quantity::Orbital(_)) => "ψ (a.u.)",
        Source::Wavefunction(Quantity::BasisFunction(_)) => "χ (a.u.)",
        Source::Wavefunction(Quantity::Density) => "ρ (a.u.)",
        Source::Wavefunction(Quantity::SpinDensity) => "ρα − ρβ (a.u.)",
        Source::Wavefunction(Quantity::Potential) => "V (a.u.)",
        Source::Wavefunction(Quantity::DensityLaplacian) => "Laplacian of ρ (a.u.)",
        Source::Wavefunction(Quantity::ReducedGradient) => "s",
        Source::Wavefunction(Quantity::NciGradient) => "s (ρ ≤ 0.05 a.u.)",
        Source::Wavefunction(Quantity::NciCloud) => "sign(λ₂)ρ (1 − s/0.5) (a.u.)",
        Source::Wavefunction(Quantity::SignLambda2Rho) => "sign(λ₂)ρ (a.u.)",
        Source::Wavefunction(Quantity::DifferenceDensity) => "ρ_exc − ρ_gs (a.u.)",
        Source::Wavefunction(Quantity::Attachment) => "attachment ρ (a.u.)",
        Source::Wavefunction(Quantity::Detachment) => "detachment ρ (a.u.)",
        Source::Wavefunction(Quantity::ExcitedDensity) => "ρ_exc (a.u.)",
        _ => "value",
    }
}

/// The caption's second line: the plane (`how`), its offset (Å), its points and extent.
pub fn where_text(how: &str, plane: &Plane, offset: f64) -> String {
    let n = plane.points;
    let [w, h] = plane.size.map(|s| s * ANGSTROM_PER_BOHR);
    let offset = if offset != 0.0 { format!(", offset {offset} Å") } else { String::new() };
    format!("{how}{offset} · {n}×{n} points over {w:.2} × {h:.2} Å")
}

/// A potential's colours span twice its most negative value both ways: the nuclei's potential
/// (which grows without bound) saturates, and the negative regions, where an electrophile is
/// drawn, keep their shades. `None` (the automatic scale) when it has no negative region.
pub fn potential_scale(map: &PlaneMap) -> Option<ColorScale> {
    let lowest = map.values.iter().copied().filter(|v| v.is_finite()).fold(0.0, f64::min);
    (lowest < 0.0).then(|| ColorScale::Diverging { limit: -2.0 * lowest })
}

/// The colour scale `source`'s map needs when the automatic one would wash it out: a
/// potential's ([`potential_scale`]), or a Laplacian's, whose values at the nuclei exceed the
/// valence shells' by orders of magnitude (it saturates at the 98th percentile of |value|).
pub fn scale_for(source: Source, map: &PlaneMap) -> Option<ColorScale> {
    match source {
        Source::Wavefunction(Quantity::Potential) => potential_scale(map),
        Source::Wavefunction(Quantity::DensityLaplacian) => {
            let mut magnitudes: Vec<f64> = map.values.iter().filter(|v| v.is_finite()).map(|v| v.abs()).collect();
            magnitudes.sort_by(f64::total_cmp);
            let limit = *magnitudes.get(magnitudes.len() * 98 / 100)?;
            (limit > 0.0).then_some(ColorScale::Diverging { limit })
        }
        _ => None,
    }
}
