//! `helical-gear`: command-line front end of the helical_gear_mesh library.
//!
//! Every subcommand takes `--params FILE` (JSON in the schema of [`GearPair`]; default: the
//! paper's Table 1) and `--json` (one JSON object on stdout; human-readable text otherwise).
//! JSON keys are snake_case with units in the name.

use std::process::ExitCode;

#[path = "cli/bench.rs"]
mod bench_cmd;
#[path = "cli/dynamics.rs"]
mod dynamics_cmd;
#[path = "cli/mods.rs"]
mod mods_cmd;
#[path = "cli/paper.rs"]
mod paper_cmd;

use clap::{Args, Parser, Subcommand};
use helical_gear_mesh::compliance::data::{CacheOptions, ComplianceData};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
use helical_gear_mesh::contact::{ContactSolver, FlankSide};
use helical_gear_mesh::mesh::{Mesh, pressure_waterfall, static_curve};
use helical_gear_mesh::paper;
use helical_gear_mesh::{GearPair, PairGeometry};
use serde_json::json;

#[derive(Parser)]
#[command(name = "helical-gear", version, about = "Andersson–Vedmar helical-gear mesh model")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args, Clone)]
struct Common {
    /// Gear-pair parameters as JSON (schema of `GearPair`); default: the paper's Table 1.
    #[arg(long, value_name = "FILE")]
    params: Option<std::path::PathBuf>,
    /// Print one JSON object on stdout instead of text.
    #[arg(long)]
    json: bool,
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
        /// Compute the data afresh (FE and fit; never the embedded or cached data) and write
        /// them to FILE, e.g. `resources/compliance_table1.json`.
        #[arg(long, value_name = "FILE")]
        write_cache: Option<std::path::PathBuf>,
        /// FE mesh density; other than `default` the data are always computed.
        #[arg(long, value_enum, default_value_t = DensityArg::Default)]
        density: DensityArg,
    },
    /// Print the default parameters (Table 1) as JSON, a template for `--params`.
    Params,
    /// Static transmission error over the mesh cycle (Eq. 16) and the pressure waterfall.
    Static {
        #[command(flatten)]
        common: Common,
        /// Driving torque M on the pinion, N·m (default: the parameters' `drive.torque_nm`).
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
        #[command(flatten)]
        model: mods_cmd::ModelArgs,
    },
    /// Harris map: peak-to-peak static TE against torque for a set of modification variants.
    Harris(mods_cmd::HarrisArgs),
    /// Spectrum of the static TE over a hunting period, in orders of the pinion rotation.
    Spectrum(mods_cmd::SpectrumArgs),
    /// One trajectory of Eqs. 1–4 from the static equilibrium at a nominal speed: time, the
    /// eight states, TE and the four mesh torques.
    Simulate(dynamics_cmd::SimulateArgs),
    /// Steady-state TE_max/STE_max over a range of pinion speeds, separation flags and the
    /// located resonances.
    Sweep(dynamics_cmd::SweepArgs),
    /// The paper run: static TE and Fig. 7, the speed sweeps of Fig. 9, Figs. 10–13, the
    /// resonances, separation, tip contact and a sensitivity study, into `--out DIR`.
    Paper(paper_cmd::PaperArgs),
    /// The work-precision benchmark: time per mesh evaluation against the torque error for
    /// every fidelity and resolution, integrator steps against the TE error, the paper run's
    /// wall time.
    Bench(bench_cmd::BenchArgs),
}

/// FE mesh density presets of `compliance --density`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum DensityArg {
    /// `GearMeshDensity::coarse()`.
    Coarse,
    /// `GearMeshDensity::default()`.
    Default,
    /// `GearMeshDensity::refined()`.
    Refined,
}

impl DensityArg {
    fn density(self) -> GearMeshDensity {
        match self {
            DensityArg::Coarse => GearMeshDensity::coarse(),
            DensityArg::Default => GearMeshDensity::default(),
            DensityArg::Refined => GearMeshDensity::refined(),
        }
    }
}

/// Name of a preset density, or `"custom"`.
fn density_name(d: &GearMeshDensity) -> &'static str {
    [("coarse", GearMeshDensity::coarse()), ("default", GearMeshDensity::default())]
        .into_iter()
        .chain([("refined", GearMeshDensity::refined())])
        .find(|(_, v)| v == d)
        .map_or("custom", |(n, _)| n)
}

/// Number of axial slices of the pair-stiffness load case.
const STIFFNESS_SLICES: usize = 200;

