//! Regression tests of the dynamics' step rule and work bounds (`dynamics::limits`): low
//! speed and standstill are integrated stably, a run-up from rest works, and every request
//! whose cost grows with an input is refused before anything is reserved or integrated.

mod common;

use std::sync::OnceLock;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::dynamics::model::{N_STATES, W_P};
use helical_gear_mesh::dynamics::{
    Clearance, ConstantStiffnessMesh, DriveUnit, Drivetrain, DynamicsError, GearDynamics,
    MAX_UNIT_SUBSTEPS, OdeSystem, RK4_MAX_OMEGA_H, STEPS_PER_FAST_PERIOD, Stepping, SweepOptions,
    UnitKind, UnitStepping, default_rk4_step, fastest_mode, simulate, stable_rk4_step, sweep,
};
use helical_gear_mesh::mesh::statics::EquilibriumSettings;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions, MeshTorques};

use common::small_table_options;

/// Table 1 at a coarse table fidelity (fast to build) and its drivetrain.
fn table_mesh() -> (Mesh, Drivetrain) {
    static MESH: OnceLock<(Mesh, Drivetrain)> = OnceLock::new();
    let (m, d) = MESH.get_or_init(|| {
        let pair = GearPair::paper_table1();
        let options = small_table_options();
        (
            Mesh::new(&pair, options).unwrap(),
            Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap(),
        )
    });
    (m.clone(), *d)
}

fn too_large(e: &DynamicsError) -> bool {
    matches!(e, DynamicsError::TooLarge(_))
}

/// simulate from the static start at `omega` with step `dt` over `t_end`: TE samples.
fn te_run(omega: f64, dt: f64, t_end: f64) -> (Vec<f64>, f64) {
    let (mesh, drive) = table_mesh();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let tr = simulate(&mut model, &start.y, t_end, &Stepping::Rk4 { dt }).unwrap();
    (tr.outputs.iter().map(|o| o.te).collect(), start.te)
}

#[test]
fn simulate_default_step_is_stable_at_8_rad_s() {
    let (mesh, drive) = table_mesh();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let w = fastest_mode(&mut model, 0.0).unwrap();
    let t_end = 0.02;
    let dt = default_rk4_step(&mut model, 8.0, 0.0, t_end).unwrap();
    // The fast mode, not the mesh period (T_m/128 = 2.6e-4 s), sets the step.
    let rule = stable_rk4_step(drive.mesh_period(8.0), 128.0, w, STEPS_PER_FAST_PERIOD);
    assert!(dt <= rule && dt > 0.99 * rule, "dt {dt:e}, rule {rule:e}");
    assert!(w * dt <= 2.0 * std::f64::consts::PI / 32.0 * 1.000001, "ω·dt = {}", w * dt);
    let (te, te0) = te_run(8.0, dt, t_end);
    let dev = te.iter().map(|t| (t - te0).abs()).fold(0.0, f64::max);
    // Quasi-static running: TE stays near the static TE (the old step gave ±0.8 m).
    assert!(dev < 0.5 * te0, "TE deviates {dev:e} m from the static {te0:e} m");
    // The old default step is refused, naming dt and the limit, instead of diverging.
    let old = drive.mesh_period(8.0) / 128.0;
    let mut model = GearDynamics::new(table_mesh().0, drive).unwrap();
    let start = model.static_start(0.0, 8.0, &EquilibriumSettings::default()).unwrap();
    let e = simulate(&mut model, &start.y, 100.0 * old, &Stepping::Rk4 { dt: old }).unwrap_err();
    assert!(too_large(&e), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("dt = ") && msg.contains(&format!("{RK4_MAX_OMEGA_H}")), "{msg}");
}

#[test]
fn simulate_from_rest_to_10_rad_s_agrees_with_a_4x_finer_step() {
    let (mesh, drive) = table_mesh();
    let t_end = 0.01;
    for omega in [0.0, 0.5, 1.0, 5.0, 8.0, 10.0] {
        let mut model = GearDynamics::new(mesh.clone(), drive).unwrap();
        let dt = default_rk4_step(&mut model, omega, 0.0, t_end).unwrap();
        let (coarse, te0) = te_run(omega, dt, t_end);
        let (fine, _) = te_run(omega, dt / 4.0, t_end);
        assert_eq!(fine.len(), 4 * (coarse.len() - 1) + 1);
        let diff =
            coarse.iter().enumerate().map(|(i, c)| (c - fine[4 * i]).abs()).fold(0.0, f64::max);
        assert!(
            diff / te0 < 1e-3,
            "ω {omega}: max TE difference {:.3e} of the static TE",
            diff / te0
        );
        assert!(coarse.iter().all(|t| t.is_finite() && (t - te0).abs() < te0), "ω {omega}");
    }
}

