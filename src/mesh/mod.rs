//! The mesh model: from hub angles and rates to mesh torques (paper §5, Eqs. 12–15).
//!
//! [`MeshModel`] is built once from a validated [`GearPair`] and [`MeshOptions`] and is
//! immutable (`Send + Sync`, shared by `Arc`); each call of [`MeshModel::evaluate`] takes the
//! state (φp, φg, φ̇p, φ̇g), a [`MeshWorkspace`] (scratch memory, one per caller) and a
//! [`WarmStart`] (the previous loads) and returns [`MeshOutputs`]; the result depends on
//! (model, state, warm start) only (see the `model` module docs):
//!
//! ```text
//! state ─> contact (instant lines of contact, all tooth pairs, driving and back flanks)
//!       ─> compliance matrix C_ij = α*_p + α*_g (loaded tooth and its neighbours)
//!       ─> load solver (Eq. 12, complementarity, warm start)
//!       ─> M_F (Eq. 13), M_D (Eq. 14), pressure (Eq. 15), diagnostics
//! ```
//!
//! Sign conventions are those of the crate: TE = φp·g_p + φg·g_g (Eq. 16), mesh torques enter
//! Eqs. 2–3 with a minus sign and are positive in normal drive; back-flank contact gives
//! negative torques.
//!
//! [`MeshTorques`] is the one-method interface the dynamics and the FMU use; [`statics`] finds
//! the static equilibrium for any implementation of it. Its implementations here:
//!
//! * [`FullMesh`] — an `Arc<MeshModel>` with its own workspace and warm start (`model`);
//! * [`TableMesh`] — the table over (phase, TE) built from a model, with a [`FullMesh`] for
//!   the states outside it (`table`, which depends on `model`, never the other way);
//! * [`Mesh`] — "a mesh at a fidelity", the one type the shells (FMUs, C API, Python, CLI)
//!   build from [`MeshOptions::fidelity`]: one of the two. A clone shares model and table and
//!   starts with a fresh workspace and a cold start.
//!
//! [`MeshTorques::warm_start`] and [`MeshTorques::set_warm_start`] let a caller keep the warm
//! start as part of its own state (the dynamics units and their snapshots, the mesh FMU's
//! state).
//!
//! [`MeshTorques::mesh_jacobian`] gives the outputs with their partial derivatives
//! ([`MeshJacobian`]), computed from the model: at table fidelity the exact derivative of the
//! table's interpolant ([`MeshTable::evaluate_jacobian`]), at full fidelity (and outside the
//! table) the exact sensitivity of the load solution at its active set (the `model::jacobian`
//! module documents every term; nothing is neglected). Both agree with central differences of
//! [`Mesh::evaluate`] to better than 1e-5 of the row (`tests/mesh_jacobian.rs`).
//!
//! The model holds in a stated range of the state ([`validity`]: flank overlaps up to 0.2·m_n,
//! i.e. −j_t − 0.2·m_n ≤ TE ≤ 0.2·m_n, and |φp| up to 2⁵³ pinion pitches). A state outside it,
//! or inside it but so far overloaded that its load problem is not well posed (teeth crushed
//! through), is reported as [`MeshError::OutOfRange`], which names TE, the mesh phase, the
//! range and the overlap against the module; a pinion angle beyond the exact range is
//! [`MeshError::AngleOutOfRange`]. Never "separated" for teeth that passed through each other.

pub mod bearings;
pub mod face_load;
pub mod forces;
pub mod friction;
pub mod model;
pub mod outputs;
pub mod pose;
pub mod shaft;
pub mod statics;
pub mod supports;
pub mod table;
pub mod validity;

use std::fmt;
use std::sync::Arc;

use crate::compliance::data::{CacheOptions, ComplianceData};
use crate::compliance::fe::gear_mesh::GearMeshDensity;
use crate::compliance::influence_fe::DEFAULT_DEPTH_MN;
use crate::error::ParamError;
use crate::geometry::{Member, PairGeometry};
use crate::load::LoadError;
use crate::params::GearPair;

pub use face_load::{FaceLoad, face_load, k_h_beta_crowned, k_h_beta_iso};
pub use forces::{ForceFrame, MeshWrench};
pub use friction::{Friction, FrictionModel};
pub use model::{
    FullMesh, GearCompliance, MAX_WARM_LOADS, MeshModel, MeshWorkspace, SolveStats, WarmLoad,
    WarmStart,
};
pub use pose::BodyPose;
pub use statics::{
    Equilibrium, EquilibriumSettings, StaticCurve, TipThreshold, WaterfallRow, equilibrium,
    pressure_waterfall, static_curve, static_curve_with, tip_contact_threshold,
    tip_contact_threshold_curve,
};
pub use supports::{
    Support, SupportedEquilibrium, Supports, supported_equilibrium, supported_static_curve,
};
pub use table::{
    MeshTable, POSE_STEP_MN, PoseTable, TABLE_POSE_BOUND_MN, TableMesh, TableTruncation,
};
pub use validity::ValidityRange;

/// The kinematic state of the two gears.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshState {
    /// Pinion hub angle φp, rad (absolute sense, see the crate docs).
    pub phi_p: f64,
    /// Gear hub angle φg, rad (same sense; negative and decreasing in normal running).
    pub phi_g: f64,
    /// Pinion speed φ̇p, rad/s.
    pub w_p: f64,
    /// Gear speed φ̇g, rad/s.
    pub w_g: f64,
    /// Pinion body's displacement from its nominal bearing axis (m, rad; [`pose`]); zero: the
    /// rigid-bearing model.
    pub pose_p: BodyPose,
    /// Gear body's displacement from its nominal bearing axis (m, rad; [`pose`]).
    pub pose_g: BodyPose,
    /// Rate of `pose_p` (m/s, rad/s).
    pub rate_p: BodyPose,
    /// Rate of `pose_g` (m/s, rad/s).
    pub rate_g: BodyPose,
}

