//! Dihedral scans (seed 000): key frames computed at known torsion angles θ, the skeleton at any
//! θ between them, and which orbital of each frame continues which orbital of the previous one.
//!
//! Solvers return every orbital with an arbitrary sign and may reorder orbitals of similar
//! energy between frames, so a frame's "HOMO" is matched to the previous frame's by overlap:
//! its sign is flipped when the overlap is negative, and a different orbital is reported (or
//! followed) when it overlaps the previous one better than the one of the same name.

use glam::{DQuat, DVec3};
use thiserror::Error;

use super::gto::{GridSpec, PreparedBasis};
use super::molecule::Molecule;
use super::orbitals::{OrbitalSpec, Spin, Wavefunction};
use super::overlap::cross_overlap;
use super::{Atom, VolumeGrid};

/// Two key angles closer than this (degrees) are the same angle.
pub const ANGLE_TOLERANCE: f64 = 1e-3;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScanError {
    #[error("a scan needs at least two frames, found {0}")]
    TooFewFrames(usize),
    #[error("atom {0} of the dihedral is beyond the {1} atoms of the molecule")]
    AtomOutOfRange(usize, usize),
    #[error("the dihedral's atoms must be four different atoms")]
    RepeatedAtom,
    #[error("atoms {0} and {1} of the dihedral lie in one ring: no fragment turns about their bond")]
    Ring(usize, usize),
    #[error("frame at {angle}°: no orbital {spec} (the frame's file has {available} orbitals of that spin)")]
    MissingOrbital { angle: f64, spec: String, available: usize },
    #[error("frame at {angle}°: {found} volumes for {wanted} orbitals")]
    MissingVolume { angle: f64, wanted: usize, found: usize },
}

/// What a key frame holds for its orbitals.
#[derive(Debug, Clone)]
pub enum FrameContent {
    /// Orbitals from basis sets (Molden, fchk), evaluated on the scan's common grid: one file
    /// for every slot, or one per slot (the same orbital from two methods side by side).
    Wavefunctions(Vec<Wavefunction>),
    /// Precomputed grids (cube files), one per requested orbital, all on one grid.
    Volumes(Vec<VolumeGrid>),
}

#[derive(Debug, Clone)]
pub struct KeyFrame {
    /// θ of this frame (degrees), as the manifest labels it.
    pub angle: f64,
    /// Where the frame came from (for messages).
    pub source: String,
    pub molecule: Molecule,
    pub content: FrameContent,
}

/// How an orbital slot picks its orbital in each frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Follow {
    /// By name: "HOMO" is each frame's HOMO (character swaps are reported).
    #[default]
    Index,
    /// By character: each frame's orbital is the one overlapping the previous frame's most.
    Overlap,
}

#[derive(Debug, Clone)]
pub struct Scan {
    pub title: String,
    /// The torsion's atoms, 0-based.
    pub dihedral: [usize; 4],
    /// What each view shows: the manifest's names ("homo", "lumo", "homo-1", …).
    pub orbitals: Vec<String>,
    /// Optional caption per view (say the method, when each view reads its own files).
    pub captions: Vec<String>,
    /// Key frames, sorted by strictly increasing angle.
    pub frames: Vec<KeyFrame>,
    /// Atoms that turn with θ: the side of the j–k bond that holds k.
    pub moving: Vec<usize>,
}

/// Where θ falls between the key frames: frames `a` ≤ θ ≤ `b` and the mixing ratio
/// k = (θ − θa)/(θb − θa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bracket {
    pub a: usize,
    pub b: usize,
    pub k: f64,
}

/// One orbital slot's choice in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackPoint {
    /// Index into the frame's `Wavefunction::orbitals` (or its volumes).
    pub index: usize,
    /// ±1: the factor that aligns the phase with the previous frame.
    pub sign: f64,
    /// Orbital energy (Eh), when the frame has one.
    pub energy: Option<f64>,
    /// ⟨previous|this⟩ after the sign (1 for the first frame).
    pub overlap: f64,
    /// Whether the solver turned this orbital's sign over since the previous frame (⟨previous
    /// as written|this as written⟩ < 0): the steps alignment undoes.
    pub flipped: bool,
}

