//! The table with the gear bodies displaced — a specification.
//!
//! The table ([`super::MeshTable`]) holds the mesh on rigid bearings over (mesh phase, TE). A
//! small pose of the bodies changes the contact only through the gear's pose relative to the
//! pinion, R = (U_x, U_y, U_z, Θ_x, Θ_y) ([`crate::mesh::pose`], "The gear seen from the
//! pinion"). Its effect splits into two parts:
//!
//! 1. **A shift of TE.** The relative displacement at the operating pitch point at mid-face,
//!    along the flanks' normal and through the helix, moves the flanks towards each other as a
//!    change of TE does:
//!
//!    ```text
//!    ΔTE_drive = −(U_x·sin α_wt + U_y·cos α_wt) − r_bg·ω_g·(U_z + Θ_y·r_wg)
//!    ΔTE_back  = +(U_x·sin α_wt − U_y·cos α_wt) − r_bg·ω_g·(U_z + Θ_y·r_wg)
//!    ```
//!
//!    (the driving flanks' normal (sin α_wt, cos α_wt), the back flanks' mirrored about the
//!    line of centres; an axial shift turns the gear through its helix, which is a TE change
//!    for both sides alike; ω_g the gear's twist rate, r_wg = r_bg/cos α_wt). This part is
//!    non-linear in TE and the table keeps it exactly: it is evaluated at TE + ΔTE of the
//!    side in contact. It is what carries most of the effect of a translation: a support
//!    that yields along the line of action lowers the mesh load as a TE change does.
//! 2. **The rest, to first order.** The tilts load the face unevenly (the tilting moments
//!    change at once, the torques hardly), and the translation across the line of action
//!    changes the operating pressure angle. For the elastic torques M_F,p, M_F,g and the
//!    force and tilting moments on the pinion (7 outputs), the table holds their derivative
//!    with respect to each component of R at a fixed shifted TE,
//!
//!    ```text
//!    S_k(phase, TE) = ∂O/∂R_k at TE_shifted fixed, by central differences ±h_k
//!    ```
//!
//!    with h = [`POSE_STEP_MN`]·m_n for the translations and h/b for the tilts (a secant over
//!    the poses soft supports produce, which also averages the kinks where a contact starts
//!    or ends), as secants S/δ over the distance from the onset like the other node values,
//!    on a coarser grid: a third of the phase points (at least 8) and half the TE points per
//!    axis (at least 8 and 6), interpolated bilinearly in (phase, √δ): 32 × 12 for the
//!    default 96 × 24 table. (A third of its TE points, 32 × 8, samples a third fewer nodes
//!    but raised the soft supports' errors of `tests/table_pose.rs` by 20–30 %.) The outputs
//!    are then
//!
//!    ```text
//!    O(phase, TE, R) = O_table(phase, TE + ΔTE(R)) + δ·Σ_k (S_k/δ)·R_k
//!    ```
//!
//!    and, as in the full model, the gear's moment follows from the transfer formula about
//!    its displaced centre, every vector is turned by the pinion's tilt into the housing
//!    frame, and Eq. 14 damps the approach rate including the body motion. The loaded extent,
//!    F_n, p_max, the root stresses and the discrete outputs are those at the shifted TE.
//!
//! # Cost and bound
//! The sensitivities are built once per table, at its first posed state or when a model is
//! prepared for poses ([`crate::mesh::MeshTorques::prepare_poses`]), and shared by every mesh
//! that shares the table ([`super::MeshTable::pose_table`]): 10 full evaluations per node of
//! the coarse grid (3 840 for the default table, 1.7 times its nodes). As with the table's own
//! back flanks ([`super`], "Back flanks on demand"), the build samples the driving flanks
//! alone; the back flanks' sensitivities are sampled, whole and in the same way, at the first
//! posed state on the back flanks (after the table's back-flank axis, whose span they take),
//! once per table, with values that do not depend on when that happens. A drive line whose
//! flanks stay in contact pays neither. An evaluation adds one bilinear interpolation of 35
//! values. Relative poses beyond [`TABLE_POSE_BOUND_MN`]·m_n (translations) or that over b
//! (tilts) are refused with an error naming the bound: the first-order part is measured within
//! it (`tests/table_pose.rs`). The per-pair table of tooth deviations and friction are not
//! covered (refused when the model is prepared).

