//! The periodic table as the viewer needs it: symbols, colours and radii.

pub use super::element_table::ELEMENTS;

/// Per-element data. Index 0 of [`ELEMENTS`] is the dummy/ghost element "X".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementData {
    pub symbol: &'static str,
    /// Covalent radius in ångström (Cordero et al. 2008).
    pub covalent_radius: f32,
    /// Van der Waals radius in ångström (Alvarez 2013, Bondi where missing).
    pub vdw_radius: f32,
    /// Jmol CPK colour, sRGB.
    pub color: [u8; 3],
}

/// Data for atomic number `z`; out-of-range numbers give the dummy element.
pub fn element(z: u32) -> &'static ElementData {
    ELEMENTS.get(z as usize).unwrap_or(&ELEMENTS[0])
}

/// Atomic number from a symbol, case-insensitive ("C", "cl", "HE").
pub fn atomic_number(symbol: &str) -> Option<u32> {
    let s = symbol.trim();
    ELEMENTS.iter().position(|e| e.symbol.eq_ignore_ascii_case(s)).filter(|&z| z > 0).map(|z| z as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_indexed_by_atomic_number() {
        assert_eq!(element(1).symbol, "H");
        assert_eq!(element(6).symbol, "C");
        assert_eq!(element(8).symbol, "O");
        assert_eq!(element(29).symbol, "Cu");
        assert_eq!(element(118).symbol, "Og");
        assert_eq!(element(500).symbol, element(0).symbol);
        assert_eq!(atomic_number("cl"), Some(17));
        assert_eq!(atomic_number("HE"), Some(2));
        assert_eq!(atomic_number("Qq"), None);
    }

    #[test]
    fn radii_are_physical() {
        for (z, e) in ELEMENTS.iter().enumerate().skip(1) {
            assert!(e.covalent_radius > 0.2 && e.covalent_radius < 2.6, "Z={z} {e:?}");
            assert!(e.vdw_radius >= e.covalent_radius, "Z={z} {e:?}");
        }
        // Carbon: 0.76 Å covalent (sp3), 1.70-1.77 Å vdW.
        assert!((element(6).covalent_radius - 0.76).abs() < 0.01);
    }
}
