//! Mesh friction and power loss: a Coulomb force at every loaded slice along the true sliding
//! of the two flanks, the friction torques, the loss power, the instantaneous mesh efficiency
//! and the heat into each gear.
//!
//! The paper neglects friction (its Section 2). This module adds it as a force tangent to the
//! flanks; the normal load problem of Eq. 12 is unchanged (the compliance acts along the
//! normal only, as in the paper), so friction is a sum over the loaded slices of the load
//! solution.
//!
//! # Options
//! [`Friction`] (the `friction` option of every shell, JSON `{"model": …, "mu": …, …}`):
//! `none` (the default and the paper's model: every result bit for bit the frictionless
//! one), `constant` (μ given), or `iso_tr_14179_2` (the mean friction coefficient of
//! ISO/TR 14179-2 after Schlenk, see [`iso_mean_mu`], from the current load and speed).
//!
//! # Sliding velocity (frame of [`super::forces`])
//! A slice's contact lies at P = (P1, ζ·m_n): P1 the pinion flank point of the contact
//! search (the gear's point P2 differs by the overlap along the normal, micrometres). The
//! flank velocities there are those of the rigid gear bodies turning about their axes, the
//! pinion about (0, 0) and the gear about (a, 0), both positive about +z:
//!
//! ```text
//! v_p = φ̇p·(−P_y, P_x, 0),     v_g = φ̇g·(−P_y, P_x − a, 0),     v_s = v_p − v_g
//! ```
//!
//! The sliding velocity is the part of v_s tangent to the flanks, v_t = v_s − (v_s·N̂)·N̂,
//! with N̂ the unit normal of the pinion's helicoid, (n_t, −ω_p·s_p)/|…| (module docs of
//! [`super::forces`]); the normal part is the rate of approach, which the elastic problem
//! carries. This holds everywhere the contact search finds a contact, outside the plane of
//! action too (tip rounding, relief corners), where the sliding is largest.
//!
//! # Force, torques and power
//! With F = |F_i| the magnitude of the slice's 3D normal force (q·m_n·Δζ·√(1 + (ω_p·s_p)²)),
//! the friction force on the pinion is
//!
//! ```text
//! f = −μ·F·v_t / √(|v_t|² + v₀²)        at P,      −f on the gear
//! ```
//!
//! i.e. against the pinion's sliding, with magnitude μ·F·g(|v_t|/v₀), g(x) = x/√(1 + x²):
//! Coulomb (μ·F) where the sliding is much faster than the regularisation speed v₀, viscous
//! (μ·F·|v_t|/v₀) within it. The force reverses where v_t does: at the pitch line, where the
//! pinion flank's sliding changes from leading to trailing. Its wrench is taken with the
//! elastic one ([`super::MeshWrench::of_force`]): it is inside `F_p`, `M_p` and the torques.
//! The friction torques M_R,p and M_R,g are minus the z moments of f about each axis, so
//! that they enter Eqs. 2–3 as M_F does (and are part of the reported M_F,p, M_F,g):
//!
//! ```text
//! M_R,p = −(P × f)_z,      M_R,g = ((P − O_g) × f)_z
//! ```
//!
//! The loss power is the work of the friction pair on the sliding,
//!
//! ```text
//! P_loss = −f·v_t = μ·F·|v_t|² / √(|v_t|² + v₀²) ≥ 0
//! ```
//!
//! and, since f·v_p and −f·v_g are the powers of the friction on each body, exactly
//! M_R,p·φ̇p + M_R,g·φ̇g = P_loss at every evaluation (no power is created; at standstill none
//! is lost).
//!
//! # Regularisation speed v₀
//! Coulomb friction jumps where the sliding reverses (the pitch line; a drive reversing
//! through standstill). A jump would make the right-hand side of Eqs. 1–4 discontinuous, and
//! the fixed-step integrators' order would fall to one. v₀ smooths it over a stated band: the
//! default 0.05 m/s is a few per cent of the sliding speeds of a running mesh (Table 1 at
//! 300 rad/s: up to about 3 m/s at the ends of the path), so only the slices within
//! v₀/(|φ̇p|·(1 + 1/u)) of the pitch line (tenths of a millimetre at 300 rad/s) feel it,
//! whereas near standstill the friction becomes a viscous term of slope μ·F·ρ²/v₀ that a
//! larger v₀ keeps below the mesh damping's scale. It is an option (`regularisation_speed_m_s`).
//!
//! # Heat into each gear
//! The loss heats both flanks. The split follows Blok's partition for two bodies of equal
//! thermal effusivity (both steel here) at high Péclet number: each surface takes a share in
//! proportion to the square root of its own tangential speed through the contact,
//! Q_p/Q_g = √|v_p,t| / √|v_g,t| (v_·,t the tangent parts of v_p, v_g; on the involute the
//! rolling speeds φ̇·ρ, since the contact point moves along the normal). Equal halves when
//! both are zero. Q_p + Q_g = P_loss.
//!
//! # Efficiency
//! `eta_mesh` = 1 − P_loss/P_in, with P_in the power the driving gear puts into the mesh,
//! the larger of (M_F,p + M_D,p)·φ̇p and (M_F,g + M_D,g)·φ̇g (each is the power the mesh takes
//! from that gear); 1 where P_in ≤ 0 (standstill, no load), clamped to [0, 1]. Where the
//! elastic energy of the mesh does not change (steady TE on the involute) this is exactly the
//! output power over the input power.
//!
//! # Table fidelity and the Jacobian
//! The table carries the friction as node values (module docs of [`super::table`],
//! "Friction"). The partial derivatives of the friction torques are taken by central
//! differences of the evaluation (steps 1e-7 rad and 1e-6 of the speed); those of the elastic
//! and damping torques stay exact.
//!
//! # ISO/TR 14179-2 for comparison
//! [`loss_factor_h_v`]: the gear loss factor H_V (Ohlendorf) from the geometry, the load
//! sharing assumed uniform along the path of contact; the mean loss of ISO/TR 14179-2 is
//! μ_mz·H_V·P_in. [`iso_mean_mu`]: the mean coefficient of friction μ_mz (Schlenk).

