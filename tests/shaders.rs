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
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
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
