//! Gear-pair parameters: the serde/JSON schema, the paper's Table 1 default and validation.
//!
//! All values are SI (m, rad, Pa, kg/m³, N·m, N·s/m …) except the basic-rack quantities, which
//! gear engineers give relative to the normal module m_n; those keys end in `_mn` (for example
//! `rack_fillet_radius_mn = 0.35` means ρ_fP = 0.35·m_n).
//!
//! Conventions:
//! * the pinion (`_p`) is the driving gear; the pinion helix is right-handed, the gear's
//!   left-handed (opposite hands are required for parallel axes; the hand only mirrors the
//!   contact line along the face width and does not change any result of the torsional model);
//! * the basic rack follows ISO 53: its tooth is the gear tooth of an infinite gear, tip outward,
//!   addendum `addendum_mn`, dedendum `dedendum_mn`, root fillet `rack_fillet_radius_mn`;
//! * tip relief of the basic rack (Fig. 2 of the paper): a straight line that leaves the nominal
//!   flank `tip_relief_height_mn` below the rack tip and lies `tip_relief_depth_mn`, measured
//!   normal to the nominal flank in the normal section, inside it at the rack tip;
//! * the normal backlash `normal_backlash_mn` (at the operating centre distance, measured
//!   normal to the flanks in the normal section) is made by thinning both gears' teeth equally;
//! * the centre distance is the zero-backlash operating centre distance of the profile shifts.
//!
//! A [`GearPair`] read from JSON is only data; [`crate::geometry::PairGeometry::new`] validates it
//! (every rule returns a [`ParamError`] naming the key, the value and the allowed range) and
//! derives the geometry. [`GearPair::validate`] runs the same checks.
//!
//! Ranges: every numeric parameter has one inclusive range, a [`Bounds`] `pub const` beside the
//! check that enforces it ([`GearPair::check_params`], [`DriveLine::check`], [`check_d_mesh`]);
//! the FMI variable tables write the same constants as `min`/`max` into `modelDescription.xml`.
//! Where the paper's data only require `> 0` or "finite", the bounds are finite physical limits
//! (each constant's doc says why). A value inside its range may still be refused in combination
//! with others — undercut, pointed tooth, tip interference, overlapping root fillets, contact
//! ratio below 1, a bore outside the root circle: [`crate::geometry::PairGeometry::new`] checks
//! those and the error names the parameter to change and the limit the combination implies.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
pub mod modifications;

use self::modifications::Modifications;

/// Elastic and mass properties of one gear's material. In JSON every key is optional (missing
/// keys: [`Material::steel`]); unknown keys are an error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Material {
    /// Young's modulus E, Pa (> 0).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν, dimensionless, in (0, 0.5).
    pub poisson_ratio: f64,
    /// Density, kg/m³ (> 0).
    pub density_kg_m3: f64,
}

impl Default for Material {
    /// [`Material::steel`].
    fn default() -> Self {
        Self::steel()
    }
}

impl Material {
    /// Steel as assumed where the paper is silent: E = 206 GPa, ν = 0.3, ρ = 7850 kg/m³.
    pub fn steel() -> Self {
        Self { youngs_modulus_pa: 206e9, poisson_ratio: 0.3, density_kg_m3: 7850.0 }
    }
}

/// The parts connected to the gear set (paper Fig. 1 and Eqs. 1–4): not part of the
/// [`GearPair`] (the gear pair describes the gears; the mesh element does not depend on what
/// drives it), given beside it to what needs it (CLI `--drive FILE`, Python `drive=`, the C
/// API's `drive_json`, the FMU parameters `drive.*` of the stateful models).
///
/// Sign convention: the driving torque `torque_nm` acts on the driving inertia J₁ in the positive
/// rotational sense; the braking torque `torque_nm·z_g/z_p` acts on J₂ (Eq. 4). In JSON every
/// key is optional (missing keys: [`DriveLine::paper_table1`]); unknown keys are an error
/// ([`DriveLine::from_json`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveLine {
    /// Driving torque M on the pinion side, N·m.
    pub torque_nm: f64,
    /// Inertia J₁ of the driving mass, kg·m².
    pub j1_kgm2: f64,
    /// Inertia J₂ of the driven mass, kg·m².
    pub j2_kgm2: f64,
    /// Torsional stiffness c₁ of the pinion shaft, N·m/rad.
    pub c1_nm_per_rad: f64,
    /// Torsional stiffness c₂ of the gear shaft, N·m/rad.
    pub c2_nm_per_rad: f64,
    /// Viscous damping d₁ of the pinion shaft, N·m·s/rad.
    pub d1_nms_per_rad: f64,
    /// Viscous damping d₂ of the gear shaft, N·m·s/rad.
    pub d2_nms_per_rad: f64,
}

