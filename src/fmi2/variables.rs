//! The one variable table of the FMU.
//!
//! [`VARIABLES`] lists every FMI variable once: name, value reference, causality, variability,
//! type, unit, description, and how an instance reads and writes it. Everything else is derived
//! from it: the value-reference dispatch of `fmi2Get*`/`fmi2Set*`, the start values (read from
//! [`Settings::default`] and [`MeshState::default`], so they cannot drift from the Rust defaults),
//! the serialised FMU state, `modelDescription.xml`, the GUID ([`guid`]), the HTML documentation
//! inside the FMU and the variable table of the README.
//!
//! Naming: parameters are named by their key in the gear-pair JSON (`GearPair`), nested keys
//! joined by a dot (`material_p.youngs_modulus_pa`, `drive.torque_nm`), so that a parameter
//! error from the library (which names the JSON key) names the FMI variable too. The one
//! exception is the mesh damping: JSON key `d_mesh_n_s_per_m`, FMI variable `d_mesh` (tunable).

use std::sync::OnceLock;

use crate::mesh::{ComplianceModel, Fidelity, MeshOptions, MeshOutputs, MeshState};
use crate::params::GearPair;

/// Everything the parameters of an instance set: the gear pair and the model options.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Gear pair (geometry, materials, mesh damping, drive line).
    pub pair: GearPair,
    /// Options of the mesh model (fidelity, slices, compliance representation …).
    pub options: MeshOptions,
}

impl Default for Settings {
    /// The paper's Table 1 gear pair with the default [`MeshOptions`].
    fn default() -> Self {
        Self { pair: GearPair::paper_table1(), options: MeshOptions::default() }
    }
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
}

impl Causality {
    /// The attribute value in `modelDescription.xml`.
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
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
}

impl VarType {
    /// The element name in `modelDescription.xml`.
    pub fn as_str(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        }
    }
}

/// How an instance reads (and, for parameters and inputs, writes) a variable.
///
/// Integer setters return `Err(allowed)` with the allowed range in words when the value cannot
/// be represented (e.g. a negative number of teeth); all other range checks happen when the
/// model is built (`fmi2ExitInitializationMode`) and name the parameter.
#[derive(Clone, Copy)]
pub enum Access {
    /// Real parameter stored in [`Settings`].
    RealParam(fn(&Settings) -> f64, fn(&mut Settings, f64)),
    /// Integer parameter stored in [`Settings`].
    IntParam(fn(&Settings) -> i32, fn(&mut Settings, i32) -> Result<(), &'static str>),
    /// Boolean parameter stored in [`Settings`].
    BoolParam(fn(&Settings) -> bool, fn(&mut Settings, bool)),
    /// Real input stored in [`MeshState`].
    Input(fn(&MeshState) -> f64, fn(&mut MeshState, f64)),
    /// Real output of [`MeshOutputs`].
    RealOutput(fn(&MeshOutputs) -> f64),
    /// Integer output of [`MeshOutputs`].
    IntOutput(fn(&MeshOutputs) -> i32),
    /// Boolean output of [`MeshOutputs`].
    BoolOutput(fn(&MeshOutputs) -> bool),
    /// Calculated parameter of [`Derived`].
    Calculated(fn(&Derived) -> f64),
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
    /// Drive-line data (not used by the mesh element; carried for the master).
    pub const DRIVE: u32 = 16;
    /// Model options that change the elastic solution (fidelity, slices, compliance model,
    /// neighbour coupling, table resolution).
    pub const OPTIONS: u32 = 32;
    /// The `compute_pressure` switch.
    pub const PRESSURE: u32 = 64;
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
    /// Smallest allowed value (Integer options).
    pub min: Option<i32>,
    /// Largest allowed value (Integer options).
    pub max: Option<i32>,
    /// Parameter group (parameters only, see [`group`]).
    pub group: u32,
    /// Dependencies (outputs and calculated parameters only).
    pub depends: Option<Depends>,
    /// How an instance reads and writes the value.
    pub access: Access,
}

impl Variable {
    /// The FMI base type.
    pub fn var_type(&self) -> VarType {
        match self.access {
            Access::RealParam(..)
            | Access::Input(..)
            | Access::RealOutput(_)
            | Access::Calculated(_) => VarType::Real,
            Access::IntParam(..) | Access::IntOutput(_) => VarType::Integer,
            Access::BoolParam(..) | Access::BoolOutput(_) => VarType::Boolean,
        }
    }

