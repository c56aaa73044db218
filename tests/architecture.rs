//! Keeps the layers of ARCHITECTURE.md true: each layer names only the crate modules below it
//! (whether as `crate::gpu`, `crate::{gpu, model}`, `super::super::gpu` or renamed with `as`) and
//! only the external crates its row of the table allows.

use std::path::{Path, PathBuf};

/// For each layer (a directory or file under src/), the crate modules it must not name.
const MODULE_RULES: &[(&str, &[&str])] = &[
    (
        "model",
        &[
            "formats",
            "scene",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "formats",
        &[
            "scene",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "scene",
        &[
            "formats",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "gpu",
        &[
            "formats",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "meshes.rs",
        &[
            "formats",
            "gpu",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "evaluate.rs",
        &[
            "formats",
            "meshes",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "layers.rs",
        &[
            "formats",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    ("headless.rs", &["formats", "key_volumes", "app", "arithmetic", "demo", "info", "shots", "plane"]),
    ("key_volumes.rs", &["formats", "headless", "app", "arithmetic", "demo", "info", "shots", "plane"]),
    (
        "info.rs",
        &[
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "shots",
            "plane",
        ],
    ),
    (
        "demo.rs",
        &[
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "info",
            "shots",
            "plane",
        ],
    ),
    (
        "figure.rs",
        &[
            "model",
            "formats",
            "scene",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "movie.rs",
        &[
            "model",
            "formats",
            "scene",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "shots",
            "plane",
        ],
    ),
    (
        "arithmetic.rs",
        &[
            "formats",
            "gpu",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    ("shots.rs", &["formats", "app", "arithmetic", "demo", "info", "plane"]),
    (
        "compute.rs",
        &[
            "scene",
            "gpu",
            "meshes",
            "evaluate",
            "layers",
            "headless",
            "key_volumes",
            "app",
            "arithmetic",
            "demo",
            "info",
            "figure",
            "movie",
            "shots",
            "plane",
        ],
    ),
    (
        "plane",
        &["gpu", "meshes", "layers", "headless", "key_volumes", "app", "arithmetic", "demo", "info", "movie", "shots"],
    ),
    ("app", &[]),
];

/// For each layer, the external crates (of Cargo.toml's dependencies) it may name; the table in
/// ARCHITECTURE.md says the same.
const CRATE_RULES: &[(&str, &[&str])] = &[
    ("model", &["glam", "serde", "rayon", "thiserror", "bytemuck", "meshopt"]),
    ("formats", &["glam", "serde", "rayon", "thiserror", "flate2", "fast_float2", "toml", "bytemuck"]),
    ("scene", &["glam", "serde"]),
    ("gpu", &["glam", "thiserror", "wgpu", "bytemuck", "half", "image", "pollster", "log"]),
    ("meshes.rs", &["glam"]),
    ("evaluate.rs", &["wgpu"]),
    ("arithmetic.rs", &["glam"]),
    ("layers.rs", &["glam"]),
    ("headless.rs", &["wgpu", "image"]),
    ("key_volumes.rs", &["glam", "thiserror", "wgpu", "image"]),
    ("figure.rs", &["image", "ab_glyph", "epaint_default_fonts"]),
    ("movie.rs", &["thiserror", "image", "gif", "color_quant", "png"]),
    ("shots.rs", &["thiserror", "image"]),
    ("info.rs", &["glam", "serde", "serde_json"]),
    ("compute.rs", &["serde", "serde_json", "thiserror", "log", "libc"]),
    ("demo.rs", &["flate2"]),
    ("plane", &["glam", "thiserror", "image"]),
    ("app", &["glam", "serde", "toml", "wgpu", "image", "log", "egui", "eframe", "egui_wgpu", "egui_plot", "rfd"]),
    // The binary: main.rs and its subcommands.
    ("cli", &["wgpu", "glam", "rayon", "clap", "anyhow", "image", "serde_json", "toml"]),
    ("main.rs", &["clap", "anyhow", "env_logger", "libc"]),
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
    for (layer, forbidden) in MODULE_RULES {
        for f in layer_files(layer) {
            let code = code(&std::fs::read_to_string(&f).unwrap());
            for prefix in ["crate::", "super::super::"] {
                for (name, line) in modules_after(&code, prefix) {
                    if forbidden.contains(&name.as_str()) {
                        violations.push(format!("{}:{line}: {layer} names {name}", f.display()));
                    }
                }
            }
        }
    }
    assert!(violations.is_empty(), "layering violations:\n{}", violations.join("\n"));
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
    // The binary: main.rs and its subcommand modules under cli/.
    let binary = |f: &Path| f.ends_with("main.rs") || f.starts_with(src.join("cli"));
    for f in files.iter().filter(|f| !binary(f)) {
        let text = std::fs::read_to_string(f).unwrap();
        assert!(!text.contains("anyhow"), "{} uses anyhow; library code returns typed errors", f.display());
    }
}
