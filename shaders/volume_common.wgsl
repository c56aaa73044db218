// Slice-based volume rendering, shared part: slice polygons in world space, and the opacity law
// that turns a value into premultiplied colour (Naka et al.'s emission–absorption clouds). The
// fragment shaders that sample a value are in volume_slices.wgsl (a 3D texture) and
// volume_direct.wgsl (the orbital evaluated from its basis functions, Jang and Varetto).

struct VolumeUniforms {
    clip_from_world: mat4x4<f32>,
    tex_from_world: mat4x4<f32>,
    // xyz: eye position (bohr)
    eye: vec4<f32>,
    // xyz: unit normal of the slice planes, w: distance between planes (bohr)
    plane: vec4<f32>,
    positive_color: vec4<f32>,
    negative_color: vec4<f32>,
    // Opacity k1·ρ^k2 per `ref_step` (bohr) of travel, ρ scaled by `inv_max` = 1 / max|value|.
    k1: f32,
    k2: f32,
    inv_max: f32,
    ref_step: f32,
    // 1 for a signed field (an orbital), 0 for a density scaled to its maximum, 2 for a density
    // on a log scale.
    signed_field: u32,
    // Shapes of the positive and negative lobes (the power law, the gradient and clipping are
    // pipeline overrides).
    shape_positive: u32,
    shape_negative: u32,
    // TF_* bits: shading from the gradient, and (read where a walk takes several clouds, which
    // one pipeline's overrides cannot tell apart) the gradient, a shaped function, clipping.
    tf_bits: u32,
    // The smallest scaled |value| that can be seen at these k1, k2.
    visible_min: f32,
    // A scan frame's mix ratio k between its key volumes A and B.
    morph_k: f32,
    // A density on a log scale (signed_field 2): t = (log10 ρ − log_lo) · inv_log_span.
    log_lo: f32,
    inv_log_span: f32,
    // centre, width, peak opacity (fractions of max|value|), unused
    tf_positive: vec4<f32>,
    tf_negative: vec4<f32>,
    // The 2D transfer function's gradient power, boundary enhancement, and 1 / max|∇value|.
    gradient_power: f32,
    boundary: f32,
    inv_max_grad: f32,
    // Grid cells per brick edge (the walk's shown-bricks texture, volume_interleave.wgsl).
    brick_cells: f32,
    // xyz: unit normal, w: offset; fragments with n·p > offset are cut away
    clip: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // Where translucent surfaces go through the cloud (volume_interleave.wgsl): the inverse of
    // clip_from_world, the slices' box mapped to the unit cube, and x: the nearest plane's
    // distance along `plane`, y: the number of planes, zw: the frame's size in pixels.
    world_from_clip: mat4x4<f32>,
    box_from_world: mat4x4<f32>,
    slab: vec4<f32>,
};

const TF_SHADING: u32 = 1u;
const TF_GRADIENT: u32 = 2u;
const TF_SHAPED: u32 = 4u;
const TF_CLIP: u32 = 8u;

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
    return slice_vertex(world);
}

// A slice's vertex at `world` (shared by the vertex stages that add to it).
fn slice_vertex(world: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(world, 1.0);
    out.uvw = (u.tex_from_world * vec4<f32>(world, 1.0)).xyz;
    out.from_eye = world - u.eye.xyz;
    out.world = world;
    return out;
}

fn gaussian(x: f32) -> f32 {
    return exp(-x * x);
}

// Jang and Varetto's shapes on the signed value s = value / max|value|, placed at the signed centre c;
// `outward` (±1) is the sign of the values the lobe colours. See scene::transfer::Shape::at.
fn shape_factor(shape: u32, s: f32, c: f32, w_in: f32, outward: f32) -> f32 {
    let w = max(w_in, 1e-4);
    let bell = gaussian((s - c) / w);
    switch shape {
        case 0u: { return select(0.0, 1.0, abs(s - c) <= 0.5 * w); }
        case 1u: { return bell; }
        // The halves of the bell left and right of its peak; nothing on the other side.
        case 2u: { return select(0.0, bell, s <= c); }
        case 3u: { return select(0.0, bell, s >= c); }
        default: {
            let contours = pow(0.5 + 0.5 * cos(6.2831853 * (s - c) / w), 8.0);
            return select(contours, 0.0, (s - c) * outward < -0.5 * w);
        }
    }
}

fn clipped(world: vec3<f32>) -> bool {
    return CLIP && dot(u.clip.xyz, world) > u.clip.w;
}

// Specialised per pipeline (overrides, not uniforms): a branch on a uniform still costs the
// untaken side on a CPU rasteriser, and the gradient is six extra samples.
override GRADIENT: bool = false;
override SHAPED: bool = false;
override CLIP: bool = false;

fn needs_gradient() -> bool {
    return GRADIENT;
}

