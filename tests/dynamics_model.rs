//! Tests of the 4-DOF model of Eqs. 1–4 against analytic properties, with the analytic
//! (linear-spring) mesh models: static start, linearised eigenfrequencies, energy balance
//! through contact loss, quasi-static limit, RK4 step convergence, resonance location of a
//! sweep, typed propagation of mesh failures.

use std::f64::consts::PI;
use std::ops::ControlFlow;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::dynamics::model::{PHI_1, PHI_2, PHI_G, PHI_P, W_1, W_2, W_G, W_P};
use helical_gear_mesh::dynamics::{
    Clearance, ConstantStiffnessMesh, Drivetrain, DynamicsError, GearDynamics, OdeError, OdeSystem,
    PeriodicStiffnessMesh, Rk4, SteadyMethod, SteadyRunOptions, Stepping, run_to_steady, simulate,
};
use helical_gear_mesh::mesh::statics::{EquilibriumSettings, equilibrium};
use helical_gear_mesh::mesh::{MeshError, MeshOutputs, MeshState, MeshTorques};
use nalgebra::{Matrix4, SymmetricEigen, Vector4};

/// Mesh stiffness of the analytic meshes, N/m: puts the mesh mode near 2·10⁴ rad/s with the
/// Table 1 inertias (the paper's main resonance, 660 rad/s × 30 teeth).
const K_MESH: f64 = 1.2e8;

/// Table 1 drivetrain and base radii (g_p, g_g), m.
fn table1() -> (Drivetrain, f64, f64) {
    let pair = GearPair::paper_table1();
    let g = helical_gear_mesh::PairGeometry::new(&pair).unwrap();
    (
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap(),
        g.pinion.rb,
        g.gear.rb,
    )
}

/// Time-invariant J and K of Eqs. 1–4 with a linear mesh, built here from the equations.
fn mass_and_stiffness(d: &Drivetrain, k: f64, gp: f64, gg: f64) -> (Vector4<f64>, Matrix4<f64>) {
    let j = Vector4::new(d.j1, d.j_p, d.j_g, d.j2);
    // Potential V = ½c₁(φ₁ − φp)² + ½k(φp·g_p + φg·g_g)² + ½c₂(φg − φ₂)² (minus the work of
    // the constant torques, which does not enter the Hessian).
    let mut kk = Matrix4::zeros();
    let mut add = |a: [f64; 4], s: f64| {
        for r in 0..4 {
            for c in 0..4 {
                kk[(r, c)] += s * a[r] * a[c];
            }
        }
    };
    add([1.0, -1.0, 0.0, 0.0], d.c1);
    add([0.0, gp, gg, 0.0], k);
    add([0.0, 0.0, 1.0, -1.0], d.c2);
    (j, kk)
}

#[test]
fn static_start_is_a_steady_rotation_for_a_constant_stiffness_mesh() {
    let (drive, gp, gg) = table1();
    let mesh = ConstantStiffnessMesh::new(K_MESH, 150.0, gp, gg, Clearance::Separating).unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let omega = 300.0;
    let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let y0 = start.y;
    // Static TE of a linear spring and the shaft wind-up.
    let ste = drive.torque / (K_MESH * gp);
    assert!((start.te - ste).abs() < 1e-9 * ste, "{} vs {ste}", start.te);
    assert!((y0[PHI_1] - y0[PHI_P] - drive.torque / drive.c1).abs() < 1e-15);
    assert!((y0[PHI_2] - y0[PHI_G] - drive.brake_torque() / drive.c2).abs() < 1e-12);
    assert_eq!((y0[W_1], y0[W_P]), (omega, omega));
    assert!((y0[W_G] + omega * 30.0 / 47.0).abs() < 1e-12 && y0[W_2] == y0[W_G]);
    // Zero accelerations: every torque balances (relative to the torques' scale M/J).
    let mut d = [0.0; 8];
    model.rhs(0.0, &y0, &mut d).unwrap();
    for (i, j) in [(W_1, drive.j1), (W_P, drive.j_p), (W_G, drive.j_g), (W_2, drive.j2)] {
        assert!(d[i].abs() * j < 1e-9 * drive.torque, "acceleration {i}: {}", d[i]);
    }
    // And it stays so: 20 ms at constant speed, TE constant.
    let tr = simulate(&mut model, &y0, 0.02, &Stepping::Rk4 { dt: 1e-5 }).unwrap();
    assert_eq!(tr.time.len(), 2001);
    assert!((tr.time[2000] - 0.02).abs() < 1e-15);
    for (y, o) in tr.states.iter().zip(&tr.outputs) {
        assert!((o.te - ste).abs() < 1e-9 * ste, "TE drifted to {}", o.te);
        assert!((y[W_P] - omega).abs() < 1e-9 * omega);
        assert!(!o.separated);
    }
}

