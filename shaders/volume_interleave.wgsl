// Clouds and translucent surfaces in one depth order (Koide and Miyata with Naka et al.'s clouds): per
// pixel, the sorted fragments and the samples of up to four clouds are composited front to
// back in one walk. Each cloud is sampled where its slices would sample it (its own planes, its
// own opacity law); the clouds' samples are merged by depth, and samples of several clouds at
// one depth combine symmetrically, so the order the clouds are listed in changes nothing.
//
// A single cloud is drawn by its slices first (PREDRAWN): only pixels with fragments are
// walked, and the scene behind the cloud is what the slices let through. Several clouds are
// not drawn by slices at all: every pixel walks them over the scene.
// Prepended: volume_common.wgsl (cloud 0's texture is its `volume`), volume_gradient.wgsl,
// volume_field.wgsl, fullscreen.wgsl, oit_common.wgsl, oit_sort.wgsl.

// Each walked cloud's uniforms, indexed at run time (a copy of one chosen by a switch would cost
// a CPU rasteriser the whole struct per sample), and its texture (cloud 0's is `volume`).
@group(0) @binding(3) var<uniform> clouds: array<VolumeUniforms, 4>;
@group(0) @binding(4) var volume1: texture_3d<f32>;
@group(0) @binding(5) var volume2: texture_3d<f32>;
@group(0) @binding(6) var volume3: texture_3d<f32>;
// The opaque scene's depth: a cloud's samples stop there.
@group(0) @binding(7) var scene_depth: texture_depth_2d;

// How many clouds the walk takes (at most 4), and whether the one cloud is already drawn.
override CLOUDS: u32 = 1u;
override PREDRAWN: bool = true;

// Cloud k's value at texture coordinate uvw (each texture named where it is sampled: a texture
// handed to a function as an argument is not something every driver compiles).
fn cloud_value(k: u32, uvw: vec3<f32>) -> f32 {
    switch k {
        case 1u: { return textureSampleLevel(volume1, volume_sampler, uvw, 0.0).r; }
        case 2u: { return textureSampleLevel(volume2, volume_sampler, uvw, 0.0).r; }
        case 3u: { return textureSampleLevel(volume3, volume_sampler, uvw, 0.0).r; }
        default: { return textureSampleLevel(volume, volume_sampler, uvw, 0.0).r; }
    }
}

// Cloud k's gradient (world units) by central differences one texel apart.
fn cloud_gradient(k: u32, c: VolumeUniforms, uvw: vec3<f32>) -> vec3<f32> {
    var dims: vec3<u32>;
    switch k {
        case 1u: { dims = textureDimensions(volume1); }
        case 2u: { dims = textureDimensions(volume2); }
        case 3u: { dims = textureDimensions(volume3); }
        default: { dims = textureDimensions(volume); }
    }
    let h = 1.0 / vec3<f32>(dims);
    var g_tex: vec3<f32>;
    for (var a = 0; a < 3; a += 1) {
        var d = vec3<f32>(0.0);
        d[a] = h[a];
        g_tex[a] = (cloud_value(k, uvw + d) - cloud_value(k, uvw - d)) / (2.0 * h[a]);
    }
    return world_gradient(c, g_tex);
}

// One sample of cloud k at p (its object's frame): the premultiplied colour, alpha < 0 where
// it is invisible or cut away.
fn sample_cloud(k: u32, p: vec3<f32>, from_eye: vec3<f32>) -> vec4<f32> {
    let c = clouds[k];
    if ((c.tf_bits & TF_CLIP) != 0u && dot(c.clip.xyz, p) > c.clip.w) {
        return vec4<f32>(-1.0);
    }
    let uvw = (c.tex_from_world * vec4<f32>(p, 1.0)).xyz;
    let gradient = GRADIENT && (c.tf_bits & TF_GRADIENT) != 0u;
    var grad = vec3<f32>(0.0);
    if (gradient) {
        grad = cloud_gradient(k, c, uvw);
    }
    return shade_with(c, c.signed_field, SHAPED && (c.tf_bits & TF_SHAPED) != 0u, gradient, cloud_value(k, uvw), grad, from_eye);
}