impl Default for DriveLine {
    /// [`DriveLine::paper_table1`].
    fn default() -> Self {
        Self::paper_table1()
    }
}

impl DriveLine {
    /// Table 1 of the paper: M = 100 N·m, J₁ = J₂ = 0.62 kg·m², c₁ = c₂ = 984 N·m/rad,
    /// d₁ = d₂ = 0.04 N·m·s/rad.
    pub fn paper_table1() -> Self {
        Self {
            torque_nm: 100.0,
            j1_kgm2: 0.62,
            j2_kgm2: 0.62,
            c1_nm_per_rad: 984.0,
            c2_nm_per_rad: 984.0,
            d1_nms_per_rad: 0.04,
            d2_nms_per_rad: 0.04,
        }
    }

    /// Reads a drive line from JSON text (the schema of this struct: missing keys from
    /// [`DriveLine::paper_table1`], unknown keys an error naming the key, an array or any
    /// other non-object an error).
    pub fn from_json(text: &str) -> Result<Self, String> {
        const WHAT: &str = "drive-line JSON";
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("{WHAT}: {e}"))?;
        json_object(WHAT, &value, "(the drive line)", false)?;
        serde_json::from_value(value).map_err(|e| format!("{WHAT}: {e}"))
    }
}

/// All data of one helical gear pair (the JSON schema of `--params FILE`).
///
/// Angles in rad, lengths in m, basic-rack quantities in units of m_n (keys ending `_mn`).
///
/// The drive line (torque, inertias, shafts) is not part of the pair: it is a [`DriveLine`]
/// given beside it.
///
/// In JSON every key is optional: a missing key takes its value from Table 1
/// ([`GearPair::paper_table1`]; inside `material_p` and `material_g` key by key), so
/// `{"helix_angle_rad": 0.2}` is Table 1 with β = 0.2 rad. Unknown keys are an error naming
/// the key. This is the one filling rule of every interface (CLI `--params`, Python, the C API).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GearPair {
    /// Number of pinion teeth z_p.
    pub z_p: u32,
    /// Number of gear teeth z_g.
    pub z_g: u32,
    /// Normal module m_n, m.
    pub normal_module_m: f64,
    /// Normal pressure angle α_n of the basic rack, rad.
    pub pressure_angle_rad: f64,
    /// Helix angle β at the reference cylinder, rad (pinion right hand, gear left hand).
    pub helix_angle_rad: f64,
    /// Face width b, m (both gears).
    pub face_width_m: f64,
    /// Profile shift coefficient x_p of the pinion.
    pub profile_shift_p: f64,
    /// Profile shift coefficient x_g of the gear.
    pub profile_shift_g: f64,
    /// Addendum coefficient h_aP/m_n of the basic rack; the tip radius is r + (x + h_aP/m_n)·m_n.
    pub addendum_mn: f64,
    /// Dedendum coefficient h_fP/m_n of the basic rack; the root radius is r + (x − h_fP/m_n)·m_n.
    pub dedendum_mn: f64,
    /// Root fillet radius ρ_fP of the basic rack (normal section), in m_n.
    pub rack_fillet_radius_mn: f64,
    /// Tip relief depth δ of the basic rack at its tip, normal to the flank, in m_n (0 = none).
    pub tip_relief_depth_mn: f64,
    /// Height H of the relief zone below the basic-rack tip, in m_n.
    pub tip_relief_height_mn: f64,
    /// Radius of the tip rounding, a circular arc in the transverse plane tangent to the relief
    /// (or involute) and to the tip circle, in m_n (0 = sharp edge).
    pub tip_rounding_radius_mn: f64,
    /// Normal backlash j_n at the operating centre distance, in m_n (split equally between gears).
    pub normal_backlash_mn: f64,
    /// Diameter of the hub bore of both gears, m (the FE models are fixed there).
    pub bore_diameter_m: f64,
    /// Pinion material.
    pub material_p: Material,
    /// Gear material.
    pub material_g: Material,
    /// Mesh damping coefficient d_mesh of Eq. 14, N·s/m.
    pub d_mesh_n_s_per_m: f64,
    /// Flank modifications, misalignment and tooth deviations ([`crate::modifications`]);
    /// all zero by default, and left out when serialised at the default.
    #[serde(skip_serializing_if = "Modifications::is_default")]
    pub modifications: Modifications,
}

