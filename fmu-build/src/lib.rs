//! `fmu-build`: generates the files derived from the library's FMI variable table and packs the
//! FMU.
//!
//! * [`model_description`] — `modelDescription/<modelIdentifier>/modelDescription.xml`;
//! * [`docs`] — the FMU reference pages `docs/fmu/*.md` (one per model, the shared parameters,
//!   an index) and each FMU's `documentation/index.html`;
//! * [`headers`] — the C headers in `include/` (cbindgen) and the value-reference headers
//!   `include/fmi2_models/<modelIdentifier>.h`;
//! * [`parameters`] — `docs/parameters.md`, the parameter reference of every interface (JSON
//!   key, FMI name, Python keyword, ISO symbol, unit, default, range, meaning);
//! * [`pack`] — `target/fmu/<modelIdentifier>.fmu` for every model of the family, each with
//!   the same shared library under its model identifier.
//!
//! The checked-in generated files are compared with what this crate generates by the tests in
//! `fmu-build/tests/`; `cargo run -p fmu-build -- --write-generated` rewrites them.

pub mod docs;
pub mod headers;
pub mod model_description;
pub mod pack;
pub mod parameters;

use std::path::PathBuf;

use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::MODELS;

/// Path of the checked-in model description of `model`, relative to the workspace root.
pub fn model_description_path(model: &ModelInfo) -> String {
    format!("modelDescription/{}/modelDescription.xml", model.identifier)
}

/// The workspace root (parent of this crate's directory).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("fmu-build is in the workspace")
        .into()
}

/// Every generated, checked-in file: path relative to the workspace root and current text.
pub fn generated_files() -> Result<Vec<(String, String)>, String> {
    let root = workspace_root();
    let mut files = Vec::new();
    for m in MODELS {
        files.push((model_description_path(m), model_description::model_description_xml(m)));
        files.push((headers::vr_header_path(m), headers::vr_header(m)));
    }
    files.push((headers::CAPI_HEADER.into(), headers::capi_header(&root)?));
    files.push((headers::FMI2_HEADER.into(), headers::fmi2_header(&root)?));
    files.extend(docs::pages());
    files.push((parameters::PAGE.into(), parameters::parameters_page()?));
    Ok(files)
}

/// Files of the repository's `resources/` that go into the FMU's `resources/`.
pub const RESOURCE_FILES: &[&str] = &["compliance_table1.json"];

/// Resource files of the FMU: name inside `resources/` and contents. The compliance data of
/// the default gear pair is the same checked-in file that the library compiles in; the FMU
/// carries it for reference (provenance, inspection) and never reads it at run time.
pub fn resources() -> Result<Vec<(String, Vec<u8>)>, String> {
    let dir = workspace_root().join("resources");
    RESOURCE_FILES
        .iter()
        .map(|name| {
            let p = dir.join(name);
            std::fs::read(&p)
                .map(|b| (name.to_string(), b))
                .map_err(|e| format!("reading {}: {e}", p.display()))
        })
        .collect()
}
