//! Scans (Naka et al., docs/references.md): key frames computed at known values of a coordinate — a bond length, a
//! bond angle, a dihedral, or a position along a path (an IRC, a relaxed scan) — the skeleton
//! at any value between them, and which orbital of each frame continues which orbital of the
//! previous one.
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
use super::superpose::superpose;
use super::{Atom, VolumeGrid};

/// The most key frames a scan holds: each is a file loaded and kept, and a volume per orbital
/// made from it.
pub const MAX_KEY_FRAMES: usize = 1000;
/// The most orbitals a scan shows side by side.
pub const MAX_SCAN_ORBITALS: usize = 16;

/// Two key frames whose coordinates are closer than this (degrees, Å, path units) are at the
/// same place.
pub const ANGLE_TOLERANCE: f64 = 1e-3;

/// What a scan's key frames vary. Atoms are 0-based.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coordinate {
    /// The distance between two atoms (Å): the side of the second moves along the bond.
    Distance([usize; 2]),
    /// The angle i–j–k at j (degrees): the side of k turns in the angle's plane.
    Angle([usize; 3]),
    /// The torsion i–j–k–l about the j–k bond (degrees): the side of k turns about the bond.
    Dihedral([usize; 4]),
    /// Frames in order with no single internal coordinate (an IRC, a relaxed scan, a morph):
    /// every atom moves, blended between frames. Its value is measured as the [`PathMeasure`]
    /// says.
    Path(PathMeasure),
}

/// What a path's value counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PathMeasure {
    /// The frame's number (manifests written before paths had a length).
    #[default]
    Frame,
    /// The length travelled from the first frame, Å: each step the root of the sum of the atoms'
    /// squared displacements once the frame is laid on the one before it.
    ArcLength,
    /// The same with each displacement weighted by √(atomic mass), amu^½·Å: the reaction
    /// coordinate IRCs print (in bohr there).
    MassWeighted,
}

impl PathMeasure {
    /// As manifests write it: "frame", "arc length", "mass-weighted arc length".
    pub fn name(self) -> &'static str {
        match self {
            PathMeasure::Frame => "frame",
            PathMeasure::ArcLength => "arc length",
            PathMeasure::MassWeighted => "mass-weighted arc length",
        }
    }

    /// The measure a manifest names.
    pub fn from_name(name: &str) -> Option<Self> {
        [PathMeasure::Frame, PathMeasure::ArcLength, PathMeasure::MassWeighted].into_iter().find(|m| m.name() == name)
    }
}

/// Where each of `molecules` (frames in path order, the same atoms) lies along the path, as
/// `measure` counts: 0 at the first frame. Each frame is laid on the one before it (the rigid
/// motion that fits it best), so a program writing each geometry in its own orientation adds no
/// length.
pub fn path_values(molecules: &[Molecule], measure: PathMeasure) -> Vec<f64> {
    if measure == PathMeasure::Frame {
        return (0..molecules.len()).map(|i| i as f64).collect();
    }
    let mut values = Vec::with_capacity(molecules.len());
    let mut travelled = 0.0;
    for (k, m) in molecules.iter().enumerate() {
        if k > 0 {
            let before: Vec<DVec3> = molecules[k - 1].atoms.iter().map(|a| a.position).collect();
            let here: Vec<DVec3> = m.atoms.iter().map(|a| a.position).collect();
            let (rotation, shift) = superpose(&here, &before);
            let squared: f64 = (m.atoms.iter().zip(here.iter().zip(&before)))
                .map(|(atom, (p, q))| {
                    let weight = match measure {
                        PathMeasure::MassWeighted => {
                            super::atomic_masses::ATOMIC_MASSES.get(atom.z as usize).copied().unwrap_or(0.0)
                        }
                        _ => 1.0,
                    };
                    weight * (rotation * *p + shift).distance_squared(*q)
                })
                .sum();
            travelled += squared.sqrt() * super::units::ANGSTROM_PER_BOHR;
        }
        values.push(travelled);
    }
    values
}

impl Coordinate {
    /// The atoms that define it (none for a path).
    pub fn atoms(&self) -> &[usize] {
        match self {
            Coordinate::Distance(a) => a,
            Coordinate::Angle(a) => a,
            Coordinate::Dihedral(a) => a,
            Coordinate::Path(_) => &[],
        }
    }

