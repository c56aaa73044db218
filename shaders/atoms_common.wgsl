// What the atom passes share: the frame's globals, the per-atom storage buffers (uploaded once;
// a colour or style change rewrites only `attrs` or `looks`) and the exact ray–sphere test.

struct Globals {
    clip_from_world: mat4x4<f32>,
    // xyz: eye position (bohr)
    eye: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // xyz: camera up vector
    up: vec4<f32>,
    // x: high bits of this object's atom pick ids; the atom index is added; y: 1 when the
    // compute rasteriser's pixels are packed 64-bit words (atoms_splat_packed.wgsl); z: 1 to walk
    // each cell's atoms backwards (they are sorted along the axis nearest the view direction)
    pick: vec4<u32>,
    // x, y: viewport size (px); z: pixels per bohr at unit clip w; w: largest radius (px)
    // the compute rasteriser draws (larger spheres are impostor quads)
    viewport: vec4<f32>,
    // The far-plane point each pixel's ray passes through: f0 + ndc.x * fx + ndc.y * fy.
    ray_f0: vec4<f32>,
    ray_fx: vec4<f32>,
    ray_fy: vec4<f32>,
    // x: atoms; y: bonds; z: style flags (STYLE_*); w: invocations per dispatch row
    counts: vec4<u32>,
    // x: stick radius; y: the largest atom radius drawn (bohr)
    sticks: vec4<f32>,
    // x: cells to rasterise this frame (nearest first); y: where their order starts in the
    // lists; z: where the atom indices start in cell_data; w: this frame's number
    cells: vec4<u32>,
    // Where the cell lists start in `lists`: x: seen last frame (drawn first); y: left for the
    // occlusion test (later: the cells that write ids); z: left and not hidden; w: the frame
    // each cell was last seen in
    cell_lists: vec4<u32>,
    // Depth cue: x, y: the clip w where darkening starts and where it is full; z: how much the
    // farthest darkens (0: off)
    cue: vec4<f32>,
    // Clip z and w of the eye (x, y) and of the view direction (z, w): a point r along the
    // view direction from p has clip z, w = clip(p).zw − r·(z, w).
    clip_zw: vec4<f32>,
    // Clip z and w of the pixel rays' parts (ray_f0 − eye, ray_fx; then ray_fy): the ray
    // through ndc reaches clip zw = clip_zw.xy + t·(ray_zw.xy + ndc.x·ray_zw.zw + ndc.y·ray_zw_y.xy).
    ray_zw: vec4<f32>,
    ray_zw_y: vec4<f32>,
    // The object's clipping plane when it cuts atoms (xyz: unit normal, w: distance): points p
    // with dot(xyz, p) > w are cut away; (0, 0, 0, 1e30) cuts nothing.
    cut: vec4<f32>,
};

// Words before the lists in `lists`: the spheres' and the bonds' indirect draws, then the cell
// lists' counts.
const LISTS: u32 = 12u;

const STYLE_CYLINDERS: u32 = 1u;
const STYLE_UNBONDED_ONLY: u32 = 2u;

// attrs: bits 0-7 atomic number, 8-15 flags, 16-31 palette index.
const FLAG_GHOST: u32 = 1u;
const FLAG_HIDDEN: u32 = 2u;
const FLAG_BONDED: u32 = 4u;
// looks: radius per atomic number (x, bohr) for the style, then the palette (linear RGB).
const PALETTE: u32 = 128u;

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> attrs: array<u32>;
@group(0) @binding(3) var<storage, read> looks: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> bonds: array<vec2<u32>>;
// Atoms binned into spatial cells: a header per cell (first, count, bounding sphere), then the
// atom indices cell by cell.
@group(0) @binding(5) var<storage, read> cell_data: array<u32>;

fn flags_of(i: u32) -> u32 {
    return (attrs[i] >> 8u) & 255u;
}

// Radius of atom i in this style; 0 when it is not drawn.
fn radius_of(i: u32) -> f32 {
    let a = attrs[i];
    let f = (a >> 8u) & 255u;
    if ((f & FLAG_HIDDEN) != 0u) {
        return 0.0;
    }
    if ((g.counts.z & STYLE_UNBONDED_ONLY) != 0u && (f & FLAG_BONDED) != 0u) {
        return 0.0;
    }
    var r = looks[a & 255u].x;
    if ((f & FLAG_GHOST) != 0u) {
        r = 0.5 * r;
    }
    return r;
}

// The radius the compute rasteriser and its resolve use: never under half a pixel, so a far
// atom still covers the pixel it falls in (Lee et al.'s point of the projected size).
fn splat_radius(i: u32) -> f32 {
    let r = radius_of(i);
    let w = (g.clip_from_world * vec4<f32>(positions[i].xyz, 1.0)).w;
    return select(0.0, max(r, 0.5 * w / g.viewport.z), r > 0.0);
}

fn color_of(i: u32) -> vec3<f32> {
    return looks[PALETTE + (attrs[i] >> 16u)].rgb;
}

// The unnormalised direction of the ray through pixel `px` (pixel centres at .5).
fn ray_through(px: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(2.0 * px.x / g.viewport.x - 1.0, 1.0 - 2.0 * px.y / g.viewport.y);
    return g.ray_f0.xyz + ndc.x * g.ray_fx.xyz + ndc.y * g.ray_fy.xyz - g.eye.xyz;
}

// Distance parameter of the first hit of the ray eye + t·d on a sphere, < 0 when it misses.
fn hit_sphere(d: vec3<f32>, center: vec3<f32>, radius: f32) -> f32 {
    let oc = g.eye.xyz - center;
    let a = dot(d, d);
    let b = dot(oc, d);
    let c = dot(oc, oc) - radius * radius;
    let disc = b * b - a * c;
    if (disc < 0.0) {
        return -1.0;
    }
    return (-b - sqrt(disc)) / a;
}

// How far beyond the clipping plane `p` lies (> 0: cut away).
fn beyond_cut(p: vec3<f32>) -> f32 {
    return dot(g.cut.xyz, p) - g.cut.w;
}

fn depth_of(world: vec3<f32>) -> f32 {
    let c = g.clip_from_world * vec4<f32>(world, 1.0);
    return c.z / c.w;
}