#[test]
fn dopri5_trajectory_on_an_output_grid_matches_rk4() {
    let (drive, gp, gg) = table1();
    let mesh = ConstantStiffnessMesh::new(K_MESH, 150.0, gp, gg, Clearance::Separating).unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let mut y0 = model.static_start(0.0, 300.0, &EquilibriumSettings::default()).unwrap().y;
    y0[W_P] += 1.0;
    let rk = simulate(&mut model, &y0, 2e-3, &Stepping::Rk4 { dt: 1e-6 }).unwrap();
    let options = helical_gear_mesh::dynamics::Dopri5Options::with_tolerances(1e-10, 1e-14);
    let stepping = Stepping::Dopri5 { options, output_dt: Some(1e-5) };
    let dp = simulate(&mut model, &y0, 2e-3, &stepping).unwrap();
    // 201 outputs including t = 0 and t_end (201·1e-5 rounds above 2e-3).
    assert_eq!(dp.time.len(), 201);
    assert!((dp.time[200] - 2e-3).abs() < 1e-15);
    let te_amp = rk.outputs.iter().map(|o| o.te).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for (i, (t, o)) in dp.time.iter().zip(&dp.outputs).enumerate() {
        let j = 10 * i;
        assert!((rk.time[j] - t).abs() < 1e-15);
        worst = worst.max((rk.outputs[j].te - o.te).abs());
        // TE = φp·g_p + φg·g_g, correctly rounded (see helical_gear_mesh::numeric).
        let te = helical_gear_mesh::numeric::dot2(dp.states[i][PHI_P], gp, dp.states[i][PHI_G], gg);
        assert_eq!(o.te, te);
    }
    eprintln!("max |TE_dopri5 − TE_rk4| = {worst:.3e} m, {} DOPRI5 steps", dp.steps);
    // TE is a difference of angles of order 1 rad times radii: rtol 1e-10 on the angles
    // limits it to about 1e-11 m per step.
    assert!(worst < 1e-6 * te_amp, "{worst:e}");
    assert!(dp.steps < 2000, "DOPRI5 took {} steps", dp.steps);
}

/// Times of the sign changes of a sampled signal (linear interpolation between samples).
#[derive(Default)]
struct Crossings {
    prev: Option<(f64, f64)>,
    times: Vec<f64>,
}

impl Crossings {
    fn push(&mut self, t: f64, x: f64) {
        if let Some((t0, x0)) = self.prev
            && (x0 < 0.0) != (x < 0.0)
        {
            self.times.push(t0 + (t - t0) * x0 / (x0 - x));
        }
        self.prev = Some((t, x));
    }

    /// Angular frequency from a least-squares line through crossing number vs time
    /// (consecutive crossings are half a period apart).
    fn omega(&self) -> f64 {
        let n = self.times.len() as f64;
        let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
        for (i, t) in self.times.iter().enumerate() {
            let x = i as f64;
            sx += x;
            sy += t;
            sxx += x * x;
            sxy += x * t;
        }
        let half_period = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        PI / half_period
    }
}

