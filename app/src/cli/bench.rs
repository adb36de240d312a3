//! The `bench` subcommand: the work-precision benchmark
//! ([`helical_gear_app::bench::run_bench`]). Progress goes to stderr; stdout gets a text
//! table, or the report as one JSON object with `--json`.

use clap::Args;
use helical_gear_app::bench::{
    BenchOptions, cores, load_average, loaded, run_bench, write_bench_files,
};

use super::{Common, DriveArg, load_drive, load_params};

/// Arguments of `helical-gear bench`.
#[derive(Args, Clone)]
pub struct BenchArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    drive: DriveArg,
    /// Also write the CSV tables, bench.json and the log–log plots (PNG) into DIR.
    #[arg(long, value_name = "DIR")]
    out: Option<std::path::PathBuf>,
    /// Small sizes and short runs: a smoke test of the benchmark, not a measurement.
    #[arg(long)]
    quick: bool,
    /// Skip the timing of the whole paper run.
    #[arg(long)]
    no_paper: bool,
    /// Write the report with `--out` even when the 1-minute load average exceeds half the
    /// cores (the generated page then says so at its top); without it such a run is refused.
    #[arg(long)]
    allow_loaded: bool,
}

/// `helical-gear bench`.
pub fn bench_cmd(a: &BenchArgs) -> Result<(), String> {
    let pair = load_params(&a.common)?;
    let drive = load_drive(&a.drive)?;
    // A report for docs/ measures the code, not other work on the machine: refuse to start one
    // on a busy machine unless asked to (the page then marks it).
    let (load, n) = (load_average(), cores());
    if a.out.is_some()
        && !a.quick
        && !a.allow_loaded
        && let Some(load1) = loaded(&load, n as f64)
    {
        return Err(format!(
            "bench --out: the 1-minute load average is {load1} on {n} cores (more than half the \
             cores busy with other work), so the times would measure that work too; run it on \
             an idle machine, or pass --allow-loaded to write a report that its page marks as \
             measured on a loaded machine"
        ));
    }
    let opts = BenchOptions { quick: a.quick, paper: !a.no_paper, progress: true };
    let r = run_bench(&pair, &drive, &opts)?;
    if let Some(dir) = &a.out {
        for f in write_bench_files(&r, dir)? {
            eprintln!("wrote {}", f.display());
        }
    }
    if a.common.json {
        println!("{}", serde_json::to_string(&r).map_err(|e| e.to_string())?);
        return Ok(());
    }
    println!("Work-precision benchmark ({} cores, {})", r.cores, r.cpu);
    println!(
        "  full_eval_us {:.1} (general assembly {:.1}), table_eval_ns {:.0}, table_max_rel_err \
         {:.2e}, paper_runtime_s {}",
        r.full_eval_us,
        r.full_eval_general_us,
        r.table_eval_ns,
        r.table_max_rel_err,
        r.paper_runtime_s.map_or("not run".into(), |s| format!("{s:.1}"))
    );
    println!("\n  mesh evaluation (error of M_F,p against {} slices):", r.reference_slices);
    println!(
        "  {:<38} {:>6} {:>9} {:>11} {:>10}",
        "case", "slices", "µs/eval", "max error", "fact/solve"
    );
    for c in &r.mesh {
        let name = match c.table_size {
            Some([p, t]) => format!("{} {p}×{t}", c.family),
            None => c.family.clone(),
        };
        let fact = c.factorizations_per_solve.map_or(String::new(), |f| format!("{f:.2}"));
        println!(
            "  {name:<38} {:>6} {:>9.3} {:>11.2e} {fact:>10}",
            c.slices, c.eval_us, c.max_rel_err
        );
    }
    println!("\n  options (full fidelity):");
    for c in &r.options {
        println!(
            "  {:<44} {:>9.1} µs {:>7.1} % saved, M_F,p change {:.1e}",
            c.option, c.eval_us, c.saving_percent, c.max_rel_change
        );
    }
    println!("\n  dynamics (max TE error against the reference):");
    for c in &r.dynamics {
        println!(
            "  {:<7} {:>8.0e} {:>9.2} ms {:>9} evaluations, error {:.2e}",
            c.integrator,
            c.setting,
            c.run_s * 1e3,
            c.mesh_evaluations,
            c.max_te_rel_err
        );
    }
    let h = &r.hunting;
    println!(
        "\n  tooth deviations, table fidelity ({} slices): {} meshes, RK4 {} steps per mesh \
         period: {:.2} s, {} evaluations; {:.0} ns per evaluation; M_F,p error against full \
         fidelity at {} states: max {:.2e}, rms {:.2e} of the nominal torque",
        h.slices,
        h.meshes,
        h.steps_per_mesh,
        h.run_s,
        h.mesh_evaluations,
        h.table_eval_ns,
        h.sampled_states,
        h.max_torque_err,
        h.rms_torque_err
    );
    println!(
        "\n  drive-line unit (the HelicalGearDrive engine in-process), 532 rad/s, H = 1e-4 s:"
    );
    for c in &r.drive_units {
        let how = c
            .rtol
            .map_or(format!("RK4 {:4} sub-steps per mesh period", c.steps_per_mesh_period), |r| {
                format!("DOPRI5 rtol {r:e}")
            });
        println!(
            "    {:5} {how}: {:.3e} s simulated in {:.3} s = {:.4}× real time, TE error {}",
            c.fidelity,
            c.simulated_s,
            c.wall_s,
            c.realtime_factor,
            c.te_rel_err.map_or("-".to_string(), |e| format!("{e:.1e}"))
        );
    }
    Ok(())
}
