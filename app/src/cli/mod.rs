//! The subcommands of `helical-gear`, one module each, and what they share: the common
//! arguments ([`Common`]: `--params FILE`, `--json`), the drive line of the commands that use
//! it ([`DriveArg`]: `--drive FILE`) and the loading of both.

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

/// The gear pair of `--params` (JSON in the schema of [`GearPair`]), or the paper's Table 1;
/// the error names the file.
pub fn load_params(common: &Common) -> Result<GearPair, String> {
    match &common.params {
        None => Ok(GearPair::paper_table1()),
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            GearPair::from_json(&text)
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
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            DriveLine::from_json(&text).map_err(|e| format!("{}: {e}", path.display()))?
        }
    };
    d.check().map_err(|e| e.to_string())?;
    Ok(d)
}