impl MeshState {
    /// True when both bodies are at their nominal axes and at rest there (the rigid-bearing
    /// model of the paper).
    #[inline]
    pub fn bodies_at_rest(&self) -> bool {
        // Branch-free on the hot path: the bits of all twenty values without their signs
        // (−0 is at rest too) are zero together.
        let mut bits = 0u64;
        for b in [&self.pose_p, &self.pose_g, &self.rate_p, &self.rate_g] {
            for v in b.values() {
                bits |= v.to_bits();
            }
        }
        bits << 1 == 0
    }
}

/// Results of one mesh evaluation (the C API's `HgmOutputs`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshOutputs {
    /// Elastic mesh torque on the pinion M_F,p (Eq. 13), N·m; enters Eq. 2 with a minus sign.
    pub m_f_p: f64,
    /// Elastic mesh torque on the gear M_F,g (Eq. 13), N·m; enters Eq. 3 with a minus sign.
    pub m_f_g: f64,
    /// Damping torque on the pinion M_D,p (Eq. 14), N·m; enters Eq. 2 with a minus sign.
    pub m_d_p: f64,
    /// Damping torque on the gear M_D,g (Eq. 14), N·m; enters Eq. 3 with a minus sign.
    pub m_d_g: f64,
    /// Transmission error TE = φp·g_p + φg·g_g (Eq. 16), m; > 0 when the teeth must deform.
    pub te: f64,
    /// Total normal contact force F = Σ w_i·q_i, N (all flanks in contact).
    pub f_n: f64,
    /// Total length of the loaded contact lines, m.
    pub contact_length: f64,
    /// Largest Hertz pressure (Eq. 15), Pa (0 when pressure is not computed or no load).
    pub p_max: f64,
    /// Number of tooth pairs carrying load.
    pub n_pairs: u32,
    /// True when a loaded contact lies on the tip rounding (or tip edge) of either gear.
    pub tip_contact: bool,
    /// True when no flank carries load (loss of contact).
    pub separated: bool,
    /// True when the back flanks carry load (TE below minus the backlash; the torques are
    /// then negative).
    pub back_contact: bool,
    /// Force of all contacts on the pinion F_p = (x, y, z), N, in the housing frame of
    /// `mesh::forces` and docs/loads.md (x from the pinion axis to the gear axis, z along the
    /// pinion axis towards ζ = b₀, y = z × x); elastic part (Eq. 13) plus damping part
    /// (Eq. 14). In normal drive
    /// F_p,x < 0 (the gears are pushed apart), F_p,y < 0 and, with the right-hand pinion,
    /// F_p,z > 0.
    pub force_p: [f64; 3],
    /// Tilting moments of F_p about the pinion centre at mid-face (0, 0, b/2), (x, y), N·m;
    /// the z component is −(M_F,p + M_D,p).
    pub moment_p: [f64; 2],
    /// Force of all contacts on the gear F_g = −F_p (x, y, z), N, same frame.
    pub force_g: [f64; 3],
    /// Tilting moments of F_g about the gear centre at mid-face (a, 0, b/2), (x, y), N·m;
    /// the z component is −(M_F,g + M_D,g).
    pub moment_g: [f64; 2],
    /// Tooth-root stress of the pinion, Pa: the largest maximum principal stress at the
    /// tension-side root fillet over the loaded teeth and the face width, from the FE stress
    /// influence superposed over every loaded slice ([`crate::compliance::root_stress`];
    /// tension positive). 0 without load, and 0 for a model built without FE data (e.g. a
    /// Winkler or custom compliance).
    pub root_stress_p: f64,
    /// Tooth-root stress of the gear, Pa (as [`MeshOutputs::root_stress_p`]).
    pub root_stress_g: f64,
    /// Friction torque on the pinion M_R,p ([`friction`]), N·m: the part of
    /// [`MeshOutputs::m_f_p`] due to the friction at the flanks, signed as M_F,p (enters Eq. 2
    /// with a minus sign). 0 without friction.
    pub m_r_p: f64,
    /// Friction torque on the gear M_R,g, N·m (as [`MeshOutputs::m_r_p`], part of
    /// [`MeshOutputs::m_f_g`]). M_R,p·φ̇p + M_R,g·φ̇g = P_loss.
    pub m_r_g: f64,
    /// Mesh friction power loss P_loss, W (≥ 0; 0 without friction and at standstill).
    pub p_loss: f64,
    /// Instantaneous mesh efficiency 1 − P_loss/P_in ([`friction`]: P_in the power the
    /// driving gear puts into the mesh), 0 … 1; 1 where P_in ≤ 0 and without friction.
    pub eta_mesh: f64,
    /// Heat of the friction into the pinion's flanks Q_p, W (Blok's partition; Q_p + Q_g =
    /// P_loss).
    pub q_p: f64,
    /// Heat of the friction into the gear's flanks Q_g, W.
    pub q_g: f64,
}

impl Default for MeshOutputs {
    /// All zero and false, except the efficiency: 1 (nothing is lost).
    fn default() -> Self {
        Self {
            m_f_p: 0.0,
            m_f_g: 0.0,
            m_d_p: 0.0,
            m_d_g: 0.0,
            te: 0.0,
            f_n: 0.0,
            contact_length: 0.0,
            p_max: 0.0,
            n_pairs: 0,
            tip_contact: false,
            separated: false,
            back_contact: false,
            force_p: [0.0; 3],
            moment_p: [0.0; 2],
            force_g: [0.0; 3],
            moment_g: [0.0; 2],
            root_stress_p: 0.0,
            root_stress_g: 0.0,
            m_r_p: 0.0,
            m_r_g: 0.0,
            p_loss: 0.0,
            eta_mesh: 1.0,
            q_p: 0.0,
            q_g: 0.0,
        }
    }
}

