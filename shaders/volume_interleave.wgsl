// Translucent surfaces inside a cloud (seed 003 with seed 000's clouds): per pixel, the
// sorted fragments and the cloud's samples are composited front to back in one walk, the
// samples taken where the slices would take them (the same planes, the same opacity law).
// The slices already drew the cloud alone into the scene, over what lies behind it, so the
// scene behind the cloud is what that drawing let through: every fragment's transmission
// multiplies it too.
// Prepended: volume_common.wgsl, volume_gradient.wgsl, volume_field.wgsl, fullscreen.wgsl,
// oit_common.wgsl, oit_sort.wgsl.

@fragment
fn fs_interleave(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(pos.xy);
    let shown = textureLoad(scene, vec2<i32>(px), 0).rgb;
    let count = gather(px);
    if (count == 0u) {
        return vec4<f32>(shown, 1.0);
    }
    var walk = begin_walk(count);
    // The ray through the pixel's centre, in the cloud's frame.
    let ndc = vec2<f32>(pos.x / u.slab.z * 2.0 - 1.0, 1.0 - pos.y / u.slab.w * 2.0);
    let far = u.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    let eye = u.eye.xyz;
    let dir = normalize(far.xyz / far.w - eye);
    let opaque = textureLoad(opaque_depth, px, 0);
    // What the slices drew here: the cloud alone.
    var cloud = vec3<f32>(0.0);
    var cloud_through = 1.0;
    // And what the fragments let through, of all behind the cloud.
    var fragments_through = vec3<f32>(1.0);
    var i = 0u;
    let n = u.plane.xyz;
    let spacing = u.plane.w;
    let n_dot_r = dot(n, dir);
    if (n_dot_r > 1e-4) {
        // Where the ray is inside the slices' box, and the planes it crosses there.
        let o = (u.box_from_world * vec4<f32>(eye, 1.0)).xyz;
        let d = (u.box_from_world * vec4<f32>(dir, 0.0)).xyz;
        let t0 = -o / d;
        let t1 = (vec3<f32>(1.0) - o) / d;
        let t_in = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), 0.0);
        let t_out = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
        let e = dot(n, eye);
        let first = max(ceil((e + t_in * n_dot_r - u.slab.x) / spacing), 0.0);
        let last = min(floor((e + t_out * n_dot_r - u.slab.x) / spacing), u.slab.y - 1.0);
        for (var j = first; j <= last; j += 1.0) {
            let t = (u.slab.x + j * spacing - e) / n_dot_r;
            let p = eye + t * dir;
            let clip = u.clip_from_world * vec4<f32>(p, 1.0);
            let z = clip.z / clip.w;
            if (z >= opaque) {
                break;
            }
            while (i < count && sorted_depth[i] < z) {
                walk = step_walk(walk, i);
                fragments_through *= walk.last;
                i += 1u;
            }
            if (clipped(p)) {
                continue;
            }
            let uvw = (u.tex_from_world * vec4<f32>(p, 1.0)).xyz;
            var grad = vec3<f32>(0.0);
            if (needs_gradient()) {
                grad = field_gradient(uvw);
            }
            let c = shade(field(uvw), grad, p - eye);
            if (c.a < 0.0) {
                continue;
            }
            walk.color += walk.through * c.rgb;
            walk.through *= 1.0 - c.a;
            cloud += cloud_through * c.rgb;
            cloud_through *= 1.0 - c.a;
        }
    }
    for (; i < count; i += 1u) {
        walk = step_walk(walk, i);
        fragments_through *= walk.last;
    }
    return vec4<f32>(walk.color + fragments_through * max(shown - cloud, vec3<f32>(0.0)), 1.0);
}
