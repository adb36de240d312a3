//! Versioned compliance data of a gear pair: the FE influence grids of both gears
//! ([`super::influence_fe`]), the fitted constants of Eqs. 5–8 ([`super::fitted`]), the FE sizes
//! and timings, and the provenance that says which gear pair, mesh, depth h and code produced
//! them.
//!
//! # Where the data come from ([`ComplianceData::for_pair`])
//! 1. The **embedded** data of the paper's Table 1 pair, a checked-in resource
//!    (`resources/compliance_table1.json`, compiled into the library), when its key matches the
//!    pair ([`ComplianceData::matches`]).
//! 2. Otherwise a **disk cache** file in [`CacheOptions::dir`], named by a 64-bit FNV-1a hash of
//!    the key's JSON ([`ComplianceData::cache_file_name`]), when it exists, parses, has this
//!    [`FORMAT_VERSION`], the default mesh density and depth h, and matches the pair. A file that
//!    fails any of these checks is not trusted: a warning goes to stderr and the data are
//!    recomputed (and the file replaced).
//! 3. Otherwise they are **computed** (FE of both gears at [`GearMeshDensity::default`] and
//!    h = [`DEFAULT_DEPTH_MN`]·m_n, then the fits; for Table 1 about 4 s in a release build on
//!    an idle 2-core machine) and written to the cache directory if one is set.
//!
//! The cache directory defaults to the environment variable `HELICAL_GEAR_CACHE_DIR`
//! ([`CACHE_DIR_ENV`]) when it is set and not empty ([`CacheOptions::default`]); without it
//! nothing is written to disk.
//!
//! # The key
//! [`ComplianceKey`] holds every parameter that changes the compliance: tooth numbers, module,
//! pressure and helix angles, face width, profile shifts, the basic rack (addendum, dedendum,
//! fillet, tip relief, tip rounding), the backlash (it thins the teeth), the bore (where the FE
//! model is fixed), and E and ν of both materials. It leaves out what does not: the material
//! densities, d_mesh and the drive line (torque, inertias, shafts). Two keys match when every
//! value is bitwise equal (JSON round-trips f64 exactly: serde_json's `float_roundtrip`).
//!
//! # Body support
//! The FE bodies are fixed at the pair's bore ([`BodySupport::Bore`]): φp, φg are hub angles and
//! the compliance includes the body between hub and teeth, which for Table 1 (15 mm bore)
//! carries about 70 % of the tooth-pair compliance. [`ComplianceData::compute_rim_fixed`]
//! computes the alternative the paper leaves open, each body fixed just inside its rim
//! ([`BodySupport::Rim`]; teeth and rim only), for the sensitivity study of the paper run; the
//! provenance records the support and its diameters, and such data are never read from or
//! written to the disk cache.
//!
//! # Regenerating the embedded resource
//! ```text
//! cargo run --release -- compliance --write-cache resources/compliance_table1.json
//! ```
//! computes the Table 1 data afresh (it never copies the embedded or cached data) and writes
//! them. The α* values of the grids are stored rounded to [`ALPHA_SIGNIFICANT_DIGITS`]
//! significant digits (far below the FE discretisation error of about 3 %), which keeps the
//! file near 1.9 MB; all other numbers are stored exactly. A test recomputes the data and checks
//! the resource against them.
//!
//! # The fit ([`FitRecord::fit`])
//! The constants of Eqs. 5–8 are fitted on the domain where Eq. 12 uses the formula, on loads
//! that the FE model represents without its nodal artefact:
//! * pairs of one contact line: observation and load on the same profile row
//!   ([`PairSelection::SameRow`]; see [`super::fitted`] for why the formula is meant for them);
//! * the profile rows up to the first row on the tip rounding: contacts reach the rounding only
//!   to τ ≤ 0.18 rad for Table 1 even at TE = 200 µm (≈ 6.5 × the static TE; checked by a test),
//!   so the first rounding row (τ = 0.27 rad at the default density) brackets every contact
//!   normal, and the rows beyond it (up to the radial normal at the tip circle, τ = 1.06 rad)
//!   carry no contact: [`FitRecord::max_tau_rad`];
//! * loads and observations at the axial Gauss abscissae of the FE elements
//!   ([`axial_gauss_resample`]), where the influence of a line load is smooth.
//!
//! [`FitRecord`] stores the fit's own σ(e_rel) (Eq. 9) and, on the node grid, σ over the same
//! domain, over all pairs of the fitted rows and over all same-tooth pairs, so the restriction
//! is visible in the numbers.
//!
//! Measured for Table 1 at the default density (11 × 13 grid; σ of e_rel, pinion / gear):
//!
//! | fitted and measured on | σ(e_rel) |
//! | --- | --- |
//! | all 20 449 node pairs | 0.30 / 0.78 |
//! | same-row node pairs, all rows | 0.134 / 0.190 |
//! | same-row node pairs, rows up to τ = 0.27 rad | 0.027 / 0.024 |
//! | the same at the Gauss abscissae (stored) | 0.021 / 0.016 |
//! | the same without the rounding row | 0.020 / 0.015 |
//!
//! Across the profile at equal ζ the formula gives √(ψψ_F), while the FE data at depth h have
//! a near field there (the neighbouring rows, 0.3·m_n away, lie 15–25 % below √(ψψ_F)), and on
//! the rows beyond the first rounding row α* turns with the normal towards the radial
//! direction, which the linear τ terms of Eq. 6 cannot follow: these pairs dominate the first
//! two lines; Eq. 12 never uses them. At the nodes, loads on corner and mid-side node levels
//! alternate by ±5 % of the diagonal (see [`super::influence_fe`]); the Gauss abscissae remove
//! that. With two elements on the tip rounding (the earlier default density, first rounding
//! row at τ = 0.53 rad) the stored value was 0.031 / 0.026: the linear τ terms then had to
//! bridge 0.53 rad.
//!
//! The fit takes about 0.02 s per gear (release build).

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::InfluenceGrid;
/// The error of the compliance computations ([`super::error`]), re-exported where it was.
pub use super::error::ComplianceError;
use super::fe::gear_mesh::GearMeshDensity;
use super::fitted::{
    Deviation, FitError, FitOptions, FitReport, FittedInfluence, InfluenceParameters, PairSelection,
};
use super::influence_fe::{DEFAULT_DEPTH_MN, FeInfluence, axial_gauss_resample, fe_influence};
use super::interpolated::InterpolatedInfluence;
use super::stiffness::{PairStiffness, pair_stiffness};
use crate::geometry::{Member, PairGeometry};
use crate::params::GearPair;

