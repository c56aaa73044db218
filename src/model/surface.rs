//! Molecular surfaces of any molecule, each a field on a grid of cubic voxels cut by marching
//! cubes ([`super::isosurface`]):
//!
//! - **Gaussian** (VMD's QuickSurf, Mol*'s default): ρ(x) = Σᵢ exp(−α·|x − cᵢ|²/rᵢ²), cut at
//!   ρ = e^(−α), so a lone atom's surface is its van der Waals sphere and neighbours blend
//!   smoothly (α, the smoothness, sets how much).
//! - **Solvent-excluded** (SES, Connolly's): what a probe sphere rolling over the atoms cannot
//!   reach. The probe's centre may go anywhere outside the solvent-accessible spheres
//!   (rᵢ + probe); a point is inside the SES when it is farther than the probe radius from every
//!   such place. One exact Euclidean distance transform (Felzenszwalb & Huttenlocher) finds, for
//!   each point inside the accessible spheres, the nearest grid point outside them; that point
//!   projected onto its sphere gives the distance to the accessible surface to well under a
//!   voxel, so the surface is smooth rather than voxel-stepped (EDTSurf's method, refined).
//!
//! Both are built in parallel over planes of the grid (rayon) and can be cancelled between
//! planes. Positions and radii are bohr.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use glam::DVec3;
use rayon::prelude::*;

use super::grid::{GridSpec, VolumeGrid};
use super::isosurface::{self, Level, Mesh};
use super::units::BOHR_PER_ANGSTROM;

/// Which surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceKind {
    Gaussian,
    SolventExcluded,
}

/// An atom as the surface sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub centre: DVec3,
    pub radius: f64,
}

impl Sphere {
    /// A molecule's atoms as van der Waals spheres: those `shown` marks (all without a mask),
    /// ghosts and dummy centres left out.
    pub fn of_molecule(molecule: &super::Molecule, shown: Option<&[bool]>) -> Vec<Sphere> {
        Self::of_atoms(molecule, shown).0
    }

    /// [`Self::of_molecule`] with each sphere's atom index.
    pub fn of_atoms(molecule: &super::Molecule, shown: Option<&[bool]>) -> (Vec<Sphere>, Vec<u32>) {
        molecule
            .atoms
            .iter()
            .enumerate()
            .filter(|&(i, a)| !a.ghost && a.z > 0 && shown.is_none_or(|m| m.get(i).copied().unwrap_or(true)))
            .map(|(i, a)| (Self::of(a), i as u32))
            .unzip()
    }

    fn of(a: &super::Atom) -> Sphere {
        Sphere { centre: a.position, radius: a.element().vdw_radius as f64 * BOHR_PER_ANGSTROM }
    }
}

/// For each point (near the surface of `spheres`), the sphere whose surface is nearest to it:
/// what colours a molecular surface by its atoms. `u32::MAX` where no sphere lies within
/// `reach` of its surface.
pub fn nearest_spheres(spheres: &[Sphere], points: &[glam::Vec3], reach: f64) -> Vec<u32> {
    if spheres.is_empty() {
        return vec![u32::MAX; points.len()];
    }
    let cells = CellIndex::new(spheres, reach);
    points
        .par_iter()
        .map(|p| {
            let p = p.as_dvec3();
            let mut best = (f64::INFINITY, u32::MAX);
            cells.for_each_near_indexed(p, |i, s| {
                let d = (p - s.centre).length() - s.radius;
                if d < best.0 && d <= reach {
                    best = (d, i);
                }
            });
            best.1
        })
        .collect()
}

/// How a surface is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceParams {
    pub kind: SurfaceKind,
    /// Grid spacing, bohr.
    pub resolution: f64,
    /// Probe radius for the SES, bohr (water: 1.4 Å).
    pub probe: f64,
    /// α of the Gaussian surface: larger is tighter around the atoms.
    pub smoothness: f64,
}

impl SurfaceParams {
    /// Water's radius, 1.4 Å, in bohr.
    pub const WATER_PROBE: f64 = 1.4 * BOHR_PER_ANGSTROM;
    /// Mol*'s default smoothness.
    pub const SMOOTHNESS: f64 = 1.5;

    /// Points the automatic resolution aims for at most.
    pub const AUTO_POINTS: f64 = 1.0e7;

