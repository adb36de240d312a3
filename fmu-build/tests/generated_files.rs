//! The checked-in generated files (model description, C headers, FMU reference pages) must
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

/// Every variable of every model is on exactly one page: the model's own page or, when all
/// models share it, `docs/fmu/parameters.md`; the model pages link the shared page.
#[test]
fn every_variable_is_on_its_model_page_or_the_shared_parameters_page() {
    use fmu_build::docs::{model_page, parameters_page, shared_variables};
    use helical_gear_mesh::fmi2::models::MODELS;
    let shared = shared_variables();
    assert!(shared.iter().any(|v| v.name == "d_mesh"), "the gear-pair parameters are shared");
    assert!(!shared.iter().any(|v| v.name == "phi_p"), "inputs are each model's own");
    let params = parameters_page();
    for m in MODELS {
        let page = model_page(m);
        assert!(page.contains("(parameters.md)"), "{}", m.identifier);
        for v in m.variables {
            let cell = format!("| `{}` | {} |", v.name, v.vr);
            let (on_page, on_shared) = (page.matches(&cell).count(), params.matches(&cell).count());
            assert_eq!(on_page + on_shared, 1, "{}: {} on one page", m.identifier, v.name);
            assert_eq!(on_shared == 1, shared.iter().any(|s| s.name == v.name));
        }
    }
}

/// The C API's structs and enums are the library's `#[repr(C)]` types under their C names:
/// every type the header defines is one of `headers::CAPI_TYPES` (or the status and opaque
/// handles of `capi.rs`), and `capi.rs` itself defines no `#[repr(C)]` struct that could drift
/// from the library's. Together with `checked_in_generated_files_are_current` this holds the
/// header's structs to the library's field for field.
#[test]
fn c_api_structs_are_the_library_types() {
    use fmu_build::headers::{CAPI_TYPES, capi_header};
    let root = fmu_build::workspace_root();
    let header = capi_header(&root).expect("header generates");
    let c_names: Vec<&str> = CAPI_TYPES.iter().map(|(_, c)| *c).collect();
    let mut defined = Vec::new();
    for line in header.lines() {
        if let Some(name) = line.strip_prefix("} ").and_then(|r| r.strip_suffix(';')) {
            defined.push(name.to_string());
        }
    }
    for name in &defined {
        assert!(
            name == "HgmStatus" || c_names.contains(&name.as_str()),
            "the header defines `{name}`, which is not one of the library's types"
        );
    }
    for c in &c_names {
        assert!(defined.iter().any(|d| d == c), "the header lacks `{c}`");
    }
    let capi = std::fs::read_to_string(root.join("src/capi.rs")).unwrap();
    assert_eq!(
        capi.lines().filter(|l| l.starts_with("#[repr(C)]")).count(),
        1,
        "capi.rs defines a C type besides HgmStatus (the C API's types are the library's)"
    );
    // The layouts cbindgen wrote are the ones Rust uses (no field or padding lost).
    use helical_gear_mesh::dynamics::{UnitInputRates, UnitInputs, UnitOutputs};
    use helical_gear_mesh::mesh::MeshOutputs;
    use std::mem::{offset_of, size_of};
    assert_eq!(size_of::<UnitInputs>(), 7 * 8);
    assert_eq!(size_of::<UnitInputRates>(), 5 * 8);
    assert_eq!(offset_of!(MeshOutputs, n_pairs), 8 * 8);
    assert_eq!(offset_of!(MeshOutputs, back_contact), 8 * 8 + 4 + 2);
    assert_eq!(offset_of!(UnitOutputs, t), 0);
    assert_eq!(offset_of!(UnitOutputs, mesh), (15 + 8) * 8);
    assert!(header.contains("double dydt[HGM_N_STATES];"));
    assert!(header.contains("HgmOutputs mesh;"));
}

