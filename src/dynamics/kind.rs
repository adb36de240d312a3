//! What a unit holds: its kind ([`UnitKind`]: Pair, Stage or Drive), its states and their
//! order, the quantities it computes ([`UnitQuantity`]) and the shape of its linearisation
//! ([`UnitLinearization`]: the rows and columns of A, B, C, D, named by quantity). Kept apart
//! from the unit itself ([`super::unit`]) so that the relative coordinates
//! ([`super::relative`]), which the unit uses, can name the kinds without importing the unit.
//!
//! Quantities are typed, not named: the physics knows no interface's variable names. Each
//! interface holds its own map from [`UnitQuantity`] to its names (the FMUs: `fmi2::models`);
//! the [`Display`](std::fmt::Display) of a quantity, used in error messages, is the name of the
//! Rust field that holds it ([`super::unit::UnitInputs`], [`super::unit::UnitOutputs`],
//! [`crate::mesh::MeshOutputs`]) or, for the relative coordinates, of the coordinate in
//! [`super::relative`].

use super::model::{N_STATES, PHI_G, PHI_P, W_G, W_P};

/// Which part of the drive line a unit holds (the C API's `HgmUnitKind`: the values of
/// `hgm_unit_create`'s `kind`, the codes of [`crate::options`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum UnitKind {
    /// J_p, J_g and the mesh. States (φp, φg, φ̇p, φ̇g). Inputs tau_p, tau_g.
    Pair = 0,
    /// Pair plus the shafts c1/d1, c2/d2. States (φp, φg, φ̇p, φ̇g). Inputs phi_1, w_1, phi_2,
    /// w_2.
    Stage = 1,
    /// The whole 4-DOF model of Eqs. 1–4. States in the order of dynamics::model (8). Input M.
    Drive = 2,
}

impl UnitKind {
    /// Number of states: 4 for Pair and Stage, 8 for Drive.
    pub fn n_states(self) -> usize {
        match self {
            UnitKind::Pair | UnitKind::Stage => 4,
            UnitKind::Drive => N_STATES,
        }
    }

    /// The states in state order (angles rad, then rates rad/s): Pair and Stage (φp, φg,
    /// φ̇p, φ̇g), Drive (φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂).
    pub fn states(self) -> &'static [UnitQuantity] {
        use UnitQuantity::*;
        match self {
            UnitKind::Pair | UnitKind::Stage => &[PhiP, PhiG, WP, WG],
            UnitKind::Drive => &[Phi1, PhiP, PhiG, Phi2, W1, WP, WG, W2],
        }
    }

    /// Indices of (φp, φg, φ̇p, φ̇g) in the state vector.
    pub(crate) fn hub_indices(self) -> [usize; 4] {
        match self {
            UnitKind::Pair | UnitKind::Stage => [0, 1, 2, 3],
            UnitKind::Drive => [PHI_P, PHI_G, W_P, W_G],
        }
    }
}

/// Dense linearisation (row-major matrices) at one (t, x, u):
/// ẋ ≈ A·δx + B·δu, out ≈ C·δx + D·δu.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitLinearization {
    /// Number of states (columns of A and C).
    pub n_x: usize,
    /// Number of inputs (columns of B and D), in the order of [`Self::inputs`].
    pub n_u: usize,
    /// Number of outputs (rows of C and D), in the order of [`Self::outputs`].
    pub n_y: usize,
    /// A = ∂ẋ/∂x, n_x × n_x, row-major (units: those of ẋ over those of x).
    pub a: Vec<f64>,
    /// B = ∂ẋ/∂u, n_x × n_u.
    pub b: Vec<f64>,
    /// C = ∂out/∂x, n_y × n_x.
    pub c: Vec<f64>,
    /// D = ∂out/∂u, n_y × n_u.
    pub d: Vec<f64>,
}

const PAIR_OUTPUTS: [UnitQuantity; 11] = {
    use UnitQuantity::*;
    [PhiP, WP, AP, PhiG, WG, AG, MFP, MFG, MDP, MDG, Te]
};
const STAGE_OUTPUTS: [UnitQuantity; 13] = {
    use UnitQuantity::*;
    [PhiP, WP, AP, PhiG, WG, AG, Tau1, Tau2, MFP, MFG, MDP, MDG, Te]
};
const DRIVE_OUTPUTS: [UnitQuantity; 17] = {
    use UnitQuantity::*;
    [Phi1, PhiP, PhiG, Phi2, W1, WP, WG, W2, AP, AG, Tau1, Tau2, MFP, MFG, MDP, MDG, Te]
};

impl UnitLinearization {
    /// The inputs in column order of B and D, per kind: Pair (τp, τg); Stage (φ₁, φ̇₁, φ₂,
    /// φ̇₂), the motion of the shafts' far ends; Drive the driving torque M.
    pub fn inputs(kind: UnitKind) -> &'static [UnitQuantity] {
        use UnitQuantity::*;
        match kind {
            UnitKind::Pair => &[TauP, TauG],
            UnitKind::Stage => &[Phi1, W1, Phi2, W2],
            UnitKind::Drive => &[DrivingTorque],
        }
    }

    /// The outputs in row order of C and D: Pair φp, φ̇p, φ̈p, φg, φ̇g, φ̈g, M_F,p, M_F,g,
    /// M_D,p, M_D,g, TE; Stage the same with τ₁, τ₂ after φ̈g; Drive the eight states, φ̈p,
    /// φ̈g, τ₁, τ₂, the mesh torques and TE.
    pub fn outputs(kind: UnitKind) -> &'static [UnitQuantity] {
        match kind {
            UnitKind::Pair => &PAIR_OUTPUTS,
            UnitKind::Stage => &STAGE_OUTPUTS,
            UnitKind::Drive => &DRIVE_OUTPUTS,
        }
    }
}

