//! The range of values over each brick of a grid: where a transfer function can show nothing,
//! renderers need not cut slices.

use glam::DMat4;

use super::VolumeGrid;

/// Grid cells along each side of a brick.
pub const BRICK_CELLS: usize = 4;

/// Bricks of `edge` cells tiling a grid: brick b along an axis spans the grid points
/// `edge·b ..= min(edge·(b + 1), n − 1)`. Neighbours share their face's points, so every value
/// a trilinear sample inside a brick mixes is one of its own.
#[derive(Debug, Clone, PartialEq)]
pub struct BrickRanges {
    pub edge: usize,
    /// Grid points per axis (as `VolumeGrid::dims`).
    pub dims: [usize; 3],
    /// The grid's placement (world from grid indices).
    pub world_from_grid: DMat4,
    /// Bricks per axis.
    pub counts: [usize; 3],
    /// (min, max) of the values in each brick, x slowest (as the grid's values).
    pub ranges: Vec<(f32, f32)>,
}

impl BrickRanges {
    pub fn of(grid: &VolumeGrid, edge: usize) -> Self {
        let edge = edge.max(1);
        let dims = grid.dims;
        let counts = dims.map(|n| n.saturating_sub(1).div_ceil(edge).max(1));
        let span = |b: usize, a: usize| b * edge..=((b + 1) * edge).min(dims[a].saturating_sub(1));
        let mut ranges = Vec::with_capacity(counts.iter().product());
        for bi in 0..counts[0] {
            for bj in 0..counts[1] {
                for bk in 0..counts[2] {
                    let mut range = (f32::INFINITY, f32::NEG_INFINITY);
                    for i in span(bi, 0) {
                        for j in span(bj, 1) {
                            let start = grid.index(i, j, 0);
                            for &v in &grid.values[start + bk * edge..=start + *span(bk, 2).end()] {
                                range = (range.0.min(v), range.1.max(v));
                            }
                        }
                    }
                    ranges.push(range);
                }
            }
        }
        Self { edge, dims, world_from_grid: grid.world_from_grid, counts, ranges }
    }

    pub fn index(&self, b: [usize; 3]) -> usize {
        (b[0] * self.counts[1] + b[1]) * self.counts[2] + b[2]
    }

    /// The ranges of two grids of the same shape merged brick by brick (what a mix of the two
    /// can take); None for different shapes.
    pub fn union(&self, other: &BrickRanges) -> Option<BrickRanges> {
        (self.dims == other.dims && self.edge == other.edge).then(|| BrickRanges {
            ranges: self.ranges.iter().zip(&other.ranges).map(|(a, b)| (a.0.min(b.0), a.1.max(b.1))).collect(),
            ..self.clone()
        })
    }

    /// Which bricks hold a value a transfer function shows, given the smallest value it shows
    /// (`floor`) and whether it shows |value| (a signed field) or the value itself.
    pub fn occupied(&self, floor: f32, signed: bool) -> Vec<bool> {
        let top = |&(lo, hi): &(f32, f32)| if signed { hi.max(-lo) } else { hi };
        self.ranges.iter().map(|r| top(r) >= floor).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bricks_share_their_faces_and_hold_their_extremes() {
        // 10 points along x: bricks of 4 cells span points 0..=4, 4..=8 and 8..=9.
        let dims = [10, 3, 2];
        let mut values = vec![0.0f32; 60];
        let g = VolumeGrid::new("a", dims, DMat4::IDENTITY, values.clone());
        values[g.index(4, 1, 1)] = -2.0;
        values[g.index(9, 2, 0)] = 3.0;
        let g = VolumeGrid::new("a", dims, DMat4::IDENTITY, values);
        let b = BrickRanges::of(&g, 4);
        assert_eq!(b.counts, [3, 1, 1]);
        assert_eq!(b.ranges, vec![(-2.0, 0.0), (-2.0, 0.0), (0.0, 3.0)]);
        assert_eq!(b.occupied(1.0, true), vec![true, true, true]);
        assert_eq!(b.occupied(1.0, false), vec![false, false, true]);
        let flipped = BrickRanges { ranges: vec![(0.0, 5.0), (-1.0, 0.0), (0.0, 0.0)], ..b.clone() };
        assert_eq!(b.union(&flipped).unwrap().ranges, vec![(-2.0, 5.0), (-2.0, 0.0), (0.0, 3.0)]);
    }
}
