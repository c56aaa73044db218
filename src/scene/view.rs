//! Which way to look at a molecule: the first view of a new file (its principal axes, tilted so
//! that no bond points at the viewer and a planar π system shows its lobes above and below the
//! ring), and the presets a chemist asks for (along x, y or z, down a bond, perpendicular to the
//! plane of three atoms). Plain math on positions; the camera turns to it with
//! [`super::Camera::look_along`].

use glam::{DVec3, Vec3};

use crate::model::Molecule;

/// A direction to look along (from the eye towards the molecule) and the screen's up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewDirection {
    pub direction: Vec3,
    pub up: Vec3,
}

impl ViewDirection {
    pub const ALONG_Z: Self = Self { direction: Vec3::NEG_Z, up: Vec3::Y };
}

/// How a view is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewPreset {
    /// The principal axes, tilted ([`first_view`]).
    Auto,
    /// Looking along the positive x, y or z axis of the file's coordinates.
    AlongX,
    AlongY,
    AlongZ,
    /// Looking from atom a down the a→b bond (0-based indices).
    Bond(usize, usize),
    /// Looking perpendicular to the plane of three atoms.
    Plane(usize, usize, usize),
}

impl ViewPreset {
    /// `auto`, `x`, `y`, `z`, `bond:I,J` or `plane:I,J,K` (atom numbers from 1, as chemists
    /// count them).
    pub fn parse(s: &str) -> Result<Self, String> {
        let atoms = |list: &str, n: usize| -> Result<Vec<usize>, String> {
            let v: Vec<usize> = list
                .split(',')
                .map(|t| t.trim().parse::<usize>().ok().filter(|&i| i >= 1).map(|i| i - 1))
                .collect::<Option<_>>()
                .ok_or_else(|| format!("`{s}`: atom numbers count from 1, separated by commas"))?;
            if v.len() != n {
                return Err(format!("`{s}`: {n} atom numbers expected, {} given", v.len()));
            }
            Ok(v)
        };
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "x" => Ok(Self::AlongX),
            "y" => Ok(Self::AlongY),
            "z" => Ok(Self::AlongZ),
            other => match other.split_once(':') {
                Some(("bond", list)) => atoms(list, 2).map(|v| Self::Bond(v[0], v[1])),
                Some(("plane", list)) => atoms(list, 3).map(|v| Self::Plane(v[0], v[1], v[2])),
                _ => Err(format!("`{s}`: expected auto, x, y, z, bond:I,J or plane:I,J,K")),
            },
        }
    }

    /// The direction this preset looks along for `molecule` (its own frame); an error names an
    /// atom that is not there or atoms that do not define the direction.
    pub fn direction(self, molecule: &Molecule) -> Result<ViewDirection, String> {
        let at = |i: usize| {
            molecule
                .atoms
                .get(i)
                .map(|a| a.position)
                .ok_or_else(|| format!("atom {} is not in the molecule ({} atoms)", i + 1, molecule.atoms.len()))
        };
        let first = first_view(molecule);
        match self {
            Self::Auto => Ok(first),
            Self::AlongX => Ok(ViewDirection { direction: Vec3::X, up: Vec3::Z }),
            Self::AlongY => Ok(ViewDirection { direction: Vec3::Y, up: Vec3::Z }),
            Self::AlongZ => Ok(ViewDirection { direction: Vec3::Z, up: Vec3::Y }),
            Self::Bond(a, b) => {
                let d = at(b)? - at(a)?;
                if d.length() < 1e-6 {
                    return Err(format!("atoms {} and {} are at the same place", a + 1, b + 1));
                }
                // Keep the screen's up from the first view where it is not along the bond.
                let up =
                    if first.up.as_dvec3().cross(d).length() > 1e-3 * d.length() { first.up } else { first.direction };
                Ok(ViewDirection { direction: d.normalize().as_vec3(), up })
            }
            Self::Plane(a, b, c) => {
                let (pa, pb, pc) = (at(a)?, at(b)?, at(c)?);
                let n = (pb - pa).cross(pc - pa);
                if n.length() < 1e-6 {
                    return Err(format!("atoms {}, {} and {} lie on a line", a + 1, b + 1, c + 1));
                }
                Ok(ViewDirection { direction: -n.normalize().as_vec3(), up: (pb - pa).normalize().as_vec3() })
            }
        }
    }
}

