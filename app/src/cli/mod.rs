//! The subcommands of `helical-gear`, one module each, and what they share: the common
//! arguments ([`Common`]: `--params FILE`, `--json`), the drive line of the commands that use
//! it ([`DriveArg`]: `--drive FILE`), the mesh friction of the analyses that take it
//! ([`FrictionArg`]: `--friction FILE|none`) and the loading of them.

pub mod bench;
pub mod compliance;
pub mod contact;
pub mod dynamics;
pub mod geometry;
pub mod mods;
pub mod paper;
pub mod statics;

use clap::Args;
use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::Friction;
use helical_gear_mesh::params::DriveLine;

/// Arguments every subcommand takes.
#[derive(Args, Clone)]
pub struct Common {
    /// Gear-pair parameters as JSON (schema of `GearPair`); default: the paper's Table 1.
    #[arg(long, value_name = "FILE")]
    pub params: Option<std::path::PathBuf>,
    /// Print one JSON object on stdout instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Largest JSON file read for `--params`, `--drive`, `--bearings`, `--supports`, `--friction` and the
/// variants file,
/// bytes: 16 MiB, far above any parameter file (a few kB) and far below a runaway read
/// (`--params /dev/zero` read 4.2 GB before failing).
pub const MAX_JSON_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// The text of the JSON file `path` given as `option`; the error names the option and the
/// path and says what is wrong: no such file, a directory, more than [`MAX_JSON_FILE_BYTES`],
/// not UTF-8 text.
pub fn read_json_file(option: &str, path: &std::path::Path) -> Result<String, String> {
    use std::io::Read;
    let shown = path.display();
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(format!("{option} {shown}: no such file"));
        }
        Err(e) => return Err(format!("{option} {shown}: cannot read: {e}")),
    };
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(format!("{option} {shown}: is a directory, not a JSON file"));
    }
    let mut bytes = Vec::new();
    file.take(MAX_JSON_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{option} {shown}: cannot read: {e}"))?;
    if bytes.len() as u64 > MAX_JSON_FILE_BYTES {
        return Err(format!(
            "{option} {shown}: more than {MAX_JSON_FILE_BYTES} bytes (16 MiB), the most read \
             for a JSON file"
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{option} {shown}: not UTF-8 text (byte {}); a JSON file is UTF-8",
            e.utf8_error().valid_up_to()
        )
    })
}

/// The gear pair of `--params` (JSON in the schema of [`GearPair`]), or the paper's Table 1;
/// the error names the file.
pub fn load_params(common: &Common) -> Result<GearPair, String> {
    match &common.params {
        None => Ok(GearPair::paper_table1()),
        Some(path) => {
            let text = read_json_file("--params", path)?;
            GearPair::from_json(&text).map_err(|e| format!("--params {}: {e}", path.display()))
        }
    }
}

/// The drive line (torque, inertias, shafts) of the commands that use it or its torque.
#[derive(Args, Clone, Default)]
pub struct DriveArg {
    /// Drive line as JSON (schema of `DriveLine`: `torque_nm`, `j1_kgm2`, `j2_kgm2`,
    /// `c1_nm_per_rad`, `c2_nm_per_rad`, `d1_nms_per_rad`, `d2_nms_per_rad`; missing keys from
    /// Table 1); default: the paper's Table 1 drive line.
    #[arg(long, value_name = "FILE")]
    pub drive: Option<std::path::PathBuf>,
}

/// The drive line of `--drive` (JSON in the schema of [`DriveLine`], missing keys from Table
/// 1), or Table 1's; checked against its bounds. The error names the file.
pub fn load_drive(a: &DriveArg) -> Result<DriveLine, String> {
    let d = match &a.drive {
        None => DriveLine::paper_table1(),
        Some(path) => {
            let text = read_json_file("--drive", path)?;
            DriveLine::from_json(&text).map_err(|e| format!("{}: {e}", path.display()))?
        }
    };
    d.check().map_err(|e| e.to_string())?;
    Ok(d)
}

/// The mesh friction option of `static`, `simulate` and `sweep`.
#[derive(Args, Clone, Default)]
pub struct FrictionArg {
    /// Mesh friction: a JSON file `{"model": "none" | "constant" | "iso_tr_14179_2", "mu": …,
    /// "oil_viscosity_pa_s": …, "roughness_ra_m": …, "lubricant_factor": …,
    /// "regularisation_speed_m_s": …}` (every key optional, SI units; docs/friction.md), or
    /// `none`; default none, the paper's frictionless model.
    #[arg(long, value_name = "FILE|none")]
    pub friction: Option<std::path::PathBuf>,
}

/// The friction option of `--friction` (the JSON of [`Friction::from_json`], or `none`);
/// the error names the flag, the file and the bad key or value.
pub fn load_friction(a: &FrictionArg) -> Result<Friction, String> {
    match &a.friction {
        None => Ok(Friction::none()),
        Some(path) if path.as_os_str() == "none" => Ok(Friction::none()),
        Some(path) => read_json_as("--friction", path, Friction::from_json),
    }
}

/// The JSON file `path` of command-line option `option` read ([`read_json_file`]) and parsed
/// by `parse`; a parse error is given as `<option> <path>: <error>`.
pub fn read_json_as<T, E: std::fmt::Display>(
    option: &str,
    path: &std::path::Path,
    parse: impl FnOnce(&str) -> Result<T, E>,
) -> Result<T, String> {
    let text = read_json_file(option, path)?;
    parse(&text).map_err(|e| format!("{option} {}: {e}", path.display()))
}
