// Lines of constant width on screen (the plane map's frame in the view): each segment is a quad
// expanded across its direction on screen in the vertex stage, depth-tested with the opaque
// scene so atoms in front hide it and it hides what lies behind it.

struct LineUniforms {
    clip_from_object: mat4x4<f32>,
    // rgb: linear colour
    color: vec4<f32>,
    // xy: the frame's size in pixels, z: the lines' width in pixels
    screen: vec4<f32>,
};

struct Segment {
    a: vec4<f32>,
    b: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: LineUniforms;
@group(0) @binding(1) var<storage, read> segments: array<Segment>;

// The quad's corners: (0 at a / 1 at b, side −1 / +1), two triangles.
const CORNERS = array<vec2<f32>, 6>(
    vec2<f32>(0.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    vec2<f32>(0.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
);

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) k: u32) -> @builtin(position) vec4<f32> {
    let s = segments[k];
    let ca = u.clip_from_object * vec4<f32>(s.a.xyz, 1.0);
    let cb = u.clip_from_object * vec4<f32>(s.b.xyz, 1.0);
    let corner = CORNERS[vi];
    let c = mix(ca, cb, corner.x);
    // The segment's direction on screen (pixels), from both ends' positions in front of the
    // eye; a segment seen end-on keeps a width in x.
    let pa = ca.xy / max(ca.w, 1e-6) * u.screen.xy;
    let pb = cb.xy / max(cb.w, 1e-6) * u.screen.xy;
    var d = pb - pa;
    if (dot(d, d) < 1e-8) {
        d = vec2<f32>(1.0, 0.0);
    }
    let across = normalize(vec2<f32>(-d.y, d.x));
    // Half the width on each side, in clip units at this end's depth.
    let offset = across * corner.y * u.screen.z / u.screen.xy * c.w;
    return vec4<f32>(c.xy + offset, c.z, c.w);
}

struct FragOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
};

@fragment
fn fs_main() -> FragOut {
    var out: FragOut;
    out.color = vec4<f32>(u.color.rgb, 1.0);
    // A guide, not part of the molecule: nothing to pick.
    out.id = 0u;
    return out;
}