fn compliance_cmd(
    common: &Common,
    write_cache: Option<&std::path::Path>,
    density: DensityArg,
) -> Result<(), String> {
    let p = load_params(common)?;
    let geo = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let data = if write_cache.is_some() || density != DensityArg::Default {
        let d = ComplianceData::compute(
            &p,
            &density.density(),
            DEFAULT_DEPTH_MN * p.normal_module_m,
            true,
        )
        .map_err(|e| e.to_string())?;
        std::sync::Arc::new(d)
    } else {
        let options = CacheOptions { progress: true, ..CacheOptions::default() };
        ComplianceData::for_pair(&p, &options).map_err(|e| e.to_string())?
    };
    if let Some(path) = write_cache {
        data.write_file(path).map_err(|e| e.to_string())?;
        eprintln!("compliance data written to {}", path.display());
    }
    let st = data.pair_stiffness(&geo, STIFFNESS_SLICES).map_err(|e| e.to_string())?;
    let shares = st.shares();
    let (gp, gg) = (&data.pinion, &data.gear);
    let prov = &data.provenance;
    let mut out = json!({
        "source": data.source().as_str(),
        "format_version": prov.format_version,
        "crate_version": prov.crate_version,
        "command": prov.command,
        "density": density_name(&prov.density),
        "depth_h_m": prov.depth_h_m,
        "grid_rows": gp.grid.profile.len(),
        "grid_columns": gp.grid.zeta.len(),
        "grid_teeth": gp.grid.teeth,
        "fe_dofs_p": gp.fe.dofs,
        "fe_dofs_g": gg.fe.dofs,
        "fe_seconds": data.fe_seconds(),
        "fe_mesh_s_p": gp.fe.mesh_s,
        "fe_mesh_s_g": gg.fe.mesh_s,
        "fe_assembly_s_p": gp.fe.assembly_s,
        "fe_assembly_s_g": gg.fe.assembly_s,
        "fe_factorisation_s_p": gp.fe.factorisation_s,
        "fe_factorisation_s_g": gg.fe.factorisation_s,
        "fe_solve_s_p": gp.fe.solve_s,
        "fe_solve_s_g": gg.fe.solve_s,
        "fe_observe_s_p": gp.fe.observe_s,
        "fe_observe_s_g": gg.fe.observe_s,
        "fe_load_cases_p": gp.fe.load_cases,
        "fe_load_cases_g": gg.fe.load_cases,
    });
    let fit_and_stiffness = json!({
        "e_rel_std_p": gp.fit.report.sigma_e_rel,
        "e_rel_std_g": gg.fit.report.sigma_e_rel,
        "e_rel_std_nodes_domain_p": gp.fit.nodes_domain.std,
        "e_rel_std_nodes_domain_g": gg.fit.nodes_domain.std,
        "e_rel_std_nodes_rows_p": gp.fit.nodes_rows.std,
        "e_rel_std_nodes_rows_g": gg.fit.nodes_rows.std,
        "e_rel_std_nodes_all_p": gp.fit.nodes_all.std,
        "e_rel_std_nodes_all_g": gg.fit.nodes_all.std,
        "fit_seconds_p": gp.fit.fit_s,
        "fit_seconds_g": gg.fit.fit_s,
        "fit_max_tau_p_rad": gp.fit.max_tau_rad,
        "fit_max_tau_g_rad": gg.fit.max_tau_rad,
        "alpha_ref_p_m_per_n": gp.fit.alpha_ref_m_per_n,
        "alpha_ref_g_m_per_n": gg.fit.alpha_ref_m_per_n,
        "pair_stiffness_n_per_mm_per_um": st.c_prime_n_per_mm_per_um,
        "pair_load_n_per_m": st.load_n_per_m,
        "pair_torque_nm": st.torque_nm,
        "pair_deflection_t_um": st.delta_t_m * 1e6,
        "pair_u_global_p_um": st.u_global_p_m * 1e6,
        "pair_u_global_g_um": st.u_global_g_m * 1e6,
        "pair_u_local_um": st.u_local_m * 1e6,
        "pair_share_global_p": shares[0],
        "pair_share_global_g": shares[1],
        "pair_share_local": shares[2],
    });
    if let (Some(o), serde_json::Value::Object(more)) = (out.as_object_mut(), fit_and_stiffness) {
        o.extend(more);
    }
    if common.json {
        println!("{out}");
        return Ok(());
    }
    println!(
        "Compliance data ({}): {} density, h = {:.3} mm, grid {} rows × {} columns, teeth {:?}",
        data.source().as_str(),
        density_name(&prov.density),
        prov.depth_h_m * 1e3,
        gp.grid.profile.len(),
        gp.grid.zeta.len(),
        gp.grid.teeth
    );
    println!("  regenerate: {}", prov.command);
    for (name, g) in [("pinion", gp), ("gear", gg)] {
        let fe = &g.fe;
        println!(
            "  {name:6}: {} DOFs, FE {:.2} s (mesh {:.2}, assembly {:.2}, factorisation {:.2}, \
             solves {:.2} for {} loads, observation {:.2})",
            fe.dofs,
            fe.total_s(),
            fe.mesh_s,
            fe.assembly_s,
            fe.factorisation_s,
            fe.solve_s,
            fe.load_cases,
            fe.observe_s
        );
        println!(
            "          fit {:.2} s: σ(e_rel) = {:.4} (Eq. 9, fitted pairs); node grid {:.4} on \
             the same domain, {:.4} on all pairs of the fitted rows, {:.4} over all pairs; \
             α_ref = {:.4e} m/N",
            g.fit.fit_s,
            g.fit.report.sigma_e_rel,
            g.fit.nodes_domain.std,
            g.fit.nodes_rows.std,
            g.fit.nodes_all.std,
            g.fit.alpha_ref_m_per_n
        );
    }
    println!("  FE total {:.2} s when computed", data.fe_seconds());
    println!(
        "Tooth-pair stiffness at the pitch point (T = {} N·m on one pair, q = {:.1} N/mm): \
         c′ = {:.3} N/(mm·µm)",
        st.torque_nm,
        st.load_n_per_m * 1e-3,
        st.c_prime_n_per_mm_per_um
    );
    println!(
        "  transverse deflection {:.3} µm; normal approach: pinion global {:.3} µm ({:.0} %), \
         gear global {:.3} µm ({:.0} %), local {:.3} µm ({:.0} %)",
        st.delta_t_m * 1e6,
        st.u_global_p_m * 1e6,
        100.0 * shares[0],
        st.u_global_g_m * 1e6,
        100.0 * shares[1],
        st.u_local_m * 1e6,
        100.0 * shares[2]
    );
    Ok(())
}