/// Version of the data format; files of another version are not read.
pub const FORMAT_VERSION: u32 = 1;

/// Environment variable naming the default disk-cache directory ([`CacheOptions::default`]).
pub const CACHE_DIR_ENV: &str = "HELICAL_GEAR_CACHE_DIR";

/// Significant digits of the α* values written by [`ComplianceData::to_json`].
pub const ALPHA_SIGNIFICANT_DIGITS: usize = 10;

/// Command that regenerates the embedded resource.
pub const TABLE1_COMMAND: &str =
    "cargo run --release -- compliance --write-cache resources/compliance_table1.json";

/// The embedded Table 1 data (see the module docs).
const TABLE1_JSON: &str = include_str!("../../resources/compliance_table1.json");

/// Every gear-pair parameter that changes the compliance (see the module docs). Units as in
/// [`GearPair`]: SI, basic-rack quantities in units of m_n.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ComplianceKey {
    /// Number of pinion teeth.
    pub z_p: u32,
    /// Number of gear teeth.
    pub z_g: u32,
    /// Normal module m_n, m.
    pub normal_module_m: f64,
    /// Normal pressure angle of the basic rack, rad.
    pub pressure_angle_rad: f64,
    /// Helix angle at the reference cylinder, rad.
    pub helix_angle_rad: f64,
    /// Face width b, m.
    pub face_width_m: f64,
    /// Profile shift coefficient of the pinion.
    pub profile_shift_p: f64,
    /// Profile shift coefficient of the gear.
    pub profile_shift_g: f64,
    /// Basic-rack addendum, in m_n.
    pub addendum_mn: f64,
    /// Basic-rack dedendum, in m_n.
    pub dedendum_mn: f64,
    /// Basic-rack fillet radius, in m_n.
    pub rack_fillet_radius_mn: f64,
    /// Tip relief depth at the rack tip, in m_n.
    pub tip_relief_depth_mn: f64,
    /// Tip relief height, in m_n.
    pub tip_relief_height_mn: f64,
    /// Tip rounding radius, in m_n.
    pub tip_rounding_radius_mn: f64,
    /// Normal backlash, in m_n.
    pub normal_backlash_mn: f64,
    /// Bore diameter of both gears, m.
    pub bore_diameter_m: f64,
    /// Young's modulus of the pinion, Pa.
    pub youngs_modulus_p_pa: f64,
    /// Poisson's ratio of the pinion.
    pub poisson_ratio_p: f64,
    /// Young's modulus of the gear, Pa.
    pub youngs_modulus_g_pa: f64,
    /// Poisson's ratio of the gear.
    pub poisson_ratio_g: f64,
}

