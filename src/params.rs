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

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::modifications::Modifications;

/// Elastic and mass properties of one gear's material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus E, Pa (> 0).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν, dimensionless, in (0, 0.5).
    pub poisson_ratio: f64,
    /// Density, kg/m³ (> 0).
    pub density_kg_m3: f64,
}

impl Material {
    /// Steel as assumed where the paper is silent: E = 206 GPa, ν = 0.3, ρ = 7850 kg/m³.
    pub fn steel() -> Self {
        Self { youngs_modulus_pa: 206e9, poisson_ratio: 0.3, density_kg_m3: 7850.0 }
    }
}

/// The parts connected to the gear set (paper Fig. 1 and Eqs. 1–4).
///
/// Sign convention: the driving torque `torque_nm` acts on the driving inertia J₁ in the positive
/// rotational sense; the braking torque `torque_nm·z_g/z_p` acts on J₂ (Eq. 4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
}

/// All data of one helical gear pair (the JSON schema of `--params FILE`).
///
/// Angles in rad, lengths in m, basic-rack quantities in units of m_n (keys ending `_mn`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
    #[serde(default)]
    pub profile_shift_p: f64,
    /// Profile shift coefficient x_g of the gear.
    #[serde(default)]
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
    /// The shafts and masses on both sides (Eqs. 1–4).
    pub drive: DriveLine,
    /// Flank modifications, misalignment and tooth deviations ([`crate::modifications`]);
    /// optional in JSON, all zero by default, and left out when serialised at the default.
    #[serde(default, skip_serializing_if = "Modifications::is_default")]
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
    /// j_n = 0.0725·m_n, and the drive line of Table 1.
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
            drive: DriveLine::paper_table1(),
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

    /// Reads a gear pair from JSON text (the schema of this struct; unknown keys are an error).
    pub fn from_json(text: &str) -> Result<Self, String> {
        serde_json::from_str(text).map_err(|e| format!("gear-pair JSON: {e}"))
    }

    /// Validates every parameter and the derived geometry; see
    /// [`crate::geometry::PairGeometry::new`] for the rules.
    pub fn validate(&self) -> Result<(), ParamError> {
        crate::geometry::PairGeometry::new(self).map(|_| ())
    }

    /// Checks the plain ranges of the scalar parameters (no geometry needed). Called first by
    /// [`crate::geometry::PairGeometry::new`].
    pub(crate) fn check_ranges(&self) -> Result<(), ParamError> {
        let deg = std::f64::consts::PI / 180.0;
        check_finite_range("normal_module_m", self.normal_module_m, 1e-5, 1.0, "in [1e-5, 1] m")?;
        check_finite_range(
            "pressure_angle_rad",
            self.pressure_angle_rad,
            10.0 * deg,
            35.0 * deg,
            "in [10°, 35°] = [0.1745, 0.6109] rad",
        )?;
        let beta = self.helix_angle_rad;
        if !beta.is_finite() || !(0.0..45.0 * deg).contains(&beta) {
            return Err(ParamError::new("helix_angle_rad", beta, "in [0, 45°) = [0, 0.7854) rad"));
        }
        check_finite_range("face_width_m", self.face_width_m, 1e-6, 10.0, "in (0, 10] m")?;
        check_finite_range("profile_shift_p", self.profile_shift_p, -1.5, 1.5, "in [-1.5, 1.5]")?;
        check_finite_range("profile_shift_g", self.profile_shift_g, -1.5, 1.5, "in [-1.5, 1.5]")?;
        check_finite_range("addendum_mn", self.addendum_mn, 0.3, 2.0, "in [0.3, 2.0]")?;
        check_finite_range("dedendum_mn", self.dedendum_mn, 0.3, 2.5, "in [0.3, 2.5]")?;
        if self.dedendum_mn <= self.addendum_mn {
            return Err(ParamError::new(
                "dedendum_mn",
                self.dedendum_mn,
                format!("> addendum_mn = {} (tip clearance)", self.addendum_mn),
            ));
        }
        check_finite_range(
            "rack_fillet_radius_mn",
            self.rack_fillet_radius_mn,
            0.0,
            1.0,
            "in [0, 1]",
        )?;
        check_finite_range(
            "tip_relief_depth_mn",
            self.tip_relief_depth_mn,
            0.0,
            0.2,
            "in [0, 0.2]",
        )?;
        if self.tip_relief_depth_mn > 0.0 {
            check_finite_range(
                "tip_relief_height_mn",
                self.tip_relief_height_mn,
                1e-3,
                self.addendum_mn + self.dedendum_mn,
                format!(
                    "in (0, addendum_mn + dedendum_mn = {}]",
                    self.addendum_mn + self.dedendum_mn
                ),
            )?;
        } else {
            check_finite_range(
                "tip_relief_height_mn",
                self.tip_relief_height_mn,
                0.0,
                self.addendum_mn + self.dedendum_mn,
                "finite and >= 0",
            )?;
        }
        check_finite_range(
            "tip_rounding_radius_mn",
            self.tip_rounding_radius_mn,
            0.0,
            0.5,
            "in [0, 0.5]",
        )?;
        check_finite_range("normal_backlash_mn", self.normal_backlash_mn, 0.0, 0.5, "in [0, 0.5]")?;
        check_finite_range("bore_diameter_m", self.bore_diameter_m, 1e-6, 100.0, "> 0")?;
        for (key, m) in [("material_p", &self.material_p), ("material_g", &self.material_g)] {
            check_finite_range(
                &format!("{key}.youngs_modulus_pa"),
                m.youngs_modulus_pa,
                1e6,
                1e13,
                "in [1e6, 1e13] Pa",
            )?;
            let nu = m.poisson_ratio;
            if !nu.is_finite() || nu <= 0.0 || nu >= 0.5 {
                return Err(ParamError::new(&format!("{key}.poisson_ratio"), nu, "in (0, 0.5)"));
            }
            check_finite_range(
                &format!("{key}.density_kg_m3"),
                m.density_kg_m3,
                1.0,
                1e5,
                "in [1, 1e5] kg/m³",
            )?;
        }
        check_d_mesh(self.d_mesh_n_s_per_m)?;
        let d = &self.drive;
        check_finite_range("drive.torque_nm", d.torque_nm, -1e9, 1e9, "finite, |M| <= 1e9 N·m")?;
        check_finite_range("drive.j1_kgm2", d.j1_kgm2, 1e-12, 1e9, "> 0")?;
        check_finite_range("drive.j2_kgm2", d.j2_kgm2, 1e-12, 1e9, "> 0")?;
        check_finite_range("drive.c1_nm_per_rad", d.c1_nm_per_rad, 1e-9, 1e15, "> 0")?;
        check_finite_range("drive.c2_nm_per_rad", d.c2_nm_per_rad, 1e-9, 1e15, "> 0")?;
        check_finite_range("drive.d1_nms_per_rad", d.d1_nms_per_rad, 0.0, 1e12, ">= 0")?;
        check_finite_range("drive.d2_nms_per_rad", d.d2_nms_per_rad, 0.0, 1e12, ">= 0")?;
        Ok(())
    }
}

/// `Ok` when `value` is finite and in `[lo, hi]`, else a [`ParamError`] with `allowed`.
/// Largest mesh damping coefficient d_mesh (Eq. 14), N·s/m: the range of the JSON key
/// `d_mesh_n_s_per_m` (FMI parameter `d_mesh`) is [0, D_MESH_MAX_N_S_PER_M].
pub const D_MESH_MAX_N_S_PER_M: f64 = 1e9;

/// Checks a mesh damping coefficient against its range [0, [`D_MESH_MAX_N_S_PER_M`]] N·s/m:
/// the one check behind the pair's validation and every later change of the tunable damping
/// (FMU `d_mesh`, C API `hgm_set_d_mesh`, Python).
pub fn check_d_mesh(d_mesh: f64) -> Result<(), ParamError> {
    check_finite_range("d_mesh_n_s_per_m", d_mesh, 0.0, D_MESH_MAX_N_S_PER_M, "in [0, 1e9] N·s/m")
}

pub(crate) fn check_finite_range(
    name: &str,
    value: f64,
    lo: f64,
    hi: f64,
    allowed: impl Into<String>,
) -> Result<(), ParamError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(ParamError::new(name, value, allowed))
    }
}
