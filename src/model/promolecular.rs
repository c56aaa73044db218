//! Promolecular densities: sums of spherical neutral atoms, what NCI uses where a
//! wavefunction is out of reach (proteins, ligands in pockets). The atoms' radial densities
//! come from `assets/atomic_densities.txt`, made by `scripts/make_atomic_densities.py`
//! (spherically averaged all-electron Hartree–Fock atoms, H–Cm): ln ρ tabulated at radii evenly
//! spaced in ln r, interpolated by a natural cubic spline in ln r (so ρ, ρ′ and ρ″ are smooth
//! and analytic), constant inside the first radius and falling exponentially beyond the last.
//! Atoms are found near a batch of points through cells as wide as the largest reach.

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::DVec3;

use super::molecule::Molecule;
use super::nci::{DensityDerivatives, DensitySource, bounds};

/// The table, embedded: a structure file needs nothing beside the binary.
const TABLE: &str = include_str!("../../assets/atomic_densities.txt");

/// Below this an atom's density is left out (e/bohr³): it ends each atom's reach.
pub const DENSITY_FLOOR: f64 = 1e-10;

/// The slowest fall of ln ρ (per bohr) beyond the table's last radius; the script that
/// normalised the densities used the same.
const MIN_TAIL_DECAY: f64 = 1.0;

/// The heaviest element a table may name (beyond oganesson a Z is a typo).
const MAX_TABLE_Z: u32 = 118;

/// One element's spherical density.
#[derive(Debug, Clone, PartialEq)]
pub struct AtomicDensity {
    pub z: u32,
    /// ln r of the first radius and the step in ln r.
    u0: f64,
    du: f64,
    /// ln ρ at each radius, and its second derivative in ln r (the spline's moments).
    log_rho: Vec<f64>,
    moments: Vec<f64>,
    /// ln ρ's slope (per bohr, negative) beyond the last radius.
    tail: f64,
    /// Beyond this radius (bohr) ρ < [`DENSITY_FLOOR`].
    pub reach: f64,
}

impl AtomicDensity {
    fn new(z: u32, r_min: f64, r_max: f64, log_rho: Vec<f64>) -> Option<Self> {
        let n = log_rho.len();
        if n < 4 || r_min <= 0.0 || r_max <= r_min || log_rho.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let (u0, du) = (r_min.ln(), (r_max / r_min).ln() / (n - 1) as f64);
        let moments = natural_spline_moments(&log_rho, du);
        let r_last = r_max * (-du).exp();
        let slope = -((log_rho[n - 2] - log_rho[n - 1]) / (r_max - r_last)).max(MIN_TAIL_DECAY);
        let floor = DENSITY_FLOOR.ln();
        let reach = if log_rho[n - 1] > floor {
            r_max + (log_rho[n - 1] - floor) / -slope
        } else {
            let last_above = log_rho.iter().rposition(|&v| v > floor).unwrap_or(0);
            (u0 + (last_above + 1) as f64 * du).exp()
        };
        Some(Self { z, u0, du, log_rho, moments, tail: slope, reach })
    }

