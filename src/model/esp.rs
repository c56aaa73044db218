//! The electrostatic potential of a molecule from its wavefunction:
//! V(C) = Σ_A Z_A / |C − R_A| − Σ_μν P_μν ∫ χ_μ(r) χ_ν(r) / |r − C| dr.
//!
//! McMurchie–Davidson: the product of two cartesian Gaussian primitives is a short sum of
//! Hermite Gaussians Λ_tuv centred at P = (αA + βB)/p with exponent p = α + β (coefficients
//! E^{ij}_t per axis), and the potential of Λ_tuv at C is (2π/p) R_tuv(p, P − C), where R follows
//! from the Boys functions F_n(p|P − C|²) by a recursion. Contracting the density matrix into the
//! Hermite coefficients once, when the potential is built, leaves per point and primitive pair
//! only the Boys functions, the R recursion and one dot product: the cost no longer depends on
//! how many functions a shell has.
//!
//! Pure shells are handled on their cartesian components (P_cart = Tᵀ P T with the cartesian →
//! pure matrices T), with the same normalised coefficients as the evaluator ([`PreparedBasis`]),
//! so the potential belongs to exactly the density orbcloud draws.
//!
//! Far from a group of primitive pairs (all pairs whose centre lies nearest one atom), the
//! group's potential is its multipole expansion about the atom, summed to order
//! [`MULTIPOLE_ORDER`]; it is used only where both the truncation of the expansion and the
//! penetration of the Gaussians are bounded below [`FAR_FIELD_ERROR`] (see [`Group`]).

use glam::DVec3;
use rayon::prelude::*;

use super::GridSpec;
use super::basis::MAX_L;
use super::boys::{self, boys};
use super::gto::{PreparedBasis, PreparedShell};
use super::molecule::Molecule;
use super::orbitals::Wavefunction;

#[cfg(target_arch = "x86_64")]
mod lanes;

/// Primitive pairs whose charge is below this (a.u.) are left out.
const PAIR_SCREEN: f64 = 1e-15;
/// Highest t + u + v of a primitive pair: two h functions.
const MAX_PAIR_L: usize = 2 * MAX_L as usize;
/// Distances below this (bohr) from a nucleus count as this distance: the potential is infinite
/// at a nucleus, and a grid point on one must still give a finite number.
const NUCLEUS_CORE: f64 = 1e-6;

/// Order of the far-field multipole expansions.
pub const MULTIPOLE_ORDER: usize = 10;
/// Bound (a.u.) on the error of a group's far field where it replaces the exact sum.
pub const FAR_FIELD_ERROR: f64 = 1e-7;

/// One primitive pair as a sum of Hermite Gaussians.
#[derive(Debug, Clone, Copy)]
struct HermitePair {
    center: DVec3,
    p: f64,
    /// Highest t + u + v.
    l: usize,
    /// Index of its first coefficient in `Potential::coefficients`.
    first: usize,
}

/// The (t, u, v) with t + u + v ≤ l, in the order coefficients are stored, with their index in a
/// dense (l+1)³ cube.
struct Triples {
    tuv: Vec<[usize; 3]>,
    cube: Vec<usize>,
}

fn triples(l: usize) -> &'static Triples {
    static TABLE: std::sync::OnceLock<Vec<Triples>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=MAX_PAIR_L.max(MULTIPOLE_ORDER))
            .map(|l| {
                let s = l + 1;
                let mut tuv = Vec::new();
                for k in 0..=l {
                    for t in (0..=k).rev() {
                        for u in (0..=k - t).rev() {
                            tuv.push([t, u, k - t - u]);
                        }
                    }
                }
                let cube = tuv.iter().map(|&[t, u, v]| (t * s + u) * s + v).collect();
                Triples { tuv, cube }
            })
            .collect()
    });
    &table[l]
}

/// Hermite expansion coefficients E^{ij}_t of one axis (without the exp(−μX²) factor):
/// x_A^i x_B^j = Σ_t E^{ij}_t Λ_t, for i ≤ la, j ≤ lb.
type HermiteE = [[[f64; MAX_PAIR_L + 1]; MAX_L as usize + 1]; MAX_L as usize + 1];

fn hermite_e(la: usize, lb: usize, xpa: f64, xpb: f64, p: f64) -> HermiteE {
    let mut e = [[[0.0; MAX_PAIR_L + 1]; MAX_L as usize + 1]; MAX_L as usize + 1];
    let h = 0.5 / p;
    e[0][0][0] = 1.0;
    for i in 0..=la {
        for j in 0..=lb {
            if i == 0 && j == 0 {
                continue;
            }
            let (from, x) = if i > 0 { (e[i - 1][j], xpa) } else { (e[i][j - 1], xpb) };
            for t in 0..=i + j {
                let mut v = x * from[t];
                if t > 0 {
                    v += h * from[t - 1];
                }
                if t < MAX_PAIR_L {
                    v += (t + 1) as f64 * from[t + 1];
                }
                e[i][j][t] = v;
            }
        }
    }
    e
}

