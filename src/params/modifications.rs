//! The flank modifications, misalignment and tooth deviations as users write them (the
//! `modifications` object of the gear-pair JSON): plain data with their serde schema and the
//! small formulas that read them (relief shapes, the deviation map's interpolation, hunting
//! periods). The separation these make between the flanks, and the checks against the pair's
//! geometry, are physics: [`crate::modifications`] (the keys, units, signs and formulas are
//! specified there).

use serde::{Deserialize, Serialize};

/// Shape of a relief: amount·t^p with t ∈ [0, 1] the relative position in the relief zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReliefShape {
    /// p = 1: a straight relief.
    #[default]
    Linear,
    /// p = 2: a parabolic relief, tangent to the unmodified flank where it starts.
    Parabolic,
}

impl ReliefShape {
    #[inline]
    pub(crate) fn apply(self, t: f64) -> f64 {
        match self {
            ReliefShape::Linear => t,
            ReliefShape::Parabolic => t * t,
        }
    }
}

/// End relief of the lead (both face ends). Amounts in m along the line of action (≥ 0,
/// removes material), lengths in m along the face (≥ 0, the two together at most b).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EndRelief {
    /// Relief at the ζ = 0 face end, m.
    pub amount_start_m: f64,
    /// Length of the relief zone at the ζ = 0 end, m.
    pub length_start_m: f64,
    /// Relief at the ζ = b₀ face end, m.
    pub amount_end_m: f64,
    /// Length of the relief zone at the ζ = b₀ end, m.
    pub length_end_m: f64,
    /// Linear or parabolic.
    pub shape: ReliefShape,
}

/// Tip relief given on the gear (rather than on the basic rack): the amount at the tip circle
/// and the diameter where it starts, the relief growing linearly or parabolically in roll
/// length. Acts on top of the basic-rack relief of the [`crate::GearPair`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TipRelief {
    /// Relief at the tip circle, m (≥ 0).
    pub amount_m: f64,
    /// Diameter where the relief starts, m (between the base and the tip diameter).
    pub start_diameter_m: f64,
    /// Linear or parabolic in roll length.
    pub shape: ReliefShape,
}

/// A measured or tabulated flank deviation over a (roll length × face) grid, interpolated
/// bilinearly and held constant outside the grid. Positive values remove material.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviationMap {
    /// Roll lengths L = √(r² − r_b²) of the grid rows, m, strictly increasing (≥ 2).
    pub roll_length_m: Vec<f64>,
    /// Axial positions z = ζ·m_n of the grid columns, m from the ζ = 0 face end, strictly
    /// increasing (≥ 2).
    pub face_m: Vec<f64>,
    /// Deviation at each grid node, m: `values_m[row][column]`.
    pub values_m: Vec<Vec<f64>>,
}

impl DeviationMap {
    pub(crate) fn value(&self, roll: f64, z: f64) -> f64 {
        let (i, u) = bracket(&self.roll_length_m, roll);
        let (j, v) = bracket(&self.face_m, z);
        let a = &self.values_m[i];
        let b = &self.values_m[i + 1];
        (1.0 - u) * ((1.0 - v) * a[j] + v * a[j + 1]) + u * ((1.0 - v) * b[j] + v * b[j + 1])
    }
}

impl DeviationMap {
    /// ∂(value)/∂(roll length) of the bilinear interpolant (0 where the roll length is clamped).
    pub(crate) fn d_roll(&self, roll: f64, z: f64) -> f64 {
        let xs = &self.roll_length_m;
        if roll <= xs[0] || roll >= xs[xs.len() - 1] {
            return 0.0;
        }
        let (i, _) = bracket(xs, roll);
        let (j, v) = bracket(&self.face_m, z);
        let a = &self.values_m[i];
        let b = &self.values_m[i + 1];
        let (va, vb) = ((1.0 - v) * a[j] + v * a[j + 1], (1.0 - v) * b[j] + v * b[j + 1]);
        (vb - va) / (xs[i + 1] - xs[i])
    }
}

/// Interval index i and fraction t ∈ [0, 1] of `x` in the increasing nodes `xs` (clamped).
pub(crate) fn bracket(xs: &[f64], x: f64) -> (usize, f64) {
    let n = xs.len();
    if x <= xs[0] {
        return (0, 0.0);
    }
    if x >= xs[n - 1] {
        return (n - 2, 1.0);
    }
    let i = xs.partition_point(|&v| v <= x).saturating_sub(1).min(n - 2);
    (i, (x - xs[i]) / (xs[i + 1] - xs[i]))
}