#[test]
fn static_start_at_zero_speed_is_an_equilibrium() {
    let (mesh, drive) = table_mesh();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let s = model.static_start(0.0, 0.0, &EquilibriumSettings::default()).unwrap();
    assert!(s.te > 0.0 && s.te.is_finite());
    assert!(s.y[4..].iter().all(|w| *w == 0.0), "rates {:?}", &s.y[4..]);
    let mut dydt = [0.0; N_STATES];
    model.rhs(0.0, &s.y, &mut dydt).unwrap();
    // Accelerations small against the driving torque's M/J_p (residual of the equilibrium
    // search on M_F,p and the gear-side balance).
    let scale = drive.torque / drive.j_p;
    for (i, a) in dydt[4..].iter().enumerate() {
        assert!(a.abs() < 1e-6 * scale, "acceleration {i}: {a:e} (scale {scale:e})");
    }
}

#[test]
fn pair_runs_up_from_rest_to_300_rad_s() {
    // The Pair from the static equilibrium at rest, the pinion hub torque raised by ΔM: the
    // gear set accelerates as one rigid body, ω_p(t) = ΔM·t/J_eff with J_eff = J_p + J_g·(z_p/z_g)²,
    // while TE follows the static TE of the (slightly higher) mesh load.
    let (mesh, drive) = table_mesh();
    let mut u = DriveUnit::new(
        UnitKind::Pair,
        mesh,
        drive,
        UnitStepping::Rk4 { steps_per_mesh_period: 128 },
    )
    .unwrap();
    let start = u.start_static(0.0, 0.0, &EquilibriumSettings::default()).unwrap();
    let ratio = drive.z_p as f64 / drive.z_g as f64;
    let j_eff = drive.j_p + drive.j_g * ratio * ratio;
    let t_run = 0.05;
    let dm = j_eff * 300.0 / t_run;
    let mut inputs = *u.inputs();
    inputs.tau_p += dm;
    u.set_inputs(inputs).unwrap();
    let (gp, gg) = u.mesh().base_radii();
    let h = 1e-3;
    let mut te_max: f64 = 0.0;
    while u.time() < t_run - 0.5 * h {
        u.advance(h).unwrap();
        let y = u.state();
        let te = y[0] * gp + y[1] * gg;
        assert!(te.is_finite() && te > 0.0, "t {}: TE {te:e}", u.time());
        te_max = te_max.max(te);
    }
    let w = u.state()[2];
    assert!((w - 300.0).abs() < 0.01 * 300.0, "ω_p after the run-up {w} rad/s");
    // The mesh carries at most M + ΔM: TE stays below a few times the static TE.
    assert!(te_max < 3.0 * start.te * (1.0 + dm / drive.torque), "TE max {te_max:e}");
}

#[test]
fn simulate_refuses_a_39_gb_trajectory() {
    let (mesh, drive) = table_mesh();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    // Default step at the largest speed, 1e5 rad/s, over 1 s: 6e7 samples (8.8 GB).
    let e = default_rk4_step(&mut model, 1e5, 0.0, 1.0).unwrap_err();
    assert!(too_large(&e) && e.to_string().contains("GB"), "{e}");
    // An explicit step of 1 ps over 1 ms: 1e9 samples, refused before reserving.
    let start = model.static_start(0.0, 100.0, &EquilibriumSettings::default()).unwrap();
    let e = simulate(&mut model, &start.y, 1e-3, &Stepping::Rk4 { dt: 1e-12 }).unwrap_err();
    assert!(too_large(&e) && e.to_string().contains("samples"), "{e}");
}

/// A linear mesh with the unit's inertias and shafts (no table needed).
fn linear_unit(drive: Drivetrain, n: u32) -> DriveUnit<ConstantStiffnessMesh> {
    let mesh = ConstantStiffnessMesh::new(3e8, 100.0, 0.05, 0.08, Clearance::Bilateral).unwrap();
    DriveUnit::new(UnitKind::Drive, mesh, drive, UnitStepping::Rk4 { steps_per_mesh_period: n })
        .unwrap()
}

