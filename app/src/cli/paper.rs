//! The `paper` subcommand: the whole paper run ([`helical_gear_app::paper::run_paper`]) into
//! an output directory. Progress goes to stderr, one line per stage; stdout gets a short text
//! summary, or the summary JSON with `--json`.

use clap::Args;
use helical_gear_app::paper::{PaperOptions, reference, run_paper};

use super::{Common, DriveArg, load_drive, load_params};

/// Arguments of `helical-gear paper`.
#[derive(Args, Clone)]
pub struct PaperArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    drive: DriveArg,
    /// Output directory (created if missing): summary.json, summary.md and the CSV data of
    /// every figure.
    #[arg(long, value_name = "DIR")]
    out: std::path::PathBuf,
    /// Coarse speed grids and few refinement runs: a smoke run, not the result.
    #[arg(long)]
    quick: bool,
    /// Total slices over the simultaneous contact lines (the paper's 200).
    #[arg(long, default_value_t = 200)]
    slices: usize,
    /// Worker threads of the sweeps (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
}

/// `helical-gear paper`.
pub fn paper_cmd(a: &PaperArgs) -> Result<(), String> {
    if a.threads == Some(0) {
        return Err("--threads = 0: allowed >= 1".into());
    }
    let pair = load_params(&a.common)?;
    let drive = load_drive(&a.drive)?;
    let opts =
        PaperOptions { quick: a.quick, slices: a.slices, threads: a.threads, progress: true };
    let s = run_paper(&pair, &drive, &a.out, &opts)?;
    if a.common.json {
        println!("{}", serde_json::to_string(&s).map_err(|e| e.to_string())?);
        return Ok(());
    }
    let w = |x: Option<f64>| x.map_or("none".to_string(), |x| format!("{x:.0} rad/s"));
    let iv = |x: Option<[f64; 2]>| {
        x.map_or("none".to_string(), |[lo, hi]| format!("{lo:.0} … {hi:.0} rad/s"))
    };
    println!("Paper run in {:.0} s, results in {}", s.runtime_s, a.out.display());
    println!("  STE max        {:.1} µm (paper {} µm)", s.ste_max_um, reference::STE_MAX_UM);
    println!(
        "  ω_crit         {:.0} rad/s (paper {} rad/s); 2nd {}, 3rd {}",
        s.omega_crit_rad_s,
        reference::OMEGA_CRIT_RAD_S,
        w(s.omega_crit_2_rad_s),
        w(s.omega_crit_3_rad_s)
    );
    println!(
        "  separation     d_mesh = 100: {}; d_mesh = 200: {}",
        iv(s.separation_d100_rad_s),
        iv(s.separation_d200_rad_s)
    );
    println!(
        "  tip rounding   at 570 rad/s: {}; at ω_crit·570/660 = {:.0} rad/s: {}",
        s.tip_rounding_contact_570, s.omega_equivalent_570_rad_s, s.tip_rounding_contact_equivalent
    );
    let um = |x: Option<f64>| x.map_or("none".to_string(), |x| format!("{x:.1} µm"));
    let te570 = s
        .tip_margins
        .iter()
        .find(|m| m.compliance == "default" && m.omega_p_rad_s == reference::OMEGA_FIG13_RAD_S)
        .map(|m| m.te_max_um);
    println!(
        "  tip onset      static TE threshold {} (rim-fixed {}); steady TE max at 570 rad/s {}",
        um(s.tip_contact_te_threshold_um),
        um(s.tip_contact_te_threshold_rim_um),
        um(te570)
    );
    println!(
        "  see summary.md for the assumptions, the sensitivity study and the deviations from \
         the paper"
    );
    Ok(())
}
