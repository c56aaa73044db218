//! Orbitals and densities on axis-aligned grids, by separation of variables.
//!
//! When a grid's steps run along x, y and z (what `cube`, the viewer and scans make), each term
//! of an orbital's cartesian expansion factorises along the axes (coordinates relative to the
//! term's centre):
//!
//!   w · x^a y^b z^c · exp(−α r²) = w · [x^a exp(−α x²)] · [y^b exp(−α y²)] · [z^c exp(−α z²)].
//!
//! Exponentials are then needed only along the axes: per primitive, tables of x^a exp(−α x²)
//! over the grid's x positions and of y^b exp(−α y²) over its y positions; per centre height
//! and exponent, exp(−α z²) over the z positions, shared by all shells of an atom that use the
//! exponent and by atoms at the same height. A row (i, j) of the grid (z fastest) is
//! Σ_g exp(−α_g z²) · P_g(z), the coefficients of each P_g taken from the x and y tables: a few
//! multiply-adds per point and term, no `exp`. Terms with the same z table over the same stretch
//! of a row are summed before the row is touched.
//!
//! Cutoffs are [`PreparedBasis`]'s: each primitive's sphere cuts a row to an interval, the one
//! the general path uses, so both paths drop the same terms at the same points.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use super::basis::cartesian_powers;
use super::grid::GridSpec;
use super::gto::{MAX_EVAL_L, PreparedBasis, interval, primitive_reach2};

/// Coefficients per set and z power in a row entry: room for the highest l.
const STRIDE: usize = MAX_EVAL_L as usize + 1;

/// Sets (orbitals of a density) evaluated together.
const BATCH: usize = 8;

/// Whether the grid's steps run along x, y and z respectively.
pub fn is_axis_aligned(grid: &GridSpec) -> bool {
    (0..3).all(|axis| (0..3).all(|c| c == axis || grid.step(axis)[c] == 0.0))
}

/// What a grid is stored as.
pub trait GridValue: Copy + Default + Send + Sync {
    fn from_f64(v: f64) -> Self;
}

impl GridValue for f64 {
    fn from_f64(v: f64) -> Self {
        v
    }
}

impl GridValue for f32 {
    fn from_f64(v: f64) -> Self {
        v as f32
    }
}

/// Values of one axis's factor t^e exp(−α t²) at the grid positions where the primitive can
/// reach (`start..start + len`), for e = 0..=highest power.
struct AxisTable {
    start: usize,
    len: usize,
    /// values[e · len + (i − start)].
    values: Vec<f64>,
}

impl AxisTable {
    fn new(positions: &[f64], centre: f64, alpha: f64, r2max: f64, powers: usize) -> Self {
        let reach = within(positions, 0..positions.len(), centre, r2max);
        let len = reach.len();
        let mut values = vec![0.0; (powers + 1) * len];
        for (n, &t) in positions[reach.clone()].iter().enumerate() {
            let d = t - centre;
            let mut v = (-alpha * d * d).exp();
            for e in 0..=powers {
                values[e * len + n] = v;
                v *= d;
            }
        }
        Self { start: reach.start, len, values }
    }

    fn contains(&self, i: usize) -> bool {
        i.wrapping_sub(self.start) < self.len
    }

    fn at(&self, e: usize, i: usize) -> f64 {
        self.values[e * self.len + i - self.start]
    }

    /// Power `e`'s values over `range` (inside the table's).
    fn slice(&self, e: usize, range: Range<usize>) -> &[f64] {
        &self.values[e * self.len + range.start - self.start..e * self.len + range.end - self.start]
    }
}

/// The stretch of `range` where (positions − centre)² ≤ limit (contiguous: the square is
/// convex).
fn within(positions: &[f64], range: Range<usize>, centre: f64, limit: f64) -> Range<usize> {
    let inside = |k: usize| (positions[k] - centre) * (positions[k] - centre) <= limit;
    let Some(start) = range.clone().find(|&k| inside(k)) else {
        return range.start..range.start;
    };
    let end = (start..range.end).rev().find(|&k| inside(k)).map_or(start, |k| k + 1);
    start..end
}

