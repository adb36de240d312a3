//! Elastic supports of the gear bodies and the static equilibrium with the bodies displaced —
//! a specification.
//!
//! # Support
//! Each gear body sits on a linear elastic support at its centre at mid-face (the bearings and
//! the shaft seen from the gear): the force and moment the support exerts on the body are
//!
//! ```text
//! R = −K·p − C·ṗ,    p = (u_x, u_y, u_z, θ_x, θ_y)  (the body's pose, [`super::pose`])
//! ```
//!
//! with K the 5 × 5 stiffness (N/m, N/rad, N·m/m, N·m/rad by block) and C the damping of the
//! same shape (N·s/m …). K must be symmetric and positive definite (a support that holds the
//! body in every direction); C symmetric and positive semi-definite. A body without a support
//! is held rigidly (its pose stays zero). The body's mass (kg) and transverse moment of inertia
//! about its centre (kg·m²) are part of the description for the dynamics of the bodies.
//!
//! # JSON
//! `{"pinion": {...}, "gear": {...}}`, each with `mass_kg`, `j_transverse_kgm2` and either
//! `"stiffness": {"radial_n_per_m", "axial_n_per_m", "tilt_nm_per_rad"}` (isotropic in the
//! transverse plane: K = diag(k_r, k_r, k_a, k_t, k_t)) or `"stiffness_matrix"`: 5 × 5 rows in
//! the order of p; `"damping"` likewise (`"radial_ns_per_m"`, `"axial_ns_per_m"`,
//! `"tilt_nms_per_rad"` or `"damping_matrix"`; missing: none). A missing body is rigid.
//! Instead of the stiffness, `"shaft": {"bending_stiffness_nm2", "bearings": [{"z_m",
//! "radial_n_per_m", "axial_n_per_m"?}, …]}` describes the gear's shaft on 2 … 4 elastic
//! bearings, from which the stiffness at the gear centre is derived ([`super::shaft`]; read
//! with the pair's face width, [`Supports::from_json_for`], since the gear centre is at b/2).
//!
//! # Static equilibrium with the bodies displaced
//! At pinion angle φp and pinion torque M the unknowns are TE and both poses. The mesh's force
//! and moments on each body at its displaced centre, W(p_p, p_g) (F_x, F_y, F_z, M_x, M_y,
//! [`super::forces`]), balance the supports: K·p = W. [`supported_equilibrium`] solves it by a
//! fixed point: TE from the torque balance at the current poses
//! ([`super::statics::equilibrium`]), then p = K⁻¹·W, until the poses change by less than
//! 1e-10 of their size (and 1e-16 m). The torque fixes the mesh force's size, so W depends on
//! the poses only through the load distribution and the moment arms, weakly: the iteration
//! contracts by the ratio of that dependence to the support's stiffness (a few iterations for
//! supports stiffer than the tooth pair; an error naming the iteration count otherwise).

use serde_json::Value;

use super::shaft::ShaftSupport;
use super::statics::{Equilibrium, EquilibriumSettings, StaticCurve, curve_points, equilibrium};
use super::{BodyPose, MeshError, MeshTorques};
use crate::error::ParamError;

/// One body's support (module docs): SI units, the order of [`BodyPose::values`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support {
    /// The body's mass, kg.
    pub mass_kg: f64,
    /// The body's moment of inertia about a transverse axis through its centre, kg·m².
    pub j_transverse_kgm2: f64,
    /// Stiffness K (N/m, N/rad, N·m/m, N·m/rad by block).
    pub stiffness: [[f64; 5]; 5],
    /// Damping C (N·s/m, N·s/rad, N·m·s/m, N·m·s/rad by block).
    pub damping: [[f64; 5]; 5],
    /// The shaft on its bearings the stiffness was derived from (the JSON's `shaft` form,
    /// [`super::shaft`]); `None` when the stiffness was given at the gear centre.
    pub shaft: Option<ShaftSupport>,
}

/// The supports of both bodies; `None`: held rigidly.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Supports {
    /// The pinion body's support.
    pub pinion: Option<Support>,
    /// The gear body's support.
    pub gear: Option<Support>,
}

