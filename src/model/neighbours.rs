//! Pairs of points closer than a cell width, in O(n): points binned into cubic cells (a dense
//! grid when the points fill their box, sorted cell keys when they are sparse), each cell
//! compared with itself and its 13 forward neighbours.

use glam::DVec3;

/// A cell holding more points than this is a degenerate input (points piled on one spot);
/// its pairs are not searched, so that a hostile file cannot make the search quadratic.
pub const MAX_POINTS_PER_CELL: usize = 256;

type Key = [i64; 3];

/// The 13 neighbours after a cell in lexicographic order (with the cell itself, every pair of
/// neighbouring cells is visited once).
const FORWARD: [[i64; 3]; 13] = [
    [0, 0, 1],
    [0, 1, -1],
    [0, 1, 0],
    [0, 1, 1],
    [1, -1, -1],
    [1, -1, 0],
    [1, -1, 1],
    [1, 0, -1],
    [1, 0, 0],
    [1, 0, 1],
    [1, 1, -1],
    [1, 1, 0],
    [1, 1, 1],
];

/// Calls `visit(i, j)` with `i < j` for every pair of included points in the same or
/// neighbouring cells of width `cell`: a superset of the pairs closer than `cell`, which the
/// caller filters by distance. Points with non-finite coordinates are left out.
pub fn for_each_near_pair(
    points: &[DVec3],
    include: impl Fn(usize) -> bool,
    cell: f64,
    mut visit: impl FnMut(usize, usize),
) {
    let cell = cell.max(1e-6);
    let key = |p: DVec3| {
        let c = (p / cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    };
    let mut binned: Vec<(Key, u32)> = (0..points.len())
        .filter(|&i| include(i) && points[i].is_finite())
        .map(|i| (key(points[i]), i as u32))
        .collect();
    if binned.len() < 2 {
        return;
    }
    binned.sort_unstable();
    // Runs of equal keys: one per occupied cell.
    let mut cells: Vec<(Key, usize, usize)> = Vec::new();
    for (n, (k, _)) in binned.iter().enumerate() {
        match cells.last_mut() {
            Some((last, _, end)) if last == k => *end = n + 1,
            _ => cells.push((*k, n, n + 1)),
        }
    }
    let members = |c: usize| binned[cells[c].1..cells[c].2].iter().map(|&(_, i)| i as usize);
    let crowded = |c: usize| cells[c].2 - cells[c].1 > MAX_POINTS_PER_CELL;
    let find = |k: Key| cells.binary_search_by(|(ck, _, _)| ck.cmp(&k)).ok();
    let ordered = |a: usize, b: usize| if a < b { (a, b) } else { (b, a) };
    for c in 0..cells.len() {
        if crowded(c) {
            continue;
        }
        let here: Vec<usize> = members(c).collect();
        for (n, &a) in here.iter().enumerate() {
            for &b in &here[n + 1..] {
                let (i, j) = ordered(a, b);
                visit(i, j);
            }
        }
        let k = cells[c].0;
        for d in FORWARD {
            // Saturating: a far-away point's cell index sits at the i64 limit.
            let nk = [k[0].saturating_add(d[0]), k[1].saturating_add(d[1]), k[2].saturating_add(d[2])];
            if nk == k {
                continue;
            }
            let Some(other) = find(nk) else { continue };
            if crowded(other) {
                continue;
            }
            for &a in &here {
                for b in members(other) {
                    let (i, j) = ordered(a, b);
                    visit(i, j);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_exactly_the_close_pairs() {
        let mut s = 99u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let points: Vec<DVec3> = (0..600).map(|_| DVec3::new(rnd(), rnd(), rnd()) * 20.0 - 7.0).collect();
        let cut = 2.5;
        let mut fast = Vec::new();
        for_each_near_pair(
            &points,
            |_| true,
            cut,
            |i, j| {
                if points[i].distance(points[j]) < cut {
                    fast.push((i, j));
                }
            },
        );
        fast.sort_unstable();
        let mut slow = Vec::new();
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                if points[i].distance(points[j]) < cut {
                    slow.push((i, j));
                }
            }
        }
        assert!(slow.len() > 100);
        assert_eq!(fast, slow);
    }
}