// Each cloud's ray (its object's frame), the planes it crosses and the next one's depth, one
// cloud per component (vectors, not arrays: an array indexed at run time costs memory traffic
// per access on a CPU rasteriser, a vector's component a select).
var<private> eye_x: vec4<f32>;
var<private> eye_y: vec4<f32>;
var<private> eye_z: vec4<f32>;
var<private> dir_x: vec4<f32>;
var<private> dir_y: vec4<f32>;
var<private> dir_z: vec4<f32>;
// Plane j lies at t = (first + j·spacing) / n_dot_r along the ray.
var<private> first: vec4<f32>;
var<private> spacing: vec4<f32>;
var<private> n_dot_r: vec4<f32>;
// The next plane and the last.
var<private> plane_next: vec4<f32>;
var<private> plane_last: vec4<f32>;
// Window depth at t: (depth_a + t·depth_b) / (depth_c + t·depth_d).
var<private> depth_a: vec4<f32>;
var<private> depth_b: vec4<f32>;
var<private> depth_c: vec4<f32>;
var<private> depth_d: vec4<f32>;
var<private> next_depth: vec4<f32>;

const NO_SAMPLE: f32 = 2.0;

// Where less than this gets through, what lies behind cannot change the pixel by half a level
// of 255: the walk ends there.
const OPAQUE_ENOUGH: f32 = 0.002;

fn next_t() -> vec4<f32> {
    return (first + plane_next * spacing) / n_dot_r;
}

// Every cloud's next sample's depth (NO_SAMPLE past its last plane).
fn next_depths() -> vec4<f32> {
    let t = next_t();
    let z = (depth_a + t * depth_b) / (depth_c + t * depth_d);
    return select(vec4<f32>(NO_SAMPLE), z, plane_next <= plane_last);
}

// The nearest sample of any cloud (NO_SAMPLE when all are done).
fn nearest_depth() -> f32 {
    let d = next_depth;
    return min(min(d.x, d.y), min(d.z, d.w));
}

// Sets up every cloud's ray through the pixel at `xy`; returns the first sample's depth.
fn begin_clouds(xy: vec2<f32>) -> f32 {
    plane_next = vec4<f32>(1.0);
    plane_last = vec4<f32>(0.0);
    first = vec4<f32>(0.0);
    spacing = vec4<f32>(1.0);
    n_dot_r = vec4<f32>(1.0);
    depth_c = vec4<f32>(1.0);
    for (var k = 0u; k < CLOUDS; k += 1u) {
        let c = clouds[k];
        let ndc = vec2<f32>(xy.x / c.slab.z * 2.0 - 1.0, 1.0 - xy.y / c.slab.w * 2.0);
        let far = c.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
        let eye = c.eye.xyz;
        let dir = normalize(far.xyz / far.w - eye);
        eye_x[k] = eye.x;
        eye_y[k] = eye.y;
        eye_z[k] = eye.z;
        dir_x[k] = dir.x;
        dir_y[k] = dir.y;
        dir_z[k] = dir.z;
        let m = c.clip_from_world;
        let row_z = vec4<f32>(m[0].z, m[1].z, m[2].z, m[3].z);
        let row_w = vec4<f32>(m[0].w, m[1].w, m[2].w, m[3].w);
        depth_a[k] = dot(row_z, vec4<f32>(eye, 1.0));
        depth_b[k] = dot(row_z, vec4<f32>(dir, 0.0));
        depth_c[k] = dot(row_w, vec4<f32>(eye, 1.0));
        depth_d[k] = dot(row_w, vec4<f32>(dir, 0.0));
        let n = c.plane.xyz;
        let step = c.plane.w;
        let along = dot(n, dir);
        if (along > 1e-4) {
            // Where the ray is inside the slices' box, and the planes it crosses there.
            let o = (c.box_from_world * vec4<f32>(eye, 1.0)).xyz;
            let d = (c.box_from_world * vec4<f32>(dir, 0.0)).xyz;
            let t0 = -o / d;
            let t1 = (vec3<f32>(1.0) - o) / d;
            let t_in = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), 0.0);
            let t_out = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
            let e = dot(n, eye);
            first[k] = c.slab.x - e;
            spacing[k] = step;
            n_dot_r[k] = along;
            plane_next[k] = max(ceil((e + t_in * along - c.slab.x) / step), 0.0);
            plane_last[k] = min(floor((e + t_out * along - c.slab.x) / step), c.slab.y - 1.0);
        }
    }
    next_depth = next_depths();
    return nearest_depth();
}

