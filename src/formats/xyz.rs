//! XYZ reader: an atom count, a comment line, then one line per atom (element symbol or
//! atomic number, x, y, z in ångström, further columns ignored). Several frames in one file
//! make a trajectory, one model per frame.

use glam::DVec3;

use super::ParseError;
use super::structure::{bare_atom, document, element_of};
use super::text::{Lines, excerpt};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, Structure};

pub fn parse(file: &str, text: &str) -> Result<Document, ParseError> {
    let mut lines = Lines::new(file, text);
    let mut s = Structure::default();
    let mut title = String::new();
    let mut frame = 0;
    loop {
        if lines.rest().trim().is_empty() {
            break;
        }
        let count_line = lines.next_line("an atom count")?;
        let count: usize = count_line
            .trim()
            .parse()
            .map_err(|_| lines.error("an atom count (a whole number)", &excerpt(count_line)))?;
        // An atom line takes at least 8 bytes ("H 0 0 0\n"): a count the rest of the file cannot
        // hold is refused here, at its line.
        let left = lines.rest().len();
        if count > left / 8 + 1 {
            return Err(
                lines.error("an atom count the rest of the file can hold", &format!("{count} atoms in {left} bytes"))
            );
        }
        let comment = lines.next_line("a comment line")?.trim().to_string();
        frame += 1;
        if frame == 1 {
            title = comment.clone();
        }
        s.begin_model(frame, comment);
        for _ in 0..count {
            let line = lines.next_line(&format!("{count} atom lines in frame {frame}"))?;
            let mut tokens = line.split_whitespace();
            let symbol = tokens.next().unwrap_or("");
            let z = match symbol.parse::<u8>() {
                Ok(z) if z as u32 <= super::MAX_Z => Some(z),
                Ok(_) => None,
                Err(_) => element_of(symbol.trim_end_matches(|c: char| c.is_ascii_digit() || c == '_')),
            }
            .ok_or_else(|| lines.error("an element symbol or atomic number", &excerpt(line)))?;
            let mut xyz = [0.0; 3];
            for v in &mut xyz {
                let t = tokens.next().unwrap_or("");
                *v = super::text::parse_real(t)
                    .ok_or_else(|| lines.error("x, y and z coordinates after the element", &excerpt(line)))?;
            }
            s.push(&bare_atom(symbol, z, DVec3::from_array(xyz) * BOHR_PER_ANGSTROM));
        }
    }
    if s.is_empty() {
        return Err(lines.error("an atom count followed by atoms", "no atoms"));
    }
    Ok(document(file, &title, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRAJ: &str = "3\nwater frame 1\nO 0.0 0.0 0.0\nH 0.757 0.586 0.0\nH -0.757 0.586 0.0\n\
3\nwater frame 2\n8 0.0 0.0 0.1\nH 0.757 0.586 0.1\nH -0.757 0.586 0.1\n";

    #[test]
    fn frames_are_models() {
        let d = parse("t.xyz", TRAJ).unwrap();
        let s = &d.structure.as_ref().unwrap().structure;
        assert_eq!(s.models.len(), 2);
        assert_eq!(s.models[1].title, "water frame 2");
        assert_eq!(d.molecule.atoms.len(), 3);
        assert_eq!(d.molecule.bonds.len(), 2);
        assert_eq!(d.title, "water frame 1");
    }

    #[test]
    fn short_frames_and_bad_counts_name_the_line() {
        let e = parse("t.xyz", "2\nc\nO 0 0 0\n").unwrap_err();
        assert_eq!(e.line, 3, "{e}");
        let e = parse("t.xyz", "99999999999999\nc\n").unwrap_err();
        assert_eq!(e.line, 1, "{e}");
        let e = parse("t.xyz", "1\nc\nQq 0 0 0\n").unwrap_err();
        assert!(e.expected.contains("element"), "{e}");
    }
}