/// Along z, shared by every primitive of one exponent at one centre height: the offsets
/// z − z_centre and exp(−α (z − z_centre)²) at every grid position.
struct ZTable {
    dz: Vec<f64>,
    ez: Vec<f64>,
    /// Highest power of z among its groups.
    lz: usize,
}

/// One primitive of one shell: Σ_m w_m,s x^a y^b z^c exp(−α r²) for each set s.
struct Group {
    centre: DVec3,
    r2max: f64,
    /// Largest (z − z_centre)² on the grid: rows nearer than r2max minus this lie wholly inside.
    dz2_far: f64,
    powers: Vec<[usize; 3]>,
    /// weights[m · n_sets + s].
    weights: Vec<f64>,
    lz: usize,
    x: AxisTable,
    y: AxisTable,
    ztable: usize,
}

/// Everything a grid needs that does not depend on the row.
struct Plan {
    groups: Vec<Group>,
    ztables: Vec<ZTable>,
    n_sets: usize,
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// z step (bohr).
    sz: f64,
}

impl Plan {
    fn new(basis: &PreparedBasis, sets: &[(&[f64], f64)], grid: &GridSpec) -> Self {
        let [nx, ny, nz] = grid.dims;
        let (o, s) = (grid.origin(), [grid.step(0).x, grid.step(1).y, grid.step(2).z]);
        let xs: Vec<f64> = (0..nx).map(|i| o.x + i as f64 * s[0]).collect();
        let ys: Vec<f64> = (0..ny).map(|j| o.y + j as f64 * s[1]).collect();
        let zs: Vec<f64> = (0..nz).map(|k| o.z + k as f64 * s[2]).collect();
        let monomials: Vec<(Vec<f64>, Vec<bool>)> = sets.iter().map(|(c, _)| basis.monomial_coefficients(c)).collect();
        // (z-table key, exponent, group) for every primitive of every shell with a weight.
        let mut keyed = Vec::new();
        for (si, shell) in basis.shells.iter().enumerate() {
            if !monomials.iter().any(|(_, active)| active[si]) {
                continue;
            }
            let first = shell.first_cartesian as usize;
            for p in shell.primitives() {
                let (alpha, c) = (basis.exponents[p], basis.coefficients[p]);
                let r2max = primitive_reach2(basis, p);
                let (mut powers, mut weights) = (Vec::new(), Vec::new());
                for (m, pw) in cartesian_powers(shell.l).iter().enumerate() {
                    let w: Vec<f64> = monomials.iter().map(|(d, _)| c * d[first + m]).collect();
                    if w.iter().any(|&w| w != 0.0) {
                        powers.push(pw.map(|e| e as usize));
                        weights.extend(w);
                    }
                }
                if powers.is_empty() {
                    continue;
                }
                let centre = shell.center();
                let [lx, ly, lz] = [0, 1, 2].map(|a| powers.iter().map(|p| p[a]).max().unwrap_or(0));
                let far = |z: Option<&f64>| z.map_or(0.0, |z| (z - centre.z) * (z - centre.z));
                let group = Group {
                    centre,
                    r2max,
                    dz2_far: far(zs.first()).max(far(zs.last())),
                    powers,
                    weights,
                    lz,
                    x: AxisTable::new(&xs, centre.x, alpha, r2max, lx),
                    y: AxisTable::new(&ys, centre.y, alpha, r2max, ly),
                    ztable: 0,
                };
                keyed.push(((centre.z.to_bits(), alpha.to_bits()), alpha, group));
            }
        }
        // The groups of one z table next to each other.
        keyed.sort_by_key(|(key, _, _)| *key);
        let mut groups = Vec::with_capacity(keyed.len());
        let mut ztables: Vec<ZTable> = Vec::new();
        let mut last = None;
        for (key, alpha, mut group) in keyed {
            if last != Some(key) {
                let dz: Vec<f64> = zs.iter().map(|z| z - group.centre.z).collect();
                let ez = dz.iter().map(|d| (-alpha * d * d).exp()).collect();
                ztables.push(ZTable { dz, ez, lz: 0 });
                last = Some(key);
            }
            let table = ztables.len() - 1;
            ztables[table].lz = ztables[table].lz.max(group.lz);
            group.ztable = table;
            groups.push(group);
        }
        Self { groups, ztables, n_sets: sets.len(), xs, ys, sz: s[2] }
    }
}