// The samples of every cloud at depth z, combined (α = 1 − Π(1 − αₖ), colours weighted by
// their opacities: the same whichever cloud is listed first), and each of those clouds moved
// to its next plane. Alpha 0 where none is visible.
fn take_samples(z: f32) -> vec4<f32> {
    let here = next_depth == vec4<f32>(z);
    let t = next_t();
    var color = vec3<f32>(0.0);
    var alpha_sum = 0.0;
    var through = 1.0;
    var visible = 0u;
    var only = vec4<f32>(0.0);
    for (var k = 0u; k < CLOUDS; k += 1u) {
        if (!here[k]) {
            continue;
        }
        let eye = vec3<f32>(eye_x[k], eye_y[k], eye_z[k]);
        let from_eye = t[k] * vec3<f32>(dir_x[k], dir_y[k], dir_z[k]);
        let s = sample_cloud(k, eye + from_eye, from_eye);
        if (s.a > 0.0) {
            color += s.rgb;
            alpha_sum += s.a;
            through *= 1.0 - s.a;
            visible += 1u;
            only = s;
        }
    }
    plane_next += select(vec4<f32>(0.0), vec4<f32>(1.0), here);
    next_depth = next_depths();
    if (visible <= 1u) {
        return only;
    }
    let alpha = 1.0 - through;
    return vec4<f32>(color * (alpha / alpha_sum), alpha);
}

@fragment
fn fs_interleave(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(pos.xy);
    let shown = textureLoad(scene, vec2<i32>(px), 0).rgb;
    let count = gather(px);
    if (PREDRAWN && count == 0u) {
        return vec4<f32>(shown, 1.0);
    }
    var walk = begin_walk(count);
    // What the clouds alone composite to here (what a predrawn cloud's slices drew).
    var cloud = vec3<f32>(0.0);
    var cloud_through = 1.0;
    // And what the fragments let through, of all behind the cloud.
    var fragments_through = vec3<f32>(1.0);
    var i = 0u;
    let opaque = textureLoad(scene_depth, px, 0);
    var z = begin_clouds(pos.xy);
    loop {
        if (z >= opaque) {
            break;
        }
        while (i < count && sorted_depth[i] < z) {
            walk = step_walk(walk, i);
            fragments_through *= walk.last;
            i += 1u;
        }
        let c = take_samples(z);
        if (c.a > 0.0) {
            walk.color += walk.through * c.rgb;
            walk.through *= 1.0 - c.a;
            cloud += cloud_through * c.rgb;
            cloud_through *= 1.0 - c.a;
            if (!PREDRAWN && max(max(walk.through.r, walk.through.g), walk.through.b) < OPAQUE_ENOUGH) {
                return vec4<f32>(walk.color, 1.0);
            }
        }
        z = nearest_depth();
    }
    for (; i < count; i += 1u) {
        walk = step_walk(walk, i);
        fragments_through *= walk.last;
    }
    if (PREDRAWN) {
        return vec4<f32>(walk.color + fragments_through * max(shown - cloud, vec3<f32>(0.0)), 1.0);
    }
    return vec4<f32>(walk.color + walk.through * shown, 1.0);
}

// Several clouds and no translucent surfaces: the clouds' samples alone, over the scene.
@fragment
fn fs_clouds(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(pos.xy);
    let shown = textureLoad(scene, vec2<i32>(px), 0).rgb;
    let opaque = textureLoad(scene_depth, px, 0);
    var color = vec3<f32>(0.0);
    var through = 1.0;
    var z = begin_clouds(pos.xy);
    loop {
        if (z >= opaque) {
            break;
        }
        let c = take_samples(z);
        if (c.a > 0.0) {
            color += through * c.rgb;
            through *= 1.0 - c.a;
            if (through < OPAQUE_ENOUGH) {
                break;
            }
        }
        z = nearest_depth();
    }
    return vec4<f32>(color + through * shown, 1.0);
}
