//! Where a map lies: a plane (through three atoms, by origin and normal, along a bond), its
//! in-plane axes, and the rectangle of N×N points a map evaluates.

use glam::DVec3;

use super::PlaneError;
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{GridSpec, Molecule};

/// The most points along a side: 4000² values are 16 million, a minute of evaluation and
/// 128 MB of numbers; beyond that a map is no longer a figure.
pub const MAX_POINTS: usize = 4000;

/// Three points closer to a line than this sine of the angle between them span no plane a user
/// meant (the normal would follow rounding).
const COLLINEAR_SINE: f64 = 1e-4;

/// Atoms further than this from the plane (bohr) do not decide a map's default extent: a map
/// through a ring shows the ring and its neighbours, not the far side of the molecule.
const FIT_DISTANCE: f64 = 2.0 * BOHR_PER_ANGSTROM;

/// Space around the fitted atoms (bohr), where their orbitals and densities still show.
const MARGIN: f64 = 2.0 * BOHR_PER_ANGSTROM;

/// An infinite plane with a right-handed frame: `u` and `v` in the plane, `normal` = u × v, and
/// `origin` on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub normal: DVec3,
}

impl Frame {
    /// The plane through atoms `a`, `b` and `c` (1-based): u along a→b, the normal along
    /// (b − a) × (c − a), so v = n × u points to c's side.
    pub fn through_atoms(molecule: &Molecule, atoms: [usize; 3]) -> Result<Self, PlaneError> {
        let [a, b, c] = atoms.map(|i| atom_position(molecule, i));
        if atoms[0] == atoms[1] || atoms[1] == atoms[2] || atoms[0] == atoms[2] {
            return Err(PlaneError::Collinear(format!("atoms {},{},{} repeat an atom", atoms[0], atoms[1], atoms[2])));
        }
        Self::through_points(a?, b?, c?)
            .map_err(|_| PlaneError::Collinear(format!("atoms {},{},{} lie on a line", atoms[0], atoms[1], atoms[2])))
    }

    /// The plane through three points: u along a→b, v = n × u towards c.
    pub fn through_points(a: DVec3, b: DVec3, c: DVec3) -> Result<Self, PlaneError> {
        let (ab, ac) = (b - a, c - a);
        let n = ab.cross(ac);
        if !n.is_finite() || n.length() <= COLLINEAR_SINE * ab.length() * ac.length() {
            return Err(PlaneError::Collinear("the three points lie on a line".into()));
        }
        let normal = n.normalize();
        let u = ab.normalize();
        Ok(Self { origin: a, u, v: normal.cross(u), normal })
    }

    /// The plane through `origin` perpendicular to `normal`; u is the coordinate axis least
    /// aligned with the normal, made perpendicular to it (x for a plane facing z).
    pub fn from_normal(origin: DVec3, normal: DVec3) -> Result<Self, PlaneError> {
        if !normal.is_finite() || !origin.is_finite() || normal.length() <= 1e-12 {
            return Err(PlaneError::ZeroNormal);
        }
        let normal = normal.normalize();
        let a = normal.abs();
        let axis = if a.x <= a.y && a.x <= a.z {
            DVec3::X
        } else if a.y <= a.z {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let u = (axis - normal * normal.dot(axis)).normalize();
        Ok(Self { origin, u, v: normal.cross(u), normal })
    }

    /// The plane that holds the bond a→b (u along it, the origin at its middle) and the
    /// direction `toward` (v is its part perpendicular to the bond): with an offset, a plane
    /// parallel to the bond.
    pub fn along_bond(a: DVec3, b: DVec3, toward: DVec3) -> Result<Self, PlaneError> {
        let mid = 0.5 * (a + b);
        Self::through_points(a, b, a + toward)
            .map(|f| Self { origin: mid, ..f })
            .map_err(|_| PlaneError::Collinear("the direction runs along the bond".into()))
    }

    /// The same plane moved `distance` (bohr) along its normal.
    pub fn offset(self, distance: f64) -> Self {
        Self { origin: self.origin + self.normal * distance, ..self }
    }

    /// Signed distance of `p` from the plane (bohr), positive on the normal's side.
    pub fn distance(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }

    /// `p` projected into the plane, as (u, v) from the origin.
    pub fn coordinates(&self, p: DVec3) -> [f64; 2] {
        let d = p - self.origin;
        [d.dot(self.u), d.dot(self.v)]
    }

    /// A rectangle of `points`×`points` in this plane. `size` (bohr, u and v sides) or, when
    /// `None`, a square that holds the atoms near the plane with a margin. The rectangle is
    /// centred on the origin when `keep_origin`, else on the middle of those atoms.
    pub fn rectangle(
        &self,
        molecule: &Molecule,
        size: Option<[f64; 2]>,
        points: usize,
        keep_origin: bool,
    ) -> Result<Plane, PlaneError> {
        if !(2..=MAX_POINTS).contains(&points) {
            return Err(PlaneError::Points(points));
        }
        if let Some(s) = size
            && !s.iter().all(|x| x.is_finite() && *x > 0.0)
        {
            return Err(PlaneError::Extent(s.map(|x| x / BOHR_PER_ANGSTROM)));
        }
        let near: Vec<[f64; 2]> = molecule
            .atoms
            .iter()
            .filter(|a| self.distance(a.position).abs() <= FIT_DISTANCE)
            .map(|a| self.coordinates(a.position))
            .collect();
        // A plane away from every atom still frames the molecule seen through it.
        let fitted =
            if near.is_empty() { molecule.atoms.iter().map(|a| self.coordinates(a.position)).collect() } else { near };
        let (lo, hi) = fitted.iter().fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
        });
        let center =
            if keep_origin || fitted.is_empty() { [0.0, 0.0] } else { [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])] };
        let size = size.unwrap_or_else(|| {
            let half =
                fitted.iter().map(|p| (p[0] - center[0]).abs().max((p[1] - center[1]).abs())).fold(0.0, f64::max);
            [2.0 * (half + MARGIN); 2]
        });
        Ok(Plane { frame: *self, center: self.origin + self.u * center[0] + self.v * center[1], size, points })
    }
}

