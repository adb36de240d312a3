//! The gear bodies on elastic supports, coupled to the drive line of Eqs. 1–4 — a
//! specification.
//!
//! # Degrees of freedom
//! The four rotations of Eqs. 1–4 ([`super::model`]) and, for each gear body on a support
//! ([`crate::mesh::supports`]), its pose p = (u_x, u_y, u_z, θ_x, θ_y) at its centre at
//! mid-face in the housing frame ([`crate::mesh::pose`]). A body without a support is held
//! rigidly: its pose and rate stay zero. The state vector has 28 components:
//!
//! ```text
//! y = (φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂, p_p (5), p_g (5), ṗ_p (5), ṗ_g (5))
//! ```
//!
//! (indices [`POSE_P`], [`POSE_G`], [`RATE_P`], [`RATE_G`] for the blocks).
//!
//! # Equations of motion
//! The mesh is evaluated at the whole state: the hub angles and speeds, both poses and both
//! pose rates ([`crate::mesh::MeshState`]). Its torques enter Eqs. 1–4 exactly as with rigid
//! bearings. Its force F and tilting moments M on each body (housing frame, elastic and damping
//! parts, about the body's displaced centre, [`crate::mesh::forces`]) drive the body against
//! its support's reaction R = −K·p − C·ṗ:
//!
//! ```text
//! m·ü   = F + R_u                                   (translation, 3 components)
//! J_t·θ̈_x = M_x + R_θx − J_z·φ̇·θ̇_y                (tilt about x)
//! J_t·θ̈_y = M_y + R_θy + J_z·φ̇·θ̇_x                (tilt about y)
//! ```
//!
//! with m the body's mass, J_t its transverse moment of inertia about its centre, J_z its polar
//! inertia (the J_p, J_g of Eqs. 2–3) and φ̇ its speed. The last terms are the gyroscopic
//! moments of the spinning body: its spin axis is tilted to (θ_y, −θ_x, 1), so its angular
//! momentum J_z·φ̇·(θ_y, −θ_x, 1) + J_t·(θ̇_x, θ̇_y, 0) changes at the rate of the applied
//! moment (terms of second order in the pose, and φ̈ times the tilt, are left out). They do
//! no work, so they leave the energy balance alone, and they split each tilting mode of a
//! spinning body into a forward and a backward whirl.
//!
//! # Static start
//! [`SupportedDynamics::static_start`] starts at the static equilibrium of the mesh with the
//! bodies displaced ([`crate::mesh::supported_equilibrium`]): TE and both poses balance the
//! torque and the supports, the shafts are wound up as in
//! [`GearDynamics::static_start`](super::GearDynamics::static_start), every speed is the
//! nominal one and the bodies are at rest on their supports.
//!
//! # Linearised modes and the step
//! [`SupportedDynamics::linear_modes`] linearises the whole system about the static start: the
//! shafts and supports are linear, the gyroscopic terms too, and the mesh's force and torques
//! are differentiated by central differences of the full mesh outputs — with respect to TE at a
//! fixed mesh phase (which gives the φp and φg columns through g_p and g_g, as
//! [`super::model::mesh_linearisation`] does for the torsional model), to each pose component,
//! to the TE rate and to each pose rate. The eigenvalues λ of the first-order state matrix give
//! the coupled modes (frequency Im λ, damping ratio −Re λ/|λ|), and the largest |λ| the RK4
//! step rule of [`super::limits`]: at most T_m/128 and 2π/(32·|λ|_max).
//!
//! # What is not modelled
//! Friction with supports is refused (the pose sensitivities of the friction forces are not
//! derived). The support is linear and acts at the body's centre; the shaft arrangement of
//! `static --bearings` is not turned into a support yet.

use nalgebra::DMatrix;
use num_complex::Complex;

use super::integrators::{OdeError, OdeSystem, Rk4};
use super::limits::{STEPS_PER_FAST_PERIOD, check_rk4_step};
use super::model::{Drivetrain, DynamicsError, GearDynamics, N_STATES, invalid};
use super::simulate::{DEFAULT_STEPS_PER_MESH_PERIOD, Trajectory, check_samples};
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::supports::{Support, Supports, supported_equilibrium};
use crate::mesh::{BodyPose, MeshError, MeshOutputs, MeshState, MeshTorques};

