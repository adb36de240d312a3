//! Static equilibrium of the mesh (paper §6, the static part): for a pinion angle φp and a
//! driving torque M, the gear angle φg at which the elastic mesh torque balances it,
//! M_F,p(φp, φg) = M (Eqs. 1–4 without the dynamic terms; the shafts then only wind up and do
//! not change the mesh). The static transmission error is STE(φp) = TE at that φg (Eq. 16).
//!
//! The unknown is TE (φg = (TE − φp·g_p)/g_g): at fixed φp, M_F,p is continuous and
//! non-decreasing in TE (more overlap, more load), strictly increasing once any slice is
//! loaded. The root is bracketed by expanding from a guess and then found by Brent's method
//! (inverse quadratic interpolation with bisection safeguard), which converges superlinearly
//! on the piecewise-smooth M_F,p(TE) and never leaves the bracket. The bracket search ends at
//! the model's validity range ([`MeshTorques::te_range`], `super::validity`): a torque that no
//! TE inside it carries is an [`MeshError::Equilibrium`] naming the bound, not an evaluation
//! beyond it.
//!
//! [`tip_contact_threshold_curve`] gives, over one mesh period, the smallest TE at which a
//! loaded contact reaches a tip rounding or tip edge: the static onset of tip contact that the
//! paper run compares with the steady dynamic TE.

use super::{BodyPose, MeshError, MeshOutputs, MeshState, MeshTorques};

/// A static equilibrium point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equilibrium {
    /// Pinion angle φp, rad (as given).
    pub phi_p: f64,
    /// Gear angle φg of equilibrium, rad.
    pub phi_g: f64,
    /// Static transmission error at this φp, m.
    pub te: f64,
    /// Mesh outputs at the equilibrium (at the speeds of [`EquilibriumSettings::w_p`]).
    pub outputs: MeshOutputs,
    /// Number of mesh evaluations used.
    pub evaluations: usize,
    /// The pinion body's pose at the equilibrium ([`super::pose`]; zero on rigid bearings).
    pub pose_p: BodyPose,
    /// The gear body's pose at the equilibrium.
    pub pose_g: BodyPose,
}

/// Settings of [`equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumSettings {
    /// Torque tolerance relative to |M| (dimensionless).
    pub rel_tol: f64,
    /// Absolute TE tolerance, m: the bracket is not narrowed below this. A bracket narrowed to
    /// it is accepted with a torque residual up to 1e-4·|M| (a very stiff mesh at a small
    /// torque: 1e-15 m of TE can be more than `rel_tol` of the torque).
    pub te_tol: f64,
    /// Largest number of mesh evaluations.
    pub max_evaluations: usize,
    /// Pinion speed of the quasi-static state, rad/s (default 0: standstill), the gear
    /// turning at the rigid ratio φ̇g = −φ̇p·g_p/g_g, so that TE does not change and the
    /// damping of Eq. 14 is zero. It matters only with friction ([`super::friction`]): the
    /// sliding speeds, the friction torques inside M_F,p and the loss.
    pub w_p: f64,
    /// The pinion body's pose ([`super::pose`]; default zero: rigid bearings).
    pub pose_p: BodyPose,
    /// The gear body's pose.
    pub pose_g: BodyPose,
}

impl Default for EquilibriumSettings {
    /// |M_F,p − M| ≤ 1e-11·|M|, TE to 1e-15 m, at most 200 evaluations, at rest on rigid
    /// bearings.
    fn default() -> Self {
        Self {
            rel_tol: 1e-11,
            te_tol: 1e-15,
            max_evaluations: 200,
            w_p: 0.0,
            pose_p: BodyPose::default(),
            pose_g: BodyPose::default(),
        }
    }
}