#[test]
fn unit_step_refuses_1e10_substeps() {
    let (_, drive) = table_mesh();
    let settings = EquilibriumSettings::default();
    // w_p_start = 1e5 rad/s (the largest speed) at 65536 sub-steps per mesh period:
    // T_m/65536 ≈ 3.2e-11 s, a 0.1 ms step would be 3.1e6 sub-steps.
    let mut u = linear_unit(drive, 65_536);
    u.start_static(0.0, 1e5, &settings).unwrap();
    let (t0, y0) = (u.time(), u.state().to_vec());
    let e = u.advance(1e-4).unwrap_err();
    assert!(too_large(&e) && e.to_string().contains("sub-steps"), "{e}");
    assert_eq!((u.time(), u.state()), (t0, y0.as_slice()), "state untouched");
    // 2^31 − 1 steps per mesh period: refused when the unit is made (the option's bounds,
    // 4 … 65536), before any step could ask for them.
    let mesh = ConstantStiffnessMesh::new(3e8, 100.0, 0.05, 0.08, Clearance::Bilateral).unwrap();
    let steps = UnitStepping::Rk4 { steps_per_mesh_period: i32::MAX as u32 };
    let Err(e) = DriveUnit::new(UnitKind::Drive, mesh, drive, steps) else {
        panic!("2^31 - 1 sub-steps per mesh period accepted");
    };
    assert!(
        e.to_string().contains("steps_per_mesh_period") && e.to_string().contains("65536"),
        "{e}"
    );
    // A stiff, light unit: J = 1e-12 kg·m² on c = 1e15 N·m/rad, ω ≈ 3e13 rad/s.
    let stiff = Drivetrain { j1: 1e-12, j2: 1e-12, c1: 1e15, c2: 1e15, ..drive };
    let mut u = linear_unit(stiff, 128);
    u.start_static(0.0, 100.0, &settings).unwrap();
    let (t0, y0) = (u.time(), u.state().to_vec());
    let e = u.advance(1e-4).unwrap_err();
    assert!(too_large(&e), "{e}");
    assert_eq!((u.time(), u.state()), (t0, y0.as_slice()));
    // Below the bound the same unit steps.
    let h = 0.5 * MAX_UNIT_SUBSTEPS * 2.0 * std::f64::consts::PI / (u.fastest_mode() * 32.0);
    u.advance(h.min(1e-9)).unwrap();
}

#[test]
fn unit_time_that_stops_advancing_is_an_error() {
    let (_, drive) = table_mesh();
    let mut u = linear_unit(drive, 128);
    u.start_static(1e17, 100.0, &EquilibriumSettings::default()).unwrap();
    let y0 = u.state().to_vec();
    assert_eq!(1e17 + 1e-4, 1e17);
    let e = u.advance(1e-4).unwrap_err();
    assert!(too_large(&e) && e.to_string().contains("cannot advance"), "{e}");
    assert_eq!((u.time(), u.state()), (1e17, y0.as_slice()), "neither state nor time moved");
    // Near 0 the same step advances.
    u.set_time(0.0).unwrap();
    u.advance(1e-4).unwrap();
    assert_eq!(u.time(), 1e-4);
    assert!(u.state()[W_P].is_finite());
}

#[test]
fn sweep_at_0_01_rad_s_ends_within_bounds() {
    let (mesh, drive) = table_mesh();
    let e = sweep(&mesh, &drive, &[0.01, 0.02], &SweepOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("RK4 steps") && msg.contains("at most"), "{msg}");
    // refine_runs = 1e9 is refused before any run.
    let opts = SweepOptions { refine_runs: 1_000_000_000, ..SweepOptions::default() };
    let e = sweep(&mesh, &drive, &[300.0, 400.0], &opts).unwrap_err();
    assert!(too_large(&e) && e.to_string().contains("refine"), "{e}");
}

#[test]
fn table_size_4096_is_refused() {
    let pair = GearPair::paper_table1();
    let options = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: 4096,
        table_te_points: 4096,
        ..MeshOptions::default()
    };
    let e = Mesh::new(&pair, options).unwrap_err().to_string();
    assert!(e.contains("table_phase_points") && e.contains("65536"), "{e}");
}