/// Number of states of the supported model: 8 of Eqs. 1–4 and 20 of the two bodies.
pub const N_BODY_STATES: usize = 28;
/// Index of the pinion body's pose (5 components: u_x, u_y, u_z, θ_x, θ_y; m, rad).
pub const POSE_P: usize = 8;
/// Index of the gear body's pose.
pub const POSE_G: usize = 13;
/// Index of the pinion body's pose rate (m/s, rad/s).
pub const RATE_P: usize = 18;
/// Index of the gear body's pose rate.
pub const RATE_G: usize = 23;

/// The names of the support force and moment on each body (what the support exerts on the
/// body, N and N·m), in the order of [`SupportReactions::values`].
pub const REACTION_NAMES: [&str; 10] =
    ["R_p_x", "R_p_y", "R_p_z", "R_p_mx", "R_p_my", "R_g_x", "R_g_y", "R_g_z", "R_g_mx", "R_g_my"];

/// The force and moment each support exerts on its body, R = −K·p − C·ṗ (N, N·m; the order of
/// [`BodyPose::values`]); zero for a rigid body.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupportReactions {
    /// On the pinion body.
    pub pinion: [f64; 5],
    /// On the gear body.
    pub gear: [f64; 5],
}

impl SupportReactions {
    /// The ten values in the order of [`REACTION_NAMES`].
    pub fn values(&self) -> [f64; 10] {
        let mut v = [0.0; 10];
        v[..5].copy_from_slice(&self.pinion);
        v[5..].copy_from_slice(&self.gear);
        v
    }
}

/// The start of a supported run: state, static TE, mesh outputs and reactions there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportedStart {
    /// The state at t = 0 (28 components, module docs).
    pub y: [f64; N_BODY_STATES],
    /// The static TE, m.
    pub te: f64,
    /// The mesh outputs at the start.
    pub outputs: MeshOutputs,
    /// The support reactions at the start (they balance the mesh's force and moments).
    pub reactions: SupportReactions,
}

/// The coupled modes of the linearised model (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct CoupledModes {
    /// Eigenvalues λ of the first-order state matrix with Im λ > 0 (one per oscillating mode;
    /// the drive line's free rotation is left out), in ascending Im λ, rad/s.
    pub eigenvalues: Vec<Complex<f64>>,
    /// The mode shapes: per eigenvalue its eigenvector of the first-order system in the layout
    /// of the 28 states (module docs; zero for a rigid body), scaled so that its largest
    /// component is 1. The free motion Re(v·e^(λt)) of the linearisation starts at Re(v).
    pub shapes: Vec<[Complex<f64>; N_BODY_STATES]>,
    /// The largest |λ| of all eigenvalues (overdamped ones included), rad/s.
    pub fastest: f64,
    /// Mesh stiffness along the line of action at the start, N/m.
    pub mesh_stiffness: f64,
}

impl CoupledModes {
    /// The modes' frequencies Im λ/(2π), Hz, ascending.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues.iter().map(|l| l.im / (2.0 * std::f64::consts::PI)).collect()
    }
}

/// Eqs. 1–4 with both gear bodies on their supports, as an [`OdeSystem`] of
/// [`N_BODY_STATES`] states (module docs).
#[derive(Debug, Clone)]
pub struct SupportedDynamics<M> {
    gears: GearDynamics<M>,
    supports: Supports,
    evaluations: usize,
    /// The last evaluation (bits of the 28 states, outputs), reused for a bit-identical state:
    /// recording a step's end state and the next step's first stage evaluate the same state.
    /// The mesh is a function of the state, so this changes no result (as in
    /// [`GearDynamics`]); dropped whenever the mesh is used from outside.
    cache: Option<([u64; N_BODY_STATES], MeshOutputs)>,
}