/// How each evaluation is computed (the C API's `HgmFidelity`: the values of
/// `hgm_unit_create`'s `fidelity`, the codes of [`crate::options`] and of the FMUs' `fidelity`
/// parameter; before this encoding was shared, `TABLE` was 0 and `FULL` 1).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Fidelity {
    /// Contact search and load solve at every call.
    #[default]
    Full = 0,
    /// Interpolation in a table over (mesh phase, TE) built once from `Full`; points outside
    /// the table fall back to `Full`.
    Table = 1,
}

/// Which representation of the FE influence data gives the global compliance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ComplianceModel {
    /// Smooth interpolation of the FE influence grid.
    #[default]
    Interpolated = 0,
    /// The fitted influence function of Eqs. 5–8 (neighbour teeth interpolated).
    Fitted = 1,
}

/// Options of [`MeshModel`] (fidelity and table resolution: of [`Mesh`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshOptions {
    /// Evaluation fidelity.
    pub fidelity: Fidelity,
    /// Total number of slices over all simultaneous contact lines (the paper's 200): each tooth
    /// pair's contact line is cut into `slices / ceil(ε_α + ε_β)` equal axial slices.
    pub slices: usize,
    /// Representation of the global compliance.
    pub compliance: ComplianceModel,
    /// Keep the coupling between simultaneous contact lines through the gear bodies
    /// (influence of a load on one tooth on its neighbours).
    pub neighbour_coupling: bool,
    /// Include the local Weber–Banaschek deformation (Eq. 10) in the load problem; off leaves
    /// the global (FE) compliance alone — for studies of its share, not for production.
    pub local_contact: bool,
    /// Compute the Hertz pressure (p_max); off saves the per-slice square roots.
    pub pressure: bool,
    /// Compute the damping torques M_D (Eq. 14).
    pub damping: bool,
    /// Keep the per-slice detail ([`Mesh::slices`]) of the last evaluation (the initial
    /// setting of each workspace, [`MeshWorkspace::set_detail`]).
    pub detail: bool,
    /// Table resolution: points per mesh period along the phase (default 96; [`table`],
    /// "Default size").
    pub table_phase_points: usize,
    /// Table resolution: points along TE on each flank side (default 24; [`table`], "Default
    /// size").
    pub table_te_points: usize,
    /// Table fidelity: the most total slices (as [`MeshOptions::slices`], in
    /// [`model::SLICES`]) of the full-model samples the table is built from: the table samples
    /// the full model at min(`slices`, `table_slices`) ([`MeshOptions::table_sample_slices`]);
    /// `slices` still sets the full model outside the table. Default 100: the table's own
    /// interpolation error (2.0·10⁻⁴ of M_F,p at 96 × 24 against 800 slices) is 4.5 times the
    /// discretisation error of 100 slices (4.4·10⁻⁵), so sampling at the 200 slices of a full
    /// evaluation leaves the table's error where it is and triples the build ([`table`],
    /// "Sample slices"). Unused at full fidelity (still checked).
    pub table_slices: usize,
    /// Table fidelity: the design torque on the pinion, N·m, whose static TE sizes the
    /// table's TE range (driving flanks up to 4× the largest static TE at this torque; see
    /// [`table`]). Its magnitude, in [`table::TABLE_DESIGN_TORQUE_NM`]; default 100 N·m, the
    /// torque of Table 1. The drive-line units set it to max(|M|, 1 N·m) of their drive line's
    /// torque M. Unused at full fidelity (still checked).
    pub table_design_torque_nm: f64,
    /// A Winkler reference compliance instead of the FE data: the tooth-pair stiffness c′ per
    /// unit contact-line length, N/m² (1 N/(mm·µm) = 1e9 N/m²), pure linear springs along the
    /// line (each slice deflects under its own load only, no neighbour teeth), split equally
    /// between the gears. `None` (default): the FE compliance of [`MeshOptions::compliance`].
    /// Combine with `local_contact: false` for the pure elastic-foundation model of ISO 6336.
    pub winkler_c_prime: Option<f64>,
    /// Friction at the flanks ([`friction`]): `none` (default, the paper's model) or a law
    /// with its inputs. With friction the torques, forces and moments include the friction
    /// forces, and the loss outputs ([`MeshOutputs::p_loss`] …) are filled.
    pub friction: Friction,
}

impl Default for MeshOptions {
    fn default() -> Self {
        Self {
            fidelity: Fidelity::Full,
            slices: 200,
            compliance: ComplianceModel::Interpolated,
            neighbour_coupling: true,
            local_contact: true,
            pressure: true,
            damping: true,
            detail: false,
            table_phase_points: 96,
            table_te_points: 24,
            table_slices: 100,
            table_design_torque_nm: 100.0,
            winkler_c_prime: None,
            friction: Friction::none(),
        }
    }
}

impl MeshOptions {
    /// These options with the table sized for the drive line `drive`:
    /// [`MeshOptions::table_design_torque_nm`] = max(|M|, 1 N·m) of its torque M (the rule of
    /// the drive-line units, the C API, the CLI and Python).
    pub fn sized_for(self, drive: &crate::params::DriveLine) -> Self {
        Self { table_design_torque_nm: drive.torque_nm.abs().max(1.0), ..self }
    }