use crate::contact::ContactPoint;
use crate::error::ParamError;
use crate::geometry::PairGeometry;
use crate::params::Bounds;

use super::forces::{ForceFrame, MeshWrench};
use super::{MeshError, MeshJacobian, MeshOutputs, MeshState};

/// Which friction law applies at the contacts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionModel {
    /// No friction (the paper's model; every result as without the option).
    #[default]
    None,
    /// A constant coefficient [`Friction::mu`].
    Constant,
    /// The mean coefficient of ISO/TR 14179-2 ([`iso_mean_mu`]) at the current load and
    /// speed, from the oil viscosity, the roughness and the lubricant factor.
    #[serde(rename = "iso_tr_14179_2")]
    IsoTr14179_2,
}

impl FrictionModel {
    /// The model's JSON name.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Constant => "constant",
            Self::IsoTr14179_2 => "iso_tr_14179_2",
        }
    }
}

/// The friction option ([`super::MeshOptions::friction`]); JSON keys as the field names.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Friction {
    /// The law: `none` (default), `constant`, `iso_tr_14179_2`.
    pub model: FrictionModel,
    /// Coefficient of friction of the `constant` model, dimensionless, in [`MU`].
    pub mu: f64,
    /// Dynamic viscosity of the oil at the oil temperature, Pa·s (`iso_tr_14179_2`), in
    /// [`OIL_VISCOSITY_PA_S`]. Default 0.05 Pa·s (an ISO VG 220 mineral oil near 60 °C).
    pub oil_viscosity_pa_s: f64,
    /// Arithmetic mean roughness Ra of the flanks, the mean of both gears, m
    /// (`iso_tr_14179_2`), in [`ROUGHNESS_RA_M`]. Default 0.5 µm (ground flanks).
    pub roughness_ra_m: f64,
    /// Lubricant factor X_L of ISO/TR 14179-2 (1 for mineral oil), in [`LUBRICANT_FACTOR`].
    pub lubricant_factor: f64,
    /// Regularisation speed v₀ of the friction near zero sliding, m/s (module docs), in
    /// [`REGULARISATION_SPEED_M_S`]. Default 0.05 m/s.
    pub regularisation_speed_m_s: f64,
}

