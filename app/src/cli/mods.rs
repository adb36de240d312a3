//! Modifications on the command line: the compliance flags of `static` and its face-load
//! outputs (line load, K_Hβ beside ISO 6336-1), `harris` (peak-to-peak static TE against torque
//! for a set of modification variants, each merged into the base key by key) and `spectrum`
//! (static TE spectrum over a hunting period, or with `--dynamic` the steady dynamic TE over
//! the deviations' period, sampled at uniform pinion angles).

use clap::{Args, ValueEnum};
use helical_gear_app::plot::PlotError;
use helical_gear_app::plot::{LineChart, Series, SeriesStyle, line_chart, write_csv};
use helical_gear_mesh::mesh::{
    ComplianceModel, Mesh, MeshOptions, MeshState, StaticCurve, face_load, k_h_beta_iso,
    static_curve,
};
use helical_gear_mesh::modifications::Modifications;
use helical_gear_mesh::numeric::amplitude_spectrum;
use helical_gear_mesh::results::{
    DynamicSpectrumRecord, HarrisRecord, HarrisVariantRecord, SpectrumRecord, SteadyRunRecord,
};
use helical_gear_mesh::{DriveLine, GearPair};
use serde::Deserialize;

use super::{Common, DriveArg, FrictionArg, load_drive, load_friction, load_params};

/// `--compliance` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ComplianceArg {
    /// Interpolated FE influence grid.
    Interpolated,
    /// Fitted influence function of Eqs. 5–8.
    Fitted,
    /// Winkler reference: uniform stiffness c′ per unit contact length, no coupling.
    Winkler,
}

/// Compliance flags shared by `static`, `harris` and `spectrum`.
#[derive(Args, Clone, Debug)]
pub struct ModelArgs {
    /// Global tooth compliance.
    #[arg(long, value_enum, default_value_t = ComplianceArg::Interpolated)]
    pub compliance: ComplianceArg,
    /// Stiffness c′ of `--compliance winkler`, N/(mm·µm) per unit contact-line length (pure
    /// linear springs along the line, split equally between the gears).
    #[arg(long, default_value_t = 14.0)]
    pub winkler_c_prime: f64,
    /// Leave out the local Weber–Banaschek contact deformation (Eq. 10).
    #[arg(long)]
    pub no_local_contact: bool,
}

impl ModelArgs {
    /// Mesh options with `slices` total slices (detail on: the line loads need it).
    pub fn options(&self, slices: usize) -> MeshOptions {
        MeshOptions {
            slices,
            compliance: match self.compliance {
                ComplianceArg::Fitted => ComplianceModel::Fitted,
                _ => ComplianceModel::Interpolated,
            },
            winkler_c_prime: (self.compliance == ComplianceArg::Winkler)
                .then_some(self.winkler_c_prime * 1e9),
            local_contact: !self.no_local_contact,
            detail: true,
            ..MeshOptions::default()
        }
    }
}

/// Face-load results of a static curve.
pub struct FaceLoads {
    /// Per point: (K_Hβ, max line load N/mm, mean line load N/mm).
    pub points: Vec<(f64, f64, f64)>,
    /// Largest K_Hβ over the points.
    pub k_h_beta_max: f64,
    /// K_Hβ of the line load averaged over the points (uniform over whole mesh periods): the
    /// distribution ISO 6336-1 describes (a helical pair's instantaneous line load varies
    /// along the face with the number of contact lines crossing each ζ even when perfect).
    pub k_h_beta_cycle: f64,
    /// ISO 6336-1 method C for F_βy = |f_ma + f_Hβ,p + f_Hβ,g| and the aligned pair's mean
    /// mesh stiffness per unit face width.
    pub k_h_beta_iso: f64,
    /// Effective misalignment F_βy used, m.
    pub f_beta_y_m: f64,
    /// Mesh stiffness per unit face width of the aligned pair, N/(mm·µm).
    pub c_gamma_n_per_mm_um: f64,
}