    /// Defaults for these atoms: 0.25 Å voxels, coarser where the atoms' box would need more
    /// than [`Self::AUTO_POINTS`] grid points (up to 2 Å).
    pub fn auto(kind: SurfaceKind, spheres: &[Sphere]) -> Self {
        let (lo, hi) = bounds(spheres, |s| s.radius + Self::WATER_PROBE);
        let volume = (hi - lo).max(DVec3::ONE).element_product();
        let bohr = (volume / Self::AUTO_POINTS).cbrt();
        let resolution = bohr.clamp(0.25 * BOHR_PER_ANGSTROM, 2.0 * BOHR_PER_ANGSTROM);
        let resolution = if resolution.is_finite() { resolution } else { 2.0 * BOHR_PER_ANGSTROM };
        Self { kind, resolution, probe: Self::WATER_PROBE, smoothness: Self::SMOOTHNESS }
    }
}

/// Why no surface was built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceError {
    #[error("no atoms to put a surface around")]
    NoAtoms,
    #[error("the surface was cancelled")]
    Cancelled,
    #[error(
        "a {kind:?} surface at {spacing:.2} Å needs a grid of {points} points (at most {max}); choose a coarser resolution"
    )]
    TooLarge { kind: SurfaceKind, spacing: f64, points: u64, max: u64 },
    #[error("{0} is not a usable {1} (it must be finite and positive)")]
    BadParameter(f64, &'static str),
}

/// The most grid points a surface may use: the SES needs about 25 bytes per point while it is
/// built (2.5 GiB here).
pub const MAX_GRID_POINTS: u64 = 150_000_000;

/// A built surface: the mesh (outward normals, counter-clockwise seen from outside) and the grid
/// it was cut from.
#[derive(Debug, Clone)]
pub struct Surface {
    pub mesh: Mesh,
    pub grid: GridSpec,
    /// Seconds spent in each phase, in order (for benchmarks).
    pub phases: Vec<(&'static str, f64)>,
}

/// Seconds per phase, as the build goes; each phase's end also moves the build's progress on.
struct Phases<'a> {
    list: Vec<(&'static str, f64)>,
    last: std::time::Instant,
    progress: &'a AtomicU32,
}

/// Thousandths of a build done when each phase ends: their shares of the time measured for
/// 10⁵ atoms (SES at 0.92 Å: 221, 236, 65, 554 and 100 ms; a Gaussian surface spends about
/// three quarters on its Gaussians).
const PROGRESS_AT: [(&str, u32); 6] = [
    ("accessible spheres", 190),
    ("distance transform", 390),
    ("estimate", 440),
    ("exact distances", 915),
    ("gaussians", 750),
    ("marching cubes", 1000),
];

impl<'a> Phases<'a> {
    fn new(progress: &'a AtomicU32) -> Self {
        // Started: at least one thousandth, so a reader tells it from "not building".
        progress.store(1, Ordering::Relaxed);
        Self { list: Vec::new(), last: std::time::Instant::now(), progress }
    }

    /// Ends the phase called `name`.
    fn done(&mut self, name: &'static str) {
        let now = std::time::Instant::now();
        self.list.push((name, (now - self.last).as_secs_f64()));
        self.last = now;
        if let Some((_, at)) = PROGRESS_AT.iter().find(|(n, _)| *n == name) {
            self.progress.store(*at, Ordering::Relaxed);
        }
    }
}

/// Builds the surface of `spheres`. `cancel` is polled between planes.
pub fn build(spheres: &[Sphere], params: &SurfaceParams, cancel: &AtomicBool) -> Result<Surface, SurfaceError> {
    build_reporting(spheres, params, cancel, &AtomicU32::new(0))
}

/// [`build`], storing in `progress` the thousandths done as each phase ends (for a progress
/// bar).
pub fn build_reporting(
    spheres: &[Sphere],
    params: &SurfaceParams,
    cancel: &AtomicBool,
    progress: &AtomicU32,
) -> Result<Surface, SurfaceError> {
    if spheres.is_empty() {
        return Err(SurfaceError::NoAtoms);
    }
    for (value, what) in [(params.resolution, "resolution"), (params.smoothness, "smoothness")] {
        if !(value.is_finite() && value > 0.0) {
            return Err(SurfaceError::BadParameter(value, what));
        }
    }
    if !(params.probe.is_finite() && params.probe >= 0.0) {
        return Err(SurfaceError::BadParameter(params.probe, "probe radius"));
    }
    let h = params.resolution;
    // How far beyond its centre each sphere's field reaches.
    let reach = match params.kind {
        SurfaceKind::Gaussian => gaussian_cutoff(params.smoothness),
        SurfaceKind::SolventExcluded => 1.0,
    };
    let pad = |s: &Sphere| match params.kind {
        SurfaceKind::Gaussian => s.radius * reach,
        SurfaceKind::SolventExcluded => s.radius + params.probe,
    };
    let (lo, hi) = bounds(spheres, pad);
    // Two voxels of margin: the field is outside the surface on every face.
    let (lo, hi) = (lo - DVec3::splat(2.0 * h), hi + DVec3::splat(2.0 * h));
    let extent = (hi - lo) / h;
    let points = extent.to_array().iter().fold(1u64, |n, e| n.saturating_mul((e.ceil() as u64).saturating_add(1)));
    if !extent.is_finite() || points > MAX_GRID_POINTS {
        let points = if extent.is_finite() { points } else { u64::MAX };
        return Err(SurfaceError::TooLarge {
            kind: params.kind,
            spacing: h / BOHR_PER_ANGSTROM,
            points,
            max: MAX_GRID_POINTS,
        });
    }
    let spec = GridSpec::spaced(lo, hi, h);
    let mut phases = Phases::new(progress);
    let (values, level) = match params.kind {
        SurfaceKind::Gaussian => {
            let values = gaussian_field(&spec, spheres, params.smoothness, cancel)?;
            phases.done("gaussians");
            (values, (-params.smoothness).exp() as f32)
        }
        SurfaceKind::SolventExcluded => (ses_field(&spec, spheres, params.probe, cancel, &mut phases)?, 0.0),
    };
    let grid = VolumeGrid::new("surface", spec.dims, spec.world_from_grid, values);
    let mesh = isosurface::extract(&grid, &[Level { value: level, sign: 1.0 }]).pop().unwrap_or_default();
    phases.done("marching cubes");
    Ok(Surface { mesh, grid: spec, phases: phases.list })
}

/// The box holding every sphere grown by `pad`.
fn bounds(spheres: &[Sphere], pad: impl Fn(&Sphere) -> f64) -> (DVec3, DVec3) {
    spheres.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), s| {
        let r = DVec3::splat(pad(s));
        (lo.min(s.centre - r), hi.max(s.centre + r))
    })
}

