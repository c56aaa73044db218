//! Distances, angles and dihedrals between atoms: what a chemist measures by picking two,
//! three or four atoms.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::Molecule;
use super::units::BOHR_PER_ANGSTROM;

/// Angle at `b` between `a` and `c`, degrees (0..=180).
pub fn angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (a - b).angle_between(c - b).to_degrees()
}

/// Dihedral angle a–b–c–d in degrees, (−180, 180], IUPAC sign (clockwise looking from b to c
/// is positive).
pub fn dihedral(p: [DVec3; 4]) -> f64 {
    let (b1, b2, b3) = (p[1] - p[0], p[2] - p[1], p[3] - p[2]);
    let n1 = b1.cross(b2);
    let n2 = b2.cross(b3);
    let y = b2.length() * b1.dot(n2);
    let x = n1.dot(n2);
    y.atan2(x).to_degrees()
}

/// A measurement between 2 (distance), 3 (angle) or 4 (dihedral) atoms, by 0-based index.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Measurement {
    pub atoms: Vec<usize>,
}

impl Measurement {
    /// A measurement of 2 to 4 distinct atoms; `None` otherwise.
    pub fn new(atoms: &[usize]) -> Option<Self> {
        let distinct = atoms.iter().enumerate().all(|(n, a)| !atoms[..n].contains(a));
        ((2..=4).contains(&atoms.len()) && distinct).then(|| Self { atoms: atoms.to_vec() })
    }

    /// Its value in `molecule`: ångström for a distance, degrees for angles; `None` when an
    /// atom is not in the molecule.
    pub fn value(&self, molecule: &Molecule) -> Option<f64> {
        let p: Vec<DVec3> =
            self.atoms.iter().map(|&i| molecule.atoms.get(i).map(|a| a.position)).collect::<Option<_>>()?;
        Some(match p[..] {
            [a, b] => a.distance(b) / BOHR_PER_ANGSTROM,
            [a, b, c] => angle(a, b, c),
            [a, b, c, d] => dihedral([a, b, c, d]),
            _ => return None,
        })
    }

    /// "O1–C2 1.208 Å", "H3–C2–O1 121.6°", "C1–C2–C3–C4 −90.0°".
    pub fn label(&self, molecule: &Molecule) -> String {
        let names: Vec<String> = self
            .atoms
            .iter()
            .map(|&i| molecule.atoms.get(i).map_or("?".into(), |a| format!("{}{}", a.element().symbol, i + 1)))
            .collect();
        let value = match self.value(molecule) {
            Some(v) if self.atoms.len() == 2 => format!("{v:.3} Å"),
            Some(v) => format!("{v:.1}°").replace('-', "−"),
            None => "—".into(),
        };
        format!("{} {value}", names.join("–"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;

    fn atom(z: u32, ang: [f64; 3]) -> Atom {
        Atom { z, charge: z as f64, position: DVec3::from_array(ang) * BOHR_PER_ANGSTROM, ghost: false }
    }

    #[test]
    fn distance_angle_and_dihedral_of_a_known_geometry() {
        // H–O–O–H with the hydrogens at ±90° about the O–O axis.
        let m = Molecule::new(vec![
            atom(1, [0.0, 1.0, 0.0]),
            atom(8, [0.0, 0.0, 0.0]),
            atom(8, [1.5, 0.0, 0.0]),
            atom(1, [1.5, 0.0, 1.0]),
        ]);
        let v = |a: &[usize]| Measurement::new(a).unwrap().value(&m).unwrap();
        assert!((v(&[1, 2]) - 1.5).abs() < 1e-12);
        assert!((v(&[0, 1, 2]) - 90.0).abs() < 1e-9);
        assert!((v(&[0, 1, 2, 3]).abs() - 90.0).abs() < 1e-9);
        // Reversing the atoms keeps a dihedral's sign; mirroring flips it.
        assert!((v(&[3, 2, 1, 0]) - v(&[0, 1, 2, 3])).abs() < 1e-9);
        let mirrored = Molecule::new(
            m.atoms.iter().map(|a| Atom { position: a.position * DVec3::new(1.0, 1.0, -1.0), ..a.clone() }).collect(),
        );
        let d = Measurement::new(&[0, 1, 2, 3]).unwrap();
        assert!((d.value(&mirrored).unwrap() + d.value(&m).unwrap()).abs() < 1e-9);
        assert_eq!(Measurement::new(&[1, 2]).unwrap().label(&m), "O2–O3 1.500 Å");
        assert!(Measurement::new(&[1]).is_none() && Measurement::new(&[1, 1]).is_none());
        assert!(Measurement::new(&[0, 9]).unwrap().value(&m).is_none());
    }
}