/// Line loads at every point of `curve` (re-evaluated on `model` with detail) and K_Hβ beside
/// ISO 6336-1. The ISO stiffness comes from the same static run without modifications (and,
/// when the curve's bodies sit on supports, `supported`, on rigid bearings: c_γ is the mesh's
/// own). Each point is evaluated at its equilibrium's poses.
pub fn face_loads(
    model: &mut Mesh,
    curve: &StaticCurve,
    pitch: f64,
    points_per_pitch: usize,
    pitches: usize,
    supported: bool,
) -> Result<FaceLoads, String> {
    let mut points = Vec::with_capacity(curve.points.len());
    let mut k_max = f64::NEG_INFINITY;
    let mut sum = vec![0.0; model.slices_per_line()];
    for e in &curve.points {
        // At the equilibrium's poses (zero on rigid bearings).
        let s = MeshState {
            phi_p: e.phi_p,
            phi_g: e.phi_g,
            pose_p: e.pose_p,
            pose_g: e.pose_g,
            ..Default::default()
        };
        model.evaluate(&s).map_err(|e| e.to_string())?;
        let fl = face_load(model);
        for (a, w) in sum.iter_mut().zip(&fl.line_load) {
            *a += w;
        }
        let k = fl.k_h_beta();
        k_max = k_max.max(k);
        points.push((k, fl.max() * 1e-3, fl.mean() * 1e-3));
    }
    let pair = model.pair().clone();
    let mods = &pair.modifications;
    let f_beta_y =
        (mods.mesh_misalignment_m + mods.pinion.helix_slope_m + mods.gear.helix_slope_m).abs();
    let rb = model.geometry().pinion.rb;
    // ISO's c_γ is the mesh's own: a curve on supports holds their compliance too.
    let stiffness = if mods.is_default() && !supported {
        curve.mean_stiffness(rb)
    } else {
        let aligned = GearPair { modifications: Modifications::default(), ..pair.clone() };
        let mut m = Mesh::new(&aligned, *model.options()).map_err(|e| e.to_string())?;
        static_curve(&mut m, curve.torque, 0.0, pitch, points_per_pitch, pitches)
            .map_err(|e| e.to_string())?
            .mean_stiffness(rb)
    };
    let b = pair.face_width_m;
    let c_gamma = stiffness / b;
    let w_m = curve.torque / rb / b;
    let cycle_mean = sum.iter().sum::<f64>() / sum.len() as f64;
    let k_h_beta_cycle = sum.iter().copied().fold(0.0, f64::max) / cycle_mean;
    Ok(FaceLoads {
        points,
        k_h_beta_max: k_max,
        k_h_beta_cycle,
        k_h_beta_iso: k_h_beta_iso(f_beta_y, c_gamma, w_m),
        f_beta_y_m: f_beta_y,
        c_gamma_n_per_mm_um: c_gamma * 1e-9,
    })
}

/// Arguments of `helical-gear harris`.
#[derive(Args, Clone)]
pub struct HarrisArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    model: ModelArgs,
    /// Smallest torque, N·m (> 0).
    #[arg(long)]
    torque_from: f64,
    /// Largest torque, N·m.
    #[arg(long = "to")]
    torque_to: f64,
    /// Number of torques (uniform).
    #[arg(long, default_value_t = 10)]
    points: usize,
    /// JSON list of `{"name": …, "modifications": {…}}`; each variant's modifications are
    /// merged into those of the base parameters key by key (missing keys keep the base's).
    #[arg(long, value_name = "FILE")]
    variants: std::path::PathBuf,
    /// Pinion angles per pitch of each static curve.
    #[arg(long, default_value_t = 16)]
    points_per_pitch: usize,
    /// Total slices over the simultaneous contact lines.
    #[arg(long, default_value_t = 100)]
    slices: usize,
    /// Write harris.csv, harris.json and harris.png into DIR.
    #[arg(long, value_name = "DIR")]
    out: Option<std::path::PathBuf>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Variant {
    name: String,
    #[serde(default = "empty_object")]
    modifications: serde_json::Value,
}

fn empty_object() -> serde_json::Value {
    serde_json::Value::Object(Default::default())
}

fn plot_err(e: PlotError) -> String {
    e.to_string()
}

