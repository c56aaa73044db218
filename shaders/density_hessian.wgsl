// The total density ρ = Σ_i n_i ψ_i², its gradient and its Hessian at grid points, from the
// occupied orbitals written out as cartesian Gaussians (NCI: s and λ₂ are finished from these on
// the CPU in double precision). Prepended: gto_common.wgsl, whose shells and primitives this reads;
// its weights hold, per group of four orbitals, one vec4 of the four orbitals' weights per
// cartesian component (group g's component c at 4·(g·cartesians + c)).
//
// A dispatch evaluates BATCH groups (16 orbitals) and adds their share to the output (the
// first batch writes it): the sums over orbitals split into sums over batches. Per shell, with
// d = r − A, R0 = Σ d_p e^(−α_p r²), R1 = Σ −2α_p d_p e^(−α_p r²), R2 = Σ 4α_p² d_p e^(−α_p r²),
// and a cartesian component's monomial m = x^a y^b z^c:
//   χ = m R0,  ∂_a χ = ∂_a m R0 + m d_a R1,
//   ∂_a∂_b χ = ∂_a∂_b m R0 + (∂_a m d_b + ∂_b m d_a) R1 + m (δ_ab R1 + d_a d_b R2),
// each taken once per batch and shared by its orbitals, whose weights scale it.

struct HessianParams {
    // Grid index (i, j, k) to bohr.
    world_from_grid: mat4x4<f32>,
    // x, y, z: the grid's nx, ny, nz (cube order, z fastest); w: groups of four orbitals (the
    // buffers hold a multiple of BATCH, the groups beyond this padding with zero weights).
    dims: vec4<u32>,
    // x: the chunk's first point (cube order), y: its points, z: cartesian components per group,
    // w: the batch's first group (a multiple of BATCH; 0 writes the output, others add to it).
    chunk: vec4<u32>,
};

// Groups of four orbitals per dispatch (the four accumulators o0…o3 below, named so that they
// stay in registers).
const BATCH: u32 = 4u;

// A value, its gradient and its Hessian (xx, xy, xz, yy, yz, zz): of one basis function.
struct Derivatives {
    v: f32, x: f32, y: f32, z: f32,
    xx: f32, xy: f32, xz: f32, yy: f32, yz: f32, zz: f32,
};

// The same of four orbitals, one per lane.
struct Derivatives4 {
    v: vec4<f32>, x: vec4<f32>, y: vec4<f32>, z: vec4<f32>,
    xx: vec4<f32>, xy: vec4<f32>, xz: vec4<f32>, yy: vec4<f32>, yz: vec4<f32>, zz: vec4<f32>,
};

// Four orbitals' derivatives += their weights times a basis function's.
fn add_scaled(o: ptr<function, Derivatives4>, w: vec4<f32>, f: Derivatives) {
    (*o).v += w * f.v;
    (*o).x += w * f.x;
    (*o).y += w * f.y;
    (*o).z += w * f.z;
    (*o).xx += w * f.xx;
    (*o).xy += w * f.xy;
    (*o).xz += w * f.xz;
    (*o).yy += w * f.yy;
    (*o).yz += w * f.yz;
    (*o).zz += w * f.zz;
}