/// A change of character: in `frame`, the orbital named like the slot is not the one that
/// continues the previous frame's.
#[derive(Debug, Clone, PartialEq)]
pub struct Swap {
    pub slot: usize,
    pub frame: usize,
    /// The orbital of the slot's name, and its |overlap| with the previous frame's.
    pub by_name: usize,
    pub by_name_overlap: f64,
    /// The orbital that overlaps the previous frame's most, and that |overlap|.
    pub by_overlap: usize,
    pub best_overlap: f64,
}

/// The orbitals each slot shows across the frames, phase-aligned.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracks {
    /// `points[slot][frame]`.
    pub points: Vec<Vec<TrackPoint>>,
    pub swaps: Vec<Swap>,
    pub follow: Follow,
}

impl Tracks {
    /// How many frame-to-frame steps the solver turned the slot's orbital over.
    pub fn flips(&self, slot: usize) -> usize {
        self.points[slot].iter().filter(|p| p.flipped).count()
    }
}

/// Orbitals further than this (in energy order) from the slot's named orbital are not
/// considered as its continuation.
const FOLLOW_WINDOW: usize = 3;

pub use super::measure::dihedral;

/// `angle` wrapped to (−180, 180].
pub fn wrap_degrees(angle: f64) -> f64 {
    let a = angle.rem_euclid(360.0);
    if a > 180.0 { a - 360.0 } else { a }
}

/// The dihedral `d` (0-based atoms) measured in a molecule.
pub fn measure(molecule: &Molecule, d: [usize; 4]) -> f64 {
    dihedral(d.map(|i| molecule.atoms[i].position))
}

/// The atoms on k's side of the j–k bond (k included, j not): what turns when the dihedral
/// about j–k changes. Fails when j can be reached from k without that bond (a ring).
pub fn moving_fragment(molecule: &Molecule, j: usize, k: usize) -> Result<Vec<usize>, ScanError> {
    let n = molecule.atoms.len();
    let mut neighbours = vec![Vec::new(); n];
    for b in &molecule.bonds {
        let (a, c) = (b.a as usize, b.b as usize);
        if (a == j && c == k) || (a == k && c == j) {
            continue;
        }
        neighbours[a].push(c);
        neighbours[c].push(a);
    }
    let mut seen = vec![false; n];
    let mut stack = vec![k];
    seen[k] = true;
    while let Some(a) = stack.pop() {
        for &c in &neighbours[a] {
            if c == j {
                return Err(ScanError::Ring(j + 1, k + 1));
            }
            if !seen[c] {
                seen[c] = true;
                stack.push(c);
            }
        }
    }
    Ok((0..n).filter(|&i| seen[i]).collect())
}

/// Turns `moving` atoms rigidly about the axis through `positions[j]` → `positions[k]` so that
/// the dihedral about j–k grows by `degrees`.
pub fn twist(positions: &mut [DVec3], moving: &[usize], j: usize, k: usize, degrees: f64) {
    let origin = positions[k];
    let axis = (positions[k] - positions[j]).normalize_or_zero();
    if axis == DVec3::ZERO {
        return;
    }
    let rotation = DQuat::from_axis_angle(axis, degrees.to_radians());
    for &i in moving {
        positions[i] = origin + rotation * (positions[i] - origin);
    }
}