#[test]
fn free_response_has_the_eigenfrequencies_of_the_linear_system() {
    let (mut drive, gp, gg) = table1();
    drive.d1 = 0.0;
    drive.d2 = 0.0;
    // One-sided contact: the test checks it is never left (small amplitude).
    let mesh = ConstantStiffnessMesh::new(K_MESH, 0.0, gp, gg, Clearance::Separating).unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();

    // Analytic: K v = ω² J v via the symmetric A = J^{-1/2} K J^{-1/2}.
    let (j, k) = mass_and_stiffness(&drive, K_MESH, gp, gg);
    let a = Matrix4::from_fn(|r, c| k[(r, c)] / (j[r] * j[c]).sqrt());
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..4).collect();
    order.sort_by(|&x, &y| eig.eigenvalues[x].total_cmp(&eig.eigenvalues[y]));
    let omegas: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i].max(0.0).sqrt()).collect();
    // Rigid-body mode: ω = 0 (to round-off of the largest eigenvalue).
    assert!(eig.eigenvalues[order[0]].abs() < 1e-10 * eig.eigenvalues[order[3]]);
    let by_lib = drive.linear_frequencies(K_MESH, gp, gg);
    for (a, b) in omegas.iter().zip(by_lib) {
        assert!((a - b).abs() <= 1e-9 * omegas[3]);
    }
    // Modal projection rows u_rᵀ J^{1/2}: η_r = u_rᵀ J^{1/2} (q − q₀) is a pure cosine for
    // r = 1, 2, 3 (the rigid rotation is J-orthogonal to them).
    let proj: Vec<Vector4<f64>> = order[1..]
        .iter()
        .map(|&i| {
            let u = eig.eigenvectors.column(i);
            Vector4::from_fn(|r, _| u[r] * j[r].sqrt())
        })
        .collect();

    let start = model.static_start(0.0, 100.0, &EquilibriumSettings::default()).unwrap();
    let q0 = Vector4::new(start.y[PHI_1], start.y[PHI_P], start.y[PHI_G], start.y[PHI_2]);
    let mut y = start.y;
    // Perturbation: pinion speed, driving-mass angle, load speed (excites all three modes).
    y[W_P] += 2.0;
    y[PHI_1] += 2e-3;
    y[W_2] -= 0.5;

    let (t_end, h) = (1.0, 2e-6);
    let n = (t_end / h) as usize;
    let mut rk4 = Rk4::new(8);
    let mut crossings: Vec<Crossings> = (0..3).map(|_| Crossings::default()).collect();
    let mut te_min = f64::INFINITY;
    rk4.integrate(&mut model, 0.0, t_end, n, &mut y, |_, t, y| {
        // Rigid rotation at the nominal speeds, removed before projecting (it is J-orthogonal
        // to the modes anyway, up to round-off of the large angles).
        let q = Vector4::new(y[PHI_1], y[PHI_P], y[PHI_G], y[PHI_2]) - q0;
        for (c, p) in crossings.iter_mut().zip(&proj) {
            c.push(t, p.dot(&q));
        }
        te_min = te_min.min(y[PHI_P] * gp + y[PHI_G] * gg);
        ControlFlow::Continue(())
    })
    .unwrap();
    assert!(te_min > 0.0, "contact was lost (TE min {te_min})");
    for (r, c) in crossings.iter().enumerate() {
        let w_sim = c.omega();
        let w_ref = omegas[r + 1];
        let err = (w_sim - w_ref).abs() / w_ref;
        eprintln!(
            "mode {}: analytic {w_ref:.6} rad/s, simulated {w_sim:.6} rad/s ({} crossings), \
             rel. error {err:.2e}",
            r + 1,
            c.times.len()
        );
        assert!(c.times.len() >= 10);
        assert!(err < 1e-3, "mode {} off by {err:.3e}", r + 1);
    }
}

/// Eqs. 1–4 plus one quadrature state: the energy dissipated in d₁, d₂ and the mesh damper.
struct WithDissipation {
    model: GearDynamics<ConstantStiffnessMesh>,
}

impl OdeSystem for WithDissipation {
    fn dim(&self) -> usize {
        9
    }

    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) -> Result<(), OdeError> {
        self.model.rhs(t, &y[..8], &mut d[..8])?;
        // The same mesh evaluation (remembered) gives the mesh damping torques.
        let o = self.model.outputs(&y[..8]).map_err(|e| OdeError::rhs(t, e))?;
        let dr = self.model.drive();
        d[8] = dr.d1 * (y[W_1] - y[W_P]).powi(2)
            + dr.d2 * (y[W_G] - y[W_2]).powi(2)
            + o.m_d_p * y[W_P]
            + o.m_d_g * y[W_G];
        Ok(())
    }
}