impl Default for Friction {
    fn default() -> Self {
        Self {
            model: FrictionModel::None,
            mu: 0.05,
            oil_viscosity_pa_s: 0.05,
            roughness_ra_m: 0.5e-6,
            lubricant_factor: 1.0,
            regularisation_speed_m_s: 0.05,
        }
    }
}

/// Range of [`Friction::mu`]: 0 … 1.
pub const MU: Bounds<f64> = Bounds::new(0.0, 1.0, "");
/// Range of [`Friction::oil_viscosity_pa_s`]: 1e-4 … 10 Pa·s.
pub const OIL_VISCOSITY_PA_S: Bounds<f64> = Bounds::new(1e-4, 10.0, "Pa.s");
/// Range of [`Friction::roughness_ra_m`]: 0.01 … 10 µm.
pub const ROUGHNESS_RA_M: Bounds<f64> = Bounds::new(1e-8, 1e-5, "m");
/// Range of [`Friction::lubricant_factor`]: 0.1 … 3.
pub const LUBRICANT_FACTOR: Bounds<f64> = Bounds::new(0.1, 3.0, "");
/// Range of [`Friction::regularisation_speed_m_s`]: 1e-4 … 1 m/s.
pub const REGULARISATION_SPEED_M_S: Bounds<f64> = Bounds::new(1e-4, 1.0, "m/s");

/// Sum velocity below which [`iso_mean_mu`] is held at its value there, m/s: the formula
/// grows as v_Σc^−0.2 without bound towards standstill, far outside the running conditions
/// it was fitted to; the loss still vanishes with the sliding.
pub const ISO_MIN_SUM_VELOCITY_M_S: f64 = 0.1;

impl Friction {
    /// No friction (the default).
    pub fn none() -> Self {
        Self::default()
    }

    /// A constant coefficient `mu` with the default regularisation.
    pub fn constant(mu: f64) -> Self {
        Self { model: FrictionModel::Constant, mu, ..Self::default() }
    }

    /// True unless the model is `none`.
    pub fn is_on(&self) -> bool {
        self.model != FrictionModel::None
    }

    /// Parses the JSON object of the module docs (`none` or an empty text: no friction). An
    /// unknown key or a wrong type is an error naming it; the values are checked
    /// ([`Friction::check`]).
    pub fn from_json(text: &str) -> Result<Self, String> {
        let t = text.trim();
        if t.is_empty() || t == "none" || t == "\"none\"" {
            return Ok(Self::none());
        }
        let f: Self = serde_json::from_str(t).map_err(|e| format!("friction JSON: {e}"))?;
        f.check().map_err(|e| format!("friction: {e}"))?;
        Ok(f)
    }

    /// The JSON text of this option.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|_| "{}".into())
    }

    /// Checks every value against its range (also those the model does not use, so that a
    /// value is never silently ignored when the model is switched); the error names the key
    /// (`friction.mu`, …), the value and the range.
    pub fn check(&self) -> Result<(), ParamError> {
        MU.check("friction.mu", self.mu)?;
        OIL_VISCOSITY_PA_S.check("friction.oil_viscosity_pa_s", self.oil_viscosity_pa_s)?;
        ROUGHNESS_RA_M.check("friction.roughness_ra_m", self.roughness_ra_m)?;
        LUBRICANT_FACTOR.check("friction.lubricant_factor", self.lubricant_factor)?;
        REGULARISATION_SPEED_M_S
            .check("friction.regularisation_speed_m_s", self.regularisation_speed_m_s)
    }
}