    /// The total slices the table samples the full model at: min(`slices`, `table_slices`).
    pub fn table_sample_slices(&self) -> usize {
        self.slices.min(self.table_slices)
    }
}

/// One slice of the last evaluation (kept when [`MeshOptions::detail`] is set).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SliceDetail {
    /// ζ = z/m_n of the slice centre.
    pub zeta: f64,
    /// Tooth pair (see [`crate::contact::ContactPoint::pair`]).
    pub pair: i64,
    /// True on the back flanks.
    pub back: bool,
    /// Overlap Δ0t·m_n, m.
    pub overlap_m: f64,
    /// Load intensity q, N/m.
    pub q_n_per_m: f64,
    /// Hertz pressure, Pa (0 without load or when pressure is off).
    pub pressure_pa: f64,
    /// Kind of contact, e.g. `involute/involute`, `rounding/involute` (pinion/gear).
    pub kind: &'static str,
    /// True if the contact lies on the tip rounding or tip circle of either flank.
    pub tip: bool,
    /// Sliding speed of the flanks |v_t| ([`friction`]), m/s (0 without friction).
    pub sliding_speed_m_s: f64,
    /// Magnitude of the slice's friction force, N (0 without friction).
    pub friction_n: f64,
}

/// Errors of the mesh model.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshError {
    /// A gear-pair parameter or option is invalid.
    Param(ParamError),
    /// A state component is NaN or infinite.
    NonFinite {
        /// Name of the input (`phi_p`, `phi_g`, `w_p`, `w_g`, …).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// The compliance data could not be built or loaded.
    Compliance(String),
    /// The load solver failed.
    Load(LoadError),
    /// The static equilibrium could not be found.
    Equilibrium(String),
    /// The implementation cannot give what was asked (e.g. analytic derivatives); names it.
    Unsupported(&'static str),
    /// The state lies outside the range where the model holds: TE outside the stated
    /// validity range ([`validity`]: flank overlaps beyond 0.2·m_n, teeth passed through each
    /// other), or inside it but with flanks overlapping so far (teeth crushed through) that
    /// the load problem of Eq. 12 is not well posed there (the compliance matrix of the loaded
    /// slices is not a P-matrix).
    OutOfRange {
        /// Transmission error of the state, m.
        te: f64,
        /// Mesh phase: pinion angle reduced to one pitch, rad.
        phase: f64,
        /// The validity range of TE, [TE_min, TE_max], m ([`ValidityRange`]).
        range: (f64, f64),
        /// Largest required overlap Δ·m_n of a slice, m (outside the range: TE on the
        /// driving flanks, −TE − j_t on the back flanks).
        max_overlap: f64,
        /// Normal module m_n, m (the scale of the tooth).
        module: f64,
        /// The load solver's failure when the state lies inside the range; `None` when TE
        /// lies outside it.
        cause: Option<LoadError>,
    },
    /// The pinion angle lies beyond the range where the mesh phase and the tooth-pair number
    /// are exact (|φp| ≤ 2⁵³ pinion pitches, [`validity`]).
    AngleOutOfRange {
        /// Name of the input (`phi_p`).
        name: &'static str,
        /// Its value, rad.
        value: f64,
        /// The bound on its magnitude, rad.
        bound: f64,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshError::Param(e) => write!(f, "{e}"),
            MeshError::NonFinite { name, value } => {
                write!(f, "input `{name}` = {value} is not finite")
            }
            MeshError::Compliance(m) => write!(f, "compliance: {m}"),
            MeshError::Load(e) => write!(f, "load distribution: {e}"),
            MeshError::Equilibrium(m) => write!(f, "static equilibrium: {m}"),
            MeshError::Unsupported(what) => write!(f, "not supported by this mesh model: {what}"),
            MeshError::OutOfRange { te, phase, range, max_overlap, module, cause: None } => {
                write!(
                    f,
                    "mesh state outside the model's range: TE = {te:.4e} m at mesh phase \
                     {phase:.6} rad requires a flank overlap of {max_overlap:.3e} m ({:.3}·m_n), \
                     outside the validity range {:.4e} m <= TE <= {:.4e} m (flank overlaps up \
                     to {}·m_n: beyond, the teeth would have to pass through each other)",
                    max_overlap / module,
                    range.0,
                    range.1,
                    validity::MAX_OVERLAP_MN
                )
            }
            MeshError::OutOfRange { te, phase, range, max_overlap, module, cause: Some(cause) } => {
                write!(
                    f,
                    "mesh state outside the model's range: TE = {te:.4e} m at mesh phase \
                     {phase:.6} rad requires a flank overlap of {max_overlap:.3e} m ({:.3}·m_n); \
                     TE lies inside the validity range {:.4e} m <= TE <= {:.4e} m, but the model \
                     holds for elastic approaches small against the tooth (for Table 1 the load \
                     problem was measured well posed up to overlaps of 0.19·m_n with the fitted \
                     and 0.59·m_n with the interpolated compliance; the nominal load needs about \
                     0.01·m_n), and here the load problem is not well posed ({cause})",
                    max_overlap / module,
                    range.0,
                    range.1
                )
            }
            MeshError::AngleOutOfRange { name, value, bound } => write!(
                f,
                "input `{name}` = {value:.4e} rad is beyond the exact range |{name}| <= \
                 {bound:.4e} rad (2^53 pinion pitches, where the mesh phase and the tooth-pair \
                 number are exact)"
            ),
        }
    }
}

impl std::error::Error for MeshError {}

impl From<ParamError> for MeshError {
    fn from(e: ParamError) -> Self {
        MeshError::Param(e)
    }
}