impl<M: MeshTorques> SupportedDynamics<M> {
    /// The model with mesh `mesh`, drivetrain `drive` and the bodies' `supports`; the mesh is
    /// prepared for poses ([`MeshTorques::prepare_poses`]: a table builds its pose
    /// sensitivities). A mesh with friction is refused (module docs).
    pub fn new(mesh: M, drive: Drivetrain, supports: Supports) -> Result<Self, DynamicsError> {
        if mesh.has_friction() {
            return Err(invalid(
                "friction",
                1.0,
                "none with supports (the friction forces' pose sensitivities are not derived)",
            ));
        }
        let mut mesh = mesh;
        mesh.prepare_poses().map_err(|source| DynamicsError::Mesh { t: None, source })?;
        Ok(Self { gears: GearDynamics::new(mesh, drive)?, supports, evaluations: 0, cache: None })
    }

    /// The drivetrain.
    pub fn drive(&self) -> &Drivetrain {
        self.gears.drive()
    }

    /// Sets the driving torque M (N·m, finite; the caller checks) of Eqs. 1 and 4; the load
    /// on J₂ follows (M·z_g/z_p).
    pub(crate) fn set_torque(&mut self, torque: f64) {
        self.gears.set_torque(torque);
    }

    /// The supports.
    pub fn supports(&self) -> &Supports {
        &self.supports
    }

    /// The mesh model (forgets the remembered evaluation).
    pub fn mesh_mut(&mut self) -> &mut M {
        self.cache = None;
        self.gears.mesh_mut()
    }

    /// Number of mesh evaluations so far (remembered ones not counted).
    pub fn mesh_evaluations(&self) -> usize {
        self.evaluations
    }

    /// The mesh state of state `y` (28 components).
    pub fn mesh_state(y: &[f64]) -> MeshState {
        let body = |i: usize| BodyPose::from_values(std::array::from_fn(|k| y[i + k]));
        MeshState {
            phi_p: y[1],
            phi_g: y[2],
            w_p: y[5],
            w_g: y[6],
            pose_p: body(POSE_P),
            pose_g: body(POSE_G),
            rate_p: body(RATE_P),
            rate_g: body(RATE_G),
        }
    }

    /// The support reactions at state `y`.
    pub fn reactions(&self, y: &[f64]) -> SupportReactions {
        let s = Self::mesh_state(y);
        let r = |sup: &Option<Support>, p: &BodyPose, v: &BodyPose| {
            sup.map_or([0.0; 5], |k| k.reaction(p, v))
        };
        SupportReactions {
            pinion: r(&self.supports.pinion, &s.pose_p, &s.rate_p),
            gear: r(&self.supports.gear, &s.pose_g, &s.rate_g),
        }
    }

    /// The mesh outputs at state `y` (28 components); the last evaluation is reused for a
    /// bit-identical state.
    pub fn outputs(&mut self, y: &[f64]) -> Result<MeshOutputs, DynamicsError> {
        if y.len() != N_BODY_STATES {
            return Err(invalid("state length", y.len() as f64, "28"));
        }
        self.mesh_at(y).map_err(|source| DynamicsError::Mesh { t: None, source })
    }

    /// The mesh at state `y` (28 components), remembered (see the field `cache`).
    fn mesh_at(&mut self, y: &[f64]) -> Result<MeshOutputs, MeshError> {
        let key: [u64; N_BODY_STATES] = std::array::from_fn(|i| y[i].to_bits());
        if let Some((k, o)) = &self.cache
            && *k == key
        {
            return Ok(*o);
        }
        self.evaluations += 1;
        let o = self.gears.mesh_mut().mesh(&Self::mesh_state(y))?;
        self.cache = Some((key, o));
        Ok(o)
    }