/// The bonded torsion i–j–k–l whose angle changes most across `molecules` (all with the same
/// atoms; bonds from the first), or None when no bond has neighbours on both sides. Ring bonds
/// are skipped; the outer atoms are each side's heaviest neighbour, lowest number on ties.
pub fn most_changing_dihedral(molecules: &[Molecule]) -> Option<[usize; 4]> {
    let first = molecules.first()?;
    let n = first.atoms.len();
    let mut neighbours = vec![Vec::new(); n];
    for b in &first.bonds {
        neighbours[b.a as usize].push(b.b as usize);
        neighbours[b.b as usize].push(b.a as usize);
    }
    let outer = |centre: usize, other: usize| {
        neighbours[centre]
            .iter()
            .copied()
            .filter(|&x| x != other)
            .max_by(|&a, &b| first.atoms[a].z.cmp(&first.atoms[b].z).then(b.cmp(&a)))
    };
    let mut best: Option<([usize; 4], f64)> = None;
    for b in &first.bonds {
        let (j, k) = (b.a.min(b.b) as usize, b.a.max(b.b) as usize);
        let (Some(i), Some(l)) = (outer(j, k), outer(k, j)) else { continue };
        if i == l || moving_fragment(first, j, k).is_err() {
            continue;
        }
        let d = [i, j, k, l];
        // Spread of the angle around its first value, unwrapped.
        let start = measure(first, d);
        let (lo, hi) = molecules.iter().fold((0.0f64, 0.0f64), |(lo, hi), m| {
            let delta = wrap_degrees(measure(m, d) - start);
            (lo.min(delta), hi.max(delta))
        });
        if best.is_none_or(|(_, s)| hi - lo > s + 1e-9) {
            best = Some((d, hi - lo));
        }
    }
    best.map(|(d, _)| d)
}