    /// The start value as it appears in `modelDescription.xml` (parameters and inputs), from
    /// [`Settings::default`] and [`MeshState::default`].
    pub fn start(&self) -> Option<String> {
        let s = Settings::default();
        let i = MeshState::default();
        match self.access {
            Access::RealParam(get, _) => Some(format_real(get(&s))),
            Access::IntParam(get, _) => Some(get(&s).to_string()),
            Access::BoolParam(get, _) => Some(get(&s).to_string()),
            Access::Input(get, _) => Some(format_real(get(&i))),
            _ => None,
        }
    }

    /// The `initial` attribute: `exact` for parameters, `calculated` for outputs and
    /// calculated parameters, none for inputs.
    pub fn initial(&self) -> Option<&'static str> {
        match self.causality {
            Causality::Parameter => Some("exact"),
            Causality::CalculatedParameter | Causality::Output => Some("calculated"),
            Causality::Input => None,
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

const NONE: Variable = Variable {
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
    access: Access::RealOutput(|_| 0.0),
};

macro_rules! real_param {
    ($name:literal, $vr:expr, $group:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal,
     $($field:ident).+) => {
        Variable {
            name: $name,
            vr: $vr,
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

macro_rules! output {
    ($name:literal, $vr:expr, $var:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal,
     $dep:expr, $access:expr) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Output,
            variability: $var,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            depends: Some($dep),
            access: $access,
            ..NONE
        }
    };
}

const ANGLES: &[&str] = &["phi_p", "phi_g"];
const ALL_INPUTS: &[&str] = &["phi_p", "phi_g", "w_p", "w_g"];
const ELASTIC_DEPS: Depends = Depends {
    inputs: ANGLES,
    linear_fixed: false,
    groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS,
};

fn u32_to_i32(v: u32) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

fn usize_to_i32(v: usize) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

use Variability::{Continuous, Discrete};

const RAD: Option<&str> = Some("rad");
const DEG: Option<&str> = Some("deg");
const M: Option<&str> = Some("m");
const MM: Option<&str> = Some("mm");
const NM: Option<&str> = Some("N.m");
const PA: Option<&str> = Some("Pa");
const ANGLE: Option<&str> = Some("Angle");
const LENGTH: Option<&str> = Some("Length");
const TORQUE: Option<&str> = Some("Torque");

/// Every variable of the FMU, in `modelDescription.xml` order (the ScalarVariable index is the
/// position in this table plus one).
pub static VARIABLES: &[Variable] = &[
    // ---- inputs
    Variable {
        name: "phi_p",
        vr: 0,
        causality: Causality::Input,
        variability: Continuous,
        description: "Pinion hub angle, rad; positive counter-clockwise seen from the zeta = 0 \
                      face (the pinion drives in the positive sense)",
        unit: RAD,
        display_unit: DEG,
        quantity: ANGLE,
        access: Access::Input(|s| s.phi_p, |s, v| s.phi_p = v),
        ..NONE
    },
    Variable {
        name: "phi_g",
        vr: 1,
        causality: Causality::Input,
        variability: Continuous,
        description: "Gear hub angle, rad, same sense as phi_p (negative and decreasing in \
                      normal running); TE = phi_p*g_p + phi_g*g_g",
        unit: RAD,
        display_unit: DEG,
        quantity: ANGLE,
        access: Access::Input(|s| s.phi_g, |s, v| s.phi_g = v),
        ..NONE
    },
    Variable {
        name: "w_p",
        vr: 2,
        causality: Causality::Input,
        variability: Continuous,
        description: "Pinion speed d(phi_p)/dt, rad/s",
        unit: Some("rad/s"),
        display_unit: Some("rpm"),
        quantity: Some("AngularVelocity"),
        access: Access::Input(|s| s.w_p, |s, v| s.w_p = v),
        ..NONE
    },
    Variable {
        name: "w_g",
        vr: 3,
        causality: Causality::Input,
        variability: Continuous,
        description: "Gear speed d(phi_g)/dt, rad/s (negative in normal running)",
        unit: Some("rad/s"),
        display_unit: Some("rpm"),
        quantity: Some("AngularVelocity"),
        access: Access::Input(|s| s.w_g, |s, v| s.w_g = v),
        ..NONE
    },
    // ---- outputs
    output!(
        "M_F_p",
        10,
        Continuous,
        NM,
        None,
        TORQUE,
        "Elastic mesh torque on the pinion (Eq. 13), N.m; enters the pinion equation with a \
         minus sign: J_p*phi_p'' = c1*(phi_1 - phi_p) + ... - M_F_p - M_D_p; positive in \
         normal drive",
        ELASTIC_DEPS,
        Access::RealOutput(|o| o.m_f_p)
    ),
    output!(
        "M_F_g",
        11,
        Continuous,
        NM,
        None,
        TORQUE,
        "Elastic mesh torque on the gear (Eq. 13), N.m; enters the gear equation with a minus \
         sign; M_F_g/M_F_p = g_g/g_p in the plane of action",
        ELASTIC_DEPS,
        Access::RealOutput(|o| o.m_f_g)
    ),
    output!(
        "M_D_p",
        12,
        Continuous,
        NM,
        None,
        TORQUE,
        "Damping mesh torque on the pinion (Eq. 14, d_mesh), N.m; enters the pinion equation \
         with a minus sign",
        Depends {
            inputs: ALL_INPUTS,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::DAMPING,
        },
        Access::RealOutput(|o| o.m_d_p)
    ),
    output!(
        "M_D_g",
        13,
        Continuous,
        NM,
        None,
        TORQUE,
        "Damping mesh torque on the gear (Eq. 14, d_mesh), N.m; enters the gear equation with \
         a minus sign",
        Depends {
            inputs: ALL_INPUTS,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::DAMPING,
        },
        Access::RealOutput(|o| o.m_d_g)
    ),
    output!(
        "TE",
        14,
        Continuous,
        M,
        Some("um"),
        LENGTH,
        "Transmission error TE = phi_p*g_p + phi_g*g_g (Eq. 16), m; 0 when ideal unloaded \
         driving flanks just touch, > 0 when the teeth must deform",
        Depends { inputs: ANGLES, linear_fixed: true, groups: group::GEOMETRY },
        Access::RealOutput(|o| o.te)
    ),
    output!(
        "F_n",
        15,
        Continuous,
        Some("N"),
        None,
        Some("Force"),
        "Total normal contact force of all loaded flanks, N (elastic part, >= 0)",
        ELASTIC_DEPS,
        Access::RealOutput(|o| o.f_n)
    ),
    output!(
        "contact_length",
        16,
        Continuous,
        M,
        MM,
        LENGTH,
        "Total length of the loaded contact lines, m",
        ELASTIC_DEPS,
        Access::RealOutput(|o| o.contact_length)
    ),
    output!(
        "p_max",
        17,
        Continuous,
        PA,
        Some("MPa"),
        Some("Pressure"),
        "Largest Hertz contact pressure (Eq. 15), Pa; 0 without load or when compute_pressure \
         is false",
        Depends {
            inputs: ANGLES,
            linear_fixed: false,
            groups: group::GEOMETRY | group::ELASTIC | group::OPTIONS | group::PRESSURE,
        },
        Access::RealOutput(|o| o.p_max)
    ),
    output!(
        "n_pairs",
        18,
        Discrete,
        None,
        None,
        None,
        "Number of tooth pairs carrying load",
        ELASTIC_DEPS,
        Access::IntOutput(|o| u32_to_i32(o.n_pairs))
    ),
    output!(
        "tip_contact",
        19,
        Discrete,
        None,
        None,
        None,
        "True when a loaded contact lies on the tip rounding (or tip edge) of either gear",
        ELASTIC_DEPS,
        Access::BoolOutput(|o| o.tip_contact)
    ),
    output!(
        "separated",
        20,
        Discrete,
        None,
        None,
        None,
        "True when no flank carries load (loss of contact)",
        ELASTIC_DEPS,
        Access::BoolOutput(|o| o.separated)
    ),
    output!(
        "back_contact",
        21,
        Discrete,
        None,
        None,
        None,
        "True when the back flanks carry load (TE below minus the backlash); the mesh torques \
         are then negative",
        ELASTIC_DEPS,
        Access::BoolOutput(|o| o.back_contact)
    ),
    // ---- calculated parameters
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
    // ---- gear-pair parameters
    Variable {
        name: "z_p",
        vr: 100,
        description: "Number of pinion teeth",
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
        group: group::DAMPING,
        access: Access::RealParam(|s| s.pair.d_mesh_n_s_per_m, |s, v| s.pair.d_mesh_n_s_per_m = v),
        ..NONE
    },
    real_param!(
        "drive.torque_nm",
        123,
        group::DRIVE,
        NM,
        None,
        TORQUE,
        "Driving torque M on J_1 (positive sense), N.m; the load on J_2 is M*z_g/z_p (Eq. 4). \
         Not used by the mesh element; for the master's drive-line model",
        drive.torque_nm
    ),
    real_param!(
        "drive.j1_kgm2",
        124,
        group::DRIVE,
        Some("kg.m2"),
        None,
        Some("MomentOfInertia"),
        "Inertia J_1 of the driving mass, kg.m2 (for the master)",
        drive.j1_kgm2
    ),
    real_param!(
        "drive.j2_kgm2",
        125,
        group::DRIVE,
        Some("kg.m2"),
        None,
        Some("MomentOfInertia"),
        "Inertia J_2 of the driven mass, kg.m2 (for the master)",
        drive.j2_kgm2
    ),
    real_param!(
        "drive.c1_nm_per_rad",
        126,
        group::DRIVE,
        Some("N.m/rad"),
        None,
        Some("RotationalSpringConstant"),
        "Torsional stiffness c_1 of the pinion shaft, N.m/rad (for the master)",
        drive.c1_nm_per_rad
    ),
    real_param!(
        "drive.c2_nm_per_rad",
        127,
        group::DRIVE,
        Some("N.m/rad"),
        None,
        Some("RotationalSpringConstant"),
        "Torsional stiffness c_2 of the gear shaft, N.m/rad (for the master)",
        drive.c2_nm_per_rad
    ),
    real_param!(
        "drive.d1_nms_per_rad",
        128,
        group::DRIVE,
        Some("N.m.s/rad"),
        None,
        Some("RotationalDampingConstant"),
        "Viscous damping d_1 of the pinion shaft, N.m.s/rad (for the master)",
        drive.d1_nms_per_rad
    ),
    real_param!(
        "drive.d2_nms_per_rad",
        129,
        group::DRIVE,
        Some("N.m.s/rad"),
        None,
        Some("RotationalDampingConstant"),
        "Viscous damping d_2 of the gear shaft, N.m.s/rad (for the master)",
        drive.d2_nms_per_rad
    ),
    // ---- model options
    Variable {
        name: "fidelity",
        vr: 200,
        description: "Evaluation fidelity: 0 = full contact search and load solve at every \
                      call, 1 = interpolation in a (mesh phase, TE) table built at \
                      initialisation (outside the table: full)",
        min: Some(0),
        max: Some(1),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| match s.options.fidelity {
                Fidelity::Full => 0,
                Fidelity::Table => 1,
            },
            |s, v| {
                s.options.fidelity = match v {
                    0 => Fidelity::Full,
                    1 => Fidelity::Table,
                    _ => return Err("0 (full) or 1 (table)"),
                };
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
        min: Some(1),
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
        min: Some(0),
        max: Some(1),
        group: group::OPTIONS,
        access: Access::IntParam(
            |s| match s.options.compliance {
                ComplianceModel::Interpolated => 0,
                ComplianceModel::Fitted => 1,
            },
            |s, v| {
                s.options.compliance = match v {
                    0 => ComplianceModel::Interpolated,
                    1 => ComplianceModel::Fitted,
                    _ => return Err("0 (interpolated) or 1 (fitted)"),
                };
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
        min: Some(2),
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
        min: Some(2),
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
];

/// The variable with value reference `vr`, if any.
pub fn by_vr(vr: u32) -> Option<&'static Variable> {
    // A linear scan over ~60 entries costs less than a hash; the table is small and fixed.
    VARIABLES.iter().find(|v| v.vr == vr)
}

/// The variable named `name`, if any.
pub fn by_name(name: &str) -> Option<&'static Variable> {
    VARIABLES.iter().find(|v| v.name == name)
}

/// Model identifier of the FMU (name of the shared library and of the model).
pub const MODEL_IDENTIFIER: &str = "HelicalGearMesh";

/// Log categories: name and description. Messages with status error or fatal are always
/// passed to the logger; the others only when debug logging is on for their category.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusError", "Errors: invalid parameters or inputs, illegal call sequences"),
    ("logStatusWarning", "Warnings"),
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
    /// Input derivatives are not used.
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
    /// `fmi2GetDirectionalDerivative` is not provided.
    pub provides_directional_derivative: bool,
}

/// The capabilities this FMU implements.
pub const CS_CAPABILITIES: CsCapabilities = CsCapabilities {
    needs_execution_tool: false,
    can_handle_variable_communication_step_size: true,
    can_interpolate_inputs: false,
    max_output_derivative_order: 0,
    can_run_asynchronuously: false,
    can_be_instantiated_only_once_per_process: false,
    can_not_use_memory_management_functions: true,
    can_get_and_set_fmu_state: true,
    can_serialize_fmu_state: true,
    provides_directional_derivative: false,
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
    UnitDef { name: "N", base: &[("kg", 1), ("m", 1), ("s", -2)], display: &[] },
    UnitDef { name: "N.m", base: &[("kg", 1), ("m", 2), ("s", -2)], display: &[] },
    UnitDef {
        name: "Pa",
        base: &[("kg", 1), ("m", -1), ("s", -2)],
        display: &[("MPa", 1e-6), ("GPa", 1e-9)],
    },
    UnitDef { name: "N.s/m", base: &[("kg", 1), ("s", -1)], display: &[] },
    UnitDef { name: "kg.m2", base: &[("kg", 1), ("m", 2)], display: &[] },
    UnitDef { name: "kg/m3", base: &[("kg", 1), ("m", -3)], display: &[] },
    UnitDef { name: "N.m/rad", base: &[("kg", 1), ("m", 2), ("s", -2), ("rad", -1)], display: &[] },
    UnitDef {
        name: "N.m.s/rad",
        base: &[("kg", 1), ("m", 2), ("s", -1), ("rad", -1)],
        display: &[],
    },
];

/// Canonical text of everything a master relies on (model identifier, version, capabilities,
/// log categories, and every variable with type, causality, variability, unit, start value and
/// range); the GUID is its hash.
pub fn canonical_description() -> String {
    let mut s = format!("{MODEL_IDENTIFIER} {MODEL_VERSION} fmi2 cs\n{CS_CAPABILITIES:?}\n");
    for u in UNITS {
        s.push_str(&format!("{u:?}\n"));
    }
    for (k, _) in LOG_CATEGORIES {
        s.push_str(&format!("log {k}\n"));
    }
    for v in VARIABLES {
        s.push_str(&format!(
            "{}|{}|{}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}\n",
            v.name,
            v.vr,
            v.var_type().as_str(),
            v.causality.as_str(),
            v.variability.as_str(),
            v.unit,
            v.start(),
            v.min,
            v.max,
            v.depends.map(|d| (d.inputs, d.linear_fixed, d.groups)),
            v.group
        ));
    }
    s
}

/// 128-bit FNV-1a hash.
fn fnv1a_128(bytes: &[u8]) -> u128 {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u128::from(b)).wrapping_mul(PRIME))
}

/// The GUID of the FMU: `{…}` formed from the 128-bit FNV-1a hash of
/// [`canonical_description`] (with the RFC 9562 version-8 and variant bits set). It changes
/// whenever a variable, a start value, a capability or the crate version changes.
pub fn guid() -> &'static str {
    static GUID: OnceLock<String> = OnceLock::new();
    GUID.get_or_init(|| {
        let mut h = fnv1a_128(canonical_description().as_bytes());
        h = (h & !(0xF_u128 << 76)) | (0x8_u128 << 76); // version 8 (custom)
        h = (h & !(0x3_u128 << 62)) | (0x2_u128 << 62); // RFC variant
        let x = format!("{h:032x}");
        format!("{{{}-{}-{}-{}-{}}}", &x[0..8], &x[8..12], &x[12..16], &x[16..20], &x[20..32])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_and_names_are_unique() {
        for (i, a) in VARIABLES.iter().enumerate() {
            for b in &VARIABLES[i + 1..] {
                assert_ne!(a.vr, b.vr, "{} and {}", a.name, b.name);
                assert_ne!(a.name, b.name);
            }
        }
    }

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
        for k in &keys {
            assert!(
                VARIABLES.iter().any(|v| v.causality == Causality::Parameter && v.json_key() == k),
                "GearPair field {k} has no FMI parameter"
            );
        }
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
                    let other = if v.max == Some(1) { 1 - start } else { start + 1 };
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
        for v in VARIABLES {
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
