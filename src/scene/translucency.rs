//! Koide and Miyata's optical model of translucent isosurfaces (docs/references.md), and the CPU reference
//! of its exact-order composition that the GPU's fragment lists are checked against.
//!
//! A surface fragment with outward normal N, seen along V (towards the eye) and lit from L,
//! shines I = S{a N·L + [b/(1 + c N·V)](R·V)ⁿ} + d/(1 + f|N·V|) and lets t = exp(−g/|N·V|) of
//! what lies behind it through (S = 0 where N·L < 0 or N·V < 0). Back to front,
//! B₍ₙ₋₁₎ = Iₙ + tₙ·Bₙ: no (1 − t) factor on I. Every coefficient is per RGB channel.
//!
//! Where the ray runs inside a surface of another object (the HOMO of one molecule meeting the
//! LUMO of another, Koide and Miyata's collision), a surface's d, f, g switch to its glow values, so
//! the overlap glows.

use serde::{Deserialize, Serialize};

/// One surface's coefficients, each per R, G, B.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Optics {
    /// Diffuse.
    pub a: [f32; 3],
    /// Specular, and its view weighting c and exponent n.
    pub b: [f32; 3],
    pub c: [f32; 3],
    pub n: f32,
    /// Emission d/(1 + f|N·V|) of the thin layer the surface stands for.
    pub d: [f32; 3],
    pub f: [f32; 3],
    /// Transmission exp(−g/|N·V|).
    pub g: [f32; 3],
    /// d, f, g where the surface lies inside a surface of another object.
    pub glow_d: [f32; 3],
    pub glow_f: [f32; 3],
    pub glow_g: [f32; 3],
}

/// Looks of translucent surfaces, each made from the surface's colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum OpticsPreset {
    /// Koide and Miyata's pictures: tinted glass with a soft emitting rim; overlaps glow warm.
    #[default]
    Koide,
    /// Clear glass: strong highlights, little emission, very transparent.
    Glassy,
    /// Smoke: mostly emission and absorption, hardly any highlight.
    Smoke,
}

impl OpticsPreset {
    pub const ALL: [OpticsPreset; 3] = [OpticsPreset::Koide, OpticsPreset::Glassy, OpticsPreset::Smoke];

    pub fn label(self) -> &'static str {
        match self {
            OpticsPreset::Koide => "tinted glass",
            OpticsPreset::Glassy => "glassy",
            OpticsPreset::Smoke => "smoke",
        }
    }

    /// The coefficients of a surface of linear RGB `color`.
    pub fn optics(self, color: [f32; 3]) -> Optics {
        let scale = |k: f32| color.map(|c| k * c);
        let flat = |k: f32| [k; 3];
        // A surface absorbs more of what it does not reflect, so what it lets through is tinted
        // its own colour.
        let tinted = |g: f32, extra: f32| color.map(|c| g + extra * (1.0 - c));
        // Overlaps glow a warm white, brighter than either surface.
        let glow_d = [0.8, 0.62, 0.28];
        match self {
            OpticsPreset::Koide => Optics {
                a: scale(0.45),
                b: flat(0.55),
                c: flat(0.5),
                n: 24.0,
                d: scale(0.3),
                f: flat(2.0),
                g: tinted(0.2, 0.25),
                glow_d,
                glow_f: flat(0.6),
                glow_g: flat(0.12),
            },
            OpticsPreset::Glassy => Optics {
                a: scale(0.2),
                b: flat(0.9),
                c: flat(0.2),
                n: 60.0,
                d: scale(0.08),
                f: flat(6.0),
                g: tinted(0.06, 0.15),
                glow_d,
                glow_f: flat(1.0),
                glow_g: flat(0.08),
            },
            OpticsPreset::Smoke => Optics {
                a: scale(0.12),
                b: flat(0.05),
                c: flat(1.0),
                n: 8.0,
                d: scale(0.55),
                f: flat(0.8),
                g: tinted(0.45, 0.3),
                glow_d,
                glow_f: flat(0.4),
                glow_g: flat(0.3),
            },
        }
    }
}

/// Per-channel factors on a preset's coefficients (all 1: the preset as it is): how a surface's
/// a, b, c, n, d, f, g and glow are edited per R, G, B while staying tied to its colour.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct OpticsTuning(pub Optics);

impl Default for OpticsTuning {
    fn default() -> Self {
        let one = [1.0; 3];
        Self(Optics { a: one, b: one, c: one, n: 1.0, d: one, f: one, g: one, glow_d: one, glow_f: one, glow_g: one })
    }
}

