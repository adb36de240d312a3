//! `fmu-build`: builds the `helical_gear_mesh` cdylib in release mode and packs one FMU per
//! model, `target/fmu/<modelIdentifier>.fmu`, each with the same library; with
//! `--write-generated` it rewrites the generated, checked-in files instead (model
//! descriptions, C headers, the FMU reference pages in `docs/fmu/`).
//!
//! When the Rust target `x86_64-pc-windows-gnu` and the MinGW-w64 linker are installed, the
//! cdylib is also cross-compiled for Windows and every FMU carries `binaries/win64/` beside the
//! build machine's platform; otherwise one line says why win64 is skipped (an error with
//! `--require-win64` or `FMU_BUILD_REQUIRE_WIN64=1`).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use fmu_build::pack::Binary;
use fmu_build::{generated_files, pack, resources, workspace_root};
use helical_gear_mesh::fmi2::models::MODELS;

const USAGE: &str = "usage: fmu-build [--require-win64 | --write-generated]\n\
    \n  (no argument)       cargo build --release the cdylib, write target/fmu/<model>.fmu for\
    \n                      every model (HelicalGearMesh, HelicalGearPair, HelicalGearStage,\
    \n                      HelicalGearDrive, HelicalGearbox), with binaries/win64 when\
    \n                      x86_64-pc-windows-gnu and its MinGW-w64 linker are installed (else\
    \n                      a line saying why win64 is skipped)\
    \n  --require-win64     the same, but a missing win64 build is an error (also when the\
    \n                      environment variable FMU_BUILD_REQUIRE_WIN64 is 1)\
    \n  --write-generated   rewrite modelDescription/<model>/modelDescription.xml, include/*.h\
    \n                      the FMU reference pages docs/fmu/*.md and the parameter reference\n                      docs/parameters.md from the Rust sources";

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

/// Rust target triple of the Windows DLL.
const WIN64_TARGET: &str = "x86_64-pc-windows-gnu";
/// The MinGW-w64 linker named in `.cargo/config.toml` for [`WIN64_TARGET`].
const WIN64_LINKER: &str = "x86_64-w64-mingw32-gcc";

/// Runs `cargo build --release` of the library's cdylib with `extra` arguments.
fn cargo_build_lib(root: &Path, extra: &[&str]) -> Result<(), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let status = Command::new(cargo)
        .current_dir(root)
        .args(["build", "--release", "-p", "helical_gear_mesh", "--lib"])
        .args(extra)
        .status()
        .map_err(|e| format!("could not run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build {} failed with {status}", extra.join(" ")));
    }
    Ok(())
}

/// Why the Windows DLL cannot be cross-compiled here, or `None` when it can: the Rust standard
/// library for [`WIN64_TARGET`] must be installed and the linker [`WIN64_LINKER`] must run.
fn win64_unavailable() -> Option<String> {
    if pack::platform().is_ok_and(|(dir, _, _)| dir == pack::WIN64_DIR) {
        return Some("this machine builds win64 natively".into());
    }
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".to_string());
    let libdir = Command::new(rustc)
        .args(["--print", "target-libdir", "--target", WIN64_TARGET])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()));
    if !libdir.is_some_and(|d| d.is_dir()) {
        return Some(format!(
            "the Rust target {WIN64_TARGET} is not installed (`rustup target add {WIN64_TARGET}`)"
        ));
    }
    let linker_runs =
        Command::new(WIN64_LINKER).arg("--version").output().is_ok_and(|o| o.status.success());
    if !linker_runs {
        return Some(format!(
            "the linker {WIN64_LINKER} is not on PATH (Debian: `apt-get install gcc-mingw-w64-x86-64`)"
        ));
    }
    None
}

/// Cross-compiles the Windows DLL when possible and returns its platform directory and file;
/// `None` (after printing why) when it is skipped, an error when `required`.
fn build_win64(
    root: &Path,
    target: &Path,
    required: bool,
) -> Result<Option<(&'static str, PathBuf)>, String> {
    if let Some(why) = win64_unavailable() {
        if required {
            return Err(format!("win64 is required but cannot be built: {why}"));
        }
        eprintln!("fmu-build: win64 skipped: {why}");
        return Ok(None);
    }
    cargo_build_lib(root, &["--target", WIN64_TARGET])?;
    Ok(Some((pack::WIN64_DIR, target.join(WIN64_TARGET).join("release").join(pack::WIN64_LIB))))
}

/// Builds the cdylib for this machine (and for win64 when possible) and returns the platform
/// directory and library file of each binary the FMU carries.
fn build_binaries(
    root: &Path,
    target: &Path,
    require_win64: bool,
) -> Result<Vec<(&'static str, PathBuf)>, String> {
    cargo_build_lib(root, &[])?;
    let (dir, lib_name, _) = pack::platform()?;
    let mut binaries = vec![(dir, target.join("release").join(lib_name))];
    binaries.extend(build_win64(root, target, require_win64)?);
    Ok(binaries)
}

fn build_and_pack(require_win64: bool) -> Result<Vec<PathBuf>, String> {
    let root = workspace_root();
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    let binaries = build_binaries(&root, &target, require_win64)?
        .into_iter()
        .map(|(platform, file)| Binary { platform: platform.to_string(), file })
        .collect::<Vec<_>>();
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
        [] | ["--require-win64"] => {
            let require = !args.is_empty()
                || std::env::var("FMU_BUILD_REQUIRE_WIN64").is_ok_and(|v| v == "1");
            build_and_pack(require).map(|ps| {
                for p in ps {
                    eprintln!("fmu-build: wrote {}", p.display());
                }
            })
        }
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
