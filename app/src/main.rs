//! `helical-gear`: command-line front end of the helical_gear_mesh library.
//!
//! Every subcommand takes `--params FILE` (JSON in the schema of [`GearPair`]; default: the
//! paper's Table 1) and `--json` (one JSON object on stdout; human-readable text otherwise);
//! those that use the drive line or its torque also take `--drive FILE` (JSON in the schema
//! of `DriveLine`; default: Table 1's drive line).
//! JSON keys are snake_case with units in the name.

use std::process::ExitCode;

mod cli;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use cli::compliance::DensityArg;
use cli::{Common, bench, compliance, contact, dynamics, geometry, mods, paper, statics};
use helical_gear_mesh::{DriveLine, GearPair};

#[derive(Parser)]
#[command(name = "helical-gear", version, about = "Andersson–Vedmar helical-gear mesh model")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derived geometry: contact ratios, radii, centre distance, inertias.
    Geometry {
        #[command(flatten)]
        common: Common,
    },
    /// Per-slice table of the instant line of contact at a pinion angle and transmission error.
    Contact {
        #[command(flatten)]
        common: Common,
        /// Pinion hub angle φp, rad.
        #[arg(long, allow_hyphen_values = true)]
        phi_p: f64,
        /// Transmission error TE = φp·g_p + φg·g_g, m (sets φg).
        #[arg(long, allow_hyphen_values = true)]
        te: f64,
        /// Number of axial slices.
        #[arg(long, default_value_t = 20)]
        slices: usize,
        /// List the back-flank contacts (through the backlash) instead of the driving flanks.
        #[arg(long)]
        back: bool,
    },
    /// FE compliance data of both gears (embedded, disk cache or computed), fit quality and
    /// the tooth-pair stiffness at the pitch point.
    Compliance {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        drive: cli::DriveArg,
        /// Compute the data afresh (FE and fit; never the embedded or cached data) and write
        /// them to FILE, e.g. `resources/compliance_table1.json`.
        #[arg(long, value_name = "FILE")]
        write_cache: Option<std::path::PathBuf>,
        /// Compute the data afresh and write the root-stress influence of the same FE run to
        /// FILE, e.g. `resources/root_stress_table1.json`.
        #[arg(long, value_name = "FILE")]
        write_root_stress: Option<std::path::PathBuf>,
        /// FE mesh density; other than `default` the data are always computed.
        #[arg(long, value_enum, default_value_t = DensityArg::Default)]
        density: DensityArg,
    },
    /// Print the default parameters (Table 1) as JSON, a template for `--params`.
    Params {
        /// Print Table 1's drive line instead, a template for `--drive`.
        #[arg(long)]
        drive: bool,
    },
    /// Static transmission error over the mesh cycle (Eq. 16) and the pressure waterfall.
    Static {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        drive: cli::DriveArg,
        /// Driving torque M on the pinion, N·m (default: the drive line's `torque_nm`).
        #[arg(long)]
        torque: Option<f64>,
        /// Pinion angles per pinion pitch.
        #[arg(long, default_value_t = 20)]
        points_per_pitch: usize,
        /// Number of pinion pitches.
        #[arg(long, default_value_t = 1)]
        pitches: usize,
        /// Total slices over the simultaneous contact lines (the paper's 200).
        #[arg(long, default_value_t = 200)]
        slices: usize,
        /// Write the STE curve and the pressure waterfall (Fig. 7) as CSV and PNG into DIR.
        #[arg(long, value_name = "DIR")]
        plot: Option<std::path::PathBuf>,
        /// Bearing arrangement (JSON: `{"pinion": {"locating_z_m": …, "floating_z_m": …},
        /// "gear": {…}}`, docs/loads.md): adds the bearing loads over the mesh cycle.
        #[arg(long, value_name = "FILE")]
        bearings: Option<std::path::PathBuf>,
        /// Elastic supports of the gear bodies (JSON: `{"pinion": {"mass_kg", "j_transverse_kgm2",
        /// "stiffness": {"radial_n_per_m", "axial_n_per_m", "tilt_nm_per_rad"}}, "gear": {…}}`,
        /// docs/gear-bodies.md): each point is the equilibrium with both bodies displaced on
        /// their supports, and reports their poses.
        #[arg(long, value_name = "FILE")]
        supports: Option<std::path::PathBuf>,
        #[command(flatten)]
        model: mods::ModelArgs,
        #[command(flatten)]
        friction: cli::FrictionArg,
        /// Pinion speed ω_p of the quasi-static states, rad/s (the gear at the rigid ratio;
        /// 0: standstill, negative: running backwards): the sliding speeds, the friction loss
        /// and the ISO/TR 14179-2 μ. Without friction the states do not depend on it.
        #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
        omega_p: f64,
    },
    /// Harris map: peak-to-peak static TE against torque for a set of modification variants.
    Harris(mods::HarrisArgs),
    /// Spectrum of the static TE over a hunting period, in orders of the pinion rotation.
    Spectrum(mods::SpectrumArgs),
    /// One trajectory of Eqs. 1–4 from the static equilibrium at a nominal speed: time, the
    /// eight states, TE and the four mesh torques.
    Simulate(dynamics::SimulateArgs),
    /// Steady-state TE_max/STE_max over a range of pinion speeds, separation flags and the
    /// located resonances.
    Sweep(dynamics::SweepArgs),
    /// The paper run: static TE and Fig. 7, the speed sweeps of Fig. 9, Figs. 10–13, the
    /// resonances, separation, tip contact and a sensitivity study, into `--out DIR`.
    Paper(paper::PaperArgs),
    /// The work-precision benchmark: time per mesh evaluation against the torque error for
    /// every fidelity and resolution, integrator steps against the TE error, the paper run's
    /// wall time.
    Bench(bench::BenchArgs),
}