/// The modifications and deviations of one gear's driving flanks (see the module docs for the
/// formulas). Every key is optional in JSON; missing means zero.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlankModification {
    /// Lead crowning C_β, m (≥ 0): the separation at each face end relative to mid-face.
    pub lead_crowning_m: f64,
    /// Helix slope modification or deviation f_Hβ, m: separation at ζ = b₀ relative to ζ = 0.
    pub helix_slope_m: f64,
    /// End relief at both face ends.
    pub end_relief: EndRelief,
    /// Profile crowning C_α, m (≥ 0): separation at both ends of the active profile relative
    /// to its middle.
    pub profile_crowning_m: f64,
    /// Profile slope modification or deviation f_Hα, m: separation at the tip end of the
    /// active profile relative to its start.
    pub profile_slope_m: f64,
    /// Tip relief given on the gear.
    pub tip_relief: TipRelief,
    /// Position deviation of each tooth's flank, m: empty (none) or exactly z values.
    pub pitch_deviations_m: Vec<f64>,
    /// Eccentricity e, m (≥ 0).
    pub runout_m: f64,
    /// Phase ψ of the eccentricity, rad: the angular position (from tooth 0 in the direction
    /// of increasing tooth number) of the flank it moves furthest from the mating flank.
    pub runout_phase_rad: f64,
    /// A measured deviation map.
    pub deviation_map: Option<DeviationMap>,
}

/// Modifications of both gears and the pair's misalignment (the `modifications` object of the
/// [`crate::GearPair`] JSON; all zero by default).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Modifications {
    /// The pinion's driving flanks.
    pub pinion: FlankModification,
    /// The gear's driving flanks.
    pub gear: FlankModification,
    /// Equivalent mesh misalignment f_ma in the plane of action, m: the extra separation at
    /// the ζ = b₀ face end relative to the ζ = 0 end (positive: the ζ = b₀ end opens).
    pub mesh_misalignment_m: f64,
}

impl Modifications {
    /// True when nothing is given (the default); serialisation then leaves the key out.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Parses a `modifications` JSON object (the schema of docs/modifications.md; every key optional, missing = zero). Errors name the unknown or ill-typed key as serde reports it. Values are validated
    /// against the geometry later, by [`Modifications::validate`].
    /// An array where an object belongs (`[]`, which serde would read as all zero) is an
    /// error naming the key.
    pub fn from_json(text: &str) -> Result<Self, String> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("modifications JSON: {e}"))?;
        super::modification_objects("modifications JSON", &value, "modifications")?;
        serde_json::from_value(value).map_err(|e| format!("modifications JSON: {e}"))
    }

    /// `self` with `patch` (a JSON object of the same schema) merged in key by key: a key of
    /// `patch` replaces the same key of `self`, nested objects (`pinion`, `gear`,
    /// `end_relief`, `tip_relief`, `deviation_map`) are merged the same way, lists replace
    /// whole; keys not in `patch` keep their values. Errors: `patch` is not an object, or the
    /// result does not fit the schema (the message names the key).
    pub fn merged(&self, patch: &serde_json::Value) -> Result<Self, String> {
        fn merge(base: &mut serde_json::Value, patch: &serde_json::Value) {
            match (base, patch) {
                (serde_json::Value::Object(b), serde_json::Value::Object(p)) => {
                    for (k, v) in p {
                        merge(b.entry(k.clone()).or_insert(serde_json::Value::Null), v);
                    }
                }
                (b, p) => *b = p.clone(),
            }
        }
        if !patch.is_object() {
            return Err(format!("modifications: expected a JSON object, got {patch}"));
        }
        let mut base = serde_json::to_value(self).map_err(|e| format!("modifications: {e}"))?;
        merge(&mut base, patch);
        serde_json::from_value(base).map_err(|e| format!("modifications JSON: {e}"))
    }

    /// True when any tooth-by-tooth deviation (pitch deviations or runout) is given: the mesh
    /// then repeats only after the hunting period.
    pub fn has_tooth_deviations(&self) -> bool {
        [&self.pinion, &self.gear]
            .iter()
            .any(|g| g.runout_m != 0.0 || g.pitch_deviations_m.iter().any(|&e| e != 0.0))
    }

    /// Number of meshes after which the pair repeats with tooth deviations:
    /// z_p·z_g/gcd(z_p, z_g) (1410 for Table 1).
    pub fn hunting_meshes(z_p: u32, z_g: u32) -> u64 {
        let (mut a, mut b) = (z_p as u64, z_g as u64);
        while b != 0 {
            (a, b) = (b, a % b);
        }
        z_p as u64 * z_g as u64 / a.max(1)
    }

    /// Number of meshes after which the pair repeats: 1 without tooth-by-tooth deviations,
    /// z_p with deviations of the pinion only, z_g with deviations of the gear only, else the
    /// hunting period [`Modifications::hunting_meshes`].
    pub fn period_meshes(&self, z_p: u32, z_g: u32) -> u64 {
        let has = |g: &FlankModification| {
            g.runout_m != 0.0 || g.pitch_deviations_m.iter().any(|&e| e != 0.0)
        };
        match (has(&self.pinion), has(&self.gear)) {
            (false, false) => 1,
            (true, false) => z_p as u64,
            (false, true) => z_g as u64,
            (true, true) => Self::hunting_meshes(z_p, z_g),
        }
    }
}
