// Per-pixel fragment lists of translucent surfaces (Koide and Miyata, docs/references.md): every fragment of every
// translucent surface is kept, with what its optics need, in a linked list per pixel. The
// lists are sorted and composited in exact depth order when the frame resolves.

struct FragmentNode {
    // Window depth (0 near, 1 far).
    depth: f32,
    // N·V (low half) and N·L (high half), f16.
    cosines: u32,
    // R·V (low half, f16) and the surface's index in the frame (high half).
    highlight_surface: u32,
    // Index + 1 of the next node of the pixel's list; 0 ends it.
    next: u32,
};

struct ListInfo {
    // Pixels per row of the heads.
    width: u32,
    // Nodes the buffer holds; fragments past it are counted, not stored.
    capacity: u32,
    // Translucent surfaces this frame.
    surfaces: u32,
    _pad: u32,
};

fn node_surface(node: FragmentNode) -> u32 {
    return node.highlight_surface >> 16u;
}

// One translucent surface's coefficients (scene::translucency::Optics), per RGB.
struct SurfaceOptics {
    // rgb: diffuse a; w: the specular exponent n.
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
    f: vec4<f32>,
    g: vec4<f32>,
    glow_d: vec4<f32>,
    glow_f: vec4<f32>,
    glow_g: vec4<f32>,
    // xy: the surfaces of the same object (bits); a surface glows inside any other.
    same_object: vec4<u32>,
};

struct Shaded {
    luminance: vec3<f32>,
    transmission: vec3<f32>,
};

const MIN_N_DOT_V: f32 = 0.01;

// Koide and Miyata: I = S{a N·L + [b/(1 + c N·V)](R·V)ⁿ} + d/(1 + f|N·V|), t = exp(−g/|N·V|), with
// S = 0 where N·L < 0 or N·V < 0; d, f, g switch to the glow's inside another object's surface
// (scene::translucency::Optics::shade is the CPU reference).
fn koide(o: SurfaceOptics, n_dot_l: f32, n_dot_v: f32, r_dot_v: f32, glow: bool) -> Shaded {
    let d = select(o.d.rgb, o.glow_d.rgb, glow);
    let f = select(o.f.rgb, o.glow_f.rgb, glow);
    let g = select(o.g.rgb, o.glow_g.rgb, glow);
    let cos_v = max(abs(n_dot_v), MIN_N_DOT_V);
    var luminance = d / (1.0 + f * cos_v);
    if (n_dot_l > 0.0 && n_dot_v > 0.0) {
        let highlight = pow(max(r_dot_v, 0.0), o.a.w);
        luminance += o.a.rgb * n_dot_l + o.b.rgb / (1.0 + o.c.rgb * n_dot_v) * highlight;
    }
    return Shaded(luminance, exp(-g / cos_v));
}