/// Restores the default action of SIGPIPE, which the Rust runtime ignores: a reader that
/// closes our stdout early (`helical-gear simulate … --csv | head -1`) then ends the program
/// quietly, as it does for other command-line tools, instead of a `println!` panic about a
/// broken pipe.
fn restore_sigpipe() {
    #[cfg(unix)]
    {
        unsafe extern "C" {
            fn signal(signum: std::ffi::c_int, handler: usize) -> usize;
        }
        const SIGPIPE: std::ffi::c_int = 13; // the same number on Linux, macOS and the BSDs
        const SIG_DFL: usize = 0;
        // SAFETY: called first thing in main, before any thread exists; SIG_DFL is a valid
        // action for SIGPIPE.
        unsafe {
            signal(SIGPIPE, SIG_DFL);
        }
    }
}

fn main() -> ExitCode {
    restore_sigpipe();
    // Negative numbers are values, not options: `--torque -100` (the back flanks) and
    // `--omega-p -5` (running backwards) parse as numbers in every subcommand.
    let command = Cli::command().mut_subcommands(|s| s.allow_negative_numbers(true));
    let cli = match Cli::from_arg_matches(&command.get_matches()) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    let result = match &cli.command {
        Command::Geometry { common } => geometry::geometry_cmd(common),
        Command::Contact { common, phi_p, te, slices, back } => {
            contact::contact_cmd(common, *phi_p, *te, *slices, *back)
        }
        Command::Static {
            common,
            drive,
            torque,
            points_per_pitch,
            pitches,
            slices,
            plot,
            bearings,
            supports,
            model,
            friction,
            omega_p,
        } => statics::static_cmd(
            common,
            drive,
            *torque,
            *points_per_pitch,
            *pitches,
            *slices,
            plot.as_deref(),
            bearings.as_deref(),
            supports.as_deref(),
            model,
            friction,
            *omega_p,
        ),
        Command::Harris(args) => mods::harris_cmd(args),
        Command::Spectrum(args) => mods::spectrum_cmd(args),
        Command::Simulate(args) => dynamics::simulate_cmd(args),
        Command::Sweep(args) => dynamics::sweep_cmd(args),
        Command::Compliance { common, drive, write_cache, write_root_stress, density } => {
            compliance::compliance_cmd(
                common,
                drive,
                write_cache.as_deref(),
                write_root_stress.as_deref(),
                *density,
            )
        }
        Command::Paper(args) => paper::paper_cmd(args),
        Command::Bench(args) => bench::bench_cmd(args),
        Command::Params { drive } => match if *drive {
            serde_json::to_string_pretty(&DriveLine::paper_table1())
        } else {
            serde_json::to_string_pretty(&GearPair::paper_table1())
        } {
            Ok(s) => {
                println!("{s}");
                Ok(())
            }
            Err(e) => Err(e.to_string()),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("helical-gear: error: {e}");
            ExitCode::FAILURE
        }
    }
}
