//! The 4-DOF torsional model of the gear set (paper §2, Eqs. 1–4, Fig. 1).
//!
//! Driving mass J₁, massless pinion shaft (c₁, d₁), pinion J_p, mesh, gear J_g, massless gear
//! shaft (c₂, d₂), driven mass J₂:
//!
//! ```text
//! J₁ φ̈₁ = M − c₁(φ₁ − φp) − d₁(φ̇₁ − φ̇p)                              (1)
//! J_p φ̈p = c₁(φ₁ − φp) + d₁(φ̇₁ − φ̇p) − M_F,p − M_D,p                  (2)
//! J_g φ̈g = −c₂(φg − φ₂) − d₂(φ̇g − φ̇₂) − M_F,g − M_D,g                 (3)
//! J₂ φ̈₂ = M·z_g/z_p + c₂(φg − φ₂) + d₂(φ̇g − φ̇₂)                       (4)
//! ```
//!
//! # Sign conventions
//!
//! All four angles are measured in one absolute rotational sense (that of the crate: the pinion
//! drives turning in the positive sense, so φg and φ₂ are negative and decreasing in normal
//! running). The transmission error is TE = φp·g_p + φg·g_g (Eq. 16). The mesh torques
//! M_F,p, M_F,g, M_D,p, M_D,g come from a [`MeshTorques`] implementation, are positive in
//! normal drive and enter Eqs. 2–3 with a minus sign, exactly as written above: the mesh brakes
//! the pinion and drives the gear in the negative sense.
//!
//! **The braking torque on J₂ is +M·z_g/z_p** (the paper's sign, kept): the load opposes the
//! gear set's negative rotation, so it acts in the positive sense. Check at steady rotation
//! (all accelerations and shaft-damper rates zero): Eq. 3 gives c₂(φg − φ₂) = −M_F,g, so the
//! gear shaft is wound with φ₂ − φg = M_F,g/c₂ > 0 (the load lags the gear, which turns in the
//! negative sense), and Eq. 4 then reads 0 = M·z_g/z_p − M_F,g, i.e. the gear side is in
//! equilibrium with the positive mesh torque M_F,g = M·z_g/z_p = M·g_g/g_p that the plane of
//! action transmits (g_g/g_p = z_g/z_p for gears cut by one rack).
//!
//! # State vector
//!
//! Eight first-order states, in this order (indices [`PHI_1`] … [`W_2`]):
//! (φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂), rad and rad/s.
//!
//! # Start at static equilibrium
//!
//! [`GearDynamics::static_start`] gives the state at t = 0 that is in static equilibrium at the
//! nominal speed, so that the slow, almost undamped shaft modes are not excited by the start:
//! φp = φp,0 (given, usually 0), φg from the static mesh equilibrium M_F,p(φp, φg) = M
//! ([`crate::mesh::statics::equilibrium`]), the pinion shaft wound up by the driving torque,
//! φ₁ = φp + M/c₁, the gear shaft wound up by the mesh torque of that equilibrium,
//! φ₂ = φg + M_F,g/c₂, and all rates at the nominal speed: φ̇₁ = φ̇p = ω_p,
//! φ̇g = φ̇₂ = −ω_p·z_p/z_g. The shaft dampers then carry no torque and the mesh damping
//! (∝ dTE/dt = ω_p·(g_p − g_g·z_p/z_g) = 0) none either, so Eqs. 1–3 hold with zero
//! acceleration; Eq. 4 holds too wherever M_F,g = M·z_g/z_p (contact in the plane of action).
//!
//! # Mesh evaluations
//!
//! [`GearDynamics`] remembers the last mesh evaluation and reuses it when it is asked again for
//! bit-identical (φp, φg, φ̇p, φ̇g). The mesh is a function of that state only, so this changes
//! no result; it makes recording the outputs at every step free (the first RK4 stage and the
//! DOPRI5 first-same-as-last stage are evaluated at the step's end state anyway).

use std::fmt;

use nalgebra::{Matrix4, SymmetricEigen};

use super::integrators::{OdeError, OdeSystem};
use super::steady::SteadyError;
use crate::error::ParamError;
use crate::geometry::PairGeometry;
use crate::mesh::statics::{EquilibriumSettings, equilibrium, static_curve_with};
use crate::mesh::{MeshError, MeshOutputs, MeshState, MeshTorques, WarmStart};
use crate::params::{DriveLine, GearPair};

