//! The checked-in generated files (model description, C headers, README variable table) must
//! equal what the code generates now.

#[test]
fn checked_in_generated_files_are_current() {
    let root = fmu_build::workspace_root();
    let mut stale = Vec::new();
    for (path, text) in fmu_build::generated_files().expect("generation succeeds") {
        let on_disk = std::fs::read_to_string(root.join(path)).unwrap_or_default();
        if on_disk != text {
            let line = on_disk
                .lines()
                .zip(text.lines())
                .position(|(a, b)| a != b)
                .map_or_else(|| "length".to_string(), |i| format!("line {}", i + 1));
            stale.push(format!("{path} (first difference: {line})"));
        }
    }
    assert!(
        stale.is_empty(),
        "generated files are stale: {}; regenerate with `cargo run -p fmu-build -- \
         --write-generated` and commit",
        stale.join(", ")
    );
}

#[test]
fn model_description_lists_every_variable_once_with_its_value_reference() {
    use helical_gear_mesh::fmi2::variables::{VARIABLES, guid};
    let xml = fmu_build::model_description::model_description_xml();
    assert!(xml.contains(&format!("guid=\"{}\"", guid())));
    for v in VARIABLES {
        let needle = format!("name=\"{}\" valueReference=\"{}\"", v.name, v.vr);
        assert_eq!(xml.matches(&needle).count(), 1, "{needle}");
    }
    assert_eq!(xml.matches("<ScalarVariable ").count(), VARIABLES.len());
}

#[test]
fn readme_table_replacement_needs_both_markers() {
    use fmu_build::docs::{README_BEGIN, README_END, readme_with_table};
    assert!(readme_with_table("no markers").is_err());
    let text = format!("a\n{README_BEGIN}\nold\n{README_END}\nb\n");
    let new = readme_with_table(&text).unwrap();
    assert!(new.starts_with("a\n") && new.ends_with(&format!("{README_END}\nb\n")));
    assert!(new.contains("| `phi_p` |") && !new.contains("old"));
    assert_eq!(readme_with_table(&new).unwrap(), new, "idempotent");
}