impl Scan {
    /// Checks the dihedral against the molecule and finds the moving fragment. `frames` must be
    /// sorted by angle without duplicates (the manifest reader reports those with their lines).
    pub fn new(
        title: String,
        dihedral: [usize; 4],
        orbitals: Vec<String>,
        frames: Vec<KeyFrame>,
    ) -> Result<Self, ScanError> {
        if frames.len() < 2 {
            return Err(ScanError::TooFewFrames(frames.len()));
        }
        let n = frames[0].molecule.atoms.len();
        if let Some(&bad) = dihedral.iter().find(|&&i| i >= n) {
            return Err(ScanError::AtomOutOfRange(bad + 1, n));
        }
        let mut sorted = dihedral;
        sorted.sort_unstable();
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            return Err(ScanError::RepeatedAtom);
        }
        let moving = moving_fragment(&frames[0].molecule, dihedral[1], dihedral[2])?;
        Ok(Self { title, dihedral, orbitals, captions: Vec::new(), frames, moving })
    }

    /// The dihedral as chemists write it: "2-3-4-5" (1-based).
    pub fn dihedral_label(&self) -> String {
        self.dihedral.map(|i| (i + 1).to_string()).join("-")
    }

    /// The angle range covered by the key frames.
    pub fn range(&self) -> (f64, f64) {
        (self.frames[0].angle, self.frames[self.frames.len() - 1].angle)
    }

    pub fn angles(&self) -> Vec<f64> {
        self.frames.iter().map(|f| f.angle).collect()
    }

    /// The two key frames around θ (clamped to the scan's range).
    pub fn bracket(&self, theta: f64) -> Bracket {
        let (lo, hi) = self.range();
        let t = theta.clamp(lo, hi);
        let b = self.frames.iter().position(|f| f.angle >= t).unwrap_or(self.frames.len() - 1).max(1);
        let a = b - 1;
        let (ta, tb) = (self.frames[a].angle, self.frames[b].angle);
        Bracket { a, b, k: ((t - ta) / (tb - ta)).clamp(0.0, 1.0) }
    }

    /// The skeleton at θ: each bracketing frame's moving fragment turned towards θ by its share
    /// of the measured twist between them, then the two blended (1−k):k, so the result is each
    /// key frame's own geometry at its angle and a rigid rotation for rigid scans.
    pub fn geometry_at(&self, theta: f64) -> Molecule {
        let Bracket { a, b, k } = self.bracket(theta);
        let (fa, fb) = (&self.frames[a].molecule, &self.frames[b].molecule);
        let [_, j, kk, _] = self.dihedral;
        let delta = wrap_degrees(measure(fb, self.dihedral) - measure(fa, self.dihedral));
        let mut pa: Vec<DVec3> = fa.atoms.iter().map(|x| x.position).collect();
        let mut pb: Vec<DVec3> = fb.atoms.iter().map(|x| x.position).collect();
        twist(&mut pa, &self.moving, j, kk, k * delta);
        twist(&mut pb, &self.moving, j, kk, -(1.0 - k) * delta);
        let atoms: Vec<Atom> = fa
            .atoms
            .iter()
            .zip(pa.iter().zip(&pb))
            .map(|(atom, (&p, &q))| Atom { position: p.lerp(q, k), ..atom.clone() })
            .collect();
        Molecule { atoms, bonds: self.frames[0].molecule.bonds.clone() }
    }

    /// The angle of the key frame nearest to θ.
    pub fn nearest_frame(&self, theta: f64) -> usize {
        let Bracket { a, b, k } = self.bracket(theta);
        if k <= 0.5 { a } else { b }
    }

    /// Chooses each slot's orbital in every frame and aligns its phase with the previous frame
    /// by overlap: analytic overlaps between the frames' basis sets for wavefunctions, sums over
    /// the common grid for cube series.
    pub fn track(&self, follow: Follow) -> Result<Tracks, ScanError> {
        let mut points: Vec<Vec<TrackPoint>> = Vec::with_capacity(self.orbitals.len());
        let mut swaps = Vec::new();
        for (slot, name) in self.orbitals.iter().enumerate() {
            let spec: Option<OrbitalSpec> = name.parse().ok();
            let mut track: Vec<TrackPoint> = Vec::with_capacity(self.frames.len());
            let mut previous_basis: Option<PreparedBasis> = None;
            for (f, frame) in self.frames.iter().enumerate() {
                let by_name = self.named_orbital(frame, slot, spec)?;
                let wf = frame.wavefunction(slot);
                let energy_of = |i: usize| wf.map(|w| w.orbitals[i].energy);
                let basis = wf.map(|w| PreparedBasis::with_threshold(&w.basis, 0.0));
                let Some(&prev) = track.last() else {
                    track.push(TrackPoint {
                        index: by_name,
                        sign: 1.0,
                        energy: energy_of(by_name),
                        overlap: 1.0,
                        flipped: false,
                    });
                    previous_basis = basis;
                    continue;
                };
                let before = &self.frames[f - 1];
                // ⟨previous aligned|candidate⟩: analytic between the two frames' basis sets, or
                // over the common grid for cube series.
                let overlap_with: Box<dyn Fn(usize) -> f64> =
                    match (before.wavefunction(slot), wf, &previous_basis, &basis) {
                        (Some(pwf), Some(wf), Some(pb), Some(b)) => {
                            let s = cross_overlap(pb, b);
                            let ca = &pwf.orbitals[prev.index].coefficients;
                            Box::new(move |i| prev.sign * bilinear(ca, &s, &wf.orbitals[i].coefficients))
                        }
                        _ => match (&before.content, &frame.content) {
                            (FrameContent::Volumes(va), FrameContent::Volumes(vb)) => {
                                Box::new(move |i| prev.sign * grid_overlap(&va[prev.index], &vb[i]))
                            }
                            _ => Box::new(|_| 0.0),
                        },
                    };
                let (best, best_overlap) = candidates(frame, slot, by_name)
                    .into_iter()
                    .map(|i| (i, overlap_with(i)))
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                    .unwrap_or((by_name, overlap_with(by_name)));
                let named_overlap = overlap_with(by_name);
                if best != by_name && best_overlap.abs() > named_overlap.abs() + 1e-6 {
                    swaps.push(Swap {
                        slot,
                        frame: f,
                        by_name,
                        by_name_overlap: named_overlap.abs(),
                        by_overlap: best,
                        best_overlap: best_overlap.abs(),
                    });
                }
                let (index, o) = match follow {
                    Follow::Index => (by_name, named_overlap),
                    Follow::Overlap => (best, best_overlap),
                };
                let sign = if o < 0.0 { -1.0 } else { 1.0 };
                track.push(TrackPoint {
                    index,
                    sign,
                    energy: energy_of(index),
                    overlap: o * sign,
                    flipped: sign != prev.sign,
                });
                previous_basis = basis;
            }
            points.push(track);
        }
        Ok(Tracks { points, swaps, follow })
    }

    /// Checks that every frame has every slot's orbital, without computing any overlap.
    pub fn check_orbitals(&self) -> Result<(), ScanError> {
        for (slot, name) in self.orbitals.iter().enumerate() {
            let spec: Option<OrbitalSpec> = name.parse().ok();
            for frame in &self.frames {
                self.named_orbital(frame, slot, spec)?;
            }
        }
        Ok(())
    }

    /// A slot's orbital by name in one frame.
    fn named_orbital(&self, frame: &KeyFrame, slot: usize, spec: Option<OrbitalSpec>) -> Result<usize, ScanError> {
        match (&frame.content, frame.wavefunction(slot)) {
            (_, Some(wf)) => spec.and_then(|s| wf.resolve(s, Spin::Alpha)).ok_or_else(|| ScanError::MissingOrbital {
                angle: frame.angle,
                spec: self.orbitals[slot].clone(),
                available: wf.of_spin(Spin::Alpha).count(),
            }),
            (FrameContent::Volumes(v), _) if slot < v.len() => Ok(slot),
            (FrameContent::Volumes(v), _) => {
                Err(ScanError::MissingVolume { angle: frame.angle, wanted: self.orbitals.len(), found: v.len() })
            }
            (FrameContent::Wavefunctions(_), None) => {
                Err(ScanError::MissingVolume { angle: frame.angle, wanted: self.orbitals.len(), found: 0 })
            }
        }
    }
}