    /// The static start at pinion angle `phi_p0` (rad) and nominal pinion speed `omega_p`
    /// (rad/s) (module docs); `settings` as for the mesh equilibrium.
    pub fn static_start(
        &mut self,
        phi_p0: f64,
        omega_p: f64,
        settings: &EquilibriumSettings,
    ) -> Result<SupportedStart, DynamicsError> {
        self.cache = None;
        // The rigid start checks the arguments and gives the TE guess.
        let rigid = self.gears.static_start(phi_p0, omega_p, settings)?;
        let d = *self.gears.drive();
        let eq = supported_equilibrium(
            self.gears.mesh_mut(),
            phi_p0,
            d.torque,
            rigid.te,
            &self.supports,
            settings,
        )
        .map_err(|source| DynamicsError::Mesh { t: None, source })?
        .equilibrium;
        let mut y = [0.0; N_BODY_STATES];
        y[..N_STATES].copy_from_slice(&rigid.y);
        y[2] = eq.phi_g;
        y[3] = eq.phi_g + eq.outputs.m_f_g / d.c2;
        if self.supports.pinion.is_some() {
            y[POSE_P..POSE_P + 5].copy_from_slice(&eq.pose_p.values());
        }
        if self.supports.gear.is_some() {
            y[POSE_G..POSE_G + 5].copy_from_slice(&eq.pose_g.values());
        }
        let outputs = self.outputs(&y)?;
        Ok(SupportedStart { y, te: eq.te, outputs, reactions: self.reactions(&y) })
    }

    /// Writes the derivative at state `y` with mesh outputs `o` into `dydt`.
    fn derivative(&self, y: &[f64], o: &MeshOutputs, dydt: &mut [f64]) {
        self.gears.derivative(&y[..N_STATES], o, &mut dydt[..N_STATES]);
        let d = self.gears.drive();
        let r = self.reactions(y);
        let bodies = [
            (&self.supports.pinion, POSE_P, RATE_P, o.force_p, o.moment_p, r.pinion, d.j_p, y[5]),
            (&self.supports.gear, POSE_G, RATE_G, o.force_g, o.moment_g, r.gear, d.j_g, y[6]),
        ];
        for (sup, ip, iv, f, m, r, j_z, spin) in bodies {
            let Some(s) = sup else {
                dydt[ip..ip + 5].fill(0.0);
                dydt[iv..iv + 5].fill(0.0);
                continue;
            };
            dydt[ip..ip + 5].copy_from_slice(&y[iv..iv + 5]);
            let h = j_z * spin;
            for k in 0..3 {
                dydt[iv + k] = (f[k] + r[k]) / s.mass_kg;
            }
            dydt[iv + 3] = (m[0] + r[3] - h * y[iv + 4]) / s.j_transverse_kgm2;
            dydt[iv + 4] = (m[1] + r[4] + h * y[iv + 3]) / s.j_transverse_kgm2;
        }
    }