impl ComplianceKey {
    /// The key of gear pair `p`.
    pub fn of(p: &GearPair) -> Self {
        Self {
            z_p: p.z_p,
            z_g: p.z_g,
            normal_module_m: p.normal_module_m,
            pressure_angle_rad: p.pressure_angle_rad,
            helix_angle_rad: p.helix_angle_rad,
            face_width_m: p.face_width_m,
            profile_shift_p: p.profile_shift_p,
            profile_shift_g: p.profile_shift_g,
            addendum_mn: p.addendum_mn,
            dedendum_mn: p.dedendum_mn,
            rack_fillet_radius_mn: p.rack_fillet_radius_mn,
            tip_relief_depth_mn: p.tip_relief_depth_mn,
            tip_relief_height_mn: p.tip_relief_height_mn,
            tip_rounding_radius_mn: p.tip_rounding_radius_mn,
            normal_backlash_mn: p.normal_backlash_mn,
            bore_diameter_m: p.bore_diameter_m,
            youngs_modulus_p_pa: p.material_p.youngs_modulus_pa,
            poisson_ratio_p: p.material_p.poisson_ratio,
            youngs_modulus_g_pa: p.material_g.youngs_modulus_pa,
            poisson_ratio_g: p.material_g.poisson_ratio,
        }
    }

    /// 64-bit FNV-1a hash of the key's compact JSON (stable across runs and platforms).
    pub fn hash(&self) -> u64 {
        let text = serde_json::to_string(self).unwrap_or_default();
        fnv1a(text.as_bytes())
    }
}

/// 64-bit FNV-1a hash of `bytes`.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Where a [`ComplianceData`] came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DataSource {
    /// Computed in this process.
    #[default]
    Computed,
    /// The resource compiled into the library.
    Embedded,
    /// A disk-cache file.
    Disk,
}

impl DataSource {
    /// `"computed"`, `"embedded"` or `"disk"`.
    pub fn as_str(self) -> &'static str {
        match self {
            DataSource::Computed => "computed",
            DataSource::Embedded => "embedded",
            DataSource::Disk => "disk",
        }
    }
}

/// What produced the data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// [`FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// Version of this crate that computed the data.
    pub crate_version: String,
    /// The gear-pair parameters the data belong to.
    pub key: ComplianceKey,
    /// FE mesh density of both gears.
    pub density: GearMeshDensity,
    /// Depth h of Vedmar's division, m (the local term must use the same h).
    pub depth_h_m: f64,
    /// A command that regenerates the data.
    pub command: String,
    /// Where the FE bodies are fixed (absent in files: at the bore).
    #[serde(default, skip_serializing_if = "BodySupport::is_bore")]
    pub support: BodySupport,
}

/// Ratio of the rim radius r_K = r_f − `rim_depth_mn`·m_n to the radius of the circle where
/// [`BodySupport::Rim`] fixes a gear body: just inside the rim, one thin web ring below it.
pub const RIM_SUPPORT_RATIO: f64 = 1.06;

/// Where the FE model of each gear body is fixed, i.e. what the angles φp, φg of the mesh model
/// are the rotations of.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum BodySupport {
    /// At the bore of the gear pair ([`GearPair::bore_diameter_m`]): φp, φg are hub rotations
    /// and the compliance includes the body (web and rim) between hub and teeth. The model's
    /// default.
    #[default]
    Bore,
    /// Each body fixed just inside its rim, on the circle of diameter 2·r_K/[`RIM_SUPPORT_RATIO`]
    /// with r_K = r_f − `rim_depth_mn`·m_n of the FE mesh density: φp, φg are rim rotations and
    /// the compliance holds the teeth and the rim only (a rigid body below the rim). A
    /// sensitivity case ([`ComplianceData::compute_rim_fixed`]), not a production model.
    Rim {
        /// Diameter of the fixed circle of the pinion, m.
        diameter_p_m: f64,
        /// Diameter of the fixed circle of the gear, m.
        diameter_g_m: f64,
    },
}