impl Default for GearPair {
    fn default() -> Self {
        Self::paper_table1()
    }
}

impl GearPair {
    /// The paper's Table 1 gear pair: z = 30/47, m_n = 3 mm, α_n = 20°, β = 10°, b = 15 mm,
    /// ρ_fP = 0.35·m_n, δ = 0.015·m_n, H = 0.5·m_n, tip rounding 0.05·m_n, bore 15 mm,
    /// j_n = 0.0725·m_n (the drive line of Table 1 is [`DriveLine::paper_table1`]).
    ///
    /// Not given by the paper and assumed here (printed in every run summary): zero profile
    /// shift, ISO 53 addendum 1.0 and dedendum 1.25, steel (E = 206 GPa, ν = 0.3,
    /// ρ = 7850 kg/m³) and d_mesh = 100 N·s/m (the paper's first damping value).
    pub fn paper_table1() -> Self {
        Self {
            z_p: 30,
            z_g: 47,
            normal_module_m: 3e-3,
            pressure_angle_rad: 20f64.to_radians(),
            helix_angle_rad: 10f64.to_radians(),
            face_width_m: 15e-3,
            profile_shift_p: 0.0,
            profile_shift_g: 0.0,
            addendum_mn: 1.0,
            dedendum_mn: 1.25,
            rack_fillet_radius_mn: 0.35,
            tip_relief_depth_mn: 0.015,
            tip_relief_height_mn: 0.5,
            tip_rounding_radius_mn: 0.05,
            normal_backlash_mn: 0.0725,
            bore_diameter_m: 15e-3,
            material_p: Material::steel(),
            material_g: Material::steel(),
            d_mesh_n_s_per_m: 100.0,
            modifications: Modifications::default(),
        }
    }

    /// The modelling assumptions behind these parameters that the paper does not state, as
    /// human-readable lines (printed in every run summary). Lists the values actually used.
    pub fn assumptions(&self) -> Vec<String> {
        let m = |mat: &Material| {
            format!(
                "E = {:.0} GPa, ν = {}, ρ = {} kg/m³",
                mat.youngs_modulus_pa / 1e9,
                mat.poisson_ratio,
                mat.density_kg_m3
            )
        };
        vec![
            format!("pinion material: {} (paper: not given)", m(&self.material_p)),
            format!("gear material: {} (paper: not given)", m(&self.material_g)),
            format!(
                "profile shifts x_p = {}, x_g = {} (paper: not given; centre distance is the \
                 zero-backlash operating one)",
                self.profile_shift_p, self.profile_shift_g
            ),
            format!(
                "basic rack addendum {}·m_n, dedendum {}·m_n (paper: not given; ISO 53 values)",
                self.addendum_mn, self.dedendum_mn
            ),
            "tip relief depth δ measured normal to the rack flank at the rack tip; backlash by \
             equal thinning of both gears"
                .to_string(),
            "J_p, J_g: toothed discs of face width b down to the bore (paper: not given)"
                .to_string(),
        ]
    }