    /// The coupled modes linearised about the static start `start` (module docs; the spin of
    /// the gyroscopic terms is the start's speeds): central differences of the mesh, 4 mesh
    /// evaluations and 20 more per supported body.
    pub fn linear_modes(&mut self, start: &SupportedStart) -> Result<CoupledModes, DynamicsError> {
        let d = *self.gears.drive();
        let (gp, gg) = self.gears.base_radii();
        // Degrees of freedom: φ₁, φp, φg, φ₂, then the supported bodies' poses.
        let mut dofs: Vec<(usize, f64, f64)> = Vec::new(); // (pose index, mass, polar inertia)
        for (sup, ip, j_z) in
            [(&self.supports.pinion, POSE_P, d.j_p), (&self.supports.gear, POSE_G, d.j_g)]
        {
            if let Some(s) = sup {
                for k in 0..5 {
                    let m = if k < 3 { s.mass_kg } else { s.j_transverse_kgm2 };
                    dofs.push((ip + k, m, j_z));
                }
            }
        }
        let n = 4 + dofs.len();
        let mut mass = vec![d.j1, d.j_p, d.j_g, d.j2];
        mass.extend(dofs.iter().map(|x| x.1));
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut c = DMatrix::<f64>::zeros(n, n);
        // Shafts.
        for (i, j, ks, ds) in [(0, 1, d.c1, d.d1), (2, 3, d.c2, d.d2)] {
            for (a, bb, s) in [(i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)] {
                k[(a, bb)] += s * ks;
                c[(a, bb)] += s * ds;
            }
        }
        // Supports and gyroscopic terms.
        let mut row = 4;
        for (sup, spin, j_z) in
            [(&self.supports.pinion, start.y[5], d.j_p), (&self.supports.gear, start.y[6], d.j_g)]
        {
            if let Some(s) = sup {
                for a in 0..5 {
                    for bb in 0..5 {
                        k[(row + a, row + bb)] += s.stiffness[a][bb];
                        c[(row + a, row + bb)] += s.damping[a][bb];
                    }
                }
                c[(row + 3, row + 4)] += j_z * spin;
                c[(row + 4, row + 3)] -= j_z * spin;
                row += 5;
            }
        }
        // The mesh: generalised forces on (φp, φg, poses) by central differences.
        let forces = |o: &MeshOutputs, f: &mut Vec<f64>| {
            f.clear();
            f.extend([0.0, -o.m_f_p - o.m_d_p, -o.m_f_g - o.m_d_g, 0.0]);
            for &(i, _, _) in &dofs {
                let (pose, k) = if i < POSE_G { (0, i - POSE_P) } else { (1, i - POSE_G) };
                let v = match (pose, k) {
                    (0, 0..=2) => o.force_p[k],
                    (0, _) => o.moment_p[k - 3],
                    (_, 0..=2) => o.force_g[k],
                    (_, _) => o.moment_g[k - 3],
                };
                f.push(v);
            }
        };
        let te = start.te.abs().max(1e-7);
        let mut probes: Vec<Probe> = vec![
            // TE at a fixed phase: φg moves by δ/g_g; columns φp (·g_p) and φg (·g_g).
            (2, 0.01 * te / gg, vec![(1, gp / gg), (2, 1.0)], false),
            // TE rate: φ̇g moves by v/g_g.
            (6, 1e-3 / gg, vec![(1, gp / gg), (2, 1.0)], true),
        ];
        for (col, &(i, _, _)) in dofs.iter().enumerate() {
            let tilt = (i - POSE_P) % 5 >= 3;
            let step = if tilt { 0.01 * te / gp } else { 0.01 * te };
            probes.push((i, step, vec![(4 + col, 1.0)], false));
            let vstep = if tilt { 1e-3 / gp } else { 1e-3 };
            probes.push((i + 10, vstep, vec![(4 + col, 1.0)], true));
        }
        let (mut fp, mut fm) = (Vec::new(), Vec::new());
        let mut mesh_k = 0.0;
        for (i, h, cols, rate) in probes {
            let mut y = start.y;
            y[i] += h;
            let op = self.outputs(&y)?;
            y[i] = start.y[i] - h;
            let om = self.outputs(&y)?;
            forces(&op, &mut fp);
            forces(&om, &mut fm);
            if i == 2 {
                mesh_k = (op.m_f_p - om.m_f_p) / (2.0 * h * gg) / gp;
            }
            for (col, w) in cols {
                for r in 0..n {
                    let df = -(fp[r] - fm[r]) / (2.0 * h) * w;
                    if rate {
                        c[(r, col)] += df;
                    } else {
                        k[(r, col)] += df;
                    }
                }
            }
        }
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for r in 0..n {
            a[(r, r + n)] = 1.0;
            for col in 0..n {
                a[(r + n, col)] = -k[(r, col)] / mass[r];
                a[(r + n, col + n)] = -c[(r, col)] / mass[r];
            }
        }
        let eig: Vec<Complex<f64>> = a.complex_eigenvalues().iter().copied().collect();
        if eig.iter().any(|l| !(l.re.is_finite() && l.im.is_finite())) {
            return Err(invalid("linearised modes", f64::NAN, "finite eigenvalues"));
        }
        let fastest = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
        // The drive line's free rotation (constant torques at both ends) is a double zero
        // eigenvalue; round-off gives it a tiny imaginary part, which is not a mode.
        let mut eigenvalues: Vec<Complex<f64>> =
            eig.into_iter().filter(|l| l.im > 1e-6 * fastest).collect();
        eigenvalues.sort_by(|x, y| x.im.total_cmp(&y.im));
        // State index of each first-order coordinate: (q, q̇) with q = (φ₁, φp, φg, φ₂, poses).
        let index = |r: usize| {
            let (q, rate) = if r < n { (r, false) } else { (r - n, true) };
            let i = if q < 4 { q } else { dofs[q - 4].0 };
            match (q < 4, rate) {
                (_, false) => i,
                (true, true) => i + 4,
                (false, true) => i + 10,
            }
        };
        let shapes = eigenvalues
            .iter()
            .map(|l| {
                let v = eigenvector(&a, *l);
                let mut full = [Complex::new(0.0, 0.0); N_BODY_STATES];
                for (r, x) in v.iter().enumerate() {
                    full[index(r)] = *x;
                }
                full
            })
            .collect();
        Ok(CoupledModes { eigenvalues, shapes, fastest, mesh_stiffness: mesh_k })
    }
}