/// The step rule includes the damping: at every d_mesh of its allowed range, every eigenvalue
/// λ of the damped linearisation (Table 1 at its static equilibrium, 300 rad/s) times the
/// default step h lies inside RK4's stability region (|R(h·λ)| ≤ 1), while the undamped rule
/// (h from the undamped frequency alone) leaves it once the mesh mode is overdamped.
#[test]
fn default_step_keeps_every_damped_eigenvalue_inside_the_rk4_region() {
    use helical_gear_mesh::dynamics::limits::{linear_eigenvalues, rk4_amplification};
    use helical_gear_mesh::dynamics::model::mesh_linearisation;
    let (mesh, drive) = table_mesh();
    let omega = 300.0;
    let t_m = drive.mesh_period(omega);
    let mut undamped_rule_fails = Vec::new();
    for d_mesh in [0.0, 1e2, 1e3, 1e4, 2.5e4, 1e5, 1e6, 1e7, 1e9] {
        let mut m = mesh.clone();
        m.set_d_mesh(d_mesh).unwrap();
        let (gp, gg) = m.base_radii();
        let lin = mesh_linearisation(&mut m, 0.0, drive.torque).unwrap();
        let mut model = GearDynamics::new(m, drive).unwrap();
        let w = fastest_mode(&mut model, 0.0).unwrap();
        let h = stable_rk4_step(t_m, 128.0, w, STEPS_PER_FAST_PERIOD);
        // The linearisation's matrices (coordinates φ₁, φp, φg, φ₂).
        let (k, c) = (lin.stiffness, lin.damping);
        let kk = [
            drive.c1,
            -drive.c1,
            0.0,
            0.0,
            -drive.c1,
            drive.c1 + k * gp * gp,
            k * gp * gg,
            0.0,
            0.0,
            k * gp * gg,
            drive.c2 + k * gg * gg,
            -drive.c2,
            0.0,
            0.0,
            -drive.c2,
            drive.c2,
        ];
        let cc = [
            drive.d1,
            -drive.d1,
            0.0,
            0.0,
            -drive.d1,
            drive.d1 + c * gp * gp,
            c * gp * gg,
            0.0,
            0.0,
            c * gp * gg,
            drive.d2 + c * gg * gg,
            -drive.d2,
            0.0,
            0.0,
            -drive.d2,
            drive.d2,
        ];
        let lambdas = linear_eigenvalues(&[drive.j1, drive.j_p, drive.j_g, drive.j2], &kk, &cc);
        assert_eq!(lambdas.len(), 8, "d_mesh {d_mesh:e}");
        // The rigid-body mode is a double 0, resolved by the eigen-solver to about
        // √ε·|λ|max: no growing mode beyond that.
        let scale = lambdas.iter().map(|l| l.norm()).fold(0.0, f64::max);
        for l in &lambdas {
            assert!(l.re <= 1e-8 * scale, "d_mesh {d_mesh:e}: growing mode {l}");
            if l.norm() < 1e-6 * scale {
                continue; // the rigid-body mode: neutral, R = 1
            }
            let r = rk4_amplification(l * h);
            assert!(r <= 1.0 + 1e-12, "d_mesh {d_mesh:e}: |R(hλ)| = {r} for λ = {l}, h = {h:e}");
        }
        // The damping is Eq. 14's: c grows in proportion to d_mesh.
        if d_mesh > 0.0 {
            assert!(c > 0.0, "d_mesh {d_mesh:e}: damping coefficient {c}");
        }
        let omega_undamped = drive.linear_frequencies(k, gp, gg)[3];
        let h_old = stable_rk4_step(t_m, 128.0, omega_undamped, STEPS_PER_FAST_PERIOD);
        if lambdas.iter().any(|l| l.norm() > 1e-6 * scale && rk4_amplification(l * h_old) > 1.0) {
            undamped_rule_fails.push(d_mesh);
        }
    }
    // The defect the rule mends: without the damping the step leaves the region from about
    // 2.5e4 N·s/m on (Table 1, 300 rad/s), and never below critical damping.
    assert!(undamped_rule_fails.contains(&1e5), "{undamped_rule_fails:?}");
    assert!(!undamped_rule_fails.contains(&1e3), "{undamped_rule_fails:?}");
}

