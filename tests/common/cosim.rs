//! Co-simulation masters of the Table 1 drive line, shared by `tests/dynamics_unit.rs` (which
//! asserts their convergence) and the measurement program `app/examples/measure.rs` (which
//! tabulates their errors in `docs/bench/cosimulation.md`).
//!
//! The drive line is cut at the shafts (Stage unit: kinematics in, shaft torques out) or at the
//! hubs (Pair unit: torques in); a master integrates the rest and holds what it receives over
//! each communication step H. Every function returns TE (m) at the communication points
//! t_k = k·H, k = 0…n; [`reference`] gives the same instants of the whole 4-DOF model, and
//! [`rel_err`] the largest difference relative to the largest |TE_ref|. The mesh is the Table 1
//! pair at table fidelity with the default table (96 × 24 nodes, built once per process).

use std::sync::OnceLock;

use helical_gear_mesh::dynamics::model::{PHI_1, PHI_2, W_1, W_2};
use helical_gear_mesh::dynamics::{
    DriveUnit, Drivetrain, GearDynamics, HubCoupling, Stepping, UnitInputRates, UnitInputs,
    UnitKind, UnitStepping, simulate,
};
use helical_gear_mesh::mesh::statics::EquilibriumSettings;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions};
use helical_gear_mesh::params::GearPair;

/// The Table 1 pair at table fidelity (built once) and its drivetrain.
pub fn table_mesh() -> (Mesh, Drivetrain) {
    static MESH: OnceLock<(Mesh, Drivetrain)> = OnceLock::new();
    let (m, d) = MESH.get_or_init(|| {
        let pair = GearPair::paper_table1();
        let options = MeshOptions { fidelity: Fidelity::Table, ..MeshOptions::default() };
        let mesh = Mesh::new(&pair, options).unwrap();
        (mesh, Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap())
    });
    (m.clone(), *d)
}

/// RK4 inside the unit at `n` sub-steps per mesh period.
pub fn rk4(n: u32) -> UnitStepping {
    UnitStepping::Rk4 { steps_per_mesh_period: n }
}

/// A unit of `kind` on the [`table_mesh`], started in static equilibrium at `omega` (rad/s).
pub fn started(kind: UnitKind, stepping: UnitStepping, omega: f64) -> DriveUnit<Mesh> {
    let (mesh, drive) = table_mesh();
    let mut u = DriveUnit::new(kind, mesh, drive, stepping).unwrap();
    u.start_static(0.0, omega, &EquilibriumSettings::default()).unwrap();
    u
}

/// Co-simulation of the drive line cut at the shafts: J1 and J2 in the master, the Stage unit
/// with the shafts, hubs and mesh. Zero-order hold at the communication points t_k = k·H:
/// the master gives the far-end motion, the unit the shaft torques. Returns TE at the t_k.
pub fn stage_cut(omega: f64, h: f64, n: usize) -> Vec<f64> {
    let mut stage = started(UnitKind::Stage, rk4(128), omega);
    let d = *stage.drive();
    let y = stage_start(omega);
    let (mut p1, mut w1, mut p2, mut w2) = (y[PHI_1], y[W_1], y[PHI_2], y[W_2]);
    let load = d.torque * d.z_g as f64 / d.z_p as f64;
    let mut te = Vec::with_capacity(n + 1);
    for k in 0..=n {
        stage
            .set_inputs(UnitInputs { phi_1: p1, w_1: w1, phi_2: p2, w_2: w2, ..Default::default() })
            .unwrap();
        let o = stage.outputs().unwrap();
        te.push(o.mesh.te);
        if k == n {
            break;
        }
        // The master: J1·φ1'' = M + tau_1, J2·φ2'' = M·z_g/z_p + tau_2, torques held: exact.
        let a1 = (d.torque + o.tau_1) / d.j1;
        let a2 = (load + o.tau_2) / d.j2;
        stage.advance(h).unwrap();
        p1 += w1 * h + 0.5 * a1 * h * h;
        w1 += a1 * h;
        p2 += w2 * h + 0.5 * a2 * h * h;
        w2 += a2 * h;
    }
    te
}

/// The 8-state static start of the whole drive line at `omega`.
pub fn stage_start(omega: f64) -> [f64; 8] {
    let (mesh, drive) = table_mesh();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap().y
}

/// Co-simulation cut at the hubs: J1, J2 and the shafts in the master, the Pair unit with the
/// hubs and the mesh. At t_k the master computes the shaft torques on the hubs from its state
/// and the unit's hub motion; over the step the unit holds them and the master integrates J1
/// and J2 (RK4, 8 sub-steps) against the hub motion extrapolated with the rates of t_k.
pub fn pair_cut(omega: f64, h: f64, n: usize) -> Vec<f64> {
    pair_cut_with(omega, h, n, false)
}

/// [`pair_cut`] with the held shaft torques taken at mid-step (`mid`): from the master's state
/// and the unit's hub motion at t_k, both extrapolated linearly to t_k + H/2.
pub fn pair_cut_mid(omega: f64, h: f64, n: usize) -> Vec<f64> {
    pair_cut_with(omega, h, n, true)
}

/// [`pair_cut`] with first-order hold: the master passes the shaft torques and their time
/// derivatives at t_k (exact from its state and the unit's outputs: d tau_p/dt = c1·(φ̇1 −
/// φ̇p) + d1·(φ̈1 − a_p), with φ̈1 from J1's equation), as `fmi2SetRealInputDerivatives` does.
pub fn pair_cut_foh(omega: f64, h: f64, n: usize) -> Vec<f64> {
    pair_cut_hold(omega, h, n, false, true, false)
}