/// `helical-gear harris`: peak-to-peak static TE over one mesh period against torque for each
/// variant.
pub fn harris_cmd(a: &HarrisArgs) -> Result<(), String> {
    let base = load_params(&a.common)?;
    let (t0, t1) = (a.torque_from, a.torque_to);
    if !(t0.is_finite() && t1.is_finite() && t0 > 0.0 && t1 >= t0) {
        return Err(format!("--torque-from = {t0}, --to = {t1}: allowed 0 < from <= to, finite"));
    }
    if !(1..=1000).contains(&a.points) || !(2..=1000).contains(&a.points_per_pitch) {
        return Err(format!(
            "--points = {} (allowed 1..=1000), --points-per-pitch = {} (allowed 2..=1000)",
            a.points, a.points_per_pitch
        ));
    }
    let text = super::read_json_file("--variants", &a.variants)?;
    let variants: Vec<Variant> = serde_json::from_str(&text)
        .map_err(|e| format!("variants file {}: {e}", a.variants.display()))?;
    if variants.is_empty() {
        return Err("the variants file lists no variant".into());
    }
    let torques: Vec<f64> = (0..a.points)
        .map(|i| if a.points == 1 { t0 } else { t0 + (t1 - t0) * i as f64 / (a.points - 1) as f64 })
        .collect();
    let mut rows = Vec::new();
    for v in &variants {
        eprintln!("harris: variant {}", v.name);
        let modifications =
            base.modifications.merged(&v.modifications).map_err(|e| format!("{}: {e}", v.name))?;
        let pair = GearPair { modifications, ..base.clone() };
        let mut options = a.model.options(a.slices);
        options.detail = false;
        let mut m = Mesh::new(&pair, options).map_err(|e| format!("{}: {e}", v.name))?;
        let pitch = m.geometry().pinion.angular_pitch();
        let mut ptp = Vec::with_capacity(torques.len());
        for &t in &torques {
            let c = static_curve(&mut m, t, 0.0, pitch, a.points_per_pitch, 1)
                .map_err(|e| format!("{} at {t} N·m: {e}", v.name))?;
            ptp.push((c.max() - c.min()) * 1e6);
        }
        rows.push((v.name.clone(), ptp));
    }
    let record = HarrisRecord {
        torques_nm: torques.clone(),
        variants: rows
            .iter()
            .map(|(n, p)| HarrisVariantRecord { name: n.clone(), ste_peak_to_peak_um: p.clone() })
            .collect(),
    };
    record.check_finite()?;
    let out = serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let mut header = vec!["torque_nm".to_string()];
        header.extend(rows.iter().map(|(n, _)| format!("{n}_ste_peak_to_peak_um")));
        let h: Vec<&str> = header.iter().map(String::as_str).collect();
        let data = (0..torques.len()).map(|i| {
            std::iter::once(torques[i]).chain(rows.iter().map(|(_, p)| p[i])).collect::<Vec<_>>()
        });
        write_csv(&dir.join("harris.csv"), &h, data).map_err(plot_err)?;
        std::fs::write(dir.join("harris.json"), &out)
            .map_err(|e| format!("cannot write harris.json: {e}"))?;
        let chart = LineChart {
            title: "Harris map: peak-to-peak static TE".into(),
            x_label: "torque (N·m)".into(),
            y_label: "STE peak to peak (µm)".into(),
            series: rows
                .iter()
                .map(|(n, p)| Series {
                    name: n.clone(),
                    points: torques.iter().copied().zip(p.iter().copied()).collect(),
                    style: SeriesStyle::LinePoints,
                })
                .collect(),
            ..LineChart::default()
        };
        line_chart(&dir.join("harris.png"), &chart, (900, 600)).map_err(plot_err)?;
    }
    if a.common.json {
        println!("{out}");
    } else {
        print!("{:>12}", "torque_nm");
        for (n, _) in &rows {
            print!(" {n:>16}");
        }
        println!();
        for (i, t) in torques.iter().enumerate() {
            print!("{t:12.3}");
            for (_, p) in &rows {
                print!(" {:16.3}", p[i]);
            }
            println!();
        }
        println!("(peak-to-peak static TE over one mesh period, µm)");
    }
    Ok(())
}

