//! Replays every kept fuzz input: each file of `fuzz/corpus/<target>/` through the same
//! function the fuzz target `<target>` runs (`tests/fuzz_harness/mod.rs`), so every input the
//! fuzzer ever kept stays a regression test on stable Rust. Inputs that still expose a known
//! defect live under `fuzz/artifacts-known/` instead and are not replayed here.

mod fuzz_harness;

use std::path::Path;

/// Runs `f` on every file of `fuzz/corpus/<target>/`; returns how many there were.
/// A file that takes over a second is named on stderr (`--nocapture`), as a hint to minimise.
fn replay(target: &str, f: fn(&[u8])) -> usize {
    // FUZZ_CORPUS=DIR replays DIR/<target>/ instead (e.g. fuzz/artifacts-known).
    let base = std::env::var_os("FUZZ_CORPUS").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus"),
        std::path::PathBuf::from,
    );
    let dir = base.join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else { return 0 };
    let mut files: Vec<_> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
    files.sort();
    for path in &files {
        let data = std::fs::read(path).expect("corpus file reads");
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let started = std::time::Instant::now();
        let r = std::panic::catch_unwind(|| f(&data));
        let took = started.elapsed().as_secs_f64();
        if took > 1.0 {
            eprintln!("fuzz/corpus/{target}/{name}: {took:.1} s");
        }
        if let Err(p) = r {
            std::panic::resume_unwind(Box::new(format!(
                "fuzz/corpus/{target}/{name}: {}",
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            )));
        }
    }
    files.len()
}

#[test]
fn corpus_gear_pair_json_replays_clean() {
    replay("gear_pair_json", fuzz_harness::gear_pair_json);
}

#[test]
fn corpus_mesh_evaluate_replays_clean() {
    replay("mesh_evaluate", fuzz_harness::mesh_evaluate);
}

#[test]
fn corpus_capi_replays_clean() {
    replay("capi", fuzz_harness::capi);
}

#[test]
fn corpus_fmi2_calls_replays_clean() {
    replay("fmi2_calls", fuzz_harness::fmi2_calls);
}
