//! `fmu-build`: builds the `helical_gear_mesh` cdylib in release mode and packs one FMU per
//! model, `target/fmu/<modelIdentifier>.fmu`, each with the same library; with
//! `--write-generated` it rewrites the generated, checked-in files instead (model
//! descriptions, C headers, README variable tables).

use std::path::PathBuf;
use std::process::{Command, ExitCode};

use fmu_build::pack::Binary;
use fmu_build::{generated_files, pack, resources, workspace_root};
use helical_gear_mesh::fmi2::models::MODELS;

const USAGE: &str = "usage: fmu-build [--write-generated]\n\
    \n  (no argument)       cargo build --release the cdylib, write target/fmu/<model>.fmu for\
    \n                      every model (HelicalGearMesh, HelicalGearPair, HelicalGearStage,\
    \n                      HelicalGearDrive)\
    \n  --write-generated   rewrite modelDescription/<model>/modelDescription.xml, include/*.h\
    \n                      and the README's FMU variable tables from the Rust sources";

fn write_generated() -> Result<(), String> {
    let root = workspace_root();
    for (path, text) in generated_files()? {
        let p = root.join(&path);
        let old = std::fs::read_to_string(&p).unwrap_or_default();
        if old != text {
            if let Some(dir) = p.parent() {
                std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            }
            std::fs::write(&p, text).map_err(|e| format!("{}: {e}", p.display()))?;
            eprintln!("fmu-build: wrote {path}");
        } else {
            eprintln!("fmu-build: {path} is current");
        }
    }
    Ok(())
}

fn build_and_pack() -> Result<Vec<PathBuf>, String> {
    let root = workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let status = Command::new(cargo)
        .current_dir(&root)
        .args(["build", "--release", "-p", "helical_gear_mesh", "--lib"])
        .status()
        .map_err(|e| format!("could not run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build failed with {status}"));
    }
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    let (dir, lib_name, _) = pack::platform()?;
    let binaries =
        vec![Binary { platform: dir.to_string(), file: target.join("release").join(lib_name) }];
    let resources = resources()?;
    let mut written = Vec::new();
    for m in MODELS {
        let out = target.join("fmu").join(format!("{}.fmu", m.identifier));
        pack::pack(m, &binaries, &resources, &out)?;
        written.push(out);
    }
    Ok(written)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        [] => build_and_pack().map(|ps| {
            for p in ps {
                eprintln!("fmu-build: wrote {}", p.display());
            }
        }),
        ["--write-generated"] => write_generated(),
        ["-h" | "--help"] => {
            println!("{USAGE}");
            Ok(())
        }
        _ => Err(format!("unknown arguments {args:?}\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmu-build: {e}");
            ExitCode::FAILURE
        }
    }
}