impl KeyFrame {
    /// The wavefunction a slot's orbital comes from: the frame's only one, or the slot's own.
    pub fn wavefunction(&self, slot: usize) -> Option<&Wavefunction> {
        match &self.content {
            FrameContent::Wavefunctions(w) if w.len() == 1 => w.first(),
            FrameContent::Wavefunctions(w) => w.get(slot),
            FrameContent::Volumes(_) => None,
        }
    }
}

/// aᵀ S b for S row-major len(a) × len(b).
fn bilinear(a: &[f64], s: &[f64], b: &[f64]) -> f64 {
    let nb = b.len().max(1);
    a.iter().enumerate().map(|(u, &x)| x * b.iter().enumerate().map(|(v, &y)| s[u * nb + v] * y).sum::<f64>()).sum()
}

/// The orbitals that may continue a slot's orbital in `frame`: same spin, within
/// [`FOLLOW_WINDOW`] of the named one in energy order; all volumes of a cube frame.
fn candidates(frame: &KeyFrame, slot: usize, by_name: usize) -> Vec<usize> {
    match (&frame.content, frame.wavefunction(slot)) {
        (_, Some(wf)) => {
            let order = wf.by_energy(wf.orbitals[by_name].spin);
            let pos = order.iter().position(|&i| i == by_name).unwrap_or(0);
            order[pos.saturating_sub(FOLLOW_WINDOW)..(pos + FOLLOW_WINDOW + 1).min(order.len())].to_vec()
        }
        (FrameContent::Volumes(v), _) => (0..v.len()).collect(),
        _ => vec![by_name],
    }
}

/// ∫ a·b dV over two grids of the same shape (the caller checks they share one grid).
pub fn grid_overlap(a: &VolumeGrid, b: &VolumeGrid) -> f64 {
    a.values.iter().zip(&b.values).map(|(&x, &y)| x as f64 * y as f64).sum::<f64>() * a.voxel_volume()
}

impl Scan {
    /// The grid all key volumes share: for cube series the cubes' grid; otherwise the box
    /// holding every frame's atoms plus `margin` (bohr), cubic voxels, `points` along its
    /// longest side.
    pub fn common_grid(&self, margin: f64, points: usize) -> GridSpec {
        if let FrameContent::Volumes(v) = &self.frames[0].content
            && let Some(g) = v.first()
        {
            return GridSpec { world_from_grid: g.world_from_grid, dims: g.dims };
        }
        let (lo, hi) = self
            .frames
            .iter()
            .filter_map(|f| f.molecule.bounds())
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
        GridSpec::cubic_voxels(lo - DVec3::splat(margin), hi + DVec3::splat(margin), points)
    }