/// The mean coefficient of friction μ_mz of ISO/TR 14179-2 (Schlenk):
///
/// ```text
/// μ_mz = 0.048·(F_bt/b / (v_Σc·ρ_redC))^0.2 · η_oil^−0.05 · Ra^0.25 · X_L
/// ```
///
/// in the units of the formula (F_bt/b in N/mm, v_Σc in m/s, ρ_redC in mm, η_oil in mPa·s,
/// Ra in µm); the arguments here are SI: `load_per_width` F_bt/b (N/m, the tangential load
/// at the base circle per face width), `sum_velocity` v_Σc = 2·v_t·sin α_wt at the pitch
/// point (m/s; held at [`ISO_MIN_SUM_VELOCITY_M_S`] below it), `rho_red` ρ_redC the
/// reduced radius of curvature at the pitch point in the normal section (m). 0 without load.
pub fn iso_mean_mu(f: &Friction, load_per_width: f64, sum_velocity: f64, rho_red: f64) -> f64 {
    if load_per_width <= 0.0 {
        return 0.0;
    }
    let w_n_per_mm = load_per_width * 1e-3;
    let v = sum_velocity.abs().max(ISO_MIN_SUM_VELOCITY_M_S);
    let rho_mm = rho_red * 1e3;
    let eta_mpas = f.oil_viscosity_pa_s * 1e3;
    let ra_um = f.roughness_ra_m * 1e6;
    0.048
        * (w_n_per_mm / (v * rho_mm)).powf(0.2)
        * eta_mpas.powf(-0.05)
        * ra_um.powf(0.25)
        * f.lubricant_factor
}

/// The gear loss factor H_V of ISO/TR 14179-2 (Ohlendorf) from the geometry:
///
/// ```text
/// H_V = π·(u + 1)/(z₁·u·cos β_b) · (1 − ε_α + ε₁² + ε₂²)
/// ```
///
/// with u = z_g/z_p, ε₁, ε₂ the addendum contact ratios of pinion and gear (the parts of the
/// path of contact beyond the pitch point on each gear's addendum over the transverse base
/// pitch, from the tip radii), ε_α = ε₁ + ε₂. It is the mean over a mesh cycle of the sliding
/// speed over the pitch-line speed, each contact's share weighted by a load shared uniformly
/// along the path of contact (two pairs carry half each, one carries all): the mean loss is
/// μ·H_V·P_in. Valid for ε_α < 2.
pub fn loss_factor_h_v(geo: &PairGeometry) -> f64 {
    let (p, g) = (&geo.pinion, &geo.gear);
    let u = g.z as f64 / p.z as f64;
    let pet = geo.base_pitch;
    let s = geo.alpha_wt.sin();
    let rw_p = p.rb / geo.alpha_wt.cos();
    let rw_g = g.rb / geo.alpha_wt.cos();
    let e1 = ((p.ra * p.ra - p.rb * p.rb).sqrt() - rw_p * s) / pet;
    let e2 = ((g.ra * g.ra - g.rb * g.rb).sqrt() - rw_g * s) / pet;
    let ea = e1 + e2;
    std::f64::consts::PI * (u + 1.0) / (p.z as f64 * u * geo.base_helix_angle.cos())
        * (1.0 - ea + e1 * e1 + e2 * e2)
}

/// The constants of the friction at one model (from the geometry and the option).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionConst {
    /// The option.
    pub friction: Friction,
    /// Pinion base radius r_bp, m (F_bt = M_F,p/r_bp).
    pub rb_p: f64,
    /// Ratio of the gear speed to the pinion speed at rigid kinematics, −r_bp/r_bg.
    pub ratio: f64,
    /// Face width b, m.
    pub face_width: f64,
    /// 2·r_wp·sin α_wt: v_Σc per rad/s of the pinion, m.
    pub sum_velocity_per_w: f64,
    /// ρ_redC at the pitch point, normal section, m.
    pub rho_red: f64,
}

impl FrictionConst {
    /// The constants of `friction` on `geo`.
    pub fn new(geo: &PairGeometry, friction: Friction) -> Self {
        let (s, c) = geo.alpha_wt.sin_cos();
        let rw_p = geo.pinion.rb / c;
        let rw_g = geo.gear.rb / c;
        let (rp, rg) = (rw_p * s, rw_g * s);
        Self {
            friction,
            rb_p: geo.pinion.rb,
            ratio: -geo.pinion.rb / geo.gear.rb,
            face_width: geo.params.face_width_m,
            sum_velocity_per_w: 2.0 * rw_p * s,
            rho_red: rp * rg / (rp + rg) / geo.base_helix_angle.cos(),
        }
    }