    /// Reads a gear pair from JSON text (the schema of this struct: missing keys from Table 1,
    /// unknown keys an error naming the key). A `drive` key (the drive line, once part of the
    /// pair) is refused with a message saying where the drive line goes now
    /// ([`DRIVE_MOVED`]).
    /// Every object of the schema must be a JSON object: with missing keys filled in, serde
    /// would read an array (`[]`) as a struct of defaults, so an array where an object belongs
    /// is an error naming its key.
    pub fn from_json(text: &str) -> Result<Self, String> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("gear-pair JSON: {e}"))?;
        objects_where_structs(&value)?;
        serde_json::from_value(value).map_err(|e| format!("gear-pair JSON: {e}"))
    }

    /// Checks every scalar parameter against its [`Bounds`] (the `pub const`s below, which the
    /// FMI variable tables, the C header and Python read) and the two rules between parameters
    /// that need no geometry (dedendum above addendum; a relief zone no higher than the rack
    /// tooth, and of positive height when there is relief). Called first by
    /// [`crate::geometry::PairGeometry::new`]; the combined geometric validity (undercut,
    /// pointed tooth, tip interference, contact ratio, bore inside the root) is checked there.
    pub fn check_params(&self) -> Result<(), ParamError> {
        Z_P.check_int("z_p", i64::from(self.z_p))?;
        Z_G.check_int("z_g", i64::from(self.z_g))?;
        NORMAL_MODULE_M.check("normal_module_m", self.normal_module_m)?;
        PRESSURE_ANGLE_RAD.check("pressure_angle_rad", self.pressure_angle_rad)?;
        HELIX_ANGLE_RAD.check("helix_angle_rad", self.helix_angle_rad)?;
        FACE_WIDTH_M.check("face_width_m", self.face_width_m)?;
        let b_max = MAX_FACE_WIDTH_MN * self.normal_module_m;
        if self.face_width_m > b_max {
            return Err(ParamError::new(
                "face_width_m",
                self.face_width_m,
                format!(
                    "<= {MAX_FACE_WIDTH_MN}·normal_module_m = {b_max:.6e} m (b/m_n = {:.4e}; \
                     the widest helical gears have b/m_n of 30–40, and the tooth FE and the \
                     rigid-shaft load distribution stop holding beyond): lower face_width_m \
                     or raise normal_module_m",
                    self.face_width_m / self.normal_module_m
                ),
            ));
        }
        PROFILE_SHIFT.check("profile_shift_p", self.profile_shift_p)?;
        PROFILE_SHIFT.check("profile_shift_g", self.profile_shift_g)?;
        ADDENDUM_MN.check("addendum_mn", self.addendum_mn)?;
        DEDENDUM_MN.check("dedendum_mn", self.dedendum_mn)?;
        if self.dedendum_mn <= self.addendum_mn {
            return Err(ParamError::new(
                "dedendum_mn",
                self.dedendum_mn,
                format!("> addendum_mn = {} (tip clearance)", self.addendum_mn),
            ));
        }
        RACK_FILLET_RADIUS_MN.check("rack_fillet_radius_mn", self.rack_fillet_radius_mn)?;
        TIP_RELIEF_DEPTH_MN.check("tip_relief_depth_mn", self.tip_relief_depth_mn)?;
        TIP_RELIEF_HEIGHT_MN.check("tip_relief_height_mn", self.tip_relief_height_mn)?;
        let tooth = self.addendum_mn + self.dedendum_mn;
        let h = self.tip_relief_height_mn;
        if self.tip_relief_depth_mn > 0.0 && !(h >= 1e-3 && h <= tooth) {
            return Err(ParamError::new(
                "tip_relief_height_mn",
                h,
                format!("in [1e-3, addendum_mn + dedendum_mn = {tooth}] when there is relief"),
            ));
        }
        if h > tooth {
            return Err(ParamError::new(
                "tip_relief_height_mn",
                h,
                format!("<= addendum_mn + dedendum_mn = {tooth}"),
            ));
        }
        TIP_ROUNDING_RADIUS_MN.check("tip_rounding_radius_mn", self.tip_rounding_radius_mn)?;
        NORMAL_BACKLASH_MN.check("normal_backlash_mn", self.normal_backlash_mn)?;
        BORE_DIAMETER_M.check("bore_diameter_m", self.bore_diameter_m)?;
        for (key, m) in [("material_p", &self.material_p), ("material_g", &self.material_g)] {
            YOUNGS_MODULUS_PA.check(&format!("{key}.youngs_modulus_pa"), m.youngs_modulus_pa)?;
            POISSON_RATIO.check(&format!("{key}.poisson_ratio"), m.poisson_ratio)?;
            DENSITY_KG_M3.check(&format!("{key}.density_kg_m3"), m.density_kg_m3)?;
        }
        check_d_mesh(self.d_mesh_n_s_per_m)
    }
}

impl DriveLine {
    /// Checks every drive-line value against its [`Bounds`] ([`DRIVE_TORQUE_NM`],
    /// [`DRIVE_INERTIA_KGM2`], [`DRIVE_STIFFNESS_NM_PER_RAD`], [`DRIVE_DAMPING_NMS_PER_RAD`]);
    /// the error names the key as `drive.<field>`.
    pub fn check(&self) -> Result<(), ParamError> {
        if !DRIVE_TORQUE_NM.contains(self.torque_nm) {
            return Err(ParamError::new(
                "drive.torque_nm",
                self.torque_nm,
                format!(
                    "{} (positive: the pinion drives on its driving flanks; for the gear \
                     driving the pinion, swap pinion and gear)",
                    DRIVE_TORQUE_NM.allowed()
                ),
            ));
        }
        DRIVE_INERTIA_KGM2.check("drive.j1_kgm2", self.j1_kgm2)?;
        DRIVE_INERTIA_KGM2.check("drive.j2_kgm2", self.j2_kgm2)?;
        DRIVE_STIFFNESS_NM_PER_RAD.check("drive.c1_nm_per_rad", self.c1_nm_per_rad)?;
        DRIVE_STIFFNESS_NM_PER_RAD.check("drive.c2_nm_per_rad", self.c2_nm_per_rad)?;
        DRIVE_DAMPING_NMS_PER_RAD.check("drive.d1_nms_per_rad", self.d1_nms_per_rad)?;
        DRIVE_DAMPING_NMS_PER_RAD.check("drive.d2_nms_per_rad", self.d2_nms_per_rad)
    }
}

