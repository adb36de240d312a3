//! The `geometry` subcommand: derived geometry (contact ratios, radii, centre distance,
//! inertias).

use helical_gear_mesh::PairGeometry;
use serde_json::json;

use super::{Common, load_params};

/// Runs `helical-gear geometry`: the derived geometry (radii in m, inertias in kg·m²,
/// contact ratios) as text or JSON.
pub fn geometry_cmd(common: &Common) -> Result<(), String> {
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
