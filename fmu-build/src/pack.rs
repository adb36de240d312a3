//! Packing of `HelicalGearMesh.fmu` (a zip archive with the FMI 2.0 layout).
//!
//! ```text
//! modelDescription.xml
//! binaries/<platform>/HelicalGearMesh.<so|dylib|dll>   the cdylib, renamed to the model identifier
//!                                                      (the build machine's platform, and win64
//!                                                      when cross-compiled)
//! documentation/index.html                             variables and conventions
//! resources/compliance_table1.json                    compliance data of the default pair
//!                                                      (also compiled in; not read at run time)
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use helical_gear_mesh::fmi2::variables::MODEL_IDENTIFIER;
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

/// File extension of the FMU binary in FMI platform directory `dir`.
pub fn extension(dir: &str) -> Result<&'static str, String> {
    match dir {
        "linux64" | "linux32" => Ok("so"),
        "darwin64" => Ok("dylib"),
        "win64" | "win32" => Ok("dll"),
        other => Err(format!("unknown FMI platform directory `{other}`")),
    }
}

/// One file of the archive: path inside the FMU and contents.
pub struct Entry {
    /// Path inside the archive (forward slashes).
    pub path: String,
    /// File contents.
    pub bytes: Vec<u8>,
}

/// Everything that goes into the FMU besides the binary.
pub fn entries(resources: Vec<(String, Vec<u8>)>) -> Vec<Entry> {
    let mut e = vec![
        Entry {
            path: "modelDescription.xml".into(),
            bytes: crate::model_description::model_description_xml().into_bytes(),
        },
        Entry {
            path: "documentation/index.html".into(),
            bytes: crate::docs::index_html().into_bytes(),
        },
    ];
    e.extend(
        resources
            .into_iter()
            .map(|(name, bytes)| Entry { path: format!("resources/{name}"), bytes }),
    );
    e
}

/// The FMU entries `binaries/<dir>/<MODEL_IDENTIFIER>.<ext>` of `binaries`, each a FMI platform
/// directory and the built cdylib for it.
pub fn binary_entries(binaries: &[(&str, PathBuf)]) -> Result<Vec<Entry>, String> {
    binaries
        .iter()
        .map(|(dir, file)| {
            let bytes =
                std::fs::read(file).map_err(|e| format!("reading {}: {e}", file.display()))?;
            let ext = extension(dir)?;
            Ok(Entry { path: format!("binaries/{dir}/{MODEL_IDENTIFIER}.{ext}"), bytes })
        })
        .collect()
}

/// Writes the FMU to `out` with `binaries`: FMI platform directory and built cdylib of each
/// platform the FMU carries.
pub fn pack(
    binaries: &[(&str, PathBuf)],
    resources: Vec<(String, Vec<u8>)>,
    out: &Path,
) -> Result<(), String> {
    let bins = binary_entries(binaries)?;
    if let Some(parent) = out.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    let file = std::fs::File::create(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let opts = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    let z = |e: zip::result::ZipError| format!("writing {}: {e}", out.display());
    let mut all = entries(resources);
    all.extend(bins);
    for e in all {
        zip.start_file(e.path.as_str(), opts.unix_permissions(0o644)).map_err(z)?;
        zip.write_all(&e.bytes).map_err(|err| format!("writing {}: {err}", out.display()))?;
    }
    zip.finish().map_err(z)?;
    Ok(())
}