/// Σ_s w_s ψ_s (or Σ_s w_s ψ_s² when `square`) on an axis-aligned grid, cube order.
pub fn grid_sum<T: GridValue>(basis: &PreparedBasis, sets: &[(&[f64], f64)], square: bool, grid: &GridSpec) -> Vec<T> {
    let [_, ny, nz] = grid.dims;
    if sets.len() > BATCH {
        // A slab holds coefficients per set: bounded by evaluating the sets a few at a time.
        let mut total = vec![0.0f64; grid.len()];
        for batch in sets.chunks(BATCH) {
            let part: Vec<f64> = grid_sum(basis, batch, square, grid);
            total.iter_mut().zip(part).for_each(|(t, p)| *t += p);
        }
        return total.into_iter().map(T::from_f64).collect();
    }
    let mut out = vec![T::default(); grid.len()];
    if out.is_empty() || sets.is_empty() {
        return out;
    }
    let plan = Plan::new(basis, sets, grid);
    out.par_chunks_mut(ny * nz)
        .enumerate()
        .for_each_init(|| Slab::new(&plan, ny, nz), |slab, (i, values)| slab.fill(&plan, i, sets, square, values));
    out
}

/// A stretch `k0..k1` of a row over which Σ_c b[s][c] z^c · exp(−α z²) of one z table is
/// added, for each set s.
#[derive(Clone, Copy)]
struct Entry {
    ztable: usize,
    k0: usize,
    k1: usize,
    lz: usize,
    /// Offset of its coefficients (n_sets × STRIDE) in the row's coefficient buffer.
    at: usize,
}

/// A row's entries for the primitives whose sphere cuts it short.
#[derive(Default)]
struct PartialRow {
    entries: Vec<Entry>,
    coefficients: Vec<f64>,
}

/// One x slab's z polynomials. Rows that lie wholly inside a primitive's sphere (most of them,
/// for the valence primitives that cost the most) take its coefficients for all of their y at
/// once, summed per z table; rows the sphere cuts short get an entry of their own.
struct Slab {
    /// Per z table: offset of its whole-row coefficients in `whole` ([set][z power][row]), or
    /// `usize::MAX` when no group reached it in this slab; and the rows they cover.
    table_at: Vec<usize>,
    table_rows: Vec<Range<usize>>,
    touched: Vec<usize>,
    whole: Vec<f64>,
    partial: Vec<PartialRow>,
    /// ψ of each set along the row, then their weighted sum.
    psi: Vec<f64>,
    total: Vec<f64>,
    ny: usize,
    nz: usize,
}

impl Slab {
    fn new(plan: &Plan, ny: usize, nz: usize) -> Self {
        Self {
            table_at: vec![usize::MAX; plan.ztables.len()],
            table_rows: vec![0..0; plan.ztables.len()],
            touched: Vec::new(),
            whole: Vec::new(),
            partial: (0..ny).map(|_| PartialRow::default()).collect(),
            psi: vec![0.0; nz * plan.n_sets],
            total: vec![0.0; nz],
            ny,
            nz,
        }
    }