    /// The grid key volumes are evaluated on, `points` along its longest side: the
    /// [`Self::decay_box`] of the tracked orbitals, or (cube series, no atoms)
    /// [`Self::common_grid`] with `margin`.
    pub fn key_grid(&self, tracks: &Tracks, margin: f64, points: usize) -> GridSpec {
        match self.decay_box(tracks) {
            Some((lo, hi)) => GridSpec::cubic_voxels(lo, hi, points),
            None => self.common_grid(margin, points),
        }
    }

    /// The box (bohr) that holds every slot's orbital in every key frame: the union of the
    /// boxes where each decays to 1 % of its largest |ψ| ([`super::extent::quantity_box`]).
    /// `None` for cube series (their grid is given) or frames without atoms.
    pub fn decay_box(&self, tracks: &Tracks) -> Option<(DVec3, DVec3)> {
        let mut boxes = Vec::new();
        for (f, frame) in self.frames.iter().enumerate() {
            for (slot, points) in tracks.points.iter().enumerate() {
                let wf = frame.wavefunction(slot)?;
                let orbital = super::orbitals::Quantity::Orbital(points[f].index);
                boxes.push(super::extent::quantity_box(wf, &frame.molecule, orbital)?);
            }
        }
        boxes.into_iter().reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
    }

    /// A slot's coefficient vector in `frame`, sign-aligned (wavefunction frames).
    pub fn aligned_coefficients(&self, tracks: &Tracks, slot: usize, frame: usize) -> Option<Vec<f64>> {
        let p = tracks.points[slot][frame];
        let wf = self.frames[frame].wavefunction(slot)?;
        Some(wf.orbitals[p.index].coefficients.iter().map(|c| c * p.sign).collect())
    }

    /// A slot's key volume in `frame` on `grid`, sign-aligned: evaluated on the CPU for
    /// wavefunction frames, the cube's values for cube frames.
    pub fn key_values(&self, tracks: &Tracks, slot: usize, frame: usize, grid: &GridSpec) -> Vec<f32> {
        let p = tracks.points[slot][frame];
        match (&self.frames[frame].content, self.frames[frame].wavefunction(slot)) {
            (_, Some(wf)) => {
                let c = self.aligned_coefficients(tracks, slot, frame).unwrap_or_default();
                PreparedBasis::new(&wf.basis).eval_grid_f32(&c, grid)
            }
            (FrameContent::Volumes(v), _) => v[p.index].values.iter().map(|&x| x * p.sign as f32).collect(),
            _ => vec![0.0; grid.len()],
        }
    }

    /// The exactly interpolated volume at θ: (1−k)·ψa + k·ψb of the two bracketing key frames.
    pub fn interpolated_values(&self, tracks: &Tracks, slot: usize, theta: f64, grid: &GridSpec) -> Vec<f32> {
        let Bracket { a, b, k } = self.bracket(theta);
        let (va, vb) = (self.key_values(tracks, slot, a, grid), self.key_values(tracks, slot, b, grid));
        let (wa, wb) = ((1.0 - k) as f32, k as f32);
        va.iter().zip(&vb).map(|(&x, &y)| wa * x + wb * y).collect()
    }

    /// [`Self::interpolated_values`] as a grid named `label`.
    pub fn interpolated_grid(
        &self,
        tracks: &Tracks,
        slot: usize,
        theta: f64,
        grid: &GridSpec,
        label: impl Into<String>,
    ) -> VolumeGrid {
        let values = self.interpolated_values(tracks, slot, theta, grid);
        let mut g = VolumeGrid::new(label, grid.dims, grid.world_from_grid, values);
        g.kind = super::grid::ValueKind::Signed;
        g
    }

    /// The slot showing the orbital named `name` (as the manifest names it, any case).
    pub fn slot(&self, name: &str) -> Option<usize> {
        self.orbitals.iter().position(|o| o.eq_ignore_ascii_case(name))
    }