#[test]
fn energy_balance_holds_through_contact_loss_and_back_flank_impacts() {
    let (mut drive, gp, gg) = table1();
    drive.d1 = 2.0;
    drive.d2 = 2.0;
    let backlash = 10e-6;
    let mesh =
        ConstantStiffnessMesh::new(K_MESH, 150.0, gp, gg, Clearance::Backlash(backlash)).unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let start = model.static_start(0.0, 100.0, &EquilibriumSettings::default()).unwrap();
    let mut y0 = [0.0; 9];
    y0[..8].copy_from_slice(&start.y);
    // A large pinion-speed kick: TE swings through the backlash onto the back flanks.
    y0[W_P] += 30.0;
    let mut sys = WithDissipation { model };

    let energy = |sys: &WithDissipation, y: &[f64]| -> f64 {
        let d = sys.model.drive();
        let te = y[PHI_P] * gp + y[PHI_G] * gg;
        0.5 * (d.j1 * y[W_1].powi(2)
            + d.j_p * y[W_P].powi(2)
            + d.j_g * y[W_G].powi(2)
            + d.j2 * y[W_2].powi(2))
            + 0.5 * d.c1 * (y[PHI_1] - y[PHI_P]).powi(2)
            + 0.5 * d.c2 * (y[PHI_G] - y[PHI_2]).powi(2)
            + sys.model.mesh().elastic_energy(te)
    };
    let e0 = energy(&sys, &y0);
    let t_end = 0.02;
    let mut results = Vec::new();
    for n in [20_000usize, 40_000] {
        let mut y = y0;
        let (mut separated, mut back, mut recontacts) = (0usize, 0usize, 0usize);
        let mut was_separated = false;
        let mut worst: f64 = 0.0;
        let mut rk4 = Rk4::new(9);
        let d = *sys.model.drive();
        let balance = |sys: &WithDissipation, y: &[f64]| {
            let work =
                d.torque * (y[PHI_1] - y0[PHI_1]) + d.brake_torque() * (y[PHI_2] - y0[PHI_2]);
            energy(sys, y) - e0 + y[8] - work
        };
        let mut yy = y;
        let mut steps = Vec::new();
        rk4.integrate(&mut sys, 0.0, t_end, n, &mut yy, |_, _, y| {
            steps.push(*<&[f64; 9]>::try_from(y).unwrap());
            ControlFlow::Continue(())
        })
        .unwrap();
        for s in &steps {
            let o = sys.model.outputs(&s[..8]).unwrap();
            if o.separated {
                separated += 1;
            } else if was_separated {
                recontacts += 1;
            }
            was_separated = o.separated;
            back += usize::from(o.back_contact);
            worst = worst.max(balance(&sys, s).abs());
        }
        y = yy;
        let dissipated = y[8];
        eprintln!(
            "n = {n}: dissipated {dissipated:.6e} J, worst |balance| {worst:.3e} J \
             ({:.2e} of the dissipated energy); steps separated {separated}, on back flanks \
             {back}, re-contacts {recontacts}",
            worst / dissipated
        );
        assert!(separated > 0 && back > 0 && recontacts >= 3, "no contact loss/back contact");
        results.push((worst, dissipated));
    }
    // Integration accuracy: small, and shrinking with the step.
    let (w1, diss) = results[0];
    let (w2, _) = results[1];
    assert!(w2 < 1e-6 * diss, "balance error {w2:.3e} J vs dissipated {diss:.3e} J");
    assert!(w2 < 0.5 * w1, "balance error does not converge: {w1:.3e} -> {w2:.3e}");
}