/// The inclusive range `[min, max]` of one numeric parameter, in `unit`: declared once as a
/// `pub const` beside the check that enforces it ([`Bounds::check`]), and read by the FMI
/// variable tables (`min`/`max` of `modelDescription.xml`), the C header and Python. A value
/// is accepted exactly when it is finite (integers: any) and `min <= value <= max`; the error
/// names the key, the value and the range.
///
/// The bounds of one parameter hold with any values of the others; combinations (undercut,
/// pointed tooth, tip interference, contact ratio, the table's node count …) are checked where
/// the combination is known and are an error at initialisation with a message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds<T> {
    /// Smallest accepted value, in `unit`.
    pub min: T,
    /// Largest accepted value, in `unit`.
    pub max: T,
    /// Unit of `min`, `max` and the value (SI; `""` for dimensionless, `"m_n"` for values in
    /// units of the normal module).
    pub unit: &'static str,
}

impl<T: Copy> Bounds<T> {
    /// The range `[min, max]` in `unit`.
    pub const fn new(min: T, max: T, unit: &'static str) -> Self {
        Self { min, max, unit }
    }
}

/// A bound as written in messages: plain for 1e-3 <= |x| < 1e6, otherwise exponent form, at
/// most 7 significant digits (e.g. `0.35`, `1e-5`, `7.853982e-1`).
fn fmt_bound(x: f64) -> String {
    let s =
        if x == 0.0 || (1e-3..1e6).contains(&x.abs()) { format!("{x}") } else { format!("{x:e}") };
    if s.len() > 12 { format!("{x:.6e}") } else { s }
}

fn fmt_allowed(min: String, max: String, unit: &str) -> String {
    let u = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    format!("in [{min}, {max}]{u}")
}

impl Bounds<f64> {
    /// The range in words for an error message, e.g. `in [1e-5, 1] m`.
    pub fn allowed(&self) -> String {
        fmt_allowed(fmt_bound(self.min), fmt_bound(self.max), self.unit)
    }

    /// True when `value` is finite and in `[min, max]`.
    pub fn contains(&self, value: f64) -> bool {
        value.is_finite() && value >= self.min && value <= self.max
    }

    /// `Ok` when [`Bounds::contains`] `value`, else a [`ParamError`] naming `name`, the value
    /// and the range.
    pub fn check(&self, name: &str, value: f64) -> Result<(), ParamError> {
        if self.contains(value) {
            Ok(())
        } else {
            Err(ParamError::new(name, value, self.allowed()))
        }
    }
}

impl Bounds<i64> {
    /// The range in words for an error message, e.g. `in [5, 100000]`.
    pub fn allowed(&self) -> String {
        fmt_allowed(self.min.to_string(), self.max.to_string(), self.unit)
    }

    /// `Ok` when `value` is in `[min, max]`, else a [`ParamError`] naming `name`, the value
    /// and the range.
    pub fn check_int(&self, name: &str, value: i64) -> Result<(), ParamError> {
        if (self.min..=self.max).contains(&value) {
            Ok(())
        } else {
            Err(ParamError::new(name, value as f64, self.allowed()))
        }
    }
}

/// Number of teeth z_p, z_g: 5 … 100 000 (fewer than 5 teeth cannot mesh continuously; the
/// undercut limit of the given rack and shift, usually higher, is checked with the geometry).
/// 100 000 teeth of the smallest module (10 µm) make a 1 m wheel, beyond any gear made (the
/// largest girth gears have a few hundred teeth). The model's work and memory do not grow with
/// z (the contact search, the FE sectors and the body inertia work on a few teeth; the
/// hunting period of a spectrum, which does, has its own bound), so the upper bound only
/// marks where a tooth number stops being a gear.
pub const Z_P: Bounds<i64> = Bounds::new(5, 100_000, "");
/// See [`Z_P`].
pub const Z_G: Bounds<i64> = Z_P;
/// Normal module m_n: 10 µm (instrument gears) … 1 m, m.
pub const NORMAL_MODULE_M: Bounds<f64> = Bounds::new(1e-5, 1.0, "m");
/// Normal pressure angle α_n: 10° … 35° (the range of standard and special racks), rad.
pub const PRESSURE_ANGLE_RAD: Bounds<f64> =
    Bounds::new(10.0 * std::f64::consts::PI / 180.0, 35.0 * std::f64::consts::PI / 180.0, "rad");