impl BodySupport {
    /// True for [`BodySupport::Bore`].
    pub fn is_bore(&self) -> bool {
        *self == BodySupport::Bore
    }
}

/// Diameter (m) of the circle where [`BodySupport::Rim`] fixes the body of gear `g` of `pair`
/// meshed with `density`: 2·(r_f − `rim_depth_mn`·m_n)/[`RIM_SUPPORT_RATIO`].
pub fn rim_support_diameter(
    g: &crate::geometry::GearGeometry,
    pair: &GearPair,
    density: &GearMeshDensity,
) -> f64 {
    2.0 * (g.rf - density.rim_depth_mn * pair.normal_module_m) / RIM_SUPPORT_RATIO
}

/// Sizes and wall-clock times of the FE run of one gear.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeRecord {
    /// Total DOFs (3 × nodes).
    pub dofs: usize,
    /// Free DOFs (not fixed at the bore).
    pub free_dofs: usize,
    /// Number of hex20 elements.
    pub elements: usize,
    /// Number of unit load cases solved.
    pub load_cases: usize,
    /// Mesh generation, s.
    pub mesh_s: f64,
    /// Element stiffness and assembly, s.
    pub assembly_s: f64,
    /// Symbolic and numeric Cholesky factorisation, s.
    pub factorisation_s: f64,
    /// Solves of all load cases, s.
    pub solve_s: f64,
    /// Locating the points at depth h and interpolating, s.
    pub observe_s: f64,
}

impl FeRecord {
    /// The record of an FE influence run.
    pub fn of(inf: &FeInfluence) -> Self {
        let st = &inf.stats;
        Self {
            dofs: st.dofs,
            free_dofs: st.free_dofs,
            elements: st.elements,
            load_cases: st.solved_cases,
            mesh_s: inf.mesh_s,
            assembly_s: st.assembly_s,
            factorisation_s: st.factorisation_s(),
            solve_s: st.solve_s,
            observe_s: inf.observe_s,
        }
    }

    /// Total FE wall time (mesh, assembly, factorisation, solves, observation), s.
    pub fn total_s(&self) -> f64 {
        self.mesh_s + self.assembly_s + self.factorisation_s + self.solve_s + self.observe_s
    }
}

/// The fitted constants of Eqs. 5–8 of one gear and the quality of the fit (see the module
/// docs for the fitted domain).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// The constants (scaled form, see [`super::fitted`]).
    pub params: InfluenceParameters,
    /// Reference compliance, m/N (α* = `alpha_ref_m_per_n`·α).
    pub alpha_ref_m_per_n: f64,
    /// Face width b₀ = b/m_n used in Eqs. 6 and 8.
    pub b0: f64,
    /// Fitted pairs.
    pub pairs: PairSelection,
    /// Rows with τ above this value (rad) were not fitted (0: no rounding rows on the grid).
    pub max_tau_rad: f64,
    /// The fit's own report: e_rel (Eq. 9) over the fitted pairs at the axial Gauss abscissae.
    pub report: FitReport,
    /// e_rel against the node grid over the fitted domain (same selection and rows).
    pub nodes_domain: Deviation,
    /// e_rel against the node grid over all pairs of the fitted rows (any two rows).
    pub nodes_rows: Deviation,
    /// e_rel against the node grid over all same-tooth pairs (outside the domain included:
    /// on the rows beyond `max_tau_rad` Eq. 6, linear in τ, is extrapolated far and ψ(load)
    /// can come close to zero, so this number can be large).
    pub nodes_all: Deviation,
    /// Wall time of the fit (resampling, least squares, deviations), s.
    pub fit_s: f64,
}

