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
    let members: Vec<u32> =
        (0..points.len()).filter(|&i| include(i) && points[i].is_finite()).map(|i| i as u32).collect();
    if members.len() < 2 {
        return;
    }
    let keys: Vec<Key> = members.iter().map(|&i| key(points[i as usize])).collect();
    let grid = Grid::new(&members, &keys);
    let ordered = |a: usize, b: usize| if a < b { (a, b) } else { (b, a) };
    for c in 0..grid.cells.len() {
        let (k, here) = (grid.cells[c], grid.members(c));
        if here.len() > MAX_POINTS_PER_CELL {
            continue;
        }
        for (n, &a) in here.iter().enumerate() {
            for &b in &here[n + 1..] {
                let (i, j) = ordered(a as usize, b as usize);
                visit(i, j);
            }
        }
        for d in FORWARD {
            // Saturating: a far-away point's cell index sits at the i64 limit.
            let nk = [k[0].saturating_add(d[0]), k[1].saturating_add(d[1]), k[2].saturating_add(d[2])];
            if nk == k {
                continue;
            }
            let there = grid.find(nk);
            if there.len() > MAX_POINTS_PER_CELL {
                continue;
            }
            for &a in here {
                for &b in there {
                    let (i, j) = ordered(a as usize, b as usize);
                    visit(i, j);
                }
            }
        }
    }
}

/// Points grouped by cell: a dense array of cell starts when the occupied box is small enough
/// (O(n) counting sort, O(1) lookups), sorted keys otherwise (a sparse or hostile input).
struct Grid {
    /// Occupied cells' keys, in the order their points sit in `points`.
    cells: Vec<Key>,
    /// Each occupied cell's range in `points`.
    ranges: Vec<(u32, u32)>,
    points: Vec<u32>,
    dense: Option<Dense>,
}

struct Dense {
    lo: Key,
    dims: [i64; 3],
    /// Start of each cell of the box in `points` (one more entry than cells).
    start: Vec<u32>,
}

impl Dense {
    fn index(&self, k: Key) -> Option<usize> {
        let c = [k[0] - self.lo[0], k[1] - self.lo[1], k[2] - self.lo[2]];
        (0..3)
            .all(|a| (0..self.dims[a]).contains(&c[a]))
            .then(|| (c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])) as usize)
    }
}

impl Grid {
    fn new(members: &[u32], keys: &[Key]) -> Self {
        let lo = keys.iter().fold(keys[0], |m, k| [m[0].min(k[0]), m[1].min(k[1]), m[2].min(k[2])]);
        let hi = keys.iter().fold(keys[0], |m, k| [m[0].max(k[0]), m[1].max(k[1]), m[2].max(k[2])]);
        let dims = [0, 1, 2].map(|a| hi[a].saturating_sub(lo[a]).saturating_add(1));
        let total = dims.iter().try_fold(1i64, |acc, &d| acc.checked_mul(d));
        match total.filter(|&t| t <= 8 * members.len() as i64 + 64) {
            Some(total) => {
                let mut dense = Dense { lo, dims, start: vec![0; total as usize + 1] };
                let index: Vec<usize> = keys.iter().map(|&k| dense.index(k).unwrap_or(0)).collect();
                for &c in &index {
                    dense.start[c + 1] += 1;
                }
                for c in 0..total as usize {
                    dense.start[c + 1] += dense.start[c];
                }
                let mut fill = dense.start.clone();
                let mut points = vec![0u32; members.len()];
                for (n, &c) in index.iter().enumerate() {
                    points[fill[c] as usize] = members[n];
                    fill[c] += 1;
                }
                let (mut cells, mut ranges) = (Vec::new(), Vec::new());
                for c in 0..total as usize {
                    let (a, b) = (dense.start[c], dense.start[c + 1]);
                    if b > a {
                        let c = c as i64;
                        let (x, y, z) = (c % dims[0], c / dims[0] % dims[1], c / (dims[0] * dims[1]));
                        cells.push([lo[0] + x, lo[1] + y, lo[2] + z]);
                        ranges.push((a, b));
                    }
                }
                Self { cells, ranges, points, dense: Some(dense) }
            }
            None => {
                let mut order: Vec<(Key, u32)> = keys.iter().copied().zip(members.iter().copied()).collect();
                order.sort_unstable();
                let (mut cells, mut ranges) = (Vec::<Key>::new(), Vec::<(u32, u32)>::new());
                for (n, (k, _)) in order.iter().enumerate() {
                    match (cells.last(), ranges.last_mut()) {
                        (Some(last), Some(r)) if last == k => r.1 = n as u32 + 1,
                        _ => {
                            cells.push(*k);
                            ranges.push((n as u32, n as u32 + 1));
                        }
                    }
                }
                Self { cells, ranges, points: order.into_iter().map(|(_, i)| i).collect(), dense: None }
            }
        }
    }

    fn members(&self, c: usize) -> &[u32] {
        let (a, b) = self.ranges[c];
        &self.points[a as usize..b as usize]
    }

    /// The points of the cell `k`, empty when it holds none.
    fn find(&self, k: Key) -> &[u32] {
        match &self.dense {
            Some(d) => d.index(k).map_or(&[][..], |c| &self.points[d.start[c] as usize..d.start[c + 1] as usize]),
            None => self.cells.binary_search(&k).map_or(&[][..], |c| self.members(c)),
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
        // Two far-apart clusters: the sparse path finds the same pairs within each.
        let far: Vec<DVec3> = points.iter().map(|&p| p + DVec3::splat(1e6)).collect();
        let both: Vec<DVec3> = points.iter().chain(&far).copied().collect();
        let mut sparse = 0;
        for_each_near_pair(&both, |_| true, cut, |i, j| sparse += (both[i].distance(both[j]) < cut) as usize);
        assert_eq!(sparse, 2 * slow.len());
    }
}
