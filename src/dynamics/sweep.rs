//! Speed sweeps: the steady dynamic TE relative to the static one over a range of pinion
//! speeds, run in parallel, and the location of the resonance peaks (the paper's Fig. 9).
//!
//! * [`static_te_curve`]: the static transmission error STE(φp) over one mesh period
//!   (φp ∈ [0, 2π/z_p)) from the static equilibrium M_F,p = M at each angle
//!   ([`crate::mesh::statics::equilibrium`]); its maximum STE_max normalises the sweep (a
//!   finer curve gives a slightly larger maximum: [`SweepOptions::static_points`]).
//! * [`sweep`]: one [`run_to_steady`] per speed, on a rayon pool; every worker owns its own
//!   clone of the mesh (for [`crate::mesh::Mesh`]: the shared `Arc` of the immutable model and
//!   table, the worker's own workspace), and every run starts the load solver cold
//!   ([`MeshTorques::set_warm_start`] with an empty warm start), so a speed's result does not
//!   depend on the worker or on the runs before it; results come back in the order of the
//!   speeds given. For each speed: TE_max/STE_max over the steady window and
//!   the separation, tip-contact and back-contact flags of that window.
//! * Resonances: the interior local maxima of TE_max/STE_max over the speed grid whose
//!   topographic prominence (height above the higher of the two lowest points that separate it
//!   from higher ground on either side) is at least [`SweepOptions::min_prominence`], each
//!   refined by a golden-section search for the maximum inside its two neighbouring grid
//!   speeds ([`SweepOptions::refine_runs`] extra runs per peak, peaks in parallel). The
//!   bracket shrinks by about 0.618 per run.
//!
//! Step size: unless [`SteadyRunOptions::max_step`] is set, the sweep estimates the mesh
//! stiffness and damping at the static equilibrium ([`mesh_stiffness`],
//! [`super::model::mesh_linearisation`]), takes the fastest rate ω_max of Eqs. 1–4 linearised
//! ([`Drivetrain::linear_frequencies`], [`Drivetrain::fastest_rate`]: the damped eigenvalues,
//! which an overdamped mesh mode moves beyond the undamped frequency) and limits the
//! RK4 step to 2π/(ω_max·[`SweepOptions::steps_per_fastest_mode`]) ([`stable_rk4_step`]):
//! at low speeds the mesh mode, not the mesh period, sets the step. Work is bounded before
//! anything runs: at most [`MAX_SWEEP_SPEEDS`] speeds, [`MAX_REFINE_RUNS`] refinement runs
//! per peak, and each run's steps and window by [`run_to_steady`]'s bounds (a sweep at
//! 0.01 rad/s is refused at once rather than integrating for hours).
//!
//! Progress: with [`SweepOptions::progress`] one line per finished run goes to stderr (never
//! stdout).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use super::limits::{MAX_REFINE_RUNS, MAX_SPECTRUM_SAMPLES, MAX_SWEEP_SPEEDS, stable_rk4_step};
#[cfg(doc)]
use super::model::mesh_stiffness;
use super::model::{Drivetrain, DynamicsError, GearDynamics, invalid, mesh_linearisation};
use super::simulate::{
    DEFAULT_STEPS_PER_MESH_PERIOD, SteadyMethod, SteadyResponse, SteadyRunOptions, SteadyWarning,
    run_to_steady,
};
use crate::mesh::statics::{StaticCurve, static_curve};
use crate::mesh::{MeshError, MeshTorques, WarmStart};

/// STE(φp) at `points` (≥ 2) equally spaced pinion angles φp_i = i·2π/(z_p·points) over one
/// mesh period, under driving torque `torque` (N·m, > 0): [`static_curve`] (each angle's
/// [`crate::mesh::statics::equilibrium`] started from the previous STE) over one pinion pitch.
pub fn static_te_curve<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    torque: f64,
    z_p: u32,
    points: usize,
) -> Result<StaticCurve, MeshError> {
    if points < 2 || z_p == 0 || !(torque.is_finite() && torque > 0.0) {
        return Err(MeshError::Equilibrium(format!(
            "static TE curve needs points >= 2 (got {points}), z_p >= 1 (got {z_p}) and a \
             finite torque > 0 (got {torque} N·m)"
        )));
    }
    let pitch = 2.0 * std::f64::consts::PI / z_p as f64;
    static_curve(mesh, torque, 0.0, pitch, points, 1)
}