fn load_params(common: &Common) -> Result<GearPair, String> {
    match &common.params {
        None => Ok(GearPair::paper_table1()),
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            GearPair::from_json(&text)
        }
    }
}

fn geometry_cmd(common: &Common) -> Result<(), String> {
    let p = load_params(common)?;
    let g = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let out = json!({
        "eps_alpha": g.eps_alpha,
        "eps_beta": g.eps_beta,
        "base_radius_p_m": g.pinion.rb,
        "base_radius_g_m": g.gear.rb,
        "tip_radius_p_m": g.pinion.ra,
        "tip_radius_g_m": g.gear.ra,
        "root_radius_p_m": g.pinion.rf,
        "root_radius_g_m": g.gear.rf,
        "reference_radius_p_m": g.pinion.r,
        "reference_radius_g_m": g.gear.r,
        "form_radius_p_m": g.pinion.r_form,
        "form_radius_g_m": g.gear.r_form,
        "relief_start_radius_p_m": g.pinion.r_relief_start,
        "relief_start_radius_g_m": g.gear.r_relief_start,
        "rounding_start_radius_p_m": g.pinion.r_rounding_start,
        "rounding_start_radius_g_m": g.gear.r_rounding_start,
        "center_distance_m": g.center_distance,
        "transverse_pressure_angle_rad": g.alpha_t,
        "operating_pressure_angle_rad": g.alpha_wt,
        "base_helix_angle_rad": g.base_helix_angle,
        "base_pitch_m": g.base_pitch,
        "backlash_te_m": g.backlash_te,
        "j_p_kgm2": g.j_p,
        "j_g_kgm2": g.j_g,
        "assumptions": p.assumptions(),
    });
    if common.json {
        println!("{out}");
    } else {
        println!(
            "Gear pair geometry (z = {}/{}, m_n = {} mm)",
            p.z_p,
            p.z_g,
            p.normal_module_m * 1e3
        );
        for (k, v) in out.as_object().into_iter().flatten() {
            if k != "assumptions" {
                println!("  {k:32} {v}");
            }
        }
        println!("Assumptions:");
        for a in p.assumptions() {
            println!("  - {a}");
        }
    }
    Ok(())
}