impl OpticsTuning {
    /// The coefficients' names, as the command line and the editor give them.
    pub const NAMES: [&'static str; 10] = ["a", "b", "c", "n", "d", "f", "g", "glow_d", "glow_f", "glow_g"];

    /// The factors of coefficient `name` (`n` has one), or `None` for no such name.
    pub fn factors_mut(&mut self, name: &str) -> Option<&mut [f32]> {
        let o = &mut self.0;
        Some(match name {
            "a" => &mut o.a,
            "b" => &mut o.b,
            "c" => &mut o.c,
            "n" => std::slice::from_mut(&mut o.n),
            "d" => &mut o.d,
            "f" => &mut o.f,
            "g" => &mut o.g,
            "glow_d" => &mut o.glow_d,
            "glow_f" => &mut o.glow_f,
            "glow_g" => &mut o.glow_g,
            _ => return None,
        })
    }

    /// `optics` with every coefficient multiplied by its factors.
    pub fn apply(&self, o: Optics) -> Optics {
        let k = &self.0;
        let mul = |v: [f32; 3], k: [f32; 3]| std::array::from_fn(|i| v[i] * k[i].max(0.0));
        Optics {
            a: mul(o.a, k.a),
            b: mul(o.b, k.b),
            c: mul(o.c, k.c),
            n: o.n * k.n.max(0.0),
            d: mul(o.d, k.d),
            f: mul(o.f, k.f),
            g: mul(o.g, k.g),
            glow_d: mul(o.glow_d, k.glow_d),
            glow_f: mul(o.glow_f, k.glow_f),
            glow_g: mul(o.glow_g, k.glow_g),
        }
    }
}

/// How one isosurface mesh is drawn: opaque in a colour, or translucent with Koide and Miyata's optics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceLook {
    /// Linear RGB (of the opaque surface; a translucent one's optics were made from it).
    pub color: [f32; 3],
    pub optics: Option<Optics>,
    /// Lee et al.'s level of detail for an opaque closed surface: parts that look smaller than
    /// this many pixels are drawn as points ([`crate::model::octree`]); `None`: every triangle.
    pub lod_px: Option<f32>,
}

impl From<[f32; 3]> for SurfaceLook {
    fn from(color: [f32; 3]) -> Self {
        Self { color, optics: None, lod_px: None }
    }
}

/// |N·V| below this counts as this (a fragment seen exactly edge-on is opaque, not infinite).
pub const MIN_N_DOT_V: f32 = 1e-2;

impl Optics {
    /// Luminance I and transmission t of one fragment; `glow`: it lies inside a surface of
    /// another object.
    pub fn shade(&self, n_dot_l: f32, n_dot_v: f32, r_dot_v: f32, glow: bool) -> ([f32; 3], [f32; 3]) {
        let lit = n_dot_l > 0.0 && n_dot_v > 0.0;
        let (d, f, g) = if glow { (self.glow_d, self.glow_f, self.glow_g) } else { (self.d, self.f, self.g) };
        let cos_v = n_dot_v.abs().max(MIN_N_DOT_V);
        let highlight = r_dot_v.max(0.0).powf(self.n);
        let mut i = [0.0; 3];
        let mut t = [0.0; 3];
        for k in 0..3 {
            let surface =
                if lit { self.a[k] * n_dot_l + self.b[k] / (1.0 + self.c[k] * n_dot_v) * highlight } else { 0.0 };
            i[k] = surface + d[k] / (1.0 + f[k] * cos_v);
            t[k] = (-g[k] / cos_v).exp();
        }
        (i, t)
    }
}

/// One translucent surface of a frame: its coefficients and the object it belongs to (a
/// surface glows only inside another object's surfaces, so nested shells of one density do
/// not).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TranslucentSurface {
    pub optics: Optics,
    pub object: u32,
}

/// Most translucent surfaces one frame composites (the walk keeps one inside bit per surface).
pub const MAX_TRANSLUCENT_SURFACES: usize = 64;

/// One surface fragment in a pixel: what the GPU's fragment list holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Window depth (0 near, 1 far).
    pub depth: f32,
    /// Index into the frame's [`TranslucentSurface`]s.
    pub surface: u32,
    pub n_dot_v: f32,
    pub n_dot_l: f32,
    pub r_dot_v: f32,
}

/// Front-to-back order: by depth, ties by surface, so every input order gives one result.
pub fn sort_fragments(fragments: &mut [Fragment]) {
    fragments.sort_by(|p, q| p.depth.total_cmp(&q.depth).then(p.surface.cmp(&q.surface)));
}

