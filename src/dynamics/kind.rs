//! What a unit holds: its kind ([`UnitKind`]: Pair, Stage or Drive), its states and their
//! order, and the shape of its linearisation ([`UnitLinearization`]: the rows and columns of
//! A, B, C, D). Kept apart from the unit itself ([`super::unit`]) so that the relative
//! coordinates ([`super::relative`]), which the unit uses, can name the kinds without
//! importing the unit.

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

    /// State names in state order (rad, rad/s).
    pub fn state_names(self) -> &'static [&'static str] {
        match self {
            UnitKind::Pair | UnitKind::Stage => &["phi_p", "phi_g", "w_p", "w_g"],
            UnitKind::Drive => &["phi_1", "phi_p", "phi_g", "phi_2", "w_1", "w_p", "w_g", "w_2"],
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

const PAIR_OUTPUTS: [&str; 11] =
    ["phi_p", "w_p", "a_p", "phi_g", "w_g", "a_g", "M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"];
const STAGE_OUTPUTS: [&str; 13] = [
    "phi_p", "w_p", "a_p", "phi_g", "w_g", "a_g", "tau_1", "tau_2", "M_F_p", "M_F_g", "M_D_p",
    "M_D_g", "TE",
];
const DRIVE_OUTPUTS: [&str; 17] = [
    "phi_1", "phi_p", "phi_g", "phi_2", "w_1", "w_p", "w_g", "w_2", "a_p", "a_g", "tau_1", "tau_2",
    "M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE",
];

impl UnitLinearization {
    /// Input names in column order of B and D, per kind: Pair `tau_p`, `tau_g`; Stage
    /// `phi_1`, `w_1`, `phi_2`, `w_2`; Drive `M`.
    pub fn inputs(kind: UnitKind) -> &'static [&'static str] {
        match kind {
            UnitKind::Pair => &["tau_p", "tau_g"],
            UnitKind::Stage => &["phi_1", "w_1", "phi_2", "w_2"],
            UnitKind::Drive => &["M"],
        }
    }

    /// Output names in row order of C and D (FMU output names): Pair `phi_p`, `w_p`, `a_p`,
    /// `phi_g`, `w_g`, `a_g`, `M_F_p`, `M_F_g`, `M_D_p`, `M_D_g`, `TE`; Stage the same with
    /// `tau_1`, `tau_2` after `a_g`; Drive the eight states, `a_p`, `a_g`, `tau_1`, `tau_2` and
    /// the mesh torques and `TE`.
    pub fn outputs(kind: UnitKind) -> &'static [&'static str] {
        match kind {
            UnitKind::Pair => &PAIR_OUTPUTS,
            UnitKind::Stage => &STAGE_OUTPUTS,
            UnitKind::Drive => &DRIVE_OUTPUTS,
        }
    }
}