/// Arguments of `helical-gear spectrum`.
#[derive(Args, Clone)]
pub struct SpectrumArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    drive: DriveArg,
    #[command(flatten)]
    model: ModelArgs,
    // `--friction`: with `--dynamic` only (the static spectrum is at standstill, where nothing
    // slides).
    #[command(flatten)]
    friction: FrictionArg,
    /// Driving torque, N·m (default: the drive line's `torque_nm`).
    #[arg(long)]
    torque: Option<f64>,
    /// Pinion angles per mesh period (the spectrum reaches half of this in mesh orders).
    #[arg(long, default_value_t = 8)]
    points_per_pitch: usize,
    /// Total slices over the simultaneous contact lines.
    #[arg(long, default_value_t = 100)]
    slices: usize,
    /// Largest pinion order printed and plotted (default: all up to the Nyquist order).
    #[arg(long)]
    max_order: Option<f64>,
    /// Write spectrum.csv, ste_hunting.csv and spectrum.png (with `--dynamic`:
    /// spectrum_dynamic.csv, te_dynamic.csv, spectrum_dynamic.png) into DIR.
    #[arg(long, value_name = "DIR")]
    out: Option<std::path::PathBuf>,
    /// The dynamic TE instead of the static one: Eqs. 1–4 on the table fidelity from the
    /// static start at `--speed` until TE repeats with the period of the deviations, then the
    /// spectrum of that last period.
    #[arg(long, requires = "speed")]
    dynamic: bool,
    /// Nominal pinion speed of `--dynamic`, rad/s.
    #[arg(long)]
    speed: Option<f64>,
    /// RK4 steps per mesh period of `--dynamic` (a multiple of --points-per-pitch).
    #[arg(long, default_value_t = 64)]
    steps_per_period: usize,
    /// Cap on the mesh periods integrated by `--dynamic`.
    #[arg(long, default_value_t = 20_000)]
    max_periods: usize,
}

/// The dynamic TE of `--dynamic` over one period of the response: (TE samples at
/// `points_per_pitch` per mesh period, meshes in the period, JSON of the run).
fn dynamic_te(
    a: &SpectrumArgs,
    pair: &GearPair,
    drive: &DriveLine,
    speed: f64,
) -> Result<(Vec<f64>, usize, SteadyRunRecord), String> {
    use helical_gear_mesh::dynamics::{
        Drivetrain, GearDynamics, SteadyMethod, SteadyRunOptions, run_to_steady,
    };
    if !(speed.is_finite() && speed > 0.0) {
        return Err(format!("--speed = {speed} rad/s: allowed > 0 and finite"));
    }
    if a.steps_per_period < 4 || !a.steps_per_period.is_multiple_of(a.points_per_pitch) {
        return Err(format!(
            "--steps-per-period = {}: allowed >= 4 and a multiple of --points-per-pitch = {}",
            a.steps_per_period, a.points_per_pitch
        ));
    }
    let mut options = a.model.options(a.slices);
    options.detail = false;
    options.fidelity = helical_gear_mesh::mesh::Fidelity::Table;
    options.friction = load_friction(&a.friction)?;
    eprintln!("spectrum: building the table");
    let mesh = Mesh::new(pair, options.sized_for(drive)).map_err(|e| e.to_string())?;
    let drive = Drivetrain::new(mesh.geometry(), drive).map_err(|e| e.to_string())?;
    let mut dynm = GearDynamics::new(mesh, drive).map_err(|e| e.to_string())?;
    let period = pair.modifications.period_meshes(pair.z_p, pair.z_g) as usize;
    eprintln!("spectrum: dynamics at {speed} rad/s until TE repeats every {period} meshes");
    let opts = SteadyRunOptions {
        method: SteadyMethod::Rk4 { steps_per_period: a.steps_per_period },
        max_periods: a.max_periods.max(2 * period),
        period_meshes: period,
        ..SteadyRunOptions::default()
    };
    let r = run_to_steady(&mut dynm, speed, &opts).map_err(|e| e.to_string())?;
    if let Some(w) = &r.warning {
        eprintln!("spectrum: warning: {w}");
    }
    let te = r.window_te(a.points_per_pitch).map_err(|e| e.to_string())?;
    Ok((te, r.period_multiple, SteadyRunRecord::new(speed, &r)))
}

