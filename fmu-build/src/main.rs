//! `fmu-build`: builds the `helical_gear_mesh` cdylib in release mode.
//!
//! Packing `target/fmu/HelicalGearMesh.fmu` (binary, modelDescription.xml, resources,
//! documentation) is added together with the FMI entry points.

use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let status = Command::new(cargo)
        .args(["build", "--release", "-p", "helical_gear_mesh", "--lib"])
        .status();
    match status {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("fmu-build: cargo build failed with {s}");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("fmu-build: could not run cargo: {e}");
            ExitCode::FAILURE
        }
    }
}
