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
// Each cloud's bricks of grid cells (`brick_cells` on a side) that hold a value its transfer
// function shows (1) or none (0): a ray skips the planes it meets inside an empty brick, where
// every sample would be invisible. One texel "shown" where nothing is skipped.
@group(0) @binding(8) var bricks0: texture_3d<u32>;
@group(0) @binding(9) var bricks1: texture_3d<u32>;
@group(0) @binding(10) var bricks2: texture_3d<u32>;
@group(0) @binding(11) var bricks3: texture_3d<u32>;

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

// Whether cloud k's brick at `brick` (whole brick coordinates, within its texture) can show
// anything.
fn brick_shown(k: u32, brick: vec3<i32>) -> bool {
    switch k {
        case 1u: { return textureLoad(bricks1, brick, 0).r != 0u; }
        case 2u: { return textureLoad(bricks2, brick, 0).r != 0u; }
        case 3u: { return textureLoad(bricks3, brick, 0).r != 0u; }
        default: { return textureLoad(bricks0, brick, 0).r != 0u; }
    }
}

// The texel sizes of cloud k's volume and of its bricks' texture.
fn cloud_dims(k: u32) -> array<vec3<u32>, 2> {
    switch k {
        case 1u: { return array(textureDimensions(volume1), textureDimensions(bricks1)); }
        case 2u: { return array(textureDimensions(volume2), textureDimensions(bricks2)); }
        case 3u: { return array(textureDimensions(volume3), textureDimensions(bricks3)); }
        default: { return array(textureDimensions(volume), textureDimensions(bricks0)); }
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

// Where the ray o + t·d (brick coordinates: brick b spans [b, b + 1)) first enters a brick of
// cloud k that can show something, walking the bricks it crosses from t_a (Amanatides and Woo);
// past t_b when none does before.
fn first_shown(k: u32, o: vec3<f32>, d: vec3<f32>, top: vec3<f32>, t_a: f32, t_b: f32) -> f32 {
    var b = clamp(floor(o + t_a * d), vec3<f32>(0.0), top);
    let forward = d > vec3<f32>(0.0);
    let step = select(vec3<f32>(-1.0), vec3<f32>(1.0), forward);
    // The t at which the ray crosses the next face on each axis, and between faces.
    let inv = 1.0 / d;
    var cross = (b + select(vec3<f32>(0.0), vec3<f32>(1.0), forward) - o) * inv;
    let between = abs(inv);
    var t = t_a;
    // A ray crosses at most this many bricks (a bound, should rounding keep it in one).
    let most = u32(top.x + top.y + top.z) + 3u;
    for (var n = 0u; n < most; n += 1u) {
        if (t > t_b) {
            return t;
        }
        if (brick_shown(k, vec3<i32>(b))) {
            return t;
        }
        // On to the neighbour across the nearest face (an axis the ray runs along never
        // crosses: its t is infinite).
        if (cross.x <= cross.y && cross.x <= cross.z) {
            t = cross.x;
            b.x += step.x;
            cross.x += between.x;
        } else if (cross.y <= cross.z) {
            t = cross.y;
            b.y += step.y;
            cross.y += between.y;
        } else {
            t = cross.z;
            b.z += step.z;
            cross.z += between.z;
        }
        if (any(b < vec3<f32>(0.0)) || any(b > top)) {
            return max(t_b, t) + 1.0;
        }
    }
    return t_a;
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
            if (plane_next[k] <= plane_last[k]) {
                // Only the planes between the first and the last brick the ray meets that can
                // show anything: every sample before or after lies where nothing shows.
                let t_a = (first[k] + plane_next[k] * step) / along;
                let t_b = (first[k] + plane_last[k] * step) / along;
                let dims = cloud_dims(k);
                // Texel centres lie at (i + ½)/n in texture coordinates: index = uvw·n − ½.
                let per_brick = vec3<f32>(dims[0]) / c.brick_cells;
                let o = (c.tex_from_world * vec4<f32>(eye, 1.0)).xyz * per_brick - 0.5 / c.brick_cells;
                let d = (c.tex_from_world * vec4<f32>(dir, 0.0)).xyz * per_brick;
                let top = vec3<f32>(dims[1]) - 1.0;
                let t_shown = first_shown(k, o, d, top, t_a, t_b);
                let t_last = -first_shown(k, o, -d, top, -t_b, -t_a);
                // Only where the bricks moved an end: the planes at the ends, recomputed, could
                // round past themselves.
                if (t_shown > t_a) {
                    plane_next[k] = max(plane_next[k], ceil((t_shown * along - first[k]) / step));
                }
                if (t_last < t_b) {
                    plane_last[k] = min(plane_last[k], floor((t_last * along - first[k]) / step));
                }
            }
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