impl From<LoadError> for MeshError {
    fn from(e: LoadError) -> Self {
        MeshError::Load(e)
    }
}

/// Partial derivatives of the four mesh torques with respect to the mesh state at one state.
///
/// `d[i][j]` = ∂torque_i/∂state_j with the torques in the order (M_F,p, M_F,g, M_D,p, M_D,g)
/// ([`MeshJacobian::M_F_P`] …) and the state in the order (φp, φg, φ̇p, φ̇g)
/// ([`MeshJacobian::PHI_P`] …). Units: N·m/rad for the angle columns, N·m·s/rad for the rate
/// columns. Signs follow the torques' (positive in normal drive, entering Eqs. 2–3 with a minus
/// sign), so a loaded mesh has ∂M_F,p/∂φp = g_p·k > 0 with k the mesh stiffness along the line
/// of action. Where the contact state changes (a slice starts or stops carrying load) the
/// torques are not differentiable; the values are then the one-sided derivatives of the
/// contact set found at the state.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshJacobian {
    /// ∂torque_i/∂state_j, see the type's doc.
    pub d: [[f64; 4]; 4],
    /// The derivatives with respect to the gear bodies' poses and pose rates ([`pose`]), same
    /// rows; `None` where not provided (the table, which holds the rigid-bearing mesh; friction).
    /// Boxed: the table's Jacobian, a hot path without it, stays small to return.
    pub pose: Option<Box<PoseJacobian>>,
}

/// ∂torque_i/∂(pose component) of [`MeshJacobian`]: rows as [`MeshJacobian`]'s (M_F,p, M_F,g,
/// M_D,p, M_D,g), columns the five components of a body's pose or rate in the order of
/// [`BodyPose::values`] (u_x, u_y, u_z: N·m/m or N·m/(m/s); th_x, th_y: N·m/rad or
/// N·m/(rad/s)). The elastic torques depend on the poses; the damping torques on the rates and,
/// through the loaded extent, on the poses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PoseJacobian {
    /// ∂torque/∂pose_p.
    pub d_pose_p: [[f64; 5]; 4],
    /// ∂torque/∂pose_g.
    pub d_pose_g: [[f64; 5]; 4],
    /// ∂torque/∂rate_p.
    pub d_rate_p: [[f64; 5]; 4],
    /// ∂torque/∂rate_g.
    pub d_rate_g: [[f64; 5]; 4],
}

impl PoseJacobian {
    /// True when every entry is finite.
    pub fn is_finite(&self) -> bool {
        [self.d_pose_p, self.d_pose_g, self.d_rate_p, self.d_rate_g]
            .iter()
            .flatten()
            .flatten()
            .all(|v| v.is_finite())
    }
}

impl MeshJacobian {
    /// Row of M_F,p.
    pub const M_F_P: usize = 0;
    /// Row of M_F,g.
    pub const M_F_G: usize = 1;
    /// Row of M_D,p.
    pub const M_D_P: usize = 2;
    /// Row of M_D,g.
    pub const M_D_G: usize = 3;
    /// Column of φp.
    pub const PHI_P: usize = 0;
    /// Column of φg.
    pub const PHI_G: usize = 1;
    /// Column of φ̇p.
    pub const W_P: usize = 2;
    /// Column of φ̇g.
    pub const W_G: usize = 3;
}

/// Anything that gives the mesh torques for a state: [`Mesh`], [`FullMesh`], [`TableMesh`],
/// or a stand-in in tests.
pub trait MeshTorques {
    /// Mesh outputs for `state`.
    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError>;

    /// The mesh outputs a right-hand side needs for `state` — the [`outputs::OutputField::torques`]
    /// outputs of [`outputs::MESH_OUTPUT_FIELDS`]: M_F, M_D, TE, the loaded contact length and
    /// the friction torques and loss — bit for bit as [`Self::mesh`] gives them, and whether
    /// the rest is there too (`true`: every field as [`Self::mesh`] gives it; `false`: the
    /// other fields may be left at their defaults). The default is [`Self::mesh`], complete.
    fn torques(&mut self, state: &MeshState) -> Result<(MeshOutputs, bool), MeshError> {
        Ok((self.mesh(state)?, true))
    }

    /// [`Self::torques`] written into `out`, returning its completeness flag: every
    /// [`outputs::OutputField::torques`] output bit for bit as [`Self::mesh`] gives it, and with
    /// `true` every other field too; with `false` the other fields are unspecified (they may
    /// hold an earlier evaluation's values). After an error `out` holds nothing valid. For a
    /// caller that keeps its record in place (a right-hand side's cache): no record is moved
    /// through return values or reset. The default writes [`Self::torques`]' record.
    fn torques_into(
        &mut self,
        state: &MeshState,
        out: &mut MeshOutputs,
    ) -> Result<bool, MeshError> {
        let (o, complete) = self.torques(state)?;
        *out = o;
        Ok(complete)
    }

    /// Base radii (g_p, g_g), m, that define TE = φp·g_p + φg·g_g.
    fn base_radii(&self) -> (f64, f64);

    /// The range [TE_min, TE_max] (m) in which the implementation holds; states outside it
    /// are errors ([`MeshError::OutOfRange`] for the [`MeshModel`], [`validity`]). Searches
    /// over TE (the static equilibrium) end there. The default is unbounded.
    fn te_range(&self) -> (f64, f64) {
        (f64::NEG_INFINITY, f64::INFINITY)
    }

    /// True when the mesh has friction ([`friction`]): its torques then depend on the speeds
    /// at rest in TE, and a steady run loses power in the mesh. The default is false.
    fn has_friction(&self) -> bool {
        false
    }