/// Per-thread scratch of the R recursion.
#[derive(Default)]
pub struct Scratch {
    r: Vec<f64>,
    /// The same, eight points at a time.
    #[cfg(target_arch = "x86_64")]
    lanes: Vec<[f64; 8]>,
}

/// One step of the R recursion: r[dst] = X_axis · r[from] + weight · r[back].
#[derive(Clone, Copy)]
struct Step {
    dst: u16,
    from: u16,
    back: u16,
    axis: u8,
    weight: f64,
}

/// The R recursion of order l as a straight list of steps over a compact layout: level n holds
/// the (t, u, v) of [`triples`]`(l − n)`, levels one after the other, so R^0 comes first and in
/// the coefficients' order.
struct Recipe {
    /// Start of each level n.
    levels: Vec<usize>,
    steps: Vec<Step>,
    len: usize,
}

fn recipe(l: usize) -> &'static Recipe {
    static TABLE: std::sync::OnceLock<Vec<Recipe>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=MAX_PAIR_L.max(MULTIPOLE_ORDER))
            .map(|l| {
                let mut levels = Vec::with_capacity(l + 1);
                let mut index = std::collections::HashMap::new();
                let mut len = 0;
                for n in 0..=l {
                    levels.push(len);
                    for &tuv in &triples(l - n).tuv {
                        index.insert((n, tuv), len);
                        len += 1;
                    }
                }
                let at = |n: usize, tuv: [usize; 3]| index[&(n, tuv)] as u16;
                let mut steps = Vec::new();
                for k in 1..=l {
                    for n in 0..=l - k {
                        for &[t, u, v] in triples(k).tuv.iter().filter(|x| x.iter().sum::<usize>() == k) {
                            // Lower the first non-zero index: R^n_{..i..} = X R^{n+1}_{..i−1..} +
                            // (i − 1) R^{n+1}_{..i−2..}.
                            let (axis, i) = if t > 0 {
                                (0, t)
                            } else if u > 0 {
                                (1, u)
                            } else {
                                (2, v)
                            };
                            let lowered = |by: usize| {
                                let mut x = [t, u, v];
                                x[axis] -= by;
                                x
                            };
                            let from = at(n + 1, lowered(1));
                            let (back, weight) =
                                if i > 1 { (at(n + 1, lowered(2)), (i - 1) as f64) } else { (from, 0.0) };
                            steps.push(Step { dst: at(n, [t, u, v]), from, back, axis: axis as u8, weight });
                        }
                    }
                }
                Recipe { levels, steps, len }
            })
            .collect()
    });
    &table[l]
}

/// R^0_tuv(p, X) for every t + u + v ≤ l, written to `scratch.r[..]` in [`triples`]`(l)` order.
/// `far` takes the asymptotic Boys functions: the derivatives of √π/(2√p |X|), a point's.
fn hermite_r(l: usize, p: f64, x: DVec3, far: bool, scratch: &mut Scratch) {
    let recipe = recipe(l);
    let r = &mut scratch.r;
    if r.len() < recipe.len {
        r.resize(recipe.len, 0.0);
    }
    let mut f = [0.0; boys::MAX_N + 1];
    let t2 = p * x.length_squared();
    if far {
        boys::asymptotic(l, t2, &mut f);
    } else {
        boys(l, t2, &mut f);
    }
    let mut factor = 1.0;
    for (n, &start) in recipe.levels.iter().enumerate() {
        r[start] = factor * f[n];
        factor *= -2.0 * p;
    }
    let x = x.to_array();
    for s in &recipe.steps {
        r[s.dst as usize] = x[s.axis as usize] * r[s.from as usize] + s.weight * r[s.back as usize];
    }
}

/// Number of monomials x^a y^b z^c with a + b + c ≤ [`MULTIPOLE_ORDER`].
const FAR_TERMS: usize = (MULTIPOLE_ORDER + 1) * (MULTIPOLE_ORDER + 2) * (MULTIPOLE_ORDER + 3) / 6;

/// A group's far field Σ M_tuv ∂^{tuv} g(X), g = √π/(2|X|), X = A − C, in closed form.
///
/// ∂^{tuv}(1/r) = H_tuv(X)/r^{2n+1} with H_tuv homogeneous of degree n = t + u + v, so
/// H_tuv(X)/r^{2n+1} = H_tuv(Y)/r with Y = X/r² (Kelvin's inversion): the whole field is one
/// polynomial of degree [`MULTIPOLE_ORDER`] in Y over r, the same numbers as the R recursion
/// at a fraction of its cost (one Horner pass, no recursion per point).
struct FarField {
    /// Coefficients in [`horner_order`].
    coefficients: [f64; FAR_TERMS],
    /// [`MULTIPOLE_ORDER`], read at run time: loops over constant bounds this long unroll into
    /// more code than they save.
    order: usize,
}

