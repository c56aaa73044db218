//! Every WGSL shader parses and validates with naga: no GPU needed.

use orbcloud::gpu::{SHADER_MODULES, SHADERS, module_source};

#[test]
fn every_shader_file_is_registered() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");
    let mut on_disk: Vec<String> = std::fs::read_dir(dir)
        .expect("shaders/ exists")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    on_disk.sort();
    let mut registered: Vec<String> = SHADERS.iter().map(|(n, _)| n.to_string()).collect();
    registered.sort();
    assert_eq!(on_disk, registered, "shaders/ and gpu::SHADERS disagree");
}

/// Files that only serve as prerequisites of other modules (they have no entry points).
fn prerequisites() -> Vec<&'static str> {
    SHADER_MODULES.iter().flat_map(|(name, parts)| parts.iter().copied().filter(move |p| p != name)).collect()
}

#[test]
fn every_shader_module_validates() {
    let prereqs = prerequisites();
    let mut validated = 0;
    for (name, _) in SHADERS.iter().filter(|(n, _)| !prereqs.contains(n)) {
        let source = module_source(name);
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        // pack2x16float/unpack2x16float (the fragment lists' half floats) need this one; wgpu
        // grants it on Vulkan, Metal and DX12 (DownlevelFlags::SHADER_F16_IN_F32).
        // The packed splat words need 64-bit atomics (used only where the device has them).
        use naga::valid::Capabilities as C;
        let capabilities =
            C::default() | C::SHADER_FLOAT16_IN_FLOAT32 | C::SHADER_INT64 | C::SHADER_INT64_ATOMIC_ALL_OPS;
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities)
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        assert!(!module.entry_points.is_empty(), "{name} has no entry points");
        validated += 1;
    }
    assert!(validated >= 4, "only {validated} shader modules found");
}

#[test]
fn every_prerequisite_is_registered() {
    let names: Vec<&str> = SHADERS.iter().map(|(n, _)| *n).collect();
    for p in prerequisites() {
        assert!(names.contains(&p), "{p} is a prerequisite but not in gpu::SHADERS");
    }
}

/// A Rust mirror of a WGSL struct: the module that declares it, the WGSL name, the Rust size and
/// each field's name and offset, in order.
macro_rules! mirror {
    ($module:expr, $wgsl:expr, $ty:ty, [$($field:ident),* $(,)?]) => {
        ($module, $wgsl, std::mem::size_of::<$ty>(), vec![$((stringify!($field), std::mem::offset_of!($ty, $field))),*])
    };
}

#[test]
fn rust_mirrors_match_the_wgsl_layouts() {
    use orbcloud::gpu::{
        arrows::ArrowUniforms, arrows::GpuArrow, atoms::AtomGlobals, basis_buffers::GpuShell,
        density_hessian::HessianParams, gto::FillParams, isosurface::SurfaceUniforms, occlusion::CullUniforms,
        occlusion::GpuBatch, occlusion::PyramidSize, oit::GpuOptics, oit::ListInfo, volume::VolumeUniforms,
    };
    let mirrors = [
        mirror!(
            "arrows.wgsl",
            "Arrow",
            GpuArrow,
            [start, shaft_radius, to, head_radius, head_length, pad0, pad1, pad2]
        ),
        mirror!("arrows.wgsl", "ArrowUniforms", ArrowUniforms, [clip_from_object, eye, light, color]),
        mirror!(
            "volume_slices.wgsl",
            "VolumeUniforms",
            VolumeUniforms,
            [
                clip_from_world,
                tex_from_world,
                eye,
                plane,
                positive_color,
                negative_color,
                k1,
                k2,
                inv_max,
                ref_step,
                signed_field,
                shape_positive,
                shape_negative,
                tf_bits,
                visible_min,
                morph_k,
                log_lo,
                inv_log_span,
                tf_positive,
                tf_negative,
                gradient_power,
                boundary,
                inv_max_grad,
                brick_cells,
                clip,
                light,
                world_from_clip,
                box_from_world,
                slab,
            ]
        ),
        mirror!(
            "atoms.wgsl",
            "Globals",
            AtomGlobals,
            [
                clip_from_world,
                eye,
                light,
                up,
                pick,
                viewport,
                ray_f0,
                ray_fx,
                ray_fy,
                counts,
                sticks,
                cells,
                cell_lists,
                cue,
                clip_zw,
                ray_zw,
                ray_zw_y,
                cut
            ]
        ),
        mirror!("isosurface.wgsl", "SurfaceUniforms", SurfaceUniforms, [clip_from_world, eye, light, color, pick, cut]),
        mirror!("surface_cull.wgsl", "CullUniforms", CullUniforms, [clip_from_object, counts]),
        mirror!("surface_cull.wgsl", "Batch", GpuBatch, [lo, first_index, hi, index_count, cluster]),
        mirror!("depth_pyramid.wgsl", "PyramidSize", PyramidSize, [frame]),
        mirror!("isosurface.wgsl", "ListInfo", ListInfo, [width, capacity, surfaces, _pad]),
        mirror!("resolve.wgsl", "SurfaceOptics", GpuOptics, [a, b, c, d, f, g, glow_d, glow_f, glow_g, same_object]),
        mirror!("gto_fill.wgsl", "FillParams", FillParams, [world_from_grid, dims]),
        mirror!("density_hessian.wgsl", "HessianParams", HessianParams, [world_from_grid, dims, chunk]),
        mirror!("gto_fill.wgsl", "GtoShell", GpuShell, [center, cutoff2, l, prim_offset, prim_count, weight_offset]),
    ];
    for (module_name, wgsl, size, fields) in mirrors {
        let source = module_source(module_name);
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(wgsl))
            .unwrap_or_else(|| panic!("{module_name} declares no struct {wgsl}"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else { panic!("{wgsl} is not a struct") };
        let wgsl_fields: Vec<(&str, usize)> =
            members.iter().map(|m| (m.name.as_deref().unwrap_or("?"), m.offset as usize)).collect();
        assert_eq!(wgsl_fields, fields, "{wgsl} in {module_name}: members and offsets differ from the Rust mirror");
        assert_eq!(*span as usize, size, "{wgsl} in {module_name}: size differs from the Rust mirror");
    }
}
