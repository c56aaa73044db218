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
};

@group(0) @binding(0) var<uniform> u: VolumeUniforms;
@group(0) @binding(1) var volume: texture_3d<f32>;
@group(0) @binding(2) var volume_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

@vertex
fn vs_main(@location(0) world: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

// Opacity per reference step: alpha = k1 * rho^k2, rho normalised to [0, 1].
fn unit_opacity(rho: f32) -> f32 {
    if (rho <= 0.0) {
        return 0.0;
    }
    return clamp(u.params.x * pow(rho, u.params.y), 0.0, 1.0);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let uvw = (u.tex_from_world * vec4<f32>(in.world, 1.0)).xyz;
    let value = textureSampleLevel(volume, volume_sampler, uvw, 0.0).r;
    let scaled = value * u.params.z;
    var rho: f32;
    var color: vec3<f32>;
    if (u.flags.x == 1u) {
        rho = scaled * scaled;
        color = select(u.negative_color.rgb, u.positive_color.rgb, value >= 0.0);
    } else {
        rho = max(scaled, 0.0);
        color = mix(u.negative_color.rgb, u.positive_color.rgb, sqrt(min(rho, 1.0)));
    }
    let a_unit = unit_opacity(rho);
    // The ray crosses the gap between two planes over spacing / |cos|: correct alpha for that length.
    let ray = normalize(in.world - u.eye.xyz);
    let path = u.plane.w / max(abs(dot(ray, u.plane.xyz)), 0.05);
    let alpha = 1.0 - pow(1.0 - min(a_unit, 0.9999), path / u.params.w);
    return vec4<f32>(color * alpha, alpha);
}