    /// The coefficient of friction at elastic pinion torque `m_f_p` (N·m) and pinion speed
    /// `w_p` (rad/s): μ of `constant`, μ_mz of `iso_tr_14179_2`, 0 for `none`.
    pub fn mu(&self, m_f_p: f64, w_p: f64) -> f64 {
        match self.friction.model {
            FrictionModel::None => 0.0,
            FrictionModel::Constant => self.friction.mu,
            FrictionModel::IsoTr14179_2 => iso_mean_mu(
                &self.friction,
                m_f_p.abs() / self.rb_p / self.face_width,
                self.sum_velocity_per_w * w_p,
                self.rho_red,
            ),
        }
    }

    /// The regularisation g(|v|/v₀) = |v|/√(|v|² + v₀²) for a sliding speed `speed`, m/s.
    #[inline]
    pub fn regularisation(&self, speed: f64) -> f64 {
        let v0 = self.friction.regularisation_speed_m_s;
        speed / (speed * speed + v0 * v0).sqrt()
    }
}

/// The friction of one slice (module docs) at unit coefficient: what a slice contributes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SliceFriction {
    /// The wrench of the friction force on the pinion (and −force on the gear), for μ = 1.
    pub wrench: MeshWrench,
    /// Loss power for μ = 1, W.
    pub loss: f64,
    /// Share of the loss that heats the pinion (Blok), 0 … 1.
    pub heat_share_p: f64,
    /// Sliding speed |v_t|, m/s.
    pub sliding_speed: f64,
    /// Magnitude of the friction force for μ = 1, N.
    pub force: f64,
}

/// `|v|`.
#[inline]
fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The tangent part of `v` for the unit normal `n`.
#[inline]
fn tangent(v: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    [v[0] - d * n[0], v[1] - d * n[1], v[2] - d * n[2]]
}

/// The friction of contact `c` carrying the transverse normal force `transverse_n`
/// = q·m_n·Δζ (N) at speeds `w_p`, `w_g` (rad/s), for μ = 1: regularised with speed `v0`
/// (m/s), or pure Coulomb (the direction of the sliding only) when `v0` is 0.
pub fn slice_friction(
    frame: &ForceFrame,
    c: &ContactPoint,
    transverse_n: f64,
    w_p: f64,
    w_g: f64,
    v0: f64,
) -> SliceFriction {
    let (s, co) = c.normal_angle.sin_cos();
    let nz = -frame.twist_p * c.arm_p_m;
    let scale = (1.0 + nz * nz).sqrt();
    let n = [co / scale, s / scale, nz / scale];
    let force_n = transverse_n * scale;
    let [px, py] = c.point_p;
    let vp = [-w_p * py, w_p * px, 0.0];
    let vg = [-w_g * py, w_g * (px - frame.center_distance), 0.0];
    let vt = tangent([vp[0] - vg[0], vp[1] - vg[1], 0.0], n);
    let speed = norm(vt);
    let denom = (speed * speed + v0 * v0).sqrt();
    let (vpt, vgt) = (norm(tangent(vp, n)).sqrt(), norm(tangent(vg, n)).sqrt());
    let heat_share_p = if vpt + vgt > 0.0 { vpt / (vpt + vgt) } else { 0.5 };
    if denom == 0.0 {
        return SliceFriction { heat_share_p, ..SliceFriction::default() };
    }
    let k = -force_n / denom;
    let f = [k * vt[0], k * vt[1], k * vt[2]];
    let point = [px, py, c.zeta * frame.module];
    SliceFriction {
        wrench: MeshWrench::of_force(frame, point, f),
        loss: force_n * speed * speed / denom,
        heat_share_p,
        sliding_speed: speed,
        force: force_n * speed / denom,
    }
}