use std::sync::Arc;

use super::MeshTable;
use super::build::over_indices;
use crate::contact::RelativePose;
use crate::geometry::PairGeometry;
use crate::mesh::model::{FullMesh, MeshModel};
use crate::mesh::pose::approach_rate;
use crate::mesh::{BodyPose, MeshError, MeshState};

/// Number of outputs with a pose sensitivity: M_F,p, M_F,g, F_p (x, y, z), M_p (x, y).
const NO: usize = 7;
/// Values per node: the 7 outputs' derivatives with respect to the 5 components of R.
const NS: usize = NO * 5;

/// The central-difference step of the sensitivities, in units of m_n (translations; tilts
/// this over b).
pub const POSE_STEP_MN: f64 = 0.005;

/// The largest relative pose the table evaluates, in units of m_n (translations; tilts this
/// over b): 60 µm and 0.004 rad for Table 1.
pub const TABLE_POSE_BOUND_MN: f64 = 0.02;

/// The pose sensitivities of a table (module docs).
#[derive(Debug, Clone)]
pub struct PoseTable {
    np: usize,
    phase_lo: f64,
    phase_h: f64,
    /// Central-difference steps of the five components of R (m, rad).
    h: [f64; 5],
    /// The driving flanks' sensitivities, sampled by the build.
    drive: PoseAxis,
    /// The back flanks' sensitivities, sampled at the first posed back-flank state (module
    /// docs, "Cost and bound"); the same error at every call where that failed.
    back: std::sync::OnceLock<Result<PoseAxis, MeshError>>,
    /// The full model the sensitivities sample (the table's).
    model: Arc<MeshModel>,
    bound_u: f64,
    bound_th: f64,
    build_s: f64,
}

#[derive(Debug, Clone)]
struct PoseAxis {
    onset: f64,
    dir: f64,
    range: f64,
    n: usize,
    /// `values[ip * n + it][o * 5 + k]`: ∂O_o/∂R_k over δ.
    values: Vec<[f64; NS]>,
}

impl PoseAxis {
    fn empty() -> Self {
        Self { onset: 0.0, dir: 1.0, range: 0.0, n: 0, values: Vec::new() }
    }
}

/// ΔTE of the relative pose `r` on the driving flanks (`dir` > 0) or the back flanks (module
/// docs), m.
pub(crate) fn te_shift(geo: &PairGeometry, r: &RelativePose, dir: f64) -> f64 {
    // The driving flanks' shift is the approach the damping of Eq. 14 sees (for a pose instead
    // of a rate); the back flanks' normal is mirrored about the line of centres, which turns
    // the sign of the U_x part.
    let drive = approach_rate(geo, r);
    if dir > 0.0 { drive } else { drive + 2.0 * r.u[0] * geo.alpha_wt.sin() }
}

/// The five components of `r` in the order of [`BodyPose::values`].
fn components(r: &RelativePose) -> [f64; 5] {
    [r.u[0], r.u[1], r.u[2], r.th[0], r.th[1]]
}

