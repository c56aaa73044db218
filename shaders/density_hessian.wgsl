// The total density ρ = Σ_i n_i ψ_i², its gradient and its Hessian at grid points, from the
// occupied orbitals written out as cartesian Gaussians (NCI: s and λ₂ are finished from these on
// the CPU in double precision). Prepended: gto_common.wgsl, whose shells and primitives this reads;
// its weights hold, per group of four orbitals, one vec4 of the four orbitals' weights per
// cartesian component (group g's component c at 4·(g·cartesians + c)).
//
// Per shell, with d = r − A, R0 = Σ d_p e^(−α_p r²), R1 = Σ −2α_p d_p e^(−α_p r²) and
// R2 = Σ 4α_p² d_p e^(−α_p r²), and the angular part A(d) = Σ_c w_c x^a y^b z^c:
//   χ = A R0,  ∂_a χ = ∂_a A R0 + A d_a R1,
//   ∂_a∂_b χ = ∂_a∂_b A R0 + (∂_a A d_b + ∂_b A d_a) R1 + A (δ_ab R1 + d_a d_b R2),
// so each shell's exponentials are taken once per group and its angular sums once per component.

struct HessianParams {
    // Grid index (i, j, k) to bohr.
    world_from_grid: mat4x4<f32>,
    // x, y, z: the grid's nx, ny, nz (cube order, z fastest); w: groups of four orbitals.
    dims: vec4<u32>,
    // x: the chunk's first point (cube order), y: its points, z: cartesian components per group.
    chunk: vec4<u32>,
};

@group(0) @binding(0) var<uniform> params: HessianParams;
// The four occupations of each group (0 for the padding orbitals of the last group).
@group(0) @binding(1) var<storage, read> occupations: array<vec4<f32>>;
// Per point of the chunk: ρ, ∂xρ, ∂yρ, ∂zρ, ∂xxρ, ∂xyρ, ∂xzρ, ∂yyρ, ∂yzρ, ∂zzρ.
@group(0) @binding(2) var<storage, read_write> derivatives: array<f32>;

// (xⁿ, n xⁿ⁻¹, n(n−1) xⁿ⁻²) by the product rule, one factor of x at a time (exact where x = 0).
fn power_derivatives(x: f32, n: u32) -> vec3<f32> {
    var p = vec3<f32>(1.0, 0.0, 0.0);
    for (var i = 0u; i < n; i++) {
        p = vec3<f32>(x * p.x, p.x + x * p.y, 2.0 * p.y + x * p.z);
    }
    return p;
}

fn group_weights(index: u32) -> vec4<f32> {
    let at = 4u * index;
    return vec4<f32>(gto_weights[at], gto_weights[at + 1u], gto_weights[at + 2u], gto_weights[at + 3u]);
}