/// `helical-gear spectrum`: the static TE over a whole hunting period and its spectrum in
/// orders of the pinion rotation.
pub fn spectrum_cmd(a: &SpectrumArgs) -> Result<(), String> {
    let pair = load_params(&a.common)?;
    let drive = load_drive(&a.drive)?;
    let torque = a.torque.unwrap_or(drive.torque_nm);
    if !(torque.is_finite() && torque > 0.0) {
        return Err(format!("--torque = {torque} N·m: allowed > 0 and finite"));
    }
    if !(2..=256).contains(&a.points_per_pitch) {
        return Err(format!("--points-per-pitch = {}: allowed 2..=256", a.points_per_pitch));
    }
    if let Some(k) = a.max_order.filter(|k| !(k.is_finite() && *k >= 0.0)) {
        return Err(format!(
            "--max-order = {k}: allowed finite and >= 0 (orders of the pinion rotation)"
        ));
    }
    let t0 = std::time::Instant::now();
    if a.dynamic {
        return dynamic_spectrum(a, &pair, &drive, t0);
    }
    if load_friction(&a.friction)?.is_on() {
        return Err("--friction applies to --dynamic only (the static spectrum is taken at \
                    standstill, where nothing slides)"
            .into());
    }
    // One static equilibrium per sample: bounded before the model is built or memory reserved.
    let hunting = Modifications::hunting_meshes(pair.z_p, pair.z_g);
    let samples = hunting.saturating_mul(a.points_per_pitch as u64);
    if samples > helical_gear_mesh::dynamics::MAX_SPECTRUM_SAMPLES {
        return Err(format!(
            "spectrum would solve {samples:.3e} static equilibria ({hunting} meshes of the \
             hunting period × {} points per pitch); at most {:.0e}: lower --points-per-pitch \
             or use tooth numbers with a common factor",
            a.points_per_pitch,
            helical_gear_mesh::dynamics::MAX_SPECTRUM_SAMPLES as f64
        ));
    }
    let mut options = a.model.options(a.slices).sized_for(&drive);
    options.detail = false;
    let mut m = Mesh::new(&pair, options).map_err(|e| e.to_string())?;
    let pitch = m.geometry().pinion.angular_pitch();
    let meshes = hunting as usize;
    let revs = meshes as f64 / pair.z_p as f64;
    eprintln!("spectrum: static TE over {meshes} meshes ({revs} pinion revolutions)");
    let curve = static_curve(&mut m, torque, 0.0, pitch, a.points_per_pitch, meshes)
        .map_err(|e| e.to_string())?;
    let ste: Vec<f64> = curve.points.iter().map(|e| e.te).collect();
    let amp = amplitude_spectrum(&ste);
    let orders: Vec<f64> = (0..amp.len()).map(|j| j as f64 / revs).collect();
    let max_order = a.max_order.unwrap_or(f64::INFINITY);
    let keep: Vec<usize> = (0..amp.len()).filter(|&j| orders[j] <= max_order).collect();
    let record = SpectrumRecord {
        torque_nm: torque,
        hunting_meshes: meshes,
        pinion_revolutions: revs,
        ste_mean_um: curve.mean() * 1e6,
        ste_peak_to_peak_um: (curve.max() - curve.min()) * 1e6,
        orders: keep.iter().map(|&j| orders[j]).collect(),
        amplitudes_um: keep.iter().map(|&j| amp[j] * 1e6).collect(),
        seconds: t0.elapsed().as_secs_f64(),
    };
    record.check_finite()?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        write_csv(
            &dir.join("spectrum.csv"),
            &["pinion_order", "amplitude_um"],
            keep.iter().map(|&j| vec![orders[j], amp[j] * 1e6]),
        )
        .map_err(plot_err)?;
        write_csv(
            &dir.join("ste_hunting.csv"),
            &["phi_p_rad", "ste_um"],
            curve.points.iter().map(|e| vec![e.phi_p, e.te * 1e6]),
        )
        .map_err(plot_err)?;
        let amp_max = keep.iter().skip(1).map(|&j| amp[j]).fold(0.0, f64::max);
        let chart = LineChart {
            title: format!("Static TE spectrum over a hunting period ({meshes} meshes)"),
            x_label: "order of the pinion rotation".into(),
            y_label: "amplitude (µm)".into(),
            series: vec![Series {
                name: String::new(),
                // Markers at the lines above 0.2 % of the largest (a line through thousands of
                // near-zero bins with sharp spikes draws miter artefacts).
                points: keep
                    .iter()
                    .skip(1)
                    .filter(|&&j| amp[j] > 2e-3 * amp_max)
                    .map(|&j| (orders[j], amp[j] * 1e6))
                    .collect(),
                style: SeriesStyle::Points,
            }],
            // From zero: the lines are amplitudes (≥ 0).
            y_range: Some((0.0, 1.05 * (amp_max * 1e6).max(1e-9))),
            ..LineChart::default()
        };
        line_chart(&dir.join("spectrum.png"), &chart, (1000, 600)).map_err(plot_err)?;
    }
    if a.common.json {
        println!("{}", serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?);
    } else {
        println!(
            "Static TE spectrum, M = {torque} N·m, hunting period {meshes} meshes ({revs} pinion \
             revolutions): mean {:.3} µm, peak to peak {:.3} µm",
            curve.mean() * 1e6,
            (curve.max() - curve.min()) * 1e6
        );
        let mut idx: Vec<usize> = keep.iter().copied().filter(|&j| j > 0).collect();
        idx.sort_by(|&x, &y| amp[y].total_cmp(&amp[x]));
        println!("  largest lines: {:>12} {:>12}", "order", "amplitude_um");
        for &j in idx.iter().take(20) {
            println!("                 {:12.4} {:12.5}", orders[j], amp[j] * 1e6);
        }
    }
    Ok(())
}