/// Index of φ₁ (driving mass angle, rad) in the state vector.
pub const PHI_1: usize = 0;
/// Index of φp (pinion hub angle, rad).
pub const PHI_P: usize = 1;
/// Index of φg (gear hub angle, rad).
pub const PHI_G: usize = 2;
/// Index of φ₂ (driven mass angle, rad).
pub const PHI_2: usize = 3;
/// Index of φ̇₁ (rad/s).
pub const W_1: usize = 4;
/// Index of φ̇p (rad/s).
pub const W_P: usize = 5;
/// Index of φ̇g (rad/s).
pub const W_G: usize = 6;
/// Index of φ̇₂ (rad/s).
pub const W_2: usize = 7;
/// Number of states.
pub const N_STATES: usize = 8;

/// Names of the eight states with their units, in state order (as used in CSV/JSON output).
pub const STATE_NAMES: [&str; N_STATES] = [
    "phi_1_rad",
    "phi_p_rad",
    "phi_g_rad",
    "phi_2_rad",
    "w_1_rad_s",
    "w_p_rad_s",
    "w_g_rad_s",
    "w_2_rad_s",
];

/// Errors of the dynamic simulation.
#[derive(Debug)]
#[non_exhaustive]
pub enum DynamicsError {
    /// The mesh model failed; `t` is the simulation time of the failed evaluation, s
    /// (`None` outside a time integration, e.g. while finding the static start).
    Mesh {
        /// Time of the failed evaluation, s.
        t: Option<f64>,
        /// The mesh model's error.
        source: MeshError,
    },
    /// The integrator failed (step size collapse, non-finite state, …).
    Ode(OdeError),
    /// The steady-state detector rejected its options or a sample.
    Steady(SteadyError),
    /// A gear-pair parameter is invalid.
    Param(ParamError),
    /// An argument or option is out of range.
    InvalidInput {
        /// Name of the argument or option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Allowed range, in words.
        allowed: &'static str,
    },
    /// A request whose work (samples, steps, sub-steps, runs) exceeds a bound of
    /// [`super::limits`], or an RK4 step outside the stability region: the message names the
    /// request, its cost and the bound. Nothing was allocated or integrated.
    TooLarge(String),
    /// A run of a speed sweep failed at pinion speed `omega_p` (rad/s).
    AtSpeed {
        /// Pinion speed of the failed run, rad/s.
        omega_p: f64,
        /// What failed.
        source: Box<DynamicsError>,
    },
}

impl fmt::Display for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DynamicsError::Mesh { t: Some(t), source } => {
                write!(f, "mesh model failed at t = {t:e} s: {source}")
            }
            DynamicsError::Mesh { t: None, source } => write!(f, "mesh model failed: {source}"),
            DynamicsError::Ode(e) => write!(f, "integration: {e}"),
            DynamicsError::Steady(e) => write!(f, "steady-state detection: {e}"),
            DynamicsError::Param(e) => write!(f, "{e}"),
            DynamicsError::InvalidInput { name, value, allowed } => {
                write!(
                    f,
                    "invalid `{name}` = {}: allowed {allowed}",
                    crate::error::short_num(*value)
                )
            }
            DynamicsError::TooLarge(m) => write!(f, "{m}"),
            DynamicsError::AtSpeed { omega_p, source } => {
                write!(f, "run at ω_p = {omega_p} rad/s: {source}")
            }
        }
    }
}

impl std::error::Error for DynamicsError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            DynamicsError::Mesh { source, .. } => Some(source),
            DynamicsError::Ode(e) => Some(e),
            DynamicsError::Steady(e) => Some(e),
            DynamicsError::Param(e) => Some(e),
            DynamicsError::AtSpeed { source, .. } => Some(source.as_ref()),
            DynamicsError::InvalidInput { .. } | DynamicsError::TooLarge(_) => None,
        }
    }
}

impl From<OdeError> for DynamicsError {
    /// A right-hand-side failure that carries a [`MeshError`] becomes [`DynamicsError::Mesh`]
    /// (with its time); every other integrator error is wrapped as [`DynamicsError::Ode`].
    fn from(e: OdeError) -> Self {
        if let OdeError::Rhs { t, source } = &e
            && let Some(m) = source.downcast_ref::<MeshError>()
        {
            return DynamicsError::Mesh { t: Some(*t), source: m.clone() };
        }
        DynamicsError::Ode(e)
    }
}

