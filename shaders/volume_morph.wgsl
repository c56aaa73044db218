// Naka et al.'s interpolation between two key volumes A and B on one grid, θ between their
// angles with ratio k = u.morph_k (`volume` is A).
//
// exact: the two volumes sampled and mixed per sample. α-mix: the two samples' colours and
// opacities mixed per slice (Naka et al.'s reference). three-pass: Naka et al.'s real-time
// approximation, the attenuation by one key volume's opacity, drawn in one pass (`plane_over`).
// Prepended: volume_common.wgsl, volume_gradient.wgsl, volume_slab.wgsl.

@group(1) @binding(0) var volume_b: texture_3d<f32>;
// A's and B's texels classified once for the transfer function (volume_classify.wgsl), as
// Naka et al.'s key volumes are stored as coloured translucent textures: α-mix and three-pass
// mix the two key volumes' colours and opacities, which do not depend on k, so a drag reads
// them instead of classifying two samples each time.
@group(1) @binding(1) var classified_a: texture_3d<f32>;
@group(1) @binding(2) var classified_b: texture_3d<f32>;

// Whether α-mix and three-pass read the classified textures (a pipeline constant; not where
// the transfer function needs the gradient, whose lighting depends on the view).
override CLASSIFIED: bool = false;

// The weights of A and B the next sample takes (set by `shade_mix`).
var<private> weights: vec2<f32>;

// weights.x·A + weights.y·B at uvw, sampling only what is weighted.
fn field(uvw: vec3<f32>) -> f32 {
    var v = 0.0;
    if (weights.x != 0.0) {
        v += weights.x * textureSampleLevel(volume, volume_sampler, uvw, 0.0).r;
    }
    if (weights.y != 0.0) {
        v += weights.y * textureSampleLevel(volume_b, volume_sampler, uvw, 0.0).r;
    }
    return v;
}

// Premultiplied colour of the mix w at uvw (alpha < 0: invisible); `c`: the uniforms.
fn shade_mix(c: VolumeUniforms, uvw: vec3<f32>, from_eye: vec3<f32>, w: vec2<f32>) -> vec4<f32> {
    weights = w;
    var grad = vec3<f32>(0.0);
    if (needs_gradient()) {
        grad = field_gradient(uvw);
    }
    return shade_with(c, FIELD, SHAPED, GRADIENT, field(uvw), grad, from_eye);
}

// The premultiplied colour of a classified texture's sample at uvw; `steps`: the reference
// steps between two planes along this ray.
fn classified_sample(c: VolumeUniforms, t: texture_3d<f32>, uvw: vec3<f32>, steps: f32) -> vec4<f32> {
    let e = textureSampleLevel(t, volume_sampler, uvw, 0.0).xy;
    // An orbital's extinction carries the sign that picks its colour; a density's colour is y.
    let hue = select(e.y, select(0.0, 1.0, e.x >= 0.0), FIELD == 1u);
    let alpha = opacity(abs(e.x) * steps);
    return vec4<f32>(mix(c.negative_color.rgb, c.positive_color.rgb, hue) * alpha, alpha);
}

// The premultiplied colours of A's and B's samples at uvw, each alone (an invisible sample
// counts as clear).
fn samples(c: VolumeUniforms, uvw: vec3<f32>, from_eye: vec3<f32>, steps: f32) -> array<vec4<f32>, 2> {
    if (CLASSIFIED) {
        return array<vec4<f32>, 2>(classified_sample(c, classified_a, uvw, steps), classified_sample(c, classified_b, uvw, steps));
    }
    let a = shade_mix(c, uvw, from_eye, vec2<f32>(1.0, 0.0));
    let b = shade_mix(c, uvw, from_eye, vec2<f32>(0.0, 1.0));
    return array<vec4<f32>, 2>(max(a, vec4<f32>(0.0)), max(b, vec4<f32>(0.0)));
}

// How the two key volumes are mixed: 0 exact, 1 α-mix, 2 three-pass (a pipeline constant).
override MIX: u32 = 0u;

// The colour and opacity a plane's slice blends "over" what lies behind it, at uvw:
//
// exact: the two volumes sampled and mixed, ψ = (1−k)ψA + kψB, then shaded.
//
// α-mix, Naka et al.'s reference (their eq. 5): the colours and opacities mixed, α = (1−k)α_A +
// kα_B, d_i = (1−k)C_A α_A + k C_B α_B + d_{i−1}(1 − α).
//
// three-pass, Naka et al.'s method (their eqs. 6–7): the frame attenuated by A_i's opacity (B_i's
// when k > 0.5), then (1−k)·A_i and k·B_i added. The three blends of a slice are one
// premultiplied "over" whose colour is the two additions and whose opacity the attenuation's,
// so one pass draws them: d_i = (1−k)C_A α_A + k C_B α_B + d_{i−1}(1 − α_{A|B}).
fn plane_over(c: VolumeUniforms, uvw: vec3<f32>, from_eye: vec3<f32>, steps: f32) -> vec4<f32> {
    let k = c.morph_k;
    if (MIX == 0u) {
        return max(shade_mix(c, uvw, from_eye, vec2<f32>(1.0 - k, k)), vec4<f32>(0.0));
    }
    let s = samples(c, uvw, from_eye, steps);
    let m = (1.0 - k) * s[0] + k * s[1];
    if (MIX == 1u) {
        return m;
    }
    return vec4<f32>(m.rgb, select(s[0].a, s[1].a, k > 0.5));
}

// A slab of planes per fragment (volume_slab.wgsl), each plane's "over" composed front to back.
@fragment
fn fs_morph(in: SlabOut) -> @location(0) vec4<f32> {
    // Read once: handed by value to the functions called per sample.
    let c = u;
    let taken = slab_samples(in);
    // The ray's direction, and so the path between planes, is the fragment's.
    let steps = path_steps(c.plane, c.ref_step, in.from_eye);
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < SLAB; j += 1u) {
        let over = plane_over(c, in.uvw + in.step_uvw * f32(j), in.from_eye, steps);
        acc = behind(acc, over.rgb, over.a, slab_takes(in, taken, j));
    }
    // Nothing to add: no read-modify-write of the frame buffer.
    if (all(acc == vec4<f32>(0.0))) {
        discard;
    }
    return acc;
}
