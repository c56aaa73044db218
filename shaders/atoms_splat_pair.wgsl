// The compute rasteriser's pixels as two words each (any device): the depth keys, then the atom
// ids, then the coarse depths. Ids take a second pass: an atom writes its id where its depth
// won.

@group(1) @binding(1) var<storage, read_write> splat: array<atomic<u32>>;

const PACKED: bool = false;

fn pixels() -> u32 {
    return u32(g.viewport.x) * u32(g.viewport.y);
}

fn depth_key(pixel: u32) -> u32 {
    return atomicLoad(&splat[pixel]);
}

// Nearest wins (the id comes in the second pass).
fn draw_depth(pixel: u32, key: u32, id: u32) {
    if (key > atomicLoad(&splat[pixel])) {
        atomicMax(&splat[pixel], key);
    }
}

fn draw_id(pixel: u32, key: u32, id: u32) {
    if (key != 0u && key == atomicLoad(&splat[pixel])) {
        atomicStore(&splat[pixels() + pixel], id);
    }
}

fn coarse_load(k: u32) -> u32 {
    return atomicLoad(&splat[2u * pixels() + k]);
}

fn coarse_store(k: u32, key: u32) {
    atomicStore(&splat[2u * pixels() + k], key);
}
