//! Contour lines by marching squares: each cell's crossings joined into polylines, a saddle
//! cell (opposite corners on the same side) resolved by the value at its centre.

use std::collections::HashMap;

/// A contour line in grid coordinates (x along the fastest index); `closed` when it returns to
/// its start (a loop inside the map) rather than ending at the map's border or a missing value.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    pub points: Vec<[f64; 2]>,
    pub closed: bool,
}

/// A cell's edges, counter-clockwise from the bottom: bottom (i,j)–(i+1,j), right
/// (i+1,j)–(i+1,j+1), top (i,j+1)–(i+1,j+1), left (i,j)–(i,j+1).
const BOTTOM: u8 = 0;
const RIGHT: u8 = 1;
const TOP: u8 = 2;
const LEFT: u8 = 3;

/// The segments of a cell whose corners above the level are `case` (bit 0 bottom-left, 1
/// bottom-right, 2 top-right, 3 top-left); `centre_above` decides the two saddles.
fn segments(case: u8, centre_above: bool) -> &'static [(u8, u8)] {
    match case {
        1 | 14 => &[(LEFT, BOTTOM)],
        2 | 13 => &[(BOTTOM, RIGHT)],
        3 | 12 => &[(LEFT, RIGHT)],
        4 | 11 => &[(RIGHT, TOP)],
        6 | 9 => &[(BOTTOM, TOP)],
        7 | 8 => &[(TOP, LEFT)],
        // Bottom-left and top-right above: joined through a centre above the level, so the
        // other two corners are cut off; apart otherwise, each cut off itself.
        5 if centre_above => &[(BOTTOM, RIGHT), (TOP, LEFT)],
        5 => &[(LEFT, BOTTOM), (RIGHT, TOP)],
        10 if centre_above => &[(LEFT, BOTTOM), (RIGHT, TOP)],
        10 => &[(BOTTOM, RIGHT), (TOP, LEFT)],
        _ => &[],
    }
}

/// The contour lines of `values` (`nx` × `ny`, x fastest) at `level`. A corner counts as above
/// when its value exceeds the level; cells with a missing (NaN) corner, or whose corners all
/// have magnitudes below `floor`, have no lines.
pub fn contour(values: &[f64], nx: usize, ny: usize, level: f64, floor: f64) -> Vec<Polyline> {
    assert_eq!(values.len(), nx * ny, "a grid of nx × ny values");
    let at = |i: usize, j: usize| values[j * nx + i];
    // Each crossing is named by its grid edge: 2·(j·nx + i) for the edge from (i,j) along x,
    // one more for the edge along y; a crossing is shared by the two cells beside its edge.
    let mut position: HashMap<usize, [f64; 2]> = HashMap::new();
    let mut pieces: Vec<[usize; 2]> = Vec::new();
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx.saturating_sub(1) {
            let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            if corners.iter().any(|v| v.is_nan()) || corners.iter().all(|v| v.abs() < floor) {
                continue;
            }
            let case = corners.iter().enumerate().fold(0u8, |c, (k, &v)| c | (u8::from(v > level) << k));
            let centre_above = corners.iter().sum::<f64>() * 0.25 > level;
            for &(a, b) in segments(case, centre_above) {
                let ends = [a, b].map(|edge| {
                    let (id, p) = crossing(edge, i, j, nx, &corners, level);
                    position.insert(id, p);
                    id
                });
                pieces.push(ends);
            }
        }
    }
    join(&pieces, &position)
}

/// Where the level crosses `edge` of cell (i, j): the edge's name and the point, linear
/// between the edge's two corners.
fn crossing(edge: u8, i: usize, j: usize, nx: usize, c: &[f64; 4], level: f64) -> (usize, [f64; 2]) {
    let t = |a: f64, b: f64| ((level - a) / (b - a)).clamp(0.0, 1.0);
    let (x, y) = (i as f64, j as f64);
    let id = |i: usize, j: usize, along_y: bool| 2 * (j * nx + i) + usize::from(along_y);
    match edge {
        BOTTOM => (id(i, j, false), [x + t(c[0], c[1]), y]),
        RIGHT => (id(i + 1, j, true), [x + 1.0, y + t(c[1], c[2])]),
        TOP => (id(i, j + 1, false), [x + t(c[3], c[2]), y + 1.0]),
        _ => (id(i, j, true), [x, y + t(c[0], c[3])]),
    }
}