/// The monomials (a, b, c) in the order [`FarField::at`] reads them: a, then b, then c falling.
fn horner_order() -> &'static [[usize; 3]] {
    static ORDER: std::sync::OnceLock<Vec<[usize; 3]>> = std::sync::OnceLock::new();
    ORDER.get_or_init(|| {
        let k = MULTIPOLE_ORDER;
        let mut out = Vec::with_capacity(FAR_TERMS);
        for a in (0..=k).rev() {
            for b in (0..=k - a).rev() {
                for c in (0..=k - a - b).rev() {
                    out.push([a, b, c]);
                }
            }
        }
        out
    })
}

/// H_tuv of every (t, u, v) of [`triples`]`(MULTIPOLE_ORDER)`, each over the monomials of a dense
/// (K+1)³ cube, from H_000 = 1 and ∂_i(H/r^{2n+1}) = (r² ∂_i H − (2n+1) X_i H)/r^{2n+3}.
fn inverse_distance_polynomials() -> &'static [Vec<f64>] {
    static TABLE: std::sync::OnceLock<Vec<Vec<f64>>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let s = MULTIPOLE_ORDER + 1;
        let index = |e: [usize; 3]| (e[0] * s + e[1]) * s + e[2];
        let order = &triples(MULTIPOLE_ORDER).tuv;
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(order.len());
        for (m, &tuv) in order.iter().enumerate() {
            let n: usize = tuv.iter().sum();
            if n == 0 {
                let mut h = vec![0.0; s * s * s];
                h[0] = 1.0;
                out.push(h);
                continue;
            }
            let axis = tuv.iter().position(|&i| i > 0).unwrap_or(0);
            let mut lowered = tuv;
            lowered[axis] -= 1;
            let from = &out[order[..m].iter().position(|&x| x == lowered).unwrap_or(0)];
            let mut h = vec![0.0; s * s * s];
            for e in triples(n - 1).tuv.iter().filter(|e| e.iter().sum::<usize>() == n - 1) {
                let c = from[index(*e)];
                if c == 0.0 {
                    continue;
                }
                // −(2n−1) X_i H.
                let mut up = *e;
                up[axis] += 1;
                h[index(up)] -= (2 * n - 1) as f64 * c;
                // r² ∂_i H.
                if e[axis] > 0 {
                    for j in 0..3 {
                        let mut d = *e;
                        d[axis] -= 1;
                        d[j] += 2;
                        h[index(d)] += e[axis] as f64 * c;
                    }
                }
            }
            out.push(h);
        }
        out
    })
}

/// Per monomial of [`horner_order`], the moments whose H_tuv holds it, with its coefficient, in
/// the moments' order. H_tuv is homogeneous of degree t + u + v, so a monomial meets only the
/// moments of its own degree: a level's far field sums 66 products at most per coefficient
/// rather than 286, with the same sum (the terms left out are zeros).
fn far_terms() -> &'static [Vec<(u16, f64)>] {
    static TABLE: std::sync::OnceLock<Vec<Vec<(u16, f64)>>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let s = MULTIPOLE_ORDER + 1;
        let polynomials = inverse_distance_polynomials();
        horner_order()
            .iter()
            .map(|e| {
                let at = (e[0] * s + e[1]) * s + e[2];
                polynomials.iter().enumerate().filter(|(_, h)| h[at] != 0.0).map(|(m, h)| (m as u16, h[at])).collect()
            })
            .collect()
    })
}

impl FarField {
    /// From moments M_tuv in [`triples`]`(MULTIPOLE_ORDER)` order.
    fn new(moments: &[f64]) -> Self {
        let mut coefficients = [0.0; FAR_TERMS];
        let half_sqrt_pi = 0.5 * std::f64::consts::PI.sqrt();
        for (c, terms) in coefficients.iter_mut().zip(far_terms()) {
            *c = half_sqrt_pi * terms.iter().map(|&(m, h)| moments[m as usize] * h).sum::<f64>();
        }
        Self { coefficients, order: MULTIPOLE_ORDER }
    }

    /// The field at X = A − C.
    #[inline]
    fn at(&self, x: DVec3) -> f64 {
        let r2 = x.length_squared();
        let y = x / r2;
        let mut rest = &self.coefficients[..];
        let mut px = 0.0;
        for a in (0..=self.order).rev() {
            let mut py = 0.0;
            for b in (0..=self.order - a).rev() {
                let (row, tail) = rest.split_at(self.order - a - b + 1);
                rest = tail;
                py = py * y.y + row.iter().fold(0.0, |sum, &c| sum * y.z + c);
            }
            px = px * y.x + py;
        }
        px / r2.sqrt()
    }
}