impl FitRecord {
    /// Fits Eqs. 5–8 to the node grid `grid` of one gear with face width `b0` (units of m_n)
    /// on the domain described in the module docs, and measures the deviations.
    pub fn fit(grid: &InfluenceGrid, b0: f64) -> Result<Self, FitError> {
        let t0 = Instant::now();
        let first_rounding =
            grid.tau.iter().copied().filter(|&t| t > 0.0).fold(f64::INFINITY, f64::min);
        let max_tau = if first_rounding.is_finite() { first_rounding } else { 0.0 };
        let resampled = axial_gauss_resample(grid).map_err(|e| FitError::Input(e.to_string()))?;
        let pairs = PairSelection::SameRow;
        let options = FitOptions { pairs, max_tau, ..FitOptions::default() };
        let (fitted, report) = FittedInfluence::fit_with(&resampled, b0, &options)?;
        let nc = grid.zeta.len();
        let in_rows = |i: usize| grid.tau[i / nc] <= max_tau;
        let nodes_domain =
            fitted.deviation(grid, |i, j| in_rows(i) && in_rows(j) && pairs.selects(i, j, nc))?;
        let nodes_rows = fitted.deviation(grid, |i, j| in_rows(i) && in_rows(j))?;
        let nodes_all = fitted.deviation(grid, |_, _| true)?;
        Ok(Self {
            params: fitted.params,
            alpha_ref_m_per_n: fitted.alpha_ref,
            b0,
            pairs,
            max_tau_rad: max_tau,
            report,
            nodes_domain,
            nodes_rows,
            nodes_all,
            fit_s: t0.elapsed().as_secs_f64(),
        })
    }
}

/// The compliance data of one gear.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearCompliance {
    /// FE influence grid (observations on teeth −1, 0, +1 at depth h, loads on tooth 0).
    pub grid: InfluenceGrid,
    /// Fitted constants of Eqs. 5–8 and fit quality.
    pub fit: FitRecord,
    /// FE sizes and timings.
    pub fe: FeRecord,
}

/// Compliance data of a gear pair (see the module docs).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ComplianceData {
    /// What produced the data.
    pub provenance: Provenance,
    /// The pinion's data.
    pub pinion: GearCompliance,
    /// The gear's data.
    pub gear: GearCompliance,
    /// Where this value came from (not stored).
    #[serde(skip)]
    source: DataSource,
}

/// Settings of [`ComplianceData::for_pair`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CacheOptions {
    /// Disk-cache directory (created when needed); `None`: no disk cache.
    pub dir: Option<PathBuf>,
    /// Print the progress of an FE computation on stderr.
    pub progress: bool,
}

impl Default for CacheOptions {
    /// The directory from the environment variable [`CACHE_DIR_ENV`] (`HELICAL_GEAR_CACHE_DIR`)
    /// when it is set and not empty, else no disk cache; no progress output.
    fn default() -> Self {
        let dir = std::env::var_os(CACHE_DIR_ENV).filter(|v| !v.is_empty()).map(PathBuf::from);
        Self { dir, progress: false }
    }
}

impl CacheOptions {
    /// No disk cache, no progress output (embedded data or computation only).
    pub fn no_disk() -> Self {
        Self { dir: None, progress: false }
    }
}

/// `"pinion"` or `"gear"`.
pub fn member_name(m: Member) -> &'static str {
    match m {
        Member::Pinion => "pinion",
        Member::Gear => "gear",
    }
}

/// `v` rounded to `digits` significant digits (non-finite values unchanged).
fn round_significant(v: f64, digits: usize) -> f64 {
    if !v.is_finite() || v == 0.0 {
        return v;
    }
    format!("{:.*e}", digits.saturating_sub(1), v).parse().unwrap_or(v)
}

impl ComplianceData {
    /// Runs the FE model of both gears of `pair` with mesh `density` and depth `depth_h_m` (m),
    /// each body fixed at the bore, then the fits ([`FitRecord::fit`]). Progress goes to stderr
    /// when `progress` is true.
    pub fn compute(
        pair: &GearPair,
        density: &GearMeshDensity,
        depth_h_m: f64,
        progress: bool,
    ) -> Result<Self, ComplianceError> {
        Self::compute_with_support(pair, density, depth_h_m, false, progress)
    }

