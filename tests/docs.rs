//! The documentation's links hold: every relative link in README.md, ARCHITECTURE.md and the
//! user guide (`docs/`, an mdBook) names a file that exists, and every `#anchor` a heading of
//! that file, as mdBook and GitHub make anchors of headings. The guide's table of contents names
//! every chapter in `docs/`.

use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The pages checked: README, ARCHITECTURE and each chapter of the guide.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![root().join("README.md"), root().join("ARCHITECTURE.md")];
    let mut chapters: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    chapters.sort();
    pages.extend(chapters);
    pages
}

/// Markdown outside code: fenced blocks and inline code spans removed.
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            let mut inside = false;
            out.extend(
                line.split('`')
                    .enumerate()
                    .filter(|_| {
                        inside = !inside;
                        inside
                    })
                    .map(|(_, part)| part),
            );
            out.push('\n');
        }
    }
    out
}

/// The links `[text](target)` whose target is a path or an anchor (not a web address, not a
/// formula in brackets).
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        let Some(end) = rest.find(')') else { break };
        let target = &rest[..end];
        let path_like = target.chars().all(|c| c.is_ascii_alphanumeric() || "./#-_".contains(c))
            && (target.starts_with('#') || target.contains('.'));
        if path_like && !target.starts_with("http") {
            out.push(target.to_string());
        }
    }
    out
}

/// A heading's anchor as mdBook and GitHub make it: lower case, letters, digits, `-` and `_`
/// kept, spaces to `-`, the rest dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            c if c.is_whitespace() => Some('-'),
            _ => None,
        })
        .collect()
}

fn anchors(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    prose(&text).lines().filter_map(|l| l.strip_prefix('#')).map(|h| anchor(h.trim_start_matches('#'))).collect()
}

#[test]
fn every_relative_link_names_a_file_and_a_heading_that_exist() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for target in links(&prose(&text)) {
            let (file, fragment) = target.split_once('#').unwrap_or((&target, ""));
            let path = if file.is_empty() { page.clone() } else { page.parent().unwrap().join(file) };
            if !path.exists() {
                broken.push(format!("{}: {target}: no such file", page.display()));
            } else if !fragment.is_empty()
                && path.extension().is_some_and(|e| e == "md")
                && !anchors(&path).contains(&fragment.to_string())
            {
                broken.push(format!("{}: {target}: no such heading", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_guide_s_contents_name_every_chapter() {
    let summary = std::fs::read_to_string(root().join("docs/SUMMARY.md")).unwrap();
    let named = links(&summary);
    for page in pages().iter().skip(2) {
        let name = page.file_name().unwrap().to_string_lossy().to_string();
        if name != "SUMMARY.md" {
            assert!(named.contains(&name), "docs/SUMMARY.md does not name {name}");
        }
    }
}

#[test]
fn anchors_follow_mdbook() {
    assert_eq!(anchor("The papers behind it"), "the-papers-behind-it");
    assert_eq!(anchor("Computing with PySCF"), "computing-with-pyscf");
    assert_eq!(anchor("Scans: Walsh diagrams (angle)"), "scans-walsh-diagrams-angle");
    assert_eq!(links("see [a](b.md#c) and [x](R·V) and [w](https://x.org)"), vec!["b.md#c".to_string()]);
}