impl From<SteadyError> for DynamicsError {
    fn from(e: SteadyError) -> Self {
        DynamicsError::Steady(e)
    }
}

impl From<ParamError> for DynamicsError {
    fn from(e: ParamError) -> Self {
        DynamicsError::Param(e)
    }
}

pub(crate) fn invalid(name: &'static str, value: f64, allowed: &'static str) -> DynamicsError {
    DynamicsError::InvalidInput { name, value, allowed }
}

/// Inertias, shafts and load of the 4-DOF model (everything of Eqs. 1–4 except the mesh).
///
/// SI units: kg·m², N·m/rad, N·m·s/rad, N·m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drivetrain {
    /// Driving torque M on J₁, N·m (> 0 drives the pinion in the positive sense).
    pub torque: f64,
    /// Inertia J₁ of the driving mass, kg·m².
    pub j1: f64,
    /// Inertia J_p of the pinion body, kg·m².
    pub j_p: f64,
    /// Inertia J_g of the gear body, kg·m².
    pub j_g: f64,
    /// Inertia J₂ of the driven mass, kg·m².
    pub j2: f64,
    /// Torsional stiffness c₁ of the pinion shaft, N·m/rad.
    pub c1: f64,
    /// Torsional stiffness c₂ of the gear shaft, N·m/rad.
    pub c2: f64,
    /// Viscous damping d₁ of the pinion shaft, N·m·s/rad.
    pub d1: f64,
    /// Viscous damping d₂ of the gear shaft, N·m·s/rad.
    pub d2: f64,
    /// Number of pinion teeth z_p (the mesh period is 2π/(z_p·ω_p)).
    pub z_p: u32,
    /// Number of gear teeth z_g.
    pub z_g: u32,
    /// Factor of the brake torque, dimensionless: 1 (Eq. 4) unless the mesh has friction
    /// ([`crate::mesh::friction`]); then [`GearDynamics::static_start`] sets it to the mean
    /// mesh efficiency of the quasi-static mesh cycle at the start speed,
    /// 1 − P̄_loss/(M·ω_p), so that the brake takes the power the mesh delivers and the
    /// nominal speed is a steady state (the brake of a speed-held test rig).
    pub brake_factor: f64,
}

impl Drivetrain {
    /// The drivetrain of a gear pair with the drive line `drive`: M, J₁, J₂, c₁, c₂, d₁, d₂
    /// from `drive` (checked against its bounds, [`DriveLine::check`]), J_p, J_g of the gear
    /// bodies (teeth and web to the bore) and z_p, z_g from the validated geometry `geo`.
    pub fn new(geo: &PairGeometry, drive: &DriveLine) -> Result<Self, ParamError> {
        drive.check()?;
        let d = drive;
        Ok(Self {
            torque: d.torque_nm,
            j1: d.j1_kgm2,
            j_p: geo.j_p,
            j_g: geo.j_g,
            j2: d.j2_kgm2,
            c1: d.c1_nm_per_rad,
            c2: d.c2_nm_per_rad,
            d1: d.d1_nms_per_rad,
            d2: d.d2_nms_per_rad,
            z_p: geo.params.z_p,
            z_g: geo.params.z_g,
            brake_factor: 1.0,
        })
    }

    /// [`Drivetrain::new`] from the gear pair `pair` (validated and its geometry derived
    /// here) and the drive line `drive`.
    pub fn from_pair(pair: &GearPair, drive: &DriveLine) -> Result<Self, ParamError> {
        Self::new(&PairGeometry::new(pair)?, drive)
    }

    /// Braking torque on J₂, M·z_g/z_p times [`Drivetrain::brake_factor`] (1 without mesh
    /// friction), N·m (enters Eq. 4 with a plus sign; see the module doc for why that sign
    /// balances the gear side).
    pub fn brake_torque(&self) -> f64 {
        self.torque * self.z_g as f64 / self.z_p as f64 * self.brake_factor
    }

    /// Gear speed −ω_p·z_p/z_g at pinion speed `omega_p`, rad/s (negative for ω_p > 0).
    pub fn gear_speed(&self, omega_p: f64) -> f64 {
        -omega_p * self.z_p as f64 / self.z_g as f64
    }