/// Helix angle β: 0 (spur) up to the largest double below 45° (beyond, the transverse
/// quantities of a helical gear with this rack degenerate), rad.
pub const HELIX_ANGLE_RAD: Bounds<f64> =
    Bounds::new(0.0, f64::from_bits(std::f64::consts::FRAC_PI_4.to_bits() - 1), "rad");
/// Largest face width in normal modules, b/m_n ≤ 40 (checked with the module, in
/// [`GearPair::check_params`]). The widest helical gears in service have b/m_n of 30–40
/// (beyond, the load cannot be spread over the face width by shafts and housings); the model's
/// tooth FE and its rigid-shaft load distribution are made and tested for that range
/// (`tests/stress_designs.rs`: 4–40·m_n). Beyond it the FE fails late and without naming the
/// cause: b = 100·m_n (Table 1, 0.3 m) ran the FE for 4 minutes before its pitch-point load
/// case no longer fitted the pair, b = 10 m reported an inverted element.
pub const MAX_FACE_WIDTH_MN: f64 = 40.0;

/// Face width b: 1 µm … 10 m, m, and at most [`MAX_FACE_WIDTH_MN`]·m_n.
pub const FACE_WIDTH_M: Bounds<f64> = Bounds::new(1e-6, 10.0, "m");
/// Profile shift coefficients x_p, x_g: −1.5 … 1.5 (beyond, the tooth is pointed or undercut
/// for any practical rack).
pub const PROFILE_SHIFT: Bounds<f64> = Bounds::new(-1.5, 1.5, "");
/// Addendum of the basic rack h_aP/m_n: 0.3 … 2.0, in m_n.
pub const ADDENDUM_MN: Bounds<f64> = Bounds::new(0.3, 2.0, "m_n");
/// Dedendum of the basic rack h_fP/m_n: 0.3 … 2.5, in m_n (and above the addendum).
pub const DEDENDUM_MN: Bounds<f64> = Bounds::new(0.3, 2.5, "m_n");
/// Root fillet radius of the basic rack ρ_fP/m_n: 0 … 1, in m_n.
pub const RACK_FILLET_RADIUS_MN: Bounds<f64> = Bounds::new(0.0, 1.0, "m_n");
/// Tip relief depth δ/m_n: 0 (none) … 0.2, in m_n.
pub const TIP_RELIEF_DEPTH_MN: Bounds<f64> = Bounds::new(0.0, 0.2, "m_n");
/// Height H/m_n of the relief zone: 0 … 4.5 (the largest addendum plus dedendum), in m_n; with
/// relief also in [1e-3, addendum_mn + dedendum_mn].
pub const TIP_RELIEF_HEIGHT_MN: Bounds<f64> = Bounds::new(0.0, 4.5, "m_n");
/// Tip rounding radius/m_n: 0 (sharp edge) … 0.5, in m_n.
pub const TIP_ROUNDING_RADIUS_MN: Bounds<f64> = Bounds::new(0.0, 0.5, "m_n");
/// Normal backlash j_n/m_n: 0 … 0.5, in m_n.
pub const NORMAL_BACKLASH_MN: Bounds<f64> = Bounds::new(0.0, 0.5, "m_n");
/// Hub bore diameter: 1 µm … 100 m, m (and inside the root circle, checked with the geometry).
pub const BORE_DIAMETER_M: Bounds<f64> = Bounds::new(1e-6, 100.0, "m");
/// Young's modulus E: 1 MPa (elastomers) … 10 TPa (above diamond), Pa.
pub const YOUNGS_MODULUS_PA: Bounds<f64> = Bounds::new(1e6, 1e13, "Pa");
/// Poisson's ratio ν: 0.001 … 0.499 (ν = 0.5, incompressible, makes the FE solid lock).
pub const POISSON_RATIO: Bounds<f64> = Bounds::new(1e-3, 0.499, "");
/// Density: 1 … 100 000 kg/m³.
pub const DENSITY_KG_M3: Bounds<f64> = Bounds::new(1.0, 1e5, "kg/m3");
/// Driving torque M of the drive line (`torque_nm`): 1 N·m … 1e9 N·m, N·m. Positive: the
/// model's pinion drives on its driving flanks (the crate's sign convention), and the units'
/// static start, their step bound (the mesh stiffness under M) and the table's TE range are
/// all built on that flank; a drive in which the gear drives the pinion (coast) is the same
/// model with the roles of pinion and gear swapped, not a negative M. Below 1 N·m the static
/// TE of most designs is lost in the table's light-load grading (the table's smallest design
/// torque, [`crate::mesh::table::TABLE_DESIGN_TORQUE_NM`]); 1e9 N·m is far above the largest
/// gear drives (about 1e7 N·m), and what a given design carries within the model's validity
/// range is its own, named at the static start. The back flanks are loaded by the dynamics
/// (and by `helical-gear static` through TE), not by a negative nominal torque.
pub const DRIVE_TORQUE_NM: Bounds<f64> = Bounds::new(1.0, 1e9, "N.m");
/// Inertias J₁, J₂: 1e-12 … 1e9 kg·m² (positive: the equations divide by them).
pub const DRIVE_INERTIA_KGM2: Bounds<f64> = Bounds::new(1e-12, 1e9, "kg.m2");
/// Shaft stiffnesses c₁, c₂: 1e-9 … 1e15 N·m/rad (positive: a shaft must connect).
pub const DRIVE_STIFFNESS_NM_PER_RAD: Bounds<f64> = Bounds::new(1e-9, 1e15, "N.m/rad");
/// Shaft damping d₁, d₂: 0 … 1e12 N·m·s/rad.
pub const DRIVE_DAMPING_NMS_PER_RAD: Bounds<f64> = Bounds::new(0.0, 1e12, "N.m.s/rad");

