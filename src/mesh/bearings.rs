//! Bearing loads: the statics of each gear's shaft, rigid, on two bearings, under the mesh
//! force and tilting moments of [`super::forces`].
//!
//! # Arrangement
//! Each shaft (pinion, gear) runs along its gear's axis, parallel to z in the housing frame of
//! [`super::forces`]; its gear's centre is at z_c = b/2. It sits in a **locating** bearing at
//! z = z_L, which takes radial (x, y) and axial (z) load, and a **floating** bearing at
//! z = z_F ≠ z_L, which takes radial load only (the usual locating/floating arrangement). The
//! bearings act on the axis; the torque about the axis is carried by the shaft's couplings,
//! not by the bearings.
//!
//! # Reactions
//! With F the mesh force on the gear (N) and M = (M_x, M_y) its tilting moment about the gear's
//! centre (N·m), the reactions R_L, R_F (the force of each bearing on the shaft, N) satisfy
//! R_L + R_F + F = 0 and, about the centre, with levers d = z − z_c along the axis
//! ((0, 0, d) × R = (−d·R_y, d·R_x, 0)), −d_L·R_L,y − d_F·R_F,y + M_x = 0 and
//! d_L·R_L,x + d_F·R_F,x + M_y = 0. Hence, with L = d_L − d_F = z_L − z_F:
//!
//! ```text
//! R_L,x = (d_F·F_x − M_y)/L,   R_F,x = −F_x − R_L,x
//! R_L,y = (d_F·F_y + M_x)/L,   R_F,y = −F_y − R_L,y
//! R_L,z = −F_z,                R_F,z = 0
//! ```
//!
//! Linear in (F, M), so the mean over a mesh cycle is the reaction to the mean load, and the
//! spectrum of a reaction is the same combination of the loads' spectra.
//!
//! # Checks
//! Positions are finite, within ±[`BEARING_Z_M`]'s range, and the two bearings of a shaft at
//! least [`MIN_BEARING_SPAN_M`] apart (a shorter span makes the reactions grow as 1/L without
//! bound); the error names the key and the limit.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::params::Bounds;

/// Axial position of a bearing in the housing frame, m: ±1000 m (any real shaft).
pub const BEARING_Z_M: Bounds<f64> = Bounds::new(-1e3, 1e3, "m");

/// Smallest distance between the locating and the floating bearing of a shaft, m (1 µm).
pub const MIN_BEARING_SPAN_M: f64 = 1e-6;

/// The two bearings of one shaft: axial positions z (m) in the housing frame of
/// [`super::forces`] (z = 0 at the end face ζ = 0, the gear's centre at z = b/2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftBearings {
    /// Position of the locating bearing (radial and axial load), m.
    pub locating_z_m: f64,
    /// Position of the floating bearing (radial load only), m.
    pub floating_z_m: f64,
}

impl ShaftBearings {
    /// Checks the positions (see the module docs); `shaft` names the shaft in the error
    /// (`pinion` or `gear`).
    pub fn check(&self, shaft: &str) -> Result<(), ParamError> {
        BEARING_Z_M.check(&format!("{shaft}.locating_z_m"), self.locating_z_m)?;
        BEARING_Z_M.check(&format!("{shaft}.floating_z_m"), self.floating_z_m)?;
        let span = (self.locating_z_m - self.floating_z_m).abs();
        if span < MIN_BEARING_SPAN_M {
            return Err(ParamError::new(
                &format!("{shaft}.floating_z_m"),
                self.floating_z_m,
                format!(
                    "|locating_z_m − floating_z_m| >= {MIN_BEARING_SPAN_M:.0e} m (the \
                     locating bearing is at {:.6e} m)",
                    self.locating_z_m
                ),
            ));
        }
        Ok(())
    }

    /// The reactions `[locating, floating]` (force of each bearing on the shaft, x, y, z, N)
    /// to the mesh force `force` (N) and tilting moment `moment` (x, y, N·m) about the gear's
    /// centre at z = `center_z` (m): the formulas of the module docs.
    pub fn reactions(&self, center_z: f64, force: [f64; 3], moment: [f64; 2]) -> [[f64; 3]; 2] {
        let d_l = self.locating_z_m - center_z;
        let d_f = self.floating_z_m - center_z;
        let span = d_l - d_f;
        let lx = (d_f * force[0] - moment[1]) / span;
        let ly = (d_f * force[1] + moment[0]) / span;
        [[lx, ly, -force[2]], [-force[0] - lx, -force[1] - ly, 0.0]]
    }
}

/// The bearings of both shafts (`helical-gear static --bearings FILE`, Python
/// `bearing_loads`): JSON `{"pinion": {"locating_z_m": …, "floating_z_m": …}, "gear": {…}}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingArrangement {
    /// The pinion shaft's bearings.
    pub pinion: ShaftBearings,
    /// The gear shaft's bearings.
    pub gear: ShaftBearings,
}

/// Why a bearing arrangement's JSON was refused: its structure (not JSON, a key missing,
/// unknown or not a number; the message names the key path, e.g. `pinion.floating_z_m`), or a
/// value outside its range ([`ShaftBearings::check`]).
#[derive(Debug, Clone, PartialEq)]
pub enum BearingsError {
    /// The text is not the JSON of an arrangement; the message names the key.
    Json(String),
    /// A position outside its range.
    Param(ParamError),
}