// The density's derivatives from four orbitals with occupations n:
// ρ = Σ n ψ², ∂_a ρ = 2 Σ n ψ ∂_a ψ, ∂_a∂_b ρ = 2 Σ n (ψ ∂_a∂_b ψ + ∂_a ψ ∂_b ψ).
fn density_part(o: Derivatives4, n: vec4<f32>) -> Derivatives {
    let v = o.v;
    return Derivatives(
        dot(n, v * v),
        2.0 * dot(n, v * o.x),
        2.0 * dot(n, v * o.y),
        2.0 * dot(n, v * o.z),
        2.0 * dot(n, v * o.xx + o.x * o.x),
        2.0 * dot(n, v * o.xy + o.x * o.y),
        2.0 * dot(n, v * o.xz + o.x * o.z),
        2.0 * dot(n, v * o.yy + o.y * o.y),
        2.0 * dot(n, v * o.yz + o.y * o.z),
        2.0 * dot(n, v * o.zz + o.z * o.z),
    );
}

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

    // The batch's four groups of four orbitals.
    var o0: Derivatives4;
    var o1: Derivatives4;
    var o2: Derivatives4;
    var o3: Derivatives4;
    let n_shells = arrayLength(&gto_shells);
    let first_group = params.chunk.w;
    let stride = params.chunk.z;
    let live = params.dims.w - first_group;
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
        var c = first_group * stride + sh.weight_offset;
        // Cartesian components in orbcloud's order: a from l down, then b from l − a down.
        for (var a = i32(sh.l); a >= 0; a--) {
            let px = power_derivatives(d.x, u32(a));
            for (var b = i32(sh.l) - a; b >= 0; b--) {
                let py = power_derivatives(d.y, u32(b));
                let pz = power_derivatives(d.z, u32(i32(sh.l) - a - b));
                let m = px.x * py.x * pz.x;
                let mx = px.y * py.x * pz.x;
                let my = px.x * py.y * pz.x;
                let mz = px.x * py.x * pz.y;
                let f = Derivatives(
                    r0 * m,
                    r0 * mx + r1 * d.x * m,
                    r0 * my + r1 * d.y * m,
                    r0 * mz + r1 * d.z * m,
                    r0 * (px.z * py.x * pz.x) + 2.0 * r1 * d.x * mx + (r1 + d.x * d.x * rr) * m,
                    r0 * (px.y * py.y * pz.x) + r1 * (d.y * mx + d.x * my) + d.x * d.y * rr * m,
                    r0 * (px.y * py.x * pz.y) + r1 * (d.z * mx + d.x * mz) + d.x * d.z * rr * m,
                    r0 * (px.x * py.z * pz.x) + 2.0 * r1 * d.y * my + (r1 + d.y * d.y * rr) * m,
                    r0 * (px.x * py.y * pz.y) + r1 * (d.z * my + d.y * mz) + d.y * d.z * rr * m,
                    r0 * (px.x * py.x * pz.z) + 2.0 * r1 * d.z * mz + (r1 + d.z * d.z * rr) * m,
                );
                // The same branches for every invocation: padding groups are skipped.
                add_scaled(&o0, group_weights(c), f);
                if (live > 1u) {
                    add_scaled(&o1, group_weights(c + stride), f);
                }
                if (live > 2u) {
                    add_scaled(&o2, group_weights(c + 2u * stride), f);
                }
                if (live > 3u) {
                    add_scaled(&o3, group_weights(c + 3u * stride), f);
                }
                c++;
            }
        }
    }
    let parts = array<Derivatives, 4>(
        density_part(o0, occupations[first_group]),
        density_part(o1, occupations[first_group + 1u]),
        density_part(o2, occupations[first_group + 2u]),
        density_part(o3, occupations[first_group + 3u]),
    );
    var sum = Derivatives(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (var g = 0u; g < BATCH; g++) {
        let e = parts[g];
        sum = Derivatives(
            sum.v + e.v, sum.x + e.x, sum.y + e.y, sum.z + e.z,
            sum.xx + e.xx, sum.xy + e.xy, sum.xz + e.xz, sum.yy + e.yy, sum.yz + e.yz, sum.zz + e.zz,
        );
    }
    let values = array<f32, 10>(sum.v, sum.x, sum.y, sum.z, sum.xx, sum.xy, sum.xz, sum.yy, sum.yz, sum.zz);
    let out = 10u * id.x;
    for (var t = 0u; t < 10u; t++) {
        if (first_group == 0u) {
            derivatives[out + t] = values[t];
        } else {
            derivatives[out + t] += values[t];
        }
    }
}