/// The position of atom `index` (1-based).
pub fn atom_position(molecule: &Molecule, index: usize) -> Result<DVec3, PlaneError> {
    index
        .checked_sub(1)
        .and_then(|i| molecule.atoms.get(i))
        .map(|a| a.position)
        .ok_or(PlaneError::Atom { index, atoms: molecule.atoms.len() })
}

/// The points of a map: `points`×`points` spread evenly over a `size` rectangle centred on
/// `center`, its sides along the frame's u and v.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    pub frame: Frame,
    pub center: DVec3,
    /// Sides along u and v, bohr.
    pub size: [f64; 2],
    pub points: usize,
}

impl Plane {
    /// Distance between neighbouring points along u and v (bohr).
    pub fn spacing(&self) -> [f64; 2] {
        self.size.map(|s| s / (self.points - 1) as f64)
    }

    /// In-plane coordinates (bohr, from the centre) of point (`i` along u, `j` along v).
    pub fn local(&self, i: usize, j: usize) -> [f64; 2] {
        let h = self.spacing();
        [i as f64 * h[0] - 0.5 * self.size[0], j as f64 * h[1] - 0.5 * self.size[1]]
    }

    /// Point (`i`, `j`) in space (bohr).
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        let [x, y] = self.local(i, j);
        self.center + self.frame.u * x + self.frame.v * y
    }

    /// Every point, u fastest: index j·N + i.
    pub fn points(&self) -> Vec<DVec3> {
        (0..self.points).flat_map(|j| (0..self.points).map(move |i| (i, j))).map(|(i, j)| self.point(i, j)).collect()
    }

    /// The points as a one-layer grid whose rows run along u (the fastest index of cube
    /// order), so the evaluator's grid paths apply: each value is still the quantity at its
    /// point, with exponentials carried along a row by recurrence (and factorised along the
    /// axes when the plane is a coordinate plane).
    pub fn grid(&self) -> GridSpec {
        let [hu, hv] = self.spacing();
        let steps = [self.frame.normal, self.frame.v * hv, self.frame.u * hu];
        GridSpec::new(self.point(0, 0), steps, [1, self.points, self.points])
    }

    /// `p` in the map's coordinates: bohr from the centre along u and v, and from the plane.
    pub fn project(&self, p: DVec3) -> ([f64; 2], f64) {
        let d = p - self.center;
        ([d.dot(self.frame.u), d.dot(self.frame.v)], d.dot(self.frame.normal))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;

    fn molecule(positions: &[[f64; 3]]) -> Molecule {
        Molecule::new(
            positions
                .iter()
                .map(|p| Atom { z: 6, charge: 6.0, position: DVec3::from_array(*p), ghost: false })
                .collect(),
        )
    }

    fn assert_orthonormal(f: &Frame) {
        for (a, b) in [(f.u, f.v), (f.v, f.normal), (f.u, f.normal)] {
            assert!(a.dot(b).abs() < 1e-14, "{a} · {b}");
        }
        for x in [f.u, f.v, f.normal] {
            assert!((x.length() - 1.0).abs() < 1e-14);
        }
        assert!((f.u.cross(f.v) - f.normal).length() < 1e-14, "right-handed");
        assert!((f.normal.cross(f.u) - f.v).length() < 1e-14, "v = n × u");
    }

    #[test]
    fn points_lie_on_the_plane_through_three_atoms_at_its_offset() {
        let m = molecule(&[[0.3, -1.2, 0.7], [2.1, 0.4, -0.5], [-0.8, 1.9, 1.3], [5.0, 5.0, 5.0]]);
        let offset = 0.529_177 * BOHR_PER_ANGSTROM;
        let frame = Frame::through_atoms(&m, [1, 2, 3]).unwrap();
        assert_orthonormal(&frame);
        assert!((frame.u - (m.atoms[1].position - m.atoms[0].position).normalize()).length() < 1e-14);
        let plane = frame.offset(offset).rectangle(&m, None, 31, false).unwrap();
        // The plane as the atoms define it, independently of the frame: n ∝ (b − a) × (c − a).
        let [a, b, c] = [0, 1, 2].map(|i| m.atoms[i].position);
        let n = (b - a).cross(c - a).normalize();
        let points = plane.points();
        assert_eq!(points.len(), 31 * 31);
        for p in &points {
            assert!(((*p - a).dot(n) - offset).abs() < 1e-12, "{p} off the plane");
        }
        // The grid is regular: neighbours along u are one spacing apart.
        let h = plane.spacing();
        assert!(((points[1] - points[0]).length() - h[0]).abs() < 1e-12);
        assert!(((points[31] - points[0]).length() - h[1]).abs() < 1e-12);
        // The evaluator's grid holds the same points in the same order.
        let grid = plane.grid();
        assert_eq!(grid.len(), points.len());
        for (n, p) in points.iter().enumerate() {
            assert!((grid.point(0, n / 31, n % 31) - *p).length() < 1e-12);
        }
        // The three atoms' projections lie inside the default square.
        for atom in [a, b, c] {
            let ([x, y], _) = plane.project(atom);
            assert!(x.abs() < 0.5 * plane.size[0] && y.abs() < 0.5 * plane.size[1]);
        }
    }

    #[test]
    fn a_plane_by_origin_and_normal_is_orthonormal_and_centred_on_its_origin() {
        let m = molecule(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        for normal in [DVec3::Z, DVec3::new(1.0, 2.0, -3.0), DVec3::new(0.0, -1e-3, 5.0)] {
            let origin = DVec3::new(0.5, -0.25, 1.0);
            let f = Frame::from_normal(origin, normal).unwrap();
            assert_orthonormal(&f);
            assert!((f.normal - normal.normalize()).length() < 1e-14);
            let plane = f.rectangle(&m, Some([4.0, 6.0]), 11, true).unwrap();
            assert_eq!(plane.center, origin);
            for p in plane.points() {
                assert!((p - origin).dot(f.normal).abs() < 1e-12);
            }
            assert!(((plane.point(10, 10) - plane.point(0, 0)).length() - 4f64.hypot(6.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn a_plane_along_a_bond_holds_the_bond_and_its_offset_is_parallel() {
        let (a, b) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0));
        let f = Frame::along_bond(a, b, DVec3::Z).unwrap();
        assert_orthonormal(&f);
        assert!(f.distance(a).abs() < 1e-14 && f.distance(b).abs() < 1e-14);
        let moved = f.offset(1.5);
        assert!((moved.distance(a) + 1.5).abs() < 1e-14 && (moved.distance(b) + 1.5).abs() < 1e-14);
        assert!(Frame::along_bond(a, b, b - a).is_err(), "a direction along the bond spans no plane");
    }

    #[test]
    fn bad_planes_are_refused_with_the_reason() {
        let m = molecule(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert!(matches!(Frame::through_atoms(&m, [1, 2, 3]), Err(PlaneError::Collinear(_))));
        assert!(matches!(Frame::through_atoms(&m, [1, 2, 2]), Err(PlaneError::Collinear(_))));
        assert!(matches!(Frame::through_atoms(&m, [1, 2, 5]), Err(PlaneError::Atom { index: 5, atoms: 4 })));
        assert!(matches!(Frame::through_atoms(&m, [0, 2, 4]), Err(PlaneError::Atom { index: 0, .. })));
        assert!(matches!(Frame::from_normal(DVec3::ZERO, DVec3::ZERO), Err(PlaneError::ZeroNormal)));
        assert!(matches!(Frame::from_normal(DVec3::ZERO, DVec3::NAN), Err(PlaneError::ZeroNormal)));
        let f = Frame::through_atoms(&m, [1, 2, 4]).unwrap();
        assert!(matches!(f.rectangle(&m, None, MAX_POINTS + 1, false), Err(PlaneError::Points(_))));
        assert!(matches!(f.rectangle(&m, None, 1, false), Err(PlaneError::Points(1))));
        assert!(matches!(f.rectangle(&m, Some([0.0, 1.0]), 10, false), Err(PlaneError::Extent(_))));
    }
}