    /// Mesh outputs and their partial derivatives with respect to the state at `state`,
    /// computed from the model (not by finite differences). Implementations that cannot give
    /// them return [`MeshError::Unsupported`].
    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        let _ = state;
        Err(MeshError::Unsupported("analytic mesh Jacobian"))
    }

    /// Makes the model ready to evaluate states with the gear bodies displaced, where that
    /// needs work once: the table builds its pose sensitivities ([`table::PoseTable`]), which
    /// it would otherwise build at its first posed state. The
    /// default (the full model, which takes any pose; the analytic meshes, which refuse one)
    /// does nothing.
    fn prepare_poses(&mut self) -> Result<(), MeshError> {
        Ok(())
    }

    /// Forgets whatever earlier calls left behind that can change the next result (e.g. the
    /// warm start of an iterative load solver), so that the next call gives bit for bit what a
    /// fresh clone would give. Stateless implementations keep the default, which does nothing.
    fn forget_history(&mut self) {}

    /// The cost of one evaluation in slices: the slices of a full contact search and load
    /// solve (whose work grows at least in proportion), 0 for an evaluation whose cost does not
    /// grow with an input (a table lookup, an analytic mesh; the default). The work bounds of
    /// the units count evaluations × this cost
    /// ([`crate::dynamics::limits::MAX_UNIT_SLICE_EVALUATIONS`]).
    fn evaluation_slices(&self) -> usize {
        0
    }

    /// Copies the warm start the next evaluation would start from into `out` (reusing its
    /// memory); implementations without one leave `out` empty (the default). With
    /// [`Self::set_warm_start`] a caller keeps the warm start as part of its own state.
    fn warm_start(&self, out: &mut WarmStart) {
        out.clear();
    }

    /// Makes the next evaluation start from `warm` (as if the previous one had left it);
    /// implementations without one ignore it (the default).
    fn set_warm_start(&mut self, warm: &WarmStart) {
        let _ = warm;
    }
}

/// A mesh at a fidelity: the shells' one type for "the mesh model of this pair with these
/// options" ([`MeshOptions::fidelity`]). Either the full model ([`FullMesh`]) or its table
/// ([`TableMesh`], which falls back to the full model outside its range); both hold the
/// shared immutable [`MeshModel`] (an `Arc`), their own [`MeshWorkspace`] and [`WarmStart`].
/// A clone shares model and table and starts with a fresh workspace and a cold start.
#[derive(Debug, Clone)]
pub enum Mesh {
    /// Contact search and load solve at every call.
    Full(FullMesh),
    /// Interpolation in the table, the full model outside it.
    Table(TableMesh),
}

impl Mesh {
    /// Builds the mesh of `pair` with `options`: validates the pair and the options, obtains
    /// the FE compliance of both gears ([`ComplianceData::for_pair`] with the default
    /// [`CacheOptions`]: the embedded Table 1 data when the compliance parameters match, else a
    /// disk cache under `HELICAL_GEAR_CACHE_DIR`, else a fresh FE run of a few seconds) and, for
    /// [`Fidelity::Table`], builds the table.
    pub fn new(pair: &GearPair, options: MeshOptions) -> Result<Self, MeshError> {
        Self::with_cache(pair, options, &CacheOptions::default())
    }

    /// [`Mesh::new`] with explicit cache settings (e.g. progress on stderr).
    pub fn with_cache(
        pair: &GearPair,
        options: MeshOptions,
        cache: &CacheOptions,
    ) -> Result<Self, MeshError> {
        PairGeometry::new(pair)?;
        Self::check_options(&options)?;
        Self::from_model(Arc::new(MeshModel::with_cache(pair, options, cache)?))
    }

    /// Builds the mesh from compliance data of this pair in the representation chosen by
    /// [`MeshOptions::compliance`].
    pub fn from_data(
        pair: &GearPair,
        options: MeshOptions,
        data: &ComplianceData,
    ) -> Result<Self, MeshError> {
        if data.matches(pair) {
            Self::check_options(&options)?;
        }
        Self::from_model(Arc::new(MeshModel::from_data(pair, options, data)?))
    }

    /// Builds the mesh from the given global compliances of pinion and gear
    /// ([`MeshModel::with_compliance`]), with the table of [`Fidelity::Table`].
    pub fn with_compliance(
        pair: &GearPair,
        options: MeshOptions,
        pinion: GearCompliance,
        gear: GearCompliance,
    ) -> Result<Self, MeshError> {
        Self::check_options(&options)?;
        Self::from_model(Arc::new(MeshModel::with_compliance(pair, options, pinion, gear)?))
    }

    fn check_options(options: &MeshOptions) -> Result<(), MeshError> {
        model::check_options(options)?;
        table::check_table_size(options.table_phase_points, options.table_te_points)?;
        table::check_table_work(options)?;
        table::check_design_torque(options.table_design_torque_nm)?;
        Ok(())
    }