/// Options of [`sweep`].
#[derive(Debug, Clone, PartialEq)]
pub struct SweepOptions {
    /// Options of every run ([`run_to_steady`]); `keep_window` is ignored (windows are not
    /// kept).
    pub run: SteadyRunOptions,
    /// Points of the static TE curve over one mesh period (≥ 2). Default 64.
    pub static_points: usize,
    /// RK4 steps per period of the fastest linearised mode, used to set the largest step when
    /// `run.max_step` is `None` (see the module doc); `None` leaves the step to the steps per
    /// mesh period alone. Default [`DEFAULT_STEPS_PER_MESH_PERIOD`].
    pub steps_per_fastest_mode: Option<usize>,
    /// Worker threads; `None` uses rayon's default (the number of cores). Default `None`.
    pub threads: Option<usize>,
    /// Extra runs per resonance peak for the golden-section refinement; 0 keeps the grid
    /// maximum. Default 6.
    pub refine_runs: usize,
    /// Smallest prominence of a peak of TE_max/STE_max (dimensionless) to count as a
    /// resonance. Default 0.005: the higher-order resonances of a well-damped mesh rise only
    /// a few per cent above their surroundings, while a steady run's TE_max is converged to
    /// about 10⁻³ of the TE peak-to-peak.
    pub min_prominence: f64,
    /// One line per finished run on stderr. Default false.
    pub progress: bool,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self {
            run: SteadyRunOptions { keep_window: false, ..SteadyRunOptions::default() },
            static_points: 64,
            steps_per_fastest_mode: Some(DEFAULT_STEPS_PER_MESH_PERIOD),
            threads: None,
            refine_runs: 6,
            min_prominence: 0.005,
            progress: false,
        }
    }
}

/// The result of one speed of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    /// Pinion speed ω_p, rad/s.
    pub omega_p: f64,
    /// Largest TE over the steady window divided by STE_max.
    pub te_max_over_ste_max: f64,
    /// Smallest TE over the steady window divided by STE_max (negative: separation).
    pub te_min_over_ste_max: f64,
    /// Teeth separated somewhere in the steady window.
    pub separated: bool,
    /// Tip rounding or edge in contact somewhere in the steady window.
    pub tip_contact: bool,
    /// Back flanks in contact somewhere in the steady window.
    pub back_contact: bool,
    /// Steady state detected (otherwise see `warning`).
    pub steady: bool,
    /// Why the result is not a detected steady state, if it is not.
    pub warning: Option<SteadyWarning>,
    /// Period of the steady TE in mesh periods.
    pub period_multiple: usize,
    /// Mesh periods integrated.
    pub periods: f64,
    /// Mesh evaluations of the run.
    pub mesh_evaluations: usize,
    /// Peak outputs over the steady window against their static values at the same torque.
    pub over_static: PeakOverStatic,
    /// Mean mesh efficiency over the steady window, 1 − mean P_loss / mean mesh input power
    /// ([`SteadyResponse::p_loss_mean`], [`SteadyResponse::p_in_mean`]), dimensionless; 1
    /// without friction or where the mean input power is not positive.
    pub mesh_efficiency_mean: f64,
}

/// The static peaks of a sweep's outputs over a mesh cycle at the sweep's torque (from the
/// static curve), against which each speed's steady peaks are reported ([`PeakOverStatic`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StaticPeaks {
    /// Largest |F_p| over the static curve, N (0 for a mesh without contact geometry).
    pub force_p_max: f64,
    /// Largest tooth-root stress of the pinion and of the gear over the static curve, Pa (0
    /// for a mesh without FE data).
    pub root_stress_max: [f64; 2],
}

impl StaticPeaks {
    /// The peaks of `curve`.
    pub fn of(curve: &StaticCurve) -> Self {
        let force_p_max = curve
            .points
            .iter()
            .map(|e| super::simulate::norm3(e.outputs.force_p))
            .fold(0.0, f64::max);
        let root_stress_max = [
            curve.points.iter().map(|e| e.outputs.root_stress_p).fold(0.0, f64::max),
            curve.points.iter().map(|e| e.outputs.root_stress_g).fold(0.0, f64::max),
        ];
        Self { force_p_max, root_stress_max }
    }
}