/// Where a Gaussian's contribution falls under 1/1000 of the surface level, in units of the
/// atom's radius: exp(−α·d²) = e^(−α)/1000.
fn gaussian_cutoff(alpha: f64) -> f64 {
    (1.0 + 1000f64.ln() / alpha).sqrt()
}

/// Grid point (i, j, k) is `values[(i·ny + j)·nz + k]`; a plane is one i.
fn plane_len(spec: &GridSpec) -> usize {
    spec.dims[1] * spec.dims[2]
}

/// Spheres sorted by x, so each plane finds the few that reach it by bisection.
struct ByX<'a> {
    spheres: &'a [Sphere],
    order: Vec<u32>,
    xs: Vec<f64>,
    max_reach: f64,
}

impl<'a> ByX<'a> {
    fn new(spheres: &'a [Sphere], reach: impl Fn(&Sphere) -> f64) -> Self {
        let mut order: Vec<u32> = (0..spheres.len() as u32).collect();
        order.sort_by(|&a, &b| spheres[a as usize].centre.x.total_cmp(&spheres[b as usize].centre.x));
        let xs = order.iter().map(|&i| spheres[i as usize].centre.x).collect();
        let max_reach = spheres.iter().map(reach).fold(0.0, f64::max);
        Self { spheres, order, xs, max_reach }
    }