    /// Slab `i`'s values (Σ_s w_s ψ_s, or of ψ_s² when `square`) into `values`, row by row.
    fn fill<T: GridValue>(&mut self, plan: &Plan, i: usize, sets: &[(&[f64], f64)], square: bool, values: &mut [T]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has the feature the function is compiled for.
            unsafe { self.fill_avx512(plan, i, sets, square, values) };
            return;
        }
        self.fill_inline(plan, i, sets, square, values);
    }

    /// [`Self::fill`] with the loops along rows and over y eight lanes wide. The same
    /// products and sums in the same order: the values are those of the plain build, bit for
    /// bit.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn fill_avx512<T: GridValue>(
        &mut self,
        plan: &Plan,
        i: usize,
        sets: &[(&[f64], f64)],
        square: bool,
        values: &mut [T],
    ) {
        self.fill_inline(plan, i, sets, square, values);
    }

    #[inline(always)]
    fn fill_inline<T: GridValue>(
        &mut self,
        plan: &Plan,
        i: usize,
        sets: &[(&[f64], f64)],
        square: bool,
        values: &mut [T],
    ) {
        self.collect(plan, i);
        for (j, row) in values.chunks_mut(self.nz).enumerate() {
            self.evaluate_row(plan, j, sets, square, row);
        }
    }

    /// The z polynomials of every row of slab `i`.
    #[inline(always)]
    fn collect(&mut self, plan: &Plan, i: usize) {
        for &t in &self.touched {
            self.table_at[t] = usize::MAX;
        }
        self.touched.clear();
        self.whole.clear();
        for row in &mut self.partial {
            row.entries.clear();
            row.coefficients.clear();
        }
        let x = plan.xs[i];
        for g in plan.groups.iter().filter(|g| g.x.contains(i)) {
            let rx2 = (x - g.centre.x) * (x - g.centre.x);
            let rows = within(&plan.ys, g.y.start..g.y.start + g.y.len, g.centre.y, g.r2max - rx2);
            let whole = within(&plan.ys, rows.clone(), g.centre.y, g.r2max - rx2 - g.dz2_far);
            if !whole.is_empty() {
                self.add_whole(plan, g, i, whole.clone());
            }
            let (before, after) = if whole.is_empty() {
                (rows.clone(), rows.end..rows.end)
            } else {
                (rows.start..whole.start, whole.end..rows.end)
            };
            for j in before.chain(after) {
                self.add_partial(plan, g, [i, j], x);
            }
        }
    }

    /// Adds group `g`'s coefficients, rows `rows` of slab `i`, to its z table's whole rows.
    #[inline(always)]
    fn add_whole(&mut self, plan: &Plan, g: &Group, i: usize, rows: Range<usize>) {
        let (n_sets, ny) = (plan.n_sets, self.ny);
        let t = g.ztable;
        let powers = plan.ztables[t].lz + 1;
        if self.table_at[t] == usize::MAX {
            self.table_at[t] = self.whole.len();
            self.whole.resize(self.whole.len() + n_sets * powers * ny, 0.0);
            self.table_rows[t] = rows.clone();
            self.touched.push(t);
        } else {
            let r = &mut self.table_rows[t];
            *r = r.start.min(rows.start)..r.end.max(rows.end);
        }
        let at = self.table_at[t];
        for (m, p) in g.powers.iter().enumerate() {
            let xa = g.x.at(p[0], i);
            let y = g.y.slice(p[1], rows.clone());
            for (s, w) in g.weights[m * n_sets..(m + 1) * n_sets].iter().enumerate() {
                let q = w * xa;
                let offset = at + (s * powers + p[2]) * ny;
                for (b, yv) in self.whole[offset + rows.start..offset + rows.end].iter_mut().zip(y) {
                    *b += q * yv;
                }
            }
        }
    }

    /// Adds group `g` on row (i, j), which its sphere cuts to an interval (or misses).
    #[inline(always)]
    fn add_partial(&mut self, plan: &Plan, g: &Group, [i, j]: [usize; 2], x: f64) {
        let n_sets = plan.n_sets;
        let t = &plan.ztables[g.ztable];
        // The general path's quadratic in k for r², from the row's first point.
        let (ux, uy, uz) = (x - g.centre.x, plan.ys[j] - g.centre.y, t.dz[0]);
        let c0 = ux * ux + uy * uy + uz * uz;
        let Some((k0, k1)) = interval(plan.sz * plan.sz, uz * plan.sz, c0, g.r2max, self.nz) else {
            return;
        };
        let row = &mut self.partial[j];
        let found = row.entries.iter_mut().find(|e| e.ztable == g.ztable && e.k0 == k0 && e.k1 == k1);
        let at = match found {
            Some(e) => {
                e.lz = e.lz.max(g.lz);
                e.at
            }
            None => {
                let at = row.coefficients.len();
                row.coefficients.resize(at + n_sets * STRIDE, 0.0);
                row.entries.push(Entry { ztable: g.ztable, k0, k1, lz: g.lz, at });
                at
            }
        };
        let b = &mut row.coefficients[at..at + n_sets * STRIDE];
        for (m, p) in g.powers.iter().enumerate() {
            let xy = g.x.at(p[0], i) * g.y.at(p[1], j);
            for (s, w) in g.weights[m * n_sets..(m + 1) * n_sets].iter().enumerate() {
                b[s * STRIDE + p[2]] += w * xy;
            }
        }
    }

    /// Row `j` of the slab: Σ_s w_s ψ_s (ψ_s² when `square`) into `out`.
    #[inline(always)]
    fn evaluate_row<T: GridValue>(
        &mut self,
        plan: &Plan,
        j: usize,
        sets: &[(&[f64], f64)],
        square: bool,
        out: &mut [T],
    ) {
        let nz = self.nz;
        for (s, psi) in self.psi.chunks_mut(nz).enumerate() {
            psi.fill(0.0);
            for &t in &self.touched {
                if !self.table_rows[t].contains(&j) {
                    continue;
                }
                let table = &plan.ztables[t];
                let powers = table.lz + 1;
                let mut b = [0.0; STRIDE];
                for (c, b) in b[..powers].iter_mut().enumerate() {
                    *b = self.whole[self.table_at[t] + (s * powers + c) * self.ny + j];
                }
                add_polynomial(psi, &table.dz, &table.ez, &b[..powers]);
            }
            let row = &self.partial[j];
            for e in &row.entries {
                let table = &plan.ztables[e.ztable];
                let b = &row.coefficients[e.at + s * STRIDE..e.at + s * STRIDE + e.lz + 1];
                add_polynomial(&mut psi[e.k0..e.k1], &table.dz[e.k0..e.k1], &table.ez[e.k0..e.k1], b);
            }
        }
        if sets.len() == 1 && !square {
            let w = sets[0].1;
            for (o, p) in out.iter_mut().zip(&self.psi) {
                *o = T::from_f64(w * p);
            }
            return;
        }
        self.total.fill(0.0);
        for ((_, w), psi) in sets.iter().zip(self.psi.chunks(nz)) {
            for (t, p) in self.total.iter_mut().zip(psi) {
                *t += if square { w * p * p } else { w * p };
            }
        }
        for (o, t) in out.iter_mut().zip(&self.total) {
            *o = T::from_f64(*t);
        }
    }
}

