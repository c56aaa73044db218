//! Keeps the layers of ARCHITECTURE.md true: each layer names only the crate modules below it
//! (whether as `crate::gpu`, `crate::{gpu, model}`, `super::super::gpu` or renamed with `as`) and
//! only the external crates its row of the table allows.

use std::path::{Path, PathBuf};

/// The library's layers in order, each a room under src/ with the crate modules it may name
/// (always those before it, never those after): nothing points up.
const LAYERS: &[(&str, &[&str])] = &[
    ("model", &[]),
    ("formats", &["model"]),
    ("scene", &["model"]),
    ("gpu", &["model", "scene"]),
    ("evaluate", &["model", "scene", "gpu"]),
    ("sources", &["model", "formats", "scene", "evaluate"]),
    ("layers", &["model", "scene", "gpu", "evaluate"]),
    ("pictures", &["model", "scene", "gpu", "evaluate", "layers"]),
    ("plane", &["model", "formats", "scene", "evaluate", "pictures"]),
    ("app", &["model", "formats", "scene", "gpu", "evaluate", "sources", "layers", "pictures", "plane"]),
    ("cli", &["model", "formats", "scene", "gpu", "evaluate", "sources", "layers", "pictures", "plane", "app"]),
];

/// Files that stay below the rest of their room: plain image and file work, meshes and volume
/// arithmetic on the CPU, PySCF's jobs, the `info` report.
const NARROWER: &[(&str, &[&str])] = &[
    ("evaluate/meshes.rs", &["model", "scene"]),
    ("evaluate/arithmetic.rs", &["model", "scene"]),
    ("pictures/figure.rs", &[]),
    ("pictures/movie.rs", &[]),
    ("pictures/headless.rs", &["model", "scene", "gpu", "evaluate", "layers"]),
    ("sources/compute.rs", &["model", "formats"]),
    ("sources/demo.rs", &["model", "formats", "scene"]),
    ("cli/info.rs", &["model"]),
];

/// For each layer, the external crates (of Cargo.toml's dependencies) it may name; the table in
/// ARCHITECTURE.md says the same.
const CRATE_RULES: &[(&str, &[&str])] = &[
    ("model", &["glam", "serde", "rayon", "thiserror", "bytemuck", "meshopt"]),
    ("formats", &["glam", "serde", "serde_json", "rayon", "thiserror", "flate2", "fast_float2", "toml", "bytemuck"]),
    ("scene", &["glam", "serde"]),
    ("sources", &["flate2", "serde", "serde_json", "thiserror", "log", "libc", "toml"]),
    ("gpu", &["glam", "thiserror", "wgpu", "bytemuck", "half", "image", "pollster", "log"]),
    ("evaluate", &["glam", "wgpu", "log"]),
    ("evaluate/meshes.rs", &["glam"]),
    ("evaluate/arithmetic.rs", &["glam"]),
    ("layers", &["glam", "thiserror", "wgpu", "image"]),
    ("pictures", &["thiserror", "wgpu", "image", "ab_glyph", "epaint_default_fonts", "gif", "color_quant", "png"]),
    ("plane", &["glam", "thiserror", "image"]),
    ("app", &["glam", "serde", "toml", "wgpu", "image", "log", "egui", "eframe", "egui_wgpu", "egui_plot", "rfd"]),
    ("cli", &["wgpu", "glam", "rayon", "clap", "anyhow", "image", "serde", "serde_json", "toml"]),
    // The binary: the process's setup around the command line.
    ("main.rs", &["anyhow", "env_logger", "libc"]),
];

fn rust_files(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        for e in std::fs::read_dir(path).unwrap() {
            rust_files(&e.unwrap().path(), out);
        }
    } else if path.extension().is_some_and(|e| e == "rs") {
        out.push(path.to_path_buf());
    }
}

fn layer_files(layer: &str) -> Vec<PathBuf> {
    let mut files = Vec::new();
    rust_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(layer), &mut files);
    assert!(!files.is_empty(), "layer {layer} has no files");
    files
}

/// The text with line comments blanked (doc comments too), keeping line numbers.
fn code(text: &str) -> String {
    text.lines().map(|l| l.find("//").map_or(l, |i| &l[..i])).collect::<Vec<_>>().join("\n")
}

fn is_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The first path segment after each `prefix` (a whole path segment), and its line; a braced
/// group `prefix{a, b::c, d as e}` gives every member's first segment.
fn modules_after(code: &str, prefix: &str) -> Vec<(String, usize)> {
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    for (i, _) in code.match_indices(prefix) {
        if i > 0 && (is_ident(bytes[i - 1]) || bytes[i - 1] == b':') {
            continue;
        }
        let line = code[..i].matches('\n').count() + 1;
        let rest = &code[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // Members at depth 0 of the group, up to its closing brace.
            let (mut depth, mut member) = (0, String::new());
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.push((std::mem::take(&mut member), line));
                        continue;
                    }
                    _ => {}
                }
                if depth == 0 {
                    member.push(c);
                }
            }
            out.push((member, line));
        } else {
            out.push((rest.to_string(), line));
        }
    }
    out.into_iter()
        .filter_map(|(m, line)| {
            let name: String = m.trim().chars().take_while(|&c| is_ident(c as u8)).collect();
            (!name.is_empty()).then_some((name, line))
        })
        .collect()
}

