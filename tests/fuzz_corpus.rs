//! Replays every kept fuzz input: each file of `fuzz/corpus/<target>/` through the same
//! function the fuzz target `<target>` runs (`tests/fuzz_harness/mod.rs`), so every input the
//! fuzzer ever kept stays a regression test on stable Rust, the inputs of every defect the
//! fuzzers found included.

mod fuzz_harness;

use std::path::Path;

/// Runs `f` on every file of `fuzz/corpus/<target>/`; asserts there was at least one (a moved
/// corpus must not pass by replaying nothing).
/// A file that takes over a second is named on stderr (`--nocapture`), as a hint to minimise.
fn replay(target: &str, f: fn(&[u8])) {
    // FUZZ_CORPUS=DIR replays DIR/<target>/ instead (e.g. fuzz/artifacts-known).
    let chosen = std::env::var_os("FUZZ_CORPUS");
    let base = chosen.as_ref().map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus"),
        std::path::PathBuf::from,
    );
    let dir = base.join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        assert!(chosen.is_some(), "no corpus at {}", dir.display());
        return;
    };
    let mut files: Vec<_> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
    files.sort();
    for path in &files {
        let data = std::fs::read(path).expect("corpus file reads");
        let started = std::time::Instant::now();
        let r = std::panic::catch_unwind(|| f(&data));
        let took = started.elapsed().as_secs_f64();
        if took > 1.0 {
            eprintln!("{}: {took:.1} s", path.display());
        }
        if let Err(p) = r {
            std::panic::resume_unwind(Box::new(format!(
                "{}: {}",
                path.display(),
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            )));
        }
    }
    assert!(chosen.is_some() || !files.is_empty(), "empty corpus at {}", dir.display());
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
