//! The variable tables of the FMU family: the descriptors shared by every model and the
//! parameter tables they share.
//!
//! A [`Variable`] names one FMI scalar variable: name, value reference, causality,
//! variability, type, unit, description, and how an instance reads and writes it
//! ([`Access`]). Each model ([`super::models`]) lists its variables in one static table; the
//! value-reference dispatch of `fmi2Get*`/`fmi2Set*`, the start values (read from the model's
//! default [`Settings`] and [`InputValues`], so they cannot drift from the Rust defaults), the
//! serialised FMU state, `modelDescription.xml`, the GUID, the C header of value references,
//! the HTML documentation inside the FMU and the FMU reference pages `docs/fmu/` are all
//! derived from that table.
//!
//! Inputs and outputs are generic: an input variable names a slot of the instance's
//! [`InputValues`] (and whether the model uses its time derivative), an output variable a
//! slot of its [`OutputValues`] (Real, Integer or Boolean). The instance stores, checks,
//! serialises and hands out those values without knowing what they are; each model maps its
//! slots to its physics in its own file (`fmi2/models/`). Nothing here names a model's input
//! or output quantity except the shared mesh-output table [`MESH_OUTPUTS`], whose values one
//! function of `fmi2::models` writes.
//!
//! The same physical quantity has the same name and value reference in every model: the
//! gear-pair parameters ([`GEAR_PARAMS`], 100–122 and 130, the String `modifications`), the
//! drive line's ([`DRIVE_TORQUE`], [`DRIVE_INERTIAS`], [`DRIVE_SHAFTS`], 123–129; each model
//! lists only those it uses: the mesh element none, the Pair the torque of its static start,
//! the Stage also the shafts, the Drive all), the mesh options ([`MESH_OPTIONS`], 200–206, the String `friction` 208 and
//! `table_slices` 209), the calculated parameters ([`CALCULATED`], 30–33), the mesh outputs
//! ([`MESH_OUTPUTS`], 10–21; the 3D force and moments 400–409; the root stresses 410–411;
//! the friction torques, loss, efficiency and heat 412–417)
//! and the options of the stateful models ([`UNIT_OPTIONS`], 300–).
//!
//! Naming: parameters are named by their key in the gear-pair JSON (`GearPair`), nested keys
//! joined by a dot (`material_p.youngs_modulus_pa`), the drive line's by `drive.` and their
//! key in the drive-line JSON (`DriveLine`, [`Settings::drive`]: `drive.torque_nm`), so that
//! a parameter error from the library (which names the JSON key) names the FMI variable too. The one
//! exception is the mesh damping: JSON key `d_mesh_n_s_per_m`, FMI variable `d_mesh` (tunable).
//!
//! The items of the `HelicalGearMesh` model are in [`super::models::mesh`]
//! ([`VARIABLES`](super::models::mesh::VARIABLES), [`by_name`](super::models::mesh::by_name),
//! [`by_vr`](super::models::mesh::by_vr), [`guid`](super::models::mesh::guid),
//! [`MODEL_IDENTIFIER`](super::models::mesh::MODEL_IDENTIFIER)).

use crate::dynamics::HubCoupling;
use crate::mesh::outputs::{MESH_OUTPUT_FIELDS, OutputField, OutputKind};
use crate::mesh::{ComplianceModel, Fidelity, MeshOptions};
use crate::options::OptionEnum;

use crate::params::{self as P, Bounds, DriveLine, GearPair};

/// Everything the parameters of an instance set: the gear pair, the drive line, the mesh
/// options and the options of the stateful models (the drive line and the unit options are
/// unused by `HelicalGearMesh`).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Gear pair (geometry, materials, mesh damping).
    pub pair: GearPair,
    /// Drive line (torque, inertias, shafts): the parameters `drive.*` of the stateful models.
    pub drive: DriveLine,
    /// Options of the mesh model (fidelity, slices, compliance representation …).
    pub options: MeshOptions,
    /// Start and integration options of the stateful models.
    pub unit: UnitOptions,
    /// The gear bodies' supports of `HelicalGearbox` (unused by the other models).
    pub supports: SupportOptions,
}

impl Default for Settings {
    /// The paper's Table 1 gear pair and drive line with the default [`MeshOptions`] (full
    /// fidelity) and the default [`UnitOptions`]: the start values of `HelicalGearMesh`.
    fn default() -> Self {
        Self {
            pair: GearPair::paper_table1(),
            drive: DriveLine::paper_table1(),
            options: MeshOptions::default(),
            unit: UnitOptions::default(),
            supports: SupportOptions::default(),
        }
    }
}

/// One gear body's support as the Real parameters `supports.pinion.*` / `supports.gear.*` of
/// `HelicalGearbox` give it: isotropic in the transverse plane, K = diag(k_r, k_r, k_a, k_t,
/// k_t) and C = diag(c_r, c_r, c_a, c_t, c_t) in the order (u_x, u_y, u_z, θ_x, θ_y) of the
/// pose ([`crate::mesh::pose`], [`crate::mesh::supports`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySupportOptions {
    /// The body's mass, kg.
    pub mass_kg: f64,
    /// The body's moment of inertia about a transverse axis through its centre, kg·m².
    pub j_transverse_kgm2: f64,
    /// Radial stiffness k_r (u_x, u_y), N/m.
    pub radial_n_per_m: f64,
    /// Axial stiffness k_a (u_z), N/m.
    pub axial_n_per_m: f64,
    /// Tilting stiffness k_t (θ_x, θ_y), N·m/rad.
    pub tilt_nm_per_rad: f64,
    /// Radial damping c_r, N·s/m.
    pub radial_ns_per_m: f64,
    /// Axial damping c_a, N·s/m.
    pub axial_ns_per_m: f64,
    /// Tilting damping c_t, N·m·s/rad.
    pub tilt_nms_per_rad: f64,
}

/// The supports of `HelicalGearbox`: the Real parameters of both bodies, or the `supports`
/// JSON text ([`crate::mesh::supports`]), which overrides them when not empty.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportOptions {
    /// The pinion body's support.
    pub pinion: BodySupportOptions,
    /// The gear body's support.
    pub gear: BodySupportOptions,
    /// The supports JSON; empty: the Real parameters.
    pub json: String,
}

impl Default for SupportOptions {
    /// The example soft support of the gear-bodies guide (`docs/gear-bodies/supports.json`):
    /// pinion 2 kg, 10⁻³ kg·m², k_r = 6·10⁸ N/m, k_a = 3·10⁸ N/m, k_t = 8·10⁵ N·m/rad,
    /// c = 2000 N·s/m, 1000 N·s/m, 2 N·m·s/rad; gear 5 kg, 10⁻² kg·m², 9·10⁸, 3·10⁸,
    /// 2·10⁶, 4000, 2000, 5.
    fn default() -> Self {
        Self {
            pinion: BodySupportOptions {
                mass_kg: 2.0,
                j_transverse_kgm2: 1e-3,
                radial_n_per_m: 6e8,
                axial_n_per_m: 3e8,
                tilt_nm_per_rad: 8e5,
                radial_ns_per_m: 2000.0,
                axial_ns_per_m: 1000.0,
                tilt_nms_per_rad: 2.0,
            },
            gear: BodySupportOptions {
                mass_kg: 5.0,
                j_transverse_kgm2: 1e-2,
                radial_n_per_m: 9e8,
                axial_n_per_m: 3e8,
                tilt_nm_per_rad: 2e6,
                radial_ns_per_m: 4000.0,
                axial_ns_per_m: 2000.0,
                tilt_nms_per_rad: 5.0,
            },
            json: String::new(),
        }
    }
}

/// The integrator option of the stateful models ([`crate::dynamics::integrators::Integrator`]).
pub use crate::dynamics::integrators::Integrator;

/// The allowed codes of an option in words (`0 (full) or 1 (table)`), for the Integer setters'
/// `&'static str` error: one string per option type, made once.
fn allowed<T: OptionEnum>() -> &'static str {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static CELLS: OnceLock<Mutex<HashMap<&'static str, &'static str>>> = OnceLock::new();
    let mut map = CELLS.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    map.entry(T::OPTION).or_insert_with(|| Box::leak(T::allowed().into_boxed_str()))
}

