//! Keeps the layers of ARCHITECTURE.md true by reading the `use` and path lines of each module.

use std::path::Path;

/// For each layer (a directory or file under src/), the crate modules it must not name.
const RULES: &[(&str, &[&str])] = &[
    ("model", &["formats", "scene", "gpu", "headless", "app", "demo", "info", "wgpu", "egui", "eframe", "rfd"]),
    ("formats", &["scene", "gpu", "headless", "app", "wgpu", "egui", "eframe", "rfd"]),
    ("scene", &["formats", "gpu", "headless", "app", "wgpu", "egui", "eframe", "rfd"]),
    ("gpu", &["formats", "headless", "app", "demo", "egui", "eframe", "rfd"]),
    ("headless", &["formats", "app", "egui", "eframe", "rfd"]),
    ("info.rs", &["gpu", "headless", "app", "wgpu", "egui", "eframe"]),
];

fn rust_files(path: &Path, out: &mut Vec<std::path::PathBuf>) {
    if path.is_dir() {
        for e in std::fs::read_dir(path).unwrap() {
            rust_files(&e.unwrap().path(), out);
        }
    } else if path.extension().is_some_and(|e| e == "rs") {
        out.push(path.to_path_buf());
    }
}

fn names(line: &str, module: &str) -> bool {
    let l = line.trim_start();
    if l.starts_with("//") {
        return false;
    }
    [format!("crate::{module}"), format!("{module}::"), format!("super::super::{module}")].iter().any(|pat| {
        l.match_indices(pat.as_str()).any(|(i, _)| {
            // Only whole path segments: `crate::gpu` but not `my_gpu::`.
            i == 0 || !l.as_bytes()[i - 1].is_ascii_alphanumeric() && l.as_bytes()[i - 1] != b'_'
        })
    })
}

#[test]
fn layers_import_only_downwards() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut violations = Vec::new();
    for (layer, forbidden) in RULES {
        let mut files = Vec::new();
        rust_files(&src.join(layer), &mut files);
        assert!(!files.is_empty(), "layer {layer} has no files");
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (n, line) in text.lines().enumerate() {
                for m in *forbidden {
                    if names(line, m) {
                        violations.push(format!("{}:{}: {layer} names {m}: {}", f.display(), n + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(violations.is_empty(), "layering violations:\n{}", violations.join("\n"));
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
