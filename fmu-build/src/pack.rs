//! Packing of one FMU per model (a zip archive with the FMI 2.0 layout).
//!
//! ```text
//! modelDescription.xml
//! binaries/<platform>/<modelIdentifier>.<so|dylib|dll>  the one cdylib, renamed to the model
//!                                                      identifier (one entry per platform: the
//!                                                      build machine's, and win64 when
//!                                                      cross-compiled)
//! documentation/index.html                             variables and conventions
//! resources/compliance_table1.json                    compliance data of the default pair
//!                                                      (also compiled in; not read at run time)
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use helical_gear_mesh::fmi2::model::ModelInfo;
use zip::CompressionMethod;
use zip::write::SimpleFileOptions;

/// FMI platform directory, file name of the built cdylib and extension of the FMU binary for
/// the platform this program was compiled for.
pub fn platform() -> Result<(&'static str, &'static str, &'static str), String> {
    match (std::env::consts::OS, std::env::consts::ARCH) {
        ("linux", "x86_64") => Ok(("linux64", "libhelical_gear_mesh.so", "so")),
        ("macos", "x86_64") => Ok(("darwin64", "libhelical_gear_mesh.dylib", "dylib")),
        ("windows", "x86_64") => Ok(("win64", "helical_gear_mesh.dll", "dll")),
        (os, arch) => Err(format!("no FMI 2.0 platform name for {os}/{arch}")),
    }
}

/// FMI platform directory of the Windows DLL cross-compiled for `x86_64-pc-windows-gnu`.
pub const WIN64_DIR: &str = "win64";
/// File name of the cdylib built for `x86_64-pc-windows-gnu`.
pub const WIN64_LIB: &str = "helical_gear_mesh.dll";

/// Extension of the shared library in the FMI platform directory `dir`.
pub fn extension(dir: &str) -> Result<&'static str, String> {
    match dir {
        "linux64" | "linux32" => Ok("so"),
        "darwin64" => Ok("dylib"),
        "win64" | "win32" => Ok("dll"),
        other => Err(format!("unknown FMI 2.0 platform directory `{other}`")),
    }
}

/// One built shared library: FMI platform directory (`linux64`, `win64` …) and the file.
#[derive(Debug, Clone)]
pub struct Binary {
    /// Platform directory under `binaries/`.
    pub platform: String,
    /// The built cdylib.
    pub file: PathBuf,
}

/// One file of the archive: path inside the FMU and contents.
pub struct Entry {
    /// Path inside the archive (forward slashes).
    pub path: String,
    /// File contents.
    pub bytes: Vec<u8>,
}

/// Everything that goes into the FMU of `model` besides the binaries.
pub fn entries(model: &ModelInfo, resources: &[(String, Vec<u8>)]) -> Vec<Entry> {
    let mut e = vec![
        Entry {
            path: "modelDescription.xml".into(),
            bytes: crate::model_description::model_description_xml(model).into_bytes(),
        },
        Entry {
            path: "documentation/index.html".into(),
            bytes: crate::docs::index_html(model).into_bytes(),
        },
    ];
    e.extend(
        resources
            .iter()
            .map(|(name, bytes)| Entry { path: format!("resources/{name}"), bytes: bytes.clone() }),
    );
    e
}

/// Writes the FMU of `model` to `out` with the given binaries (the same library for every
/// model, stored as `binaries/<platform>/<modelIdentifier>.<ext>`).
pub fn pack(
    model: &ModelInfo,
    binaries: &[Binary],
    resources: &[(String, Vec<u8>)],
    out: &Path,
) -> Result<(), String> {
    if let Some(parent) = out.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    let mut all = entries(model, resources);
    for b in binaries {
        let bytes =
            std::fs::read(&b.file).map_err(|e| format!("reading {}: {e}", b.file.display()))?;
        let ext = extension(&b.platform)?;
        all.push(Entry {
            path: format!("binaries/{}/{}.{ext}", b.platform, model.identifier),
            bytes,
        });
    }
    let file = std::fs::File::create(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let opts = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .compression_level(Some(9));
    let z = |e: zip::result::ZipError| format!("writing {}: {e}", out.display());
    for e in all {
        zip.start_file(e.path.as_str(), opts.unix_permissions(0o644)).map_err(z)?;
        zip.write_all(&e.bytes).map_err(|err| format!("writing {}: {err}", out.display()))?;
    }
    zip.finish().map_err(z)?;
    Ok(())
}
