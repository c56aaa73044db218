// Contracted Gaussian basis functions evaluated on the GPU (Jang and Varetto, docs/references.md): the molecular orbital
// ψ(r) = Σ_shells R_s(|r − A_s|) · Σ_c w_sc x^a y^b z^c, with R_s(r) = Σ_p d_p e^(−α_p r²) and the
// per-orbital cartesian weights w_sc prepared on the CPU (pure shells folded into cartesian
// weights, component normalisation included).

struct GtoShell {
    center: vec3<f32>,
    // Beyond this squared distance every function of the shell is negligible.
    cutoff2: f32,
    l: u32,
    prim_offset: u32,
    prim_count: u32,
    // Index of the shell's first cartesian weight in `gto_weights`.
    weight_offset: u32,
};

@group(1) @binding(0) var<storage, read> gto_shells: array<GtoShell>;
// (exponent α, coefficient d) per primitive.
@group(1) @binding(1) var<storage, read> gto_prims: array<vec2<f32>>;
@group(1) @binding(2) var<storage, read> gto_weights: array<f32>;

fn int_pow(x: f32, n: u32) -> f32 {
    var r = 1.0;
    for (var i = 0u; i < n; i++) {
        r *= x;
    }
    return r;
}

// ψ at a point (bohr).
fn gto_value(p: vec3<f32>) -> f32 {
    var psi = 0.0;
    let n_shells = arrayLength(&gto_shells);
    for (var s = 0u; s < n_shells; s++) {
        let sh = gto_shells[s];
        let d = p - sh.center;
        let r2 = dot(d, d);
        if (r2 > sh.cutoff2) {
            continue;
        }
        var radial = 0.0;
        for (var k = 0u; k < sh.prim_count; k++) {
            let prim = gto_prims[sh.prim_offset + k];
            radial += prim.y * exp(-prim.x * r2);
        }
        // Cartesian components in orbcloud's order: a from l down, then b from l − a down.
        var angular = 0.0;
        var w = sh.weight_offset;
        for (var a = i32(sh.l); a >= 0; a--) {
            let xa = int_pow(d.x, u32(a));
            for (var b = i32(sh.l) - a; b >= 0; b--) {
                let c = u32(i32(sh.l) - a - b);
                angular += gto_weights[w] * xa * int_pow(d.y, u32(b)) * int_pow(d.z, c);
                w++;
            }
        }
        psi += radial * angular;
    }
    return psi;
}

// (ψ, ∂ψ/∂x, ∂ψ/∂y, ∂ψ/∂z) at a point (bohr).
fn gto_value_and_gradient(p: vec3<f32>) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    let n_shells = arrayLength(&gto_shells);
    for (var s = 0u; s < n_shells; s++) {
        let sh = gto_shells[s];
        let d = p - sh.center;
        let r2 = dot(d, d);
        if (r2 > sh.cutoff2) {
            continue;
        }
        // R and dR/dr² · 2 (so that ∇R = radial_d · d).
        var radial = 0.0;
        var radial_d = 0.0;
        for (var k = 0u; k < sh.prim_count; k++) {
            let prim = gto_prims[sh.prim_offset + k];
            let e = prim.y * exp(-prim.x * r2);
            radial += e;
            radial_d -= 2.0 * prim.x * e;
        }
        var angular = 0.0;
        var angular_grad = vec3<f32>(0.0);
        var w = sh.weight_offset;
        for (var a = i32(sh.l); a >= 0; a--) {
            for (var b = i32(sh.l) - a; b >= 0; b--) {
                let c = i32(sh.l) - a - b;
                let xa = int_pow(d.x, u32(a));
                let yb = int_pow(d.y, u32(b));
                let zc = int_pow(d.z, u32(c));
                let wt = gto_weights[w];
                angular += wt * xa * yb * zc;
                // d/dx x^a = a x^(a−1); a = 0 contributes nothing.
                let dxa = select(0.0, f32(a) * int_pow(d.x, u32(max(a - 1, 0))), a > 0);
                let dyb = select(0.0, f32(b) * int_pow(d.y, u32(max(b - 1, 0))), b > 0);
                let dzc = select(0.0, f32(c) * int_pow(d.z, u32(max(c - 1, 0))), c > 0);
                angular_grad += wt * vec3<f32>(dxa * yb * zc, xa * dyb * zc, xa * yb * dzc);
                w++;
            }
        }
        out.x += radial * angular;
        out = vec4<f32>(out.x, out.yzw + radial_d * d * angular + radial * angular_grad);
    }
    return out;
}
