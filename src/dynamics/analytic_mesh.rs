//! Analytic mesh models for verifying the dynamics: a linear spring and damper along the line
//! of action, with constant or mesh-periodic stiffness.
//!
//! These are not the paper's mesh model (that is [`crate::mesh`]); they have closed-form
//! static and linearised behaviour, which the tests of Eqs. 1–4, of the integrators and of the
//! speed sweep compare against.
//!
//! With TE = φp·g_p + φg·g_g (m) and dTE/dt = φ̇p·g_p + φ̇g·g_g (m/s):
//!
//! * elastic force along the line of action F = k·TE on the driving flanks (TE > 0), 0 in the
//!   backlash, k·(TE + b) on the back flanks (TE < −b) when a backlash b is modelled (see
//!   [`Clearance`]), N;
//! * damping force F_D = d_mesh·dTE/dt while any flank is in contact, 0 when separated, N;
//! * torques M_F,i = F·g_i, M_D,i = F_D·g_i (i = p, g), N·m, positive in normal drive, entering
//!   Eqs. 2–3 with a minus sign. (The paper's Eq. 14 also scales M_D with the contact length;
//!   these models use a unit length.)
//!
//! The diagnostics: `f_n` = |F|, `n_pairs` = 1 in contact, `separated` when no flank is in
//! contact, `back_contact` on the back flanks; `contact_length`, `p_max` and `tip_contact` are
//! not modelled (0, 0, false).

use std::f64::consts::PI;

use crate::error::ParamError;
use crate::mesh::{MeshError, MeshJacobian, MeshOutputs, MeshState, MeshTorques};

/// What the mesh force does away from positive TE.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clearance {
    /// F = k·TE for every TE, tension included: a linear spring that never separates.
    Bilateral,
    /// F = k·TE for TE > 0 and 0 otherwise: the teeth separate, there are no back flanks.
    Separating,
    /// As [`Clearance::Separating`], and the back flanks touch at TE = −b (b = the value, the
    /// backlash along the line of action, m, > 0): F = k·(TE + b) for TE < −b.
    Backlash(f64),
}

impl Clearance {
    fn validate(self) -> Result<(), MeshError> {
        if let Clearance::Backlash(b) = self
            && !(b.is_finite() && b > 0.0)
        {
            return Err(ParamError::new("backlash", b, "finite and > 0 (m)").into());
        }
        Ok(())
    }

    /// Spring deflection k·δ is the force: δ for TE (m), and whether the front or back flanks
    /// touch: (δ, front, back).
    fn deflection(self, te: f64) -> (f64, bool, bool) {
        match self {
            Clearance::Bilateral => (te, true, false),
            Clearance::Separating if te > 0.0 => (te, true, false),
            Clearance::Separating => (0.0, false, false),
            Clearance::Backlash(_) if te > 0.0 => (te, true, false),
            Clearance::Backlash(b) if te < -b => (te + b, false, true),
            Clearance::Backlash(_) => (0.0, false, false),
        }
    }
}

fn check_state(s: &MeshState) -> Result<(), MeshError> {
    for (name, value) in [("phi_p", s.phi_p), ("phi_g", s.phi_g), ("w_p", s.w_p), ("w_g", s.w_g)] {
        if !value.is_finite() {
            return Err(MeshError::NonFinite { name, value });
        }
    }
    if !s.bodies_at_rest() {
        // These meshes have no geometry to displace.
        return Err(MeshError::Unsupported(
            "a gear body off its bearing axis (pose or pose rate) in an analytic mesh",
        ));
    }
    Ok(())
}

fn check_positive(name: &str, v: f64) -> Result<(), MeshError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, v, "finite and > 0").into())
    }
}

