//! Where an orbital or a density actually decays: the box a grid must span to hold it, rather
//! than the atoms plus a fixed margin (which cuts off diffuse orbitals and single atoms' outer
//! shells, and shows the box's faces as a square in the picture).

use glam::DVec3;

use super::Molecule;
use super::gto::{GridSpec, PreparedBasis};
use super::orbitals::{Quantity, Wavefunction};

/// Where the search around the atoms starts (bohr): enough for most valence orbitals.
pub const START_REACH: f64 = 4.5;

/// The largest |ψ| an orbital's grid may show on its faces, as a fraction of the largest |ψ|.
pub const FACE_FRACTION: f64 = 0.01;
/// The largest ρ a density's grid may show on its faces (a.u.): a tenth of the smallest iso
/// value in common use (0.001, about the van der Waals surface). A fraction of the maximum would
/// not do: a density's maximum is the nuclear cusp, and 1 % of it lies inside the valence shell.
pub const DENSITY_FACE: f64 = 1e-4;

/// Where a field counts as decayed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decay {
    /// |f| below this fraction of max |f|.
    Relative(f64),
    /// |f| below this value.
    Absolute(f64),
}
/// Points per side of the coarse search grid.
const SEARCH_POINTS: usize = 40;
/// On the coarse grid, values count as decayed below a quarter of the face limit, so that values
/// between coarse points stay under it.
const SEARCH_MARGIN: f64 = 0.25;
/// The search box grows this many times at most when the field has not decayed at its faces.
const GROWTHS: usize = 4;

/// The box around `lo..hi` (the atoms) outside which f has decayed as `decay` says. `reach`
/// (bohr) is where the search starts looking around the atoms (the basis set's largest cutoff
/// radius is a good start); `eval` gives f on a grid, x slowest, z fastest. The result is padded
/// by one coarse step and never smaller than the atoms plus 1 bohr.
pub fn decay_box(
    lo: DVec3,
    hi: DVec3,
    reach: f64,
    decay: Decay,
    eval: impl Fn(&GridSpec) -> Vec<f64>,
) -> (DVec3, DVec3) {
    let mut reach = reach.clamp(2.0, 40.0);
    let fallback = (lo - DVec3::splat(reach), hi + DVec3::splat(reach));
    for _ in 0..GROWTHS {
        let (slo, shi) = (lo - DVec3::splat(reach), hi + DVec3::splat(reach));
        let step = (shi - slo).max_element() / (SEARCH_POINTS - 1) as f64;
        let dims = ((shi - slo) / step).ceil().as_uvec3().to_array().map(|n| n as usize + 1);
        let spec = GridSpec::new(slo, [DVec3::X * step, DVec3::Y * step, DVec3::Z * step], dims);
        let values = eval(&spec);
        let max = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if max <= 0.0 || !max.is_finite() {
            return fallback;
        }
        let threshold = SEARCH_MARGIN
            * match decay {
                Decay::Relative(f) => f * max,
                Decay::Absolute(v) => v,
            };
        let (mut a, mut b) = ([usize::MAX; 3], [0usize; 3]);
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    if values[(i * dims[1] + j) * dims[2] + k].abs() >= threshold {
                        for (axis, n) in [i, j, k].into_iter().enumerate() {
                            a[axis] = a[axis].min(n);
                            b[axis] = b[axis].max(n);
                        }
                    }
                }
            }
        }
        let at_face = (0..3).any(|axis| a[axis] == 0 || b[axis] + 1 >= dims[axis]);
        if at_face {
            // Not decayed inside the search box: look further out.
            reach *= 1.8;
            continue;
        }
        let corner = |n: [usize; 3]| slo + DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * step;
        let pad = DVec3::splat(step);
        let (blo, bhi) = (corner(a) - pad, corner(b) + pad);
        return (blo.min(lo - DVec3::ONE), bhi.max(hi + DVec3::ONE));
    }
    (lo - DVec3::splat(reach), hi + DVec3::splat(reach))
}

