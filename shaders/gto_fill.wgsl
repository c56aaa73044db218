// Fills a 3D texture with an orbital on the grid (the slice renderer then samples it).
// Prepended: gto_common.wgsl.

struct FillParams {
    // Grid index (i, j, k) to bohr.
    world_from_grid: mat4x4<f32>,
    // x: nx, y: ny, z: nz (texture width = nz: cube order, z fastest); w: what is written,
    // 0 ψ, 1–3 the x, y or z component of its analytic gradient (direct mode's, for checks).
    dims: vec4<u32>,
};

@group(0) @binding(0) var<uniform> fill: FillParams;
@group(0) @binding(1) var out_volume: texture_storage_3d<r32float, write>;

@compute @workgroup_size(4, 4, 4)
fn cs_fill(@builtin(global_invocation_id) id: vec3<u32>) {
    // Texel (x, y, z) holds grid point (i, j, k) = (z, y, x).
    if (id.x >= fill.dims.z || id.y >= fill.dims.y || id.z >= fill.dims.x) {
        return;
    }
    let p = (fill.world_from_grid * vec4<f32>(f32(id.z), f32(id.y), f32(id.x), 1.0)).xyz;
    var v: f32;
    if (fill.dims.w == 0u) {
        v = gto_value(p);
    } else {
        v = gto_value_and_gradient(p)[min(fill.dims.w, 3u)];
    }
    textureStore(out_volume, vec3<i32>(id), vec4<f32>(v, 0.0, 0.0, 1.0));
}
