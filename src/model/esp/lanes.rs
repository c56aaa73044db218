//! The potential at eight neighbouring points at once, in AVX-512 registers: the sums of
//! [`Potential::at`], each point in a lane of its own and in the same order, with the same
//! operations, so each lane's value has the one-point path's bits.
//!
//! Why: the one-point path runs chains of dependent multiply-adds on one lane (the far fields'
//! Horner passes, the Boys functions' Taylor series, the R recursion). A grid row's neighbouring
//! points share every anchor and most of the primitive pairs summed exactly (measured on a 40³
//! grid around PSB3: 92 % of the lanes' pair evaluations are used), so one pass over a pair
//! serves eight points. A point for which a pair is already part of its anchor's far field masks
//! that pair out: its lane adds nothing, as its own sum leaves the pair out. Loops over arrays of
//! lanes were tried first and compiled to one lane at a time (the table look-ups and the
//! far fields' per-lane coefficients defeat the vectoriser), hence the intrinsics.
//!
//! Machines without AVX-512 take the one-point path point by point.

use std::arch::x86_64::*;

use glam::DVec3;

use super::super::boys::{self, MAX_N};
use super::{FarField, HermitePair, Potential, Scratch, recipe, triples};

/// Points evaluated together.
pub(super) const LANES: usize = 8;
/// One number per lane, as stored between passes.
pub(super) type Lanes = [f64; LANES];

/// Whether this machine runs [`Potential::at_lanes`].
pub(super) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512dq")
}

/// The points' coordinates, axis by axis.
#[derive(Clone, Copy)]
struct Points {
    x: __m512d,
    y: __m512d,
    z: __m512d,
}

#[inline(always)]
fn splat(v: f64) -> __m512d {
    // SAFETY: AVX-512F is present wherever this module's functions run (`available`).
    unsafe { _mm512_set1_pd(v) }
}