/// Finds φg with M_F,p(φp, φg) = `torque` (N·m, > 0 drives the pinion flanks) at pinion angle
/// `phi_p` (rad), starting the bracket search at `te_guess` (m; e.g. the previous phase's STE).
/// φg is formed from TE, so |φp| is held to [`super::validity::check_formed_angle`]'s bound
/// (an error naming `phi_p` beyond it).
pub fn equilibrium<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
    te_guess: f64,
    settings: &EquilibriumSettings,
) -> Result<Equilibrium, MeshError> {
    for (name, v) in
        [("phi_p", phi_p), ("torque", torque), ("te_guess", te_guess), ("w_p", settings.w_p)]
    {
        if !v.is_finite() {
            return Err(MeshError::NonFinite { name, value: v });
        }
    }
    let (gp, gg) = mesh.base_radii();
    // The search forms φg from TE: TE keeps its digits only up to a bound on φp.
    super::validity::check_formed_angle("phi_p", phi_p, gp).map_err(MeshError::Param)?;
    let (te_lo, te_hi) = mesh.te_range();
    let te_guess = te_guess.clamp(te_lo, te_hi);
    let count = std::cell::Cell::new(0usize);
    let eval = |mesh: &mut M, te: f64| -> Result<(f64, MeshOutputs), MeshError> {
        count.set(count.get() + 1);
        let state = MeshState {
            phi_p,
            phi_g: crate::numeric::phi_g_for_te(phi_p, te, gp, gg),
            w_p: settings.w_p,
            w_g: -settings.w_p * gp / gg,
            pose_p: settings.pose_p,
            pose_g: settings.pose_g,
            ..Default::default()
        };
        let o = mesh.mesh(&state)?;
        Ok((o.m_f_p - torque, o))
    };
    let tol_m = settings.rel_tol * torque.abs().max(1e-300);

    // Bracket: f(a) < 0 < f(b) (f increasing in TE).
    let mut step = 1e-6_f64.max(te_guess.abs() * 0.05);
    let (mut a, mut fa_o) = {
        let (f, o) = eval(mesh, te_guess)?;
        (te_guess, (f, o))
    };
    if fa_o.0.abs() <= tol_m {
        return Ok(Equilibrium {
            phi_p,
            phi_g: crate::numeric::phi_g_for_te(phi_p, a, gp, gg),
            te: a,
            outputs: fa_o.1,
            evaluations: count.get(),
            pose_p: settings.pose_p,
            pose_g: settings.pose_g,
        });
    }
    let (mut b, mut fb_o);
    if fa_o.0 < 0.0 {
        loop {
            b = (a + step).min(te_hi);
            fb_o = eval(mesh, b)?;
            if fb_o.0 >= 0.0 {
                break;
            }
            if b >= te_hi {
                return Err(MeshError::Equilibrium(format!(
                    "no TE up to the end of the model's validity range, {te_hi:.4e} m, carries \
                     the torque {torque} N·m at φp = {phi_p} rad (largest mesh torque {:.4e} N·m)",
                    fb_o.1.m_f_p
                )));
            }
            a = b;
            fa_o = fb_o;
            step *= 2.0;
            if step > 1.0 || count.get() > settings.max_evaluations {
                return Err(MeshError::Equilibrium(format!(
                    "no TE up to {b:.3e} m carries the torque {torque} N·m at φp = {phi_p} rad"
                )));
            }
        }
    } else {
        b = a;
        fb_o = fa_o;
        loop {
            a = (b - step).max(te_lo);
            fa_o = eval(mesh, a)?;
            if fa_o.0 < 0.0 {
                break;
            }
            if a <= te_lo {
                return Err(MeshError::Equilibrium(format!(
                    "mesh torque stays above {torque} N·m down to the end of the model's validity \
                     range, TE = {te_lo:.4e} m, at φp = {phi_p} rad"
                )));
            }
            b = a;
            fb_o = fa_o;
            step *= 2.0;
            if step > 1.0 || count.get() > settings.max_evaluations {
                return Err(MeshError::Equilibrium(format!(
                    "mesh torque stays above {torque} N·m down to TE = {a:.3e} m at φp = {phi_p} rad"
                )));
            }
        }
    }

    // Brent's method on [a, b].
    let (mut fa, mut fb) = (fa_o.0, fb_o.0);
    let mut best = if fa.abs() < fb.abs() { (a, fa_o.1, fa) } else { (b, fb_o.1, fb) };
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    // Set when the bracket around the root has shrunk to the TE tolerance: on a stiff mesh a
    // TE step of te_tol can change the torque by more than rel_tol·|M|, and the root is then
    // as well determined as TE allows.
    let mut bracketed_to_te_tol = false;
    while count.get() < settings.max_evaluations {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * settings.te_tol;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            bracketed_to_te_tol = true;
            break;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        let (f, o) = eval(mesh, b)?;
        fb = f;
        if f.abs() < best.2.abs() {
            best = (b, o, f);
        }
        if f.abs() <= tol_m {
            break;
        }
    }
    // Accepted: the torque tolerance met (to 1e-9), or the bracket at the TE tolerance with a
    // residual that a continuous M_F,p(TE) explains (a jump would leave a larger one).
    let accept = if bracketed_to_te_tol { 1e-4 } else { 1e-9 };
    if best.2.abs() > tol_m.max(accept * torque.abs()) {
        return Err(MeshError::Equilibrium(format!(
            "torque residual {:.3e} N·m after {} evaluations at φp = {phi_p} rad \
             (TE = {:.6e} m)",
            best.2,
            count.get(),
            best.0
        )));
    }
    let te = best.0;
    Ok(Equilibrium {
        phi_p,
        phi_g: crate::numeric::phi_g_for_te(phi_p, te, gp, gg),
        te,
        outputs: best.1,
        evaluations: count.get(),
        pose_p: settings.pose_p,
        pose_g: settings.pose_g,
    })
}