/// The eigenvector of the real matrix `a` for its eigenvalue `l`, by inverse iteration with a
/// shift 10⁻¹⁰·|λ| off λ (three solves), scaled to unit largest component.
fn eigenvector(a: &DMatrix<f64>, l: Complex<f64>) -> Vec<Complex<f64>> {
    let m = a.nrows();
    let shift = l + Complex::new(1e-10 * l.norm(), 1e-10 * l.norm());
    let shifted = DMatrix::<Complex<f64>>::from_fn(m, m, |r, c| {
        Complex::new(a[(r, c)], 0.0) - if r == c { shift } else { Complex::new(0.0, 0.0) }
    });
    let lu = shifted.lu();
    let mut x = nalgebra::DVector::<Complex<f64>>::from_fn(m, |r, _| {
        Complex::new(1.0 + 0.1 * r as f64, 0.05 * r as f64)
    });
    for _ in 0..3 {
        let Some(y) = lu.solve(&x) else { break };
        let big = y.iter().map(|c| c.norm()).fold(0.0, f64::max);
        if !(big.is_finite() && big > 0.0) {
            break;
        }
        // Scaled so that the largest component is real and 1.
        let k = y.iter().position(|c| c.norm() == big).unwrap_or(0);
        let pivot = y[k];
        x = y.map(|c| c / pivot);
    }
    x.iter().copied().collect()
}

impl<M: MeshTorques> OdeSystem for SupportedDynamics<M> {
    fn dim(&self) -> usize {
        N_BODY_STATES
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        if y.len() != N_BODY_STATES || dydt.len() != N_BODY_STATES {
            return Err(OdeError::DimensionMismatch {
                what: "y/dydt",
                expected: N_BODY_STATES,
                found: if y.len() != N_BODY_STATES { y.len() } else { dydt.len() },
            });
        }
        let o = self.mesh_at(y).map_err(|e| OdeError::rhs(t, e))?;
        self.derivative(y, &o, dydt);
        Ok(())
    }
}

/// One central difference of [`SupportedDynamics::linear_modes`]: the state index perturbed,
/// its step, the columns it fills with their weights, and whether it is a rate (a column of
/// the damping matrix) or a position (of the stiffness matrix).
type Probe = (usize, f64, Vec<(usize, f64)>, bool);

/// A recorded trajectory of the supported model.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SupportedTrajectory {
    /// Times, the eight states of Eqs. 1–4 and the mesh outputs, as for rigid bearings.
    pub drive: Trajectory,
    /// Per output time the twenty body states (p_p, p_g, ṗ_p, ṗ_g; the interface order of
    /// [`crate::mesh::pose::INPUT_NAMES`]).
    pub bodies: Vec<[f64; 20]>,
    /// Per output time the support reactions.
    pub reactions: Vec<SupportReactions>,
}

impl SupportedTrajectory {
    /// The last recorded state (28 components; zero for an empty record).
    pub fn end_state(&self) -> [f64; N_BODY_STATES] {
        let mut y = [0.0; N_BODY_STATES];
        if let (Some(s), Some(b)) = (self.drive.states.last(), self.bodies.last()) {
            y[..N_STATES].copy_from_slice(s);
            y[N_STATES..].copy_from_slice(b);
        }
        y
    }
}