    /// Mesh period T_m = 2π/(z_p·|ω_p|) at pinion speed `omega_p` (rad/s; either sense), s.
    pub fn mesh_period(&self, omega_p: f64) -> f64 {
        2.0 * std::f64::consts::PI / (self.z_p as f64 * omega_p.abs())
    }

    /// Checks every value: inertias and stiffnesses finite and > 0, dampings finite and ≥ 0,
    /// torque finite, tooth numbers ≥ 1.
    pub fn validate(&self) -> Result<(), DynamicsError> {
        for (name, v) in [
            ("j1", self.j1),
            ("j_p", self.j_p),
            ("j_g", self.j_g),
            ("j2", self.j2),
            ("c1", self.c1),
            ("c2", self.c2),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        for (name, v) in [("d1", self.d1), ("d2", self.d2)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(name, v, "finite and >= 0"));
            }
        }
        if !self.torque.is_finite() {
            return Err(invalid("torque", self.torque, "finite"));
        }
        if self.z_p == 0 {
            return Err(invalid("z_p", 0.0, ">= 1"));
        }
        if self.z_g == 0 {
            return Err(invalid("z_g", 0.0, ">= 1"));
        }
        Ok(())
    }

    /// The largest modulus |λ| of the eigenvalues of Eqs. 1–4 linearised with a constant mesh
    /// stiffness `k_mesh` (N/m) and mesh damping coefficient `c_mesh` (N·s/m) along the line of
    /// action between base radii `g_p`, `g_g` (m), with the shafts' stiffness and damping
    /// (rad/s; [`fastest_linear_rate`]). Equals the fastest undamped
    /// frequency while every mode is underdamped; grows as c_mesh/m_eq once the mesh mode is
    /// overdamped.
    pub fn fastest_rate(&self, k_mesh: f64, c_mesh: f64, g_p: f64, g_g: f64) -> f64 {
        let k = stiffness_matrix(self, k_mesh, g_p, g_g);
        let c =
            stiffness_matrix(&Drivetrain { c1: self.d1, c2: self.d2, ..*self }, c_mesh, g_p, g_g);
        let j = [self.j1, self.j_p, self.j_g, self.j2];
        let flat = |m: Matrix4<f64>| -> [f64; 16] { std::array::from_fn(|i| m[(i / 4, i % 4)]) };
        fastest_linear_rate(&j, &flat(k), &flat(c))
    }

    /// Undamped natural frequencies ω (rad/s, ascending, the first is the rigid-body mode 0)
    /// of Eqs. 1–4 linearised with a constant mesh stiffness `k_mesh` (N/m) along the line of
    /// action between base radii `g_p`, `g_g` (m): M_F,p = k·TE·g_p, M_F,g = k·TE·g_g.
    ///
    /// Solves K v = ω² J v through the symmetric matrix J^{-1/2} K J^{-1/2}; eigenvalues that
    /// round-off makes slightly negative are reported as 0.
    pub fn linear_frequencies(&self, k_mesh: f64, g_p: f64, g_g: f64) -> [f64; 4] {
        let k = stiffness_matrix(self, k_mesh, g_p, g_g);
        let jm = [self.j1, self.j_p, self.j_g, self.j2];
        let a = Matrix4::from_fn(|i, j| k[(i, j)] / (jm[i] * jm[j]).sqrt());
        let eig = SymmetricEigen::new(a);
        let mut w: Vec<f64> = eig.eigenvalues.iter().map(|l| l.max(0.0).sqrt()).collect();
        w.sort_by(f64::total_cmp);
        [w[0], w[1], w[2], w[3]]
    }
}

/// Stiffness matrix of Eqs. 1–4 with a linear mesh (coordinates φ₁, φp, φg, φ₂).
fn stiffness_matrix(d: &Drivetrain, k: f64, gp: f64, gg: f64) -> Matrix4<f64> {
    let (c1, c2) = (d.c1, d.c2);
    Matrix4::new(
        c1,
        -c1,
        0.0,
        0.0,
        -c1,
        c1 + k * gp * gp,
        k * gp * gg,
        0.0,
        0.0,
        k * gp * gg,
        c2 + k * gg * gg,
        -c2,
        0.0,
        0.0,
        -c2,
        c2,
    )
}