    /// ρ(r), dρ/dr and d²ρ/dr².
    pub fn radial(&self, r: f64) -> (f64, f64, f64) {
        let n = self.log_rho.len();
        let u = r.max(1e-300).ln();
        if u <= self.u0 {
            return (self.log_rho[0].exp(), 0.0, 0.0);
        }
        let u_max = self.u0 + (n - 1) as f64 * self.du;
        if u >= u_max {
            let rho = (self.log_rho[n - 1] + self.tail * (r - u_max.exp())).exp();
            return (rho, self.tail * rho, self.tail * self.tail * rho);
        }
        let i = (((u - self.u0) / self.du) as usize).min(n - 2);
        let t = (u - self.u0) / self.du - i as f64;
        let (a, b, h) = (1.0 - t, t, self.du);
        let (y0, y1, m0, m1) = (self.log_rho[i], self.log_rho[i + 1], self.moments[i], self.moments[i + 1]);
        let f = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let fu = (y1 - y0) / h + (-(3.0 * a * a - 1.0) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        let fuu = a * m0 + b * m1;
        // ρ = e^f with f a function of u = ln r: ρ′ = ρ f_u / r, ρ″ = ρ (f_uu + f_u² − f_u) / r².
        let rho = f.exp();
        (rho, rho * fu / r, rho * (fuu + fu * fu - fu) / (r * r))
    }

    /// ρ, ∇ρ and the Hessian at `d` = point − nucleus: ∇ρ = ρ′ r̂,
    /// H = ρ″ r̂r̂ᵀ + (ρ′/r)(I − r̂r̂ᵀ).
    pub fn derivatives(&self, d: DVec3) -> DensityDerivatives {
        let r = d.length();
        let (rho, d1, d2) = self.radial(r);
        if r < 1e-12 || d1 == 0.0 && d2 == 0.0 {
            return DensityDerivatives { rho, ..Default::default() };
        }
        let n = d / r;
        let across = d1 / r;
        let hessian = std::array::from_fn(|a| {
            std::array::from_fn(|b| (d2 - across) * n[a] * n[b] + if a == b { across } else { 0.0 })
        });
        DensityDerivatives { rho, gradient: d1 * n, hessian }
    }
}

/// The second derivatives of a natural cubic spline through `y` at a uniform step `h`
/// (zero at both ends), by the tridiagonal (Thomas) solve.
fn natural_spline_moments(y: &[f64], h: f64) -> Vec<f64> {
    let n = y.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    // Rows i = 1..n−1: m_{i−1} + 4 m_i + m_{i+1} = 6 (y_{i+1} − 2 y_i + y_{i−1}) / h².
    let inner = n - 2;
    let mut c = vec![0.0; inner];
    let mut d = vec![0.0; inner];
    for k in 0..inner {
        let i = k + 1;
        let rhs = 6.0 * (y[i + 1] - 2.0 * y[i] + y[i - 1]) / (h * h);
        let (lower, prev_c, prev_d) = if k == 0 { (0.0, 0.0, 0.0) } else { (1.0, c[k - 1], d[k - 1]) };
        let pivot = 4.0 - lower * prev_c;
        c[k] = 1.0 / pivot;
        d[k] = (rhs - lower * prev_d) / pivot;
    }
    for k in (0..inner).rev() {
        let next = if k + 1 < inner { m[k + 2] } else { 0.0 };
        m[k + 1] = d[k] - c[k] * next;
    }
    m
}

/// The table parsed: one entry per element it holds, by Z (None where it has none).
fn table() -> &'static [Option<AtomicDensity>] {
    static PARSED: OnceLock<Vec<Option<AtomicDensity>>> = OnceLock::new();
    PARSED.get_or_init(|| parse(TABLE).unwrap_or_default())
}

/// `radii R_MIN R_MAX N`, then per element `Z energy basis` and N values of ln ρ (comments
/// start with `#`). None when the text is malformed.
fn parse(text: &str) -> Option<Vec<Option<AtomicDensity>>> {
    let mut tokens = text.lines().filter(|l| !l.trim_start().starts_with('#')).flat_map(str::split_whitespace);
    if tokens.next()? != "radii" {
        return None;
    }
    let r_min: f64 = tokens.next()?.parse().ok()?;
    let r_max: f64 = tokens.next()?.parse().ok()?;
    let n: usize = tokens.next()?.parse().ok()?;
    if !(4..=10_000).contains(&n) {
        return None;
    }
    let mut out: Vec<Option<AtomicDensity>> = Vec::new();
    while let Some(z) = tokens.next() {
        let z: u32 = z.parse().ok()?;
        let (_energy, _basis) = (tokens.next()?, tokens.next()?);
        let values: Vec<f64> = (0..n).map(|_| tokens.next()?.parse().ok()).collect::<Option<_>>()?;
        if z == 0 || z > MAX_TABLE_Z {
            return None;
        }
        if out.len() <= z as usize {
            out.resize(z as usize + 1, None);
        }
        out[z as usize] = Some(AtomicDensity::new(z, r_min, r_max, values)?);
    }
    Some(out)
}

/// The spherical density of element `z`, when the table holds it.
pub fn atomic_density(z: u32) -> Option<&'static AtomicDensity> {
    table().get(z as usize)?.as_ref()
}

/// The heaviest element with a density, and whether every lighter one has one too.
pub fn covered() -> (u32, bool) {
    let t = table();
    let last = t.iter().rposition(Option::is_some).unwrap_or(0) as u32;
    (last, (1..=last).all(|z| atomic_density(z).is_some()))
}

/// Why a promolecule cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PromolecularError {
    #[error("atom {atom} (Z = {z}) has no promolecular density: atomic densities cover Z = 1–{last}")]
    NoDensity { atom: usize, z: u32, last: u32 },
}