@compute @workgroup_size(64)
fn cs_density_hessian(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.chunk.y) {
        return;
    }
    let q = params.chunk.x + id.x;
    let nz = params.dims.z;
    let ny = params.dims.y;
    let index = vec3<u32>(q / (ny * nz), (q / nz) % ny, q % nz);
    let p = (params.world_from_grid * vec4<f32>(vec3<f32>(index), 1.0)).xyz;

    var rho = 0.0;
    var grad = vec3<f32>(0.0);
    // The Hessian's diagonal (xx, yy, zz) and off-diagonal (xy, xz, yz).
    var diag = vec3<f32>(0.0);
    var off = vec3<f32>(0.0);
    let n_shells = arrayLength(&gto_shells);
    for (var g = 0u; g < params.dims.w; g++) {
        // The four orbitals' value, gradient and Hessian.
        var v = vec4<f32>(0.0);
        var gx = vec4<f32>(0.0);
        var gy = vec4<f32>(0.0);
        var gz = vec4<f32>(0.0);
        var hxx = vec4<f32>(0.0);
        var hxy = vec4<f32>(0.0);
        var hxz = vec4<f32>(0.0);
        var hyy = vec4<f32>(0.0);
        var hyz = vec4<f32>(0.0);
        var hzz = vec4<f32>(0.0);
        for (var s = 0u; s < n_shells; s++) {
            let sh = gto_shells[s];
            let d = p - sh.center;
            let r2 = dot(d, d);
            if (r2 > sh.cutoff2) {
                continue;
            }
            var r0 = 0.0;
            var r1 = 0.0;
            var rr = 0.0;
            for (var k = 0u; k < sh.prim_count; k++) {
                let prim = gto_prims[sh.prim_offset + k];
                let e = prim.y * exp(-prim.x * r2);
                r0 += e;
                r1 -= 2.0 * prim.x * e;
                rr += 4.0 * prim.x * prim.x * e;
            }
            // Σ_c w_c of the monomial and its first and second derivatives.
            var a0 = vec4<f32>(0.0);
            var ax = vec4<f32>(0.0);
            var ay = vec4<f32>(0.0);
            var az = vec4<f32>(0.0);
            var axx = vec4<f32>(0.0);
            var axy = vec4<f32>(0.0);
            var axz = vec4<f32>(0.0);
            var ayy = vec4<f32>(0.0);
            var ayz = vec4<f32>(0.0);
            var azz = vec4<f32>(0.0);
            var w = g * params.chunk.z + sh.weight_offset;
            // Cartesian components in orbcloud's order: a from l down, then b from l − a down.
            for (var a = i32(sh.l); a >= 0; a--) {
                let px = power_derivatives(d.x, u32(a));
                for (var b = i32(sh.l) - a; b >= 0; b--) {
                    let py = power_derivatives(d.y, u32(b));
                    let pz = power_derivatives(d.z, u32(i32(sh.l) - a - b));
                    let wt = group_weights(w);
                    a0 += wt * (px.x * py.x * pz.x);
                    ax += wt * (px.y * py.x * pz.x);
                    ay += wt * (px.x * py.y * pz.x);
                    az += wt * (px.x * py.x * pz.y);
                    axx += wt * (px.z * py.x * pz.x);
                    axy += wt * (px.y * py.y * pz.x);
                    axz += wt * (px.y * py.x * pz.y);
                    ayy += wt * (px.x * py.z * pz.x);
                    ayz += wt * (px.x * py.y * pz.y);
                    azz += wt * (px.x * py.x * pz.z);
                    w++;
                }
            }
            v += r0 * a0;
            gx += r0 * ax + (r1 * d.x) * a0;
            gy += r0 * ay + (r1 * d.y) * a0;
            gz += r0 * az + (r1 * d.z) * a0;
            hxx += r0 * axx + (2.0 * r1 * d.x) * ax + (r1 + d.x * d.x * rr) * a0;
            hyy += r0 * ayy + (2.0 * r1 * d.y) * ay + (r1 + d.y * d.y * rr) * a0;
            hzz += r0 * azz + (2.0 * r1 * d.z) * az + (r1 + d.z * d.z * rr) * a0;
            hxy += r0 * axy + r1 * (d.y * ax + d.x * ay) + (d.x * d.y * rr) * a0;
            hxz += r0 * axz + r1 * (d.z * ax + d.x * az) + (d.x * d.z * rr) * a0;
            hyz += r0 * ayz + r1 * (d.z * ay + d.y * az) + (d.y * d.z * rr) * a0;
        }
        // ρ = Σ n ψ², ∂_a ρ = 2 Σ n ψ ∂_a ψ, ∂_a∂_b ρ = 2 Σ n (ψ ∂_a∂_b ψ + ∂_a ψ ∂_b ψ).
        let n = occupations[g];
        rho += dot(n, v * v);
        grad += 2.0 * vec3<f32>(dot(n, v * gx), dot(n, v * gy), dot(n, v * gz));
        diag += 2.0 * vec3<f32>(dot(n, v * hxx + gx * gx), dot(n, v * hyy + gy * gy), dot(n, v * hzz + gz * gz));
        off += 2.0 * vec3<f32>(dot(n, v * hxy + gx * gy), dot(n, v * hxz + gx * gz), dot(n, v * hyz + gy * gz));
    }
    let out = 10u * id.x;
    derivatives[out] = rho;
    derivatives[out + 1u] = grad.x;
    derivatives[out + 2u] = grad.y;
    derivatives[out + 3u] = grad.z;
    derivatives[out + 4u] = diag.x;
    derivatives[out + 5u] = off.x;
    derivatives[out + 6u] = off.y;
    derivatives[out + 7u] = diag.y;
    derivatives[out + 8u] = off.z;
    derivatives[out + 9u] = diag.z;
}