/// Start and integration options of the stateful models (`HelicalGearPair`,
/// `HelicalGearStage`, `HelicalGearDrive`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitOptions {
    /// Nominal pinion speed of the static-equilibrium start, rad/s.
    pub w_p_start: f64,
    /// Integrator inside a communication step.
    pub integrator: Integrator,
    /// RK4: sub-steps per mesh period (at the current pinion speed).
    pub rk4_steps_per_mesh_period: u32,
    /// DOPRI5: relative tolerance.
    pub rtol: f64,
    /// DOPRI5: absolute tolerance, for every component of the relative state (rad, m, rad/s, m/s).
    pub atol: f64,
    /// Start in static equilibrium at `w_p_start` (true) or from the explicit start state.
    pub start_from_equilibrium: bool,
    /// Explicit start state (φ1, φp, φg, φ2, φ̇1, φ̇p, φ̇g, φ̇2), rad and rad/s; the
    /// two-inertia models use φp, φg, φ̇p, φ̇g.
    pub start: [f64; 8],
    /// `HelicalGearPair`: stiffness and damping of the master's connections at the hubs, with
    /// which the held hub torques are corrected within a step (zero: plain hold; see
    /// [`crate::dynamics::unit`]).
    pub hub_coupling: HubCoupling,
}

impl Default for UnitOptions {
    /// 300 rad/s, RK4 with 128 steps per mesh period, DOPRI5 tolerances 1e-8 / 1e-12 (those
    /// of `helical-gear simulate`), equilibrium start; the explicit start state is at rest.
    fn default() -> Self {
        Self {
            w_p_start: 300.0,
            integrator: Integrator::Rk4,
            rk4_steps_per_mesh_period: 128,
            rtol: 1e-8,
            atol: 1e-12,
            start_from_equilibrium: true,
            start: [0.0; 8],
            hub_coupling: HubCoupling::default(),
        }
    }
}

use crate::dynamics::unit as U;
pub use crate::dynamics::unit::{MAX_ANGLE_RAD, MAX_SPEED_RAD_S, MAX_TORQUE_NM};

/// Nominal pinion speed of the static-equilibrium start `w_p_start`: within ±1e5 rad/s (the
/// units' speed limit [`MAX_SPEED_RAD_S`]).
pub const W_P_START_RAD_S: Bounds<f64> = Bounds::new(-MAX_SPEED_RAD_S, MAX_SPEED_RAD_S, "rad/s");
/// Explicit start angle (φ1, φp, φg, φ2): within ±1e15 rad ([`MAX_ANGLE_RAD`], the inputs'
/// limit; the mesh model's own range, |TE| up to 0.2·m_n, is checked when the state is set).
pub const START_ANGLE_RAD: Bounds<f64> = Bounds::new(-MAX_ANGLE_RAD, MAX_ANGLE_RAD, "rad");
/// Explicit start speed (φ̇1, φ̇p, φ̇g, φ̇2): within ±1e5 rad/s ([`MAX_SPEED_RAD_S`]).
pub const START_SPEED_RAD_S: Bounds<f64> = Bounds::new(-MAX_SPEED_RAD_S, MAX_SPEED_RAD_S, "rad/s");
/// The bounds of [`UnitOptions::start`], by index (four angles, then four speeds).
pub const START_BOUNDS: [Bounds<f64>; 8] = [
    START_ANGLE_RAD,
    START_ANGLE_RAD,
    START_ANGLE_RAD,
    START_ANGLE_RAD,
    START_SPEED_RAD_S,
    START_SPEED_RAD_S,
    START_SPEED_RAD_S,
    START_SPEED_RAD_S,
];

/// Names of [`UnitOptions::start`]'s entries as FMI parameters.
pub const START_NAMES: [&str; 8] =
    ["phi_1_0", "phi_p_0", "phi_g_0", "phi_2_0", "w_1_0", "w_p_0", "w_g_0", "w_2_0"];

impl UnitOptions {
    /// Checks every option against its [`Bounds`] ([`W_P_START_RAD_S`],
    /// [`crate::dynamics::unit::RK4_STEPS_PER_MESH_PERIOD`], [`crate::dynamics::unit::RTOL`],
    /// [`crate::dynamics::unit::ATOL`], [`START_BOUNDS`], the hub coupling's), whichever integrator and start is
    /// chosen; the error names the FMI parameter, the value and the range.
    pub fn check(&self) -> Result<(), crate::error::ParamError> {
        W_P_START_RAD_S.check("w_p_start", self.w_p_start)?;
        let n = i64::from(self.rk4_steps_per_mesh_period);
        U::RK4_STEPS_PER_MESH_PERIOD.check_int("rk4_steps_per_mesh_period", n)?;
        U::RTOL.check("rtol", self.rtol)?;
        U::ATOL.check("atol", self.atol)?;
        for ((b, name), x) in START_BOUNDS.iter().zip(START_NAMES).zip(self.start) {
            b.check(name, x)?;
        }
        match self.hub_coupling.validate() {
            Err(crate::dynamics::DynamicsError::Param(e)) => Err(e),
            _ => Ok(()),
        }
    }
}

/// The most Real inputs a model may have: the length of [`InputValues`]' arrays. Each
/// model's input variables name their slot ([`Access::Input`]); a test holds every model's
/// slots below this bound.
pub const MAX_INPUTS: usize = 24;
/// The most Real outputs (outputs and Model Exchange locals) a model may have: the length of
/// [`OutputValues::reals`].
pub const MAX_REAL_OUTPUTS: usize = 128;
/// The most Integer outputs a model may have: the length of [`OutputValues::ints`].
pub const MAX_INT_OUTPUTS: usize = 4;
/// The most Boolean outputs a model may have: the length of [`OutputValues::bools`].
pub const MAX_BOOL_OUTPUTS: usize = 8;

/// The input values of an instance, by slot: the input variable with
/// `Access::Input { slot, .. }` is `values[slot]` (SI units, as the variable states). The
/// instance owns them and knows nothing of their meaning; the model reads its own slots. Each
/// input is checked against its range when set or restored ([`Variable::check_input`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputValues {
    /// The values, by slot; slots that no variable of the model names stay 0.
    pub values: [f64; MAX_INPUTS],
    /// First time derivatives of the inputs over the next communication step
    /// (`fmi2SetRealInputDerivatives`, first-order hold), SI per second, by slot: kept only for
    /// the inputs whose variable says the model uses them (`derivative: true`), 0 unless set,
    /// reset to 0 when the input's value is set. Derivatives of the other inputs are accepted
    /// and not used.
    pub rates: [f64; MAX_INPUTS],
    /// True when an input value or derivative was set since the last communication step: the
    /// next step holds the inputs from its start (otherwise a stateful model keeps holding
    /// them from the time they were last set).
    pub fresh: bool,
}

impl Default for InputValues {
    /// Every value and derivative 0, not fresh.
    fn default() -> Self {
        Self { values: [0.0; MAX_INPUTS], rates: [0.0; MAX_INPUTS], fresh: false }
    }
}

/// The output values of an instance, by slot: the variable with `Access::RealOutput(slot)` is
/// `reals[slot]`, `Access::IntOutput(slot)` is `ints[slot]`, `Access::BoolOutput(slot)` is
/// `bools[slot]`. A model's [`super::model::Engine::outputs`] fills its own slots (the rest
/// stay 0); the instance caches them until an input, a parameter or the state changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputValues {
    /// Real outputs and Model Exchange locals (states in the model's coordinates, state
    /// derivatives), SI units.
    pub reals: [f64; MAX_REAL_OUTPUTS],
    /// Integer outputs.
    pub ints: [i32; MAX_INT_OUTPUTS],
    /// Boolean outputs.
    pub bools: [bool; MAX_BOOL_OUTPUTS],
}

impl Default for OutputValues {
    /// Every value 0 (false).
    fn default() -> Self {
        Self {
            reals: [0.0; MAX_REAL_OUTPUTS],
            ints: [0; MAX_INT_OUTPUTS],
            bools: [false; MAX_BOOL_OUTPUTS],
        }
    }
}

/// One past the largest Real output slot of `vars` (0 when it has none): the number of Real
/// slots a table uses, so that a model can place its own outputs after a shared table's
/// (e.g. after [`MESH_OUTPUTS`]).
pub const fn real_output_slots(vars: &[Variable]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < vars.len() {
        if let Access::RealOutput(slot) = vars[i].access
            && slot + 1 > n
        {
            n = slot + 1;
        }
        i += 1;
    }
    n
}

/// Quantities derived from the parameters when the model is built (calculated parameters).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Derived {
    /// Base radius of the pinion g_p, m.
    pub base_radius_p: f64,
    /// Base radius of the gear g_g, m.
    pub base_radius_g: f64,
    /// Mass moment of inertia of the pinion body J_p, kg·m².
    pub j_p: f64,
    /// Mass moment of inertia of the gear body J_g, kg·m².
    pub j_g: f64,
}

/// FMI causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the user before initialisation (`fixed`) or also between steps (`tunable`).
    Parameter,
    /// Computed from the parameters when the model is built.
    CalculatedParameter,
    /// Set by the master at every communication point or Runge–Kutta stage.
    Input,
    /// Computed from the inputs (direct feedthrough).
    Output,
    /// Internal: the Model Exchange states in relative coordinates and the state derivatives
    /// (readable, not connectable).
    Local,
}