#[test]
fn dynamic_te_tends_to_the_static_curve_at_low_speed() {
    let (drive, gp, gg) = table1();
    let z_p = drive.z_p;
    let mut mesh =
        PeriodicStiffnessMesh::new(K_MESH, 0.2, z_p, 200.0, gp, gg, Clearance::Separating).unwrap();
    let mut errors = Vec::new();
    for omega in [0.1, 0.2] {
        let mut model = GearDynamics::new(mesh, drive).unwrap();
        let opts = SteadyRunOptions {
            // Mesh-mode period / 40: the step follows the fast mode, not the slow mesh period.
            max_step: Some(2.0 * PI / 2.0e4 / 40.0),
            min_periods: 2,
            max_periods: 12,
            rel_tol: 1e-4,
            ..SteadyRunOptions::default()
        };
        let r = run_to_steady(&mut model, omega, &opts).unwrap();
        // Static curve from the equilibrium solver at the window's pinion angles.
        let mut worst: f64 = 0.0;
        let ste_max = mesh.static_te(PI / z_p as f64, drive.torque);
        for s in r.window.iter().step_by(500) {
            let eq = equilibrium(
                &mut mesh,
                s.y[PHI_P],
                drive.torque,
                s.outputs.te,
                &EquilibriumSettings::default(),
            )
            .unwrap();
            // The solver's equilibrium is the closed form.
            let exact = mesh.static_te(s.y[PHI_P], drive.torque);
            assert!((eq.te - exact).abs() < 1e-9 * exact);
            worst = worst.max((s.outputs.te - eq.te).abs());
        }
        eprintln!(
            "ω_p = {omega} rad/s: steady {} after {:.1} periods ({} steps/period), \
             max |TE − STE| = {worst:.3e} m = {:.2e}·STE_max",
            r.steady,
            r.periods,
            r.samples_per_period,
            worst / ste_max
        );
        assert!(r.steady);
        assert!((r.te_max - ste_max).abs() < 1e-4 * ste_max);
        errors.push(worst / ste_max);
    }
    assert!(errors[0] < 1e-5, "TE − STE = {:.3e}·STE_max at 0.1 rad/s", errors[0]);
    // Quasi-static limit: the deviation is an inertia effect, ∝ ω².
    let ratio = errors[1] / errors[0];
    assert!(
        (2.5..6.0).contains(&ratio),
        "deviation ratio {ratio} for doubled speed (expected ≈ 4)"
    );
}

/// A mesh that fails beyond a pinion angle, like a load solver that does not converge.
#[derive(Clone)]
struct FailingMesh {
    inner: ConstantStiffnessMesh,
    phi_fail: f64,
}

impl MeshTorques for FailingMesh {
    fn mesh(&mut self, s: &MeshState) -> Result<MeshOutputs, MeshError> {
        if s.phi_p > self.phi_fail {
            return Err(MeshError::Equilibrium(format!("synthetic failure at φp = {}", s.phi_p)));
        }
        self.inner.mesh(s)
    }

    fn base_radii(&self) -> (f64, f64) {
        self.inner.base_radii()
    }
}

#[test]
fn mesh_failure_propagates_as_a_typed_error_with_its_time() {
    let (drive, gp, gg) = table1();
    let inner = ConstantStiffnessMesh::new(K_MESH, 100.0, gp, gg, Clearance::Separating).unwrap();
    let mesh = FailingMesh { inner, phi_fail: 0.05 };
    for method in [
        SteadyMethod::Rk4 { steps_per_period: 64 },
        SteadyMethod::Dopri5 {
            options: helical_gear_mesh::dynamics::Dopri5Options::with_tolerances(1e-8, 1e-12),
            samples_per_period: 32,
        },
    ] {
        let mut model = GearDynamics::new(mesh.clone(), drive).unwrap();
        let opts = SteadyRunOptions { method, ..SteadyRunOptions::default() };
        match run_to_steady(&mut model, 100.0, &opts) {
            Err(DynamicsError::Mesh { t: Some(t), source: MeshError::Equilibrium(m) }) => {
                // φp ≈ ω·t crosses 0.05 rad at t = 0.5 ms; the failing stage is at most one
                // step later (DOPRI5 steps are limited to the mesh period 2.1 ms).
                assert!(t > 0.49e-3 && t < 0.5e-3 + 2.1e-3, "t = {t}");
                assert!(m.contains("synthetic"));
            }
            other => panic!("expected a mesh error, got {other:?}"),
        }
    }
    // And through `simulate`.
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let y0 = model.static_start(0.0, 100.0, &EquilibriumSettings::default()).unwrap().y;
    let e = simulate(&mut model, &y0, 1e-3, &Stepping::Rk4 { dt: 1e-6 }).unwrap_err();
    assert!(matches!(e, DynamicsError::Mesh { t: Some(_), .. }), "{e}");
}

