//! The `compliance` subcommand: the FE compliance data of both gears (embedded, disk cache or
//! computed), the fit quality and the tooth-pair stiffness at the pitch point.

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::compliance::data::{CacheOptions, ComplianceData};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
use helical_gear_mesh::results::{ComplianceRecord, density_name};

use super::{Common, DriveArg, load_drive, load_params};

/// FE mesh density presets of `compliance --density`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DensityArg {
    /// `GearMeshDensity::coarse()`.
    Coarse,
    /// `GearMeshDensity::default()`.
    Default,
    /// `GearMeshDensity::conforming()`: the default without axial coarsening (the embedded
    /// Table 1 data's mesh).
    Conforming,
    /// `GearMeshDensity::refined()`.
    Refined,
}

impl DensityArg {
    fn density(self) -> GearMeshDensity {
        match self {
            DensityArg::Coarse => GearMeshDensity::coarse(),
            DensityArg::Default => GearMeshDensity::default(),
            DensityArg::Conforming => GearMeshDensity::conforming(),
            DensityArg::Refined => GearMeshDensity::refined(),
        }
    }
}

/// Number of axial slices of the pair-stiffness load case.
const STIFFNESS_SLICES: usize = 200;

/// Runs `helical-gear compliance`: loads (or, with `--write-cache` or a non-default density,
/// computes) the FE compliance data, prints the fit quality and the tooth-pair stiffness at the
/// pitch point (c′ in N/(mm·µm), with its split into global and local approach) under the
/// torque of the drive line of `--drive`, as text or JSON. `--write-root-stress` writes the
/// root-stress influence of the same (fresh) FE run.
pub fn compliance_cmd(
    common: &Common,
    drive: &DriveArg,
    write_cache: Option<&std::path::Path>,
    write_root_stress: Option<&std::path::Path>,
    density: DensityArg,
) -> Result<(), String> {
    let p = load_params(common)?;
    let torque = load_drive(drive)?.torque_nm;
    let geo = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let fresh = write_cache.is_some() || write_root_stress.is_some();
    let data = if fresh || density != DensityArg::Default {
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
    if let Some(path) = write_root_stress {
        let stress = data.root_stress().ok_or("the FE run gave no root-stress data")?;
        stress.write_file(path).map_err(|e| e.to_string())?;
        eprintln!("root-stress data written to {}", path.display());
    }
    let st = data.pair_stiffness(&geo, STIFFNESS_SLICES, torque).map_err(|e| e.to_string())?;
    let shares = st.shares();
    let (gp, gg) = (&data.pinion, &data.gear);
    let prov = &data.provenance;
    if common.json {
        let record = ComplianceRecord::new(&data, &st);
        record.check_finite()?;
        println!("{}", serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?);
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