impl PoseTable {
    /// Builds the sensitivities of `table` on the driving flanks from the full model `model`
    /// (module docs), the coarse grid's phase rows over the available cores, each from a cold
    /// start; the back flanks' follow at their first need ([`PoseTable::correction`]).
    pub(crate) fn build(table: &MeshTable, model: &Arc<MeshModel>) -> Result<Self, MeshError> {
        let t0 = std::time::Instant::now();
        if table.pairs.is_some() {
            return Err(MeshError::Unsupported(
                "gear body poses at table fidelity with pitch deviations or runout (the per-pair \
                 table carries no pose sensitivities): use fidelity full",
            ));
        }
        if model.friction().is_some() {
            return Err(MeshError::Unsupported(
                "gear body poses at table fidelity with friction: use fidelity full, or no \
                 friction",
            ));
        }
        let geo = model.geometry();
        let mn = geo.params.normal_module_m;
        let b = geo.params.face_width_m;
        let np = (table.np / 3).max(8);
        let pitch = table.phase_h * table.np as f64;
        let h = [POSE_STEP_MN * mn; 5];
        let mut pose = Self {
            np,
            phase_lo: table.phase_lo,
            phase_h: pitch / np as f64,
            h: [h[0], h[1], h[2], h[3] / b, h[4] / b],
            drive: PoseAxis::empty(),
            back: std::sync::OnceLock::new(),
            model: model.clone(),
            bound_u: TABLE_POSE_BOUND_MN * mn,
            bound_th: TABLE_POSE_BOUND_MN * mn / b,
            build_s: 0.0,
        };
        let d = &table.drive;
        pose.drive = pose.sample_axis((d.onset, d.dir, d.range, d.n), 8)?;
        pose.build_s = t0.elapsed().as_secs_f64();
        Ok(pose)
    }