    /// The spheres (with their index) whose centre lies within the largest reach of plane x.
    fn near(&self, x: f64) -> impl Iterator<Item = (u32, &'a Sphere)> + '_ {
        let a = self.xs.partition_point(|&c| c < x - self.max_reach);
        let b = self.xs.partition_point(|&c| c <= x + self.max_reach);
        self.order[a..b].iter().map(|&i| (i, &self.spheres[i as usize]))
    }
}

/// Calls `f(j, k, d²)` for each point of plane x = `x` within `reach` of `s` (cubic voxels of
/// side `h`, origin `o`, `ny`×`nz` points per plane).
fn for_each_in_disc(
    s: &Sphere,
    reach: f64,
    x: f64,
    (o, h, ny, nz): (DVec3, f64, usize, usize),
    mut f: impl FnMut(usize, usize, f64),
) {
    let dx2 = (x - s.centre.x).powi(2);
    let r2 = reach * reach;
    if dx2 > r2 {
        return;
    }
    let disc = (r2 - dx2).sqrt();
    let span = |c: f64, n: usize| {
        let lo = ((c - disc) / h).ceil().max(0.0) as usize;
        let hi = (((c + disc) / h).floor() as i64).min(n as i64 - 1);
        (lo, hi)
    };
    let (j0, j1) = span(s.centre.y - o.y, ny);
    let (k0, k1) = span(s.centre.z - o.z, nz);
    for j in j0 as i64..=j1 {
        let dy2 = (o.y + j as f64 * h - s.centre.y).powi(2);
        for k in k0 as i64..=k1 {
            let d2 = dx2 + dy2 + (o.z + k as f64 * h - s.centre.z).powi(2);
            if d2 <= r2 {
                f(j as usize, k as usize, d2);
            }
        }
    }
}

fn cancelled(cancel: &AtomicBool) -> Result<(), SurfaceError> {
    if cancel.load(Ordering::Relaxed) { Err(SurfaceError::Cancelled) } else { Ok(()) }
}

/// ρ = Σ exp(−α d²/r²) on every grid point, one plane per task.
fn gaussian_field(
    spec: &GridSpec,
    spheres: &[Sphere],
    alpha: f64,
    cancel: &AtomicBool,
) -> Result<Vec<f32>, SurfaceError> {
    let cutoff = gaussian_cutoff(alpha);
    let by_x = ByX::new(spheres, |s| s.radius * cutoff);
    let (o, h) = (spec.origin(), spec.step(0).x);
    let [_, ny, nz] = spec.dims;
    let mut values = vec![0f32; spec.len()];
    values.par_chunks_mut(plane_len(spec)).enumerate().try_for_each(|(i, plane)| {
        cancelled(cancel)?;
        let x = o.x + i as f64 * h;
        for (_, s) in by_x.near(x) {
            let k = alpha / (s.radius * s.radius);
            for_each_in_disc(s, s.radius * cutoff, x, (o, h, ny, nz), |j, kk, d2| {
                plane[j * nz + kk] += (-k * d2).exp() as f32;
            });
        }
        Ok(())
    })?;
    Ok(values)
}

/// No accessible sphere reaches this point.
const NO_SPHERE: u32 = u32::MAX;

/// F = (distance to the nearest place the probe's centre may be) − probe: positive inside the
/// SES, zero on it. Outside the accessible spheres F = −probe − (distance outside them), so a
/// point probe gives the union of the atoms' spheres with a smooth field across it.
fn ses_field(
    spec: &GridSpec,
    spheres: &[Sphere],
    probe: f64,
    cancel: &AtomicBool,
    phases: &mut Phases<'_>,
) -> Result<Vec<f32>, SurfaceError> {
    let (o, h) = (spec.origin(), spec.step(0).x);
    let [nx, ny, nz] = spec.dims;
    let np = plane_len(spec);
    // 1. Per point: how far outside the accessible spheres it lies (negative inside) and the
    //    sphere that decides it, within two voxels of their surface.
    let margin = 2.0 * h;
    let by_x = ByX::new(spheres, |s| s.radius + probe + margin);
    let mut nearest = vec![NO_SPHERE; spec.len()];
    let mut outside = vec![f32::INFINITY; spec.len()];
    nearest.par_chunks_mut(np).zip(outside.par_chunks_mut(np)).enumerate().try_for_each(|(i, (near, out))| {
        cancelled(cancel)?;
        let x = o.x + i as f64 * h;
        for (index, s) in by_x.near(x) {
            let sas = s.radius + probe;
            for_each_in_disc(s, sas + margin, x, (o, h, ny, nz), |j, k, d2| {
                let p = j * nz + k;
                // depth < out[p] ⇔ d² < (sas + out[p])²: most points fail without a root.
                let beat = sas + out[p] as f64;
                if beat > 0.0 && d2 < beat * beat {
                    out[p] = (d2.sqrt() - sas) as f32;
                    near[p] = index;
                }
            });
        }
        Ok(())
    })?;
    phases.done("accessible spheres");
    // 2. For every point inside, the nearest grid point outside the accessible spheres.
    let inside: Vec<bool> = outside.iter().map(|&d| d < 0.0).collect();
    let feature = nearest_outside(&inside, [nx, ny, nz], cancel)?;
    drop(inside);
    cancelled(cancel)?;
    phases.done("distance transform");
    // 3. The distance to the accessible surface near that point, exact where it matters.
    let point = |p: usize| {
        let (i, j, k) = (p / np, p / nz % ny, p % nz);
        o + DVec3::new(i as f64, j as f64, k as f64) * h
    };
    // Only points near the SES need the exact distance (the estimate is at most ~2 voxels
    // long); they are refined grouped by their outside point, whose neighbourhood they share.
    let band = 1.5 * h;
    let reach = (4.0 * h).min(1.2 * BOHR_PER_ANGSTROM);
    let mut values = vec![0f32; spec.len()];
    let mut refine: Vec<(u32, u32)> = values
        .par_chunks_mut(np)
        .enumerate()
        .flat_map_iter(|(i, plane)| {
            let mut near = Vec::new();
            for (q, v) in plane.iter_mut().enumerate() {
                let p = i * np + q;
                if outside[p] >= 0.0 {
                    *v = -probe as f32 - outside[p].min(margin as f32);
                    continue;
                }
                let f = feature[p] as usize;
                let dist = (point(p) - on_sphere(point(f), spheres.get(nearest[f] as usize), probe)).length();
                *v = (dist - probe) as f32;
                if (dist - probe).abs() < band {
                    near.push((f as u32, p as u32));
                }
            }
            near
        })
        .collect();
    drop((feature, nearest, outside));
    cancelled(cancel)?;
    phases.done("estimate");
    refine.par_sort_unstable();
    let grown_spheres: Vec<Sphere> = spheres.iter().map(|s| grown(s, probe)).collect();
    let cells = CellIndex::new(&grown_spheres, reach);
    let groups: Vec<&[(u32, u32)]> = refine.chunk_by(|a, b| a.0 == b.0).collect();
    let refined: Vec<(u32, f32)> = groups
        .par_iter()
        .flat_map_iter(|group| {
            // Every accessible sphere that could cover a point within `reach` of the outside
            // point, and among them those whose surface passes that near.
            let f = point(group[0].0 as usize);
            let mut local = Vec::new();
            cells.for_each_near(f, |s| {
                if (f - s.centre).length() < s.radius + reach {
                    local.push(*s);
                }
            });
            let set: Vec<Sphere> =
                local.iter().filter(|s| ((f - s.centre).length() - s.radius).abs() <= reach).copied().collect();
            let near = NearSurface::new(&set, &local, (f, reach));
            group.iter().map(move |&(_, p)| (p, (near.distance(point(p as usize)) - probe) as f32)).collect::<Vec<_>>()
        })
        .collect();
    for (p, v) in refined {
        values[p as usize] = values[p as usize].min(v);
    }
    phases.done("exact distances");
    Ok(values)
}

/// Spheres binned in cubic cells at least as wide as the largest sphere plus `reach`, so
/// every sphere that covers a point within `reach` of a query point lies in the 27 cells
/// around it.
struct CellIndex<'a> {
    spheres: &'a [Sphere],
    origin: DVec3,
    size: f64,
    dims: [usize; 3],
    /// Sphere indices of cell c: `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> CellIndex<'a> {
    fn new(spheres: &'a [Sphere], reach: f64) -> Self {
        let size = spheres.iter().map(|s| s.radius).fold(0.0, f64::max) + reach;
        let (lo, hi) = bounds(spheres, |_| 0.0);
        let dims = ((hi - lo) / size).to_array().map(|e| e.floor() as usize + 1);
        let mut index = Self { spheres, origin: lo, size, dims, start: Vec::new(), items: Vec::new() };
        let cell_of: Vec<usize> = spheres.iter().map(|s| index.cell(index.coords(s.centre))).collect();
        let mut count = vec![0u32; dims.iter().product::<usize>() + 1];
        for &c in &cell_of {
            count[c + 1] += 1;
        }
        for c in 1..count.len() {
            count[c] += count[c - 1];
        }
        let mut fill = count.clone();
        index.items = vec![0; spheres.len()];
        for (i, &c) in cell_of.iter().enumerate() {
            index.items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        index.start = count;
        index
    }

    fn coords(&self, p: DVec3) -> [i64; 3] {
        ((p - self.origin) / self.size).floor().to_array().map(|c| c as i64)
    }

    fn cell(&self, [i, j, k]: [i64; 3]) -> usize {
        let [_, ny, nz] = self.dims;
        (i as usize * ny + j as usize) * nz + k as usize
    }

    /// Calls `f` with each sphere in the 27 cells around `p`.
    fn for_each_near(&self, p: DVec3, mut f: impl FnMut(&Sphere)) {
        self.for_each_near_indexed(p, |_, s| f(s));
    }

    /// [`Self::for_each_near`] with each sphere's index.
    fn for_each_near_indexed(&self, p: DVec3, mut f: impl FnMut(u32, &Sphere)) {
        let c = self.coords(p);
        for i in c[0] - 1..=c[0] + 1 {
            for j in c[1] - 1..=c[1] + 1 {
                for k in c[2] - 1..=c[2] + 1 {
                    let inside = [i, j, k].iter().zip(self.dims).all(|(&v, n)| v >= 0 && (v as usize) < n);
                    if inside {
                        let cell = self.cell([i, j, k]);
                        for &s in &self.items[self.start[cell] as usize..self.start[cell + 1] as usize] {
                            f(s, &self.spheres[s as usize]);
                        }
                    }
                }
            }
        }
    }
}

/// A sphere grown by the probe radius: where the probe's centre may touch it.
fn grown(s: &Sphere, probe: f64) -> Sphere {
    Sphere { centre: s.centre, radius: s.radius + probe }
}

/// `q` moved radially onto `s` grown by the probe (unchanged without a sphere).
fn on_sphere(q: DVec3, s: Option<&Sphere>, probe: f64) -> DVec3 {
    match s {
        Some(s) => {
            let out = q - s.centre;
            let len = out.length();
            if len > 0.0 { s.centre + out * ((s.radius + probe) / len) } else { q }
        }
        None => q,
    }
}

/// The nearest point of the union's surface to points near one outside grid point, among the
/// candidates that can be nearest: a point projected onto each sphere of `set`, onto each
/// circle where two meet, and the points where three meet. Only candidates within `near.1` of
/// `near.0` count, and only those no sphere of `blockers` (every sphere that can reach that
/// far) buries.
struct NearSurface<'a> {
    set: &'a [Sphere],
    blockers: &'a [Sphere],
    near: (DVec3, f64),
    circles: Vec<(DVec3, DVec3, f64)>,
    /// Exposed points where three spheres meet.
    corners: Vec<DVec3>,
}