    /// As [`ComplianceData::compute`], but each gear body fixed just inside its rim
    /// ([`BodySupport::Rim`], diameters from [`rim_support_diameter`]): the compliance of the
    /// teeth and the rim alone, referred to the rim. For Table 1 at the default density the
    /// tooth-pair stiffness at the pitch point is c′ = 16.8 N/(mm·µm) against 5.02 with the
    /// bodies fixed at the 15 mm bore (see [`super::stiffness`]). The data carry the pair's
    /// key, so [`ComplianceData::for_pair`] never takes them from the disk cache.
    pub fn compute_rim_fixed(
        pair: &GearPair,
        density: &GearMeshDensity,
        depth_h_m: f64,
        progress: bool,
    ) -> Result<Self, ComplianceError> {
        Self::compute_with_support(pair, density, depth_h_m, true, progress)
    }

    fn compute_with_support(
        pair: &GearPair,
        density: &GearMeshDensity,
        depth_h_m: f64,
        rim: bool,
        progress: bool,
    ) -> Result<Self, ComplianceError> {
        let geo = PairGeometry::new(pair)?;
        let b0 = geo.b0();
        let mut members = Vec::with_capacity(2);
        let mut diameters = [pair.bore_diameter_m; 2];
        for (i, g) in [&geo.pinion, &geo.gear].into_iter().enumerate() {
            let member = member_name(g.member);
            let mut fe_pair = pair.clone();
            if rim {
                diameters[i] = rim_support_diameter(g, pair, density);
                fe_pair.bore_diameter_m = diameters[i];
                if progress {
                    eprintln!(
                        "compliance of the {member}: body fixed just inside the rim (diameter \
                         {:.2} mm)",
                        diameters[i] * 1e3
                    );
                }
            }
            let inf = fe_influence(g, &fe_pair, density, depth_h_m, progress)
                .map_err(|source| ComplianceError::Fe { member, source })?;
            let fit = FitRecord::fit(&inf.grid, b0)
                .map_err(|source| ComplianceError::Fit { member, source })?;
            if progress {
                eprintln!(
                    "compliance of the {member}: fit in {:.2} s, σ(e_rel) = {:.4} (node grid: \
                     {:.4} on the fitted domain, {:.4} over all pairs)",
                    fit.fit_s, fit.report.sigma_e_rel, fit.nodes_domain.std, fit.nodes_all.std
                );
            }
            let fe = FeRecord::of(&inf);
            members.push(GearCompliance { grid: inf.grid, fit, fe });
        }
        let gear = members.pop().ok_or_else(|| ComplianceError::Input("no gear data".into()))?;
        let pinion =
            members.pop().ok_or_else(|| ComplianceError::Input("no pinion data".into()))?;
        let key = ComplianceKey::of(pair);
        let default_run = *density == GearMeshDensity::default()
            && depth_h_m == DEFAULT_DEPTH_MN * pair.normal_module_m;
        let (command, support) = if rim {
            (
                "ComplianceData::compute_rim_fixed (library; the paper run's sensitivity case \
                 \"compliance referred to the rim\")"
                    .to_string(),
                BodySupport::Rim { diameter_p_m: diameters[0], diameter_g_m: diameters[1] },
            )
        } else if key == ComplianceKey::of(&GearPair::paper_table1()) && default_run {
            (TABLE1_COMMAND.to_string(), BodySupport::Bore)
        } else {
            (
                "helical-gear compliance --params PARAMS.json [--density coarse|default|refined] \
                 --write-cache FILE (PARAMS.json: a gear pair with this key)"
                    .to_string(),
                BodySupport::Bore,
            )
        };
        let provenance = Provenance {
            format_version: FORMAT_VERSION,
            crate_version: env!("CARGO_PKG_VERSION").to_string(),
            key,
            density: *density,
            depth_h_m,
            command,
            support,
        };
        let data = Self { provenance, pinion, gear, source: DataSource::Computed };
        data.check()?;
        Ok(data)
    }

    /// The embedded data of the paper's Table 1 pair at the default density (parsed once and
    /// shared). Errors only if the resource is corrupt.
    pub fn embedded_table1() -> Result<Arc<Self>, ComplianceError> {
        static EMBEDDED: OnceLock<Result<Arc<ComplianceData>, ComplianceError>> = OnceLock::new();
        EMBEDDED
            .get_or_init(|| {
                let mut d = Self::from_json(TABLE1_JSON).map_err(|e| {
                    ComplianceError::InvalidData(format!("embedded Table 1 resource: {e}"))
                })?;
                d.source = DataSource::Embedded;
                Ok(Arc::new(d))
            })
            .clone()
    }