/// The box (bohr) a wavefunction's orbital or density is evaluated in: where an orbital decays
/// below [`FACE_FRACTION`] of its largest |ψ|, a density below [`DENSITY_FACE`]. `None` without
/// atoms.
pub fn quantity_box(wf: &Wavefunction, molecule: &Molecule, quantity: Quantity) -> Option<(DVec3, DVec3)> {
    let (lo, hi) = molecule.bounds()?;
    let prepared = PreparedBasis::new(&wf.basis);
    let decay = match quantity {
        // A transition density is a sum of orbital products: as small at the box's faces,
        // relative to its largest value, as an orbital's square.
        Quantity::Orbital(_) | Quantity::BasisFunction(_) | Quantity::TransitionDensity(_) => {
            Decay::Relative(FACE_FRACTION)
        }
        Quantity::Density
        | Quantity::SpinDensity
        | Quantity::DifferenceDensity
        | Quantity::Attachment
        | Quantity::Detachment
        | Quantity::ExcitedDensity => Decay::Absolute(DENSITY_FACE),
        // The potential never decays (a charged molecule's goes as 1/r): it is shown in the
        // density's box, where the surfaces it colours lie.
        Quantity::Potential => return quantity_box(wf, molecule, Quantity::Density),
        // s, sign(λ₂)ρ and ∇²ρ matter where the density does: the density's box.
        Quantity::ReducedGradient
        | Quantity::NciGradient
        | Quantity::NciCloud
        | Quantity::SignLambda2Rho
        | Quantity::DensityLaplacian => {
            return quantity_box(wf, molecule, Quantity::Density);
        }
    };
    Some(decay_box(lo, hi, START_REACH, decay, |spec| prepared.quantity_grid(wf, molecule, quantity, spec)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f = exp(−a|r − c|) sampled on `spec`.
    fn slater(spec: &GridSpec, c: DVec3, a: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(spec.len());
        for i in 0..spec.dims[0] {
            for j in 0..spec.dims[1] {
                for k in 0..spec.dims[2] {
                    out.push((-a * (spec.point(i, j, k) - c).length()).exp());
                }
            }
        }
        out
    }

    #[test]
    fn an_absolute_limit_ignores_the_maximum() {
        // A cusp-like density: 1 % of its maximum sits close in; 1e-4 a.u. lies far out.
        let c = DVec3::ZERO;
        let rho = |s: &GridSpec| slater(s, c, 2.0).iter().map(|v| 300.0 * v).collect();
        let (lo, _) = decay_box(c, c, 4.5, Decay::Absolute(DENSITY_FACE), rho);
        let r = (300.0 / DENSITY_FACE).ln() / 2.0;
        assert!(-lo.x >= 0.98 * r, "{lo} vs {r}");
        let (tight, _) = decay_box(c, c, 4.5, Decay::Relative(FACE_FRACTION), rho);
        assert!(-tight.x < 0.5 * r);
    }

    #[test]
    fn the_box_holds_a_diffuse_function_and_trims_a_tight_one() {
        let c = DVec3::new(0.5, -0.2, 0.0);
        for (a, tight) in [(0.35, false), (3.0, true)] {
            let (lo, hi) = decay_box(c, c, 4.0, Decay::Relative(FACE_FRACTION), |s| slater(s, c, a));
            // exp(−a r) = 1 % at r = ln(100)/a: the faces lie at or beyond it ...
            let r = 100f64.ln() / a;
            for axis in 0..3 {
                assert!(c[axis] - lo[axis] >= r * 0.98 && hi[axis] - c[axis] >= r * 0.98, "a {a}: {lo} {hi}");
            }
            // ... and not far beyond (one coarse step and the 1 bohr floor).
            let extent = (hi - lo).max_element() / 2.0;
            assert!(extent < (1.6 * r).max(1.0 + 0.5), "a {a}: half extent {extent} vs r {r}");
            assert_eq!(tight, extent < 4.0, "a {a}: {extent}");
        }
    }
}
