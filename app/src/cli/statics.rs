//! The `static` subcommand: static transmission error over the mesh cycle (Eq. 16), the face
//! load distribution, with `--friction` the mesh loss and efficiency at the running speed
//! `--omega-p`, and with `--plot` the pressure waterfall (Fig. 7).

use helical_gear_app::paper;
use helical_gear_mesh::mesh::bearings::BearingArrangement;
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Mesh, Supports, pressure_waterfall, static_curve_with,
    supported_static_curve,
};
use helical_gear_mesh::results::{
    BearingLoadRecord, IsoRootStressSummary, StaticCurveRecord, StaticFrictionSummary,
    StaticPointRecord, StaticRunRecord,
};

use super::{Common, DriveArg, FrictionArg, load_drive, load_friction, load_params, mods};

/// Runs `helical-gear static`: the static TE curve under `torque` (N·m on the pinion; default
/// the torque of the drive line of `--drive`) at `points_per_pitch` angles over `pitches` pinion pitches,
/// the face load and K_Hβ per point, the mesh friction of `friction` at pinion speed `omega_p`
/// (rad/s; the quasi-static states run at it when friction is on), and with `plot` the CSV/PNG
/// figures into that directory.
#[allow(clippy::too_many_arguments)]
pub fn static_cmd(
    common: &Common,
    drive: &DriveArg,
    torque: Option<f64>,
    points_per_pitch: usize,
    pitches: usize,
    slices: usize,
    plot: Option<&std::path::Path>,
    bearings: Option<&std::path::Path>,
    supports: Option<&std::path::Path>,
    model_args: &mods::ModelArgs,
    friction: &FrictionArg,
    omega_p: f64,
) -> Result<(), String> {
    if !(omega_p.is_finite() && omega_p.abs() <= helical_gear_mesh::mesh::validity::MAX_SPEED_RAD_S)
    {
        return Err(format!(
            "--omega-p = {omega_p:.4e}: allowed finite, |ω_p| <= 1e5 rad/s (0: standstill, \
             negative: running backwards)"
        ));
    }
    let friction = load_friction(friction)?;
    // The bearing arrangement is read and checked before anything is computed.
    let bearings = bearings
        .map(|path| super::read_json_as("--bearings", path, BearingArrangement::from_json))
        .transpose()?;
    if supports.is_some() && plot.is_some() {
        return Err("--plot with --supports: the pressure waterfall of --plot is computed on \
                    rigid bearings only; run --plot without --supports"
            .to_string());
    }
    let p = load_params(common)?;
    let supports = supports
        .map(|path| {
            super::read_json_as("--supports", path, |t| Supports::from_json_for(t, p.face_width_m))
        })
        .transpose()?;
    let drive = load_drive(drive)?;
    let torque = torque.unwrap_or(drive.torque_nm);
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
    let mut options = model_args.options(slices).sized_for(&drive);
    options.friction = friction;
    let mut model = Mesh::new(&p, options).map_err(|e| e.to_string())?;
    let build_s = t0.elapsed().as_secs_f64();
    let geo = model.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    // Without friction the speed changes nothing (TE and its rate are those of standstill, no
    // damping): the states are taken at rest, bit for bit the frictionless results.
    let settings = EquilibriumSettings {
        w_p: if friction.is_on() { omega_p } else { 0.0 },
        ..EquilibriumSettings::default()
    };
    let curve = match &supports {
        None => {
            static_curve_with(&mut model, torque, 0.0, pitch, points_per_pitch, pitches, &settings)
        }
        Some(s) => supported_static_curve(
            &mut model,
            torque,
            0.0,
            pitch,
            points_per_pitch,
            pitches,
            s,
            &settings,
        ),
    }
    .map_err(|e| e.to_string())?;
    let fl =
        mods::face_loads(&mut model, &curve, pitch, points_per_pitch, pitches, supports.is_some())?;
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
    let points = curve
        .points
        .iter()
        .zip(&fl.points)
        .map(|(e, &(k, w_max, w_mean))| StaticPointRecord {
            phi_p_rad: e.phi_p,
            ste_um: e.te * 1e6,
            n_pairs: e.outputs.n_pairs,
            p_max_pa: e.outputs.p_max,
            tip_contact: e.outputs.tip_contact,
            contact_length_m: e.outputs.contact_length,
            k_h_beta: k,
            line_load_max_n_per_mm: w_max,
            line_load_mean_n_per_mm: w_mean,
            force_p_n: e.outputs.force_p,
            moment_p_nm: e.outputs.moment_p,
            force_g_n: e.outputs.force_g,
            moment_g_nm: e.outputs.moment_g,
            root_stress_p_pa: e.outputs.root_stress_p,
            root_stress_g_pa: e.outputs.root_stress_g,
            p_loss_w: e.outputs.p_loss,
            eta_mesh: e.outputs.eta_mesh,
            m_r_p_nm: e.outputs.m_r_p,
            m_r_g_nm: e.outputs.m_r_g,
            q_p_w: e.outputs.q_p,
            q_g_w: e.outputs.q_g,
            pose_p: supports.is_some().then(|| e.pose_p.values()),
            pose_g: supports.is_some().then(|| e.pose_g.values()),
        })
        .collect();
    // The shared static record (per-point arrays and summary), then the face load and the
    // run's figures of this command.
    let record = StaticRunRecord {
        curve: StaticCurveRecord::new(&curve, rb),
        slices,
        k_h_beta_max: fl.k_h_beta_max,
        k_h_beta_cycle: fl.k_h_beta_cycle,
        k_h_beta_iso: fl.k_h_beta_iso,
        f_beta_y_um: fl.f_beta_y_m * 1e6,
        c_gamma_n_per_mm_per_um: fl.c_gamma_n_per_mm_um,
        model_build_s: build_s,
        seconds,
        iso: IsoRootStressSummary::new(&geo, torque),
        friction: StaticFrictionSummary::new(&curve, &geo, friction, omega_p),
        points,
        bearings: bearings.map(|b| {
            let outs: Vec<_> = curve.points.iter().map(|e| e.outputs).collect();
            BearingLoadRecord::over_cycle(&b, p.face_width_m, &outs, pitches)
        }),
    };
    record.check_finite()?;
    if common.json {
        println!("{}", serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?);
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
        let what = if supports.is_some() { "mesh on its supports" } else { "mesh" };
        println!(
            "  mean stiffness of the {what} {:.2} N/µm along the line of action",
            stiffness * 1e-6
        );
        println!("  tip-rounding contact: {}", curve.tip_rounding_contact());
        match (&record.iso.iso6336, &record.iso.iso6336_error) {
            (Some(r), _) => println!(
                "  ISO 6336-3 method B nominal root stress σ_F0: pinion {:.2} MPa (Y_F {:.4}, \
                 Y_S {:.4}), gear {:.2} MPa (Y_F {:.4}, Y_S {:.4}); Y_β {:.4}",
                r.pinion.sigma_f0_pa * 1e-6,
                r.pinion.y_f,
                r.pinion.y_s,
                r.gear.sigma_f0_pa * 1e-6,
                r.gear.y_f,
                r.gear.y_s,
                r.pinion.y_beta
            ),
            (None, e) => println!(
                "  ISO 6336-3 method B: not applicable ({})",
                e.as_deref().unwrap_or("no reason given")
            ),
        }
        println!(
            "  tooth-root stress max: pinion {:.1} MPa, gear {:.1} MPa",
            record.curve.root_stress_max_p_pa * 1e-6,
            record.curve.root_stress_max_g_pa * 1e-6
        );
        let fr = &record.friction;
        println!(
            "  mesh friction ({}) at ω_p = {omega_p} rad/s: mean loss {:.3} W, mean efficiency \
             {:.5}, ISO/TR 14179-2 loss factor H_V {:.4}, μ {}",
            friction.model.name(),
            fr.mesh_loss_mean_w,
            fr.mesh_efficiency_mean,
            fr.loss_factor_h_v,
            fr.mu_mean.map_or("none".into(), |mu| format!("{mu:.4}"))
        );
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