/// Mesh-periodic analytic mesh with relative amplitude 0.05 and a mesh-mode damping ratio of
/// about 5 % (d = 2ζ·√(k₀·m_eq), m_eq = 1/(g_p²/J_p + g_g²/J_g)); and its mesh-mode
/// frequency from the independent eigen-decomposition.
fn periodic_case() -> (Drivetrain, PeriodicStiffnessMesh, f64) {
    let (drive, gp, gg) = table1();
    let m_eq = 1.0 / (gp * gp / drive.j_p + gg * gg / drive.j_g);
    let d_mesh = 2.0 * 0.05 * (K_MESH * m_eq).sqrt();
    let mesh =
        PeriodicStiffnessMesh::new(K_MESH, 0.05, drive.z_p, d_mesh, gp, gg, Clearance::Separating)
            .unwrap();
    let (j, k) = mass_and_stiffness(&drive, K_MESH, gp, gg);
    let a = Matrix4::from_fn(|r, c| k[(r, c)] / (j[r] * j[c]).sqrt());
    let w_mesh_mode = SymmetricEigen::new(a).eigenvalues.iter().cloned().fold(0.0, f64::max).sqrt();
    (drive, mesh, w_mesh_mode)
}

#[test]
fn rk4_steps_per_mesh_period_convergence() {
    // At the main resonance (mesh frequency = mesh-mode frequency), 40 mesh periods from the
    // static start; TE compared with a 1024-step reference at the 16 common sample times of
    // the last period.
    let (drive, mesh, w_n) = periodic_case();
    let omega = w_n / drive.z_p as f64;
    let t_m = drive.mesh_period(omega);
    let periods = 40;
    let run = |n: usize| -> Vec<f64> {
        let mut model = GearDynamics::new(mesh, drive).unwrap();
        let y0 = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap().y;
        let dt = t_m / n as f64;
        let tr = simulate(&mut model, &y0, periods as f64 * t_m, &Stepping::Rk4 { dt }).unwrap();
        let stride = n / 16;
        (0..16).map(|i| tr.outputs[(periods - 1) * n + i * stride].te).collect()
    };
    let reference = run(1024);
    let scale = reference.iter().cloned().fold(0.0, f64::max);
    let mut errors = Vec::new();
    let ns = [16usize, 32, 64, 96, 128];
    for n in ns {
        let te = run(n);
        let err = te.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale;
        eprintln!("N = {n:4} steps per mesh period: max relative TE error {err:.3e}");
        errors.push(err);
    }
    // Fourth order: observed order ln(e₁/e₂)/ln(N₂/N₁) ≈ 4 between successive N.
    for (w, n) in errors.windows(2).zip(ns.windows(2)) {
        let order = (w[0] / w[1]).ln() / (n[1] as f64 / n[0] as f64).ln();
        assert!((3.6..4.4).contains(&order), "observed order {order} between N = {n:?}");
    }
    // 1e-6 relative needs just under 100 steps per period (96 gives 1.0e-6): the default,
    // 128, meets it with margin.
    assert!(errors[3] > 0.9e-6 && errors[4] < 0.5e-6, "{errors:?}");
    assert_eq!(helical_gear_mesh::dynamics::DEFAULT_STEPS_PER_MESH_PERIOD, 128);
}