/// Every numeric key of the gear-pair JSON and of the drive-line JSON (prefixed `drive.`, the
/// names of the FMU parameters and of the design-table columns) with its range: (key, nested
/// keys joined by a dot; min; max; unit), integers as `f64`. The list Python exposes as
/// `helical_gear.BOUNDS`.
pub fn parameter_bounds() -> Vec<(String, f64, f64, &'static str)> {
    let z = |b: Bounds<i64>| Bounds::new(b.min as f64, b.max as f64, b.unit);
    let mut v: Vec<(String, Bounds<f64>)> = vec![
        ("z_p".into(), z(Z_P)),
        ("z_g".into(), z(Z_G)),
        ("normal_module_m".into(), NORMAL_MODULE_M),
        ("pressure_angle_rad".into(), PRESSURE_ANGLE_RAD),
        ("helix_angle_rad".into(), HELIX_ANGLE_RAD),
        ("face_width_m".into(), FACE_WIDTH_M),
        ("profile_shift_p".into(), PROFILE_SHIFT),
        ("profile_shift_g".into(), PROFILE_SHIFT),
        ("addendum_mn".into(), ADDENDUM_MN),
        ("dedendum_mn".into(), DEDENDUM_MN),
        ("rack_fillet_radius_mn".into(), RACK_FILLET_RADIUS_MN),
        ("tip_relief_depth_mn".into(), TIP_RELIEF_DEPTH_MN),
        ("tip_relief_height_mn".into(), TIP_RELIEF_HEIGHT_MN),
        ("tip_rounding_radius_mn".into(), TIP_ROUNDING_RADIUS_MN),
        ("normal_backlash_mn".into(), NORMAL_BACKLASH_MN),
        ("bore_diameter_m".into(), BORE_DIAMETER_M),
    ];
    for g in ["material_p", "material_g"] {
        v.push((format!("{g}.youngs_modulus_pa"), YOUNGS_MODULUS_PA));
        v.push((format!("{g}.poisson_ratio"), POISSON_RATIO));
        v.push((format!("{g}.density_kg_m3"), DENSITY_KG_M3));
    }
    v.push(("d_mesh_n_s_per_m".into(), D_MESH_N_S_PER_M));
    v.push(("drive.torque_nm".into(), DRIVE_TORQUE_NM));
    v.push(("drive.j1_kgm2".into(), DRIVE_INERTIA_KGM2));
    v.push(("drive.j2_kgm2".into(), DRIVE_INERTIA_KGM2));
    v.push(("drive.c1_nm_per_rad".into(), DRIVE_STIFFNESS_NM_PER_RAD));
    v.push(("drive.c2_nm_per_rad".into(), DRIVE_STIFFNESS_NM_PER_RAD));
    v.push(("drive.d1_nms_per_rad".into(), DRIVE_DAMPING_NMS_PER_RAD));
    v.push(("drive.d2_nms_per_rad".into(), DRIVE_DAMPING_NMS_PER_RAD));
    v.into_iter().map(|(k, b)| (k, b.min, b.max, b.unit)).collect()
}

