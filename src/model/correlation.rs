//! A scan's correlation diagram: the orbitals HOMO−k … LUMO+k of the first frame, each
//! followed across the frames by its character — the orbital of the next frame that overlaps
//! it most (analytic overlaps between the two frames' basis sets), each orbital taken by one
//! line only — with its energy at every frame. Where a line's orbital changes its place in the
//! energy order, two orbitals crossed: what a Walsh diagram shows, and what following orbitals
//! by name gets wrong.

use super::PreparedBasis;
use super::orbitals::{Spin, Wavefunction};
use super::overlap::cross_overlap;
use super::scan::Scan;

/// One orbital followed across the scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Its name in the first frame: "HOMO−1", "LUMO"; " β" after a beta orbital.
    pub label: String,
    pub spin: Spin,
    /// Occupied in the first frame.
    pub occupied: bool,
    /// (the coordinate's value, energy in Eh, the orbital's index in that frame's file) per frame.
    pub points: Vec<(f64, f64, usize)>,
    /// Frames at which the orbital followed crossed another line of the diagram: their order
    /// in energy differs from the frame before (a crossing with an orbital the diagram does
    /// not draw is not marked: it would have no partner to see).
    pub crossings: Vec<usize>,
}

/// Every line of a scan's diagram.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Diagram {
    pub lines: Vec<Line>,
}

/// The diagram of HOMO−`below` … LUMO+`above` for each spin the files have (α and β of an
/// unrestricted wavefunction), from the first view's wavefunctions; None for cube series or
/// files without orbital energies.
pub fn correlation(scan: &Scan, below: usize, above: usize) -> Option<Diagram> {
    let first = scan.frames.first()?.wavefunction(0)?;
    let spins: &[Spin] = if first.restricted { &[Spin::Alpha] } else { &[Spin::Alpha, Spin::Beta] };
    let waves: Vec<&Wavefunction> = scan.frames.iter().map(|f| f.wavefunction(0)).collect::<Option<_>>()?;
    let bases: Vec<PreparedBasis> = waves.iter().map(|w| PreparedBasis::with_threshold(&w.basis, 0.0)).collect();
    let overlaps: Vec<Vec<f64>> = bases.windows(2).map(|b| cross_overlap(&b[0], &b[1])).collect();
    let mut diagram = Diagram::default();
    for &spin in spins {
        let start: Vec<usize> = {
            let order = first.by_energy(spin);
            let homo = order.iter().position(|&i| Some(i) == first.homo(spin))?;
            let hi = (homo + 1 + above).min(order.len().saturating_sub(1));
            order[homo.saturating_sub(below)..=hi].to_vec()
        };
        let mut current: Vec<usize> = start.clone();
        let mut lines: Vec<Line> = start
            .iter()
            .map(|&i| {
                let name = first.frontier_label(i, below.max(above) + 1).unwrap_or_else(|| format!("MO {}", i + 1));
                let label = match (first.restricted, spin) {
                    (false, Spin::Beta) => format!("{name} β"),
                    (false, Spin::Alpha) => format!("{name} α"),
                    _ => name,
                };
                let o = &first.orbitals[i];
                Line {
                    label: label.replace('-', "−"),
                    spin,
                    occupied: o.occupation > 0.5,
                    points: vec![(scan.frames[0].at, o.energy, i)],
                    crossings: Vec::new(),
                }
            })
            .collect();
        for f in 1..scan.frames.len() {
            let (prev, next) = (waves[f - 1], waves[f]);
            let s = &overlaps[f - 1];
            let nb = next.basis.n_functions();
            // ⟨line's orbital in f−1| as a row over the next frame's basis functions (Sᵀc), so
            // every orbital of the spin can be a candidate at the cost of one dot product each:
            // a character may climb past many orbitals between two frames.
            let rows: Vec<Vec<f64>> = current
                .iter()
                .map(|&i| {
                    let c = &prev.orbitals[i].coefficients;
                    (0..nb).map(|v| c.iter().enumerate().map(|(u, &x)| x * s[u * nb + v]).sum()).collect()
                })
                .collect();
            let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
            for (l, row) in rows.iter().enumerate() {
                for (j, o) in next.of_spin(spin) {
                    let overlap: f64 = row.iter().zip(&o.coefficients).map(|(a, b)| a * b).sum();
                    pairs.push((overlap.abs(), l, j));
                }
            }
            pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut taken_line = vec![false; current.len()];
            let mut taken: Vec<usize> = Vec::new();
            let mut next_current = current.clone();
            for (_, l, j) in pairs {
                if taken_line[l] || taken.contains(&j) {
                    continue;
                }
                taken_line[l] = true;
                taken.push(j);
                next_current[l] = j;
            }
            for (l, line) in lines.iter_mut().enumerate() {
                let j = next_current[l];
                line.points.push((scan.frames[f].at, next.orbitals[j].energy, j));
            }
            current = next_current;
        }
        mark_crossings(&mut lines);
        diagram.lines.extend(lines);
    }
    Some(diagram)
}

/// Marks, on each line, the frames where it crossed another of `lines`: the sign of their
/// energy difference changed from the frame before.
fn mark_crossings(lines: &mut [Line]) {
    let frames = lines.iter().map(|l| l.points.len()).min().unwrap_or(0);
    let energy = |lines: &[Line], l: usize, f: usize| lines[l].points[f].1;
    for l in 0..lines.len() {
        let crossed: Vec<usize> = (1..frames)
            .filter(|&f| {
                (0..lines.len()).filter(|&m| m != l).any(|m| {
                    let before = energy(lines, l, f - 1) - energy(lines, m, f - 1);
                    let after = energy(lines, l, f) - energy(lines, m, f);
                    before * after < 0.0
                })
            })
            .collect();
        lines[l].crossings = crossed;
    }
}

impl Diagram {
    /// The diagram as CSV: the coordinate's value, then each line's energy (Eh) and the
    /// orbital it is at that frame (1-based, as the file numbers them).
    pub fn csv(&self, coordinate: &str) -> String {
        let mut out = coordinate.to_string();
        for l in &self.lines {
            out.push_str(&format!(",E({0}) / Eh,{0} orbital", l.label));
        }
        out.push('\n');
        let frames = self.lines.first().map_or(0, |l| l.points.len());
        for f in 0..frames {
            out.push_str(&format!("{}", self.lines[0].points[f].0));
            for l in &self.lines {
                let (_, e, i) = l.points[f];
                out.push_str(&format!(",{e:.8},{}", i + 1));
            }
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod crossing_tests {
    use super::*;

    fn line(label: &str, energies: &[f64]) -> Line {
        Line {
            label: label.into(),
            spin: Spin::Alpha,
            occupied: true,
            points: energies.iter().enumerate().map(|(f, &e)| (f as f64, e, 0)).collect(),
            crossings: Vec::new(),
        }
    }

    #[test]
    fn only_crossings_between_drawn_lines_are_marked_on_both() {
        // a and b cross between frames 1 and 2; c stays above both (it may cross orbitals the
        // diagram does not draw, which leaves no mark).
        let mut lines = [line("a", &[-0.5, -0.4, -0.2]), line("b", &[-0.3, -0.35, -0.45]), line("c", &[0.1, 0.2, 0.3])];
        mark_crossings(&mut lines);
        assert_eq!(lines[0].crossings, [2]);
        assert_eq!(lines[1].crossings, [2], "the partner carries the mark too");
        assert!(lines[2].crossings.is_empty());
    }
}