/// Outputs of a spring k (N/m) with clearance `c` and damper `d` (N·s/m) at `s`.
fn spring_outputs(k: f64, d: f64, gp: f64, gg: f64, c: Clearance, s: &MeshState) -> MeshOutputs {
    let te = crate::numeric::dot2(s.phi_p, gp, s.phi_g, gg);
    let (delta, front, back) = c.deflection(te);
    let contact = front || back;
    let f = k * delta;
    let fd = if contact { d * (s.w_p * gp + s.w_g * gg) } else { 0.0 };
    MeshOutputs {
        m_f_p: f * gp,
        m_f_g: f * gg,
        m_d_p: fd * gp,
        m_d_g: fd * gg,
        te,
        f_n: f.abs(),
        contact_length: 0.0,
        p_max: 0.0,
        n_pairs: u32::from(contact),
        tip_contact: false,
        separated: !contact,
        back_contact: back,
        // A lumped spring has no contact geometry: no 3D force or moments.
        ..MeshOutputs::default()
    }
}

/// Exact partial derivatives of [`spring_outputs`] with stiffness `k` (N/m) and its derivative
/// `dk_dphi_p` (N/m/rad) with respect to φp: F = k·δ(TE), F_D = d·dTE/dt in contact, so
/// ∂F/∂φp = k′·δ + k·g_p, ∂F/∂φg = k·g_g and ∂F_D/∂φ̇i = d·g_i while a flank touches (all 0
/// in the backlash; at the contact switch the derivative of the side found is given).
fn spring_jacobian(
    k: f64,
    dk_dphi_p: f64,
    d: f64,
    gp: f64,
    gg: f64,
    c: Clearance,
    s: &MeshState,
) -> (MeshOutputs, MeshJacobian) {
    let o = spring_outputs(k, d, gp, gg, c, s);
    let (delta, front, back) = c.deflection(o.te);
    let mut j = MeshJacobian::default();
    if front || back {
        let df = [dk_dphi_p * delta + k * gp, k * gg];
        let dfd = [d * gp, d * gg];
        for (row, arm) in [(MeshJacobian::M_F_P, gp), (MeshJacobian::M_F_G, gg)] {
            j.d[row][MeshJacobian::PHI_P] = df[0] * arm;
            j.d[row][MeshJacobian::PHI_G] = df[1] * arm;
        }
        for (row, arm) in [(MeshJacobian::M_D_P, gp), (MeshJacobian::M_D_G, gg)] {
            j.d[row][MeshJacobian::W_P] = dfd[0] * arm;
            j.d[row][MeshJacobian::W_G] = dfd[1] * arm;
        }
    }
    (o, j)
}

/// A mesh of constant stiffness k along the line of action (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantStiffnessMesh {
    k: f64,
    d_mesh: f64,
    g_p: f64,
    g_g: f64,
    clearance: Clearance,
}

impl ConstantStiffnessMesh {
    /// Stiffness `k` (N/m, > 0), damping `d_mesh` (N·s/m, ≥ 0), base radii `g_p`, `g_g`
    /// (m, > 0), clearance behaviour `clearance`.
    pub fn new(
        k: f64,
        d_mesh: f64,
        g_p: f64,
        g_g: f64,
        clearance: Clearance,
    ) -> Result<Self, MeshError> {
        check_positive("k", k)?;
        check_positive("g_p", g_p)?;
        check_positive("g_g", g_g)?;
        if !(d_mesh.is_finite() && d_mesh >= 0.0) {
            return Err(ParamError::new("d_mesh", d_mesh, "finite and >= 0").into());
        }
        clearance.validate()?;
        Ok(Self { k, d_mesh, g_p, g_g, clearance })
    }

    /// Stiffness k, N/m.
    pub fn stiffness(&self) -> f64 {
        self.k
    }

    /// Damping d_mesh, N·s/m.
    pub fn damping(&self) -> f64 {
        self.d_mesh
    }

    /// Elastic energy stored in the mesh at transmission error `te` (m), J: ½·k·δ² with δ the
    /// spring deflection (TE on the driving flanks, TE + b on the back flanks, 0 in between).
    pub fn elastic_energy(&self, te: f64) -> f64 {
        let (delta, _, _) = self.clearance.deflection(te);
        0.5 * self.k * delta * delta
    }
}