impl Causality {
    /// The attribute value in `modelDescription.xml`.
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        }
    }
}

/// FMI variability of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    /// Constant after initialisation.
    Fixed,
    /// May be changed between communication points.
    Tunable,
    /// Changes only at communication points (Integer and Boolean outputs).
    Discrete,
    /// Real input or output.
    Continuous,
}

impl Variability {
    /// The attribute value in `modelDescription.xml`.
    pub fn as_str(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// FMI base type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    /// `fmi2Real` (f64).
    Real,
    /// `fmi2Integer` (i32).
    Integer,
    /// `fmi2Boolean` (0 or 1).
    Boolean,
    /// `fmi2String` (UTF-8, zero-terminated).
    String,
}

impl VarType {
    /// The element name in `modelDescription.xml`.
    pub fn as_str(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        }
    }
}

/// How an instance reads (and, for parameters and inputs, writes) a variable.
///
/// Integer setters return `Err(allowed)` with the allowed range in words when the value cannot
/// be represented (e.g. a negative number of teeth); all other range checks happen when the
/// model is built (`fmi2ExitInitializationMode`) against the library's [`Bounds`] (the same
/// constants as the variable's `min`/`max`) and name the parameter.
#[derive(Clone, Copy)]
pub enum Access {
    /// Real parameter stored in [`Settings`].
    RealParam(fn(&Settings) -> f64, fn(&mut Settings, f64)),
    /// Integer parameter stored in [`Settings`].
    IntParam(fn(&Settings) -> i32, fn(&mut Settings, i32) -> Result<(), &'static str>),
    /// Boolean parameter stored in [`Settings`].
    BoolParam(fn(&Settings) -> bool, fn(&mut Settings, bool)),
    /// Real input: slot `slot` of [`InputValues`]; `derivative` is true when the model uses
    /// the input's first time derivative (`fmi2SetRealInputDerivatives`, kept in
    /// [`InputValues::rates`] and carried in FMU states), false when a derivative is accepted
    /// and not used.
    Input {
        /// Index into [`InputValues::values`] (and `rates`), below [`MAX_INPUTS`].
        slot: usize,
        /// The model uses the input's first time derivative.
        derivative: bool,
    },
    /// Real output (or Model Exchange local): slot of [`OutputValues::reals`].
    RealOutput(usize),
    /// Integer output: slot of [`OutputValues::ints`].
    IntOutput(usize),
    /// Boolean output: slot of [`OutputValues::bools`].
    BoolOutput(usize),
    /// Calculated parameter of [`Derived`].
    Calculated(fn(&Derived) -> f64),
    /// String parameter stored in [`Settings`]: the getter gives the text, the setter parses
    /// it (an error names the offending key).
    StringParam(fn(&Settings) -> String, fn(&mut Settings, &str) -> Result<(), String>),
}

/// Groups of parameters, used to state which parameters an output depends on at
/// initialisation (bit set).
pub mod group {
    /// Gear geometry: teeth, module, angles, width, shifts, rack, relief, rounding, backlash,
    /// bore.
    pub const GEOMETRY: u32 = 1;
    /// Elastic constants of both materials (E, ν).
    pub const ELASTIC: u32 = 2;
    /// Densities.
    pub const DENSITY: u32 = 4;
    /// Mesh damping `d_mesh`.
    pub const DAMPING: u32 = 8;
    /// Drive-line data (listed only by the stateful models that use them).
    pub const DRIVE: u32 = 16;
    /// Model options that change the elastic solution (fidelity, slices, compliance model,
    /// neighbour coupling, table resolution).
    pub const OPTIONS: u32 = 32;
    /// The `compute_pressure` switch.
    pub const PRESSURE: u32 = 64;
    /// Start and integration options of the stateful models.
    pub const UNIT: u32 = 128;
    /// Every group.
    pub const ALL: u32 = 255;
}

/// Dependencies of an output or calculated parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Depends {
    /// Inputs it depends on (names).
    pub inputs: &'static [&'static str],
    /// True when it is linear in the inputs with coefficients that depend on `fixed`
    /// parameters only (`dependenciesKind="fixed"`); otherwise `"dependent"`.
    pub linear_fixed: bool,
    /// Parameter groups ([`group`]) it depends on at initialisation.
    pub groups: u32,
}

/// One FMI scalar variable.
#[derive(Clone, Copy)]
pub struct Variable {
    /// Name (structured naming convention).
    pub name: &'static str,
    /// Value reference (unique over all types).
    pub vr: u32,
    /// Causality.
    pub causality: Causality,
    /// Variability.
    pub variability: Variability,
    /// Description with unit and sign convention.
    pub description: &'static str,
    /// Unit (a `UnitDefinitions` entry), Real only.
    pub unit: Option<&'static str>,
    /// Default display unit, Real only.
    pub display_unit: Option<&'static str>,
    /// Physical quantity, Real only.
    pub quantity: Option<&'static str>,
    /// Smallest accepted value of a Real or Integer parameter (`min` in
    /// `modelDescription.xml`): the `min` of the library's [`Bounds`] that the parameter's
    /// check uses, so the XML, the C header and the check cannot disagree.
    pub min: Option<f64>,
    /// Largest accepted value of a Real or Integer parameter (`max`), see `min`.
    pub max: Option<f64>,
    /// Parameter group (parameters only, see [`group`]).
    pub group: u32,
    /// Dependencies (outputs and calculated parameters only).
    pub depends: Option<Depends>,
    /// How an instance reads and writes the value.
    pub access: Access,
    /// Model Exchange: the name of the continuous state this variable is the time derivative
    /// of (`derivative` attribute), `None` otherwise.
    pub derivative_of: Option<&'static str>,
}

impl Variable {
    /// The FMI base type.
    pub fn var_type(&self) -> VarType {
        match self.access {
            Access::RealParam(..)
            | Access::Input { .. }
            | Access::RealOutput(_)
            | Access::Calculated(_) => VarType::Real,
            Access::IntParam(..) | Access::IntOutput(_) => VarType::Integer,
            Access::BoolParam(..) | Access::BoolOutput(_) => VarType::Boolean,
            Access::StringParam(..) => VarType::String,
        }
    }

    /// The start value of `HelicalGearMesh` (parameters and inputs), from
    /// [`Settings::default`] and [`InputValues::default`] (every input 0).
    pub fn start(&self) -> Option<String> {
        self.start_in(&Settings::default(), &InputValues::default())
    }

    /// The start value as it appears in `modelDescription.xml` (parameters and inputs) of a
    /// model whose defaults are `s` and `i`.
    pub fn start_in(&self, s: &Settings, i: &InputValues) -> Option<String> {
        match self.access {
            Access::RealParam(get, _) => Some(format_real(get(s))),
            Access::IntParam(get, _) => Some(get(s).to_string()),
            Access::BoolParam(get, _) => Some(get(s).to_string()),
            Access::Input { slot, .. } => Some(format_real(i.values[slot])),
            Access::StringParam(get, _) => Some(get(s)),
            _ => None,
        }
    }

    /// The `initial` attribute: `exact` for parameters, `calculated` for outputs and
    /// calculated parameters, none for inputs.
    pub fn initial(&self) -> Option<&'static str> {
        match self.causality {
            Causality::Parameter => Some("exact"),
            Causality::CalculatedParameter | Causality::Output | Causality::Local => {
                Some("calculated")
            }
            Causality::Input => None,
        }
    }

    /// Checks a value `x` for this input against its stated range, by the input's unit:
    /// angles (rad) within ±[`MAX_ANGLE_RAD`], speeds (rad/s) within ±[`MAX_SPEED_RAD_S`],
    /// torques (N.m) within ±[`MAX_TORQUE_NM`], anything else finite. The error names the
    /// input, the value and the range.
    pub fn check_input(&self, x: f64) -> Result<(), String> {
        let (max, range) = match self.unit {
            Some("rad") => (MAX_ANGLE_RAD, "1e15 rad"),
            Some("rad/s") => (MAX_SPEED_RAD_S, "1e5 rad/s"),
            Some("N.m") => (MAX_TORQUE_NM, "1e9 N.m"),
            _ => (f64::INFINITY, ""),
        };
        if !x.is_finite() {
            Err(format!("input `{}` = {x} is not finite", self.name))
        } else if x.abs() <= max {
            Ok(())
        } else {
            Err(format!(
                "input `{}` = {}: allowed finite, |{}| <= {range}",
                self.name,
                crate::error::short_num(x),
                self.name
            ))
        }
    }

    /// JSON key of the gear-pair field behind a parameter (differs from the name only for
    /// `d_mesh`).
    pub fn json_key(&self) -> &'static str {
        if self.name == "d_mesh" { "d_mesh_n_s_per_m" } else { self.name }
    }
}

