//! The checked-in generated files (model description, C headers, README variable table) must
//! equal what the code generates now.

#[test]
fn checked_in_generated_files_are_current() {
    let root = fmu_build::workspace_root();
    let mut stale = Vec::new();
    for (path, text) in fmu_build::generated_files().expect("generation succeeds") {
        let on_disk = std::fs::read_to_string(root.join(&path)).unwrap_or_default();
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
    use helical_gear_mesh::fmi2::models::MODELS;
    for m in MODELS {
        let xml = fmu_build::model_description::model_description_xml(m);
        assert!(xml.contains(&format!("guid=\"{}\"", m.guid())));
        assert!(xml.contains(&format!("modelIdentifier=\"{}\"", m.identifier)));
        for v in m.variables {
            let needle = format!("name=\"{}\" valueReference=\"{}\"", v.name, v.vr);
            assert_eq!(xml.matches(&needle).count(), 1, "{}: {needle}", m.identifier);
        }
        assert_eq!(xml.matches("<ScalarVariable ").count(), m.variables.len());
    }
}

#[test]
fn every_model_has_its_own_guid_and_identifier() {
    use helical_gear_mesh::fmi2::models::{MODELS, by_guid};
    for (i, a) in MODELS.iter().enumerate() {
        assert!(std::ptr::eq(by_guid(a.guid()).unwrap(), *a));
        for b in &MODELS[i + 1..] {
            assert_ne!(a.guid(), b.guid());
            assert_ne!(a.identifier, b.identifier);
        }
    }
}

#[test]
fn readme_table_replacement_needs_both_markers() {
    use fmu_build::docs::{readme_begin, readme_end, readme_with_table};
    use helical_gear_mesh::fmi2::models::mesh::INFO;
    assert!(readme_with_table("no markers", &INFO).is_err());
    let (begin, end) = (readme_begin(&INFO), readme_end(&INFO));
    let text = format!("a\n{begin}\nold\n{end}\nb\n");
    let new = readme_with_table(&text, &INFO).unwrap();
    assert!(new.starts_with("a\n") && new.ends_with(&format!("{end}\nb\n")));
    assert!(new.contains("| `phi_p` |") && !new.contains("old"));
    assert_eq!(readme_with_table(&new, &INFO).unwrap(), new, "idempotent");
}
