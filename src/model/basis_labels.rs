//! Names of single basis functions, as chemists write atomic orbitals: "C3 2pz", "O1 3dz²",
//! "Fe1 4dxy", "N2 3dxx" (a cartesian component), "O1 4fxyz".
//!
//! The number before the letter counts the shells of that l on the atom from l + 1 (1s, 2s, 3s,
//! 2p, 3p, 3d, …), as PySCF's `ao_labels` do; split-valence and polarisation shells get the
//! next numbers. Components follow the model's order ([`super::basis`]), into which every
//! reader converts: cartesian ones alphabetical (xx, xy, xz, yy, yz, zz), pure ones
//! m = 0, +1, −1, +2, −2, … (d: z², xz, yz, x²−y², xy), p always x, y, z.

use super::basis::{Basis, ShellKind, cartesian_powers};
use super::molecule::Molecule;

const LETTERS: [&str; 6] = ["s", "p", "d", "f", "g", "h"];

/// One basis function's place: its atom, its shell and its component's name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FunctionLabel {
    /// Index of the atom (0-based).
    pub atom: usize,
    /// Index of the shell in the basis.
    pub shell: usize,
    /// The shell's name on its atom: "1s", "2p", "3d".
    pub shell_name: String,
    /// The component: "" for s, "x", "z²", "xy", "xxy", "+1".
    pub component: String,
}

impl FunctionLabel {
    /// "2pz", "3dx²−y²", "1s".
    pub fn orbital(&self) -> String {
        format!("{}{}", self.shell_name, self.component)
    }
}

/// The component names of a shell of angular momentum `l`, in the model's order.
pub fn component_names(l: u32, kind: ShellKind) -> Vec<String> {
    let pure = kind == ShellKind::Pure && l >= 2;
    match (l, pure) {
        (0, _) => vec![String::new()],
        (2, true) => ["z²", "xz", "yz", "x²−y²", "xy"].map(String::from).to_vec(),
        (3, true) => ["z³", "xz²", "yz²", "z(x²−y²)", "xyz", "x(x²−3y²)", "y(3x²−y²)"].map(String::from).to_vec(),
        (_, true) => (0..2 * l as usize + 1).map(|k| signed_m(super::solid_harmonics::pure_m(k))).collect(),
        (_, false) => cartesian_powers(l)
            .iter()
            .map(|p| "x".repeat(p[0] as usize) + &"y".repeat(p[1] as usize) + &"z".repeat(p[2] as usize))
            .collect(),
    }
}

fn signed_m(m: i32) -> String {
    match m {
        0 => "0".into(),
        m if m > 0 => format!("+{m}"),
        m => format!("−{}", -m),
    }
}

/// Every basis function's label, in the model's function order.
pub fn function_labels(basis: &Basis) -> Vec<FunctionLabel> {
    let mut seen: Vec<(usize, u32, u32)> = Vec::new(); // (atom, l, shells so far)
    let mut out = Vec::with_capacity(basis.n_functions());
    for (k, shell) in basis.shells.iter().enumerate() {
        let count = match seen.iter_mut().find(|(a, l, _)| *a == shell.atom && *l == shell.l) {
            Some(entry) => {
                entry.2 += 1;
                entry.2
            }
            None => {
                seen.push((shell.atom, shell.l, 0));
                0
            }
        };
        let letter = LETTERS.get(shell.l as usize).copied().unwrap_or("?");
        let shell_name = format!("{}{letter}", shell.l + 1 + count);
        for component in component_names(shell.l, shell.kind) {
            out.push(FunctionLabel { atom: shell.atom, shell: k, shell_name: shell_name.clone(), component });
        }
    }
    out
}

/// The atom's name: element symbol and 1-based number, "C3".
pub fn atom_name(molecule: &Molecule, atom: usize) -> String {
    let symbol = molecule.atoms.get(atom).map_or("X", |a| a.element().symbol);
    format!("{symbol}{}", atom + 1)
}

/// Basis function `k`'s full name, "C3 2pz"; `None` past the last function.
pub fn function_name(molecule: &Molecule, basis: &Basis, k: usize) -> Option<String> {
    let label = function_labels(basis).into_iter().nth(k)?;
    Some(format!("{} {}", atom_name(molecule, label.atom), label.orbital()))
}

/// The basis function a name means ("C3 2pz", "o1 3dz2", "O1 3dx2-y2"): case, spaces,
/// superscripts and the minus sign's form do not matter.
pub fn find_function(molecule: &Molecule, basis: &Basis, name: &str) -> Option<usize> {
    let key = |s: &str| -> String {
        s.chars()
            .filter(|c| !c.is_whitespace() && *c != '^')
            .map(|c| match c {
                '²' => '2',
                '³' => '3',
                '−' => '-',
                c => c.to_ascii_lowercase(),
            })
            .collect()
    };
    let wanted = key(name);
    function_labels(basis)
        .iter()
        .position(|l| key(&format!("{}{}", atom_name(molecule, l.atom), l.orbital())) == wanted)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::model::basis::Shell;
    use crate::model::molecule::Atom;

    fn shell(atom: usize, l: u32, kind: ShellKind) -> Shell {
        Shell { atom, center: DVec3::ZERO, l, kind, exponents: vec![1.0], coefficients: vec![1.0] }
    }

    #[test]
    fn shells_are_numbered_per_atom_and_components_follow_the_model_order() {
        use ShellKind::{Cartesian, Pure};
        let basis = Basis {
            shells: vec![
                shell(0, 0, Pure),
                shell(0, 0, Pure),
                shell(0, 1, Pure),
                shell(0, 0, Pure),
                shell(0, 1, Pure),
                shell(0, 2, Pure),
                shell(0, 3, Pure),
                shell(0, 4, Pure),
                shell(1, 0, Cartesian),
                shell(1, 2, Cartesian),
            ],
        };
        let atom = |z| Atom { z, charge: z as f64, position: DVec3::ZERO, ghost: false };
        let molecule = Molecule::new(vec![atom(6), atom(1)]);
        let names: Vec<String> =
            (0..basis.n_functions()).map(|k| function_name(&molecule, &basis, k).unwrap()).collect();
        assert_eq!(names[..8], ["C1 1s", "C1 2s", "C1 2px", "C1 2py", "C1 2pz", "C1 3s", "C1 3px", "C1 3py"]);
        assert_eq!(names[9..14], ["C1 3dz²", "C1 3dxz", "C1 3dyz", "C1 3dx²−y²", "C1 3dxy"]);
        assert_eq!(names[14], "C1 4fz³");
        assert_eq!(names[18], "C1 4fxyz");
        assert_eq!(names[21..24], ["C1 5g0", "C1 5g+1", "C1 5g−1"]);
        assert_eq!(names[30..], ["H2 1s", "H2 3dxx", "H2 3dxy", "H2 3dxz", "H2 3dyy", "H2 3dyz", "H2 3dzz"]);
        assert_eq!(function_name(&molecule, &basis, names.len()), None);
        for (k, name) in names.iter().enumerate() {
            assert_eq!(find_function(&molecule, &basis, name), Some(k), "{name}");
        }
        assert_eq!(find_function(&molecule, &basis, "c1 3dx2-y2"), Some(12));
        assert_eq!(find_function(&molecule, &basis, "C1 3d z^2"), Some(9));
        assert_eq!(find_function(&molecule, &basis, "C1 9s"), None);
    }
}
