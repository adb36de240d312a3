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
//! supports stiffer than the tooth pair).
//!
//! A soft support does not contract: the mesh's tilting moment changes with the tilt by about
//! k_m·(r_w·tan β_b)² (7·10⁴ N·m/rad for Table 1), so a tilting stiffness well below that makes
//! each iterate overshoot the last. When the poses do not settle in
//! [`MAX_FIXED_POINT_ITERATIONS`], when their change grows three iterations in a row, or when
//! an iterate leaves the model's range, the solve starts
//! again from the given poses with Newton's method on F(p) = K⁻¹·W(p) − p = 0 (the unknowns:
//! the poses of the supported bodies). Its Jacobian is formed by forward differences of the
//! same map (steps of 10⁻⁶ of the poses' size, at least 10⁻¹² m or 10⁻¹⁰ rad), each Newton
//! step halved until |F| falls, at most [`MAX_NEWTON_ITERATIONS`] steps, until
//! |F| ≤ 10⁻⁹·|p| + 10⁻¹⁵ m (tilts counted times 10 mm; the map's own noise, from the TE solve's
//! 10⁻¹⁵ m, is of that order, below which no step is accepted). Supports that settle by the plain iteration are solved exactly as before.

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

    /// The diagonal 5 × 5 matrix of a support isotropic in the transverse plane:
    /// diag(radial, radial, axial, tilt, tilt) in the order of [`BodyPose::values`] (a stiffness
    /// in N/m and N·m/rad, or a damping in N·s/m and N·m·s/rad).
    pub fn isotropic(radial: f64, axial: f64, tilt: f64) -> [[f64; 5]; 5] {
        let mut k = [[0.0; 5]; 5];
        for (i, x) in [radial, radial, axial, tilt, tilt].into_iter().enumerate() {
            k[i][i] = x;
        }
        k
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
            Ok(Some(Support::isotropic(v[0], v[1], v[2])))
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
    /// Fixed-point iterations used, plus the Newton steps when it turned to Newton's method
    /// (module docs).
    pub iterations: usize,
}

/// The largest number of fixed-point iterations of [`supported_equilibrium`] before it turns
/// to Newton's method (module docs).
pub const MAX_FIXED_POINT_ITERATIONS: usize = 100;

/// The largest number of Newton steps of [`supported_equilibrium`] (module docs).
pub const MAX_NEWTON_ITERATIONS: usize = 30;

/// The static equilibrium at pinion angle `phi_p` (rad) and pinion torque `torque` (N·m) with
/// both bodies on `supports` (module docs), starting the TE search at `te_guess` (m);
/// `settings` as for [`equilibrium`] (their poses are the start of the iteration). Errors: the
/// mesh's (a pose beyond its bound names the input: the support is too soft for the model's
/// small displacements), or [`MeshError::Equilibrium`] when the poses do not settle in
/// [`MAX_FIXED_POINT_ITERATIONS`] fixed-point iterations and [`MAX_NEWTON_ITERATIONS`] Newton
/// steps (module docs).
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
    let mut failure = None;
    // Iterations in a row whose change of the poses grew: three mean no contraction.
    let (mut last_change, mut growing) = (f64::INFINITY, 0);
    let mut used = 0;
    for it in 1..=MAX_FIXED_POINT_ITERATIONS {
        used = it;
        let (eq, np, ng) = match support_map(mesh, phi_p, torque, guess, supports, &s) {
            Ok(r) => r,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        guess = eq.te;
        if settled(&np, &s.pose_p) && settled(&ng, &s.pose_g) {
            return Ok(SupportedEquilibrium { equilibrium: eq, iterations: it });
        }
        let change = pose_change(&np, &s.pose_p) + pose_change(&ng, &s.pose_g);
        growing = if change > last_change { growing + 1 } else { 0 };
        last_change = change;
        if growing == 3 {
            break;
        }
        s.pose_p = np;
        s.pose_g = ng;
    }
    supported_newton(mesh, phi_p, torque, te_guess, supports, settings, failure, used)
}

/// The size of the change from pose `b` to pose `a`, m (tilts times 10 mm).
fn pose_change(a: &BodyPose, b: &BodyPose) -> f64 {
    let (a, b) = (a.values(), b.values());
    (0..5).map(|i| (a[i] - b[i]).abs() * if i >= 3 { 1e-2 } else { 1.0 }).sum()
}

/// True when pose `a` and pose `b` agree to the settling test of the module docs.
fn settled(a: &BodyPose, b: &BodyPose) -> bool {
    a.values()
        .iter()
        .zip(b.values())
        .all(|(x, y)| (x - y).abs() <= 1e-10 * x.abs().max(y.abs()) + 1e-16)
}

/// One application of the fixed-point map: the equilibrium at the poses of `s` and the poses
/// K⁻¹·W at which the supports balance its wrench (zero for a rigid body).
fn support_map<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
    guess: f64,
    supports: &Supports,
    s: &EquilibriumSettings,
) -> Result<(Equilibrium, BodyPose, BodyPose), MeshError> {
    let eq = equilibrium(mesh, phi_p, torque, guess, s)?;
    let o = &eq.outputs;
    let w_p = [o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]];
    let w_g = [o.force_g[0], o.force_g[1], o.force_g[2], o.moment_g[0], o.moment_g[1]];
    let next =
        |sup: &Option<Support>, w: &[f64; 5]| sup.map_or(BodyPose::default(), |k| k.static_pose(w));
    Ok((eq, next(&supports.pinion, &w_p), next(&supports.gear, &w_g)))
}