// The value as the transfer function sees it: ψ / max|ψ| (sign kept), ρ / max ρ, or log ρ
// between the bounds (scene::opacity::DensityScale::t is the CPU reference); `field` is
// `signed_field`, or a constant equal to it where one pipeline draws one cloud.
fn transfer_value(c: VolumeUniforms, field: u32, value: f32) -> f32 {
    if (field == 2u) {
        if (value <= 0.0) {
            return 0.0;
        }
        return clamp((log2(value) * 0.30103 - c.log_lo) * c.inv_log_span, 0.0, 1.0);
    }
    return value * c.inv_max;
}

// Premultiplied colour of one sample with gradient `grad` (world units; ignored unless the
// transfer function needs it); alpha < 0 means invisible (the caller discards, which skips the
// frame buffer's read-modify-write).
fn shade(value: f32, grad: vec3<f32>, from_eye: vec3<f32>) -> vec4<f32> {
    return shade_with(u, u.signed_field, SHAPED, needs_gradient(), value, grad, from_eye);
}

// What the transfer function makes of a value, without the gradient: x its extinction per
// reference step (negative: invisible), y where its colour lies from the negative colour (0) to
// the positive (1). The three-pass and α-mix programs keep this per texel of a key volume
// (volume_classify.wgsl), so y is set for invisible values too: a visible sample beside them
// keeps its lobe's colour.
fn classify(c: VolumeUniforms, field: u32, shaped: bool, value: f32) -> vec2<f32> {
    let scaled = transfer_value(c, field, value);
    if (!shaped) {
        var extinction: f32;
        var hue: f32;
        if (field == 1u) {
            // rho = psi^2, so rho^k2 = |psi|^(2 k2).
            extinction = c.k1 * pow(abs(scaled), 2.0 * c.k2);
            hue = select(0.0, 1.0, value >= 0.0);
        } else {
            extinction = c.k1 * pow(max(scaled, 0.0), c.k2);
            hue = sqrt(min(scaled, 1.0));
        }
        // Below this magnitude a sample is invisible (computed on the CPU from k1, k2).
        return vec2<f32>(select(extinction, -1.0, abs(scaled) < c.visible_min), hue);
    }
    let positive = value >= 0.0 || field != 1u;
    let lobe = select(c.tf_negative, c.tf_positive, positive);
    let shape = select(c.shape_negative, c.shape_positive, positive);
    let sign = select(-1.0, 1.0, positive);
    let extinction = lobe.z * shape_factor(shape, scaled, sign * lobe.x, lobe.y, sign);
    return vec2<f32>(select(extinction, -1.0, extinction < 1e-5), select(0.0, 1.0, positive));
}

// Reference steps the ray travels between two planes (`plane`: their unit normal and spacing),
// the factor of a sample's extinction in its opacity.
fn path_steps(plane: vec4<f32>, ref_step: f32, from_eye: vec3<f32>) -> f32 {
    let ray = normalize(from_eye);
    return plane.w / max(abs(dot(ray, plane.xyz)), 0.05) / ref_step;
}

// The opacity of extinction x (one reference step's, times the steps travelled): the
// extinction of one step composes exactly over the path, alpha = 1 − e^−x (Naka et al.'s
// alpha = k1 rho^k2 for one step of the power law).
fn opacity(x: f32) -> f32 {
    // 1 − e^−x loses its digits to cancellation for small x: use the series there.
    return select(1.0 - exp2(-1.442695 * x), x * (1.0 - x * (0.5 - x / 6.0)), x < 0.03);
}

// `shade` for the cloud `c` describes: `field` is its `signed_field`, `shaped` and `gradient`
// say which transfer function it uses (constants where one pipeline draws one cloud, which
// settle the branches on them when the pipeline is built; values where a walk takes several).
// The rest is kept in one piece: split into several calls that each take `c`, a walk ran 1.5
// times as long on a CPU rasteriser (a copy of the struct per call and sample); the one call
// to `classify` costs nothing measurable (`bench render`, `bench scene`).
fn shade_with(c: VolumeUniforms, field: u32, shaped: bool, gradient: bool, value: f32, grad: vec3<f32>, from_eye: vec3<f32>) -> vec4<f32> {
    let classified = classify(c, field, shaped, value);
    if (classified.x < 0.0) {
        return vec4<f32>(-1.0);
    }
    var extinction = classified.x;
    var color = mix(c.negative_color.rgb, c.positive_color.rgb, classified.y);
    if (gradient) {
        let g = min(length(grad) * c.inv_max_grad, 1.0);
        if (c.gradient_power > 0.0) {
            extinction *= pow(g, c.gradient_power);
        }
        extinction *= 1.0 - c.boundary + c.boundary * sqrt(g);
        if ((c.tf_bits & TF_SHADING) != 0u && length(grad) > 0.0) {
            // Two-sided lighting: a translucent shell is seen from both sides.
            let n = normalize(grad);
            let v = -normalize(from_eye);
            let l = c.light.xyz;
            let diffuse = abs(dot(n, l));
            let h = normalize(l + v);
            let specular = pow(abs(dot(n, h)), 32.0);
            color = color * (0.3 + 0.7 * diffuse) + vec3<f32>(0.35 * specular);
        }
    }
    let alpha = opacity(extinction * path_steps(c.plane, c.ref_step, from_eye));
    return vec4<f32>(color * alpha, alpha);
}