/// The colour of a pixel whose opaque scene (atoms, clouds, background) is `behind`, seen
/// through `fragments` (sorted front to back, [`sort_fragments`]).
pub fn composite(fragments: &[Fragment], surfaces: &[TranslucentSurface], behind: [f32; 3]) -> [f32; 3] {
    let mut walk = Walk::new(fragments);
    for frag in fragments {
        walk.fragment(frag, surfaces);
    }
    walk.finish(behind)
}

/// A ray walked front to back through sorted fragments (and, between them, a cloud's samples).
///
/// A front face (N·V > 0) enters its surface and a back face leaves it; a surface whose first
/// fragment is a back face encloses the eye. A fragment glows where the ray is inside a
/// surface of another object.
#[derive(Debug, Clone, Copy)]
pub struct Walk {
    color: [f32; 3],
    through: [f32; 3],
    inside: u64,
}

impl Walk {
    /// A walk over `fragments` (sorted front to back): which surfaces enclose the eye.
    pub fn new(fragments: &[Fragment]) -> Self {
        let mut seen = 0u64;
        let mut inside = 0u64;
        for frag in fragments {
            let bit = 1u64 << (frag.surface % 64);
            if seen & bit == 0 {
                seen |= bit;
                if frag.n_dot_v < 0.0 {
                    inside |= bit;
                }
            }
        }
        Self { color: [0.0; 3], through: [1.0; 3], inside }
    }

    /// Composites the next fragment behind what the walk holds.
    pub fn fragment(&mut self, frag: &Fragment, surfaces: &[TranslucentSurface]) {
        let Some(s) = surfaces.get(frag.surface as usize) else { return };
        let glow =
            surfaces.iter().enumerate().take(64).any(|(k, o)| self.inside & (1 << k) != 0 && o.object != s.object);
        let (i, t) = s.optics.shade(frag.n_dot_l, frag.n_dot_v, frag.r_dot_v, glow);
        self.add(i, t);
        let bit = 1u64 << (frag.surface % 64);
        if frag.n_dot_v > 0.0 { self.inside |= bit } else { self.inside &= !bit }
    }

    /// Composites a cloud sample of colour `color` and opacity `alpha` behind what the walk
    /// holds (Naka et al.'s emission–absorption, premultiplied).
    pub fn sample(&mut self, color: [f32; 3], alpha: f32) {
        self.add(color.map(|c| c * alpha), [1.0 - alpha; 3]);
    }

    /// B = I + t·B, seen from the front: light `i` dimmed by all in front, then `t` dims
    /// everything behind.
    fn add(&mut self, i: [f32; 3], t: [f32; 3]) {
        self.color = std::array::from_fn(|k| self.color[k] + self.through[k] * i[k]);
        self.through = std::array::from_fn(|k| self.through[k] * t[k]);
    }