impl Support {
    /// The force and moment (N, N·m) the support exerts on the body at pose `p` and rate
    /// `rate`: R = −K·p − C·ṗ.
    pub fn reaction(&self, p: &BodyPose, rate: &BodyPose) -> [f64; 5] {
        let (x, v) = (p.values(), rate.values());
        std::array::from_fn(|i| {
            -(0..5).map(|j| self.stiffness[i][j] * x[j] + self.damping[i][j] * v[j]).sum::<f64>()
        })
    }

    /// The pose at which the support balances the load `w` (N, N·m): K⁻¹·w.
    pub fn static_pose(&self, w: &[f64; 5]) -> BodyPose {
        let l = cholesky(&self.stiffness).expect("checked positive definite");
        BodyPose::from_values(cholesky_solve(&l, w))
    }
}

impl Supports {
    /// Reads the JSON of the module docs; errors name the key (`supports.gear.stiffness`, …).
    /// The shaft form needs the gear pair's face width ([`Self::from_json_for`]) and is an
    /// error here.
    pub fn from_json(text: &str) -> Result<Self, ParamError> {
        Self::from_json_for(text, f64::NAN)
    }

    /// [`Self::from_json`] for a gear pair of face width `face_width_m` (m), which places the
    /// gear centres of the shaft form at b/2.
    pub fn from_json_for(text: &str, face_width_m: f64) -> Result<Self, ParamError> {
        let v: Value = serde_json::from_str(text)
            .map_err(|e| ParamError::new("supports", f64::NAN, format!("valid JSON: {e}")))?;
        let Value::Object(map) = &v else {
            return Err(ParamError::new(
                "supports",
                f64::NAN,
                "a JSON object {\"pinion\", \"gear\"}",
            ));
        };
        for k in map.keys() {
            if k != "pinion" && k != "gear" {
                return Err(ParamError::new(
                    &format!("supports.{k}"),
                    f64::NAN,
                    "one of pinion, gear",
                ));
            }
        }
        let body = |name: &str| -> Result<Option<Support>, ParamError> {
            map.get(name)
                .map(|b| parse_body(&format!("supports.{name}"), b, 0.5 * face_width_m))
                .transpose()
        };
        Ok(Self { pinion: body("pinion")?, gear: body("gear")? })
    }
}

fn parse_body(key: &str, v: &Value, center_z: f64) -> Result<Support, ParamError> {
    let Value::Object(m) = v else {
        return Err(ParamError::new(key, f64::NAN, "a JSON object"));
    };
    const KEYS: [&str; 7] = [
        "mass_kg",
        "j_transverse_kgm2",
        "stiffness",
        "stiffness_matrix",
        "shaft",
        "damping",
        "damping_matrix",
    ];
    for k in m.keys() {
        if !KEYS.contains(&k.as_str()) {
            return Err(ParamError::new(
                &format!("{key}.{k}"),
                f64::NAN,
                format!("one of {}", KEYS.join(", ")),
            ));
        }
    }
    let positive = |k: &str| -> Result<f64, ParamError> {
        let name = format!("{key}.{k}");
        let x = m
            .get(k)
            .and_then(Value::as_f64)
            .ok_or_else(|| ParamError::new(&name, f64::NAN, "a number (required)"))?;
        if x.is_finite() && x > 0.0 && x < 1e9 {
            Ok(x)
        } else {
            Err(ParamError::new(&name, x, "finite, > 0 and < 1e9"))
        }
    };
    let mass_kg = positive("mass_kg")?;
    let j_transverse_kgm2 = positive("j_transverse_kgm2")?;
    let given = matrix(
        key,
        m,
        ("stiffness", "stiffness_matrix"),
        ["radial_n_per_m", "axial_n_per_m", "tilt_nm_per_rad"],
        true,
    )?;
    let shaft =
        m.get("shaft").map(|s| parse_shaft(&format!("{key}.shaft"), s, center_z)).transpose()?;
    let stiffness = match (given, &shaft) {
        (Some(_), Some(_)) => {
            return Err(ParamError::new(
                &format!("{key}.shaft"),
                f64::NAN,
                "either `shaft` or `stiffness`/`stiffness_matrix`, not both",
            ));
        }
        (Some(k), None) => k,
        (None, Some(s)) => s.stiffness(),
        (None, None) => {
            return Err(ParamError::new(
                &format!("{key}.stiffness"),
                f64::NAN,
                "`stiffness`, `stiffness_matrix` or `shaft` (required)",
            ));
        }
    };
    if cholesky(&stiffness).is_none() {
        return Err(ParamError::new(
            &format!("{key}.stiffness"),
            f64::NAN,
            "symmetric and positive definite",
        ));
    }
    let damping = matrix(
        key,
        m,
        ("damping", "damping_matrix"),
        ["radial_ns_per_m", "axial_ns_per_m", "tilt_nms_per_rad"],
        false,
    )?
    .unwrap_or([[0.0; 5]; 5]);
    Ok(Support { mass_kg, j_transverse_kgm2, stiffness, damping, shaft })
}