impl MeshTorques for ConstantStiffnessMesh {
    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        check_state(state)?;
        Ok(spring_outputs(self.k, self.d_mesh, self.g_p, self.g_g, self.clearance, state))
    }

    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        check_state(state)?;
        Ok(spring_jacobian(self.k, 0.0, self.d_mesh, self.g_p, self.g_g, self.clearance, state))
    }

    fn base_radii(&self) -> (f64, f64) {
        (self.g_p, self.g_g)
    }
}

/// A mesh whose stiffness varies with the mesh period: k(φp) = k₀·(1 + a·cos(z_p·φp)), N/m,
/// with |a| < 1, any [`Clearance`] (usually a one-sided contact) and the damping of the
/// module doc. Its static transmission error under a torque M is
/// STE(φp) = M/(g_p·k(φp)).
///
/// The force F = k(φp)·TE is not the gradient of a potential (there is no ½·k′·TE² torque on
/// the pinion): the stiffness variation pumps energy in and out, which is the parametric
/// excitation of a gear mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodicStiffnessMesh {
    k0: f64,
    a: f64,
    z_p: u32,
    d_mesh: f64,
    g_p: f64,
    g_g: f64,
    clearance: Clearance,
}

impl PeriodicStiffnessMesh {
    /// Mean stiffness `k0` (N/m, > 0), relative amplitude `a` (|a| < 1), pinion tooth number
    /// `z_p` (≥ 1), damping `d_mesh` (N·s/m, ≥ 0), base radii `g_p`, `g_g` (m, > 0) and
    /// clearance behaviour `clearance`.
    pub fn new(
        k0: f64,
        a: f64,
        z_p: u32,
        d_mesh: f64,
        g_p: f64,
        g_g: f64,
        clearance: Clearance,
    ) -> Result<Self, MeshError> {
        check_positive("k0", k0)?;
        check_positive("g_p", g_p)?;
        check_positive("g_g", g_g)?;
        if !(a.is_finite() && a.abs() < 1.0) {
            return Err(ParamError::new("a", a, "|a| < 1").into());
        }
        if z_p == 0 {
            return Err(ParamError::new("z_p", 0.0, ">= 1").into());
        }
        if !(d_mesh.is_finite() && d_mesh >= 0.0) {
            return Err(ParamError::new("d_mesh", d_mesh, "finite and >= 0").into());
        }
        clearance.validate()?;
        Ok(Self { k0, a, z_p, d_mesh, g_p, g_g, clearance })
    }

    /// Stiffness k(φp) at pinion angle `phi_p` (rad), N/m.
    pub fn stiffness(&self, phi_p: f64) -> f64 {
        self.k0 * (1.0 + self.a * (self.z_p as f64 * phi_p).cos())
    }

    /// Mean stiffness k₀, N/m.
    pub fn mean_stiffness(&self) -> f64 {
        self.k0
    }

    /// Static transmission error M/(g_p·k(φp)) under driving torque `torque` (N·m) at pinion
    /// angle `phi_p` (rad), m.
    pub fn static_te(&self, phi_p: f64, torque: f64) -> f64 {
        torque / (self.g_p * self.stiffness(phi_p))
    }

    /// Mesh period in pinion angle, 2π/z_p, rad.
    pub fn angular_pitch(&self) -> f64 {
        2.0 * PI / self.z_p as f64
    }
}

impl MeshTorques for PeriodicStiffnessMesh {
    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        check_state(state)?;
        let k = self.stiffness(state.phi_p);
        Ok(spring_outputs(k, self.d_mesh, self.g_p, self.g_g, self.clearance, state))
    }

    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        check_state(state)?;
        let k = self.stiffness(state.phi_p);
        let z = self.z_p as f64;
        let dk = -self.k0 * self.a * z * (z * state.phi_p).sin();
        Ok(spring_jacobian(k, dk, self.d_mesh, self.g_p, self.g_g, self.clearance, state))
    }

    fn base_radii(&self) -> (f64, f64) {
        (self.g_p, self.g_g)
    }
}