fn contact_cmd(
    common: &Common,
    phi_p: f64,
    te: f64,
    slices: usize,
    back: bool,
) -> Result<(), String> {
    if !phi_p.is_finite() || !te.is_finite() {
        return Err(format!("--phi-p ({phi_p}) and --te ({te}) must be finite"));
    }
    if slices == 0 || slices > 100_000 {
        return Err(format!("--slices = {slices}: allowed 1..=100000"));
    }
    let p = load_params(common)?;
    let g = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let solver = ContactSolver::new(&g);
    if phi_p.abs() > solver.max_angle() {
        return Err(format!(
            "--phi-p = {phi_p:.4e} rad is beyond the exact range |phi_p| <= {:.4e} rad (2^53 \
             pinion pitches, where the mesh phase and the tooth-pair number are exact)",
            solver.max_angle()
        ));
    }
    let phi_g = g.phi_g_for_te(phi_p, te);
    let zetas = solver.slice_zetas(slices);
    let mut cs = Vec::new();
    let side = if back { FlankSide::Back } else { FlankSide::Drive };
    let red = solver.contacts_on(side, phi_p, phi_g, &zetas, &mut cs);
    if common.json {
        let rows: Vec<_> = cs
            .iter()
            .map(|c| {
                json!({
                    "zeta": c.zeta, "pair": c.pair, "side": c.side, "kind": c.kind_name(),
                    "overlap_m": c.overlap_m, "rho_p_m": c.rho_p_m, "rho_g_m": c.rho_g_m,
                    "arm_p_m": c.arm_p_m, "arm_g_m": c.arm_g_m,
                    "radius_p_m": c.radius_p_m, "radius_g_m": c.radius_g_m,
                    "eta_star_p": c.eta_star_p, "tau_p_rad": c.tau_p,
                    "eta_star_g": c.eta_star_g, "tau_g_rad": c.tau_g,
                    "normal_angle_rad": c.normal_angle,
                })
            })
            .collect();
        println!(
            "{}",
            json!({"phi_p_rad": phi_p, "phi_g_rad": phi_g, "te_m": red.te, "slices": rows})
        );
    } else {
        println!("φp = {phi_p} rad, φg = {phi_g} rad, TE = {:.3} µm", red.te * 1e6);
        println!(
            "{:>8} {:>5} {:>22} {:>12} {:>10} {:>10} {:>10} {:>10}",
            "zeta", "pair", "kind", "overlap_um", "rho_p_mm", "rho_g_mm", "arm_p_mm", "arm_g_mm"
        );
        for c in &cs {
            println!(
                "{:8.4} {:5} {:>22} {:12.4} {:10.4} {:10.4} {:10.5} {:10.5}",
                c.zeta,
                c.pair,
                c.kind_name(),
                c.overlap_m * 1e6,
                c.rho_p_m * 1e3,
                c.rho_g_m * 1e3,
                c.arm_p_m * 1e3,
                c.arm_g_m * 1e3
            );
        }
    }
    Ok(())
}