/// [`pair_cut`] or [`pair_cut_mid`] (zero-order hold, no coupling).
fn pair_cut_with(omega: f64, h: f64, n: usize, mid: bool) -> Vec<f64> {
    pair_cut_hold(omega, h, n, mid, false, false)
}

/// [`pair_cut`] (zero-order hold) with the unit told the shafts' stiffness and damping
/// ([`HubCoupling`]): it corrects the held torques by its own hub motion within the step.
pub fn pair_cut_coupled(omega: f64, h: f64, n: usize) -> Vec<f64> {
    pair_cut_hold(omega, h, n, false, false, true)
}

/// [`pair_cut_foh`] with the [`HubCoupling`] of [`pair_cut_coupled`].
pub fn pair_cut_foh_coupled(omega: f64, h: f64, n: usize) -> Vec<f64> {
    pair_cut_hold(omega, h, n, false, true, true)
}

/// The hub cut with the held torques taken at mid-step (`mid`), their time derivatives passed
/// (`foh`) and the shafts' stiffness and damping told to the unit (`coupled`).
fn pair_cut_hold(omega: f64, h: f64, n: usize, mid: bool, foh: bool, coupled: bool) -> Vec<f64> {
    let mut pair = started(UnitKind::Pair, rk4(128), omega);
    let d = *pair.drive();
    if coupled {
        pair.set_hub_coupling(HubCoupling { c_p: d.c1, d_p: d.d1, c_g: d.c2, d_g: d.d2 }).unwrap();
    }
    let y = stage_start(omega);
    let mut m = [y[PHI_1], y[W_1], y[PHI_2], y[W_2]];
    let load = d.torque * d.z_g as f64 / d.z_p as f64;
    let mut te = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let o = pair.outputs().unwrap();
        te.push(o.mesh.te);
        if k == n {
            break;
        }
        let hub = [o.phi_p, o.w_p, o.phi_g, o.w_g];
        let e = if mid { 0.5 * h } else { 0.0 };
        let s1 = d.c1 * (m[0] + m[1] * e - hub[0] - hub[1] * e) + d.d1 * (m[1] - hub[1]);
        let s2 = d.c2 * (hub[2] + hub[3] * e - m[2] - m[3] * e) + d.d2 * (hub[3] - m[3]);
        let (mut r1, mut r2) = (0.0, 0.0);
        if foh {
            let a1 = (d.torque - s1) / d.j1;
            let a2 = (load + s2) / d.j2;
            r1 = d.c1 * (m[1] - hub[1]) + d.d1 * (a1 - o.a_p);
            r2 = d.c2 * (hub[3] - m[3]) + d.d2 * (o.a_g - a2);
        }
        pair.set_inputs(UnitInputs { tau_p: s1, tau_g: -s2, ..Default::default() }).unwrap();
        let r = UnitInputRates { tau_p_rate: r1, tau_g_rate: -r2, ..Default::default() };
        pair.set_input_rates(r).unwrap();
        pair.advance(h).unwrap();
        // Master: J1 φ1'' = M − c1(φ1 − φp(t)) − d1(φ̇1 − φ̇p), J2 φ2'' = M·z_g/z_p +
        // c2(φg(t) − φ2) + d2(φ̇g − φ̇2), hub motion φ(t) = φ(t_k) + φ̇(t_k)·s.
        let f = |s: f64, x: [f64; 4]| -> [f64; 4] {
            let pp = hub[0] + hub[1] * s;
            let pg = hub[2] + hub[3] * s;
            let t1 = d.c1 * (x[0] - pp) + d.d1 * (x[1] - hub[1]);
            let t2 = d.c2 * (pg - x[2]) + d.d2 * (hub[3] - x[3]);
            [x[1], (d.torque - t1) / d.j1, x[3], (load + t2) / d.j2]
        };
        let sub = 8;
        let hs = h / sub as f64;
        for i in 0..sub {
            let s = i as f64 * hs;
            let add = |x: [f64; 4], k: [f64; 4], c: f64| std::array::from_fn(|j| x[j] + c * k[j]);
            let k1 = f(s, m);
            let k2 = f(s + 0.5 * hs, add(m, k1, 0.5 * hs));
            let k3 = f(s + 0.5 * hs, add(m, k2, 0.5 * hs));
            let k4 = f(s + hs, add(m, k3, hs));
            m = std::array::from_fn(|j| {
                m[j] + hs / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
            });
        }
    }
    te
}

/// TE at t_k = k·H of the whole 4-DOF model by `simulate`, RK4 at a fine step (at most T_m/256,
/// a whole fraction of H).
pub fn reference(omega: f64, h: f64, n: usize) -> Vec<f64> {
    let (mesh, drive) = table_mesh();
    let m = (h / (drive.mesh_period(omega) / 256.0)).ceil() as usize;
    let dt = h / m as f64;
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let tr = simulate(&mut model, &start.y, (n * m) as f64 * dt, &Stepping::Rk4 { dt }).unwrap();
    (0..=n).map(|k| tr.outputs[k * m].te).collect()
}

/// Largest |TE − TE_ref| relative to the largest |TE_ref|.
pub fn rel_err(te: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(te.len(), reference.len());
    let scale = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let err = te.iter().zip(reference).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    err / scale
}

/// Communication steps covering about 30 mesh periods at `omega`.
pub fn steps_for(omega: f64, h: f64) -> usize {
    let (_, drive) = table_mesh();
    (30.0 * drive.mesh_period(omega) / h).ceil() as usize
}