/// Smallest angle (degrees, 0..=90) the first view keeps between any bond and the line of sight.
pub const MIN_BOND_ANGLE: f64 = 25.0;
/// How far the first view tilts from the axis of least extent (degrees): planar molecules show
/// their face and, above and below it, their π lobes.
const TILT: f64 = 60.0;

/// The first view of a molecule: from its principal axes (e1 longest … e3 shortest, the normal of
/// a planar molecule), tilted [`TILT`] from e3 towards e2, e3 up on screen; of the directions
/// near that one, the first with no bond within [`MIN_BOND_ANGLE`] of the line of sight.
pub fn first_view(molecule: &Molecule) -> ViewDirection {
    let points: Vec<DVec3> = molecule.atoms.iter().filter(|a| !a.ghost).map(|a| a.position).collect();
    if points.len() < 2 {
        return ViewDirection::ALONG_Z;
    }
    let [e1, e2, e3] = principal_axes(&points);
    let bonds: Vec<DVec3> = molecule
        .bonds
        .iter()
        .map(|b| molecule.atoms[b.b as usize].position - molecule.atoms[b.a as usize].position)
        .filter(|d| d.length() > 1e-9)
        .map(|d| d.normalize())
        .collect();
    let clearance = |d: DVec3| bonds.iter().map(|b| b.dot(d).abs().min(1.0).acos().to_degrees()).fold(90.0, f64::min);
    let mut best = (f64::NEG_INFINITY, e3, e3);
    for tilt in [TILT, 45.0, 75.0, 30.0, 85.0] {
        for step in 0..24 {
            // 0, +15°, −15°, +30°, …: azimuths nearest the e2 side first.
            let az = (((step + 1) / 2) as f64 * 15.0 * if step % 2 == 1 { 1.0 } else { -1.0 }).to_radians();
            let (t, (sa, ca)) = (tilt.to_radians(), az.sin_cos());
            let d = e3 * t.cos() + (e2 * ca + e1 * sa) * t.sin();
            let up = e3 - e3.dot(d) * d;
            let score = clearance(d);
            if score >= MIN_BOND_ANGLE {
                return ViewDirection { direction: (-d).as_vec3(), up: up.normalize().as_vec3() };
            }
            if score > best.0 {
                best = (score, d, up);
            }
        }
    }
    ViewDirection { direction: (-best.1).as_vec3(), up: best.2.normalize_or(DVec3::Y).as_vec3() }
}

