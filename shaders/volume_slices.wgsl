// Slices sampling the grid's 3D texture, SLAB planes per fragment. A slab's polygon lies on its
// front plane and covers every pixel whose ray meets one of its planes' slices; the fragment
// follows its pixel's ray through the slab's planes, composites their samples front to back,
// and the slabs are blended back to front. Each sample is the one a slice of its own plane
// takes at that pixel, so the picture is the slices'; what a slab saves is each fragment's
// fixed cost (rasterising, interpolating, blending), paid once per SLAB samples.
// Prepended: volume_common.wgsl, volume_gradient.wgsl, volume_field.wgsl.

// Planes per slab (1: one slice per plane, where slabs cannot be cut: the eye among the planes).
override SLAB: u32 = 1u;
// The cloud's `signed_field`, as a constant: what its transfer function does to a value is then
// known when the pipeline is built.
override FIELD: u32 = 1u;

// The opaque scene's depth: a slab's samples behind it are hidden (the depth test only sees
// the front plane's).
@group(1) @binding(0) var scene_depth: texture_depth_2d;

// A slab's sample this far outside its box (a fraction of its edge) still counts, for rounding:
// more would add samples a slice's polygon leaves out, which a sharp transfer function shows.
const BOX_SLACK: f32 = 1e-6;

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // Read once: the uniforms handed by value to a function called per sample would be loaded
    // whole per call.
    let c = u;
    let n = c.plane.xyz;
    let along = dot(in.from_eye, n);
    // From one plane to the next along this pixel's ray.
    let step = in.from_eye * (u.plane.w / max(along, 1e-6 * length(in.from_eye)));
    let step_uvw = (u.tex_from_world * vec4<f32>(step, 0.0)).xyz;
    let path = plane_path(c, in.from_eye);
    // The samples this ray takes, j in [first, last]: inside the box, not past the cloud's
    // last plane, nor behind the opaque scene.
    let front = round((dot(n, in.world) - c.slab.x) / c.plane.w);
    var last = min(f32(SLAB), c.slab.y - front) - 0.5;
    if (SLAB > 1u) {
        let opaque = textureLoad(scene_depth, vec2<i32>(in.clip.xy), 0);
        let ndc = vec2<f32>(in.clip.x / c.slab.z * 2.0 - 1.0, 1.0 - in.clip.y / c.slab.w * 2.0);
        let hit = c.world_from_clip * vec4<f32>(ndc, opaque, 1.0);
        // The front plane passed the depth test itself.
        last = min(last, max((dot(n, hit.xyz / hit.w) - dot(n, in.world)) / c.plane.w - 1e-3, 0.0));
    }
    // Where the ray is in the box: the box coordinates are affine in j.
    let box0 = (c.box_from_world * vec4<f32>(in.world, 1.0)).xyz;
    var step_box = (c.box_from_world * vec4<f32>(step, 0.0)).xyz;
    step_box = select(step_box, vec3<f32>(1e-30), abs(step_box) < vec3<f32>(1e-30));
    let to_lo = (vec3<f32>(-BOX_SLACK) - box0) / step_box;
    let to_hi = (vec3<f32>(1.0 + BOX_SLACK) - box0) / step_box;
    let enter = min(to_lo, to_hi);
    let exit = max(to_lo, to_hi);
    let first = max(max(enter.x, enter.y), enter.z);
    last = min(last, min(min(exit.x, exit.y), exit.z));
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < SLAB; j += 1u) {
        let t = f32(j);
        let uvw = in.uvw + step_uvw * t;
        let inside = t >= first && t <= last && !clipped(in.world + step * t);
        var grad = vec3<f32>(0.0);
        if (needs_gradient()) {
            grad = field_gradient(uvw);
        }
        let e = emission(c, FIELD, SHAPED, GRADIENT, field(uvw), grad, in.from_eye + step * t);
        let alpha = select(0.0, opacity(max(e.a, 0.0) * path), inside && e.a >= 0.0);
        acc += (1.0 - acc.a) * vec4<f32>(e.rgb * alpha, alpha);
    }
    // Nothing to add: no read-modify-write of the frame buffer.
    if (acc.a <= 0.0) {
        discard;
    }
    return acc;
}