/// Sweeping d_mesh over its allowed range at 300 rad/s: the default step agrees with a step
/// four times finer (TE and the mesh force F_p,y), or, where the damping makes the step so
/// short that the run exceeds the work bound, the request is refused naming the bound.
#[test]
fn default_step_agrees_with_a_4x_finer_one_over_the_damping_range() {
    let (mesh, drive) = table_mesh();
    let omega = 300.0;
    let mut refused = Vec::new();
    for d_mesh in [0.0, 1e3, 1e4, 2.5e4, 3e4, 1e5, 1e6, 1e9] {
        let mut m = mesh.clone();
        m.set_d_mesh(d_mesh).unwrap();
        let mut model = GearDynamics::new(m.clone(), drive).unwrap();
        let w = fastest_mode(&mut model, 0.0).unwrap();
        let h = stable_rk4_step(drive.mesh_period(omega), 128.0, w, STEPS_PER_FAST_PERIOD);
        // Two mesh periods, or fewer steps where the damping shortens the step.
        let t_end = (2.0 * drive.mesh_period(omega)).min(20_000.0 * h);
        let dt = match default_rk4_step(&mut model, omega, 0.0, t_end) {
            Ok(dt) => dt,
            Err(e) => {
                assert!(too_large(&e), "d_mesh {d_mesh:e}: {e}");
                refused.push(d_mesh);
                continue;
            }
        };
        let run = |dt: f64| {
            let mut model = GearDynamics::new(m.clone(), drive).unwrap();
            let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
            let tr = simulate(&mut model, &start.y, t_end, &Stepping::Rk4 { dt }).unwrap();
            let te: Vec<f64> = tr.outputs.iter().map(|o| o.te).collect();
            let fy: Vec<f64> = tr.outputs.iter().map(|o| o.force_p[1]).collect();
            (te, fy, start.te)
        };
        let (te, fy, te0) = run(dt);
        let (te_f, fy_f, _) = run(dt / 4.0);
        let f_static = fy[0].abs();
        let mut dte: f64 = 0.0;
        let mut dfy: f64 = 0.0;
        for i in 0..te.len() {
            dte = dte.max((te[i] - te_f[4 * i]).abs());
            dfy = dfy.max((fy[i] - fy_f[4 * i]).abs());
        }
        assert!(dte < 1e-3 * te0, "d_mesh {d_mesh:e}: TE differs by {:.2e} of static", dte / te0);
        assert!(dfy < 1e-3 * f_static, "d_mesh {d_mesh:e}: F_p,y differs by {dfy:.3e} N");
        assert!(fy.iter().all(|f| f.abs() < 2.0 * f_static), "d_mesh {d_mesh:e}: {fy:?}");
    }
    // Only the extreme of the range (the step 2π/(32·c/m)) is refused, and it is refused.
    assert!(refused.iter().all(|d| *d >= 1e6), "{refused:?}");
}

/// The units take the damped rule too, and a tuned d_mesh (the FMUs' tunable parameter) is
/// measured again: a Drive unit whose damping is raised to 1e5 N·s/m after construction has
/// the fastest rate of a unit built with it, above the undamped mesh frequency.
#[test]
fn unit_step_rule_follows_a_tuned_mesh_damping() {
    let (mesh, drive) = table_mesh();
    let unit = |m: Mesh| {
        DriveUnit::new(UnitKind::Drive, m, drive, UnitStepping::Rk4 { steps_per_mesh_period: 128 })
            .unwrap()
    };
    let mut light = mesh.clone();
    light.set_d_mesh(100.0).unwrap();
    let mut heavy = mesh.clone();
    heavy.set_d_mesh(1e5).unwrap();
    let u_light = unit(light.clone());
    let u_heavy = unit(heavy.clone());
    let mut tuned = unit(light);
    assert_eq!(tuned.fastest_mode(), u_light.fastest_mode());
    tuned.mesh_mut().set_d_mesh(1e5).unwrap();
    tuned.refresh_fastest_mode().unwrap();
    let rel = (tuned.fastest_mode() - u_heavy.fastest_mode()).abs() / u_heavy.fastest_mode();
    assert!(rel < 1e-9, "tuned {} against built {}", tuned.fastest_mode(), u_heavy.fastest_mode());
    // Overdamped: beyond the undamped frequency the light unit runs at.
    assert!(u_heavy.fastest_mode() > 2.0 * u_light.fastest_mode());
    let mut model = GearDynamics::new(heavy, drive).unwrap();
    let w = fastest_mode(&mut model, 0.0).unwrap();
    assert!(u_heavy.fastest_mode() >= w * (1.0 - 1e-9), "{} < {w}", u_heavy.fastest_mode());
}