/// A sum of spherical atoms, with the cells that find the atoms near a batch of points.
#[derive(Debug, Clone)]
pub struct Promolecule {
    centres: Vec<DVec3>,
    densities: Vec<&'static AtomicDensity>,
    /// Cell width: the largest reach.
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Promolecule {
    /// The promolecule of `molecule`'s atoms: ghosts and dummy centres (Z = 0) hold no
    /// electrons and are left out; an element without a density is refused.
    pub fn new(molecule: &Molecule) -> Result<Self, PromolecularError> {
        let mut centres = Vec::new();
        let mut densities = Vec::new();
        for (i, a) in molecule.atoms.iter().enumerate() {
            if a.ghost || a.z == 0 || !a.position.is_finite() {
                continue;
            }
            let density =
                atomic_density(a.z).ok_or(PromolecularError::NoDensity { atom: i + 1, z: a.z, last: covered().0 })?;
            centres.push(a.position);
            densities.push(density);
        }
        let cell = densities.iter().map(|d| d.reach).fold(1.0, f64::max);
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, c) in centres.iter().enumerate() {
            cells.entry(key(*c, cell)).or_default().push(i as u32);
        }
        Ok(Self { centres, densities, cell, cells })
    }

    /// How many atoms it sums.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// The atoms whose reach meets the box `lo..hi`.
    fn near(&self, lo: DVec3, hi: DVec3) -> Vec<u32> {
        let (a, b) = (key(lo - DVec3::splat(self.cell), self.cell), key(hi + DVec3::splat(self.cell), self.cell));
        let span = (0..3).map(|k| (b[k] - a[k] + 1).max(0) as u64).product::<u64>();
        let within = |i: &u32| {
            let (c, r) = (self.centres[*i as usize], self.densities[*i as usize].reach);
            let nearest = c.clamp(lo, hi);
            nearest.distance_squared(c) <= r * r
        };
        let mut out: Vec<u32> = if span > self.cells.len() as u64 {
            self.cells.values().flatten().copied().filter(within).collect()
        } else {
            let mut v = Vec::new();
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        if let Some(members) = self.cells.get(&[x, y, z]) {
                            v.extend(members.iter().copied().filter(within));
                        }
                    }
                }
            }
            v
        };
        out.sort_unstable();
        out
    }
}

fn key(p: DVec3, cell: f64) -> [i64; 3] {
    let c = (p / cell).floor();
    [c.x as i64, c.y as i64, c.z as i64]
}