/// Segments that share a crossing joined end to end into polylines.
fn join(pieces: &[[usize; 2]], position: &HashMap<usize, [f64; 2]>) -> Vec<Polyline> {
    let mut at: HashMap<usize, Vec<usize>> = HashMap::new();
    for (n, p) in pieces.iter().enumerate() {
        for &e in p {
            at.entry(e).or_default().push(n);
        }
    }
    let mut used = vec![false; pieces.len()];
    // From `edge`, the unused piece there and the crossing at its other end.
    let step = |edge: usize, used: &mut Vec<bool>| -> Option<usize> {
        let &n = at.get(&edge)?.iter().find(|&&n| !used[n])?;
        used[n] = true;
        Some(if pieces[n][0] == edge { pieces[n][1] } else { pieces[n][0] })
    };
    let mut lines = Vec::new();
    // Open lines first, from the crossings that end them, so each is walked from one end.
    let mut starts: Vec<usize> = at.iter().filter(|(_, v)| v.len() == 1).map(|(&e, _)| e).collect();
    starts.sort_unstable();
    let loops: Vec<usize> = (0..pieces.len()).map(|n| pieces[n][0]).collect();
    for start in starts.into_iter().chain(loops) {
        let mut chain = vec![start];
        let mut edge = start;
        while let Some(next) = step(edge, &mut used) {
            chain.push(next);
            edge = next;
            if next == start {
                break;
            }
        }
        if chain.len() < 2 {
            continue;
        }
        let closed = chain.len() > 2 && chain.first() == chain.last();
        lines.push(Polyline { points: chain.iter().map(|e| position[e]).collect(), closed });
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circle_is_one_closed_line_at_its_radius() {
        let (n, h, r) = (61, 0.1, 2.2);
        let coord = |k: usize| k as f64 * h - 3.0;
        let values: Vec<f64> = (0..n).flat_map(|j| (0..n).map(move |i| coord(i).powi(2) + coord(j).powi(2))).collect();
        let lines = contour(&values, n, n, r * r, 0.0);
        assert_eq!(lines.len(), 1, "one line");
        let line = &lines[0];
        assert!(line.closed);
        assert!(line.points.len() > 100, "{} points", line.points.len());
        // Linear interpolation of r² along an edge errs by at most h²/4 in r², so h²/(8r) in r.
        let bound = h * h / (8.0 * r) * 1.05;
        for p in &line.points {
            let radius = coord_at(p[0], h).hypot(coord_at(p[1], h));
            assert!((radius - r).abs() <= bound, "radius {radius}");
        }
        // The loop goes round once: its length is the circumference, within the chords' error.
        let length: f64 =
            line.points.windows(2).map(|w| ((w[1][0] - w[0][0]) * h).hypot((w[1][1] - w[0][1]) * h)).sum();
        assert!((length - std::f64::consts::TAU * r).abs() < 0.01, "length {length}");
    }

    fn coord_at(g: f64, h: f64) -> f64 {
        g * h - 3.0
    }

    #[test]
    fn a_saddle_is_joined_through_the_side_its_centre_is_on() {
        // Corners bottom-left, bottom-right, top-right, top-left; the diagonal 1 … 2 is above 0.
        let grid = |bl: f64, br: f64, tr: f64, tl: f64| vec![bl, br, tl, tr];
        // Centre (1 − 1 + 2 − 1)/4 > 0: the high corners join; the low corners are cut off,
        // each by a line between its two edges.
        let lines = contour(&grid(1.0, -1.0, 2.0, -1.0), 2, 2, 0.0, 0.0);
        assert_eq!(lines.len(), 2);
        // A line cuts a corner off when both its ends lie on the two edges that meet there.
        let cut_off = |line: &Polyline, corner: [f64; 2]| {
            line.points.len() == 2 && line.points.iter().all(|p| p[0] == corner[0] || p[1] == corner[1])
        };
        assert!(lines.iter().any(|l| cut_off(l, [1.0, 0.0])) && lines.iter().any(|l| cut_off(l, [0.0, 1.0])));
        // Centre (1 − 1.5 + 0.5 − 1)/4 < 0: the high corners are apart, each cut off.
        let lines = contour(&grid(1.0, -1.5, 0.5, -1.0), 2, 2, 0.0, 0.0);
        assert_eq!(lines.len(), 2);
        assert!(lines.iter().any(|l| cut_off(l, [0.0, 0.0])) && lines.iter().any(|l| cut_off(l, [1.0, 1.0])));
        // The crossings are where the edges' values pass 0: bottom edge at 1/(1 + 1.5).
        let bottom = lines.iter().flat_map(|l| &l.points).find(|p| p[1] == 0.0).unwrap();
        assert!((bottom[0] - 0.4).abs() < 1e-12);
    }

    #[test]
    fn lines_stop_at_the_border_and_at_missing_values() {
        // A plane tilted along x: one straight open line across the map at x = 2.5.
        let (nx, ny) = (6, 6);
        let mut values: Vec<f64> = (0..ny).flat_map(|_| (0..nx).map(|i| i as f64)).collect();
        let lines = contour(&values, nx, ny, 2.5, 0.0);
        assert_eq!(lines.len(), 1);
        assert!(!lines[0].closed);
        assert_eq!(lines[0].points.len(), ny);
        assert!(lines[0].points.iter().all(|p| (p[0] - 2.5).abs() < 1e-12));
        // A missing value in the middle breaks it in two.
        values[2 * nx + 2] = f64::NAN;
        assert_eq!(contour(&values, nx, ny, 2.5, 0.0).len(), 2);
        // A level outside the values has no line.
        assert!(contour(&values, nx, ny, 10.0, 0.0).is_empty());
        // Cells whose values all lie below the floor have none either: the line's cells hold
        // 2 and 3, so a floor of 3.5 removes it and one of 2.5 keeps it.
        assert!(contour(&values, nx, ny, 2.5, 3.5).is_empty());
        assert_eq!(contour(&values, nx, ny, 2.5, 2.5).len(), 2);
    }
}
