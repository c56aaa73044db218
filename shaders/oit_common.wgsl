// Per-pixel fragment lists of translucent surfaces (seed 003): every fragment of every
// translucent surface is kept, with what its optics need, in a linked list per pixel. The
// lists are sorted and composited in exact depth order when the frame resolves.

struct FragmentNode {
    // Window depth (0 near, 1 far).
    depth: f32,
    // N·V (low half) and N·L (high half), f16.
    cosines: u32,
    // R·V (low half, f16) and the surface's index in the frame (high half).
    highlight_surface: u32,
    // Index + 1 of the next node of the pixel's list; 0 ends it.
    next: u32,
};

struct ListInfo {
    // Pixels per row of the heads.
    width: u32,
    // Nodes the buffer holds; fragments past it are counted, not stored.
    capacity: u32,
    // Translucent surfaces this frame.
    surfaces: u32,
    _pad: u32,
};

fn node_surface(node: FragmentNode) -> u32 {
    return node.highlight_surface >> 16u;
}