impl Potential {
    /// The potential at eight points (bohr), each equal bit for bit to [`Potential::at`] there.
    ///
    /// # Safety
    /// The CPU must have AVX-512F and AVX-512DQ ([`available`]).
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) unsafe fn at_lanes(&self, points: &[DVec3; LANES], scratch: &mut Scratch) -> Lanes {
        let coordinate = |axis: usize| -> __m512d {
            let values: Lanes = std::array::from_fn(|l| points[l][axis]);
            // SAFETY: eight f64 read from an array of eight.
            unsafe { _mm512_loadu_pd(values.as_ptr()) }
        };
        let at = Points { x: coordinate(0), y: coordinate(1), z: coordinate(2) };
        let nuclear: Lanes = std::array::from_fn(|l| self.nuclear(points[l]));
        // SAFETY: as above.
        let mut v = unsafe { _mm512_loadu_pd(nuclear.as_ptr()) };
        for anchor in &self.anchors {
            let mut start = [0i64; LANES];
            let mut fields: [Option<&FarField>; LANES] = [None; LANES];
            for l in 0..LANES {
                let d = anchor.center.distance(points[l]);
                let active = anchor.levels.partition_point(|level| level.radius <= d);
                if active > 0 {
                    let level = &anchor.levels[active - 1];
                    fields[l] = Some(&level.field);
                    start[l] = level.count as i64;
                }
            }
            if fields.iter().any(Option::is_some) {
                v = far_fields(&fields, anchor.center, at, v);
            }
            // SAFETY: eight i64 read from an array of eight.
            let starts = unsafe { _mm512_loadu_si512(start.as_ptr().cast()) };
            let first = start.iter().copied().min().unwrap_or(0) as usize;
            for (index, pair) in anchor.pairs.iter().enumerate().skip(first) {
                let value = self.pair_lanes(pair, at, scratch);
                let wanted = _mm512_cmple_epi64_mask(starts, _mm512_set1_epi64(index as i64));
                v = _mm512_mask_add_pd(v, wanted, v, value);
            }
        }
        let mut out = [0.0; LANES];
        // SAFETY: eight f64 written to an array of eight.
        unsafe { _mm512_storeu_pd(out.as_mut_ptr(), v) };
        out
    }

    /// [`Potential::pair_at`] in each lane: the same products and sums in the same order.
    #[target_feature(enable = "avx512f,avx512dq")]
    fn pair_lanes(&self, pair: &HermitePair, at: Points, scratch: &mut Scratch) -> __m512d {
        let x = _mm512_sub_pd(splat(pair.center.x), at.x);
        let y = _mm512_sub_pd(splat(pair.center.y), at.y);
        let z = _mm512_sub_pd(splat(pair.center.z), at.z);
        let r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y)), _mm512_mul_pd(z, z));
        let t = _mm512_mul_pd(splat(pair.p), r2);
        let c = &self.coefficients[pair.first..];
        let mul = |a, b| _mm512_mul_pd(a, b);
        let add = |a, b| _mm512_add_pd(a, b);
        match pair.l {
            0 => mul(splat(c[0]), f0_lanes(t)),
            1 => {
                let mut f = [splat(0.0); 2];
                boys_lanes(1, t, &mut f);
                let a1 = mul(splat(-2.0 * pair.p), f[1]);
                let dot = add(add(mul(splat(c[1]), x), mul(splat(c[2]), y)), mul(splat(c[3]), z));
                add(mul(splat(c[0]), f[0]), mul(a1, dot))
            }
            2 => {
                let c: [__m512d; 10] = std::array::from_fn(|k| splat(c[k]));
                let mut f = [splat(0.0); 3];
                boys_lanes(2, t, &mut f);
                let m2p = -2.0 * pair.p;
                let (a1, a2) = (mul(splat(m2p), f[1]), mul(splat(m2p * m2p), f[2]));
                let first = add(add(add(add(add(mul(c[1], x), mul(c[2], y)), mul(c[3], z)), c[4]), c[7]), c[9]);
                let second = add(
                    add(
                        add(
                            add(add(mul(mul(c[4], x), x), mul(mul(c[5], x), y)), mul(mul(c[6], x), z)),
                            mul(mul(c[7], y), y),
                        ),
                        mul(mul(c[8], y), z),
                    ),
                    mul(mul(c[9], z), z),
                );
                add(add(mul(c[0], f[0]), mul(a1, first)), mul(a2, second))
            }
            l => {
                let recipe = recipe(l);
                let r = &mut scratch.lanes;
                if r.len() < recipe.len {
                    r.resize(recipe.len, [0.0; LANES]);
                }
                let mut f = [splat(0.0); MAX_N + 1];
                boys_lanes(l, t, &mut f);
                let store = |to: &mut Lanes, value| {
                    // SAFETY: eight f64 written to an array of eight.
                    unsafe { _mm512_storeu_pd(to.as_mut_ptr(), value) }
                };
                // SAFETY: eight f64 read from an array of eight.
                let load = |from: &Lanes| unsafe { _mm512_loadu_pd(from.as_ptr()) };
                let mut factor = 1.0;
                for (n, &begin) in recipe.levels.iter().enumerate() {
                    store(&mut r[begin], mul(splat(factor), f[n]));
                    factor *= -2.0 * pair.p;
                }
                let axes = [x, y, z];
                for s in &recipe.steps {
                    let value = add(
                        mul(axes[s.axis as usize], load(&r[s.from as usize])),
                        mul(splat(s.weight), load(&r[s.back as usize])),
                    );
                    store(&mut r[s.dst as usize], value);
                }
                // `Iterator::sum`'s own start, so each lane adds as the one-point path's sum does.
                let mut sum = splat(std::iter::empty::<f64>().sum::<f64>());
                for (rk, &ck) in r[..triples(l).tuv.len()].iter().zip(c) {
                    sum = add(sum, mul(splat(ck), load(rk)));
                }
                sum
            }
        }
    }
}