/// The peak of each output over one speed's steady window divided by its static peak over a
/// mesh cycle at the same torque ([`StaticPeaks`]): the dynamic factors engineers compare with
/// ISO 6336-1's K_v. `None` where the static peak is 0 (a mesh without contact geometry).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PeakOverStatic {
    /// max |F_p| over the steady window / max |F_p| over the static curve.
    pub mesh_force: Option<f64>,
    /// The tooth-root stress: the larger of the pinion's and the gear's max σ_F over the
    /// steady window / their max σ_F over the static curve (each gear against its own static
    /// peak).
    pub root_stress: Option<f64>,
}

impl PeakOverStatic {
    /// The ratios of the steady response `r` against `statics`.
    pub fn new(r: &SteadyResponse, statics: &StaticPeaks) -> Self {
        let ratio = |peak: f64, reference: f64| (reference > 0.0).then(|| peak / reference);
        let stress = |k: usize| ratio(r.root_stress_max[k], statics.root_stress_max[k]);
        let root_stress = match (stress(0), stress(1)) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        Self { mesh_force: ratio(r.force_p_max, statics.force_p_max), root_stress }
    }
}

impl SweepPoint {
    fn from_response(r: &SteadyResponse, ste_max: f64, statics: &StaticPeaks) -> Self {
        let mesh_efficiency_mean =
            if r.p_in_mean > 0.0 { 1.0 - r.p_loss_mean / r.p_in_mean } else { 1.0 };
        Self {
            over_static: PeakOverStatic::new(r, statics),
            mesh_efficiency_mean,
            omega_p: r.omega_p,
            te_max_over_ste_max: r.te_max / ste_max,
            te_min_over_ste_max: r.te_min / ste_max,
            separated: r.separated,
            tip_contact: r.tip_contact,
            back_contact: r.back_contact,
            steady: r.steady,
            warning: r.warning,
            period_multiple: r.period_multiple,
            periods: r.periods,
            mesh_evaluations: r.mesh_evaluations,
        }
    }
}

/// A located resonance peak.
#[derive(Debug, Clone, PartialEq)]
pub struct Resonance {
    /// Pinion speed of the largest TE_max/STE_max found, rad/s.
    pub omega_p: f64,
    /// TE_max/STE_max there.
    pub te_max_over_ste_max: f64,
    /// Final bracket of the golden-section search, rad/s (the neighbouring grid speeds when
    /// not refined).
    pub bracket: (f64, f64),
    /// Index of the peak in the speed grid.
    pub grid_index: usize,
    /// Prominence of the grid peak.
    pub prominence: f64,
    /// The refinement runs, in the order made.
    pub refinement: Vec<SweepPoint>,
}

/// Result of [`sweep`].
#[derive(Debug, Clone, PartialEq)]
pub struct SweepResult {
    /// The static TE curve (normalisation).
    pub ste: StaticCurve,
    /// One point per speed, in the order the speeds were given.
    pub points: Vec<SweepPoint>,
    /// Resonances, in ascending speed.
    pub resonances: Vec<Resonance>,
    /// Linearised mesh stiffness at φp = 0, N/m, when it was estimated for the step size.
    pub mesh_stiffness: Option<f64>,
    /// Largest RK4 step used, s (`None`: steps per mesh period only).
    pub max_step: Option<f64>,
    /// Wall-clock time of the whole sweep, s.
    pub wall_seconds: f64,
}

