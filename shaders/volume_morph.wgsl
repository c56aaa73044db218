// Seed 000's interpolation between two key volumes A and B on one grid, θ between their
// angles with ratio k = u.morph_k (`volume` is A).
//
// exact (fs_exact): the two volumes sampled and mixed per sample, ψ = (1−k)ψA + kψB, then one
// premultiplied "over" blend.
// α-mix (fs_alpha_mix): the two samples' colours and opacities mixed per slice (seed 000's
// reference). three-pass (fs_three_pass): seed 000's real-time approximation, the attenuation
// by one key volume's opacity; drawn in one pass (see there).
// Prepended: volume_common.wgsl, volume_gradient.wgsl.

@group(1) @binding(0) var volume_b: texture_3d<f32>;

// The weights of A and B this fragment samples (set first by each entry point).
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

// Premultiplied colour of the mix w at this fragment (alpha < 0: invisible).
fn shade_mix(in: VertexOut, w: vec2<f32>) -> vec4<f32> {
    weights = w;
    var grad = vec3<f32>(0.0);
    if (needs_gradient()) {
        grad = field_gradient(in.uvw);
    }
    return shade(field(in.uvw), grad, in.from_eye);
}

fn k() -> f32 {
    return u.morph_k;
}

@fragment
fn fs_exact(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    let c = shade_mix(in, vec2<f32>(1.0 - k(), k()));
    if (c.a < 0.0) {
        discard;
    }
    return c;
}

// The premultiplied colours of A's and B's samples at this fragment, each alone (an invisible
// sample counts as clear).
fn samples(in: VertexOut) -> array<vec4<f32>, 2> {
    let a = shade_mix(in, vec2<f32>(1.0, 0.0));
    let b = shade_mix(in, vec2<f32>(0.0, 1.0));
    return array<vec4<f32>, 2>(max(a, vec4<f32>(0.0)), max(b, vec4<f32>(0.0)));
}

// Seed 000's reference (their eq. 5): per slice the colours and opacities mixed, α = (1−k)α_A +
// kα_B, then one premultiplied "over": d_i = (1−k)C_A α_A + k C_B α_B + d_{i−1}(1 − α).
@fragment
fn fs_alpha_mix(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    let s = samples(in);
    let c = (1.0 - k()) * s[0] + k() * s[1];
    if (c.a <= 0.0) {
        discard;
    }
    return c;
}

// Seed 000's three-pass method (their eqs. 6–7): per slice the frame is attenuated by A_i's
// opacity (B_i's when k > 0.5), then (1−k)·A_i and k·B_i are added. The three blends of a slice
// are one premultiplied "over" whose colour is the two additions and whose opacity is the
// attenuation's, so one pass draws them: d_i = (1−k)C_A α_A + k C_B α_B + d_{i−1}(1 − α_{A|B}).
@fragment
fn fs_three_pass(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    let s = samples(in);
    let rgb = (1.0 - k()) * s[0].rgb + k() * s[1].rgb;
    let attenuation = select(s[0].a, s[1].a, k() > 0.5);
    if (attenuation <= 0.0 && all(rgb <= vec3<f32>(0.0))) {
        discard;
    }
    return vec4<f32>(rgb, attenuation);
}
