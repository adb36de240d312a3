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
