// A key volume's texels classified for the transfer function the uniforms describe (see
// `classify`) for the α-mix and three-pass programs (volume_morph.wgsl), drawn into a 2D atlas
// of its layers (grid planes i), which are then copied into a 3D texture: a CPU rasteriser
// shades one pass's fragments on all its threads, where a compute dispatch runs on one and a
// pass per layer costs each pass's set-up.
// - an orbital's (signed_field 1, R16Float): the extinction per reference step with the
//   value's sign, which picks the colour (0 where invisible);
// - a density's (Rg16Float): the extinction and the colour.
// Prepended: volume_common.wgsl.

// The atlas's largest side (gpu::classify::ATLAS_SIDE, WebGPU's guaranteed 2D texture size):
// layers are placed in rows of `columns` tiles, `rows` rows a pass.
const ATLAS_SIDE: u32 = 8192u;

struct TileOut {
    @builtin(position) clip: vec4<f32>,
    // The texel at the tile's first pixel, and the layer.
    @location(0) @interpolate(flat) origin: vec2<f32>,
    @location(1) @interpolate(flat) layer: u32,
};

// Two triangles over the layer's tile; the instance is the layer.
@vertex
fn vs_classify(@builtin(vertex_index) vi: u32, @builtin(instance_index) layer: u32) -> TileOut {
    let dims = textureDimensions(volume);
    let columns = min(dims.z, ATLAS_SIDE / dims.x);
    let per_pass = columns * (ATLAS_SIDE / dims.y);
    let tile = layer % per_pass;
    // Every pass draws into the same atlas, sized for the first.
    let rows = (min(dims.z, per_pass) + columns - 1u) / columns;
    let atlas = vec2<f32>(f32(columns * dims.x), f32(rows * dims.y));
    let origin = vec2<f32>(f32((tile % columns) * dims.x), f32((tile / columns) * dims.y));
    // Corners 0, 1, 2 and 2, 1, 3 of the tile.
    let corner = array<vec2<f32>, 6>(vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(0.0, 1.0), vec2(0.0, 1.0), vec2(1.0, 0.0), vec2(1.0, 1.0))[vi];
    let pixel = origin + corner * vec2<f32>(dims.xy);
    // Pixels (y down) to normalised device coordinates (y up).
    let ndc = vec2<f32>(pixel.x / atlas.x * 2.0 - 1.0, 1.0 - pixel.y / atlas.y * 2.0);
    return TileOut(vec4<f32>(ndc, 0.0, 1.0), origin, layer);
}

@fragment
fn fs_classify(in: TileOut) -> @location(0) vec4<f32> {
    let c = u;
    let at = vec2<i32>(in.clip.xy - in.origin);
    let value = textureLoad(volume, vec3<i32>(at, i32(in.layer)), 0).r;
    let e = classify(c, c.signed_field, (c.tf_bits & TF_SHAPED) != 0u, value);
    let extinction = max(e.x, 0.0);
    if (c.signed_field == 1u) {
        return vec4<f32>(select(-extinction, extinction, e.y > 0.5), 0.0, 0.0, 0.0);
    }
    return vec4<f32>(extinction, e.y, 0.0, 0.0);
}
