//! The generated documentation pages are current: `docs/performance.md` and the paper-run
//! section of `docs/validation.md`, rendered again from the checked-in reports
//! (`docs/bench/bench.json`, `docs/paper/summary.json`), equal the checked-in pages. No timing
//! run is needed; a stale page fails with the command that writes it.

use std::path::Path;

#[test]
fn generated_pages_match_their_reports() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let pages = helical_gear_app::pages::rendered_pages(&root).unwrap_or_else(|e| panic!("{e}"));
    for (path, expected) in pages {
        let actual = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        assert!(
            actual == expected,
            "{} is stale: regenerate it with `cargo run -p helical-gear-app --example measure -- \
             pages` (from the repository root)",
            path.display()
        );
    }
}

/// The performance page says first, in bold, when its report was measured with more than half
/// the cores busy (1-minute load average above cores/2), and not otherwise; it always states
/// the machine (cores, CPU) and the load.
#[test]
fn performance_page_marks_a_loaded_machine() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("docs/bench/bench.json")).unwrap();
    let mut bench: serde_json::Value = serde_json::from_str(&text).unwrap();
    let cores = bench["cores"].as_f64().unwrap();
    let cpu = bench["cpu"].as_str().unwrap().to_string();
    let mark = "**Measured on a loaded machine**";
    for (load1, marked) in [(0.5 * cores + 0.01, true), (0.5 * cores, false), (0.0, false)] {
        bench["load_average"] = format!("{load1} 0.00 0.00").into();
        let page = helical_gear_app::pages::performance_page(&bench).unwrap();
        assert_eq!(page.contains(mark), marked, "load {load1} on {cores} cores");
        if marked {
            let first = page.lines().find(|l| l.starts_with('>')).unwrap();
            assert!(first.contains(mark) && first.contains(&format!("{load1}")));
        }
        assert!(page.contains(&format!("{cores} cores ({cpu})")), "machine stated");
        assert!(page.contains(&format!("load average {load1} 0.00 0.00")), "load stated");
    }
    bench["load_average"] = "unknown".into();
    let page = helical_gear_app::pages::performance_page(&bench).unwrap();
    assert!(!page.contains(mark) && page.contains("load average unknown"));
}