impl DensitySource for Promolecule {
    fn derivatives_at(&self, points: &[DVec3], out: &mut [DensityDerivatives]) {
        let (lo, hi) = bounds(points);
        let near = self.near(lo, hi);
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = DensityDerivatives::default();
            for &i in &near {
                let (c, density) = (self.centres[i as usize], self.densities[i as usize]);
                let d = *p - c;
                if d.length_squared() <= density.reach * density.reach {
                    o.add(&density.derivatives(d));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::molecule::Atom;

    #[test]
    fn the_table_covers_hydrogen_to_its_last_element_without_gaps() {
        let (last, complete) = covered();
        assert!(last >= 96, "H–Cm, got up to Z = {last}");
        assert!(complete, "every element up to Z = {last}");
    }

    #[test]
    fn each_radial_density_integrates_to_z() {
        // ∫4πr²ρ dr by Simpson's rule in u = ln r (from the first radius out), plus the
        // constant core inside it.
        for z in 1..=covered().0 {
            let a = atomic_density(z).unwrap();
            let (r0, r1) = (a.u0.exp(), 60.0f64);
            let n = 20_000;
            let h = (r1 / r0).ln() / n as f64;
            let f = |k: usize| {
                let r = r0 * (k as f64 * h).exp();
                4.0 * std::f64::consts::PI * r * r * r * a.radial(r).0
            };
            let simpson: f64 = (0..=n)
                .map(|k| {
                    f(k) * if k == 0 || k == n {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    }
                })
                .sum::<f64>()
                * h
                / 3.0;
            let core = 4.0 / 3.0 * std::f64::consts::PI * r0.powi(3) * a.radial(0.0).0;
            let total = simpson + core;
            assert!((total - z as f64).abs() < 1e-3, "Z = {z}: ∫ρ = {total}");
        }
    }

    #[test]
    fn hydrogen_is_the_exact_1s_density() {
        let h = atomic_density(1).unwrap();
        for r in [0.05f64, 0.3, 1.0, 2.5, 6.0, 12.0, 20.0] {
            let want = (-2.0 * r).exp() / std::f64::consts::PI;
            let (rho, d1, d2) = h.radial(r);
            // ln ρ is linear in r, the spline's variable is ln r: the steps widen outwards.
            let tol = if r > 16.0 {
                0.05
            } else if r > 6.0 {
                5e-3
            } else {
                1e-4
            };
            assert!((rho / want - 1.0).abs() < tol, "r = {r}: {rho} vs {want}");
            if r <= 6.0 {
                assert!((d1 / (-2.0 * want) - 1.0).abs() < 1e-3, "ρ′ at {r}");
                assert!((d2 / (4.0 * want) - 1.0).abs() < 1e-2, "ρ″ at {r}");
            }
        }
    }

    #[test]
    fn promolecular_derivatives_match_finite_differences() {
        let atoms = [
            (8, [0.0, 0.0, 0.0]),
            (1, [1.8, 0.0, 0.3]),
            (1, [-0.5, 1.7, 0.0]),
            (6, [0.4, -2.9, 1.1]),
            (79, [3.9, 2.1, -1.0]),
        ];
        let molecule = Molecule::new(
            atoms
                .iter()
                .map(|&(z, p)| Atom { z, charge: z as f64, position: DVec3::from_array(p), ghost: false })
                .collect(),
        );
        let pro = Promolecule::new(&molecule).unwrap();
        assert_eq!(pro.len(), 5);
        let at = |p: DVec3| {
            let mut d = [DensityDerivatives::default()];
            pro.derivatives_at(&[p], &mut d);
            d[0]
        };
        let h = 1e-5;
        let mut checked = 0;
        for i in 0..60 {
            let t = i as f64 * 0.41;
            let p = DVec3::new(2.5 * t.sin() + 0.7, 2.2 * (1.3 * t).cos() - 0.5, 1.6 * (0.7 * t).sin());
            let d = at(p);
            // A batch gives what single points give.
            let mut batch = [DensityDerivatives::default(); 2];
            pro.derivatives_at(&[p, p + DVec3::splat(3.0)], &mut batch);
            assert_eq!(batch[0], d);
            let sum: f64 =
                molecule.atoms.iter().map(|a| atomic_density(a.z).unwrap().radial((p - a.position).length()).0).sum();
            assert!((d.rho - sum).abs() < 1e-12 * (1.0 + sum));
            for a in 0..3 {
                let mut e = DVec3::ZERO;
                e[a] = h;
                let (dp, dm) = (at(p + e), at(p - e));
                let fd = (dp.rho - dm.rho) / (2.0 * h);
                assert!(
                    (fd - d.gradient[a]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "∂{a}ρ at {p}: {fd} vs {}",
                    d.gradient[a]
                );
                for b in 0..3 {
                    let fd = (dp.gradient[b] - dm.gradient[b]) / (2.0 * h);
                    let got = d.hessian[a][b];
                    assert!((fd - got).abs() < 1e-4 * (1.0 + fd.abs()), "∂{a}∂{b}ρ at {p}: {fd} vs {got}");
                    checked += (fd.abs() > 1e-3) as usize;
                }
            }
        }
        assert!(checked > 100);
    }

    #[test]
    fn elements_without_a_density_and_a_malformed_table_are_refused() {
        let atom = |z| Atom { z, charge: 0.0, position: DVec3::ZERO, ghost: false };
        let last = covered().0;
        match Promolecule::new(&Molecule::new(vec![atom(1), atom(last + 1)])) {
            Err(PromolecularError::NoDensity { atom: 2, z, .. }) => assert_eq!(z, last + 1),
            other => panic!("{other:?}"),
        }
        let ghost = Atom { ghost: true, ..atom(200) };
        assert_eq!(Promolecule::new(&Molecule::new(vec![ghost, atom(0)])).unwrap().len(), 0);
        assert!(parse("radii 0.001 10 5\n1 -0.5 x 1 2 3").is_none(), "values missing");
        assert!(parse("radii 0.001 10 4\n1 -0.5 x 1 2 3 nan").is_none());
        assert!(parse("radius 0.001 10 4").is_none());
        assert!(parse("radii 0.001 10 4\n1 -0.5 x -1 -2 -3 -4").is_some());
    }
}