/// The default RK4 step of [`simulate_supported`] for the modes `modes` at nominal pinion
/// speed `omega_p` (rad/s): T_m/N with N ≥ [`DEFAULT_STEPS_PER_MESH_PERIOD`] the smallest
/// whole number that also gives [`STEPS_PER_FAST_PERIOD`] steps per period of the fastest
/// mode; at standstill 2π/(32·|λ|_max). A whole number of steps per mesh period keeps the
/// samples on the mesh-order grid of [`support_force_stats`].
pub fn supported_rk4_step(drive: &Drivetrain, modes: &CoupledModes, omega_p: f64) -> f64 {
    let h_fast = 2.0 * std::f64::consts::PI / (modes.fastest * STEPS_PER_FAST_PERIOD);
    if omega_p == 0.0 {
        return h_fast;
    }
    let t_m = drive.mesh_period(omega_p);
    let n = (t_m / h_fast).ceil().max(DEFAULT_STEPS_PER_MESH_PERIOD as f64);
    t_m / n
}

/// Integrates the supported model from `y0` with `n_steps` RK4 steps of `dt` (s), recording
/// every step. A step outside RK4's stability region for `modes` is refused
/// ([`check_rk4_step`]), and so is a record above
/// [`MAX_TRAJECTORY_SAMPLES`](super::limits::MAX_TRAJECTORY_SAMPLES).
pub fn simulate_supported<M: MeshTorques>(
    model: &mut SupportedDynamics<M>,
    y0: &[f64; N_BODY_STATES],
    dt: f64,
    n_steps: usize,
    modes: &CoupledModes,
) -> Result<SupportedTrajectory, DynamicsError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(invalid("dt", dt, "finite and > 0 (s)"));
    }
    if n_steps == 0 {
        return Err(invalid("n_steps", 0.0, ">= 1"));
    }
    check_samples(n_steps as f64 + 1.0, "lower t_end or raise dt")?;
    check_rk4_step(dt, modes.fastest)?;
    let evals0 = model.mesh_evaluations();
    let mut tr = SupportedTrajectory::default();
    let record = |model: &mut SupportedDynamics<M>,
                  tr: &mut SupportedTrajectory,
                  t: f64,
                  y: &[f64; N_BODY_STATES]|
     -> Result<(), DynamicsError> {
        let o = model.outputs(y)?;
        tr.drive.time.push(t);
        tr.drive.states.push(std::array::from_fn(|i| y[i]));
        tr.drive.outputs.push(o);
        tr.bodies.push(std::array::from_fn(|i| y[POSE_P + i]));
        tr.reactions.push(model.reactions(y));
        Ok(())
    };
    let mut y = *y0;
    record(model, &mut tr, 0.0, &y)?;
    let mut rk4 = Rk4::new(N_BODY_STATES);
    for i in 1..=n_steps {
        let t = (i - 1) as f64 * dt;
        rk4.step(model, t, dt, &mut y).map_err(DynamicsError::from)?;
        record(model, &mut tr, i as f64 * dt, &y)?;
    }
    tr.drive.steps = n_steps;
    tr.drive.mesh_evaluations = model.mesh_evaluations() - evals0;
    Ok(tr)
}

/// The dynamic forces of one bearing of a shaft-form support ([`crate::mesh::shaft`]) over a
/// window.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingStats {
    /// `"pinion"` or `"gear"`.
    pub shaft: &'static str,
    /// The bearing's index in the JSON's list.
    pub bearing: usize,
    /// Its position along the axis, m.
    pub z_m: f64,
    /// Per component (x, y, z) of the force the bearing exerts on the shaft, N.
    pub components: [ForceStats; 3],
}