#[test]
fn layers_name_only_the_modules_below_them() {
    let mut violations = Vec::new();
    for (layer, allowed) in LAYERS.iter().chain(NARROWER) {
        // A room names its own parts freely.
        let room = layer.split('/').next().unwrap();
        for f in layer_files(layer) {
            let code = code(&std::fs::read_to_string(&f).unwrap());
            for prefix in ["crate::", "super::super::"] {
                for (name, line) in modules_after(&code, prefix) {
                    // `super::super::x` inside a room is one of its own parts unless x is a room.
                    let is_room = LAYERS.iter().any(|(l, _)| *l == name);
                    if (prefix == "crate::" || is_room) && name != room && !allowed.contains(&name.as_str()) {
                        violations.push(format!("{}:{line}: {layer} names {name}", f.display()));
                    }
                }
            }
        }
    }
    assert!(violations.is_empty(), "layering violations:\n{}", violations.join("\n"));
}

/// Every module of lib.rs is a room of the table, and src/ holds only rooms, lib.rs and main.rs:
/// a new module is placed among the layers, not beside them.
#[test]
fn every_module_is_a_room_of_the_table() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let modules: Vec<&str> =
        lib.lines().filter_map(|l| l.strip_prefix("pub mod ")).map(|l| l.trim_end_matches(';')).collect();
    let rooms: Vec<&str> = LAYERS.iter().map(|(l, _)| *l).collect();
    for m in &modules {
        assert!(rooms.contains(m), "src/lib.rs: module {m} has no row in LAYERS (and ARCHITECTURE.md)");
    }
    for e in std::fs::read_dir(&src).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            path.is_dir() || name == "lib.rs" || name == "main.rs",
            "src/{name}: a loose file at the top of src/; put it in the room it belongs to"
        );
        if path.is_dir() {
            assert!(rooms.contains(&name.as_str()), "src/{name}/ is not a room of LAYERS");
        }
    }
    // Each room names only rooms before it.
    for (k, (layer, allowed)) in LAYERS.iter().enumerate() {
        for a in *allowed {
            assert!(rooms[..k].contains(a), "{layer} may name {a}, which is not below it");
        }
    }
}

/// The dependencies of Cargo.toml, as Rust names them.
fn dependencies() -> Vec<String> {
    let toml = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    let section = toml.split("\n[dependencies]\n").nth(1).expect("a [dependencies] section");
    let section = section.split("\n[").next().unwrap_or(section);
    section
        .lines()
        .filter_map(|l| l.split_once('=').map(|(name, _)| name.trim().replace('-', "_")))
        .filter(|name| !name.is_empty() && !name.starts_with('#'))
        .collect()
}

#[test]
fn layers_use_only_the_crates_their_row_allows() {
    let deps = dependencies();
    assert!(deps.iter().any(|d| d == "wgpu") && deps.iter().any(|d| d == "egui"), "{deps:?}");
    let mut violations = Vec::new();
    for (layer, allowed) in CRATE_RULES {
        for f in layer_files(layer) {
            let code = code(&std::fs::read_to_string(&f).unwrap());
            for dep in deps.iter().filter(|d| !allowed.contains(&d.as_str())) {
                // `dep::` at the start of a path, `use dep;` or `use dep as …`.
                let at_path_start = code
                    .match_indices(&format!("{dep}::"))
                    .any(|(i, _)| i == 0 || !(is_ident(code.as_bytes()[i - 1]) || code.as_bytes()[i - 1] == b':'));
                if at_path_start || code.contains(&format!("use {dep};")) || code.contains(&format!("use {dep} as ")) {
                    violations.push(format!("{}: {layer} uses the crate {dep}", f.display()));
                }
            }
        }
    }
    assert!(violations.is_empty(), "crates outside a layer's row:\n{}", violations.join("\n"));
}

#[test]
fn braced_and_renamed_imports_are_seen() {
    let code = "use crate::{formats, model::Molecule};\nuse crate::gpu as g;\nlet x = super::super::app::run();\nuse crate::{\n    scene::{Camera, RenderSettings},\n    headless,\n};";
    let mut names: Vec<_> =
        ["crate::", "super::super::"].iter().flat_map(|p| modules_after(code, p)).map(|(n, _)| n).collect();
    names.sort();
    assert_eq!(names, ["app", "formats", "gpu", "headless", "model", "scene"]);
    assert!(modules_after("use my_crate::gpu;", "crate::").is_empty());
}

#[test]
fn only_the_binary_uses_anyhow() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    // The binary (main.rs) and the command line's library (cli/).
    let binary = |f: &Path| f.ends_with("main.rs") || f.starts_with(src.join("cli"));
    for f in files.iter().filter(|f| !binary(f)) {
        let text = std::fs::read_to_string(f).unwrap();
        assert!(!text.contains("anyhow"), "{} uses anyhow; library code returns typed errors", f.display());
    }
}