impl<'a> NearSurface<'a> {
    fn new(set: &'a [Sphere], blockers: &'a [Sphere], near: (DVec3, f64)) -> Self {
        let mut this = Self { set, blockers, near, circles: Vec::new(), corners: Vec::new() };
        for (a, sa) in set.iter().enumerate() {
            for (b, sb) in set.iter().enumerate().skip(a + 1) {
                let Some(circle) = circle_of(sa, sb) else { continue };
                this.circles.push(circle);
                for sc in &set[b + 1..] {
                    let exposed: Vec<DVec3> =
                        meeting_points(sc, circle).into_iter().filter(|&c| this.exposed(c)).collect();
                    this.corners.extend(exposed);
                }
            }
        }
        this
    }

    /// Within reach of the outside point and on or outside every blocker (squared distances:
    /// this runs for every candidate of every point refined).
    fn exposed(&self, c: DVec3) -> bool {
        (c - self.near.0).length_squared() <= self.near.1 * self.near.1
            && self.blockers.iter().all(|s| (c - s.centre).length_squared() >= (s.radius * (1.0 - 1e-9)).powi(2))
    }

    /// The distance from `x` to the nearest candidate; infinite when none qualifies.
    fn distance(&self, x: DVec3) -> f64 {
        let mut best = self.corners.iter().map(|&c| (x - c).length_squared()).fold(f64::INFINITY, f64::min);
        let mut consider = |c: DVec3| {
            let d2 = (x - c).length_squared();
            if d2 < best && self.exposed(c) {
                best = d2;
            }
        };
        for s in self.set {
            let out = x - s.centre;
            if out.length() > 0.0 {
                consider(s.centre + out.normalize() * s.radius);
            }
        }
        for &(m, n, r) in &self.circles {
            let v = (x - m) - n * (x - m).dot(n);
            let radial = if v.length() > 1e-12 { v.normalize() } else { n.any_orthonormal_vector() };
            consider(m + radial * r);
        }
        best.sqrt()
    }
}