    /// The pixel: what was composited, over `behind`.
    pub fn finish(self, behind: [f32; 3]) -> [f32; 3] {
        std::array::from_fn(|k| self.color[k] + self.through[k] * behind[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frag(depth: f32, surface: u32, n_dot_v: f32) -> Fragment {
        Fragment { depth, surface, n_dot_v, n_dot_l: 0.5, r_dot_v: 0.2 }
    }

    #[test]
    fn one_layer_is_seed_003s_formula() {
        let o = OpticsPreset::Koide.optics([0.8, 0.2, 0.1]);
        let (i, t) = o.shade(0.6, 0.5, 0.9, false);
        for k in 0..3 {
            let expected =
                o.a[k] * 0.6 + o.b[k] / (1.0 + o.c[k] * 0.5) * 0.9f32.powf(o.n) + o.d[k] / (1.0 + o.f[k] * 0.5);
            assert!((i[k] - expected).abs() < 1e-6);
            assert!((t[k] - (-o.g[k] / 0.5).exp()).abs() < 1e-6);
        }
        // Unlit from behind: emission only; grazing: thicker.
        let (back, t_back) = o.shade(0.6, -0.5, 0.9, false);
        assert!((back[0] - o.d[0] / (1.0 + o.f[0] * 0.5)).abs() < 1e-6);
        assert_eq!(t_back, t);
        assert!(o.shade(0.6, 0.1, 0.9, false).1[0] < t[0]);
    }

    #[test]
    fn composition_is_back_to_front_without_a_one_minus_t_factor() {
        let s = TranslucentSurface { optics: OpticsPreset::Smoke.optics([0.5, 0.5, 0.5]), object: 0 };
        let frags = [frag(0.2, 0, 0.8), frag(0.4, 0, -0.8)];
        let behind = [0.3, 0.6, 0.9];
        let (i1, t1) = s.optics.shade(0.5, 0.8, 0.2, false);
        let (i2, t2) = s.optics.shade(0.5, -0.8, 0.2, false);
        let got = composite(&frags, &[s], behind);
        for k in 0..3 {
            let b1 = i2[k] + t2[k] * behind[k];
            assert!((got[k] - (i1[k] + t1[k] * b1)).abs() < 1e-6);
        }
    }

    #[test]
    fn glow_only_inside_another_objects_surface() {
        let a = TranslucentSurface { optics: OpticsPreset::Koide.optics([0.9, 0.1, 0.1]), object: 0 };
        let b = TranslucentSurface { optics: OpticsPreset::Koide.optics([0.1, 0.1, 0.9]), object: 1 };
        let nested = TranslucentSurface { object: 0, ..b };
        // The ray enters b, then a (inside b), leaves a, leaves b.
        let frags = [frag(0.1, 1, 0.7), frag(0.2, 0, 0.7), frag(0.3, 0, -0.7), frag(0.4, 1, -0.7)];
        let crossing = composite(&frags, &[a, b], [0.0; 3]);
        let shells = composite(&frags, &[a, nested], [0.0; 3]);
        assert!(crossing[0] > shells[0] + 0.05, "{crossing:?} vs {shells:?}");
        // Apart, the same surfaces do not glow: swapping which object b is changes nothing.
        let apart = [frag(0.1, 1, 0.7), frag(0.2, 1, -0.7), frag(0.3, 0, 0.7), frag(0.4, 0, -0.7)];
        assert_eq!(composite(&apart, &[a, b], [0.0; 3]), composite(&apart, &[a, nested], [0.0; 3]));
    }

    #[test]
    fn an_eye_inside_a_surface_starts_inside_it() {
        let a = TranslucentSurface { optics: OpticsPreset::Koide.optics([0.9, 0.1, 0.1]), object: 0 };
        let b = TranslucentSurface { optics: OpticsPreset::Koide.optics([0.1, 0.1, 0.9]), object: 1 };
        // b's one fragment is unlit either way; facing away, b encloses the eye and a glows.
        let b_at = |n_dot_v| Fragment { depth: 0.5, surface: 1, n_dot_v, n_dot_l: -1.0, r_dot_v: 0.0 };
        let enclosed = composite(&[frag(0.2, 0, 0.7), frag(0.3, 0, -0.7), b_at(-0.7)], &[a, b], [0.0; 3]);
        let apart = composite(&[frag(0.2, 0, 0.7), frag(0.3, 0, -0.7), b_at(0.7)], &[a, b], [0.0; 3]);
        assert!(enclosed[1] > apart[1] + 0.1, "{enclosed:?} vs {apart:?}");
    }

    #[test]
    fn tuning_scales_each_channel_of_a_preset() {
        let preset = OpticsPreset::Glassy.optics([0.2, 0.5, 0.9]);
        let mut tuning = OpticsTuning::default();
        assert_eq!(tuning.apply(preset), preset);
        tuning.factors_mut("g").unwrap().copy_from_slice(&[2.0, 1.0, 0.5]);
        tuning.factors_mut("n").unwrap()[0] = 0.5;
        let tuned = tuning.apply(preset);
        assert_eq!(tuned.g, [2.0 * preset.g[0], preset.g[1], 0.5 * preset.g[2]]);
        assert_eq!(tuned.n, 0.5 * preset.n);
        assert_eq!((tuned.a, tuned.glow_d), (preset.a, preset.glow_d));
        assert!(tuning.factors_mut("x").is_none());
        assert!(OpticsTuning::NAMES.iter().all(|n| tuning.factors_mut(n).is_some()));
    }

    #[test]
    fn sorting_makes_the_input_order_irrelevant() {
        let a = TranslucentSurface { optics: OpticsPreset::Glassy.optics([0.9, 0.6, 0.1]), object: 0 };
        let b = TranslucentSurface { optics: OpticsPreset::Koide.optics([0.1, 0.6, 0.9]), object: 1 };
        let mut frags = vec![frag(0.4, 1, -0.3), frag(0.1, 1, 0.9), frag(0.3, 0, -0.6), frag(0.2, 0, 0.6)];
        let mut reversed = frags.clone();
        reversed.reverse();
        sort_fragments(&mut frags);
        sort_fragments(&mut reversed);
        assert_eq!(composite(&frags, &[a, b], [0.1; 3]), composite(&reversed, &[a, b], [0.1; 3]));
    }
}
