// Slice-based volume rendering: each slice polygon samples the 3D grid texture and
// composites back to front with premultiplied alpha (seed 000's emission–absorption clouds).

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
};

@vertex
fn vs_main(@location(0) world: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(world, 1.0);
    out.uvw = (u.tex_from_world * vec4<f32>(world, 1.0)).xyz;
    out.from_eye = world - u.eye.xyz;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let value = textureSampleLevel(volume, volume_sampler, in.uvw, 0.0).r;
    let scaled = value * u.params.z;
    // Below this magnitude a sample is invisible (computed on the CPU from k1, k2): skip the
    // transcendental functions and the frame buffer's read-modify-write.
    if (abs(scaled) < u.flags_f.x) {
        discard;
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
    let ray = normalize(in.from_eye);
    let path = u.plane.w / max(abs(dot(ray, u.plane.xyz)), 0.05);
    let x = u.params.x * shaped * path / u.params.w;
    // 1 − e^−x loses its digits to cancellation for small x: use the series there.
    let alpha = select(1.0 - exp2(-1.442695 * x), x * (1.0 - x * (0.5 - x / 6.0)), x < 0.03);
    return vec4<f32>(color * alpha, alpha);
}