/// The circle where two spheres' surfaces meet: centre, unit axis (from a to b), radius.
fn circle_of(a: &Sphere, b: &Sphere) -> Option<(DVec3, DVec3, f64)> {
    let axis = b.centre - a.centre;
    let d = axis.length();
    if d <= 0.0 || d >= a.radius + b.radius || d <= (a.radius - b.radius).abs() {
        return None;
    }
    let n = axis / d;
    let t = (d * d + a.radius * a.radius - b.radius * b.radius) / (2.0 * d);
    Some((a.centre + n * t, n, (a.radius * a.radius - t * t).max(0.0).sqrt()))
}

/// Where the circle (centre m, axis n, radius r) of two spheres meets a third sphere `c`: zero
/// or two points.
fn meeting_points(c: &Sphere, (m, n, r): (DVec3, DVec3, f64)) -> Vec<DVec3> {
    // Points m + r(cos t·u + sin t·w) at distance c.radius from c's centre.
    let u = n.any_orthonormal_vector();
    let w = n.cross(u);
    let e = c.centre - m;
    let (eu, ew) = (e.dot(u), e.dot(w));
    // |m + r(cos t u + sin t w) − c|² = r² + |e|² − 2r(eu cos t + ew sin t) = c.radius²
    let k = (r * r + e.length_squared() - c.radius * c.radius) / (2.0 * r);
    let amp = (eu * eu + ew * ew).sqrt();
    if r <= 0.0 || amp <= 1e-12 || k.abs() > amp {
        return Vec::new();
    }
    let phase = ew.atan2(eu);
    let spread = (k / amp).acos();
    [phase + spread, phase - spread].into_iter().map(|t| m + r * (t.cos() * u + t.sin() * w)).collect()
}