/// The shaft form `{"bending_stiffness_nm2", "bearings": [{"z_m", "radial_n_per_m",
/// "axial_n_per_m"?}, …]}` ([`super::shaft`]) for a gear centred at `center_z` (m; NaN: not
/// known, an error).
fn parse_shaft(key: &str, v: &Value, center_z: f64) -> Result<ShaftSupport, ParamError> {
    let Value::Object(m) = v else {
        return Err(ParamError::new(key, f64::NAN, "a JSON object"));
    };
    if !center_z.is_finite() {
        return Err(ParamError::new(
            key,
            f64::NAN,
            "read with the gear pair (the shaft form places the gear centre at b/2): \
             Supports::from_json_for",
        ));
    }
    for k in m.keys() {
        if k != "bending_stiffness_nm2" && k != "bearings" {
            return Err(ParamError::new(
                &format!("{key}.{k}"),
                f64::NAN,
                "one of bending_stiffness_nm2, bearings",
            ));
        }
    }
    let ei = m.get("bending_stiffness_nm2").and_then(Value::as_f64).ok_or_else(|| {
        ParamError::new(&format!("{key}.bending_stiffness_nm2"), f64::NAN, "a number (required)")
    })?;
    let list = m.get("bearings").and_then(Value::as_array).ok_or_else(|| {
        ParamError::new(&format!("{key}.bearings"), f64::NAN, "a list of bearings (required)")
    })?;
    if list.len() > super::shaft::MAX_SHAFT_BEARINGS {
        return Err(ParamError::new(
            &format!("{key}.bearings"),
            list.len() as f64,
            format!("2 … {} bearings", super::shaft::MAX_SHAFT_BEARINGS),
        ));
    }
    let mut bearings = Vec::with_capacity(list.len());
    for (i, b) in list.iter().enumerate() {
        let bk = format!("{key}.bearings[{i}]");
        let Value::Object(o) = b else {
            return Err(ParamError::new(&bk, f64::NAN, "a JSON object"));
        };
        for k in o.keys() {
            if !["z_m", "radial_n_per_m", "axial_n_per_m"].contains(&k.as_str()) {
                return Err(ParamError::new(
                    &format!("{bk}.{k}"),
                    f64::NAN,
                    "one of z_m, radial_n_per_m, axial_n_per_m",
                ));
            }
        }
        let num = |k: &str, default: Option<f64>| -> Result<f64, ParamError> {
            match (o.get(k), default) {
                (None, Some(d)) => Ok(d),
                (v, _) => v.and_then(Value::as_f64).ok_or_else(|| {
                    ParamError::new(&format!("{bk}.{k}"), f64::NAN, "a number (required)")
                }),
            }
        };
        bearings.push((
            num("z_m", None)?,
            num("radial_n_per_m", None)?,
            num("axial_n_per_m", Some(0.0))?,
        ));
    }
    ShaftSupport::new(key, ei, &bearings, center_z)
}