/// The charges of a molecule, ready to give the potential anywhere.
pub struct Potential {
    nuclei: Vec<(DVec3, f64)>,
    /// Per pair, per (t, u, v) of [`triples`]: −(2π/p) Σ_μν P_μν E_t E_u E_v (the electrons'
    /// share of the potential of Λ_tuv).
    coefficients: Vec<f64>,
    anchors: Vec<Anchor>,
}

/// The primitive pairs whose centre lies nearest one shell centre, and their far field about it.
///
/// Each pair has an activation distance: from there on (distance of the point from the
/// anchor) the pair is a point multipole to within a tenth of [`FAR_FIELD_ERROR`] — its Boys
/// functions are their asymptotic form — and that multipole moved to the anchor and cut at
/// order [`MULTIPOLE_ORDER`] is within the same bound. Pairs are sorted by that distance; each
/// level holds the summed moments of the pairs active from its radius on, so a point takes one
/// multipole per anchor and the exact sum over the pairs not yet active.
struct Anchor {
    center: DVec3,
    /// Its pairs, by activation distance (the exact sums walk them in order).
    pairs: Vec<HermitePair>,
    levels: Vec<Level>,
}

struct Level {
    radius: f64,
    /// The first `count` pairs of the anchor are active from `radius` on.
    count: usize,
    /// Their far field as a polynomial in Y = (A − C)/|A − C|² (see [`FarField`]).
    field: FarField,
}

/// Radii of the levels: from 0.2 bohr, each 5 % further (a pair waits at most that long past its
/// activation distance; a level costs memory only, a point reads one per anchor).
fn level_radius(j: usize) -> f64 {
    0.2 * 1.05f64.powi(j as i32)
}