/// Formats a real so that it parses back to the same `f64` (shortest round-trip form).
pub fn format_real(v: f64) -> String {
    let s = format!("{v:?}");
    s.strip_suffix(".0").map(str::to_string).unwrap_or(s)
}

/// A blank variable for struct-update syntax in the tables.
pub(crate) const NONE: Variable = Variable {
    name: "",
    vr: 0,
    causality: Causality::Parameter,
    variability: Variability::Fixed,
    description: "",
    unit: None,
    display_unit: None,
    quantity: None,
    min: None,
    max: None,
    group: 0,
    depends: None,
    access: Access::RealOutput(0),
    derivative_of: None,
};

/// A Real `fixed` parameter stored in [`Settings::pair`] (`drive.<field>`: in
/// [`Settings::drive`]).
macro_rules! real_param {
    // A drive-line parameter: a field of `Settings::drive`.
    ($name:literal, $vr:expr, $group:expr, $bounds:expr, $unit:expr, $disp:expr, $q:expr,
     $desc:literal, drive . $field:ident) => {
        Variable {
            access: Access::RealParam(|s| s.drive.$field, |s, v| s.drive.$field = v),
            ..real_param!($name, $vr, $group, $bounds, $unit, $disp, $q, $desc, d_mesh_n_s_per_m)
        }
    };
    ($name:literal, $vr:expr, $group:expr, $bounds:expr, $unit:expr, $disp:expr, $q:expr,
     $desc:literal, $($field:ident).+) => {
        Variable {
            name: $name,
            vr: $vr,
            min: Some($bounds.min),
            max: Some($bounds.max),
            causality: Causality::Parameter,
            variability: Variability::Fixed,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            group: $group,
            access: Access::RealParam(|s| s.pair.$($field).+, |s, v| s.pair.$($field).+ = v),
            ..NONE
        }
    };
}

/// A mesh output variable: name, unit, description and output slot from entry `$i` of the
/// core's one table of the mesh outputs ([`MESH_OUTPUT_FIELDS`]); value reference, variability,
/// display unit, quantity and dependencies are the FMI table's own.
macro_rules! mesh_output {
    ($i:expr, $vr:expr, $var:expr, $disp:expr, $q:expr, $dep:expr) => {
        Variable {
            name: MESH_OUTPUT_FIELDS[$i].name,
            vr: $vr,
            causality: Causality::Output,
            variability: $var,
            description: MESH_OUTPUT_FIELDS[$i].description,
            unit: fmi_unit(MESH_OUTPUT_FIELDS[$i].unit),
            display_unit: $disp,
            quantity: $q,
            depends: Some($dep),
            access: mesh_output_access($i),
            ..NONE
        }
    };
}