    /// "distance", "angle", "dihedral" or "path", as manifests name it.
    pub fn kind(&self) -> &'static str {
        match self {
            Coordinate::Distance(_) => "distance",
            Coordinate::Angle(_) => "angle",
            Coordinate::Dihedral(_) => "dihedral",
            Coordinate::Path(_) => "path",
        }
    }

    /// The values a key frame may take: a distance up to 1000 Å, an angle of 0° to 180°, a
    /// dihedral of one turn either way of ±360° (scans unwrapped past ±180° run on), any path
    /// parameter of at most 10⁹. Beyond them a manifest is mistyped, not a scan.
    pub fn value_range(&self) -> std::ops::RangeInclusive<f64> {
        match self {
            Coordinate::Distance(_) => 0.0..=1000.0,
            Coordinate::Angle(_) => 0.0..=180.0,
            Coordinate::Dihedral(_) => -720.0..=720.0,
            Coordinate::Path(_) => -1e9..=1e9,
        }
    }

    /// The unit values are given in: "Å", "°", a path's length's, or none for a path's frames.
    pub fn unit(&self) -> &'static str {
        match self {
            Coordinate::Distance(_) | Coordinate::Path(PathMeasure::ArcLength) => " Å",
            Coordinate::Angle(_) | Coordinate::Dihedral(_) => "°",
            Coordinate::Path(PathMeasure::MassWeighted) => " amu½·Å",
            Coordinate::Path(PathMeasure::Frame) => "",
        }
    }

    /// As chemists write it: "angle 2-1-3" (1-based), "path".
    pub fn label(&self) -> String {
        let atoms: Vec<String> = self.atoms().iter().map(|i| (i + 1).to_string()).collect();
        if atoms.is_empty() { self.kind().into() } else { format!("{} {}", self.kind(), atoms.join("-")) }
    }

    /// `value` with its unit: "104.5°", "1.200 Å", frame "3.00".
    pub fn value_text(&self, value: f64) -> String {
        match self {
            Coordinate::Distance(_) | Coordinate::Path(PathMeasure::ArcLength | PathMeasure::MassWeighted) => {
                format!("{value:.3}{}", self.unit())
            }
            Coordinate::Path(PathMeasure::Frame) => format!("{value:.2}"),
            _ => format!("{value:.1}°"),
        }
    }

    /// The coordinate measured in `molecule` (Å or degrees); None for a path.
    pub fn measure(&self, molecule: &Molecule) -> Option<f64> {
        let p = |i: usize| molecule.atoms[i].position;
        match *self {
            Coordinate::Distance([i, j]) => Some(p(i).distance(p(j)) * super::units::ANGSTROM_PER_BOHR),
            Coordinate::Angle([i, j, k]) => Some(super::measure::angle(p(i), p(j), p(k))),
            Coordinate::Dihedral(d) => Some(measure(molecule, d)),
            Coordinate::Path(_) => None,
        }
    }
}

/// The coordinate a program's scan job varied (Gaussian's ModRedundant `S` line, ORCA's `%geom
/// Scan` block), read from the job rather than guessed from the geometries, with its value at
/// each of the document's frames.
#[derive(Debug, Clone, PartialEq)]
pub struct JobScan {
    pub coordinate: Coordinate,
    /// The value at each frame (Å or degrees), measured in the frame's geometry; a dihedral's
    /// unwrapped so that the values run on past ±180° as the job stepped them.
    pub values: Vec<f64>,
    /// Where the job names it ("line 93: D 3 4 9 10 S 12 30.000"), for messages.
    pub from: String,
}

impl JobScan {
    /// `coordinate` measured in each of `frames`. A dihedral is carried across ±180° so that
    /// each value lies within half a turn of the one before (a scan stepping 30° from 180° goes
    /// to 210°, not −150°). `None` when an atom of the coordinate lies beyond a frame's.
    pub fn measured(coordinate: Coordinate, frames: &[Molecule], from: String) -> Option<Self> {
        let mut values: Vec<f64> = Vec::with_capacity(frames.len());
        for m in frames {
            if coordinate.atoms().iter().any(|&i| i >= m.atoms.len()) {
                return None;
            }
            let mut v = coordinate.measure(m)?;
            if let (Coordinate::Dihedral(_), Some(&last)) = (coordinate, values.last()) {
                v = last + wrap_degrees(v - last);
            }
            values.push(v);
        }
        Some(Self { coordinate, values, from })
    }

    /// A dihedral's values turned by whole turns so that the first lies within half a turn of
    /// `first`, the value the job asked for at its first point (a scan from 200° reads 200°,
    /// not −160°); other coordinates are as measured.
    pub fn starting_near(mut self, first: f64) -> Self {
        if let (Coordinate::Dihedral(_), Some(&v)) = (self.coordinate, self.values.first()) {
            let turns = ((first - v) / 360.0).round() * 360.0;
            if turns.is_finite() {
                self.values.iter_mut().for_each(|x| *x += turns);
            }
        }
        self
    }
}