/// The static transmission error over a range of pinion angles (paper §6, Fig. 7, Eq. 16).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticCurve {
    /// Driving torque M, N·m.
    pub torque: f64,
    /// The equilibrium at each pinion angle (uniform steps).
    pub points: Vec<Equilibrium>,
}

impl StaticCurve {
    /// Largest STE, m.
    pub fn max(&self) -> f64 {
        self.points.iter().map(|e| e.te).fold(f64::NEG_INFINITY, f64::max)
    }

    /// Smallest STE, m.
    pub fn min(&self) -> f64 {
        self.points.iter().map(|e| e.te).fold(f64::INFINITY, f64::min)
    }

    /// Mean STE over the points, m.
    pub fn mean(&self) -> f64 {
        self.points.iter().map(|e| e.te).sum::<f64>() / self.points.len().max(1) as f64
    }

    /// Mean secant mesh stiffness along the transverse line of action, N/m: the mean over the
    /// points of (M/g_p)/STE (force along the line of action per unit TE).
    pub fn mean_stiffness(&self, base_radius_p: f64) -> f64 {
        let f = self.torque / base_radius_p;
        self.points.iter().map(|e| f / e.te).sum::<f64>() / self.points.len().max(1) as f64
    }

    /// True if any equilibrium has a loaded contact on a tip rounding.
    pub fn tip_rounding_contact(&self) -> bool {
        self.points.iter().any(|e| e.outputs.tip_contact)
    }
}

/// Static equilibria at `points_per_pitch` uniform pinion angles per pinion pitch over
/// `pitches` pitches starting at `phi_start` (rad), each started from the previous STE.
pub fn static_curve<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    torque: f64,
    phi_start: f64,
    pinion_pitch: f64,
    points_per_pitch: usize,
    pitches: usize,
) -> Result<StaticCurve, MeshError> {
    let settings = EquilibriumSettings::default();
    static_curve_with(mesh, torque, phi_start, pinion_pitch, points_per_pitch, pitches, &settings)
}

/// [`static_curve`] with `settings` (e.g. a running speed [`EquilibriumSettings::w_p`] for
/// the friction).
pub fn static_curve_with<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    torque: f64,
    phi_start: f64,
    pinion_pitch: f64,
    points_per_pitch: usize,
    pitches: usize,
    settings: &EquilibriumSettings,
) -> Result<StaticCurve, MeshError> {
    curve_points(torque, phi_start, pinion_pitch, points_per_pitch, pitches, |phi_p, prev| {
        equilibrium(mesh, phi_p, torque, prev.map_or(1e-5, |e| e.te), settings)
    })
}