/// The start state of [`GearDynamics::static_start`] and the mesh equilibrium it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticStart {
    /// State at t = 0 (see the module doc).
    pub y: [f64; N_STATES],
    /// Static transmission error at the start, m.
    pub te: f64,
    /// Mesh outputs of the static equilibrium (zero speeds).
    pub outputs: MeshOutputs,
    /// Mesh evaluations used by the equilibrium search.
    pub evaluations: usize,
}

/// Eqs. 1–4 as an [`OdeSystem`] with eight states, for any mesh model `M`.
///
/// A [`MeshError`] in the right-hand side is returned as [`OdeError::Rhs`] with the error as
/// its source; [`DynamicsError`]'s `From<OdeError>` turns it back into
/// [`DynamicsError::Mesh`].
#[derive(Debug, Clone)]
pub struct GearDynamics<M> {
    mesh: M,
    drive: Drivetrain,
    g_p: f64,
    g_g: f64,
    /// The last evaluation: key (bits of φp, φg, φ̇p, φ̇g) and whether its outputs
    /// (`cached_outputs`) are complete (the right-hand side asks only for the torques,
    /// [`MeshTorques::torques_into`]). Dropped whenever the mesh's warm start is set from
    /// outside ([`Self::set_warm_start`]) or the mesh is changed.
    cache: Option<([u64; 4], bool)>,
    /// The outputs of the remembered evaluation (valid while `cache` is `Some`), written in
    /// place, so that a right-hand side's outputs are not moved through return values.
    cached_outputs: MeshOutputs,
    evaluations: usize,
}