#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScanError {
    #[error("a scan needs at least two frames, found {0}")]
    TooFewFrames(usize),
    #[error("atom {0} of the coordinate is beyond the {1} atoms of the molecule")]
    AtomOutOfRange(usize, usize),
    #[error("the coordinate's atoms must be different atoms")]
    RepeatedAtom,
    #[error("atoms {0} and {1} lie in one ring: no fragment moves on one side of their bond alone")]
    Ring(usize, usize),
    #[error("frame at {at}: no orbital {spec} (the frame's file has {available} orbitals of that spin)")]
    MissingOrbital { at: f64, spec: String, available: usize },
    #[error("frame at {at}: {found} volumes for {wanted} orbitals")]
    MissingVolume { at: f64, wanted: usize, found: usize },
    #[error("a path's frames are aligned with their orbitals: cube files cannot turn with them (align = false)")]
    AlignCubes,
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
    /// The coordinate's value at this frame (degrees, Å, or the path position), as the manifest
    /// labels it.
    pub at: f64,
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
    /// What the frames vary.
    pub coordinate: Coordinate,
    /// What each view shows: the manifest's names ("homo", "lumo", "homo-1", …).
    pub orbitals: Vec<String>,
    /// Optional caption per view (say the method, when each view reads its own files).
    pub captions: Vec<String>,
    /// Key frames, sorted by strictly increasing value.
    pub frames: Vec<KeyFrame>,
    /// Atoms that move with the coordinate: the side of the bond that holds its second (a
    /// distance) or third (an angle, a dihedral) atom; every atom for a path.
    pub moving: Vec<usize>,
    /// +1, or −1 when a distance's first atom's side moves (see [`moving_atoms`]).
    pub direction: f64,
}

/// Where a value x falls between the key frames: frames `a` ≤ x ≤ `b` and the mixing ratio
/// k = (x − xa)/(xb − xa).
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

/// Turns `moving` atoms rigidly about the axis through `positions[j]` perpendicular to the
/// plane of i–j–k, so that the angle i–j–k grows by `degrees`. A linear angle has no plane: any
/// axis perpendicular to the i–j bond serves.
pub fn bend(positions: &mut [DVec3], moving: &[usize], [i, j, k]: [usize; 3], degrees: f64) {
    let origin = positions[j];
    let (u, v) = (positions[i] - origin, positions[k] - origin);
    let axis = u.cross(v).try_normalize().or_else(|| u.any_orthonormal_vector().try_normalize());
    let Some(axis) = axis else { return };
    let rotation = DQuat::from_axis_angle(axis, degrees.to_radians());
    for &a in moving {
        positions[a] = origin + rotation * (positions[a] - origin);
    }
}

/// Moves `moving` atoms along the direction from `positions[i]` to `positions[j]` so that the
/// distance i–j grows by `angstrom`.
pub fn stretch(positions: &mut [DVec3], moving: &[usize], [i, j]: [usize; 2], angstrom: f64) {
    let Some(direction) = (positions[j] - positions[i]).try_normalize() else { return };
    let shift = direction * angstrom * super::units::BOHR_PER_ANGSTROM;
    for &a in moving {
        positions[a] += shift;
    }
}

/// The atoms that move with `coordinate` in `molecule`: the side of the bond that holds the
/// coordinate's second atom (a distance; the smaller side, with the sign of motion reversed,
/// when the two atoms are not bonded and the first's side is smaller) or third atom (an angle,
/// a dihedral); every atom for a path. Returns the atoms and ±1, the direction they move in.
pub fn moving_atoms(molecule: &Molecule, coordinate: &Coordinate) -> Result<(Vec<usize>, f64), ScanError> {
    match *coordinate {
        Coordinate::Distance([i, j]) => {
            let bonded = molecule
                .bonds
                .iter()
                .any(|b| (b.a as usize, b.b as usize) == (i, j) || (b.a as usize, b.b as usize) == (j, i));
            let of_j = moving_fragment(molecule, i, j)?;
            if bonded {
                return Ok((of_j, 1.0));
            }
            let of_i = moving_fragment(molecule, j, i)?;
            Ok(if of_i.len() < of_j.len() { (of_i, -1.0) } else { (of_j, 1.0) })
        }
        Coordinate::Angle([_, j, k]) | Coordinate::Dihedral([_, j, k, _]) => {
            Ok((moving_fragment(molecule, j, k)?, 1.0))
        }
        Coordinate::Path(_) => Ok(((0..molecule.atoms.len()).collect(), 1.0)),
    }
}

/// Moves `moving` atoms (going in `direction`, as [`moving_atoms`] gives them) so that
/// `coordinate` changes by `delta` (Å or degrees; nothing for a path).
fn shift(coordinate: &Coordinate, positions: &mut [DVec3], moving: &[usize], direction: f64, delta: f64) {
    match *coordinate {
        Coordinate::Distance(d) => stretch(positions, moving, d, direction * delta),
        Coordinate::Angle(a) => bend(positions, moving, a, delta),
        Coordinate::Dihedral([_, j, k, _]) => twist(positions, moving, j, k, delta),
        Coordinate::Path(_) => {}
    }
}

