// The depth pyramid: after the first opaque draws, the farthest depth of each PYRAMID_TILE ×
// PYRAMID_TILE-pixel tile of the frame, then of each PYRAMID_BLOCK × PYRAMID_BLOCK-tile block:
// tiles first, then blocks, each in rows. Something whose nearest depth lies beyond every
// farthest depth its screen rectangle covers cannot pass the depth test anywhere.

struct PyramidSize {
    // x, y: the frame's pixels
    frame: vec4<u32>,
};

const PYRAMID_TILE: i32 = 8;
const PYRAMID_BLOCK: i32 = 8;

fn pyramid_tiles(frame: vec2<i32>) -> vec2<i32> {
    return (frame + PYRAMID_TILE - 1) / PYRAMID_TILE;
}

fn pyramid_blocks(frame: vec2<i32>) -> vec2<i32> {
    return (pyramid_tiles(frame) + PYRAMID_BLOCK - 1) / PYRAMID_BLOCK;
}

// Where the blocks start.
fn pyramid_blocks_at(frame: vec2<i32>) -> i32 {
    let t = pyramid_tiles(frame);
    return t.x * t.y;
}