/// `spectrum --dynamic`: the dynamic TE over one period of the steady response and its
/// spectrum in orders of the pinion rotation.
fn dynamic_spectrum(
    a: &SpectrumArgs,
    pair: &GearPair,
    drive: &DriveLine,
    t0: std::time::Instant,
) -> Result<(), String> {
    let speed = a.speed.unwrap_or(f64::NAN);
    let (te, meshes, info) = dynamic_te(a, pair, drive, speed)?;
    let revs = meshes as f64 / pair.z_p as f64;
    let amp = amplitude_spectrum(&te);
    let orders: Vec<f64> = (0..amp.len()).map(|j| j as f64 / revs).collect();
    let max_order = a.max_order.unwrap_or(f64::INFINITY);
    let keep: Vec<usize> = (0..amp.len()).filter(|&j| orders[j] <= max_order).collect();
    let mean = te.iter().sum::<f64>() / te.len().max(1) as f64;
    let ptp = te.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - te.iter().copied().fold(f64::INFINITY, f64::min);
    let record = DynamicSpectrumRecord {
        dynamic: info,
        period_meshes: meshes,
        pinion_revolutions: revs,
        te_mean_um: mean * 1e6,
        te_peak_to_peak_um: ptp * 1e6,
        orders: keep.iter().map(|&j| orders[j]).collect(),
        amplitudes_um: keep.iter().map(|&j| amp[j] * 1e6).collect(),
        seconds: t0.elapsed().as_secs_f64(),
    };
    record.check_finite()?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        write_csv(
            &dir.join("spectrum_dynamic.csv"),
            &["pinion_order", "amplitude_um"],
            keep.iter().map(|&j| vec![orders[j], amp[j] * 1e6]),
        )
        .map_err(plot_err)?;
        let dphi = std::f64::consts::TAU / pair.z_p as f64 / a.points_per_pitch as f64;
        write_csv(
            &dir.join("te_dynamic.csv"),
            &["mesh_phase_rad", "te_um"],
            te.iter().enumerate().map(|(i, t)| vec![i as f64 * dphi, t * 1e6]),
        )
        .map_err(plot_err)?;
        let amp_max = keep.iter().skip(1).map(|&j| amp[j]).fold(0.0, f64::max);
        let chart = LineChart {
            title: format!("Dynamic TE spectrum at {speed} rad/s ({meshes} meshes)"),
            x_label: "order of the pinion rotation".into(),
            y_label: "amplitude (µm)".into(),
            series: vec![Series {
                name: String::new(),
                points: keep
                    .iter()
                    .skip(1)
                    .filter(|&&j| amp[j] > 2e-3 * amp_max)
                    .map(|&j| (orders[j], amp[j] * 1e6))
                    .collect(),
                style: SeriesStyle::Points,
            }],
            y_range: Some((0.0, 1.05 * (amp_max * 1e6).max(1e-9))),
            ..LineChart::default()
        };
        line_chart(&dir.join("spectrum_dynamic.png"), &chart, (1000, 600)).map_err(plot_err)?;
    }
    if a.common.json {
        println!("{}", serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?);
    } else {
        println!(
            "Dynamic TE spectrum at {speed} rad/s over {meshes} meshes ({revs} pinion \
             revolutions): mean {:.3} µm, peak to peak {:.3} µm",
            mean * 1e6,
            ptp * 1e6
        );
        let mut idx: Vec<usize> = keep.iter().copied().filter(|&j| j > 0).collect();
        idx.sort_by(|&x, &y| amp[y].total_cmp(&amp[x]));
        println!("  largest lines: {:>12} {:>12}", "order", "amplitude_um");
        for &j in idx.iter().take(20) {
            println!("                 {:12.4} {:12.5}", orders[j], amp[j] * 1e6);
        }
    }
    Ok(())
}