impl Potential {
    /// The potential of `molecule`'s nuclei (their charges as the file gives them: core charges
    /// where the file has pseudopotentials) and `wf`'s electrons.
    pub fn new(molecule: &Molecule, wf: &Wavefunction) -> Self {
        let nuclei =
            molecule.atoms.iter().filter(|a| !a.ghost && a.charge != 0.0).map(|a| (a.position, a.charge)).collect();
        let basis = PreparedBasis::with_threshold(&wf.basis, 0.0);
        let density = density_matrix(wf);
        let n = basis.n_functions();
        let shells = &basis.shells;
        let blocks: Vec<(Vec<HermitePair>, Vec<f64>)> = (0..shells.len())
            .into_par_iter()
            .map(|ia| {
                let (mut pairs, mut coefficients) = (Vec::new(), Vec::new());
                for ib in 0..=ia {
                    let weight = if ia == ib { 1.0 } else { 2.0 };
                    let block = cartesian_block(&basis, &shells[ia], &shells[ib], &density, n, weight);
                    shell_pair(&basis, &shells[ia], &shells[ib], &block, &mut pairs, &mut coefficients);
                }
                (pairs, coefficients)
            })
            .collect();
        let mut out = Self { nuclei, coefficients: Vec::new(), anchors: Vec::new() };
        let mut pairs = Vec::new();
        for (block, coefficients) in blocks {
            let base = out.coefficients.len();
            pairs.extend(block.into_iter().map(|p| HermitePair { first: p.first + base, ..p }));
            out.coefficients.extend(coefficients);
        }
        let centres: Vec<DVec3> = {
            let mut c: Vec<DVec3> = shells.iter().map(super::gto::PreparedShell::center).collect();
            c.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap_or(std::cmp::Ordering::Equal));
            c.dedup();
            c
        };
        out.anchors = out.anchors(&pairs, &centres);
        out
    }

    /// Groups `pairs` by nearest centre and sums their far fields level by level.
    fn anchors(&self, pairs: &[HermitePair], centres: &[DVec3]) -> Vec<Anchor> {
        let mut members: Vec<Vec<(f64, &HermitePair)>> = vec![Vec::new(); centres.len()];
        // Errors of different pairs differ in sign and size: a tenth of the bound each keeps the
        // sum well inside it (measured: tests/esp.rs).
        let budget = FAR_FIELD_ERROR / 10.0;
        for pair in pairs {
            let Some((a, centre)) = centres
                .iter()
                .enumerate()
                .min_by(|x, y| x.1.distance_squared(pair.center).total_cmp(&y.1.distance_squared(pair.center)))
            else {
                continue;
            };
            // A pair never far enough (infinite radius) stays out of every level and is summed
            // exactly at every point, as the last of its anchor's list.
            members[a].push((self.activation(pair, pair.center.distance(*centre), budget), pair));
        }
        centres
            .par_iter()
            .zip(members)
            .map(|(&center, mut list)| {
                list.sort_by(|a, b| a.0.total_cmp(&b.0));
                let order = triples(MULTIPOLE_ORDER);
                let mut levels: Vec<Level> = Vec::new();
                let mut moments = vec![0.0; order.tuv.len()];
                let mut count = 0;
                let mut j = 0;
                while count < list.len() && list[count].0.is_finite() {
                    let radius = level_radius(j);
                    let before = count;
                    while count < list.len() && list[count].0 <= radius {
                        self.add_moments(list[count].1, center, &mut moments);
                        count += 1;
                    }
                    if count > before {
                        levels.push(Level { radius, count, field: FarField::new(&moments) });
                    }
                    j += 1;
                }
                Anchor { center, pairs: list.into_iter().map(|(_, pair)| *pair).collect(), levels }
            })
            .collect()
    }

    /// The distance from the anchor (at `offset` from the pair's centre) beyond which a pair is
    /// its multipole about the anchor to within `budget`.
    fn activation(&self, pair: &HermitePair, offset: f64, budget: f64) -> f64 {
        let c = &self.coefficients[pair.first..pair.first + triples(pair.l).tuv.len()];
        // Size of the pair's moments: Σ|c|/√p bounds each order's strength.
        let size = c.iter().map(|v| v.abs()).sum::<f64>() / pair.p.sqrt();
        if size == 0.0 {
            return 0.0;
        }
        if pair.l > MULTIPOLE_ORDER {
            // Moments above the expansion's order would be lost: summed exactly everywhere.
            return f64::INFINITY;
        }
        let l = pair.l as i32;
        let k = (MULTIPOLE_ORDER + 1 - pair.l) as i32;
        // |∂ⁿ(1/r)| ≤ n!/r^{n+1}: the first term left out, of order K + 1, weighs (K+1)!/(K+1−L)!
        // more than its δ-power says.
        let weight: f64 = ((MULTIPOLE_ORDER + 2 - pair.l)..=MULTIPOLE_ORDER + 1).map(|n| n as f64).product();
        let error = |d: f64| {
            let r = d - offset;
            // The asymptotic Boys functions hold to e^{−T}(1 + 2T)^L relative at T = p r²
            // (F_0: erfc(√T) ≤ e^{−T}); moving the multipole to the anchor and cutting it at
            // order K leaves (δ/r)^{K+1−L} / r^{L+1}.
            let t = pair.p * r * r;
            size * ((-t).exp() * (1.0 + 2.0 * t).powi(l) / r + weight * (offset / r).powi(k) / r.powi(l + 1))
        };
        let mut d = (1.5 * offset).max(offset + 0.05);
        while error(d) > budget {
            d *= 1.03;
            if d > 1e4 {
                return f64::INFINITY;
            }
        }
        d
    }

    /// Adds `pair`'s moments about `anchor` (order ≤ [`MULTIPOLE_ORDER`]) to `moments`.
    fn add_moments(&self, pair: &HermitePair, anchor: DVec3, moments: &mut [f64]) {
        let own = triples(pair.l);
        let order = triples(MULTIPOLE_ORDER);
        let delta = pair.center - anchor;
        let scale = 1.0 / pair.p.sqrt();
        // δ^n / n! per axis.
        let powers = |x: f64| {
            let mut out = [0.0; MULTIPOLE_ORDER + 1];
            out[0] = 1.0;
            for n in 1..=MULTIPOLE_ORDER {
                out[n] = out[n - 1] * x / n as f64;
            }
            out
        };
        let (px, py, pz) = (powers(delta.x), powers(delta.y), powers(delta.z));
        for (&[t, u, v], c) in own.tuv.iter().zip(&self.coefficients[pair.first..]) {
            if t + u + v > MULTIPOLE_ORDER {
                continue;
            }
            let c = c * scale;
            for (m, &[a, b, e]) in order.tuv.iter().enumerate() {
                if a >= t && b >= u && e >= v {
                    moments[m] += c * px[a - t] * py[b - u] * pz[e - v];
                }
            }
        }
    }

    /// The total charge the potential describes (nuclei minus electrons), from the Hermite
    /// coefficients: only Λ_000 carries charge, (π/p)^{3/2} each.
    pub fn total_charge(&self) -> f64 {
        let nuclear: f64 = self.nuclei.iter().map(|n| n.1).sum();
        let electronic: f64 =
            self.pairs().map(|pair| self.coefficients[pair.first] * (std::f64::consts::PI / pair.p).sqrt() / 2.0).sum();
        nuclear + electronic
    }

    /// The potential (hartree per unit charge, a.u.) at `point` (bohr): far fields where they
    /// hold, every pair exactly elsewhere.
    pub fn at(&self, point: DVec3, scratch: &mut Scratch) -> f64 {
        let mut v = self.nuclear(point);
        for anchor in &self.anchors {
            let d = anchor.center.distance(point);
            let active = anchor.levels.partition_point(|l| l.radius <= d);
            let start = if active > 0 {
                let level = &anchor.levels[active - 1];
                v += level.field.at(anchor.center - point);
                level.count
            } else {
                0
            };
            for pair in &anchor.pairs[start..] {
                v += self.pair_at(pair, point, scratch);
            }
        }
        v
    }

    /// The potential at `point` with every pair summed exactly (no far fields): the reference
    /// the far fields are tested against.
    pub fn exact_at(&self, point: DVec3, scratch: &mut Scratch) -> f64 {
        self.nuclear(point) + self.pairs().map(|pair| self.pair_at(pair, point, scratch)).sum::<f64>()
    }

    /// Every primitive pair kept, anchor by anchor.
    fn pairs(&self) -> impl Iterator<Item = &HermitePair> {
        self.anchors.iter().flat_map(|a| &a.pairs)
    }

    fn nuclear(&self, point: DVec3) -> f64 {
        self.nuclei.iter().map(|&(r, q)| q / (point - r).length().max(NUCLEUS_CORE)).sum()
    }

    fn pair_at(&self, pair: &HermitePair, point: DVec3, scratch: &mut Scratch) -> f64 {
        let x = pair.center - point;
        let c = &self.coefficients[pair.first..];
        let t = pair.p * x.length_squared();
        match pair.l {
            0 => c[0] * boys::f0(t),
            // R^0_000 = F0, R^0_i = X_i a1 (a_n = (−2p)^n F_n).
            1 => {
                let mut f = [0.0; 2];
                boys(1, t, &mut f);
                let a1 = -2.0 * pair.p * f[1];
                c[0] * f[0] + a1 * (c[1] * x.x + c[2] * x.y + c[3] * x.z)
            }
            // R^0_ii = a1 + X_i² a2, R^0_ij = X_i X_j a2; coefficients in [`triples`] order:
            // 000, 100, 010, 001, 200, 110, 101, 020, 011, 002.
            2 => {
                let mut f = [0.0; 3];
                boys(2, t, &mut f);
                let m2p = -2.0 * pair.p;
                let (a1, a2) = (m2p * f[1], m2p * m2p * f[2]);
                c[0] * f[0]
                    + a1 * (c[1] * x.x + c[2] * x.y + c[3] * x.z + c[4] + c[7] + c[9])
                    + a2 * (c[4] * x.x * x.x
                        + c[5] * x.x * x.y
                        + c[6] * x.x * x.z
                        + c[7] * x.y * x.y
                        + c[8] * x.y * x.z
                        + c[9] * x.z * x.z)
            }
            l => {
                hermite_r(l, pair.p, x, false, scratch);
                let n = triples(l).tuv.len();
                scratch.r[..n].iter().zip(c).map(|(r, ck)| ck * r).sum()
            }
        }
    }

    /// The potential at each of `points`, in parallel.
    pub fn at_points(&self, points: &[DVec3]) -> Vec<f64> {
        let mut out = vec![0.0; points.len()];
        out.par_chunks_mut(8).zip(points.par_chunks(8)).for_each_init(Scratch::default, |s, (values, chunk)| {
            self.at_neighbours(chunk, values, s);
        });
        out
    }

    /// The potential at up to eight points, near each other for speed (a grid row's, a list's
    /// neighbours): eight at a time where the CPU has AVX-512 ([`lanes`]), with the same bits.
    fn at_neighbours(&self, points: &[DVec3], values: &mut [f64], scratch: &mut Scratch) {
        #[cfg(target_arch = "x86_64")]
        if lanes::available() && !points.is_empty() {
            // A short group repeats its last point in the spare lanes.
            let group: [DVec3; lanes::LANES] = std::array::from_fn(|l| points[l.min(points.len() - 1)]);
            // SAFETY: `available` checked the CPU's features.
            let all = unsafe { self.at_lanes(&group, scratch) };
            values.copy_from_slice(&all[..values.len()]);
            return;
        }
        for (v, &p) in values.iter_mut().zip(points) {
            *v = self.at(p, scratch);
        }
    }

    /// The potential on a grid, in the grid's point order.
    pub fn on_grid(&self, grid: &GridSpec) -> Vec<f64> {
        let [nx, ny, nz] = grid.dims;
        let mut out = vec![0.0; nx * ny * nz];
        out.par_chunks_mut(nz.max(1)).enumerate().for_each_init(Scratch::default, |s, (row, values)| {
            let (i, j) = (row / ny, row % ny);
            let mut points = [DVec3::ZERO; 8];
            for (group, chunk) in values.chunks_mut(8).enumerate() {
                for (l, p) in points.iter_mut().enumerate().take(chunk.len()) {
                    *p = grid.point(i, j, group * 8 + l);
                }
                self.at_neighbours(&points[..chunk.len()], chunk, s);
            }
        });
        out
    }
}

