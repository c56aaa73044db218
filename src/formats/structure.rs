//! What the structure readers (PDB, mmCIF, XYZ) share: element symbols, and the document a
//! structure becomes.

use crate::model::elements::atomic_number;
use crate::model::{Document, Structure, StructureView};

/// Atomic number of an element symbol as structure files write it ("C", "FE", "Fe2+", "O1-").
pub(crate) fn element_of(symbol: &str) -> Option<u8> {
    // The elements of biomolecules first: a million atoms would otherwise each scan the table.
    let symbol = symbol.trim();
    match symbol.as_bytes() {
        [b'C' | b'c'] => return Some(6),
        [b'N' | b'n'] => return Some(7),
        [b'O' | b'o'] => return Some(8),
        [b'H' | b'h'] => return Some(1),
        [b'S' | b's'] => return Some(16),
        [b'P' | b'p'] => return Some(15),
        _ => {}
    }
    let s = symbol.trim_end_matches(['+', '-']).trim_end_matches(|c: char| c.is_ascii_digit());
    if s.eq_ignore_ascii_case("D") || s.eq_ignore_ascii_case("T") {
        return Some(1); // deuterium, tritium
    }
    atomic_number(s).map(|z| z as u8)
}

/// The document of a structure: its first model shown.
pub(crate) fn document(source: &str, title: &str, structure: Structure) -> Document {
    let (view, molecule) = StructureView::new(structure);
    Document {
        source: source.to_string(),
        title: if title.trim().is_empty() { source.to_string() } else { title.trim().to_string() },
        molecule,
        structure: Some(view),
        ..Document::default()
    }
}

/// An atom with an element and a position only (bohr), as XYZ and trajectory frames give them.
pub(crate) fn bare_atom(symbol: &str, z: u8, position: glam::DVec3) -> crate::model::structure::AtomRecord {
    use crate::model::structure::{AtomName, AtomRecord};
    AtomRecord {
        chain: Default::default(),
        residue: Default::default(),
        number: 0,
        insertion: 0,
        hetero: false,
        name: AtomName::new(symbol).unwrap_or_default(),
        altloc: 0,
        z,
        position,
        occupancy: 1.0,
        b_factor: 0.0,
        serial: -1,
    }
}

/// The document of a trajectory: atoms of atomic numbers `z` at each frame's positions (bohr),
/// each frame a model titled as given; the first shown.
pub(crate) fn trajectory(source: &str, title: &str, z: &[u8], frames: &[(String, Vec<glam::DVec3>)]) -> Document {
    let mut s = Structure::default();
    for (k, (name, positions)) in frames.iter().enumerate() {
        s.begin_model(k as i32 + 1, name.clone());
        for (&z, &position) in z.iter().zip(positions) {
            let symbol = crate::model::elements::element(z as u32).symbol;
            s.push(&bare_atom(symbol, z, position));
        }
    }
    document(source, title, s)
}
