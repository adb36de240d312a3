//! The `compliance` subcommand: the FE compliance data of both gears (embedded, disk cache or
//! computed), the fit quality and the tooth-pair stiffness at the pitch point.

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::compliance::data::{CacheOptions, ComplianceData};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
use serde_json::json;

use super::{Common, DriveArg, load_drive, load_params};

/// FE mesh density presets of `compliance --density`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DensityArg {
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

/// Runs `helical-gear compliance`: loads (or, with `--write-cache` or a non-default density,
/// computes) the FE compliance data, prints the fit quality and the tooth-pair stiffness at the
/// pitch point (c′ in N/(mm·µm), with its split into global and local approach) under the
/// torque of the drive line of `--drive`, as text or JSON.
pub fn compliance_cmd(
    common: &Common,
    drive: &DriveArg,
    write_cache: Option<&std::path::Path>,
    density: DensityArg,
) -> Result<(), String> {
    let p = load_params(common)?;
    let torque = load_drive(drive)?.torque_nm;
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
    let st = data.pair_stiffness(&geo, STIFFNESS_SLICES, torque).map_err(|e| e.to_string())?;
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