/// Friction sums of one evaluation (module docs), N·m and W.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrictionSums {
    /// The friction wrench on the pinion (and the gear's moments).
    pub wrench: MeshWrench,
    /// Loss power, W.
    pub loss: f64,
    /// Heat into the pinion, W.
    pub heat_p: f64,
}

impl FrictionSums {
    /// Adds a slice's friction at coefficient `mu`.
    #[inline]
    pub fn add(&mut self, s: &SliceFriction, mu: f64) {
        let mut w = s.wrench;
        for k in 0..3 {
            w.force_p[k] *= mu;
            w.moment_p[k] *= mu;
            w.moment_g[k] *= mu;
        }
        self.wrench.add(&w);
        self.loss += mu * s.loss;
        self.heat_p += mu * s.loss * s.heat_share_p;
    }

    /// The friction torques (M_R,p, M_R,g), N·m: minus the z moments (module docs).
    pub fn torques(&self) -> (f64, f64) {
        (-self.wrench.moment_p[2], -self.wrench.moment_g[2])
    }
}

/// Sets `out.eta_mesh` ([`mesh_efficiency`]) from the torques and loss already in `out` at
/// `state`: the one place both fidelities fill it.
#[inline]
pub(crate) fn set_efficiency(out: &mut MeshOutputs, state: &MeshState) {
    out.eta_mesh = mesh_efficiency(
        out.m_f_p + out.m_d_p,
        out.m_f_g + out.m_d_g,
        state.w_p,
        state.w_g,
        out.p_loss,
    );
}

/// The instantaneous mesh efficiency of the module docs from the total torques on each gear
/// (elastic, friction and damping; N·m), the speeds (rad/s) and the loss power (W).
#[inline]
pub fn mesh_efficiency(m_p: f64, m_g: f64, w_p: f64, w_g: f64, loss: f64) -> f64 {
    if loss == 0.0 {
        return 1.0;
    }
    let p_in = (m_p * w_p).max(m_g * w_g);
    if p_in <= 0.0 || !p_in.is_finite() {
        return 1.0;
    }
    (1.0 - loss / p_in).clamp(0.0, 1.0)
}

/// Adds the partial derivatives of the friction torques M_R,p, M_R,g to the rows M_F,p and
/// M_F,g of `jac` (which hold those of the elastic torques), by central differences of
/// `eval` at `state`: steps 1e-7 rad (times max(1, |φ|)) in the angles and 1e-6·max(1, |φ̇|)
/// rad/s in the speeds. The friction depends on the loads, the contact geometry and, through
/// the sliding, the speeds; its derivatives are not derived in closed form, so they carry the
/// differences' error (relative 1e-6 … 1e-4 of the row, the load solver's tolerance over
/// the step), where the elastic rows are exact.
pub(crate) fn add_friction_jacobian(
    eval: &mut dyn FnMut(&MeshState) -> Result<MeshOutputs, MeshError>,
    state: &MeshState,
    jac: &mut MeshJacobian,
) -> Result<(), MeshError> {
    let cols = [MeshJacobian::PHI_P, MeshJacobian::PHI_G, MeshJacobian::W_P, MeshJacobian::W_G];
    for (j, &col) in cols.iter().enumerate() {
        let x = [state.phi_p, state.phi_g, state.w_p, state.w_g][j];
        let h = if j < 2 { 1e-7 } else { 1e-6 } * x.abs().max(1.0);
        let at = |dx: f64| {
            let mut s = *state;
            match j {
                0 => s.phi_p += dx,
                1 => s.phi_g += dx,
                2 => s.w_p += dx,
                _ => s.w_g += dx,
            }
            s
        };
        let (sp, sm) = (at(h), at(-h));
        let hh =
            (sp.phi_p - sm.phi_p) + (sp.phi_g - sm.phi_g) + (sp.w_p - sm.w_p) + (sp.w_g - sm.w_g);
        let (op, om) = (eval(&sp)?, eval(&sm)?);
        jac.d[MeshJacobian::M_F_P][col] += (op.m_r_p - om.m_r_p) / hh;
        jac.d[MeshJacobian::M_F_G][col] += (op.m_r_g - om.m_r_g) / hh;
    }
    Ok(())
}
