// Slabs: the planes of a cloud's slices taken SLAB at a time. A slab's polygon lies on its
// front plane and covers every pixel whose ray meets one of its planes' slices; the fragment
// follows its pixel's ray through the slab's planes, composites their samples front to back,
// and the slabs are blended back to front. Each sample is the one a slice of its own plane
// takes at that pixel, so the picture is the slices'; what a slab saves is each fragment's
// fixed cost (rasterising, interpolating, blending), paid once per SLAB samples. The programs
// that sample a texture (volume_slices.wgsl, volume_morph.wgsl) loop over `slab_samples`.
// Prepended: volume_common.wgsl.

// Planes per slab (1: one slice per plane, where slabs cannot be cut: the eye among the planes).
override SLAB: u32 = 1u;
// The cloud's `signed_field`, as a constant: what its transfer function does to a value is then
// known when the pipeline is built.
override FIELD: u32 = 1u;

// The opaque scene's depth: a slab's samples behind it are hidden (the depth test only sees
// the front plane's).
@group(2) @binding(0) var scene_depth: texture_depth_2d;

// A slab's sample this far outside its box (a fraction of its edge) still counts, for rounding:
// more would add samples a slice's polygon leaves out, which a sharp transfer function shows.
const BOX_SLACK: f32 = 1e-6;

// What a slab's fragment needs beyond `VertexOut`, constant over its polygon (one plane).
struct SlabOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uvw: vec3<f32>,
    @location(1) from_eye: vec3<f32>,
    @location(2) world: vec3<f32>,
    // x: the plane's index from the front, y: its depth n·p in spacings, z: spacing / n·(p − eye),
    // so the step from one plane to the next along the ray through p is z·(p − eye).
    @location(3) @interpolate(flat) plane: vec3<f32>,
    // The opaque scene's point at pixel (x, y) and window depth d lies at n·p = (depth_n·v) /
    // (depth_w·v) spacings, v = (x, y, d, 1): world_from_clip's rows, after the map from pixels
    // to normalised device coordinates.
    @location(4) @interpolate(flat) depth_n: vec4<f32>,
    @location(5) @interpolate(flat) depth_w: vec4<f32>,
    // The step between planes in texture coordinates, and the position and step in the box's
    // (0..1 inside): all affine in p over one plane, so interpolated exactly.
    @location(6) step_uvw: vec3<f32>,
    @location(7) box: vec3<f32>,
    @location(8) step_box: vec3<f32>,
};

// Per vertex, what would otherwise cost every fragment its divisions and matrix products.
@vertex
fn vs_slab(@location(0) world: vec3<f32>) -> SlabOut {
    let slice = slice_vertex(world);
    var out: SlabOut;
    out.clip = slice.clip;
    out.uvw = slice.uvw;
    out.from_eye = slice.from_eye;
    out.world = world;
    let n = u.plane.xyz;
    let depth = dot(n, world);
    let along = max(dot(out.from_eye, n), 1e-6);
    out.plane = vec3<f32>(round((depth - u.slab.x) / u.plane.w), depth / u.plane.w, u.plane.w / along);
    // ndc = (2x / width − 1, 1 − 2y / height).
    let from_pixels = mat4x4<f32>(
        vec4<f32>(2.0 / u.slab.z, 0.0, 0.0, 0.0),
        vec4<f32>(0.0, -2.0 / u.slab.w, 0.0, 0.0),
        vec4<f32>(0.0, 0.0, 1.0, 0.0),
        vec4<f32>(-1.0, 1.0, 0.0, 1.0),
    );
    let m = u.world_from_clip * from_pixels;
    out.depth_n = vec4<f32>(dot(n, m[0].xyz), dot(n, m[1].xyz), dot(n, m[2].xyz), dot(n, m[3].xyz)) / u.plane.w;
    out.depth_w = vec4<f32>(m[0].w, m[1].w, m[2].w, m[3].w);
    let step = out.from_eye * out.plane.z;
    out.step_uvw = (u.tex_from_world * vec4<f32>(step, 0.0)).xyz;
    out.box = (u.box_from_world * vec4<f32>(world, 1.0)).xyz;
    out.step_box = (u.box_from_world * vec4<f32>(step, 0.0)).xyz;
    return out;
}

// Which of the slab's samples j this ray takes, j in [x, y]: inside the box, not past the
// cloud's last plane, nor behind the opaque scene.
fn slab_samples(in: SlabOut) -> vec2<f32> {
    var last = min(f32(SLAB), u.slab.y - in.plane.x) - 0.5;
    if (SLAB > 1u) {
        let opaque = textureLoad(scene_depth, vec2<i32>(in.clip.xy), 0);
        let v = vec4<f32>(in.clip.xy, opaque, 1.0);
        let hidden = dot(in.depth_n, v) / dot(in.depth_w, v);
        // The front plane passed the depth test itself.
        last = min(last, max(hidden - in.plane.y - 1e-3, 0.0));
    }
    // Where the ray is in the box: the box coordinates are affine in j.
    let inverse = 1.0 / select(in.step_box, vec3<f32>(1e-30), abs(in.step_box) < vec3<f32>(1e-30));
    let to_lo = (vec3<f32>(-BOX_SLACK) - in.box) * inverse;
    let to_hi = (vec3<f32>(1.0 + BOX_SLACK) - in.box) * inverse;
    let enter = min(to_lo, to_hi);
    let exit = max(to_lo, to_hi);
    return vec2<f32>(max(max(enter.x, enter.y), enter.z), min(last, min(min(exit.x, exit.y), exit.z)));
}

// Whether sample j is one the ray takes (`samples` from `slab_samples`), clipping included.
fn slab_takes(in: SlabOut, samples: vec2<f32>, j: u32) -> bool {
    let t = f32(j);
    return t >= samples.x && t <= samples.y && !clipped(in.world + in.from_eye * (in.plane.z * t));
}

// `acc` (front to back, premultiplied) with a sample of colour `rgb` and opacity `a` behind it:
// each plane's "over" of its slice, composed in the fragment. Skipped where `taken` is false.
fn behind(acc: vec4<f32>, rgb: vec3<f32>, a: f32, taken: bool) -> vec4<f32> {
    return acc + (1.0 - acc.a) * select(vec4<f32>(0.0), vec4<f32>(rgb, a), taken);
}