impl<M: MeshTorques> GearDynamics<M> {
    /// The model with mesh `mesh` and drivetrain `drive` (validated).
    pub fn new(mesh: M, drive: Drivetrain) -> Result<Self, DynamicsError> {
        drive.validate()?;
        let (g_p, g_g) = mesh.base_radii();
        for (name, v) in [("g_p", g_p), ("g_g", g_g)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0 (mesh base radius, m)"));
            }
        }
        Ok(Self {
            mesh,
            drive,
            g_p,
            g_g,
            cache: None,
            cached_outputs: MeshOutputs::default(),
            evaluations: 0,
        })
    }

    /// The drivetrain parameters.
    pub fn drive(&self) -> &Drivetrain {
        &self.drive
    }

    /// The mesh model.
    pub fn mesh(&self) -> &M {
        &self.mesh
    }

    /// The mesh model, mutable (forgets the remembered evaluation).
    pub fn mesh_mut(&mut self) -> &mut M {
        self.cache = None;
        &mut self.mesh
    }

    /// Gives the mesh model back.
    pub fn into_mesh(self) -> M {
        self.mesh
    }

    /// Base radii (g_p, g_g) of the mesh, m.
    pub fn base_radii(&self) -> (f64, f64) {
        (self.g_p, self.g_g)
    }

    /// Number of actual mesh evaluations so far (remembered ones not counted).
    pub fn mesh_evaluations(&self) -> usize {
        self.evaluations
    }

    /// Transmission error TE = φp·g_p + φg·g_g of state `y`, m.
    pub fn te(&self, y: &[f64]) -> f64 {
        crate::numeric::dot2(y[PHI_P], self.g_p, y[PHI_G], self.g_g)
    }

    /// Mesh outputs at state `y` (length 8); the last evaluation is reused for a bit-identical
    /// (φp, φg, φ̇p, φ̇g). A mesh failure is [`DynamicsError::Mesh`] with `t: None`.
    pub fn outputs(&mut self, y: &[f64]) -> Result<MeshOutputs, DynamicsError> {
        if y.len() != N_STATES {
            return Err(invalid("state length", y.len() as f64, "8"));
        }
        self.mesh_at(y[PHI_P], y[PHI_G], y[W_P], y[W_G])
            .map_err(|source| DynamicsError::Mesh { t: None, source })
    }

    /// Mesh outputs at hub angles `phi_p`, `phi_g` (rad) and rates `w_p`, `w_g` (rad/s), all
    /// fields; the last evaluation is reused for bit-identical arguments if it is complete.
    pub(crate) fn mesh_at(
        &mut self,
        phi_p: f64,
        phi_g: f64,
        w_p: f64,
        w_g: f64,
    ) -> Result<MeshOutputs, MeshError> {
        self.cached(phi_p, phi_g, w_p, w_g, true).copied()
    }

    /// [`Self::mesh_at`] for a right-hand side: the torques outputs (M_F, M_D, TE, …) are set,
    /// bit for bit those of [`Self::mesh_at`]; the rest is unspecified unless the evaluation
    /// was complete ([`MeshTorques::torques_into`]). Borrowed from the remembered evaluation.
    pub(crate) fn torques_at(
        &mut self,
        phi_p: f64,
        phi_g: f64,
        w_p: f64,
        w_g: f64,
    ) -> Result<&MeshOutputs, MeshError> {
        self.cached(phi_p, phi_g, w_p, w_g, false)
    }

    /// [`Self::torques_at`] as a copy, with its completeness flag: `true` when every field
    /// is as [`Self::mesh_at`] gives it, `false` when only the torques outputs are.
    pub(crate) fn torques_flagged_at(
        &mut self,
        phi_p: f64,
        phi_g: f64,
        w_p: f64,
        w_g: f64,
    ) -> Result<(MeshOutputs, bool), MeshError> {
        let o = *self.cached(phi_p, phi_g, w_p, w_g, false)?;
        Ok((o, self.cache.is_some_and(|(_, c)| c)))
    }

    fn cached(
        &mut self,
        phi_p: f64,
        phi_g: f64,
        w_p: f64,
        w_g: f64,
        complete: bool,
    ) -> Result<&MeshOutputs, MeshError> {
        let key = [phi_p.to_bits(), phi_g.to_bits(), w_p.to_bits(), w_g.to_bits()];
        let hit = matches!(self.cache, Some((k, c)) if k == key && (c || !complete));
        if !hit {
            // Forgotten until the evaluation into the record succeeds.
            self.cache = None;
            let state = MeshState { phi_p, phi_g, w_p, w_g, ..Default::default() };
            self.evaluations += 1;
            let c = if complete {
                self.cached_outputs = self.mesh.mesh(&state)?;
                true
            } else {
                self.mesh.torques_into(&state, &mut self.cached_outputs)?
            };
            self.cache = Some((key, c));
        }
        Ok(&self.cached_outputs)
    }

    /// Makes the mesh start its next evaluation from `warm` ([`MeshTorques::set_warm_start`])
    /// and drops the remembered evaluation (made from another warm start), so that the next
    /// results depend on (state, `warm`) only.
    pub(crate) fn set_warm_start(&mut self, warm: &WarmStart) {
        self.cache = None;
        self.mesh.set_warm_start(warm);
    }

    /// Copies the mesh's warm start into `out` ([`MeshTorques::warm_start`]).
    pub(crate) fn warm_start(&self, out: &mut WarmStart) {
        self.mesh.warm_start(out);
    }

    /// Sets the driving torque M (N·m, finite; the caller checks) of Eqs. 1 and 4.
    pub(crate) fn set_torque(&mut self, torque: f64) {
        self.drive.torque = torque;
    }

    /// The static-equilibrium start at pinion angle `phi_p0` (rad) and nominal pinion speed
    /// `omega_p` (rad/s); see the module doc. `settings` are those of the mesh equilibrium.
    pub fn static_start(
        &mut self,
        phi_p0: f64,
        omega_p: f64,
        settings: &EquilibriumSettings,
    ) -> Result<StaticStart, DynamicsError> {
        if !phi_p0.is_finite() {
            return Err(invalid("phi_p0", phi_p0, "finite"));
        }
        if !(omega_p.is_finite() && omega_p.abs() <= crate::mesh::validity::MAX_SPEED_RAD_S) {
            return Err(invalid(
                "omega_p",
                omega_p,
                "finite, |ω_p| <= 1e5 rad/s (the largest nominal speed; negative: running \
                 backwards)",
            ));
        }
        // The equilibrium forms φg from TE: TE keeps its digits only up to a bound.
        crate::mesh::validity::check_formed_angle("phi_p0", phi_p0, self.g_p)
            .map_err(DynamicsError::Param)?;
        let d = self.drive;
        // Guess: the TE of a 100 N/µm mesh; the bracket search expands from there.
        let guess = d.torque / (self.g_p * 1e8);
        // With friction the equilibrium holds at the start speed (the friction torques are
        // part of M_F), and the brake takes the power the mesh delivers over a mesh cycle.
        let friction = self.mesh.has_friction();
        let running = EquilibriumSettings { w_p: omega_p, ..*settings };
        let settings = if friction { &running } else { settings };
        let eq = equilibrium(&mut self.mesh, phi_p0, d.torque, guess, settings)
            .map_err(|source| DynamicsError::Mesh { t: None, source })?;
        self.drive.brake_factor = 1.0;
        let p_in = d.torque * omega_p;
        if friction && p_in != 0.0 {
            let pitch = 2.0 * std::f64::consts::PI / d.z_p as f64;
            let curve = static_curve_with(&mut self.mesh, d.torque, phi_p0, pitch, 16, 1, settings)
                .map_err(|source| DynamicsError::Mesh { t: None, source })?;
            let n = curve.points.len() as f64;
            let loss = curve.points.iter().map(|e| e.outputs.p_loss).sum::<f64>() / n;
            self.drive.brake_factor = 1.0 - loss / p_in;
        }
        self.cache = None;
        let w_g = d.gear_speed(omega_p);
        let y = [
            phi_p0 + d.torque / d.c1,
            phi_p0,
            eq.phi_g,
            eq.phi_g + eq.outputs.m_f_g / d.c2,
            omega_p,
            omega_p,
            w_g,
            w_g,
        ];
        Ok(StaticStart { y, te: eq.te, outputs: eq.outputs, evaluations: eq.evaluations })
    }

    /// Writes the derivative of Eqs. 1–4 at state `y` with mesh outputs `o` into `dydt`.
    pub(crate) fn derivative(&self, y: &[f64], o: &MeshOutputs, dydt: &mut [f64]) {
        derivative(&self.drive, y, MeshLoads::of(o), dydt);
    }
}