/// Σ_i occ_i c_i c_iᵀ over the occupied orbitals of both spins, row-major n × n.
pub fn density_matrix(wf: &Wavefunction) -> Vec<f64> {
    let n = wf.basis.n_functions();
    let occupied: Vec<(&[f64], f64)> = wf
        .orbitals
        .iter()
        .filter(|o| o.occupation != 0.0)
        .map(|o| (&o.coefficients[..o.coefficients.len().min(n)], o.occupation))
        .collect();
    let mut p = vec![0.0; n * n];
    p.par_chunks_mut(n.max(1)).enumerate().for_each(|(i, row)| {
        for (c, occ) in &occupied {
            let Some(&ci) = c.get(i) else { continue };
            let w = occ * ci;
            if w != 0.0 {
                for (r, cj) in row.iter_mut().zip(c.iter()) {
                    *r += w * cj;
                }
            }
        }
    });
    p
}

/// The density matrix block of shells a, b on their cartesian components, × `weight`, each
/// component carrying its normalisation factor: fa ⊙ (T_aᵀ P_ab T_b) ⊙ fb.
fn cartesian_block(
    basis: &PreparedBasis,
    a: &PreparedShell,
    b: &PreparedShell,
    density: &[f64],
    n: usize,
    weight: f64,
) -> Vec<f64> {
    let (la, lb) = (a.l as usize, b.l as usize);
    let (na, nb) = (basis.powers[la].len(), basis.powers[lb].len());
    let (fa, fb) = (a.functions(), b.functions());
    let p = |i: usize, j: usize| density[(fa.start + i) * n + fb.start + j] * weight;
    // Rows: P T_b on the right (or P itself).
    let mut right = vec![0.0; fa.len() * nb];
    for i in 0..fa.len() {
        for v in 0..nb {
            right[i * nb + v] = if b.pure {
                let t = &basis.pure_matrices[lb];
                (0..fb.len()).map(|k| p(i, k) * t[k * nb + v]).sum()
            } else {
                p(i, v)
            };
        }
    }
    let mut out = vec![0.0; na * nb];
    for u in 0..na {
        for v in 0..nb {
            let value: f64 = if a.pure {
                let t = &basis.pure_matrices[la];
                (0..fa.len()).map(|k| t[k * na + u] * right[k * nb + v]).sum()
            } else {
                right[u * nb + v]
            };
            out[u * nb + v] = value * basis.component_factors[la][u] * basis.component_factors[lb][v];
        }
    }
    out
}