impl std::fmt::Display for BearingsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BearingsError::Json(m) => write!(f, "bearing arrangement: {m}"),
            BearingsError::Param(e) => write!(f, "bearing arrangement: {e}"),
        }
    }
}

impl std::error::Error for BearingsError {}

impl From<ParamError> for BearingsError {
    fn from(e: ParamError) -> Self {
        BearingsError::Param(e)
    }
}

const SHAFTS: [&str; 2] = ["pinion", "gear"];
const POSITIONS: [&str; 2] = ["locating_z_m", "floating_z_m"];
const SCHEMA: &str = r#"{"pinion": {"locating_z_m": …, "floating_z_m": …}, "gear": {…}}"#;

/// The object at `path` of `v`, its keys checked against `allowed`.
fn object<'a>(
    v: &'a serde_json::Value,
    path: &str,
    allowed: &[&str],
) -> Result<&'a serde_json::Map<String, serde_json::Value>, BearingsError> {
    let o = v.as_object().ok_or_else(|| {
        BearingsError::Json(format!("`{path}` = {v}: allowed an object {SCHEMA}"))
    })?;
    if let Some(k) = o.keys().find(|k| !allowed.contains(&k.as_str())) {
        let at = if path == "bearings" { k.clone() } else { format!("{path}.{k}") };
        return Err(BearingsError::Json(format!(
            "unknown key `{at}` (allowed: {})",
            allowed.join(", ")
        )));
    }
    Ok(o)
}

impl BearingArrangement {
    /// Parses and checks JSON `{"pinion": {"locating_z_m": …, "floating_z_m": …}, "gear":
    /// {…}}`; the error names the key path (`gear.locating_z_m`), the value and the limit.
    pub fn from_json(text: &str) -> Result<Self, BearingsError> {
        let v: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| BearingsError::Json(format!("not JSON ({e}); expected {SCHEMA}")))?;
        let top = object(&v, "bearings", &SHAFTS)?;
        let mut z = [[0.0; 2]; 2];
        for (s, shaft) in SHAFTS.iter().enumerate() {
            let sv = top.get(*shaft).ok_or_else(|| {
                BearingsError::Json(format!("`{shaft}` is missing; expected {SCHEMA}"))
            })?;
            let so = object(sv, shaft, &POSITIONS)?;
            for (k, key) in POSITIONS.iter().enumerate() {
                let path = format!("{shaft}.{key}");
                let x = so.get(*key).ok_or_else(|| {
                    BearingsError::Json(format!("`{path}` is missing (a position in m)"))
                })?;
                z[s][k] = x.as_f64().ok_or_else(|| {
                    BearingsError::Json(format!(
                        "`{path}` = {x}: allowed a number {} (a position in m)",
                        BEARING_Z_M.allowed()
                    ))
                })?;
            }
        }
        let shaft = |z: [f64; 2]| ShaftBearings { locating_z_m: z[0], floating_z_m: z[1] };
        let a = Self { pinion: shaft(z[0]), gear: shaft(z[1]) };
        a.check()?;
        Ok(a)
    }

    /// Checks both shafts ([`ShaftBearings::check`]).
    pub fn check(&self) -> Result<(), ParamError> {
        self.pinion.check("pinion")?;
        self.gear.check("gear")
    }

    /// The reactions of the four bearings to one set of mesh outputs, in the order pinion
    /// locating, pinion floating, gear locating, gear floating (x, y, z, N); `face_width_m` b
    /// places the centres at z = b/2.
    pub fn reactions(&self, face_width_m: f64, o: &super::MeshOutputs) -> [[f64; 3]; 4] {
        let c = 0.5 * face_width_m;
        let [pl, pf] = self.pinion.reactions(c, o.force_p, o.moment_p);
        let [gl, gf] = self.gear.reactions(c, o.force_g, o.moment_g);
        [pl, pf, gl, gf]
    }

    /// (shaft, bearing, z) of the four bearings in the order of [`Self::reactions`].
    pub fn labels(&self) -> [(&'static str, &'static str, f64); 4] {
        [
            ("pinion", "locating", self.pinion.locating_z_m),
            ("pinion", "floating", self.pinion.floating_z_m),
            ("gear", "locating", self.gear.locating_z_m),
            ("gear", "floating", self.gear.floating_z_m),
        ]
    }
}

/// Single-sided amplitudes of `samples` (uniform over `periods` whole mesh periods) at the
/// mesh orders 1 … `orders`: 2·|X_j|/N at DFT bin j = k·periods (a direct DFT; N is a few
/// hundred at most). Orders above the Nyquist limit (k·periods > N/2) are left out.
pub fn order_amplitudes(samples: &[f64], periods: usize, orders: usize) -> Vec<f64> {
    let n = samples.len();
    let mut out = Vec::new();
    for k in 1..=orders {
        let j = k * periods;
        if n == 0 || 2 * j > n {
            break;
        }
        let (mut re, mut im) = (0.0, 0.0);
        for (i, x) in samples.iter().enumerate() {
            let a = std::f64::consts::TAU * (j * i % n) as f64 / n as f64;
            re += x * a.cos();
            im -= x * a.sin();
        }
        let scale = if 2 * j == n { 1.0 } else { 2.0 };
        out.push(scale * re.hypot(im) / n as f64);
    }
    out
}