    /// True iff every parameter of `pair` that changes the compliance ([`ComplianceKey`])
    /// equals the key of these data.
    pub fn matches(&self, pair: &GearPair) -> bool {
        self.provenance.key == ComplianceKey::of(pair)
    }

    /// The data for `pair`: embedded, from the disk cache, or computed (see the module docs).
    pub fn for_pair(pair: &GearPair, options: &CacheOptions) -> Result<Arc<Self>, ComplianceError> {
        pair.validate()?;
        let embedded = Self::embedded_table1()?;
        if embedded.matches(pair) {
            return Ok(embedded);
        }
        let density = GearMeshDensity::default();
        let depth = DEFAULT_DEPTH_MN * pair.normal_module_m;
        let path = options.dir.as_ref().map(|d| d.join(Self::cache_file_name(pair)));
        if let Some(path) = &path {
            if path.exists() {
                match Self::read_file(path) {
                    Ok(d)
                        if d.matches(pair)
                            && d.provenance.support.is_bore()
                            && d.provenance.density == density
                            && d.provenance.depth_h_m == depth =>
                    {
                        return Ok(Arc::new(d));
                    }
                    Ok(_) => eprintln!(
                        "warning: compliance cache {} belongs to another gear pair, mesh \
                         density, depth h or body support; recomputing",
                        path.display()
                    ),
                    Err(e) => eprintln!("warning: unusable compliance cache ({e}); recomputing"),
                }
            }
        }
        let data = Self::compute(pair, &density, depth, options.progress)?;
        if let Some(path) = &path {
            if let Err(e) = data.write_file(path) {
                eprintln!("warning: compliance cache not written ({e})");
            }
        }
        Ok(Arc::new(data))
    }

    /// File name of the disk-cache entry of `pair`: `compliance-<16 hex digits>.json` from
    /// [`ComplianceKey::hash`].
    pub fn cache_file_name(pair: &GearPair) -> String {
        format!("compliance-{:016x}.json", ComplianceKey::of(pair).hash())
    }

    /// Where these data came from.
    pub fn source(&self) -> DataSource {
        self.source
    }

    /// The data of `member`.
    pub fn member(&self, member: Member) -> &GearCompliance {
        match member {
            Member::Pinion => &self.pinion,
            Member::Gear => &self.gear,
        }
    }

    /// Total FE wall time of both gears when the data were computed, s.
    pub fn fe_seconds(&self) -> f64 {
        self.pinion.fe.total_s() + self.gear.fe.total_s()
    }

    /// The direct interpolation of `member`'s FE grid.
    pub fn interpolated(&self, member: Member) -> Result<InterpolatedInfluence, ComplianceError> {
        InterpolatedInfluence::new(self.member(member).grid.clone())
            .map_err(|e| ComplianceError::InvalidData(format!("{} grid: {e}", member_name(member))))
    }

    /// The fitted formula of `member` rebuilt from the stored constants, with the coupling to
    /// the neighbouring teeth interpolated from the grid.
    pub fn fitted(&self, member: Member) -> Result<FittedInfluence, ComplianceError> {
        let m = self.member(member);
        FittedInfluence::with_neighbours(
            m.fit.params,
            m.fit.b0,
            m.fit.alpha_ref_m_per_n,
            m.grid.clone(),
        )
        .map_err(|e| ComplianceError::InvalidData(format!("{} grid: {e}", member_name(member))))
    }

    /// The tooth-pair stiffness at the pitch point ([`super::stiffness::pair_stiffness`]) of
    /// `geo` with the interpolated same-tooth grids of these data and `slices` axial slices,
    /// loaded by the pinion torque `torque_nm` (N·m).
    /// Errors if the data do not match `geo`'s gear pair.
    pub fn pair_stiffness(
        &self,
        geo: &PairGeometry,
        slices: usize,
        torque_nm: f64,
    ) -> Result<PairStiffness, ComplianceError> {
        if !self.matches(&geo.params) {
            return Err(ComplianceError::Input(
                "the compliance data belong to another gear pair".into(),
            ));
        }
        let p = self.interpolated(Member::Pinion)?;
        let g = self.interpolated(Member::Gear)?;
        pair_stiffness(geo, &p, &g, slices, torque_nm)
    }