    /// The back flanks' sensitivities of `table`, sampled at the first call: their grid spans
    /// the table's sampled back-flank axis (the designed one where no back-flank node is well
    /// posed). The values do not depend on when that happens.
    fn back_axis(&self, table: &MeshTable) -> Result<&PoseAxis, MeshError> {
        self.back
            .get_or_init(|| {
                let d = table.back_design;
                let span = table
                    .back_axis()
                    .map_or((d.onset, -1.0, d.range, d.n), |ax| (ax.onset, ax.dir, ax.range, ax.n));
                self.sample_axis(span, 6)
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The sensitivities on the table axis (onset, direction, extent, nodes), thinned to
    /// half its nodes (at least `min`), phase rows over the available cores, each from a
    /// cold start.
    fn sample_axis(
        &self,
        (onset, dir, range, n): (f64, f64, f64, usize),
        min: usize,
    ) -> Result<PoseAxis, MeshError> {
        let mut axis = PoseAxis { onset, dir, range, n: (n / 2).max(min), values: Vec::new() };
        let new_full = || FullMesh::new(self.model.clone());
        let rows = over_indices(self.np, "pose table build", &new_full, |full, ip| {
            sample_row(full, self.phase_lo + self.phase_h * ip as f64, &axis, &self.h)
        })?;
        let mut values = vec![[0.0; NS]; self.np * axis.n];
        for (ip, row) in rows {
            values[ip * axis.n..(ip + 1) * axis.n].copy_from_slice(&row);
        }
        axis.values = values;
        Ok(axis)
    }

    /// Wall time of the build, s.
    pub fn build_seconds(&self) -> f64 {
        self.build_s
    }

    /// Refuses a relative pose beyond the table's bound (module docs), naming the component.
    pub(crate) fn check(&self, r: &RelativePose) -> Result<(), MeshError> {
        const NAMES: [&str; 5] = ["U_x", "U_y", "U_z", "Theta_x", "Theta_y"];
        for (k, v) in components(r).into_iter().enumerate() {
            let lim = if k < 3 { self.bound_u } else { self.bound_th };
            if v.abs() > lim {
                return Err(MeshError::Param(crate::error::ParamError::new(
                    &format!("relative pose {} (gear relative to pinion)", NAMES[k]),
                    v,
                    format!(
                        "|value| <= {lim:.4e} {} at table fidelity (0.02·m_n{}: the table's \
                         first-order pose sensitivities hold within it); use fidelity full \
                         beyond",
                        if k < 3 { "m" } else { "rad" },
                        if k < 3 { "" } else { "/b" },
                    ),
                )));
            }
        }
        Ok(())
    }

    /// The first-order part δ·Σ_k (S_k/δ)·R_k of the 7 outputs (module docs) at the reduced
    /// pinion angle `phi_red` (rad, in the table's phase frame) and shifted TE `te` on axis
    /// `a` (0 driving, 1 back) of `table` (the one these sensitivities belong to), for the
    /// relative pose `r`. The first back-flank call samples the back flanks' sensitivities;
    /// errors: that sampling failed.
    pub(crate) fn correction(
        &self,
        table: &MeshTable,
        phi_red: f64,
        te: f64,
        a: usize,
        r: &RelativePose,
    ) -> Result<[f64; NO], MeshError> {
        let ax = if a == 0 { &self.drive } else { self.back_axis(table)? };
        let dist = (te - ax.onset).abs().min(ax.range);
        let xp = (phi_red - self.phase_lo) / self.phase_h;
        let ip = crate::numeric::floor(xp);
        let fp = xp - ip;
        let ip0 = (ip as i64).rem_euclid(self.np as i64) as usize;
        let ip1 = (ip0 + 1) % self.np;
        let xt = (dist / ax.range).sqrt() * (ax.n - 1) as f64;
        let it0 = (xt.floor() as usize).min(ax.n - 2);
        let ft = xt - it0 as f64;
        let rc = components(r);
        let mut out = [0.0; NO];
        for (ipx, wp) in [(ip0, 1.0 - fp), (ip1, fp)] {
            for (itx, wt) in [(it0, 1.0 - ft), (it0 + 1, ft)] {
                let v = &ax.values[ipx * ax.n + itx];
                let w = wp * wt * dist;
                for (o, x) in out.iter_mut().enumerate() {
                    *x += w * (0..5).map(|k| v[o * 5 + k] * rc[k]).sum::<f64>();
                }
            }
        }
        Ok(out)
    }
}

/// The 7 outputs with a pose sensitivity of `o`, in the order of the module docs.
fn outputs7(o: &crate::mesh::MeshOutputs) -> [f64; NO] {
    [o.m_f_p, o.m_f_g, o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]]
}

/// The sensitivities S/δ of one phase row of axis `ax` at pinion angle `phi_p` with steps `h`;
/// the onset node takes the next node's secant, and a node where a perturbed state is out of
/// the model's range takes the previous node's.
fn sample_row(
    full: &mut FullMesh,
    phi_p: f64,
    ax: &PoseAxis,
    h: &[f64; 5],
) -> Result<Vec<[f64; NS]>, MeshError> {
    let geo = full.model().geometry().clone();
    let mut row = vec![[0.0; NS]; ax.n];
    for it in 1..ax.n {
        let t = it as f64 / (ax.n - 1) as f64;
        let dist = ax.range * t * t;
        let te = ax.onset + ax.dir * dist;
        let mut node = [0.0; NS];
        let mut ok = true;
        'k: for k in 0..5 {
            let mut o = [[0.0; NO]; 2];
            for (j, sgn) in [1.0, -1.0].into_iter().enumerate() {
                let mut v = [0.0; 5];
                v[k] = sgn * h[k];
                let pose_g = BodyPose::from_values(v);
                let rel = RelativePose::new(&BodyPose::default(), &pose_g, geo.center_distance);
                let te_k = te - te_shift(&geo, &rel, ax.dir);
                let state = MeshState {
                    phi_p,
                    phi_g: geo.phi_g_for_te(phi_p, te_k),
                    pose_g,
                    ..Default::default()
                };
                match full.evaluate(&state) {
                    Ok(out) => o[j] = outputs7(&out),
                    Err(MeshError::OutOfRange { .. }) => {
                        ok = false;
                        break 'k;
                    }
                    Err(e) => return Err(e),
                }
            }
            for q in 0..NO {
                node[q * 5 + k] = (o[0][q] - o[1][q]) / (2.0 * h[k]) / dist;
            }
        }
        row[it] = if ok { node } else { row[it - 1] };
    }
    row[0] = row[1];
    Ok(row)
}