/// The header's `HgmOutputs` has exactly the fields of the core's one table of the mesh
/// outputs (`mesh::outputs::MESH_OUTPUT_FIELDS`), in its order, each commented with the
/// table's unit; `HgmUnitOutputs` has the scalar fields of `dynamics::unit::UNIT_OUTPUT_FIELDS`.
#[test]
fn c_output_structs_follow_the_core_output_tables() {
    use fmu_build::headers::capi_header;
    use helical_gear_mesh::dynamics::unit::UNIT_OUTPUT_FIELDS;
    use helical_gear_mesh::mesh::outputs::MESH_OUTPUT_FIELDS;
    let header = capi_header(&fmu_build::workspace_root()).expect("header generates");
    // (member as written, e.g. `force_p[3]`, and the comment block above it) of `name`.
    let members = |name: &str| -> Vec<(String, String)> {
        let end = header.find(&format!("}} {name};")).unwrap_or_else(|| panic!("{name}"));
        let start = header[..end].rfind("typedef struct").expect("struct start");
        let (mut out, mut comment) = (Vec::new(), String::new());
        for line in header[start..end].lines().skip(1) {
            let t = line.trim();
            if t.starts_with("/*") || t.starts_with('*') {
                comment.push_str(t);
                comment.push(' ');
            } else if let Some(decl) = t.strip_suffix(';') {
                let member = decl.rsplit(' ').next().unwrap().to_string();
                out.push((member, std::mem::take(&mut comment)));
            }
        }
        out
    };
    // The table's fields, arrays folded back into their C member (`force_p[0]` .. `[2]`).
    let mut expected: Vec<(String, &str)> = Vec::new();
    for f in &MESH_OUTPUT_FIELDS {
        let base = f.c_field.split('[').next().unwrap();
        match expected.last_mut() {
            Some((m, _)) if m.split('[').next() == Some(base) => {
                let n = f.c_field[base.len() + 1..f.c_field.len() - 1].parse::<usize>().unwrap();
                *m = format!("{base}[{}]", n + 1);
            }
            _ if f.c_field.contains('[') => expected.push((format!("{base}[1]"), f.unit)),
            _ => expected.push((f.c_field.to_string(), f.unit)),
        }
    }
    let got = members("HgmOutputs");
    let got_names: Vec<&str> = got.iter().map(|(m, _)| m.as_str()).collect();
    let want_names: Vec<&str> = expected.iter().map(|(m, _)| m.as_str()).collect();
    assert_eq!(got_names, want_names, "HgmOutputs against MESH_OUTPUT_FIELDS");
    for ((member, comment), (_, unit)) in got.iter().zip(&expected) {
        if !unit.is_empty() {
            let dotted = unit.replace('.', "·");
            assert!(
                comment.contains(&format!(" {dotted}")) || comment.contains(&format!(" {unit}")),
                "the comment of HgmOutputs.{member} does not give its unit {unit}: {comment}"
            );
        }
    }
    let unit_members = members("HgmUnitOutputs");
    for (name, _, _) in &UNIT_OUTPUT_FIELDS {
        assert!(unit_members.iter().any(|(m, _)| m == name), "HgmUnitOutputs lacks `{name}`");
    }
    let scalars = unit_members.iter().filter(|(m, _)| !m.contains('[') && m != "mesh").count();
    assert_eq!(scalars, UNIT_OUTPUT_FIELDS.len(), "HgmUnitOutputs has scalars not in the table");
}

/// Every model description names the author, copyright and licence, and the licence it names
/// is the one of the repository's licence files (and of the Python package's copies of them).
#[test]
fn model_descriptions_carry_author_copyright_and_licence() {
    use fmu_build::model_description::{AUTHOR, COPYRIGHT, LICENSE};
    use helical_gear_mesh::fmi2::models::MODELS;
    for m in MODELS {
        let xml = fmu_build::model_description::model_description_xml(m);
        for (attr, value) in [("author", AUTHOR), ("copyright", COPYRIGHT), ("license", LICENSE)] {
            assert!(xml.contains(&format!(" {attr}=\"{value}\"")), "{}: {attr}", m.identifier);
        }
    }
    let root = fmu_build::workspace_root();
    let read = |p: &str| {
        std::fs::read_to_string(root.join(p)).unwrap_or_else(|e| panic!("cannot read {p}: {e}"))
    };
    assert_eq!(LICENSE, "MIT OR Apache-2.0");
    assert!(read("LICENSE-MIT").contains(AUTHOR));
    assert!(read("LICENSE-APACHE").contains("Apache License"));
    for f in ["LICENSE-MIT", "LICENSE-APACHE"] {
        assert_eq!(read(f), read(&format!("python/{f}")), "python/{f} differs from {f}");
    }
}

/// The documentation inside each FMU names exactly the drive-line parameters (`drive.*`) of
/// its model, and says so when it has none (the mesh element: the master holds the drive line).
#[test]
fn fmu_documentation_names_the_models_own_drive_parameters() {
    use helical_gear_mesh::fmi2::models::MODELS;
    let drive = |m: &helical_gear_mesh::fmi2::model::ModelInfo| -> Vec<&str> {
        m.variables.iter().map(|v| v.name).filter(|n| n.starts_with("drive.")).collect()
    };
    let all: Vec<&str> = MODELS.iter().flat_map(|m| drive(m)).collect();
    for m in MODELS {
        let html = fmu_build::docs::index_html(m);
        let own = drive(m);
        for name in &all {
            let said = html.contains(&format!("<code>{name}</code>"));
            assert_eq!(said, own.contains(name), "{}: {name}", m.identifier);
        }
        if own.is_empty() {
            assert!(html.contains("carries no drive-line parameter"), "{}", m.identifier);
        }
        assert!(
            !html.contains("darwin64"),
            "{}: a platform fmu-build does not build",
            m.identifier
        );
    }
}