/// A static curve of `points_per_pitch` pinion angles per pitch over `pitches` pitches from
/// `phi_start`, each point `solve(φp, the previous point)` (`None` for the first).
pub(crate) fn curve_points(
    torque: f64,
    phi_start: f64,
    pinion_pitch: f64,
    points_per_pitch: usize,
    pitches: usize,
    mut solve: impl FnMut(f64, Option<&Equilibrium>) -> Result<Equilibrium, MeshError>,
) -> Result<StaticCurve, MeshError> {
    let n = points_per_pitch.max(1) * pitches.max(1);
    let mut points: Vec<Equilibrium> = Vec::with_capacity(n);
    for k in 0..n {
        let phi_p = phi_start + pinion_pitch * k as f64 / points_per_pitch.max(1) as f64;
        let eq = solve(phi_p, points.last())?;
        points.push(eq);
    }
    Ok(StaticCurve { torque, points })
}

/// One row of a pressure waterfall: the contact pressure along the face width of one tooth
/// pair at one pinion angle, at static equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct WaterfallRow {
    /// Pinion angle φp, rad.
    pub phi_p: f64,
    /// Static TE at this angle, m.
    pub te: f64,
    /// Slice centres ζ = z/m_n (all slices of the face width).
    pub zeta: Vec<f64>,
    /// Hertz pressure (Eq. 15) of the tracked pair at each slice, Pa (0 where not loaded).
    pub pressure: Vec<f64>,
    /// True if any loaded slice of the tracked pair lies on a tip rounding or tip circle.
    pub tip_contact: bool,
}

/// The pressure waterfall of Fig. 7: the static contact pressure along the face width of tooth
/// pair `pair` (absolute number, see [`crate::contact::ContactPoint::pair`]) at
/// `points_per_pitch` pinion angles per pitch from `phi_from` to `phi_to` (rad). Rows where the
/// pair carries no load are kept (all zeros) so that the rows are uniform in φp.
pub fn pressure_waterfall(
    model: &mut super::Mesh,
    torque: f64,
    pair: i64,
    phi_from: f64,
    phi_to: f64,
    points_per_pitch: usize,
) -> Result<Vec<WaterfallRow>, MeshError> {
    let pitch = model.geometry().pinion.angular_pitch();
    let n = (((phi_to - phi_from) / pitch) * points_per_pitch as f64).round().max(1.0) as usize;
    let nl = model.slices_per_line();
    let b0 = model.geometry().b0();
    let zeta: Vec<f64> = (0..nl).map(|k| (k as f64 + 0.5) * b0 / nl as f64).collect();
    let detail_before = model.detail();
    model.set_detail(true);
    let mut rows = Vec::with_capacity(n + 1);
    let mut guess = 1e-5;
    let settings = EquilibriumSettings::default();
    let result = (|| {
        for i in 0..=n {
            let phi_p = phi_from + (phi_to - phi_from) * i as f64 / n as f64;
            let eq = equilibrium(model, phi_p, torque, guess, &settings)?;
            guess = eq.te;
            model.evaluate(&MeshState {
                phi_p,
                phi_g: eq.phi_g,
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            })?;
            let mut pressure = vec![0.0; nl];
            let mut tip_contact = false;
            for s in model.slices() {
                if s.pair == pair && !s.back && s.q_n_per_m > 0.0 {
                    let k = ((s.zeta / b0 * nl as f64) as usize).min(nl - 1);
                    pressure[k] = s.pressure_pa;
                    tip_contact |= s.tip;
                }
            }
            rows.push(WaterfallRow { phi_p, te: eq.te, zeta: zeta.clone(), pressure, tip_contact });
        }
        Ok(())
    })();
    model.set_detail(detail_before);
    result.map(|()| rows)
}