#[test]
fn dopri5_and_rk4_agree_on_the_steady_state_and_a_cap_gives_a_warning() {
    let (drive, mesh, w_n) = periodic_case();
    let omega = 0.97 * w_n / drive.z_p as f64;
    let mut rk = GearDynamics::new(mesh, drive).unwrap();
    let r1 = run_to_steady(&mut rk, omega, &SteadyRunOptions::default()).unwrap();
    let mut dp = GearDynamics::new(mesh, drive).unwrap();
    let opts = SteadyRunOptions {
        method: SteadyMethod::Dopri5 {
            options: helical_gear_mesh::dynamics::Dopri5Options::with_tolerances(1e-9, 1e-13),
            samples_per_period: 64,
        },
        ..SteadyRunOptions::default()
    };
    let r2 = run_to_steady(&mut dp, omega, &opts).unwrap();
    eprintln!(
        "RK4: TE max {:.6e} m after {:.0} periods, {} mesh evaluations; DOPRI5: {:.6e} m after \
         {:.1} periods, {} steps, {} mesh evaluations",
        r1.te_max,
        r1.periods,
        r1.mesh_evaluations,
        r2.te_max,
        r2.periods,
        r2.steps,
        r2.mesh_evaluations
    );
    assert!(r1.steady && r2.steady && r1.warning.is_none());
    assert_eq!((r1.period_multiple, r2.period_multiple), (1, 1));
    // Both sample on the grid i·T_m/64; they stop at different times, and the residual
    // transient is within the detector's tolerance (1e-3 of the peak-to-peak).
    let pp = r1.te_max - r1.te_min;
    assert!((r1.te_max - r2.te_max).abs() < 2e-3 * pp);
    assert!((r1.te_min - r2.te_min).abs() < 2e-3 * pp);
    assert!(!r1.separated && !r1.back_contact && !r1.tip_contact);
    // The window: one mesh period of RK4 steps, both ends included.
    assert_eq!(r1.window.len(), r1.samples_per_period + 1);
    let te_w = r1.window.iter().map(|s| s.outputs.te).fold(f64::MIN, f64::max);
    assert_eq!(te_w, r1.te_max);

    let capped = SteadyRunOptions { max_periods: 8, ..SteadyRunOptions::default() };
    let r3 = run_to_steady(&mut rk, omega, &capped).unwrap();
    assert!(!r3.steady);
    match r3.warning {
        Some(helical_gear_mesh::dynamics::SteadyWarning::NotSteady { periods, .. }) => {
            assert_eq!(periods, 8)
        }
        w => panic!("expected a warning, got {w:?}"),
    }
}

#[test]
fn sweep_finds_the_main_resonance_where_the_mesh_frequency_meets_the_mesh_mode() {
    let (drive, mesh, w_n) = periodic_case();
    let expected = w_n / drive.z_p as f64;
    let speeds: Vec<f64> = (0..11).map(|i| 560.0 + 20.0 * i as f64).collect();
    let opts = helical_gear_mesh::dynamics::SweepOptions { threads: Some(2), ..Default::default() };
    let r = helical_gear_mesh::dynamics::sweep(&mesh, &drive, &speeds, &opts).unwrap();
    // STE_max of the analytic mesh: M/(g_p·k₀·(1 − a)).
    let ste_max = mesh.static_te(PI / drive.z_p as f64, drive.torque);
    assert!((r.ste.max() - ste_max).abs() < 1e-9 * ste_max);
    assert_eq!(r.points.len(), speeds.len());
    for (p, w) in r.points.iter().zip(&speeds) {
        assert_eq!(p.omega_p, *w);
        assert!(p.steady && !p.separated, "{p:?}");
    }
    let curve: Vec<String> =
        r.points.iter().map(|p| format!("{:.0}:{:.3}", p.omega_p, p.te_max_over_ste_max)).collect();
    eprintln!("curve {}", curve.join(" "));
    eprintln!(
        "resonances {:?} (expected {expected:.2} rad/s); wall time {:.2} s",
        r.resonances.iter().map(|x| (x.omega_p, x.bracket)).collect::<Vec<_>>(),
        r.wall_seconds
    );
    assert_eq!(r.resonances.len(), 1);
    let res = &r.resonances[0];
    assert_eq!(res.refinement.len(), 6);
    let err = (res.omega_p - expected).abs() / expected;
    assert!(err < 0.02, "resonance at {} rad/s, expected {expected}", res.omega_p);
    // Height: to first order in a the stiffness variation forces the mesh mode with
    // a·k₀·TE_static, so at resonance TE ≈ TE_static·(1 + a/(2ζ)) = 1.5·TE_static, and
    // STE_max = TE_static/(1 − a): TE_max/STE_max ≈ 1.5·0.95 = 1.425 (the 4-DOF mode is not
    // exactly the one-degree-of-freedom oscillator of m_eq, hence the tolerance).
    let first_order = 1.5 * 0.95;
    eprintln!("peak TE_max/STE_max {} (first order {first_order})", res.te_max_over_ste_max);
    assert!((res.te_max_over_ste_max - first_order).abs() < 0.05 * first_order);
    assert!(res.te_max_over_ste_max > r.points[0].te_max_over_ste_max + 0.25);
    assert!(res.te_max_over_ste_max > r.points[10].te_max_over_ste_max + 0.25);
}
