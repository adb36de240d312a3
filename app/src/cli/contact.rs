//! The `contact` subcommand: per-slice table of the instant line of contact at a pinion angle and
//! transmission error.

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::contact::{ContactSolver, FlankSide};
use helical_gear_mesh::results::ContactRecord;

use super::{Common, load_params};

/// Runs `helical-gear contact`: the per-slice contact table at pinion angle `phi_p` (rad) and
/// transmission error `te` (m) over `slices` axial slices; `back` lists the back flanks.
pub fn contact_cmd(
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
        let record = ContactRecord::new(phi_p, phi_g, red.te, &cs);
        record.check_finite()?;
        println!("{}", serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?);
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