/// Onset of tip contact in the static model over one mesh period: at each pinion angle the
/// smallest TE at which a loaded contact lies on a tip rounding or tip edge of either gear
/// ([`MeshOutputs::tip_contact`]), see [`tip_contact_threshold_curve`].
#[derive(Debug, Clone, PartialEq)]
pub struct TipThreshold {
    /// First pinion angle, rad.
    pub phi_start: f64,
    /// Pinion angular pitch (the mesh period in φp), rad.
    pub pinion_pitch: f64,
    /// Pinion angles φp, rad: `phi_start` + k·pitch/n, k = 0 … n − 1.
    pub phi_p: Vec<f64>,
    /// Threshold TE at each angle, m; `None` when no tip contact up to `te_max`.
    pub te: Vec<Option<f64>>,
    /// Largest TE searched, m.
    pub te_max: f64,
}

impl TipThreshold {
    /// Smallest threshold over the angles: (φp in rad, TE in m); `None` if no angle has one.
    pub fn min(&self) -> Option<(f64, f64)> {
        self.phi_p
            .iter()
            .zip(&self.te)
            .filter_map(|(&p, t)| t.map(|t| (p, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Threshold at any pinion angle (rad), m: periodic linear interpolation between the
    /// stored angles; an angle without tip contact up to `te_max` counts as `te_max`, so the
    /// value is then a lower bound.
    pub fn at(&self, phi_p: f64) -> f64 {
        let n = self.te.len();
        if n == 0 {
            return f64::INFINITY;
        }
        let x =
            (phi_p - self.phi_start).rem_euclid(self.pinion_pitch) / self.pinion_pitch * n as f64;
        let i = (x.floor() as usize).min(n - 1);
        let f = x - i as f64;
        let v = |k: usize| self.te[k % n].unwrap_or(self.te_max);
        v(i) * (1.0 - f) + v(i + 1) * f
    }
}

/// The smallest TE (m) in (0, `te_max`] at pinion angle `phi_p` (rad) at which the full model
/// (contact search and load solve, whatever the fidelity) puts load on a tip rounding or tip
/// edge; `None` if there is none up to `te_max`. Scans TE in `steps` equal steps, then bisects
/// the first step with tip contact down to `te_tol` (m). Tip contact is taken to persist once
/// reached (more TE, more overlap at the tip); a window narrower than one scan step can be
/// missed. The scan ends at the model's validity range if `te_max` lies beyond it.
pub fn tip_contact_threshold(
    model: &mut super::Mesh,
    phi_p: f64,
    te_max: f64,
    steps: usize,
    te_tol: f64,
) -> Result<Option<f64>, MeshError> {
    let geo = model.geometry().clone();
    let te_max = te_max.min(model.validity().te_max);
    let mut tip = |te: f64| -> Result<bool, MeshError> {
        let s = MeshState {
            phi_p,
            phi_g: geo.phi_g_for_te(phi_p, te),
            w_p: 0.0,
            w_g: 0.0,
            ..Default::default()
        };
        Ok(model.evaluate_full(&s)?.tip_contact)
    };
    let steps = steps.max(1);
    let mut lo = 0.0;
    for k in 1..=steps {
        let hi = te_max * k as f64 / steps as f64;
        if tip(hi)? {
            let mut hi = hi;
            while hi - lo > te_tol {
                let mid = 0.5 * (lo + hi);
                if tip(mid)? {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Ok(Some(hi));
        }
        lo = hi;
    }
    Ok(None)
}

/// [`tip_contact_threshold`] at `points` uniform pinion angles over one pinion pitch from
/// `phi_start` (rad), in parallel (one model clone per angle); TE scanned up to `te_max` (m) in
/// `steps` steps and bisected to 1 nm.
pub fn tip_contact_threshold_curve(
    model: &super::Mesh,
    phi_start: f64,
    pinion_pitch: f64,
    points: usize,
    te_max: f64,
    steps: usize,
) -> Result<TipThreshold, MeshError> {
    use rayon::prelude::*;
    let n = points.max(1);
    let phi_p: Vec<f64> = (0..n).map(|k| phi_start + pinion_pitch * k as f64 / n as f64).collect();
    let te = phi_p
        .par_iter()
        .map(|&phi| {
            let mut m = model.clone();
            tip_contact_threshold(&mut m, phi, te_max, steps, 1e-9)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(TipThreshold { phi_start, pinion_pitch, phi_p, te, te_max })
}