/// `molecule` with `coordinate` set to each of `values` (Å or degrees) by the rules a scan's
/// drag follows: the coordinate's moving side ([`moving_atoms`]) slides along the bond, bends in
/// the angle's plane or twists about the bond, rigidly; every other coordinate stays as it was.
pub fn rigid_frames(molecule: &Molecule, coordinate: &Coordinate, values: &[f64]) -> Result<Vec<Molecule>, ScanError> {
    let (moving, direction) = moving_atoms(molecule, coordinate)?;
    let Some(now) = coordinate.measure(molecule) else { return Ok(vec![molecule.clone(); values.len()]) };
    let start: Vec<DVec3> = molecule.atoms.iter().map(|a| a.position).collect();
    Ok(values
        .iter()
        .map(|&value| {
            let delta = match coordinate {
                Coordinate::Dihedral(_) => wrap_degrees(value - now),
                _ => value - now,
            };
            let mut positions = start.clone();
            shift(coordinate, &mut positions, &moving, direction, delta);
            let atoms =
                (molecule.atoms.iter().zip(positions)).map(|(a, position)| Atom { position, ..a.clone() }).collect();
            Molecule { atoms, bonds: molecule.bonds.clone() }
        })
        .collect())
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

/// Root-mean-square change of the interatomic distances (Å) from `a` to `b`: how far two
/// geometries differ whatever their orientation.
pub fn distance_change(a: &[DVec3], b: &[DVec3]) -> f64 {
    let n = a.len();
    let (mut sum, mut pairs) = (0.0, 0usize);
    for i in 0..n {
        for j in i + 1..n {
            let d = a[i].distance(a[j]) - b[i].distance(b[j]);
            sum += d * d;
            pairs += 1;
        }
    }
    (sum / pairs.max(1) as f64).sqrt() * super::units::ANGSTROM_PER_BOHR
}

/// How much of the change across `molecules` a coordinate leaves unexplained: each frame's
/// geometry predicted by moving the first frame's atoms to that frame's value of the coordinate
/// (as the scan moves them between key frames), compared with the frame by its interatomic
/// distances (Å, root mean square over the frames). None when its atoms cannot move alone.
pub fn unexplained(molecules: &[Molecule], coordinate: &Coordinate) -> Option<f64> {
    let first = molecules.first()?;
    let (moving, direction) = moving_atoms(first, coordinate).ok()?;
    let start = coordinate.measure(first)?;
    let p0: Vec<DVec3> = first.atoms.iter().map(|a| a.position).collect();
    let mut sum = 0.0;
    for m in &molecules[1..] {
        let mut delta = coordinate.measure(m)? - start;
        if let Coordinate::Dihedral(_) = coordinate {
            delta = wrap_degrees(delta);
        }
        let mut predicted = p0.clone();
        match *coordinate {
            Coordinate::Distance(d) => stretch(&mut predicted, &moving, d, direction * delta),
            Coordinate::Angle(a) => bend(&mut predicted, &moving, a, delta),
            Coordinate::Dihedral([_, j, k, _]) => twist(&mut predicted, &moving, j, k, delta),
            Coordinate::Path(_) => return None,
        }
        let actual: Vec<DVec3> = m.atoms.iter().map(|a| a.position).collect();
        sum += distance_change(&predicted, &actual).powi(2);
    }
    Some((sum / (molecules.len() - 1).max(1) as f64).sqrt())
}

/// A path explains frames that no single coordinate does: what the best one leaves
/// unexplained must stay under this (Å of interatomic distance, RMS).
pub const PATH_THRESHOLD: f64 = 0.02;

/// The bonded coordinate that explains the change across `molecules` best (bonds from the
/// first): every bond length, every angle between two bonds, each bond's dihedral (its sides'
/// heaviest neighbours); a path when even the best leaves more than [`PATH_THRESHOLD`]
/// unexplained. Ties go to the coordinate whose moving side is smaller. None when the frames
/// do not differ.
pub fn best_coordinate(molecules: &[Molecule]) -> Option<Coordinate> {
    let first = molecules.first()?;
    let p0: Vec<DVec3> = first.atoms.iter().map(|a| a.position).collect();
    let change = molecules[1..]
        .iter()
        .map(|m| distance_change(&p0, &m.atoms.iter().map(|a| a.position).collect::<Vec<_>>()))
        .fold(0.0, f64::max);
    if change < 1e-6 {
        return None;
    }
    let n = first.atoms.len();
    let mut neighbours = vec![Vec::new(); n];
    for b in &first.bonds {
        neighbours[b.a as usize].push(b.b as usize);
        neighbours[b.b as usize].push(b.a as usize);
    }
    let mut candidates = Vec::new();
    for b in &first.bonds {
        let (i, j) = (b.a as usize, b.b as usize);
        candidates.push(Coordinate::Distance([i, j]));
        candidates.push(Coordinate::Distance([j, i]));
    }
    for (j, around) in neighbours.iter().enumerate() {
        for &i in around {
            for &k in around.iter().filter(|&&k| k != i) {
                candidates.push(Coordinate::Angle([i, j, k]));
            }
        }
    }
    candidates.extend(most_changing_dihedral(molecules).map(Coordinate::Dihedral));
    let mut best: Option<(Coordinate, f64, usize)> = None;
    for c in candidates {
        let Some(left) = unexplained(molecules, &c) else { continue };
        let moving = moving_atoms(first, &c).map_or(usize::MAX, |(m, _)| m.len());
        let better = match best {
            None => true,
            Some((_, l, m)) => left < l - 1e-6 || (left <= l + 1e-6 && moving < m),
        };
        if better {
            best = Some((c, left, moving));
        }
    }
    match best {
        Some((c, left, _)) if left <= PATH_THRESHOLD => Some(c),
        _ => Some(Coordinate::Path(PathMeasure::ArcLength)),
    }
}

/// Lays each frame on the one before it (frames in path order): the rigid motion that fits its
/// atoms to the previous frame's best ([`superpose`]), applied to the atoms and to every
/// wavefunction of the frame, so its orbitals turn with it ([`super::rigid::moved`]). The
/// first frame stays where its file put it.
pub fn align_frames(frames: &mut [&mut KeyFrame]) -> Result<(), ScanError> {
    for f in 1..frames.len() {
        let target: Vec<DVec3> = frames[f - 1].molecule.atoms.iter().map(|a| a.position).collect();
        let frame = &mut frames[f];
        let here: Vec<DVec3> = frame.molecule.atoms.iter().map(|a| a.position).collect();
        let (rotation, shift) = superpose(&here, &target);
        for atom in &mut frame.molecule.atoms {
            atom.position = rotation * atom.position + shift;
        }
        match &mut frame.content {
            FrameContent::Wavefunctions(waves) => {
                for wf in waves.iter_mut() {
                    *wf = super::rigid::moved(wf, rotation, shift);
                }
            }
            FrameContent::Volumes(_) => return Err(ScanError::AlignCubes),
        }
    }
    Ok(())
}

impl Scan {
    /// What view `slot` shows, as the window names it: "HOMO", "LUMO+1", after the view's
    /// caption when it has one ("RHF: HOMO").
    pub fn slot_name(&self, slot: usize) -> String {
        let name = self.orbitals.get(slot).map_or_else(|| format!("orbital {}", slot + 1), |o| o.to_uppercase());
        let name = name.replace('-', "−");
        match self.captions.get(slot).filter(|c| !c.is_empty()) {
            Some(caption) => format!("{caption}: {name}"),
            None => name,
        }
    }

    /// Checks the coordinate against the molecule and finds the atoms that move with it.
    /// `frames` must be sorted by value without duplicates (the manifest reader reports those
    /// with their lines).
    pub fn new(
        title: String,
        coordinate: Coordinate,
        orbitals: Vec<String>,
        frames: Vec<KeyFrame>,
    ) -> Result<Self, ScanError> {
        if frames.len() < 2 {
            return Err(ScanError::TooFewFrames(frames.len()));
        }
        let n = frames[0].molecule.atoms.len();
        if let Some(&bad) = coordinate.atoms().iter().find(|&&i| i >= n) {
            return Err(ScanError::AtomOutOfRange(bad + 1, n));
        }
        let mut sorted = coordinate.atoms().to_vec();
        sorted.sort_unstable();
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            return Err(ScanError::RepeatedAtom);
        }
        let (moving, direction) = moving_atoms(&frames[0].molecule, &coordinate)?;
        Ok(Self { title, coordinate, orbitals, captions: Vec::new(), frames, moving, direction })
    }

    /// The value range covered by the key frames.
    pub fn range(&self) -> (f64, f64) {
        (self.frames[0].at, self.frames[self.frames.len() - 1].at)
    }

    /// Each key frame's value.
    pub fn values(&self) -> Vec<f64> {
        self.frames.iter().map(|f| f.at).collect()
    }

    /// The two key frames around the value (clamped to the scan's range).
    pub fn bracket(&self, value: f64) -> Bracket {
        let (lo, hi) = self.range();
        let t = value.clamp(lo, hi);
        let b = self.frames.iter().position(|f| f.at >= t).unwrap_or(self.frames.len() - 1).max(1);
        let a = b - 1;
        let (ta, tb) = (self.frames[a].at, self.frames[b].at);
        Bracket { a, b, k: ((t - ta) / (tb - ta)).clamp(0.0, 1.0) }
    }

    /// Moves the coordinate's moving atoms in `positions` so the coordinate changes by `delta`
    /// (Å or degrees; nothing for a path).
    fn shift(&self, positions: &mut [DVec3], delta: f64) {
        shift(&self.coordinate, positions, &self.moving, self.direction, delta);
    }

    /// The skeleton at the value: each bracketing frame's moving fragment moved towards the value by its share
    /// of the measured change between them (slid along the bond, bent in the angle's plane,
    /// twisted about the bond), then the two blended (1−k):k, so the result is each key frame's
    /// own geometry at its value, and a rigid motion for rigid scans. A path blends the frames.
    pub fn geometry_at(&self, value: f64) -> Molecule {
        let Bracket { a, b, k } = self.bracket(value);
        let (fa, fb) = (&self.frames[a].molecule, &self.frames[b].molecule);
        let mut pa: Vec<DVec3> = fa.atoms.iter().map(|x| x.position).collect();
        let mut pb: Vec<DVec3> = fb.atoms.iter().map(|x| x.position).collect();
        if let (Some(va), Some(vb)) = (self.coordinate.measure(fa), self.coordinate.measure(fb)) {
            let delta = match self.coordinate {
                Coordinate::Dihedral(_) => wrap_degrees(vb - va),
                _ => vb - va,
            };
            self.shift(&mut pa, k * delta);
            self.shift(&mut pb, -(1.0 - k) * delta);
        }
        // Both shapes are now at the value; a program may have written the frames in different
        // orientations (a symmetric bend moves both arms in the standard orientation). Blend
        // them laid on each other, then carry the blend the fraction k of the way from frame a's
        // orientation to frame b's: each key frame comes back exactly as written.
        let (rotation, shift) = superpose(&pb, &pa);
        let centre = pa.iter().copied().sum::<DVec3>() / pa.len().max(1) as f64;
        let back = rotation.inverse();
        let turn = DQuat::IDENTITY.slerp(back, k);
        let travel = back * (centre - shift) - centre;
        let atoms: Vec<Atom> = fa
            .atoms
            .iter()
            .zip(pa.iter().zip(&pb))
            .map(|(atom, (&p, &q))| {
                let blended = p.lerp(rotation * q + shift, k);
                Atom { position: turn * (blended - centre) + centre + k * travel, ..atom.clone() }
            })
            .collect();
        Molecule { atoms, bonds: self.frames[0].molecule.bonds.clone() }
    }

    /// The key frame nearest to the value.
    pub fn nearest_frame(&self, value: f64) -> usize {
        let Bracket { a, b, k } = self.bracket(value);
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
                at: frame.at,
                spec: self.orbitals[slot].clone(),
                available: wf.of_spin(Spin::Alpha).count(),
            }),
            (FrameContent::Volumes(v), _) if slot < v.len() => Ok(slot),
            (FrameContent::Volumes(v), _) => {
                Err(ScanError::MissingVolume { at: frame.at, wanted: self.orbitals.len(), found: v.len() })
            }
            (FrameContent::Wavefunctions(_), None) => {
                Err(ScanError::MissingVolume { at: frame.at, wanted: self.orbitals.len(), found: 0 })
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

    /// The exactly interpolated volume at the value: (1−k)·ψa + k·ψb of the two bracketing key frames.
    pub fn interpolated_values(&self, tracks: &Tracks, slot: usize, value: f64, grid: &GridSpec) -> Vec<f32> {
        let Bracket { a, b, k } = self.bracket(value);
        let (va, vb) = (self.key_values(tracks, slot, a, grid), self.key_values(tracks, slot, b, grid));
        let (wa, wb) = ((1.0 - k) as f32, k as f32);
        va.iter().zip(&vb).map(|(&x, &y)| wa * x + wb * y).collect()
    }

    /// [`Self::interpolated_values`] as a grid named `label`.
    pub fn interpolated_grid(
        &self,
        tracks: &Tracks,
        slot: usize,
        value: f64,
        grid: &GridSpec,
        label: impl Into<String>,
    ) -> VolumeGrid {
        let values = self.interpolated_values(tracks, slot, value, grid);
        let mut g = VolumeGrid::new(label, grid.dims, grid.world_from_grid, values);
        g.kind = super::grid::ValueKind::Signed;
        g
    }

    /// The slot showing the orbital named `name` (as the manifest names it, any case).
    pub fn slot(&self, name: &str) -> Option<usize> {
        self.orbitals.iter().position(|o| o.eq_ignore_ascii_case(name))
    }

    /// A slot's orbital energy at the value (Eh), interpolated linearly between the key frames.
    pub fn energy_at(&self, tracks: &Tracks, slot: usize, value: f64) -> Option<f64> {
        let Bracket { a, b, k } = self.bracket(value);
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
    #[test]
    fn a_job_scan_carries_its_dihedral_across_a_half_turn_either_way() {
        // H–O–O–H turned about the O–O bond in steps of 50°, up from 150° and down from −150°.
        let frame = |d: f64| {
            let d = d.to_radians();
            Molecule::new(vec![
                atom(1, [1.0, 0.0, 0.0]),
                atom(8, [0.0, 0.0, 0.0]),
                atom(8, [0.0, 0.0, 1.4]),
                atom(1, [d.cos(), d.sin(), 1.4]),
            ])
        };
        let c = Coordinate::Dihedral([0, 1, 2, 3]);
        for (from, step) in [(150.0, 50.0), (-150.0, -50.0)] {
            let frames: Vec<Molecule> = (0..6).map(|k| frame(from + step * k as f64)).collect();
            let job = JobScan::measured(c, &frames, "test".into()).unwrap();
            // Steps of 50° one way throughout (whatever sign the convention gives), none of
            // them a jump of a turn back across ±180°.
            assert!((job.values[0].abs() - 150.0).abs() < 1e-9, "{:?}", job.values);
            let steps: Vec<f64> = job.values.windows(2).map(|w| w[1] - w[0]).collect();
            assert!(
                steps.iter().all(|s| (s.abs() - 50.0).abs() < 1e-9 && s.signum() == steps[0].signum()),
                "{steps:?}"
            );
            assert!(job.values[5].abs() > 360.0, "{:?}", job.values);
        }
        // A distance is measured as it is, in Å; an atom beyond the frames' is no scan.
        let d = JobScan::measured(Coordinate::Distance([1, 2]), &[frame(0.0)], "test".into()).unwrap();
        assert!((d.values[0] - 1.4 * crate::model::units::ANGSTROM_PER_BOHR).abs() < 1e-12);
        assert!(JobScan::measured(Coordinate::Distance([1, 4]), &[frame(0.0)], "test".into()).is_none());
    }

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
                KeyFrame { at: angle, source: format!("{angle}"), molecule: m, content: FrameContent::Volumes(vec![]) }
            })
            .collect()
    }

    #[test]
    fn geometry_follows_the_value() {
        let scan =
            Scan::new("t".into(), Coordinate::Dihedral([0, 1, 2, 3]), vec![], frames(&[-180.0, -90.0, 0.0])).unwrap();
        for value in [-180.0, -150.0, -90.0, -45.0, -10.0, 0.0] {
            let m = scan.geometry_at(value);
            assert!((wrap_degrees(measure(&m, [0, 1, 2, 3]) - value)).abs() < 1e-9, "{value}");
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

    /// Water, O first, bent to `angle` degrees with O–H of `oh` Å, in the xy plane.
    fn water(angle: f64, oh: f64) -> Molecule {
        let r = oh * crate::model::units::BOHR_PER_ANGSTROM;
        let half = (angle / 2.0).to_radians();
        Molecule::new(vec![
            atom(8, [0.0, 0.0, 0.0]),
            atom(1, [r * half.sin(), r * half.cos(), 0.0]),
            atom(1, [-r * half.sin(), r * half.cos(), 0.0]),
        ])
    }

    fn key(at: f64, molecule: Molecule) -> KeyFrame {
        KeyFrame { at, source: format!("{at}"), molecule, content: FrameContent::Volumes(vec![]) }
    }

    #[test]
    fn a_path_is_measured_by_the_length_travelled_whatever_each_frame_s_orientation() {
        // A symmetric stretch, 0.96 → 1.06 → 1.16 Å: the best fit only centres the frames, so
        // each step is √Σ|Δₐ − Δ̄|² (Δ̄ the mean displacement) and the steps are equal.
        let frames: Vec<Molecule> = [0.96, 1.06, 1.16].iter().map(|&r| water(104.5, r)).collect();
        let p = |m: &Molecule| m.atoms.iter().map(|a| a.position).collect::<Vec<_>>();
        let (a, b) = (p(&frames[0]), p(&frames[1]));
        let d: Vec<DVec3> = a.iter().zip(&b).map(|(x, y)| *y - *x).collect();
        let mean = d.iter().copied().sum::<DVec3>() / 3.0;
        let masses = [15.999, 1.008, 1.008];
        let step = |w: &[f64]| {
            d.iter().zip(w).map(|(v, w)| w * (*v - mean).length_squared()).sum::<f64>().sqrt()
                * crate::model::units::ANGSTROM_PER_BOHR
        };
        let plain = path_values(&frames, PathMeasure::ArcLength);
        assert!((plain[1] - step(&[1.0; 3])).abs() < 1e-9 && (plain[2] - 2.0 * plain[1]).abs() < 1e-9, "{plain:?}");
        let weighted = path_values(&frames, PathMeasure::MassWeighted);
        assert!((weighted[1] - step(&masses)).abs() < 1e-6, "{weighted:?} vs {}", step(&masses));
        // Each frame written in its own orientation and place: the same lengths.
        let mut turned = frames.clone();
        for (k, m) in turned.iter_mut().enumerate() {
            let r = DQuat::from_rotation_y(0.7 * k as f64) * DQuat::from_rotation_x(0.3);
            for atom in &mut m.atoms {
                atom.position = r * atom.position + DVec3::new(1.5, -2.0, 0.5 * k as f64);
            }
        }
        let again = path_values(&turned, PathMeasure::ArcLength);
        assert!(again.iter().zip(&plain).all(|(x, y)| (x - y).abs() < 1e-8), "{again:?} vs {plain:?}");
        assert_eq!(path_values(&frames, PathMeasure::Frame), vec![0.0, 1.0, 2.0]);
        let c = Coordinate::Path(PathMeasure::ArcLength);
        assert_eq!((c.value_text(0.1234), c.unit()), ("0.123 Å".to_string(), " Å"));
    }

    #[test]
    fn bending_and_stretching_reproduce_key_frames_and_move_one_side() {
        // An angle scan: H2 turns in the plane about O; key frames reproduced exactly.
        let frames: Vec<KeyFrame> = [90.0, 105.0, 120.0].iter().map(|&a| key(a, water(a, 0.96))).collect();
        let scan = Scan::new("bend".into(), Coordinate::Angle([1, 0, 2]), vec![], frames.clone()).unwrap();
        assert_eq!(scan.moving, vec![2], "the side of the third atom moves");
        for value in [90.0, 97.0, 105.0, 111.5, 120.0] {
            let m = scan.geometry_at(value);
            let measured = scan.coordinate.measure(&m).unwrap();
            assert!((measured - value).abs() < 1e-9, "{value}: {measured}");
            let oh = m.atoms[0].position.distance(m.atoms[2].position) * crate::model::units::ANGSTROM_PER_BOHR;
            assert!((oh - 0.96).abs() < 1e-12, "the arm keeps its length");
        }
        for f in &frames {
            let m = scan.geometry_at(f.at);
            let apart = distance_change(&positions(&m), &positions(&f.molecule));
            assert!(apart < 1e-12, "key frame at {} reproduced ({apart})", f.at);
        }
        // A bond-length scan: H2 slides along O–H2.
        let frames: Vec<KeyFrame> = [0.9, 1.2, 1.6].iter().map(|&r| key(r, stretched(r))).collect();
        let scan = Scan::new("stretch".into(), Coordinate::Distance([0, 2]), vec![], frames).unwrap();
        assert_eq!(scan.moving, vec![2]);
        for r in [0.9, 1.05, 1.37, 1.6] {
            let measured = scan.coordinate.measure(&scan.geometry_at(r)).unwrap();
            assert!((measured - r).abs() < 1e-9, "{r}: {measured}");
        }
        // A linear angle has no plane, and still bends.
        let mut p = vec![DVec3::new(-1.0, 0.0, 0.0), DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0)];
        bend(&mut p, &[2], [0, 1, 2], -30.0);
        assert!((crate::model::measure::angle(p[0], p[1], p[2]) - 150.0).abs() < 1e-9);
    }

    fn positions(m: &Molecule) -> Vec<DVec3> {
        m.atoms.iter().map(|a| a.position).collect()
    }

    /// Water at 104.5° with its second O–H at `r` Å.
    fn stretched(r: f64) -> Molecule {
        let mut m = water(104.5, 0.96);
        let o = m.atoms[0].position;
        let dir = (m.atoms[2].position - o).normalize();
        m.atoms[2].position = o + dir * r * crate::model::units::BOHR_PER_ANGSTROM;
        m
    }

    #[test]
    fn the_coordinate_that_explains_the_frames_is_found() {
        let bends: Vec<Molecule> = [95.0, 105.0, 115.0, 125.0].iter().map(|&a| water(a, 0.96)).collect();
        let c = best_coordinate(&bends).unwrap();
        assert!(matches!(c, Coordinate::Angle([_, 0, _])), "{c:?}");
        assert!(unexplained(&bends, &c).unwrap() < 1e-9);
        let stretches: Vec<Molecule> = [0.9, 1.1, 1.3].iter().map(|&r| stretched(r)).collect();
        assert_eq!(best_coordinate(&stretches), Some(Coordinate::Distance([0, 2])));
        let twists: Vec<Molecule> = frames(&[-180.0, -120.0, -60.0]).into_iter().map(|f| f.molecule).collect();
        assert_eq!(best_coordinate(&twists), Some(Coordinate::Dihedral([0, 1, 2, 3])));
        // Bending and stretching at once: no single coordinate explains it, a path does.
        let both: Vec<Molecule> = [(95.0, 0.9), (110.0, 1.1), (125.0, 1.3)].iter().map(|&(a, r)| water(a, r)).collect();
        assert_eq!(best_coordinate(&both), Some(Coordinate::Path(PathMeasure::ArcLength)));
        assert_eq!(best_coordinate(&[water(100.0, 1.0), water(100.0, 1.0)]), None, "nothing changes");
    }

    #[test]
    fn a_path_blends_every_atom() {
        let (a, b) = (water(95.0, 0.9), water(125.0, 1.3));
        let scan = Scan::new(
            "path".into(),
            Coordinate::Path(PathMeasure::Frame),
            vec![],
            vec![key(0.0, a.clone()), key(1.0, b.clone())],
        )
        .unwrap();
        assert_eq!(scan.moving, vec![0, 1, 2]);
        let mid = scan.geometry_at(0.5);
        for i in 0..3 {
            let want = a.atoms[i].position.lerp(b.atoms[i].position, 0.5);
            assert!(mid.atoms[i].position.distance(want) < 1e-12);
        }
    }
}