    /// The mesh of a built model at the model's fidelity. With [`Fidelity::Table`] the table
    /// is built here (see [`table`]; tooth deviations are added on it per tooth pair) unless
    /// the modifications that repeat on every tooth add material ([`crate::modifications`]):
    /// the table starts at TE = 0, so such a mesh evaluates at full fidelity
    /// ([`Mesh::table`] is then `None`).
    pub fn from_model(model: Arc<MeshModel>) -> Result<Self, MeshError> {
        let o = model.options();
        table::check_table_size(o.table_phase_points, o.table_te_points)?;
        table::check_table_work(o)?;
        table::check_design_torque(o.table_design_torque_nm)?;
        // The table needs the part of the modifications that repeats on every tooth to remove
        // material only (no contact below TE = 0); otherwise the mesh stays at full fidelity.
        // Tooth-by-tooth deviations are added per tooth pair on a per-pair table
        // ([`table`], "Tooth deviations").
        let full_sep = model.separation().cloned();
        let deviations = full_sep.clone().filter(|s| s.has_tooth_deviations());
        let table_ok = match &deviations {
            Some(s) => s.periodic_part().min_bound() >= 0.0,
            None => full_sep.as_ref().is_none_or(|s| s.min_bound() >= 0.0),
        };
        if o.fidelity == Fidelity::Table && table_ok {
            // The table samples the model at its own slices (`table_slices`, "Sample
            // slices" in `table`); the full model outside it keeps `slices`.
            let sampled = model.with_slices(o.table_sample_slices())?;
            let base = match &deviations {
                Some(s) => Arc::new(sampled.with_separation(Some(Arc::new(s.periodic_part())))),
                None => Arc::new(sampled),
            };
            let table = MeshTable::build(&base, deviations)?;
            return Ok(Mesh::Table(TableMesh::new(Arc::new(table), FullMesh::new(model))));
        }
        Ok(Mesh::Full(FullMesh::new(model)))
    }

    /// The full model with its workspace and warm start (the table's fallback).
    pub fn full(&self) -> &FullMesh {
        match self {
            Mesh::Full(f) => f,
            Mesh::Table(t) => t.full(),
        }
    }

    /// The full model with its workspace and warm start, mutable.
    pub fn full_mut(&mut self) -> &mut FullMesh {
        match self {
            Mesh::Full(f) => f,
            Mesh::Table(t) => t.full_mut(),
        }
    }

    /// The shared immutable model.
    pub fn model(&self) -> &Arc<MeshModel> {
        self.full().model()
    }

    /// The table of [`Fidelity::Table`], if built.
    pub fn table(&self) -> Option<&MeshTable> {
        match self {
            Mesh::Full(_) => None,
            Mesh::Table(t) => Some(t.table()),
        }
    }

    /// The gear-pair parameters.
    pub fn pair(&self) -> &GearPair {
        self.model().pair()
    }

    /// The validated geometry.
    pub fn geometry(&self) -> &PairGeometry {
        self.model().geometry()
    }

    /// The options the model was built with ([`Mesh::detail`] says whether the detail is on
    /// now).
    pub fn options(&self) -> &MeshOptions {
        self.model().options()
    }

    /// Axial slices per contact line.
    pub fn slices_per_line(&self) -> usize {
        self.model().slices_per_line()
    }

    /// The range of states in which the model holds ([`validity`]).
    pub fn validity(&self) -> &ValidityRange {
        self.model().validity()
    }

    /// Checks `state` against the validity range ([`MeshModel::check_state`]).
    pub fn check_state(&self, state: &MeshState) -> Result<(), MeshError> {
        self.model().check_state(state)
    }

    /// Mesh damping d_mesh of Eq. 14, N·s/m.
    pub fn d_mesh(&self) -> f64 {
        self.model().d_mesh()
    }

    /// Sets d_mesh, N·s/m, in [0, [`crate::params::D_MESH_MAX_N_S_PER_M`]] (the model is
    /// copied, its heavy parts shared; the table does not depend on d_mesh: the damping
    /// torques are computed from its interpolated contact extent).
    pub fn set_d_mesh(&mut self, d_mesh: f64) -> Result<(), MeshError> {
        self.full_mut().set_d_mesh(d_mesh)
    }

    /// True while the per-slice detail ([`Mesh::slices`]) is kept.
    pub fn detail(&self) -> bool {
        self.full().workspace().keep_detail()
    }

    /// Turns the per-slice detail ([`Mesh::slices`]) on or off.
    pub fn set_detail(&mut self, on: bool) {
        self.full_mut().workspace_mut().set_detail(on);
    }

    /// Switches the ζ-precomputed compliance kernel on or off ([`FullMesh::use_slice_kernel`]).
    pub fn use_slice_kernel(&mut self, on: bool) -> bool {
        self.full_mut().use_slice_kernel(on)
    }

    /// Switches the coarse pre-solve of a cold start on or off ([`FullMesh::use_coarse_start`]).
    pub fn use_coarse_start(&mut self, on: bool) {
        self.full_mut().use_coarse_start(on);
    }

    /// Work counters of the full evaluations so far.
    pub fn stats(&self) -> SolveStats {
        self.full().workspace().stats()
    }

    /// Sets the work counters to zero.
    pub fn reset_stats(&mut self) {
        self.full_mut().workspace_mut().reset_stats();
    }

    /// Per-slice detail of the last full evaluation (empty unless the detail is on).
    pub fn slices(&self) -> &[SliceDetail] {
        self.full().workspace().slices()
    }

    /// Drops the warm start: the next full evaluation starts cold and gives bit for bit what
    /// a fresh mesh would give.
    pub fn forget_warm_start(&mut self) {
        self.full_mut().forget_history();
    }

    /// Evaluates the mesh at `state` with the configured fidelity.
    pub fn evaluate(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        match self {
            Mesh::Full(f) => f.evaluate(state),
            Mesh::Table(t) => t.evaluate(state),
        }
    }

    /// Evaluates the mesh at `state` by the full contact search and load solve, whatever the
    /// fidelity ([`MeshModel::evaluate`]).
    pub fn evaluate_full(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.full_mut().evaluate(state)
    }
}