/// For each grid point, the index of the nearest point (Euclidean, grid units) whose `inside`
/// is false: Felzenszwalb & Huttenlocher's exact transform, one pass per axis, carrying the
/// nearest point's index with its squared distance. Every point gets one (the grid's faces are
/// outside).
fn nearest_outside(inside: &[bool], dims: [usize; 3], cancel: &AtomicBool) -> Result<Vec<u32>, SurfaceError> {
    let [nx, ny, nz] = dims;
    let mut dist: Vec<f32> = inside.iter().map(|&i| if i { f32::INFINITY } else { 0.0 }).collect();
    let mut feature: Vec<u32> = (0..inside.len() as u32).collect();
    // Along z: rows are contiguous.
    dist.par_chunks_mut(nz).zip(feature.par_chunks_mut(nz)).for_each_init(Envelope::default, |env, (d, f)| {
        env.line(d, f);
    });
    cancelled(cancel)?;
    // Along y: within each plane, columns of stride nz.
    let np = ny * nz;
    dist.par_chunks_mut(np).zip(feature.par_chunks_mut(np)).for_each_init(
        || (Envelope::default(), Vec::new(), Vec::new()),
        |(env, d, f), (dp, fp)| {
            for k in 0..nz {
                d.clear();
                f.clear();
                d.extend((0..ny).map(|j| dp[j * nz + k]));
                f.extend((0..ny).map(|j| fp[j * nz + k]));
                env.line(d, f);
                for j in 0..ny {
                    dp[j * nz + k] = d[j];
                    fp[j * nz + k] = f[j];
                }
            }
        },
    );
    cancelled(cancel)?;
    // Along x: columns of stride ny·nz, taken BLOCK neighbours at a time so each plane is read
    // in runs rather than one scattered value per column.
    const BLOCK: usize = 64;
    let blocks: Vec<(usize, Vec<u32>)> = (0..np.div_ceil(BLOCK))
        .into_par_iter()
        .map_init(
            || (Envelope::default(), vec![0f32; BLOCK * nx], vec![0u32; BLOCK * nx]),
            |(env, d, f), b| {
                let (c0, c1) = (b * BLOCK, ((b + 1) * BLOCK).min(np));
                let width = c1 - c0;
                // Transposed into the block: column c is d[c·nx..(c + 1)·nx].
                for i in 0..nx {
                    let row = i * np + c0;
                    for c in 0..width {
                        d[c * nx + i] = dist[row + c];
                        f[c * nx + i] = feature[row + c];
                    }
                }
                for c in 0..width {
                    env.line(&mut d[c * nx..(c + 1) * nx], &mut f[c * nx..(c + 1) * nx]);
                }
                let mut out = vec![0u32; width * nx];
                for i in 0..nx {
                    for c in 0..width {
                        out[i * width + c] = f[c * nx + i];
                    }
                }
                (c0, out)
            },
        )
        .collect();
    for (c0, out) in blocks {
        let width = out.len() / nx;
        for i in 0..nx {
            feature[i * np + c0..i * np + c0 + width].copy_from_slice(&out[i * width..(i + 1) * width]);
        }
    }
    Ok(feature)
}

/// The lower envelope of parabolas (q − p)² + d[p] along one line, reused between lines.
#[derive(Default)]
struct Envelope {
    /// Positions of the parabolas on the envelope, and where each starts to be lowest.
    v: Vec<usize>,
    z: Vec<f64>,
    d: Vec<f32>,
    f: Vec<u32>,
}