/// Adds each lane's far field (where it has one) at X = anchor − point: [`FarField::at`]'s
/// Horner pass in eight lanes side by side, each lane gathering its own coefficients.
#[target_feature(enable = "avx512f,avx512dq")]
fn far_fields(fields: &[Option<&FarField>; LANES], anchor: DVec3, at: Points, v: __m512d) -> __m512d {
    let Some(base) = fields.iter().flatten().next() else { return v };
    let order = base.order;
    // Every level's field lies in its anchor's one vector of levels, so each lane's coefficients
    // are a whole number of f64 from the first lane's; a lane without a field reads the first
    // lane's and is dropped by the mask.
    let origin = base.coefficients.as_ptr();
    let offsets: [i64; LANES] = std::array::from_fn(|l| {
        fields[l].map_or(0, |f| (f.coefficients.as_ptr() as isize - origin as isize) as i64 / 8)
    });
    // Points further out mostly share their level: one coefficient for all lanes then, read
    // once rather than gathered.
    let shared = fields.iter().flatten().all(|f| std::ptr::eq(*f, *base));
    let mut has = 0u8;
    for (l, field) in fields.iter().enumerate() {
        has |= u8::from(field.is_some()) << l;
    }
    // SAFETY: eight i64 read from an array of eight.
    let offsets = unsafe { _mm512_loadu_si512(offsets.as_ptr().cast()) };
    let x = _mm512_sub_pd(splat(anchor.x), at.x);
    let y = _mm512_sub_pd(splat(anchor.y), at.y);
    let z = _mm512_sub_pd(splat(anchor.z), at.z);
    let r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y)), _mm512_mul_pd(z, z));
    let (yx, yy, yz) = (_mm512_div_pd(x, r2), _mm512_div_pd(y, r2), _mm512_div_pd(z, r2));
    let mut next = 0i64;
    let mut px = splat(0.0);
    for a in (0..=order).rev() {
        let mut py = splat(0.0);
        for b in (0..=order - a).rev() {
            let mut pz = splat(0.0);
            for _ in 0..=order - a - b {
                let c = if shared {
                    splat(base.coefficients[next as usize])
                } else {
                    let index = _mm512_add_epi64(offsets, _mm512_set1_epi64(next));
                    // SAFETY: each lane's index lies inside its own field's coefficients (or
                    // the first lane's), all in one allocation.
                    unsafe { _mm512_i64gather_pd::<8>(index, origin) }
                };
                pz = _mm512_add_pd(_mm512_mul_pd(pz, yz), c);
                next += 1;
            }
            py = _mm512_add_pd(_mm512_mul_pd(py, yy), pz);
        }
        px = _mm512_add_pd(_mm512_mul_pd(px, yx), py);
    }
    _mm512_mask_add_pd(v, has, v, _mm512_div_pd(px, _mm512_sqrt_pd(r2)))
}

/// Each lane's nearest table point ([`boys`]'s `nearest`), with arguments past the table held
/// at its end (those lanes take the asymptotic form afterwards): where its row starts, and the
/// argument's distance from it. The table is looked up once here, not per value read.
#[derive(Clone, Copy)]
struct TableRows {
    /// Index of each lane's row's first value.
    first: __m512i,
    table: *const f64,
    dt: __m512d,
}

#[target_feature(enable = "avx512f,avx512dq")]
fn table_points(t: __m512d) -> TableRows {
    let table = boys::table();
    let held = _mm512_min_pd(t, splat(boys::T_TABLE));
    let index = _mm512_cvttpd_epu64(_mm512_add_pd(_mm512_mul_pd(held, splat(1.0 / boys::STEP)), splat(0.5)));
    let index = _mm512_min_epu64(index, _mm512_set1_epi64(table.len() as i64 - 1));
    let dt = _mm512_sub_pd(t, _mm512_mul_pd(_mm512_cvtepu64_pd(index), splat(boys::STEP)));
    let first = _mm512_mullo_epi64(index, _mm512_set1_epi64(boys::ORDERS as i64));
    TableRows { first, table: table.as_ptr().cast(), dt }
}

impl TableRows {
    /// F_n(T_i) for each lane's table point i.
    #[target_feature(enable = "avx512f,avx512dq")]
    fn at(self, n: usize) -> __m512d {
        let at = _mm512_add_epi64(self.first, _mm512_set1_epi64(n as i64));
        // SAFETY: each row is one of the table's and n < ORDERS: inside the table.
        unsafe { _mm512_i64gather_pd::<8>(at, self.table) }
    }
}

