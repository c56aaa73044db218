// The compute rasteriser's pixels as one 64-bit word each, the depth key above the atom id, so
// one atomic maximum keeps the nearest atom's depth and id together and no id pass is needed
// (devices with 64-bit storage atomics: Vulkan's shaderBufferInt64Atomics, Metal, DX12 SM 6.6).
// The coarse depths follow, one word each. The resolve reads a pixel as two 32-bit words: id
// (low), key (high).

@group(1) @binding(1) var<storage, read_write> splat: array<atomic<u64>>;

const PACKED: bool = true;

fn depth_key(pixel: u32) -> u32 {
    return u32(atomicLoad(&splat[pixel]) >> 32u);
}

// Key 0: the ray missed (an id alone must not win an empty pixel).
fn draw_depth(pixel: u32, key: u32, id: u32) {
    if (key == 0u) {
        return;
    }
    let word = (u64(key) << 32u) | u64(id);
    if (word > atomicLoad(&splat[pixel])) {
        atomicMax(&splat[pixel], word);
    }
}

fn draw_id(pixel: u32, key: u32, id: u32) {}

fn coarse_load(k: u32) -> u32 {
    return u32(atomicLoad(&splat[u32(g.viewport.x) * u32(g.viewport.y) + k]));
}

fn coarse_store(k: u32, key: u32) {
    atomicStore(&splat[u32(g.viewport.x) * u32(g.viewport.y) + k], u64(key));
}
