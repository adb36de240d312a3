//! The subcommands of `helical-gear`, one module each, and what they share: the common
//! arguments ([`Common`]: `--params FILE`, `--json`) and the loading of the parameters.

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