/// −x, as the one-point path's negation (the sign bit flipped: 0 − x would make −0 of 0).
#[target_feature(enable = "avx512f,avx512dq")]
fn negate(x: __m512d) -> __m512d {
    _mm512_xor_pd(x, splat(-0.0))
}

/// [`boys::f0`] in each lane.
#[target_feature(enable = "avx512f,avx512dq")]
fn f0_lanes(t: __m512d) -> __m512d {
    let rows = table_points(t);
    let dt = negate(rows.dt);
    let mut sum = rows.at(boys::TAYLOR - 1);
    for k in (0..boys::TAYLOR - 1).rev() {
        sum = _mm512_add_pd(rows.at(k), _mm512_div_pd(_mm512_mul_pd(sum, dt), splat((k + 1) as f64)));
    }
    let far = _mm512_mul_pd(splat(0.5), _mm512_sqrt_pd(_mm512_div_pd(splat(std::f64::consts::PI), t)));
    _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_GE_OQ>(t, splat(boys::T_TABLE)), sum, far)
}

/// [`boys::boys`] in each lane: `out[n]` = F_n(t) for n ≤ m.
#[target_feature(enable = "avx512f,avx512dq")]
fn boys_lanes(m: usize, t: __m512d, out: &mut [__m512d]) {
    let rows = table_points(t);
    let minus_dt = negate(rows.dt);
    if m <= boys::DIRECT {
        let mut factors = [splat(1.0); boys::TAYLOR];
        for k in 1..boys::TAYLOR {
            factors[k] = _mm512_div_pd(_mm512_mul_pd(factors[k - 1], minus_dt), splat(k as f64));
        }
        for (n, o) in out.iter_mut().enumerate().take(m + 1) {
            // `Iterator::sum`'s own start: the same additions as `boys`.
            let mut sum = splat(std::iter::empty::<f64>().sum::<f64>());
            for (k, &factor) in factors.iter().enumerate() {
                sum = _mm512_add_pd(sum, _mm512_mul_pd(rows.at(n + k), factor));
            }
            *o = sum;
        }
    } else {
        let (mut fm, mut factor) = (splat(0.0), splat(1.0));
        for k in 0..boys::TAYLOR {
            fm = _mm512_add_pd(fm, _mm512_mul_pd(rows.at(m + k), factor));
            factor = _mm512_mul_pd(factor, _mm512_div_pd(minus_dt, splat((k + 1) as f64)));
        }
        out[m] = fm;
        let mut lanes = [0.0; LANES];
        // SAFETY: eight f64 written to an array of eight.
        unsafe { _mm512_storeu_pd(lanes.as_mut_ptr(), t) };
        let e: Lanes = std::array::from_fn(|l| (-lanes[l]).exp());
        // SAFETY: eight f64 read from an array of eight.
        let e = unsafe { _mm512_loadu_pd(e.as_ptr()) };
        for n in (0..m).rev() {
            let twice = _mm512_mul_pd(_mm512_mul_pd(splat(2.0), t), out[n + 1]);
            out[n] = _mm512_div_pd(_mm512_add_pd(twice, e), splat((2 * n + 1) as f64));
        }
    }
    let far = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(t, splat(boys::T_TABLE));
    if far != 0 {
        // [`boys::asymptotic`]: F_0 = √(π/T)/2, F_n = F_{n−1}(2n − 1)/(2T).
        let mut value = _mm512_mul_pd(splat(0.5), _mm512_sqrt_pd(_mm512_div_pd(splat(std::f64::consts::PI), t)));
        let half_over_t = _mm512_div_pd(splat(0.5), t);
        out[0] = _mm512_mask_blend_pd(far, out[0], value);
        for (n, o) in out.iter_mut().enumerate().take(m + 1).skip(1) {
            value = _mm512_mul_pd(_mm512_mul_pd(value, splat((2 * n - 1) as f64)), half_over_t);
            *o = _mm512_mask_blend_pd(far, *o, value);
        }
    }
}