/// The refusal of a `drive` key in the gear-pair JSON: the drive line is not part of the
/// pair; where it goes instead.
pub const DRIVE_MOVED: &str = "`drive` is no longer part of the gear pair: give the drive line \
     (torque_nm, j1_kgm2, j2_kgm2, c1_nm_per_rad, c2_nm_per_rad, d1_nms_per_rad, \
     d2_nms_per_rad) as its own JSON object (CLI `--drive FILE`, Python `drive=`, C API \
     `drive_json`)";

/// Largest mesh damping coefficient d_mesh (Eq. 14), N·s/m: the range of the JSON key
/// `d_mesh_n_s_per_m` (FMI parameter `d_mesh`) is [`D_MESH_N_S_PER_M`].
pub const D_MESH_MAX_N_S_PER_M: f64 = 1e9;

/// Mesh damping coefficient d_mesh (Eq. 14): 0 … 1e9 N·s/m.
pub const D_MESH_N_S_PER_M: Bounds<f64> = Bounds::new(0.0, D_MESH_MAX_N_S_PER_M, "N.s/m");

/// Checks a mesh damping coefficient against [`D_MESH_N_S_PER_M`]: the one check behind the
/// pair's validation and every later change of the tunable damping (FMU `d_mesh`, C API
/// `hgm_set_d_mesh`, Python).
pub fn check_d_mesh(d_mesh: f64) -> Result<(), ParamError> {
    D_MESH_N_S_PER_M.check("d_mesh_n_s_per_m", d_mesh)
}

/// Checks that the gear-pair JSON `v` has an object wherever the schema has a struct (the pair
/// itself, `material_p`, `material_g`, `modifications` with its `pinion` and `gear`, their
/// `end_relief`, `tip_relief` and `deviation_map`); `null` is allowed where the field is
/// optional. The error names the key. A `drive` key is refused with [`DRIVE_MOVED`].
fn objects_where_structs(v: &serde_json::Value) -> Result<(), String> {
    const WHAT: &str = "gear-pair JSON";
    let Some(top) = json_object(WHAT, v, "(the gear pair)", false)? else { return Ok(()) };
    if top.contains_key("drive") {
        return Err(format!("{WHAT}: {DRIVE_MOVED}"));
    }
    for key in ["material_p", "material_g"] {
        if let Some(x) = top.get(key) {
            json_object(WHAT, x, key, false)?;
        }
    }
    match top.get("modifications") {
        Some(m) => modification_objects(WHAT, m, "modifications"),
        None => Ok(()),
    }
}

/// [`objects_where_structs`] for a `modifications` object `m` found at `key` of a `what`
/// (`pinion`, `gear`, their `end_relief`, `tip_relief` and the optional `deviation_map`).
fn modification_objects(what: &str, m: &serde_json::Value, key: &str) -> Result<(), String> {
    let Some(m) = json_object(what, m, key, false)? else { return Ok(()) };
    for gear in ["pinion", "gear"] {
        let Some(g) = m.get(gear) else { continue };
        let key = format!("{key}.{gear}");
        let Some(g) = json_object(what, g, &key, false)? else { continue };
        for (sub, optional) in
            [("end_relief", false), ("tip_relief", false), ("deviation_map", true)]
        {
            if let Some(x) = g.get(sub) {
                json_object(what, x, &format!("{key}.{sub}"), optional)?;
            }
        }
    }
    Ok(())
}

/// `v` as an object (`None` for a `null` where `optional`); anything else is an error naming
/// `key` of the `what` and the JSON type found.
fn json_object<'a>(
    what: &str,
    v: &'a serde_json::Value,
    key: &str,
    optional: bool,
) -> Result<Option<&'a serde_json::Map<String, serde_json::Value>>, String> {
    use serde_json::Value;
    let found = match v {
        Value::Object(m) => return Ok(Some(m)),
        Value::Null if optional => return Ok(None),
        Value::Array(_) => "an array",
        Value::String(_) => "a string",
        Value::Number(_) => "a number",
        Value::Bool(_) => "a boolean",
        Value::Null => "null",
    };
    Err(format!("{what}: `{key}` must be an object ({{…}}), found {found}"))
}