/// Newton's method on F(p) = K⁻¹·W(p) − p over the supported bodies' poses (module docs),
/// from the poses of `settings`, after `used` fixed-point iterations. When it fails too, the
/// error is the last mesh error met (a pose beyond its bound names the input), else `failure`
/// (the plain iteration's), else one naming both iteration counts.
#[allow(clippy::too_many_arguments)]
fn supported_newton<M: MeshTorques + ?Sized>(
    mesh: &mut M,
    phi_p: f64,
    torque: f64,
    te_guess: f64,
    supports: &Supports,
    settings: &EquilibriumSettings,
    mut failure: Option<MeshError>,
    used: usize,
) -> Result<SupportedEquilibrium, MeshError> {
    // The unknowns: (body, component) of each supported body.
    let bodies: Vec<usize> = [supports.pinion.is_some(), supports.gear.is_some()]
        .iter()
        .enumerate()
        .filter_map(|(b, &on)| on.then_some(b))
        .collect();
    let n = 5 * bodies.len();
    let get = |s: &EquilibriumSettings| -> Vec<f64> {
        let mut x = Vec::with_capacity(n);
        for &b in &bodies {
            x.extend(if b == 0 { s.pose_p.values() } else { s.pose_g.values() });
        }
        x
    };
    let put = |x: &[f64], base: &EquilibriumSettings| -> EquilibriumSettings {
        let mut s = *base;
        for (k, &b) in bodies.iter().enumerate() {
            let p = BodyPose::from_values(std::array::from_fn(|i| x[5 * k + i]));
            if b == 0 {
                s.pose_p = p;
            } else {
                s.pose_g = p;
            }
        }
        s
    };
    let mut guess = te_guess;
    // F at x: the residual and the equilibrium.
    let mut eval = |x: &[f64], guess: f64| -> Result<(Vec<f64>, Equilibrium), MeshError> {
        let s = put(x, settings);
        let (eq, np, ng) = support_map(mesh, phi_p, torque, guess, supports, &s)?;
        let g = get(&EquilibriumSettings { pose_p: np, pose_g: ng, ..s });
        Ok((g.iter().zip(x).map(|(a, b)| a - b).collect(), eq))
    };
    // Translations and tilts on one scale: a tilt times 10 mm, the order of a face width.
    let norm = |f: &[f64]| -> f64 {
        let scaled = f.iter().enumerate().map(|(i, v)| if i % 5 >= 3 { v * 1e-2 } else { *v });
        scaled.map(|v| v * v).sum::<f64>().sqrt()
    };
    let mut x = get(settings);
    let (mut f, mut eq) = eval(&x, guess)?;
    guess = eq.te;
    for it in 1..=MAX_NEWTON_ITERATIONS {
        // Settled: |F| at the map's noise floor (the TE solve's 1e-15 m moves the poses by
        // about as much), relative to the poses.
        if norm(&f) <= 1e-9 * norm(&x) + 1e-15 {
            return Ok(SupportedEquilibrium { equilibrium: eq, iterations: used + it - 1 });
        }
        // The Jacobian of F by forward differences.
        let size_t = (0..n).filter(|i| i % 5 < 3).map(|i| x[i].abs()).fold(0.0, f64::max);
        let size_r = (0..n).filter(|i| i % 5 >= 3).map(|i| x[i].abs()).fold(0.0, f64::max);
        let mut jac = nalgebra::DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            let h =
                if j % 5 >= 3 { (1e-6 * size_r).max(1e-10) } else { (1e-6 * size_t).max(1e-12) };
            let mut xp = x.clone();
            xp[j] += h;
            let (fp, _) = eval(&xp, guess)?;
            for i in 0..n {
                jac[(i, j)] = (fp[i] - f[i]) / h;
            }
        }
        let rhs = nalgebra::DVector::from_iterator(n, f.iter().map(|v| -v));
        let Some(dx) = jac.lu().solve(&rhs) else {
            break;
        };
        // Halve the step until |F| falls.
        let f0 = norm(&f);
        let mut t = 1.0;
        let mut accepted = false;
        for _ in 0..20 {
            let xt: Vec<f64> = x.iter().zip(dx.iter()).map(|(a, d)| a + t * d).collect();
            match eval(&xt, guess) {
                Ok((ft, et)) if norm(&ft) < f0 => {
                    (x, f, eq) = (xt, ft, et);
                    guess = eq.te;
                    accepted = true;
                    break;
                }
                Ok(_) => {}
                Err(e) => failure = Some(e),
            }
            t *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    Err(failure.unwrap_or_else(|| {
        MeshError::Equilibrium(format!(
            "the gear bodies' poses on their supports did not settle in \
         {MAX_FIXED_POINT_ITERATIONS} fixed-point iterations and {MAX_NEWTON_ITERATIONS} Newton \
         steps at phi_p = {phi_p} rad, torque = {torque} N.m (supports too soft against the \
         mesh's force and moments)"
        ))
    }))
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