/// The mesh torques a right-hand side reads, N·m: M_F and M_D of pinion and gear (Eqs. 13–14).
#[derive(Debug, Clone, Copy)]
pub(crate) struct MeshLoads {
    pub(crate) m_f_p: f64,
    pub(crate) m_f_g: f64,
    pub(crate) m_d_p: f64,
    pub(crate) m_d_g: f64,
}

impl MeshLoads {
    /// The four torques of `o`.
    pub(crate) fn of(o: &MeshOutputs) -> Self {
        Self { m_f_p: o.m_f_p, m_f_g: o.m_f_g, m_d_p: o.m_d_p, m_d_g: o.m_d_g }
    }
}

/// Eqs. 1–4: the state derivative `dydt` of drivetrain `d` at state `y` with mesh torques `o`.
fn derivative(d: &Drivetrain, y: &[f64], o: MeshLoads, dydt: &mut [f64]) {
    let shaft1 = d.c1 * (y[PHI_1] - y[PHI_P]) + d.d1 * (y[W_1] - y[W_P]);
    let shaft2 = d.c2 * (y[PHI_G] - y[PHI_2]) + d.d2 * (y[W_G] - y[W_2]);
    dydt[PHI_1] = y[W_1];
    dydt[PHI_P] = y[W_P];
    dydt[PHI_G] = y[W_G];
    dydt[PHI_2] = y[W_2];
    dydt[W_1] = (d.torque - shaft1) / d.j1;
    dydt[W_P] = (shaft1 - o.m_f_p - o.m_d_p) / d.j_p;
    dydt[W_G] = (-shaft2 - o.m_f_g - o.m_d_g) / d.j_g;
    dydt[W_2] = (d.brake_torque() + shaft2) / d.j2;
}

impl<M: MeshTorques> OdeSystem for GearDynamics<M> {
    fn dim(&self) -> usize {
        N_STATES
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        if y.len() != N_STATES || dydt.len() != N_STATES {
            return Err(OdeError::DimensionMismatch {
                what: "y/dydt",
                expected: N_STATES,
                found: if y.len() != N_STATES { y.len() } else { dydt.len() },
            });
        }
        let o =
            self.torques_at(y[PHI_P], y[PHI_G], y[W_P], y[W_G]).map_err(|e| OdeError::rhs(t, e))?;
        let m = MeshLoads::of(o);
        derivative(&self.drive, y, m, dydt);
        Ok(())
    }
}

/// Linearised mesh stiffness k = (∂M_F,p/∂TE)/g_p along the line of action, N/m, at the
/// static equilibrium for `torque` (N·m) at pinion angle `phi_p` (rad), by a central
/// difference of ±1 % of the static TE (at least ±1 nm).
pub fn mesh_stiffness<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
) -> Result<f64, MeshError> {
    Ok(mesh_linearisation(mesh, phi_p, torque)?.stiffness)
}

