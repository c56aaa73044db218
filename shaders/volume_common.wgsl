// Slice-based volume rendering, shared part: slice polygons in world space, and the opacity law
// that turns a value into premultiplied colour (seed 000's emission–absorption clouds). The
// fragment shaders that sample a value are in volume_slices.wgsl (a 3D texture) and
// volume_direct.wgsl (the orbital evaluated from its basis functions, seed 004).

struct VolumeUniforms {
    clip_from_world: mat4x4<f32>,
    tex_from_world: mat4x4<f32>,
    // xyz: eye position (bohr)
    eye: vec4<f32>,
    // xyz: unit normal of the slice planes, w: distance between planes (bohr)
    plane: vec4<f32>,
    positive_color: vec4<f32>,
    negative_color: vec4<f32>,
    // x: k1, y: k2, z: 1 / max|value|, w: reference step (bohr) the opacity k1 refers to
    params: vec4<f32>,
    // x: 1 for a signed field (orbital), 0 for a density
    flags: vec4<u32>,
    // x: the smallest |value| / max|value| that can be seen at these k1, k2
    flags_f: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: VolumeUniforms;
@group(0) @binding(1) var volume: texture_3d<f32>;
@group(0) @binding(2) var volume_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // Both are affine in the world position, so interpolation gives them exactly per fragment.
    @location(0) uvw: vec3<f32>,
    @location(1) from_eye: vec3<f32>,
    @location(2) world: vec3<f32>,
};

@vertex
fn vs_main(@location(0) world: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(world, 1.0);
    out.uvw = (u.tex_from_world * vec4<f32>(world, 1.0)).xyz;
    out.from_eye = world - u.eye.xyz;
    out.world = world;
    return out;
}

// Premultiplied colour of one sample; alpha < 0 means invisible (the caller discards, which
// skips the frame buffer's read-modify-write).
fn shade(value: f32, from_eye: vec3<f32>) -> vec4<f32> {
    let scaled = value * u.params.z;
    // Below this magnitude a sample is invisible (computed on the CPU from k1, k2).
    if (abs(scaled) < u.flags_f.x) {
        return vec4<f32>(-1.0);
    }
    var shaped: f32;
    var color: vec3<f32>;
    if (u.flags.x == 1u) {
        // rho = psi^2, so rho^k2 = |psi|^(2 k2).
        shaped = pow(abs(scaled), 2.0 * u.params.y);
        color = select(u.negative_color.rgb, u.positive_color.rgb, value >= 0.0);
    } else {
        shaped = pow(scaled, u.params.y);
        color = mix(u.negative_color.rgb, u.positive_color.rgb, sqrt(min(scaled, 1.0)));
    }
    // k1 * rho^k2 is the opacity of one reference step (seed 000's alpha), taken as an extinction
    // so it composes exactly over the distance the ray travels between two slices:
    // alpha = 1 - exp(-k1 rho^k2 * path / step).
    let ray = normalize(from_eye);
    let path = u.plane.w / max(abs(dot(ray, u.plane.xyz)), 0.05);
    let x = u.params.x * shaped * path / u.params.w;
    // 1 − e^−x loses its digits to cancellation for small x: use the series there.
    let alpha = select(1.0 - exp2(-1.442695 * x), x * (1.0 - x * (0.5 - x / 6.0)), x < 0.03);
    return vec4<f32>(color * alpha, alpha);
}