/// The statistics of the forces of every bearing of the shaft-form supports of `supports`
/// over the window of [`support_force_stats`] (same arguments); empty without a shaft form.
pub fn bearing_force_stats(
    tr: &SupportedTrajectory,
    supports: &Supports,
    samples_per_period: usize,
    orders: usize,
) -> Vec<BearingStats> {
    let mut out = Vec::new();
    for (name, sup, off) in [("pinion", &supports.pinion, 0), ("gear", &supports.gear, 5)] {
        let Some(shaft) = sup.and_then(|s| s.shaft) else { continue };
        let forces: Vec<Vec<[f64; 3]>> = tr
            .bodies
            .iter()
            .map(|b| {
                let p = BodyPose::from_values(std::array::from_fn(|k| b[off + k]));
                shaft.bearing_forces(&p).collect()
            })
            .collect();
        for (i, bearing) in shaft.bearings().enumerate() {
            let components = std::array::from_fn(|c| {
                let x: Vec<f64> = forces.iter().map(|f| f[i][c]).collect();
                series_stats(&x, samples_per_period, orders)
            });
            out.push(BearingStats { shaft: name, bearing: i, z_m: bearing.z_m, components });
        }
    }
    out
}

/// Statistics of one recorded series `x` (one value per output time) over the window of
/// [`support_force_stats`]; default when the record is shorter than one period.
fn series_stats(x: &[f64], samples_per_period: usize, orders: usize) -> ForceStats {
    let total = x.len();
    let len = window_len(total, samples_per_period);
    if len == 0 {
        return ForceStats::default();
    }
    window_stats(&x[total - len..], samples_per_period, orders)
}

/// The samples of the statistics' window among `total` recorded ones: the last whole mesh
/// periods of `samples_per_period` samples (n steps record n + 1 samples; the repeated end
/// point of the first period is left out), all of them at standstill (`samples_per_period`
/// = 0); 0 when the record holds less than one period.
fn window_len(total: usize, samples_per_period: usize) -> usize {
    if samples_per_period == 0 {
        total
    } else {
        samples_per_period * (total.saturating_sub(1) / samples_per_period)
    }
}

/// Mean, peak to peak and mesh-order amplitudes of the window `x` (whole periods of
/// `samples_per_period` samples; 0: no orders).
fn window_stats(x: &[f64], samples_per_period: usize, orders: usize) -> ForceStats {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let (lo, hi) =
        x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let orders = if samples_per_period == 0 {
        Vec::new()
    } else {
        (1..=orders)
            .map(|k| {
                let w = 2.0 * std::f64::consts::PI * k as f64 / samples_per_period as f64;
                let s = x.iter().enumerate().fold(Complex::new(0.0, 0.0), |acc, (j, &v)| {
                    acc + Complex::from_polar(v, -w * j as f64)
                });
                2.0 * s.norm() / x.len() as f64
            })
            .collect()
    };
    ForceStats { mean, peak_to_peak: hi - lo, orders }
}

/// Statistics of one support force or moment over a window.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ForceStats {
    /// Mean, N or N·m.
    pub mean: f64,
    /// Peak to peak, N or N·m.
    pub peak_to_peak: f64,
    /// Amplitudes of mesh orders 1, 2, … (N or N·m): |2/N·Σ x_j·e^(−2πi·k·t_j/T_m)|.
    pub orders: Vec<f64>,
}

/// The statistics of the ten support reactions of `tr` ([`REACTION_NAMES`] order) over the
/// last whole number of mesh periods of the record, of `samples_per_period` steps each (the
/// whole record at standstill, `samples_per_period` = 0: no orders), with the first `orders`
/// mesh-order amplitudes. `None` when the record holds less than one period.
pub fn support_force_stats(
    tr: &SupportedTrajectory,
    samples_per_period: usize,
    orders: usize,
) -> Option<[ForceStats; 10]> {
    let total = tr.reactions.len();
    let len = window_len(total, samples_per_period);
    if len == 0 {
        return None;
    }
    let window = &tr.reactions[total - len..];
    Some(std::array::from_fn(|c| {
        let x: Vec<f64> = window.iter().map(|r| r.values()[c]).collect();
        window_stats(&x, samples_per_period, orders)
    }))
}
