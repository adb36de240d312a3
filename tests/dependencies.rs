//! The model library links only the model: its normal dependency closure (what the FMUs, the C
//! API and every program linking the library carry) holds no command-line or plotting crate,
//! and it embeds no font or documentation file. The applications (`app/`: the `helical-gear`
//! CLI, the paper run, the benchmark, the figures) carry those.
//!
//! The closure is read from `cargo metadata --format-version 1` (the resolved graph of the
//! lock file, offline): from the `helical_gear_mesh` node, every dependency edge of kind
//! "normal" (not dev, not build), transitively. The resolve unifies features over the whole
//! workspace, so the closure can only be larger than the library's own: the check errs on the
//! safe side.
//!
//! The graph is read for the host platform only (`--filter-platform`, the host triple of
//! `rustc -vV`): a build downloads only the host's crates, and without the filter `cargo
//! metadata --offline` needs the manifest of every platform's crates (Windows-only ones
//! among them), which a fresh cargo home that has only built for the host does not hold.
//! With `HGM_HOST_ONLY_CARGO_HOME` set (`./test.sh` sets it to a cargo home into which only
//! `cargo fetch --target <host>` has downloaded), the metadata is read from that home, so the
//! check fails wherever it would need a crate that a fresh machine does not have.

use std::collections::{BTreeSet, HashMap};
use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// Crates that belong to the applications, never to the model library.
const FORBIDDEN: [&str; 5] = ["clap", "plotters", "ab_glyph", "image", "png"];

/// The host's target triple (`host:` of `rustc -vV`).
fn host_triple() -> String {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".to_string());
    let out = Command::new(rustc).arg("-vV").output().expect("run rustc -vV");
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines()
        .find_map(|l| l.strip_prefix("host: "))
        .map(|h| h.trim().to_string())
        .expect("`host:` line in rustc -vV")
}

/// Names of the packages in the normal dependency closure of `helical_gear_mesh`.
fn normal_closure() -> BTreeSet<String> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let mut cmd = Command::new(cargo);
    cmd.args(["metadata", "--format-version", "1", "--offline", "--locked"])
        .args(["--filter-platform", &host_triple(), "--manifest-path"])
        .arg(&manifest);
    if let Some(home) = std::env::var_os("HGM_HOST_ONLY_CARGO_HOME") {
        cmd.env("CARGO_HOME", home);
    }
    let out = cmd.output().expect("run cargo metadata");
    assert!(out.status.success(), "cargo metadata: {}", String::from_utf8_lossy(&out.stderr));
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata JSON");
    let names: HashMap<&str, &str> = meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .map(|p| (p["id"].as_str().unwrap(), p["name"].as_str().unwrap()))
        .collect();
    let nodes: HashMap<&str, &Value> = meta["resolve"]["nodes"]
        .as_array()
        .expect("resolve.nodes")
        .iter()
        .map(|n| (n["id"].as_str().unwrap(), n))
        .collect();
    let root = names
        .iter()
        .find(|(_, name)| **name == "helical_gear_mesh")
        .map(|(id, _)| *id)
        .expect("helical_gear_mesh in the workspace");
    let mut seen = BTreeSet::new();
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        if !seen.insert(id) {
            continue;
        }
        for dep in nodes[id]["deps"].as_array().into_iter().flatten() {
            let normal =
                dep["dep_kinds"].as_array().into_iter().flatten().any(|k| k["kind"].is_null());
            if normal {
                stack.push(dep["pkg"].as_str().unwrap());
            }
        }
    }
    seen.iter().filter(|id| **id != root).map(|id| names[id].to_string()).collect()
}

#[test]
fn core_dependency_closure_has_no_cli_or_plotting_crates() {
    let closure = normal_closure();
    // The closure was read at all: the model's own dependencies are in it.
    for needed in ["faer", "nalgebra", "serde_json"] {
        assert!(closure.contains(needed), "{needed} missing from {closure:?}");
    }
    let found: Vec<_> = FORBIDDEN.iter().filter(|c| closure.contains(**c)).collect();
    assert!(
        found.is_empty(),
        "the model library's normal dependencies include {found:?}; they belong to app/"
    );
}

/// Every file the library embeds (`include_bytes!`/`include_str!` under `src/`) is model data
/// from `resources/`: no font, no documentation file.
#[test]
fn core_embeds_only_model_data() {
    fn visit(dir: &Path, bad: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                visit(&path, bad);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                for line in text.lines() {
                    let embeds = line.contains("include_bytes!(") || line.contains("include_str!(");
                    if embeds && !line.contains("resources/") {
                        bad.push(format!("{}: {}", path.display(), line.trim()));
                    }
                }
            }
        }
    }
    let mut bad = Vec::new();
    visit(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut bad);
    assert!(bad.is_empty(), "the library embeds files other than resources/: {bad:#?}");
}