impl MeshTorques for Mesh {
    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.evaluate(state)
    }

    fn evaluation_slices(&self) -> usize {
        match self {
            Mesh::Full(f) => f.evaluation_slices(),
            Mesh::Table(_) => 0,
        }
    }

    fn prepare_poses(&mut self) -> Result<(), MeshError> {
        match self {
            Mesh::Full(f) => f.prepare_poses(),
            Mesh::Table(t) => t.prepare_poses(),
        }
    }

    #[inline]
    fn torques(&mut self, state: &MeshState) -> Result<(MeshOutputs, bool), MeshError> {
        match self {
            Mesh::Full(f) => f.torques(state),
            Mesh::Table(t) => t.torques(state),
        }
    }

    fn torques_into(
        &mut self,
        state: &MeshState,
        out: &mut MeshOutputs,
    ) -> Result<bool, MeshError> {
        match self {
            Mesh::Full(f) => f.torques_into(state, out),
            Mesh::Table(t) => t.torques_into(state, out),
        }
    }

    fn base_radii(&self) -> (f64, f64) {
        self.full().base_radii()
    }

    fn te_range(&self) -> (f64, f64) {
        self.full().te_range()
    }

    fn has_friction(&self) -> bool {
        self.full().has_friction()
    }

    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        match self {
            Mesh::Full(f) => f.mesh_jacobian(state),
            Mesh::Table(t) => t.mesh_jacobian(state),
        }
    }

    fn forget_history(&mut self) {
        self.full_mut().forget_history();
    }

    fn warm_start(&self, out: &mut WarmStart) {
        self.full().warm_start(out);
    }

    fn set_warm_start(&mut self, warm: &WarmStart) {
        self.full_mut().set_warm_start(warm);
    }
}

impl MeshModel {
    /// Builds the model of `pair` with `options` (the table options are not the model's, see
    /// [`Mesh`]): validates the pair and the options and obtains the FE compliance of both
    /// gears as [`Mesh::new`] does.
    pub fn new(pair: &GearPair, options: MeshOptions) -> Result<Self, MeshError> {
        Self::with_cache(pair, options, &CacheOptions::default())
    }

    /// [`MeshModel::new`] with explicit cache settings (e.g. progress on stderr).
    pub fn with_cache(
        pair: &GearPair,
        options: MeshOptions,
        cache: &CacheOptions,
    ) -> Result<Self, MeshError> {
        PairGeometry::new(pair)?;
        model::check_options(&options)?;
        if let Some(c) = options.winkler_c_prime {
            let (p, g) = winkler_compliances(pair, c)?;
            return Self::with_compliance(pair, options, p, g);
        }
        let data = ComplianceData::for_pair(pair, cache)
            .map_err(|e| MeshError::Compliance(e.to_string()))?;
        Self::from_data(pair, options, &data)
    }

    /// Builds the model from compliance data of this pair in the representation chosen by
    /// [`MeshOptions::compliance`].
    pub fn from_data(
        pair: &GearPair,
        options: MeshOptions,
        data: &ComplianceData,
    ) -> Result<Self, MeshError> {
        if !data.matches(pair) {
            return Err(MeshError::Compliance(
                "the compliance data belong to another gear pair".into(),
            ));
        }
        let (p, g) = gear_compliances(data, options.compliance)?;
        let model = Self::with_compliance(pair, options, p, g)?;
        match data.root_stress() {
            Some(stress) => model.with_shared_root_stress(stress),
            None => Ok(model),
        }
    }
}

/// FE influence data of both gears of `pair` at mesh density `density` and the default depth
/// h ([`ComplianceData::compute`], fits included), in the representation `model`.
pub fn compute_compliance(
    pair: &GearPair,
    density: &GearMeshDensity,
    model: ComplianceModel,
) -> Result<(GearCompliance, GearCompliance), MeshError> {
    let h = DEFAULT_DEPTH_MN * pair.normal_module_m;
    let data = ComplianceData::compute(pair, density, h, false)
        .map_err(|e| MeshError::Compliance(e.to_string()))?;
    gear_compliances(&data, model)
}

/// The Winkler compliances of pinion and gear for a tooth-pair stiffness `c_prime` per unit
/// contact-line length (N/m², finite and in [1e6, 1e13]), split equally: each gear deflects by
/// q/(2c′) under the load intensity q (N/m); the depth h of the (optional) local term is the
/// FE default.
pub fn winkler_compliances(
    pair: &GearPair,
    c_prime: f64,
) -> Result<(GearCompliance, GearCompliance), MeshError> {
    if !(c_prime.is_finite() && (1e6..=1e13).contains(&c_prime)) {
        return Err(ParamError::new(
            "winkler_c_prime",
            c_prime,
            "in [1e6, 1e13] N/m² (0.001 … 10 000 N/(mm·µm))",
        )
        .into());
    }
    let w = GearCompliance::Winkler {
        compliance: 0.5 / c_prime,
        depth_h: DEFAULT_DEPTH_MN * pair.normal_module_m,
    };
    Ok((w.clone(), w))
}

/// The global compliances of pinion and gear from `data` in the representation `model`.
fn gear_compliances(
    data: &ComplianceData,
    model: ComplianceModel,
) -> Result<(GearCompliance, GearCompliance), MeshError> {
    let err = |e: crate::compliance::data::ComplianceError| MeshError::Compliance(e.to_string());
    let one = |m: Member| -> Result<GearCompliance, MeshError> {
        Ok(match model {
            ComplianceModel::Interpolated => {
                GearCompliance::Interpolated(Arc::new(data.interpolated(m).map_err(err)?))
            }
            ComplianceModel::Fitted => {
                GearCompliance::Fitted(Arc::new(data.fitted(m).map_err(err)?))
            }
        })
    };
    Ok((one(Member::Pinion)?, one(Member::Gear)?))
}