/// row[k] += (Σ_c b[c] dz[k]^c) · ez[k]; the common low degrees spelled out so they vectorise.
#[inline(always)]
fn add_polynomial(row: &mut [f64], dz: &[f64], ez: &[f64], b: &[f64]) {
    let points = row.iter_mut().zip(dz.iter().zip(ez));
    match *b {
        [b0] => points.for_each(|(r, (_, e))| *r += b0 * e),
        [b0, b1] => points.for_each(|(r, (d, e))| *r += (b0 + b1 * d) * e),
        [b0, b1, b2] => points.for_each(|(r, (d, e))| *r += (b0 + d * (b1 + d * b2)) * e),
        _ => points.for_each(|(r, (d, e))| *r += b.iter().rev().fold(0.0, |h, c| h * d + c) * e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::basis::{Basis, Shell, ShellKind};
    use crate::model::gto::tests::pseudo_random;

    /// Cartesian and pure shells up to h, contracted, on four centres: two at one height (they
    /// share z tables), and a tight p shell.
    fn basis() -> Basis {
        let centres = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.3, -0.4, 0.0),
            DVec3::new(-0.9, 1.5, -0.8),
            DVec3::new(0.4, 0.6, 1.1),
        ];
        let mut shells = Vec::new();
        for l in 0..=5u32 {
            for (n, kind) in [ShellKind::Pure, ShellKind::Cartesian].into_iter().enumerate() {
                let scale = if n == 0 { 1.0 } else { 0.7 };
                shells.push(Shell {
                    atom: 0,
                    center: centres[(l as usize + n) % 4],
                    l,
                    kind,
                    exponents: vec![4.0 * scale, 1.1 * scale, 0.3 * scale],
                    coefficients: vec![0.3, 0.5, 0.4],
                });
            }
        }
        shells.push(Shell {
            atom: 0,
            center: centres[1],
            l: 1,
            kind: ShellKind::Cartesian,
            exponents: vec![9.0e4, 5.0e3, 800.0],
            coefficients: vec![0.2, 0.5, 0.6],
        });
        Basis { shells }
    }

    /// Largest |a − b| relative to the largest |b|.
    fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
    }

    fn grids() -> Vec<GridSpec> {
        vec![
            // The whole basis, rows cut by the spheres of the tighter primitives.
            GridSpec::new(
                DVec3::new(-9.0, -8.0, -8.5),
                [DVec3::X * 0.61, DVec3::Y * 0.57, DVec3::Z * 0.23],
                [30, 29, 75],
            ),
            // A sliver through part of it: few slabs, rows starting and ending inside spheres.
            GridSpec::new(
                DVec3::new(0.35, -2.0, 0.2),
                [DVec3::X * 0.05, DVec3::Y * 0.13, DVec3::Z * 0.011],
                [3, 31, 140],
            ),
            // Steps pointing backwards, and a single point along x.
            GridSpec::new(DVec3::new(3.0, 4.0, 2.0), [DVec3::X * -0.4, DVec3::Y * -0.3, DVec3::Z * -0.2], [1, 27, 33]),
        ]
    }

    #[test]
    fn separable_equals_the_row_path() {
        let basis = basis();
        for prepared in [PreparedBasis::new(&basis), PreparedBasis::with_threshold(&basis, 1e-6)] {
            let c = pseudo_random(prepared.n_functions(), 5);
            for grid in grids() {
                assert!(is_axis_aligned(&grid));
                let want = prepared.grid_sum_rows(&[(&c, 1.0)], false, &grid);
                let got: Vec<f64> = grid_sum(&prepared, &[(&c, 1.0)], false, &grid);
                let d = relative_difference(&got, &want);
                assert!(d < 1e-12, "{:?}: {d:e}", grid.dims);
                let f32s: Vec<f32> = grid_sum(&prepared, &[(&c, 1.0)], false, &grid);
                assert!(f32s.iter().zip(&got).all(|(a, b)| *a == *b as f32));
            }
        }
    }

    #[test]
    fn separable_sums_and_squares_sets() {
        let prepared = PreparedBasis::new(&basis());
        let n = prepared.n_functions();
        let (a, b, c) = (pseudo_random(n, 1), pseudo_random(n, 2), pseudo_random(n, 3));
        let (d, e) = (pseudo_random(n, 4), pseudo_random(n, 6));
        let mut sets: Vec<(&[f64], f64)> = vec![(&a, 2.0), (&b, 0.5), (&c, -1.0)];
        // More than a batch: the sets are summed a batch at a time.
        sets.extend((0..BATCH).map(|k| (if k % 2 == 0 { &d[..] } else { &e[..] }, 0.1 * k as f64)));
        for (grid, sets) in grids().into_iter().flat_map(|g| [(g, &sets[..3]), (g, &sets[..])]) {
            for square in [false, true] {
                let want = prepared.grid_sum_rows(sets, square, &grid);
                let got: Vec<f64> = grid_sum(&prepared, sets, square, &grid);
                let d = relative_difference(&got, &want);
                assert!(d < 1e-12, "{:?} {} sets, square {square}: {d:e}", grid.dims, sets.len());
            }
        }
    }

    #[test]
    fn without_cutoffs_tight_primitives_stay_finite() {
        let prepared = PreparedBasis::with_threshold(&basis(), 0.0);
        let c = pseudo_random(prepared.n_functions(), 13);
        let grid = grids().remove(0);
        let want = prepared.grid_sum_rows(&[(&c, 1.0)], false, &grid);
        let got: Vec<f64> = grid_sum(&prepared, &[(&c, 1.0)], false, &grid);
        assert!(relative_difference(&got, &want) < 1e-12);
    }

    #[test]
    fn only_axis_steps_are_separable() {
        let tilted = GridSpec::new(DVec3::ZERO, [DVec3::X, DVec3::new(0.0, 1.0, 1e-9), DVec3::Z], [2; 3]);
        assert!(!is_axis_aligned(&tilted));
        let swapped = GridSpec::new(DVec3::ZERO, [DVec3::Y, DVec3::X, DVec3::Z], [2; 3]);
        assert!(!is_axis_aligned(&swapped));
    }
}