/// The matrix of `diag_key` (three diagonal values) or `full_key` (5 × 5), checked finite,
/// symmetric, with a non-negative (or, if `positive`, positive) diagonal.
fn matrix(
    key: &str,
    m: &serde_json::Map<String, Value>,
    (diag_key, full_key): (&str, &str),
    names: [&str; 3],
    positive: bool,
) -> Result<Option<[[f64; 5]; 5]>, ParamError> {
    let limit = |name: &str, x: f64| -> Result<f64, ParamError> {
        let ok = x.is_finite() && x.abs() < 1e16 && if positive { x > 0.0 } else { x >= 0.0 };
        if ok {
            Ok(x)
        } else {
            let what = if positive { "finite, > 0 and < 1e16" } else { "finite, >= 0 and < 1e16" };
            Err(ParamError::new(name, x, what))
        }
    };
    match (m.get(diag_key), m.get(full_key)) {
        (Some(_), Some(_)) => Err(ParamError::new(
            &format!("{key}.{full_key}"),
            f64::NAN,
            format!("either `{diag_key}` or `{full_key}`, not both"),
        )),
        (None, None) => Ok(None),
        (Some(Value::Object(d)), None) => {
            for k in d.keys() {
                if !names.contains(&k.as_str()) {
                    return Err(ParamError::new(
                        &format!("{key}.{diag_key}.{k}"),
                        f64::NAN,
                        format!("one of {}", names.join(", ")),
                    ));
                }
            }
            let mut v = [0.0; 3];
            for (x, n) in v.iter_mut().zip(names) {
                let name = format!("{key}.{diag_key}.{n}");
                let y = d
                    .get(n)
                    .and_then(Value::as_f64)
                    .ok_or_else(|| ParamError::new(&name, f64::NAN, "a number (required)"))?;
                *x = limit(&name, y)?;
            }
            let mut k = [[0.0; 5]; 5];
            for (i, x) in [v[0], v[0], v[1], v[2], v[2]].into_iter().enumerate() {
                k[i][i] = x;
            }
            Ok(Some(k))
        }
        (Some(_), None) => {
            Err(ParamError::new(&format!("{key}.{diag_key}"), f64::NAN, "a JSON object"))
        }
        (None, Some(full)) => {
            let name = format!("{key}.{full_key}");
            let rows = full
                .as_array()
                .filter(|r| r.len() == 5)
                .ok_or_else(|| ParamError::new(&name, f64::NAN, "5 rows of 5 numbers"))?;
            let mut k = [[0.0; 5]; 5];
            for (i, row) in rows.iter().enumerate() {
                let row = row
                    .as_array()
                    .filter(|r| r.len() == 5)
                    .ok_or_else(|| ParamError::new(&name, f64::NAN, "5 rows of 5 numbers"))?;
                for (j, x) in row.iter().enumerate() {
                    let x = x
                        .as_f64()
                        .ok_or_else(|| ParamError::new(&name, f64::NAN, "5 rows of 5 numbers"))?;
                    if !(x.is_finite() && x.abs() < 1e16) {
                        return Err(ParamError::new(
                            &format!("{name}[{i}][{j}]"),
                            x,
                            "finite, |value| < 1e16",
                        ));
                    }
                    k[i][j] = x;
                }
            }
            for i in 0..5 {
                limit(&format!("{name}[{i}][{i}]"), k[i][i])?;
                for j in 0..i {
                    if (k[i][j] - k[j][i]).abs()
                        > 1e-12 * (k[i][i] * k[j][j]).sqrt().max(f64::MIN_POSITIVE)
                    {
                        return Err(ParamError::new(
                            &format!("{name}[{i}][{j}]"),
                            k[i][j],
                            format!("symmetric: equal to [{j}][{i}] = {}", k[j][i]),
                        ));
                    }
                }
            }
            Ok(Some(k))
        }
    }
}