fn static_cmd(
    common: &Common,
    torque: Option<f64>,
    points_per_pitch: usize,
    pitches: usize,
    slices: usize,
    plot: Option<&std::path::Path>,
    model_args: &mods_cmd::ModelArgs,
) -> Result<(), String> {
    let p = load_params(common)?;
    let torque = torque.unwrap_or(p.drive.torque_nm);
    if !(torque.is_finite() && torque > 0.0) {
        return Err(format!("--torque = {torque} N·m: allowed > 0 and finite"));
    }
    if !(1..=10_000).contains(&points_per_pitch) || !(1..=100).contains(&pitches) {
        return Err(format!(
            "--points-per-pitch = {points_per_pitch} (allowed 1..=10000), --pitches = {pitches} \
             (allowed 1..=100)"
        ));
    }
    let t0 = std::time::Instant::now();
    let options = model_args.options(slices);
    let mut model = Mesh::new(&p, options).map_err(|e| e.to_string())?;
    let build_s = t0.elapsed().as_secs_f64();
    let geo = model.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let curve = static_curve(&mut model, torque, 0.0, pitch, points_per_pitch, pitches)
        .map_err(|e| e.to_string())?;
    let fl = mods_cmd::face_loads(&mut model, &curve, pitch, points_per_pitch, pitches)?;
    let rb = geo.pinion.rb;
    let stiffness = curve.mean_stiffness(rb);
    if let Some(dir) = plot {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        // The same files as the paper run's static stage.
        paper::figure_static_te(dir, &curve)?;
        let rows = pressure_waterfall(&mut model, torque, 0, -1.5 * pitch, 1.5 * pitch, 20)
            .map_err(|e| e.to_string())?;
        paper::figure_7(dir, &rows)?;
    }
    let seconds = t0.elapsed().as_secs_f64();
    let points: Vec<_> = curve
        .points
        .iter()
        .zip(&fl.points)
        .map(|(e, &(k, w_max, w_mean))| {
            json!({
                "phi_p_rad": e.phi_p, "ste_um": e.te * 1e6, "n_pairs": e.outputs.n_pairs,
                "p_max_pa": e.outputs.p_max, "tip_contact": e.outputs.tip_contact,
                "contact_length_m": e.outputs.contact_length,
                "k_h_beta": k, "line_load_max_n_per_mm": w_max,
                "line_load_mean_n_per_mm": w_mean,
            })
        })
        .collect();
    let out = json!({
        "torque_nm": torque,
        "slices": slices,
        "ste_max_um": curve.max() * 1e6,
        "ste_min_um": curve.min() * 1e6,
        "ste_mean_um": curve.mean() * 1e6,
        "ste_peak_to_peak_um": (curve.max() - curve.min()) * 1e6,
        "mesh_stiffness_mean_n_per_um": stiffness * 1e-6,
        "tip_rounding_contact": curve.tip_rounding_contact(),
        "k_h_beta_max": fl.k_h_beta_max,
        "k_h_beta_cycle": fl.k_h_beta_cycle,
        "k_h_beta_iso": fl.k_h_beta_iso,
        "f_beta_y_um": fl.f_beta_y_m * 1e6,
        "c_gamma_n_per_mm_per_um": fl.c_gamma_n_per_mm_um,
        "model_build_s": build_s,
        "seconds": seconds,
        "points": points,
    });
    if common.json {
        println!("{out}");
    } else {
        println!(
            "Static transmission error, M = {torque} N·m, {} points over {pitches} pitch(es), \
             {slices} slices",
            curve.points.len()
        );
        println!(
            "  STE max {:.3} µm, min {:.3} µm, mean {:.3} µm (paper: max 30.5 µm)",
            curve.max() * 1e6,
            curve.min() * 1e6,
            curve.mean() * 1e6
        );
        println!("  mean mesh stiffness {:.2} N/µm along the line of action", stiffness * 1e-6);
        println!("  tip-rounding contact: {}", curve.tip_rounding_contact());
        println!(
            "  K_Hβ max {:.4}, of the cycle-averaged line load {:.4}; ISO 6336-1 method C {:.4} \
             (F_βy = {:.2} µm, c_γ = {:.2} N/(mm·µm))",
            fl.k_h_beta_max,
            fl.k_h_beta_cycle,
            fl.k_h_beta_iso,
            fl.f_beta_y_m * 1e6,
            fl.c_gamma_n_per_mm_um
        );
        println!(
            "  {:>10} {:>10} {:>6} {:>10} {:>8} {:>12}",
            "phi_p_rad", "ste_um", "pairs", "p_max_MPa", "K_Hβ", "w_max_N/mm"
        );
        for (e, (k, w_max, _)) in curve.points.iter().zip(&fl.points) {
            println!(
                "  {:10.5} {:10.4} {:6} {:10.1} {:8.4} {:12.2}",
                e.phi_p,
                e.te * 1e6,
                e.outputs.n_pairs,
                e.outputs.p_max * 1e-6,
                k,
                w_max
            );
        }
        println!("  ({seconds:.2} s, of which {build_s:.2} s building the model)");
    }
    Ok(())
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
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Geometry { common } => geometry_cmd(common),
        Command::Contact { common, phi_p, te, slices, back } => {
            contact_cmd(common, *phi_p, *te, *slices, *back)
        }
        Command::Static { common, torque, points_per_pitch, pitches, slices, plot, model } => {
            static_cmd(
                common,
                *torque,
                *points_per_pitch,
                *pitches,
                *slices,
                plot.as_deref(),
                model,
            )
        }
        Command::Harris(args) => mods_cmd::harris_cmd(args),
        Command::Spectrum(args) => mods_cmd::spectrum_cmd(args),
        Command::Simulate(args) => dynamics_cmd::simulate_cmd(args),
        Command::Sweep(args) => dynamics_cmd::sweep_cmd(args),
        Command::Compliance { common, write_cache, density } => {
            compliance_cmd(common, write_cache.as_deref(), *density)
        }
        Command::Paper(args) => paper_cmd::paper_cmd(args),
        Command::Bench(args) => bench_cmd::bench_cmd(args),
        Command::Params => match serde_json::to_string_pretty(&GearPair::paper_table1()) {
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