/// Appends the Hermite pairs of shells a, b contracted with the cartesian density block.
fn shell_pair(
    basis: &PreparedBasis,
    a: &PreparedShell,
    b: &PreparedShell,
    block: &[f64],
    pairs: &mut Vec<HermitePair>,
    coefficients: &mut Vec<f64>,
) {
    let (la, lb) = (a.l as usize, b.l as usize);
    let (pa, pb) = (&basis.powers[la], &basis.powers[lb]);
    let nb = pb.len();
    let largest = block.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if largest == 0.0 {
        return;
    }
    let l = la + lb;
    let s = l + 1;
    let triples = triples(l);
    let (ca, cb) = (a.center(), b.center());
    let r2 = (ca - cb).length_squared();
    let mut dense = vec![0.0; s * s * s];
    for i in a.primitives() {
        let (alpha, wa) = (basis.exponents[i], basis.coefficients[i]);
        for j in b.primitives() {
            let (beta, wb) = (basis.exponents[j], basis.coefficients[j]);
            let p = alpha + beta;
            let k = wa * wb * (-alpha * beta / p * r2).exp();
            if (k * largest).abs() * (std::f64::consts::PI / p).powf(1.5) < PAIR_SCREEN {
                continue;
            }
            let center = (alpha * ca + beta * cb) / p;
            let (xa, xb) = (center - ca, center - cb);
            let ex = hermite_e(la, lb, xa.x, xb.x, p);
            let ey = hermite_e(la, lb, xa.y, xb.y, p);
            let ez = hermite_e(la, lb, xa.z, xb.z, p);
            dense.iter_mut().for_each(|d| *d = 0.0);
            for (u, pu) in pa.iter().enumerate() {
                for (v, pv) in pb.iter().enumerate() {
                    let w = k * block[u * nb + v];
                    if w == 0.0 {
                        continue;
                    }
                    let (x, y, z) = (
                        &ex[pu[0] as usize][pv[0] as usize],
                        &ey[pu[1] as usize][pv[1] as usize],
                        &ez[pu[2] as usize][pv[2] as usize],
                    );
                    for (t, xt) in x.iter().enumerate().take((pu[0] + pv[0]) as usize + 1) {
                        let wx = w * xt;
                        for (q, yq) in y.iter().enumerate().take((pu[1] + pv[1]) as usize + 1) {
                            let wxy = wx * yq;
                            let row = (t * s + q) * s;
                            for (r, zr) in z.iter().enumerate().take((pu[2] + pv[2]) as usize + 1) {
                                dense[row + r] += wxy * zr;
                            }
                        }
                    }
                }
            }
            let scale = -2.0 * std::f64::consts::PI / p;
            pairs.push(HermitePair { center, p, l, first: coefficients.len() });
            coefficients.extend(triples.cube.iter().map(|&c| dense[c] * scale));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_e_at_t0_is_the_overlap_factor() {
        // ∫ (x−A)^i (x−B)^j exp(−p(x−P)²) dx / √(π/p) by quadrature against E^{ij}_0.
        let (alpha, beta, a, b) = (0.7, 1.3, -0.4, 0.9);
        let p = alpha + beta;
        let centre = (alpha * a + beta * b) / p;
        let e = hermite_e(5, 5, centre - a, centre - b, p);
        for (i, row) in e.iter().enumerate() {
            for (j, cell) in row.iter().enumerate() {
                let steps = 40_000;
                let (lo, hi) = (centre - 12.0, centre + 12.0);
                let h = (hi - lo) / steps as f64;
                let f = |x: f64| (x - a).powi(i as i32) * (x - b).powi(j as i32) * (-p * (x - centre).powi(2)).exp();
                let sum: f64 = (0..steps).map(|k| f(lo + (k as f64 + 0.5) * h)).sum::<f64>() * h;
                let want = sum / (std::f64::consts::PI / p).sqrt();
                assert!((cell[0] - want).abs() < 1e-9 * want.abs().max(1.0), "E^{i}{j}_0 {} vs {want}", cell[0]);
            }
        }
    }

    #[test]
    fn far_r_recursion_gives_derivatives_of_the_inverse_distance() {
        // R_tuv with asymptotic Boys at p: ∂^t_x ∂^u_y ∂^v_z of √π/(2√p|X|), checked by finite
        // differences of the closed form for a few low orders.
        let p = 2.0;
        let x = DVec3::new(1.3, -0.7, 2.1);
        let f = |x: DVec3| 0.5 * (std::f64::consts::PI / p).sqrt() / x.length();
        let mut s = Scratch::default();
        hermite_r(2, p, x, true, &mut s);
        let at = |t: usize, u: usize, v: usize| s.r[triples(2).tuv.iter().position(|x| *x == [t, u, v]).unwrap()];
        let h = 1e-4;
        let dx = (f(x + DVec3::X * h) - f(x - DVec3::X * h)) / (2.0 * h);
        let dxy = (f(x + DVec3::new(h, h, 0.0)) - f(x + DVec3::new(h, -h, 0.0)) - f(x + DVec3::new(-h, h, 0.0))
            + f(x + DVec3::new(-h, -h, 0.0)))
            / (4.0 * h * h);
        let dzz = (f(x + DVec3::Z * h) - 2.0 * f(x) + f(x - DVec3::Z * h)) / (h * h);
        assert!((at(0, 0, 0) - f(x)).abs() < 1e-14);
        assert!((at(1, 0, 0) - dx).abs() < 1e-8, "{} {dx}", at(1, 0, 0));
        assert!((at(1, 1, 0) - dxy).abs() < 1e-6, "{} {dxy}", at(1, 1, 0));
        assert!((at(0, 0, 2) - dzz).abs() < 1e-6, "{} {dzz}", at(0, 0, 2));
    }

    #[test]
    fn far_field_polynomial_equals_the_r_recursion() {
        // The Kelvin-inverted polynomial and the asymptotic R recursion are the same sum.
        let n = triples(MULTIPOLE_ORDER).tuv.len();
        let moments: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 5.0) / (1 + i % 7) as f64).collect();
        let field = FarField::new(&moments);
        let mut s = Scratch::default();
        for x in [DVec3::new(3.1, -2.2, 4.7), DVec3::new(-0.4, 6.0, 0.3), DVec3::new(9.0, 8.0, -7.0)] {
            hermite_r(MULTIPOLE_ORDER, 1.0, x, true, &mut s);
            let want: f64 = s.r.iter().zip(&moments).map(|(r, m)| r * m).sum();
            let got = field.at(x);
            assert!((got - want).abs() <= 1e-12 * want.abs().max(1e-3), "{got} vs {want} at {x}");
        }
    }
}