/// The lower Cholesky factor of a symmetric 5 × 5 matrix; `None` unless positive definite.
fn cholesky(a: &[[f64; 5]; 5]) -> Option<[[f64; 5]; 5]> {
    let mut l = [[0.0; 5]; 5];
    for i in 0..5 {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Solves L·Lᵀ·x = b.
fn cholesky_solve(l: &[[f64; 5]; 5], b: &[f64; 5]) -> [f64; 5] {
    let mut y = [0.0; 5];
    for i in 0..5 {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0; 5];
    for i in (0..5).rev() {
        x[i] = (y[i] - (i + 1..5).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

/// A static equilibrium with the bodies displaced on their supports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportedEquilibrium {
    /// The mesh's equilibrium at the final poses (TE, φg, the outputs, both bodies' poses in
    /// [`Equilibrium::pose_p`], [`Equilibrium::pose_g`]).
    pub equilibrium: Equilibrium,
    /// Fixed-point iterations used.
    pub iterations: usize,
}

/// The largest number of fixed-point iterations of [`supported_equilibrium`].
pub const MAX_SUPPORT_ITERATIONS: usize = 100;

/// The static equilibrium at pinion angle `phi_p` (rad) and pinion torque `torque` (N·m) with
/// both bodies on `supports` (module docs), starting the TE search at `te_guess` (m);
/// `settings` as for [`equilibrium`] (their poses are the start of the iteration). Errors: the
/// mesh's (a pose beyond its bound names the input: the support is too soft for the model's
/// small displacements), or [`MeshError::Equilibrium`] when the poses do not settle in
/// [`MAX_SUPPORT_ITERATIONS`].
pub fn supported_equilibrium<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
    te_guess: f64,
    supports: &Supports,
    settings: &EquilibriumSettings,
) -> Result<SupportedEquilibrium, MeshError> {
    let mut s = *settings;
    let mut guess = te_guess;
    for it in 1..=MAX_SUPPORT_ITERATIONS {
        let eq = equilibrium(mesh, phi_p, torque, guess, &s)?;
        guess = eq.te;
        let o = &eq.outputs;
        let w_p = [o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]];
        let w_g = [o.force_g[0], o.force_g[1], o.force_g[2], o.moment_g[0], o.moment_g[1]];
        let next = |sup: &Option<Support>, w: &[f64; 5]| {
            sup.map_or(BodyPose::default(), |k| k.static_pose(w))
        };
        let (np, ng) = (next(&supports.pinion, &w_p), next(&supports.gear, &w_g));
        let change = |a: &BodyPose, b: &BodyPose| {
            a.values()
                .iter()
                .zip(b.values())
                .all(|(x, y)| (x - y).abs() <= 1e-10 * x.abs().max(y.abs()) + 1e-16)
        };
        let settled = change(&np, &s.pose_p) && change(&ng, &s.pose_g);
        if settled {
            return Ok(SupportedEquilibrium { equilibrium: eq, iterations: it });
        }
        s.pose_p = np;
        s.pose_g = ng;
    }
    Err(MeshError::Equilibrium(format!(
        "the gear bodies' poses on their supports did not settle in {MAX_SUPPORT_ITERATIONS} \
         iterations at phi_p = {phi_p} rad, torque = {torque} N.m (supports too soft against \
         the mesh's tilting moments)"
    )))
}

/// The static curve ([`super::statics::static_curve_with`]) with both bodies on `supports`:
/// at `points_per_pitch` pinion angles per pitch over `pitches` pitches from `phi_start`, each
/// point [`supported_equilibrium`] started from the previous point's TE and poses; each
/// [`Equilibrium`] carries its poses.
#[allow(clippy::too_many_arguments)]
pub fn supported_static_curve<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    torque: f64,
    phi_start: f64,
    pinion_pitch: f64,
    points_per_pitch: usize,
    pitches: usize,
    supports: &Supports,
    settings: &EquilibriumSettings,
) -> Result<StaticCurve, MeshError> {
    curve_points(torque, phi_start, pinion_pitch, points_per_pitch, pitches, |phi_p, prev| {
        // Started from the previous point's TE and poses.
        let s = match prev {
            None => *settings,
            Some(e) => EquilibriumSettings { pose_p: e.pose_p, pose_g: e.pose_g, ..*settings },
        };
        let guess = prev.map_or(1e-5, |e| e.te);
        Ok(supported_equilibrium(mesh, phi_p, torque, guess, supports, &s)?.equilibrium)
    })
}