/// A quantity of a unit: a state (absolute or relative coordinate), an input or an output.
/// Angles and rates in the crate's one rotational sense (the pinion drives turning in the
/// positive sense, the gear then turns negatively); torques on a body positive in that sense.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnitQuantity {
    /// φp: pinion hub angle, rad.
    PhiP,
    /// φ̇p: pinion hub rate, rad/s.
    WP,
    /// φ̈p: pinion hub acceleration, rad/s².
    AP,
    /// φg: gear hub angle, rad (negative in normal running).
    PhiG,
    /// φ̇g: gear hub rate, rad/s (negative in normal running).
    WG,
    /// φ̈g: gear hub acceleration, rad/s².
    AG,
    /// φ₁: angle of J₁ (Drive) or of the pinion shaft's far end (Stage input), rad.
    Phi1,
    /// φ̇₁: rate of J₁ (Drive) or of the pinion shaft's far end (Stage input), rad/s.
    W1,
    /// φ₂: angle of J₂ (Drive) or of the gear shaft's far end (Stage input), rad.
    Phi2,
    /// φ̇₂: rate of J₂ (Drive) or of the gear shaft's far end (Stage input), rad/s.
    W2,
    /// τ₁: torque the pinion shaft exerts on J₁, N·m (J₁·φ̈₁ = M + τ₁; steady running
    /// τ₁ = −M).
    Tau1,
    /// τ₂: torque the gear shaft exerts on J₂, N·m (J₂·φ̈₂ = M·z_g/z_p + τ₂).
    Tau2,
    /// τp: torque the pinion shaft exerts on the pinion hub, N·m (the Pair's input; steady
    /// running τp = M).
    TauP,
    /// τg: torque the gear shaft exerts on the gear hub, N·m (the Pair's input; steady
    /// running τg = M·z_g/z_p).
    TauG,
    /// M_F,p: elastic mesh torque on the pinion (Eq. 13), N·m; positive in normal drive,
    /// enters J_p·φ̈p with a minus sign.
    MFP,
    /// M_F,g: elastic mesh torque on the gear (Eq. 13), N·m; positive in normal drive, enters
    /// J_g·φ̈g with a minus sign.
    MFG,
    /// M_D,p: mesh damping torque on the pinion (Eq. 14), N·m; enters J_p·φ̈p with a minus
    /// sign.
    MDP,
    /// M_D,g: mesh damping torque on the gear (Eq. 14), N·m; enters J_g·φ̈g with a minus sign.
    MDG,
    /// TE = g_p·φp + g_g·φg (Eq. 16): transmission error, m; positive in normal drive.
    Te,
    /// F_n: total normal contact force over all flanks in contact, N (≥ 0).
    FN,
    /// θ₁ = φ₁ − φp: twist of the pinion shaft, rad (positive when the drive end leads;
    /// relative coordinate, Drive).
    Theta1,
    /// θ₂ = φg − φ₂: twist of the gear shaft, rad (positive when the gear leads its load end;
    /// relative coordinate, Drive).
    Theta2,
    /// θ̇₁ = φ̇₁ − φ̇p: rate of the pinion shaft's twist, rad/s (relative coordinate, Drive).
    WTheta1,
    /// θ̇₂ = φ̇g − φ̇₂: rate of the gear shaft's twist, rad/s (relative coordinate, Drive).
    WTheta2,
    /// v_TE = g_p·φ̇p + g_g·φ̇g: rate of the transmission error, m/s (relative coordinate).
    VTe,
    /// M: driving torque on J₁, N·m (the Drive's input; the load on J₂ is M·z_g/z_p).
    DrivingTorque,
}

impl UnitQuantity {
    /// The name of the Rust field that holds the quantity (or of the relative coordinate):
    /// the name error messages use.
    pub fn field_name(self) -> &'static str {
        use UnitQuantity::*;
        match self {
            PhiP => "phi_p",
            WP => "w_p",
            AP => "a_p",
            PhiG => "phi_g",
            WG => "w_g",
            AG => "a_g",
            Phi1 => "phi_1",
            W1 => "w_1",
            Phi2 => "phi_2",
            W2 => "w_2",
            Tau1 => "tau_1",
            Tau2 => "tau_2",
            TauP => "tau_p",
            TauG => "tau_g",
            MFP => "m_f_p",
            MFG => "m_f_g",
            MDP => "m_d_p",
            MDG => "m_d_g",
            Te => "te",
            FN => "f_n",
            Theta1 => "theta_1",
            Theta2 => "theta_2",
            WTheta1 => "w_theta_1",
            WTheta2 => "w_theta_2",
            VTe => "v_te",
            DrivingTorque => "torque",
        }
    }

    /// True for an angle (rad): φp, φg, φ₁, φ₂, θ₁, θ₂.
    pub fn is_angle(self) -> bool {
        use UnitQuantity::*;
        matches!(self, PhiP | PhiG | Phi1 | Phi2 | Theta1 | Theta2)
    }
}

impl std::fmt::Display for UnitQuantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.field_name())
    }
}