    /// Consistency checks of stored data: format version, valid grids with the provenance's
    /// depth, finite positive fit scales, finite constants.
    fn check(&self) -> Result<(), ComplianceError> {
        let p = &self.provenance;
        if p.format_version != FORMAT_VERSION {
            return Err(ComplianceError::InvalidData(format!(
                "format version {} (this library reads version {FORMAT_VERSION})",
                p.format_version
            )));
        }
        if !(p.depth_h_m.is_finite() && p.depth_h_m > 0.0) {
            return Err(ComplianceError::InvalidData(format!(
                "depth h = {} m must be finite and > 0",
                p.depth_h_m
            )));
        }
        for member in [Member::Pinion, Member::Gear] {
            let name = member_name(member);
            let m = self.member(member);
            m.grid
                .validate()
                .map_err(|e| ComplianceError::InvalidData(format!("{name} grid: {e}")))?;
            if m.grid.depth_h != p.depth_h_m {
                return Err(ComplianceError::InvalidData(format!(
                    "{name} grid depth h = {} m differs from the provenance's {} m",
                    m.grid.depth_h, p.depth_h_m
                )));
            }
            let f = &m.fit;
            if !(f.alpha_ref_m_per_n.is_finite() && f.alpha_ref_m_per_n > 0.0) {
                return Err(ComplianceError::InvalidData(format!(
                    "{name} alpha_ref = {} m/N must be finite and > 0",
                    f.alpha_ref_m_per_n
                )));
            }
            let b0 = p.key.face_width_m / p.key.normal_module_m;
            if !(f.b0.is_finite() && (f.b0 - b0).abs() <= 1e-12 * b0) {
                return Err(ComplianceError::InvalidData(format!(
                    "{name} fit b0 = {} differs from the key's face width b/m_n = {b0}",
                    f.b0
                )));
            }
            if let Some(k) = f.params.to_array().iter().position(|v| !v.is_finite()) {
                return Err(ComplianceError::InvalidData(format!(
                    "{name} fitted constant {k} is not finite"
                )));
            }
        }
        Ok(())
    }

    /// Parses and checks data written by [`ComplianceData::to_json`] (source: disk).
    pub fn from_json(text: &str) -> Result<Self, ComplianceError> {
        let mut d: Self = serde_json::from_str(text)
            .map_err(|e| ComplianceError::InvalidData(format!("JSON: {e}")))?;
        d.check()?;
        d.source = DataSource::Disk;
        Ok(d)
    }

    /// Compact JSON with α* rounded to [`ALPHA_SIGNIFICANT_DIGITS`] significant digits.
    pub fn to_json(&self) -> Result<String, ComplianceError> {
        let mut d = self.clone();
        for m in [&mut d.pinion, &mut d.gear] {
            for block in &mut m.grid.alpha {
                for v in block.iter_mut() {
                    *v = round_significant(*v, ALPHA_SIGNIFICANT_DIGITS);
                }
            }
        }
        serde_json::to_string(&d).map_err(|e| ComplianceError::InvalidData(format!("JSON: {e}")))
    }

    /// Reads and checks a data file.
    pub fn read_file(path: &Path) -> Result<Self, ComplianceError> {
        let text = std::fs::read_to_string(path).map_err(|e| ComplianceError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Self::from_json(&text).map_err(|e| match e {
            ComplianceError::InvalidData(m) => {
                ComplianceError::InvalidData(format!("{}: {m}", path.display()))
            }
            other => other,
        })
    }

    /// Writes [`ComplianceData::to_json`] to `path` (through a temporary file in the same
    /// directory and a rename, so readers never see a partial file); creates the directory.
    pub fn write_file(&self, path: &Path) -> Result<(), ComplianceError> {
        let io = |e: std::io::Error| ComplianceError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let text = self.to_json()?;
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(format!(".tmp{}", std::process::id()));
        let tmp = PathBuf::from(tmp);
        std::fs::write(&tmp, text).map_err(io)?;
        std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io(e)
        })
    }
}