/// The mesh linearised about its static equilibrium (see [`mesh_linearisation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshLinearisation {
    /// Static TE of the equilibrium, m.
    pub te: f64,
    /// Mesh stiffness k along the line of action, N/m ([`mesh_stiffness`]).
    pub stiffness: f64,
    /// Mesh damping coefficient c = ∂F_D/∂v_TE along the line of action, N·s/m: the damping
    /// force of Eq. 14 per unit rate of TE, d_mesh times the loaded axial extent (units of
    /// m_n) at the equilibrium; 0 when the mesh's damping is off.
    pub damping: f64,
}

/// The mesh linearised about the static equilibrium for `torque` (N·m) at pinion angle `phi_p`
/// (rad): the stiffness as [`mesh_stiffness`] and the damping coefficient c from one
/// evaluation at the equilibrium with a TE rate v = 1 mm/s (pinion turning, gear at rest):
/// M_D,p = c·v·g_p (Eq. 14 is linear in the rate), so c = M_D,p/(v·g_p).
pub fn mesh_linearisation<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
) -> Result<MeshLinearisation, MeshError> {
    let (gp, gg) = mesh.base_radii();
    let eq =
        equilibrium(mesh, phi_p, torque, torque / (gp * 1e8), &EquilibriumSettings::default())?;
    let dte = (0.01 * eq.te.abs()).max(1e-9);
    let state = |te: f64, w_p: f64| MeshState {
        phi_p,
        phi_g: crate::numeric::phi_g_for_te(phi_p, te, gp, gg),
        w_p,
        w_g: 0.0,
        ..Default::default()
    };
    let hi = mesh.mesh(&state(eq.te + dte, 0.0))?.m_f_p;
    let lo = mesh.mesh(&state(eq.te - dte, 0.0))?.m_f_p;
    let v = 1e-3;
    let damped = mesh.mesh(&state(eq.te, v / gp))?.m_d_p;
    Ok(MeshLinearisation {
        te: eq.te,
        stiffness: (hi - lo) / (2.0 * dte) / gp,
        damping: (damped / (v * gp)).max(0.0),
    })
}

/// The largest modulus |λ| (rad/s) of the eigenvalues of the linear system J·q̈ + C·q̇ + K·q
/// = 0 with the diagonal inertias `j` (kg·m², > 0), stiffness matrix `k` (N·m/rad) and
/// damping matrix `c` (N·m·s/rad), both symmetric n × n in row-major order (n = `j.len()`
/// ≤ 4): the eigenvalues of the first-order state matrix [[0, I], [−J⁻¹K, −J⁻¹C]]. For an
/// underdamped mode |λ| = ω (the undamped frequency, whatever the damping ratio ζ < 1); an
/// overdamped one has the real eigenvalue −ω·(ζ + √(ζ² − 1)) ≈ −c/m, which grows without
/// bound with the damping (see the module doc of `super::limits`). 0 for non-finite input.
pub fn fastest_linear_rate(j: &[f64], k: &[f64], c: &[f64]) -> f64 {
    linear_eigenvalues(j, k, c).iter().map(|l| l.norm()).fold(0.0, f64::max)
}

/// The eigenvalues λ (rad/s; complex: decay rate and frequency) of the linear system of
/// [`fastest_linear_rate`]; empty for inconsistent sizes, non-finite values or an inertia
/// that is not > 0.
pub fn linear_eigenvalues(j: &[f64], k: &[f64], c: &[f64]) -> Vec<num_complex::Complex<f64>> {
    let n = j.len();
    if n == 0 || n > 4 || k.len() != n * n || c.len() != n * n {
        return Vec::new();
    }
    if j.iter().chain(k).chain(c).any(|v| !v.is_finite()) || j.iter().any(|v| *v <= 0.0) {
        return Vec::new();
    }
    let a = nalgebra::DMatrix::from_fn(2 * n, 2 * n, |r, col| {
        if r < n {
            if col == r + n { 1.0 } else { 0.0 }
        } else {
            let i = r - n;
            if col < n { -k[i * n + col] / j[i] } else { -c[i * n + col - n] / j[i] }
        }
    });
    a.complex_eigenvalues().iter().copied().collect()
}
