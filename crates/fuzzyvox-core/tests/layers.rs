//! The core's modules form layers: each uses only the layers below it (crate lines are enforced
//! by cargo; this test enforces the lines inside the core). See `docs/architecture.md`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::fs;
use std::path::Path;

/// The core's modules from the bottom up; a module may use the modules of lower layers only
/// (and `ops`, the operators crate, from anywhere).
const LAYERS: &[&[&str]] = &[
    &["class", "dispatch", "error"],
    &["measures", "geometry", "storage"],
    &["integrate", "image"],
    &["map"],
    &["file"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|layer| layer.contains(&module))
}

/// Every `crate::name` a source file's code (not its comments) names.
fn uses(source: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            out.push(name);
        }
    }
    out
}

fn sources(path: &Path, out: &mut Vec<std::path::PathBuf>) {
    if path.is_dir() {
        for entry in fs::read_dir(path).unwrap() {
            sources(&entry.unwrap().path(), out);
        }
    } else if path.is_file() && path.extension().is_some_and(|e| e == "rs") {
        out.push(path.to_path_buf());
    }
}

#[test]
fn every_module_uses_only_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut checked = 0;
    for module in LAYERS.iter().flat_map(|l| l.iter()) {
        let own = layer_of(module).unwrap();
        let mut files = Vec::new();
        sources(&src.join(module), &mut files);
        sources(&src.join(format!("{module}.rs")), &mut files);
        assert!(!files.is_empty(), "module {module} has no source");
        for file in files {
            let text = fs::read_to_string(&file).unwrap();
            for used in uses(&text) {
                if used == *module || used == "ops" {
                    continue;
                }
                let layer = layer_of(&used)
                    .unwrap_or_else(|| panic!("{}: crate::{used} is in no layer", file.display()));
                assert!(
                    layer < own,
                    "{} ({module}, layer {own}) uses crate::{used} (layer {layer})",
                    file.display()
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "only {checked} uses found");
}
