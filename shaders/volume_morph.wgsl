// Seed 000's interpolation between two key volumes A and B on one grid, θ between their
// angles with ratio k = u.morph_k (`volume` is A).
//
// exact (fs_exact): the two volumes sampled and mixed per sample, ψ = (1−k)ψA + kψB, then one
// premultiplied "over" blend.
// three-pass (fs_attenuate, fs_add_a, fs_add_b, drawn in turn for every slice through blend
// states): d_i = d_{i−1}(1 − A_i) + (1−k)A_i + kB_i, with B_i in the attenuation when k > 0.5.
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

// Pass 1, blend dst·(1 − src.a): attenuation by A_i (B_i when k > 0.5).
@fragment
fn fs_attenuate(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    let c = shade_mix(in, select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), k() > 0.5));
    if (c.a <= 0.0) {
        discard;
    }
    return vec4<f32>(0.0, 0.0, 0.0, c.a);
}

// Pass 2, additive: (1−k)·A_i.
@fragment
fn fs_add_a(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world) || k() >= 1.0) {
        discard;
    }
    let c = shade_mix(in, vec2<f32>(1.0, 0.0));
    if (c.a <= 0.0) {
        discard;
    }
    return c * (1.0 - k());
}

// Pass 3, additive: k·B_i.
@fragment
fn fs_add_b(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world) || k() <= 0.0) {
        discard;
    }
    let c = shade_mix(in, vec2<f32>(0.0, 1.0));
    if (c.a <= 0.0) {
        discard;
    }
    return c * k();
}