/// Unit principal axes of a point cloud, longest extent first (eigenvectors of the covariance,
/// by Jacobi rotations); for degenerate clouds any orthonormal completion.
pub fn principal_axes(points: &[DVec3]) -> [DVec3; 3] {
    let n = points.len().max(1) as f64;
    let centre = points.iter().copied().sum::<DVec3>() / n;
    let mut a = [[0.0f64; 3]; 3];
    for p in points {
        let d = (*p - centre).to_array();
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += d[i] * d[j] / n;
            }
        }
    }
    let (values, v) = crate::model::eigen::symmetric_eigen(a, 50);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| values[j].total_cmp(&values[i]));
    let axis = |k: usize| DVec3::new(v[0][k], v[1][k], v[2][k]).normalize_or(DVec3::X);
    let e1 = axis(order[0]);
    let e2 = (axis(order[1]) - e1.dot(axis(order[1])) * e1).normalize_or(e1.any_orthonormal_vector());
    [e1, e2, e1.cross(e2)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;

    fn molecule(atoms: &[(u32, [f64; 3])]) -> Molecule {
        Molecule::new(
            atoms.iter().map(|&(z, p)| Atom { z, charge: z as f64, position: DVec3::from(p), ghost: false }).collect(),
        )
    }

    fn bond_clearance(m: &Molecule, d: Vec3) -> f64 {
        m.bonds
            .iter()
            .map(|b| {
                let v = (m.atoms[b.b as usize].position - m.atoms[b.a as usize].position).normalize();
                v.dot(d.as_dvec3()).abs().acos().to_degrees()
            })
            .fold(90.0, f64::min)
    }

    #[test]
    fn principal_axes_of_a_flat_box() {
        let pts: Vec<DVec3> = [[-3.0, -1.0, 0.2], [3.0, 1.0, -0.2], [3.0, -1.0, 0.0], [-3.0, 1.0, 0.0]]
            .iter()
            .map(|&p| DVec3::from(p))
            .collect();
        let [e1, e2, e3] = principal_axes(&pts);
        assert!(e1.x.abs() > 0.99 && e2.y.abs() > 0.99 && e3.z.abs() > 0.97, "{e1} {e2} {e3}");
        assert!((e1.cross(e2) - e3).length() < 1e-9, "right-handed");
    }

    #[test]
    fn o2_is_seen_from_the_side_and_benzene_at_a_tilt() {
        // O₂ along z: the file's own z view looks straight down the bond.
        let o2 = molecule(&[(8, [0.0, 0.0, -1.14]), (8, [0.0, 0.0, 1.14])]);
        let v = first_view(&o2);
        assert!(bond_clearance(&o2, v.direction) > 80.0, "{v:?}");
        // Benzene in the xy plane: neither face-on nor edge-on, the normal up on screen.
        let ring: Vec<(u32, [f64; 3])> = (0..6)
            .flat_map(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_3;
                [(6, [2.64 * a.cos(), 2.64 * a.sin(), 0.0]), (1, [4.69 * a.cos(), 4.69 * a.sin(), 0.0])]
            })
            .collect();
        let benzene = molecule(&ring);
        let v = first_view(&benzene);
        let from_normal = v.direction.dot(Vec3::Z).abs().acos().to_degrees();
        assert!((from_normal - TILT as f32).abs() < 20.0, "{from_normal}° from the normal");
        assert!(v.up.dot(Vec3::Z).abs() > 0.4, "the normal points up on screen: {v:?}");
        assert!(bond_clearance(&benzene, v.direction) >= MIN_BOND_ANGLE);
    }

    #[test]
    fn presets_parse_and_point_where_asked() {
        let m = molecule(&[(6, [0.0, 0.0, 0.0]), (8, [2.3, 0.0, 0.0]), (1, [-1.0, 1.8, 0.0])]);
        assert_eq!(ViewPreset::parse("bond:1,2"), Ok(ViewPreset::Bond(0, 1)));
        assert_eq!(ViewPreset::parse("Plane:1,2,3"), Ok(ViewPreset::Plane(0, 1, 2)));
        assert!(ViewPreset::parse("bond:0,2").unwrap_err().contains("from 1"));
        assert!(ViewPreset::parse("plane:1,2").unwrap_err().contains("3 atom numbers"));
        assert!(ViewPreset::parse("diagonal").is_err());
        let bond = ViewPreset::Bond(0, 1).direction(&m).unwrap();
        assert!((bond.direction - Vec3::X).length() < 1e-6);
        let plane = ViewPreset::Plane(0, 1, 2).direction(&m).unwrap();
        assert!(plane.direction.z.abs() > 0.999);
        assert!(ViewPreset::Bond(0, 7).direction(&m).unwrap_err().contains("atom 8"));
        assert_eq!(ViewPreset::AlongZ.direction(&m).unwrap().direction, Vec3::Z);
    }
}