impl Envelope {
    /// Replaces `d` by the squared distance to the nearest source along the line (plus its own
    /// term) and `f` by that source's feature.
    fn line(&mut self, d: &mut [f32], f: &mut [u32]) {
        let n = d.len();
        self.v.clear();
        self.z.clear();
        let parabola = |p: usize, d: &[f32]| d[p] as f64 + (p * p) as f64;
        for q in 0..n {
            if !d[q].is_finite() {
                continue;
            }
            // Parabolas that q's lies below from where they start leave the envelope; the first
            // one (starting at −∞) never does.
            let mut start = f64::NEG_INFINITY;
            while let Some(&p) = self.v.last() {
                let s = (parabola(q, d) - parabola(p, d)) / (2.0 * (q as f64 - p as f64));
                if s <= *self.z.last().expect("z follows v") {
                    self.v.pop();
                    self.z.pop();
                } else {
                    start = s;
                    break;
                }
            }
            self.v.push(q);
            self.z.push(start);
        }
        if self.v.is_empty() {
            return;
        }
        self.d.clear();
        self.d.extend_from_slice(d);
        self.f.clear();
        self.f.extend_from_slice(f);
        let mut at = 0;
        for q in 0..n {
            while at + 1 < self.v.len() && self.z[at + 1] < q as f64 {
                at += 1;
            }
            let p = self.v[at];
            let dq = q as f64 - p as f64;
            d[q] = (dq * dq + self.d[p] as f64) as f32;
            f[q] = self.f[p];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_distance_transform_finds_the_nearest_outside_point() {
        // A 9×7×8 grid with an irregular blob inside; brute force agrees on the distance.
        let dims = [9, 7, 8];
        let idx = |i: usize, j: usize, k: usize| (i * dims[1] + j) * dims[2] + k;
        let mut inside = vec![false; dims.iter().product()];
        for i in 1..8 {
            for j in 1..6 {
                for k in 1..7 {
                    inside[idx(i, j, k)] = (i * 7 + j * 3 + k * 5) % 11 != 0;
                }
            }
        }
        let feature = nearest_outside(&inside, dims, &AtomicBool::new(false)).unwrap();
        let pos = |p: usize| [p / (dims[1] * dims[2]), p / dims[2] % dims[1], p % dims[2]];
        let d2 = |a: [usize; 3], b: [usize; 3]| (0..3).map(|c| (a[c] as i64 - b[c] as i64).pow(2)).sum::<i64>();
        for (p, &f) in feature.iter().enumerate() {
            let brute = (0..inside.len()).filter(|&q| !inside[q]).map(|q| d2(pos(p), pos(q))).min().unwrap();
            let f = f as usize;
            assert!(!inside[f], "point {p}: its nearest is outside");
            assert_eq!(d2(pos(p), pos(f)), brute, "point {p}");
        }
    }

    #[test]
    fn bad_parameters_and_huge_grids_are_refused_before_any_work() {
        let atom = [Sphere { centre: DVec3::ZERO, radius: 3.0 }];
        let no = AtomicBool::new(false);
        let mut p = SurfaceParams::auto(SurfaceKind::SolventExcluded, &atom);
        p.resolution = 0.0;
        assert!(matches!(build(&atom, &p, &no), Err(SurfaceError::BadParameter(..))));
        p.resolution = 1e-4;
        assert!(matches!(build(&atom, &p, &no), Err(SurfaceError::TooLarge { .. })));
        assert_eq!(
            build(&[], &SurfaceParams::auto(SurfaceKind::Gaussian, &atom), &no).unwrap_err(),
            SurfaceError::NoAtoms
        );
        let far = [atom[0], Sphere { centre: DVec3::splat(1e30), radius: 3.0 }];
        assert!(matches!(
            build(&far, &SurfaceParams::auto(SurfaceKind::Gaussian, &atom), &no),
            Err(SurfaceError::TooLarge { .. })
        ));
        let yes = AtomicBool::new(true);
        assert_eq!(
            build(&atom, &SurfaceParams::auto(SurfaceKind::Gaussian, &atom), &yes).unwrap_err(),
            SurfaceError::Cancelled
        );
    }

    #[test]
    fn progress_runs_to_a_thousandth_per_thousandth_and_stops_short_when_cancelled() {
        let atoms: Vec<Sphere> =
            (0..6).map(|i| Sphere { centre: DVec3::new(2.5 * i as f64, 0.0, 0.0), radius: 3.2 }).collect();
        for kind in [SurfaceKind::SolventExcluded, SurfaceKind::Gaussian] {
            let progress = AtomicU32::new(0);
            build_reporting(&atoms, &SurfaceParams::auto(kind, &atoms), &AtomicBool::new(false), &progress).unwrap();
            assert_eq!(progress.load(Ordering::Relaxed), 1000, "{kind:?}");
            let stopped = AtomicU32::new(0);
            let err = build_reporting(&atoms, &SurfaceParams::auto(kind, &atoms), &AtomicBool::new(true), &stopped);
            assert_eq!(err.unwrap_err(), SurfaceError::Cancelled);
            assert!((1..1000).contains(&stopped.load(Ordering::Relaxed)), "{kind:?}");
        }
        // The shares rise phase by phase.
        let ses = ["accessible spheres", "distance transform", "estimate", "exact distances", "marching cubes"];
        let at = |n: &str| PROGRESS_AT.iter().find(|(p, _)| *p == n).unwrap().1;
        assert!(ses.windows(2).all(|w| at(w[0]) < at(w[1])));
        assert!(at("gaussians") < at("marching cubes"));
    }
}