/// Indices of the interior local maxima of `values` with prominence ≥ `min_prominence`, with
/// their prominences, in ascending index (`values` finite). A plateau counts once, at its
/// first point.
pub fn find_peaks(values: &[f64], min_prominence: f64) -> Vec<(usize, f64)> {
    let n = values.len();
    let mut peaks = Vec::new();
    if n < 3 {
        return peaks;
    }
    for i in 1..n - 1 {
        let v = values[i];
        if v <= values[i - 1] {
            continue;
        }
        // Plateau: the first point after it that differs must be lower.
        let mut j = i + 1;
        while j < n && values[j] == v {
            j += 1;
        }
        if j == n || values[j] >= v {
            continue;
        }
        // Lowest point on each side before higher ground (or the end).
        let mut left_min = v;
        for &x in values[..i].iter().rev() {
            if x > v {
                break;
            }
            left_min = left_min.min(x);
        }
        let mut right_min = v;
        for &x in &values[j..] {
            if x > v {
                break;
            }
            right_min = right_min.min(x);
        }
        let prominence = v - left_min.max(right_min);
        if prominence >= min_prominence {
            peaks.push((i, prominence));
        }
    }
    peaks
}

/// Best point, final bracket and the runs made by [`golden_max`].
type GoldenResult = (SweepPoint, (f64, f64), Vec<SweepPoint>);

/// Golden-section search for the maximum of `f` given a bracketing triplet a < b < c with
/// f(b) ≥ f(a), f(c); `runs` evaluations. Returns (x, f(x), bracket, evaluations).
fn golden_max<E>(
    (mut a, mut b, mut c): (f64, f64, f64),
    mut fb: SweepPoint,
    runs: usize,
    mut f: impl FnMut(f64) -> Result<SweepPoint, E>,
) -> Result<GoldenResult, E> {
    const R: f64 = 0.381_966_011_250_105_1; // 2 − golden ratio
    let mut made = Vec::with_capacity(runs);
    for _ in 0..runs {
        let x = if c - b > b - a { b + R * (c - b) } else { b - R * (b - a) };
        let fx = f(x)?;
        made.push(fx);
        if fx.te_max_over_ste_max > fb.te_max_over_ste_max {
            if x > b {
                a = b;
            } else {
                c = b;
            }
            b = x;
            fb = fx;
        } else if x > b {
            c = x;
        } else {
            a = x;
        }
    }
    Ok((fb, (a, c), made))
}

/// Checks a sweep request before any work: `speeds` (rad/s) non-empty, each finite in
/// (0, 10⁵] ([`crate::mesh::validity::MAX_SPEED_RAD_S`]) and strictly ascending, at most
/// [`MAX_SWEEP_SPEEDS`]; the options' prominence finite and ≥ 0, threads ≥ 1, static points
/// and refinement runs within their bounds. [`fn@sweep`] calls it first; the CLI and Python
/// call it before they build the mesh (a table build takes up to a minute), so a bad argument
/// is refused at once.
pub fn check_sweep_request(speeds: &[f64], opts: &SweepOptions) -> Result<(), DynamicsError> {
    if speeds.is_empty() {
        return Err(DynamicsError::InvalidInput {
            name: "speeds",
            value: 0.0,
            allowed: "at least one speed (the number of speeds given is 0)",
        });
    }
    for (i, &w) in speeds.iter().enumerate() {
        if !(w.is_finite() && w > 0.0 && w <= crate::mesh::validity::MAX_SPEED_RAD_S) {
            return Err(invalid("speeds", w, "finite, 0 < speed <= 1e5 rad/s"));
        }
        if i > 0 && w <= speeds[i - 1] {
            return Err(invalid("speeds", w, "strictly ascending"));
        }
    }
    if !(opts.min_prominence.is_finite() && opts.min_prominence >= 0.0) {
        return Err(invalid("min_prominence", opts.min_prominence, "finite and >= 0"));
    }
    if opts.threads == Some(0) {
        return Err(invalid("threads", 0.0, ">= 1"));
    }
    if speeds.len() > MAX_SWEEP_SPEEDS {
        return Err(DynamicsError::TooLarge(format!(
            "a sweep of {} speeds; at most {MAX_SWEEP_SPEEDS}: use fewer speeds",
            speeds.len()
        )));
    }
    if opts.static_points as u64 > MAX_SPECTRUM_SAMPLES {
        return Err(DynamicsError::TooLarge(format!(
            "a static TE curve of {} points (one static equilibrium each); at most \
             {MAX_SPECTRUM_SAMPLES}: lower static_points",
            opts.static_points
        )));
    }
    if opts.refine_runs > MAX_REFINE_RUNS {
        return Err(DynamicsError::TooLarge(format!(
            "{} refinement runs per resonance (each a run to the steady state); at most \
             {MAX_REFINE_RUNS} (the bracket shrinks by 0.618 per run): lower refine_runs",
            opts.refine_runs
        )));
    }
    Ok(())
}

