//! The `geometry` subcommand: derived geometry (contact ratios, radii, centre distance,
//! inertias).

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::results::GeometryRecord;

use super::{Common, load_params};

/// Runs `helical-gear geometry`: the derived geometry (radii in m, inertias in kg·m²,
/// contact ratios) as text or JSON.
pub fn geometry_cmd(common: &Common) -> Result<(), String> {
    let p = load_params(common)?;
    let g = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let record = GeometryRecord::new(&g, &p);
    record.check_finite()?;
    let out = serde_json::to_value(&record).map_err(|e| format!("JSON: {e}"))?;
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
            // The text lists what it listed before the record had the angular pitch.
            if k != "assumptions" && k != "angular_pitch_p_rad" {
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