    /// A slot's orbital energy at θ (Eh), interpolated linearly between the key frames.
    pub fn energy_at(&self, tracks: &Tracks, slot: usize, theta: f64) -> Option<f64> {
        let Bracket { a, b, k } = self.bracket(theta);
        let (ea, eb) = (tracks.points[slot][a].energy?, tracks.points[slot][b].energy?);
        Some((1.0 - k) * ea + k * eb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn atom(z: u32, p: [f64; 3]) -> Atom {
        Atom { z, charge: z as f64, position: DVec3::from(p), ghost: false }
    }

    /// Butane-like chain C–C–C–C with one H on each end carbon.
    fn chain() -> Molecule {
        Molecule::new(vec![
            atom(6, [-1.9, 1.9, 0.0]),
            atom(6, [0.0, 0.0, 0.0]),
            atom(6, [2.9, 0.0, 0.0]),
            atom(6, [4.8, 1.9, 0.0]),
            atom(1, [-3.8, 1.4, 0.0]),
            atom(1, [6.7, 1.4, 0.0]),
        ])
    }

    #[test]
    fn dihedral_sign_and_wrap() {
        let m = chain();
        assert!((measure(&m, [0, 1, 2, 3]).abs() - 0.0).abs() < 1e-9);
        let mut p: Vec<DVec3> = m.atoms.iter().map(|a| a.position).collect();
        let moving = moving_fragment(&m, 1, 2).unwrap();
        assert_eq!(moving, vec![2, 3, 5]);
        for target in [30.0, -75.0, 120.0, 179.0] {
            let mut q = p.clone();
            twist(&mut q, &moving, 1, 2, target);
            let d = dihedral([q[0], q[1], q[2], q[3]]);
            assert!((d - target).abs() < 1e-9, "{d} vs {target}");
        }
        twist(&mut p, &moving, 1, 2, 200.0);
        assert!((dihedral([p[0], p[1], p[2], p[3]]) - (-160.0)).abs() < 1e-9);
        assert_eq!(wrap_degrees(-180.0), 180.0);
        assert_eq!(wrap_degrees(540.0), 180.0);
    }

    #[test]
    fn ring_bonds_do_not_turn() {
        // Cyclobutane-like square: every bond is in the ring.
        let m = Molecule::new(vec![
            atom(6, [0.0, 0.0, 0.0]),
            atom(6, [2.9, 0.0, 0.0]),
            atom(6, [2.9, 2.9, 0.0]),
            atom(6, [0.0, 2.9, 0.0]),
        ]);
        assert_eq!(moving_fragment(&m, 0, 1), Err(ScanError::Ring(1, 2)));
        assert_eq!(most_changing_dihedral(&[m.clone(), m]), None);
    }

    fn frames(angles: &[f64]) -> Vec<KeyFrame> {
        let base = chain();
        let moving = moving_fragment(&base, 1, 2).unwrap();
        angles
            .iter()
            .map(|&angle| {
                let mut m = base.clone();
                let mut p: Vec<DVec3> = m.atoms.iter().map(|a| a.position).collect();
                twist(&mut p, &moving, 1, 2, angle);
                for (a, q) in m.atoms.iter_mut().zip(p) {
                    a.position = q;
                }
                KeyFrame { angle, source: format!("{angle}"), molecule: m, content: FrameContent::Volumes(vec![]) }
            })
            .collect()
    }

    #[test]
    fn geometry_follows_theta() {
        let scan = Scan::new("t".into(), [0, 1, 2, 3], vec![], frames(&[-180.0, -90.0, 0.0])).unwrap();
        for theta in [-180.0, -150.0, -90.0, -45.0, -10.0, 0.0] {
            let m = scan.geometry_at(theta);
            assert!((wrap_degrees(measure(&m, [0, 1, 2, 3]) - theta)).abs() < 1e-9, "{theta}");
            // Rigid: bond lengths unchanged.
            let d = (m.atoms[3].position - m.atoms[2].position).length();
            assert!((d - (chain().atoms[3].position - chain().atoms[2].position).length()).abs() < 1e-9);
        }
        assert_eq!(scan.bracket(-100.0), Bracket { a: 0, b: 1, k: 80.0 / 90.0 });
        assert_eq!(scan.bracket(-300.0).k, 0.0);
        assert_eq!(scan.bracket(-90.0).b, 1);
        let picked = most_changing_dihedral(&scan.frames.iter().map(|f| f.molecule.clone()).collect::<Vec<_>>());
        assert_eq!(picked, Some([0, 1, 2, 3]));
    }
}