/// Runs `mesh` with drivetrain `drive` to the steady state at every speed of `speeds`
/// (rad/s, > 0, ascending for the resonance search) and locates the resonances; see the
/// module doc.
pub fn sweep<M>(
    mesh: &M,
    drive: &Drivetrain,
    speeds: &[f64],
    opts: &SweepOptions,
) -> Result<SweepResult, DynamicsError>
where
    M: MeshTorques + Clone + Send,
{
    let t0 = Instant::now();
    drive.validate()?;
    check_sweep_request(speeds, opts)?;
    let mesh_err = |source| DynamicsError::Mesh { t: None, source };

    // Static pass (and the model check) on this thread.
    let mut proto = mesh.clone();
    let ste = static_te_curve(&mut proto, drive.torque, drive.z_p, opts.static_points)
        .map_err(mesh_err)?;
    let ste_max = ste.max();
    let statics = StaticPeaks::of(&ste);
    if ste_max.is_nan() || ste_max <= 0.0 {
        return Err(invalid("ste_max", ste_max, "> 0 (m): the torque must load the teeth"));
    }
    let mut run = SteadyRunOptions { keep_window: false, ..opts.run.clone() };
    let mut k_mesh = None;
    if run.max_step.is_none()
        && let (Some(n), SteadyMethod::Rk4 { .. }) = (opts.steps_per_fastest_mode, &run.method)
    {
        if n == 0 {
            return Err(invalid("steps_per_fastest_mode", 0.0, ">= 1"));
        }
        let lin = mesh_linearisation(&mut proto, run.phi_p0, drive.torque).map_err(mesh_err)?;
        let k = lin.stiffness;
        if k.is_finite() && k > 0.0 {
            let (gp, gg) = proto.base_radii();
            // The fastest rate of the damped linearisation (the mesh damping of Eq. 14 may
            // overdamp the mesh mode: see `limits`).
            let w_max = drive.linear_frequencies(k, gp, gg)[3].max(drive.fastest_rate(
                k,
                lin.damping,
                gp,
                gg,
            ));
            // The step rule of `limits` with the sweep's finer steps per fastest period.
            run.max_step = Some(stable_rk4_step(f64::INFINITY, 1.0, w_max, n as f64));
            k_mesh = Some(k);
        }
    }
    GearDynamics::new(proto.clone(), *drive)?;

    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = opts.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().map_err(|_| {
        invalid("threads", opts.threads.unwrap_or(0) as f64, "a thread pool that can start")
    })?;

    let proto = Mutex::new(proto);
    let new_model = || -> Option<GearDynamics<M>> {
        let m = proto.lock().unwrap_or_else(|p| p.into_inner()).clone();
        GearDynamics::new(m, *drive).ok()
    };
    let done = AtomicUsize::new(0);
    let refined = AtomicUsize::new(0);
    let one = |model: &mut Option<GearDynamics<M>>,
               w: f64,
               refining: Option<usize>|
     -> Result<SweepPoint, DynamicsError> {
        let model =
            model.as_mut().ok_or_else(|| invalid("model", w, "a model that can be built"))?;
        // Every run from a cold start: the thread's model (shared mesh model, the thread's
        // workspace) carries nothing from its earlier runs, so the results do not depend on
        // which thread ran which speed.
        model.set_warm_start(&WarmStart::default());
        let r = run_to_steady(model, w, &run)
            .map_err(|e| DynamicsError::AtSpeed { omega_p: w, source: Box::new(e) })?;
        let p = SweepPoint::from_response(&r, ste_max, &statics);
        if opts.progress {
            let (label, k, total) = match refining {
                None => ("", done.fetch_add(1, Ordering::Relaxed) + 1, speeds.len()),
                Some(n) => ("refine ", refined.fetch_add(1, Ordering::Relaxed) + 1, n),
            };
            let mut flags = String::new();
            if p.separated {
                flags.push_str(", separated");
            }
            if p.back_contact {
                flags.push_str(", back contact");
            }
            if p.tip_contact {
                flags.push_str(", tip contact");
            }
            let state = if p.steady {
                format!("steady (period {} T_m) after {:.0} periods", p.period_multiple, p.periods)
            } else {
                format!("NOT steady after {:.0} periods", p.periods)
            };
            eprintln!(
                "sweep {label}{k}/{total}: ω_p = {w:.2} rad/s, TE_max/STE_max = {:.4}, {state}{flags}",
                p.te_max_over_ste_max
            );
        }
        Ok(p)
    };

    let points: Vec<SweepPoint> = pool.install(|| {
        speeds
            .par_iter()
            .map_init(new_model, |model, &w| one(model, w, None))
            .collect::<Result<Vec<_>, _>>()
    })?;

    let values: Vec<f64> = points.iter().map(|p| p.te_max_over_ste_max).collect();
    let peaks = find_peaks(&values, opts.min_prominence);
    let refine_total = Some(peaks.len() * opts.refine_runs);
    let resonances: Vec<Resonance> = pool.install(|| {
        peaks
            .par_iter()
            .with_max_len(1)
            .map_init(new_model, |model, &(i, prominence)| {
                let triplet = (speeds[i - 1], speeds[i], speeds[i + 1]);
                let (best, bracket, made) =
                    golden_max(triplet, points[i], opts.refine_runs, |w| {
                        one(model, w, refine_total)
                    })?;
                Ok(Resonance {
                    omega_p: best.omega_p,
                    te_max_over_ste_max: best.te_max_over_ste_max,
                    bracket,
                    grid_index: i,
                    prominence,
                    refinement: made,
                })
            })
            .collect::<Result<Vec<_>, DynamicsError>>()
    })?;

    Ok(SweepResult {
        ste,
        points,
        resonances,
        mesh_stiffness: k_mesh,
        max_step: run.max_step,
        wall_seconds: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peaks_with_prominence_plateaus_and_edges() {
        // Edge maxima are not peaks; a small bump on a flank has a small prominence.
        let v = [3.0, 1.0, 2.0, 1.5, 1.6, 1.0, 5.0, 5.0, 4.0, 4.5];
        let p = find_peaks(&v, 0.0);
        assert_eq!(p.iter().map(|x| x.0).collect::<Vec<_>>(), vec![2, 4, 6]);
        assert!((p[0].1 - 1.0).abs() < 1e-12); // 2 − max(1, 1)
        assert!((p[1].1 - 0.1).abs() < 1e-12); // 1.6 − max(1.5, 1.0)
        assert!((p[2].1 - 1.0).abs() < 1e-12); // 5 − max(1.0, 4.0): the right side ends at 4.0
        let p = find_peaks(&v, 0.5);
        assert_eq!(p.iter().map(|x| x.0).collect::<Vec<_>>(), vec![2, 6]);
        assert!(find_peaks(&[1.0, 2.0], 0.0).is_empty());
        assert!(find_peaks(&[1.0, 1.0, 1.0], 0.0).is_empty());
    }

    #[test]
    fn golden_section_finds_the_maximum_of_a_parabola() {
        let f = |w: f64| -> Result<SweepPoint, ()> {
            Ok(SweepPoint {
                omega_p: w,
                te_max_over_ste_max: 2.0 - (w - 1.234).powi(2),
                te_min_over_ste_max: 0.0,
                separated: false,
                tip_contact: false,
                back_contact: false,
                steady: true,
                warning: None,
                period_multiple: 1,
                periods: 0.0,
                mesh_evaluations: 0,
                over_static: PeakOverStatic::default(),
                mesh_efficiency_mean: 1.0,
            })
        };
        let (best, (a, c), made) = golden_max((1.0, 1.2, 1.6), f(1.2).unwrap(), 20, f).unwrap();
        assert_eq!(made.len(), 20);
        assert!(a <= 1.234 && 1.234 <= c);
        assert!((c - a) < 0.6 * 0.62f64.powi(18), "bracket {a}..{c}");
        assert!((best.omega_p - 1.234).abs() < 1e-4);
    }
}