/// The FMI unit of a core unit: none for the empty unit of counts and flags.
const fn fmi_unit(unit: &'static str) -> Option<&'static str> {
    if unit.is_empty() { None } else { Some(unit) }
}

/// The output slot of mesh output `i`: its position among the outputs of its type.
const fn mesh_output_access(i: usize) -> Access {
    let slot = OutputField::slot(i);
    match MESH_OUTPUT_FIELDS[i].kind() {
        OutputKind::Real => Access::RealOutput(slot),
        OutputKind::Integer => Access::IntOutput(slot),
        OutputKind::Boolean => Access::BoolOutput(slot),
    }
}

const ANGLES: &[&str] = &["phi_p", "phi_g"];
/// The angles and the gear bodies' poses (`crate::mesh::pose::INPUT_NAMES`, first ten): what
/// the elastic outputs depend on.
const ANGLES_AND_POSES: &[&str] = &[
    "phi_p", "phi_g", "u_p_x", "u_p_y", "u_p_z", "th_p_x", "th_p_y", "u_g_x", "u_g_y", "u_g_z",
    "th_g_x", "th_g_y",
];
/// Every input of the mesh element: what the damping (and so the 3D force) depends on.
const ALL_INPUTS: &[&str] = &[
    "phi_p", "phi_g", "w_p", "w_g", "u_p_x", "u_p_y", "u_p_z", "th_p_x", "th_p_y", "u_g_x",
    "u_g_y", "u_g_z", "th_g_x", "th_g_y", "v_p_x", "v_p_y", "v_p_z", "om_p_x", "om_p_y", "v_g_x",
    "v_g_y", "v_g_z", "om_g_x", "om_g_y",
];
const ELASTIC_DEPS: Depends = Depends {
    inputs: ANGLES_AND_POSES,
    linear_fixed: false,
    groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS,
};

/// Dependencies of the 3D force and moments (elastic and damping parts): those of the
/// damping torques.
const FORCE_DEPS: Depends = Depends {
    inputs: ALL_INPUTS,
    linear_fixed: false,
    groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::DAMPING,
};

pub(crate) fn u32_to_i32(v: u32) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

fn usize_to_i32(v: usize) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

use Variability::{Continuous, Discrete};

pub(crate) const RAD: Option<&str> = Some("rad");
pub(crate) const DEG: Option<&str> = Some("deg");
pub(crate) const M: Option<&str> = Some("m");
pub(crate) const MM: Option<&str> = Some("mm");
pub(crate) const NM: Option<&str> = Some("N.m");
pub(crate) const PA: Option<&str> = Some("Pa");
pub(crate) const ANGLE: Option<&str> = Some("Angle");
pub(crate) const LENGTH: Option<&str> = Some("Length");
pub(crate) const TORQUE: Option<&str> = Some("Torque");

/// The mesh outputs (value references 10–21, the 3D force and moments 400–409, the root
/// stresses 410–411) with their dependencies in `HelicalGearMesh`, shared by every model: one
/// entry per entry of the core's [`MESH_OUTPUT_FIELDS`], in its order (name, unit,
/// description and slot come from there). Their values sit in the first slots of
/// [`OutputValues`] (Real slots 0, 1, 2 … in table order, likewise Integer and Boolean),
/// written from a [`crate::mesh::MeshOutputs`] by `fmi2::models::write_mesh_outputs`, which
/// loops over the same table: a new mesh output is a field and an entry there, and an entry
/// here with its value reference and dependencies.
pub const MESH_OUTPUTS: [Variable; 30] = [
    mesh_output!(0, 10, Continuous, None, TORQUE, ELASTIC_DEPS), // "M_F_p"
    mesh_output!(1, 11, Continuous, None, TORQUE, ELASTIC_DEPS), // "M_F_g"
    mesh_output!(
        2,
        12,
        Continuous,
        None,
        TORQUE,
        Depends {
            inputs: ALL_INPUTS,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::DAMPING,
        }
    ), // "M_D_p"
    mesh_output!(
        3,
        13,
        Continuous,
        None,
        TORQUE,
        Depends {
            inputs: ALL_INPUTS,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::DAMPING,
        }
    ), // "M_D_g"
    mesh_output!(
        4,
        14,
        Continuous,
        Some("um"),
        LENGTH,
        Depends { inputs: ANGLES, linear_fixed: true, groups: group::GEOMETRY }
    ), // "TE"
    mesh_output!(5, 15, Continuous, None, Some("Force"), ELASTIC_DEPS), // "F_n"
    mesh_output!(6, 16, Continuous, MM, LENGTH, ELASTIC_DEPS),   // "contact_length"
    mesh_output!(
        7,
        17,
        Continuous,
        Some("MPa"),
        Some("Pressure"),
        Depends {
            inputs: ANGLES_AND_POSES,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::PRESSURE,
        }
    ), // "p_max"
    mesh_output!(8, 18, Discrete, None, None, ELASTIC_DEPS),     // "n_pairs"
    mesh_output!(9, 19, Discrete, None, None, ELASTIC_DEPS),     // "tip_contact"
    mesh_output!(10, 20, Discrete, None, None, ELASTIC_DEPS),    // "separated"
    mesh_output!(11, 21, Discrete, None, None, ELASTIC_DEPS),    // "back_contact"
    mesh_output!(12, 400, Continuous, None, Some("Force"), FORCE_DEPS), // "F_p_x"
    mesh_output!(13, 401, Continuous, None, Some("Force"), FORCE_DEPS), // "F_p_y"
    mesh_output!(14, 402, Continuous, None, Some("Force"), FORCE_DEPS), // "F_p_z"
    mesh_output!(15, 403, Continuous, None, TORQUE, FORCE_DEPS), // "M_p_x"
    mesh_output!(16, 404, Continuous, None, TORQUE, FORCE_DEPS), // "M_p_y"
    mesh_output!(17, 405, Continuous, None, Some("Force"), FORCE_DEPS), // "F_g_x"
    mesh_output!(18, 406, Continuous, None, Some("Force"), FORCE_DEPS), // "F_g_y"
    mesh_output!(19, 407, Continuous, None, Some("Force"), FORCE_DEPS), // "F_g_z"
    mesh_output!(20, 408, Continuous, None, TORQUE, FORCE_DEPS), // "M_g_x"
    mesh_output!(21, 409, Continuous, None, TORQUE, FORCE_DEPS), // "M_g_y"
    mesh_output!(22, 410, Continuous, Some("MPa"), Some("Pressure"), ELASTIC_DEPS), // "sigma_F_p"
    mesh_output!(23, 411, Continuous, Some("MPa"), Some("Pressure"), ELASTIC_DEPS), // "sigma_F_g"
    mesh_output!(24, 412, Continuous, None, TORQUE, FORCE_DEPS), // "M_R_p"
    mesh_output!(25, 413, Continuous, None, TORQUE, FORCE_DEPS), // "M_R_g"
    mesh_output!(26, 414, Continuous, None, Some("Power"), FORCE_DEPS), // "P_loss"
    mesh_output!(27, 415, Continuous, None, None, FORCE_DEPS),   // "eta_mesh"
    mesh_output!(28, 416, Continuous, None, Some("Power"), FORCE_DEPS), // "Q_p"
    mesh_output!(29, 417, Continuous, None, Some("Power"), FORCE_DEPS), // "Q_g"
];

/// Parameters calculated when the model is built (value references 30–33).
pub const CALCULATED: [Variable; 4] = [
    Variable {
        name: "base_radius_p",
        vr: 30,
        causality: Causality::CalculatedParameter,
        variability: Variability::Fixed,
        description: "Pinion base radius g_p, m (TE = phi_p*g_p + phi_g*g_g)",
        unit: M,
        display_unit: MM,
        quantity: LENGTH,
        depends: Some(Depends { inputs: &[], linear_fixed: false, groups: group::GEOMETRY }),
        access: Access::Calculated(|d| d.base_radius_p),
        ..NONE
    },
    Variable {
        name: "base_radius_g",
        vr: 31,
        causality: Causality::CalculatedParameter,
        variability: Variability::Fixed,
        description: "Gear base radius g_g, m",
        unit: M,
        display_unit: MM,
        quantity: LENGTH,
        depends: Some(Depends { inputs: &[], linear_fixed: false, groups: group::GEOMETRY }),
        access: Access::Calculated(|d| d.base_radius_g),
        ..NONE
    },
    Variable {
        name: "J_p",
        vr: 32,
        causality: Causality::CalculatedParameter,
        variability: Variability::Fixed,
        description: "Mass moment of inertia of the pinion body (teeth and web down to the \
                      bore), kg.m2: the J_p of Eq. 2",
        unit: Some("kg.m2"),
        display_unit: None,
        quantity: Some("MomentOfInertia"),
        depends: Some(Depends {
            inputs: &[],
            linear_fixed: false,
            groups: group::GEOMETRY | group::DENSITY,
        }),
        access: Access::Calculated(|d| d.j_p),
        ..NONE
    },
    Variable {
        name: "J_g",
        vr: 33,
        causality: Causality::CalculatedParameter,
        variability: Variability::Fixed,
        description: "Mass moment of inertia of the gear body, kg.m2: the J_g of Eq. 3",
        unit: Some("kg.m2"),
        display_unit: None,
        quantity: Some("MomentOfInertia"),
        depends: Some(Depends {
            inputs: &[],
            linear_fixed: false,
            groups: group::GEOMETRY | group::DENSITY,
        }),
        access: Access::Calculated(|d| d.j_g),
        ..NONE
    },
];

/// The gear-pair parameters of the mesh (value references 100–122 and 130; JSON keys of
/// `GearPair`); the drive line's (123–129) are [`DRIVE_TORQUE`], [`DRIVE_INERTIAS`] and
/// [`DRIVE_SHAFTS`], listed only by the models that use them.
pub const GEAR_PARAMS: [Variable; 24] = [
    Variable {
        name: "z_p",
        vr: 100,
        description: "Number of pinion teeth",
        min: Some(P::Z_P.min as f64),
        max: Some(P::Z_P.max as f64),
        group: group::GEOMETRY,
        access: Access::IntParam(
            |s| u32_to_i32(s.pair.z_p),
            |s, v| {
                s.pair.z_p = u32::try_from(v).map_err(|_| ">= 0")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "z_g",
        vr: 101,
        description: "Number of gear teeth",
        min: Some(P::Z_G.min as f64),
        max: Some(P::Z_G.max as f64),
        group: group::GEOMETRY,
        access: Access::IntParam(
            |s| u32_to_i32(s.pair.z_g),
            |s, v| {
                s.pair.z_g = u32::try_from(v).map_err(|_| ">= 0")?;
                Ok(())
            },
        ),
        ..NONE
    },
    real_param!(
        "normal_module_m",
        102,
        group::GEOMETRY,
        P::NORMAL_MODULE_M,
        M,
        MM,
        LENGTH,
        "Normal module m_n, m",
        normal_module_m
    ),
    real_param!(
        "pressure_angle_rad",
        103,
        group::GEOMETRY,
        P::PRESSURE_ANGLE_RAD,
        RAD,
        DEG,
        ANGLE,
        "Normal pressure angle of the basic rack alpha_n, rad",
        pressure_angle_rad
    ),
    real_param!(
        "helix_angle_rad",
        104,
        group::GEOMETRY,
        P::HELIX_ANGLE_RAD,
        RAD,
        DEG,
        ANGLE,
        "Helix angle beta at the reference cylinder, rad (pinion right hand, gear left hand)",
        helix_angle_rad
    ),
    real_param!(
        "face_width_m",
        105,
        group::GEOMETRY,
        P::FACE_WIDTH_M,
        M,
        MM,
        LENGTH,
        "Face width b of both gears, m",
        face_width_m
    ),
    real_param!(
        "profile_shift_p",
        106,
        group::GEOMETRY,
        P::PROFILE_SHIFT,
        None,
        None,
        None,
        "Profile shift coefficient x_p of the pinion",
        profile_shift_p
    ),
    real_param!(
        "profile_shift_g",
        107,
        group::GEOMETRY,
        P::PROFILE_SHIFT,
        None,
        None,
        None,
        "Profile shift coefficient x_g of the gear",
        profile_shift_g
    ),
    real_param!(
        "addendum_mn",
        108,
        group::GEOMETRY,
        P::ADDENDUM_MN,
        None,
        None,
        None,
        "Addendum of the basic rack in units of m_n",
        addendum_mn
    ),
    real_param!(
        "dedendum_mn",
        109,
        group::GEOMETRY,
        P::DEDENDUM_MN,
        None,
        None,
        None,
        "Dedendum of the basic rack in units of m_n",
        dedendum_mn
    ),
    real_param!(
        "rack_fillet_radius_mn",
        110,
        group::GEOMETRY,
        P::RACK_FILLET_RADIUS_MN,
        None,
        None,
        None,
        "Root fillet radius of the basic rack (normal section) in units of m_n",
        rack_fillet_radius_mn
    ),
    real_param!(
        "tip_relief_depth_mn",
        111,
        group::GEOMETRY,
        P::TIP_RELIEF_DEPTH_MN,
        None,
        None,
        None,
        "Tip relief depth delta of the basic rack at its tip, normal to the flank, in units of \
         m_n (0 = none)",
        tip_relief_depth_mn
    ),
    real_param!(
        "tip_relief_height_mn",
        112,
        group::GEOMETRY,
        P::TIP_RELIEF_HEIGHT_MN,
        None,
        None,
        None,
        "Height H of the relief zone below the basic-rack tip in units of m_n",
        tip_relief_height_mn
    ),
    real_param!(
        "tip_rounding_radius_mn",
        113,
        group::GEOMETRY,
        P::TIP_ROUNDING_RADIUS_MN,
        None,
        None,
        None,
        "Tip rounding radius (transverse plane) in units of m_n (0 = sharp edge)",
        tip_rounding_radius_mn
    ),
    real_param!(
        "normal_backlash_mn",
        114,
        group::GEOMETRY,
        P::NORMAL_BACKLASH_MN,
        None,
        None,
        None,
        "Normal backlash j_n in units of m_n, split equally between the gears",
        normal_backlash_mn
    ),
    real_param!(
        "bore_diameter_m",
        115,
        group::GEOMETRY,
        P::BORE_DIAMETER_M,
        M,
        MM,
        LENGTH,
        "Hub bore diameter of both gears, m (the FE models are fixed there)",
        bore_diameter_m
    ),
    real_param!(
        "material_p.youngs_modulus_pa",
        116,
        group::ELASTIC,
        P::YOUNGS_MODULUS_PA,
        PA,
        Some("GPa"),
        Some("Pressure"),
        "Young's modulus of the pinion, Pa",
        material_p.youngs_modulus_pa
    ),
    real_param!(
        "material_p.poisson_ratio",
        117,
        group::ELASTIC,
        P::POISSON_RATIO,
        None,
        None,
        None,
        "Poisson's ratio of the pinion",
        material_p.poisson_ratio
    ),
    real_param!(
        "material_p.density_kg_m3",
        118,
        group::DENSITY,
        P::DENSITY_KG_M3,
        Some("kg/m3"),
        None,
        Some("Density"),
        "Density of the pinion, kg/m3 (gives J_p)",
        material_p.density_kg_m3
    ),
    real_param!(
        "material_g.youngs_modulus_pa",
        119,
        group::ELASTIC,
        P::YOUNGS_MODULUS_PA,
        PA,
        Some("GPa"),
        Some("Pressure"),
        "Young's modulus of the gear, Pa",
        material_g.youngs_modulus_pa
    ),
    real_param!(
        "material_g.poisson_ratio",
        120,
        group::ELASTIC,
        P::POISSON_RATIO,
        None,
        None,
        None,
        "Poisson's ratio of the gear",
        material_g.poisson_ratio
    ),
    real_param!(
        "material_g.density_kg_m3",
        121,
        group::DENSITY,
        P::DENSITY_KG_M3,
        Some("kg/m3"),
        None,
        Some("Density"),
        "Density of the gear, kg/m3 (gives J_g)",
        material_g.density_kg_m3
    ),
    Variable {
        name: "d_mesh",
        vr: 122,
        variability: Variability::Tunable,
        description: "Mesh damping coefficient d_mesh of Eq. 14, N.s/m (JSON key \
                      d_mesh_n_s_per_m); tunable between communication points",
        unit: Some("N.s/m"),
        quantity: Some("TranslationalDampingConstant"),
        min: Some(P::D_MESH_N_S_PER_M.min),
        max: Some(P::D_MESH_N_S_PER_M.max),
        group: group::DAMPING,
        access: Access::RealParam(|s| s.pair.d_mesh_n_s_per_m, |s, v| s.pair.d_mesh_n_s_per_m = v),
        ..NONE
    },
    Variable {
        name: "modifications",
        vr: 130,
        description: "Flank modifications, misalignment and tooth deviations: the JSON object \
                      of the GearPair key `modifications` (lengths in m along the line of \
                      action, positive removes material; empty or {} for none)",
        group: group::GEOMETRY,
        access: Access::StringParam(modifications_json, set_modifications_json),
        ..NONE
    },
];

/// The drive line's nominal torque (value reference 123): the load of the static start of
/// every stateful model.
pub const DRIVE_TORQUE: [Variable; 1] = [real_param!(
    "drive.torque_nm",
    123,
    group::DRIVE,
    P::DRIVE_TORQUE_NM,
    NM,
    None,
    TORQUE,
    "Driving torque M on J_1 (positive sense), N.m; the load on J_2 is M*z_g/z_p (Eq. 4); \
     the nominal load of the static-equilibrium start",
    drive.torque_nm
)];

/// The drive line's outer inertias J1, J2 (value references 124–125): `HelicalGearDrive` only.
pub const DRIVE_INERTIAS: [Variable; 2] = [
    real_param!(
        "drive.j1_kgm2",
        124,
        group::DRIVE,
        P::DRIVE_INERTIA_KGM2,
        Some("kg.m2"),
        None,
        Some("MomentOfInertia"),
        "Inertia J_1 of the driving mass, kg.m2",
        drive.j1_kgm2
    ),
    real_param!(
        "drive.j2_kgm2",
        125,
        group::DRIVE,
        P::DRIVE_INERTIA_KGM2,
        Some("kg.m2"),
        None,
        Some("MomentOfInertia"),
        "Inertia J_2 of the driven mass, kg.m2",
        drive.j2_kgm2
    ),
];

/// The drive line's shafts c1, c2, d1, d2 (value references 126–129): `HelicalGearStage` and
/// `HelicalGearDrive`.
pub const DRIVE_SHAFTS: [Variable; 4] = [
    real_param!(
        "drive.c1_nm_per_rad",
        126,
        group::DRIVE,
        P::DRIVE_STIFFNESS_NM_PER_RAD,
        Some("N.m/rad"),
        None,
        Some("RotationalSpringConstant"),
        "Torsional stiffness c_1 of the pinion shaft, N.m/rad",
        drive.c1_nm_per_rad
    ),
    real_param!(
        "drive.c2_nm_per_rad",
        127,
        group::DRIVE,
        P::DRIVE_STIFFNESS_NM_PER_RAD,
        Some("N.m/rad"),
        None,
        Some("RotationalSpringConstant"),
        "Torsional stiffness c_2 of the gear shaft, N.m/rad",
        drive.c2_nm_per_rad
    ),
    real_param!(
        "drive.d1_nms_per_rad",
        128,
        group::DRIVE,
        P::DRIVE_DAMPING_NMS_PER_RAD,
        Some("N.m.s/rad"),
        None,
        Some("RotationalDampingConstant"),
        "Viscous damping d_1 of the pinion shaft, N.m.s/rad",
        drive.d1_nms_per_rad
    ),
    real_param!(
        "drive.d2_nms_per_rad",
        129,
        group::DRIVE,
        P::DRIVE_DAMPING_NMS_PER_RAD,
        Some("N.m.s/rad"),
        None,
        Some("RotationalDampingConstant"),
        "Viscous damping d_2 of the gear shaft, N.m.s/rad",
        drive.d2_nms_per_rad
    ),
];

/// The `modifications` parameter's text: the JSON of the pair's modifications (`{}` for none;
/// otherwise every key written out).
fn modifications_json(s: &Settings) -> String {
    if s.pair.modifications.is_default() {
        return "{}".into();
    }
    serde_json::to_string(&s.pair.modifications).unwrap_or_else(|_| "{}".into())
}

/// Parses the `modifications` parameter into the pair (empty text: none); the values are
/// validated against the geometry when the model is built.
fn set_modifications_json(s: &mut Settings, text: &str) -> Result<(), String> {
    s.pair.modifications = if text.trim().is_empty() {
        crate::modifications::Modifications::default()
    } else {
        crate::modifications::Modifications::from_json(text)
            .map_err(|e| format!("parameter `modifications`: {e}"))?
    };
    Ok(())
}

/// Options of the mesh model (value references 200–206).
pub const MESH_OPTIONS: [Variable; 9] = [
    Variable {
        name: "fidelity",
        vr: 200,
        description: "Evaluation fidelity: 0 = full contact search and load solve at every \
                      call, 1 = interpolation in a (mesh phase, TE) table built at \
                      initialisation (outside the table: full)",
        min: Some(0.0),
        max: Some(1.0),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| s.options.fidelity.code(),
            |s, v| {
                s.options.fidelity = Fidelity::from_code(v).map_err(|_| allowed::<Fidelity>())?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "slices",
        vr: 201,
        description: "Total number of slices over all simultaneous contact lines (the paper's \
                      200)",
        min: Some(crate::mesh::model::SLICES.min as f64),
        max: Some(crate::mesh::model::SLICES.max as f64),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| usize_to_i32(s.options.slices),
            |s, v| {
                s.options.slices = usize::try_from(v).map_err(|_| ">= 1")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "compliance_model",
        vr: 202,
        description: "Global tooth compliance: 0 = interpolated FE influence grid, 1 = fitted \
                      influence function of Eqs. 5-8",
        min: Some(0.0),
        max: Some(1.0),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| s.options.compliance.code(),
            |s, v| {
                s.options.compliance =
                    ComplianceModel::from_code(v).map_err(|_| allowed::<ComplianceModel>())?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "neighbour_coupling",
        vr: 203,
        description: "Keep the coupling between simultaneous contact lines through the gear \
                      bodies",
        group: group::OPTIONS,
        access: Access::BoolParam(
            |s| s.options.neighbour_coupling,
            |s, v| s.options.neighbour_coupling = v,
        ),
        ..NONE
    },
    Variable {
        name: "compute_pressure",
        vr: 204,
        description: "Compute the Hertz pressure p_max (false saves time; p_max is then 0)",
        group: group::PRESSURE,
        access: Access::BoolParam(|s| s.options.pressure, |s, v| s.options.pressure = v),
        ..NONE
    },
    Variable {
        name: "table_phase_points",
        vr: 205,
        description: "Table fidelity: points per mesh period along the phase",
        min: Some(crate::mesh::table::TABLE_POINTS.min as f64),
        max: Some(crate::mesh::table::TABLE_POINTS.max as f64),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| usize_to_i32(s.options.table_phase_points),
            |s, v| {
                s.options.table_phase_points = usize::try_from(v).map_err(|_| ">= 2")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "table_te_points",
        vr: 206,
        description: "Table fidelity: points along TE",
        min: Some(crate::mesh::table::TABLE_POINTS.min as f64),
        max: Some(crate::mesh::table::TABLE_POINTS.max as f64),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| usize_to_i32(s.options.table_te_points),
            |s, v| {
                s.options.table_te_points = usize::try_from(v).map_err(|_| ">= 2")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "table_slices",
        vr: 209,
        description: "Table fidelity: the most slices of the full-model samples the table is \
                      built from (it samples at min(slices, table_slices); 100 keeps the \
                      table's error and builds it three times faster than 200)",
        min: Some(crate::mesh::model::SLICES.min as f64),
        max: Some(crate::mesh::model::SLICES.max as f64),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| usize_to_i32(s.options.table_slices),
            |s, v| {
                s.options.table_slices = usize::try_from(v).map_err(|_| ">= 1")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "friction",
        vr: 208,
        description: "Mesh friction: the JSON object {\"model\": \"none\" | \"constant\" | \
                      \"iso_tr_14179_2\", \"mu\", \"oil_viscosity_pa_s\", \"roughness_ra_m\", \
                      \"lubricant_factor\", \"regularisation_speed_m_s\"} (docs/friction.md); \
                      empty or none for the paper's frictionless model",
        group: group::OPTIONS,
        access: Access::StringParam(friction_json, set_friction_json),
        ..NONE
    },
];

/// The `friction` parameter's text: `none`, or the JSON of the option.
fn friction_json(s: &Settings) -> String {
    if s.options.friction.is_on() { s.options.friction.to_json() } else { "none".into() }
}

/// Parses the `friction` parameter (empty text or `none`: no friction); the values are
/// checked, an error names the key.
fn set_friction_json(s: &mut Settings, text: &str) -> Result<(), String> {
    s.options.friction = crate::mesh::Friction::from_json(text)?;
    Ok(())
}

/// The start state parameter of state `i` (φ1, φp, φg, φ2, φ̇1, φ̇p, φ̇g, φ̇2).
macro_rules! start_param {
    ($name:literal, $vr:expr, $i:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal) => {
        Variable {
            name: $name,
            vr: $vr,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            min: Some(START_BOUNDS[$i].min),
            max: Some(START_BOUNDS[$i].max),
            group: group::UNIT,
            access: Access::RealParam(|s| s.unit.start[$i], |s, v| s.unit.start[$i] = v),
            ..NONE
        }
    };
}

/// Options of the stateful models: start and integrator.
pub const UNIT_OPTIONS: [Variable; 6] = [
    Variable {
        name: "w_p_start",
        vr: 300,
        description: "Nominal pinion speed of the static-equilibrium start, rad/s (the state \
                      starts in static equilibrium under drive.torque_nm, rolling at this speed)",
        unit: Some("rad/s"),
        display_unit: Some("rpm"),
        quantity: Some("AngularVelocity"),
        min: Some(W_P_START_RAD_S.min),
        max: Some(W_P_START_RAD_S.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.w_p_start, |s, v| s.unit.w_p_start = v),
        ..NONE
    },
    Variable {
        name: "integrator",
        vr: 301,
        description: "Integrator inside a communication step: 0 = classical RK4 on a grid of \
                      rk4_steps_per_mesh_period sub-steps per mesh period, 1 = adaptive \
                      Dormand-Prince 5(4) with rtol and atol",
        min: Some(0.0),
        max: Some(1.0),
        group: group::UNIT,
        access: Access::IntParam(
            |s| s.unit.integrator.code(),
            |s, v| {
                s.unit.integrator =
                    Integrator::from_code(v).map_err(|_| allowed::<Integrator>())?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "rk4_steps_per_mesh_period",
        vr: 302,
        description: "RK4: sub-steps per mesh period at the current pinion speed (each \
                      communication step is cut into equal sub-steps no longer than that)",
        min: Some(U::RK4_STEPS_PER_MESH_PERIOD.min as f64),
        max: Some(U::RK4_STEPS_PER_MESH_PERIOD.max as f64),
        group: group::UNIT,
        access: Access::IntParam(
            |s| u32_to_i32(s.unit.rk4_steps_per_mesh_period),
            |s, v| {
                s.unit.rk4_steps_per_mesh_period = u32::try_from(v).map_err(|_| ">= 1")?;
                Ok(())
            },
        ),
        ..NONE
    },
    Variable {
        name: "rtol",
        vr: 303,
        description: "DOPRI5: relative tolerance, applied to the state in relative \
                      coordinates (phi_p, TE, the shaft twists and their rates), so that it \
                      bounds the error of TE rather than that of the absolute angles",
        min: Some(U::RTOL.min),
        max: Some(U::RTOL.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.rtol, |s, v| s.unit.rtol = v),
        ..NONE
    },
    Variable {
        name: "atol",
        vr: 304,
        description: "DOPRI5: absolute tolerance, one number for every component of the \
                      relative state (rad, m, rad/s, m/s)",
        min: Some(U::ATOL.min),
        max: Some(U::ATOL.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.atol, |s, v| s.unit.atol = v),
        ..NONE
    },
    Variable {
        name: "start_from_equilibrium",
        vr: 305,
        description: "Start in static equilibrium at w_p_start under drive.torque_nm (the \
                      inputs are then set to the equilibrium's at fmi2ExitInitializationMode); \
                      false: start from the explicit start state *_0",
        group: group::UNIT,
        access: Access::BoolParam(
            |s| s.unit.start_from_equilibrium,
            |s, v| s.unit.start_from_equilibrium = v,
        ),
        ..NONE
    },
];

/// Explicit start state of the pinion and gear bodies (used when `start_from_equilibrium` is
/// false).
pub const START_PAIR: [Variable; 4] = [
    start_param!("phi_p_0", 311, 1, RAD, DEG, ANGLE, "Explicit start: pinion angle, rad"),
    start_param!("phi_g_0", 312, 2, RAD, DEG, ANGLE, "Explicit start: gear angle, rad"),
    start_param!(
        "w_p_0",
        315,
        5,
        Some("rad/s"),
        Some("rpm"),
        Some("AngularVelocity"),
        "Explicit start: pinion speed, rad/s"
    ),
    start_param!(
        "w_g_0",
        316,
        6,
        Some("rad/s"),
        Some("rpm"),
        Some("AngularVelocity"),
        "Explicit start: gear speed, rad/s"
    ),
];

/// Explicit start state of J1 and J2 (`HelicalGearDrive`).
pub const START_OUTER: [Variable; 4] = [
    start_param!("phi_1_0", 310, 0, RAD, DEG, ANGLE, "Explicit start: angle of J1, rad"),
    start_param!("phi_2_0", 313, 3, RAD, DEG, ANGLE, "Explicit start: angle of J2, rad"),
    start_param!(
        "w_1_0",
        314,
        4,
        Some("rad/s"),
        Some("rpm"),
        Some("AngularVelocity"),
        "Explicit start: speed of J1, rad/s"
    ),
    start_param!(
        "w_2_0",
        317,
        7,
        Some("rad/s"),
        Some("rpm"),
        Some("AngularVelocity"),
        "Explicit start: speed of J2, rad/s"
    ),
];

/// Concatenates variable tables (at compile time) into one of length `N` (which must be the
/// sum of their lengths).
pub const fn concat<const N: usize>(parts: &[&[Variable]]) -> [Variable; N] {
    let mut out = [NONE; N];
    let mut k = 0;
    let mut i = 0;
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[k] = parts[i][j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    assert!(k == N, "concat: N is not the sum of the lengths");
    out
}

/// Sum of the lengths of tables (for [`concat()`]).
pub const fn total_len(parts: &[&[Variable]]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < parts.len() {
        n += parts[i].len();
        i += 1;
    }
    n
}

/// `vars` with every `depends` replaced by `d` (outputs of the mesh seen from a stateful
/// model, where they depend on the state rather than on inputs).
pub const fn with_depends<const N: usize>(vars: [Variable; N], d: Depends) -> [Variable; N] {
    let mut out = vars;
    let mut i = 0;
    while i < N {
        out[i].depends = Some(d);
        i += 1;
    }
    out
}

/// Log categories: name and description. Messages with status error or fatal are always
/// passed to the logger; the others only when debug logging is on for their category.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusError", "Errors: invalid parameters or inputs, illegal call sequences"),
    ("logStatusWarning", "Warnings"),
    ("logStatusDiscard", "Communication steps that could not be completed (fmi2Discard)"),
    ("logStatusFatal", "Fatal errors (an internal failure; the instance is unusable)"),
    ("logModel", "Model building: geometry, compliance data, fidelity"),
    ("logCalls", "Every FMI call (function name)"),
];

/// Version of the model (the crate version), written to `modelDescription.xml`.
pub const MODEL_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Capability flags of the co-simulation interface (attributes of `<CoSimulation>`). Kept here
/// because the runtime behaviour must match them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CsCapabilities {
    /// The FMU needs no external tool.
    pub needs_execution_tool: bool,
    /// `fmi2DoStep` accepts any step size.
    pub can_handle_variable_communication_step_size: bool,
    /// First derivatives of the inputs are used over a step (`fmi2SetRealInputDerivatives`,
    /// order 1).
    pub can_interpolate_inputs: bool,
    /// Output derivatives provided up to this order.
    pub max_output_derivative_order: u32,
    /// Steps are synchronous.
    pub can_run_asynchronuously: bool,
    /// Any number of instances per process (no global state).
    pub can_be_instantiated_only_once_per_process: bool,
    /// The FMU allocates with its own allocator, not the importer's callbacks.
    pub can_not_use_memory_management_functions: bool,
    /// `fmi2GetFMUstate`/`fmi2SetFMUstate` work.
    pub can_get_and_set_fmu_state: bool,
    /// FMU states can be serialised to bytes.
    pub can_serialize_fmu_state: bool,
    /// `fmi2GetDirectionalDerivative` is provided (from the model's exact derivatives).
    pub provides_directional_derivative: bool,
    /// Model Exchange: `fmi2CompletedIntegratorStep` need not be called (nothing happens
    /// there).
    pub completed_integrator_step_not_needed: bool,
}

/// The capabilities this FMU implements (Co-Simulation and Model Exchange).
pub const CS_CAPABILITIES: CsCapabilities = CsCapabilities {
    needs_execution_tool: false,
    can_handle_variable_communication_step_size: true,
    can_interpolate_inputs: true,
    max_output_derivative_order: 0,
    can_run_asynchronuously: false,
    can_be_instantiated_only_once_per_process: false,
    can_not_use_memory_management_functions: true,
    can_get_and_set_fmu_state: true,
    can_serialize_fmu_state: true,
    provides_directional_derivative: true,
    completed_integrator_step_not_needed: true,
};

/// A unit of `UnitDefinitions`: name, SI base-unit exponents and display units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitDef {
    /// Unit name as used by the variables.
    pub name: &'static str,
    /// Exponents of the base units (`kg`, `m`, `s`, `rad` …), e.g. `[("kg", 1), ("m", 2),
    /// ("s", -2)]` for N.m.
    pub base: &'static [(&'static str, i32)],
    /// Display units: name and factor (display value = factor · value).
    pub display: &'static [(&'static str, f64)],
}

/// The units of the FMU's variables.
pub const UNITS: &[UnitDef] = &[
    UnitDef { name: "rad", base: &[("rad", 1)], display: &[("deg", 180.0 / std::f64::consts::PI)] },
    UnitDef {
        name: "rad/s",
        base: &[("s", -1), ("rad", 1)],
        display: &[("rpm", 30.0 / std::f64::consts::PI)],
    },
    UnitDef { name: "m", base: &[("m", 1)], display: &[("mm", 1e3), ("um", 1e6)] },
    UnitDef { name: "m/s", base: &[("m", 1), ("s", -1)], display: &[] },
    UnitDef { name: "m/s2", base: &[("m", 1), ("s", -2)], display: &[] },
    UnitDef { name: "rad/s2", base: &[("s", -2), ("rad", 1)], display: &[] },
    UnitDef { name: "N", base: &[("kg", 1), ("m", 1), ("s", -2)], display: &[] },
    UnitDef { name: "N.m", base: &[("kg", 1), ("m", 2), ("s", -2)], display: &[] },
    UnitDef { name: "W", base: &[("kg", 1), ("m", 2), ("s", -3)], display: &[] },
    UnitDef {
        name: "Pa",
        base: &[("kg", 1), ("m", -1), ("s", -2)],
        display: &[("MPa", 1e-6), ("GPa", 1e-9)],
    },
    UnitDef { name: "N.s/m", base: &[("kg", 1), ("s", -1)], display: &[] },
    UnitDef { name: "N/m", base: &[("kg", 1), ("s", -2)], display: &[] },
    UnitDef { name: "kg", base: &[("kg", 1)], display: &[] },
    UnitDef { name: "kg.m2", base: &[("kg", 1), ("m", 2)], display: &[] },
    UnitDef { name: "kg/m3", base: &[("kg", 1), ("m", -3)], display: &[] },
    UnitDef { name: "N.m/rad", base: &[("kg", 1), ("m", 2), ("s", -2), ("rad", -1)], display: &[] },
    UnitDef {
        name: "N.m.s/rad",
        base: &[("kg", 1), ("m", 2), ("s", -1), ("rad", -1)],
        display: &[],
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::models::mesh::{VARIABLES, guid};

    #[test]
    fn value_references_and_names_are_unique() {
        for (i, a) in VARIABLES.iter().enumerate() {
            for b in &VARIABLES[i + 1..] {
                assert_ne!(a.vr, b.vr, "{} and {}", a.name, b.name);
                assert_ne!(a.name, b.name);
            }
        }
    }

    /// Every `GearPair` field is a parameter of `HelicalGearDrive`, and every one but the
    /// drive line's of `HelicalGearMesh` (which lists none of `drive.*`).
    #[test]
    fn every_gear_pair_field_is_a_parameter() {
        let json = serde_json::to_value(GearPair::paper_table1()).unwrap();
        let mut keys = Vec::new();
        for (k, v) in json.as_object().unwrap() {
            match v.as_object() {
                Some(inner) => keys.extend(inner.keys().map(|ik| format!("{k}.{ik}"))),
                None => keys.push(k.clone()),
            }
        }
        let drive = super::super::models::unit::DRIVE.variables;
        for k in &keys {
            let is_param = |vars: &[Variable]| {
                vars.iter().any(|v| v.causality == Causality::Parameter && v.json_key() == k)
            };
            assert!(is_param(drive), "GearPair field {k} has no FMI parameter");
            assert_eq!(is_param(VARIABLES), !k.starts_with("drive."), "{k} in the mesh element");
        }
    }

    /// The list Python exposes (`params::parameter_bounds`) has every gear-pair parameter of
    /// `HelicalGearDrive` with that variable's `min`/`max`.
    #[test]
    fn parameter_bounds_are_the_variables_min_max() {
        let drive = super::super::models::unit::DRIVE.variables;
        let list = crate::params::parameter_bounds();
        for (k, lo, hi, _) in &list {
            let v = drive.iter().find(|v| v.json_key() == k).unwrap_or_else(|| panic!("{k}"));
            assert_eq!((v.min, v.max), (Some(*lo), Some(*hi)), "{k}");
        }
        let numeric = |v: &&Variable| {
            v.group
                & (group::GEOMETRY
                    | group::ELASTIC
                    | group::DENSITY
                    | group::DAMPING
                    | group::DRIVE)
                != 0
                && matches!(v.var_type(), VarType::Real | VarType::Integer)
        };
        assert_eq!(drive.iter().filter(numeric).count(), list.len());
    }

    #[test]
    fn start_values_round_trip_and_setters_hit_their_field() {
        for v in VARIABLES {
            let mut s = Settings::default();
            match v.access {
                Access::RealParam(get, set) => {
                    let start: f64 = v.start().unwrap().parse().unwrap();
                    assert_eq!(start, get(&s), "{}", v.name);
                    set(&mut s, start * 1.5 + 1.0);
                    assert_eq!(get(&s), start * 1.5 + 1.0, "{}", v.name);
                    assert_ne!(s, Settings::default(), "{}", v.name);
                }
                Access::IntParam(get, set) => {
                    let start: i32 = v.start().unwrap().parse().unwrap();
                    assert_eq!(start, get(&s));
                    let other = if v.max == Some(1.0) { 1 - start } else { start + 1 };
                    set(&mut s, other).unwrap();
                    assert_eq!(get(&s), other, "{}", v.name);
                    assert!(set(&mut s, -1).is_err(), "{}", v.name);
                }
                Access::BoolParam(get, set) => {
                    let start = get(&s);
                    set(&mut s, !start);
                    assert_eq!(get(&s), !start);
                }
                _ => {}
            }
        }
    }

    #[test]
    fn every_unit_and_display_unit_is_defined() {
        for v in super::super::models::MODELS.iter().flat_map(|m| m.variables) {
            if let Some(u) = v.unit {
                let def = UNITS.iter().find(|d| d.name == u).unwrap_or_else(|| panic!("{u}"));
                if let Some(d) = v.display_unit {
                    assert!(def.display.iter().any(|(n, _)| *n == d), "{}: {d}", v.name);
                }
            } else {
                assert!(v.display_unit.is_none(), "{}", v.name);
            }
        }
    }

    #[test]
    fn guid_is_stable_and_well_formed() {
        let g = guid();
        assert_eq!(g.len(), 38);
        assert!(g.starts_with('{') && g.ends_with('}'));
        assert_eq!(g, guid());
        assert_eq!(format_real(0.3), "0.3");
        assert_eq!(format_real(206e9), "206000000000");
        assert_eq!(format_real(1e-5), "1e-5");
        assert_eq!(format_real(0.0), "0");
    }
}
