//! Both gear bodies on elastic supports coupled to Eqs. 1–4 (`dynamics::bodies`), against
//! oracles derived in each test: stiff supports give the torsional model, the mean support
//! forces of a steady run are the static reactions, and the power balance of the 28 states
//! closes.

use helical_gear_mesh::dynamics::bodies::{
    CoupledModes, N_BODY_STATES, POSE_P, RATE_P, SupportedDynamics, SupportedTrajectory,
    simulate_supported, support_force_stats, supported_rk4_step,
};
use helical_gear_mesh::dynamics::{Drivetrain, GearDynamics, Stepping, simulate};
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Mesh, MeshOptions, Supports, supported_static_curve,
};
use helical_gear_mesh::{DriveLine, GearPair};

fn mesh(slices: usize) -> Mesh {
    Mesh::new(&GearPair::paper_table1(), MeshOptions { slices, ..MeshOptions::default() }).unwrap()
}

fn drive() -> Drivetrain {
    Drivetrain::from_pair(&GearPair::paper_table1(), &DriveLine::paper_table1()).unwrap()
}

/// The guide's example supports (the file its figures were made with), damping of a few per cent.
const EXAMPLE: &str = include_str!("../docs/gear-bodies/supports.json");

/// Supports 10⁶ times stiffer than the tooth pair (k_m ≈ 2·10⁸ N/m along the line of action;
/// against a tilt the helix turns r_w·θ into TE, k_m·(r_w·tan β_b)² ≈ 7·10⁴ N·m/rad) move the
/// bodies by 10⁻⁶ of TE: the trajectory is the torsional model's to that order. More
/// precisely, each support adds its static deflection F/k along the line of action, a constant
/// shift of TE (F_t·(1/k_p + 1/k_g), about 1.2·10⁻⁶ of TE here, the difference of the two static
/// starts, 0.9·10⁻⁶ here); beyond that shift, which varies a little with the load distribution
/// over the mesh cycle, the trajectories agree to 5·10⁻⁷ of TE (measured 2.4·10⁻⁷). Both models
/// take the same RK4 steps from their static starts; the step is within RK4's stability
/// region for the stiff body modes (heavy bodies keep them at ~10⁶ rad/s), which the start at
/// the supported equilibrium does not excite.
#[test]
fn stiff_supports_give_the_torsional_trajectory() {
    let stiff = r#"{"mass_kg": 50, "j_transverse_kgm2": 0.05,
        "stiffness": {"radial_n_per_m": 2e14, "axial_n_per_m": 2e14, "tilt_nm_per_rad": 7e10}}"#;
    let supports =
        Supports::from_json(&format!(r#"{{"pinion": {stiff}, "gear": {stiff}}}"#)).unwrap();
    let omega = 300.0;
    let mut m = SupportedDynamics::new(mesh(40), drive(), supports).unwrap();
    let start = m.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let modes = m.linear_modes(&start).unwrap();
    let dt = 1.6 / modes.fastest;
    let t_m = m.drive().mesh_period(omega);
    let n = (t_m / dt).ceil() as usize;
    let dt = t_m / n as f64;
    let tr = simulate_supported(&mut m, &start.y, dt, n, &modes).unwrap();

    let mut rigid = GearDynamics::new(mesh(40), drive()).unwrap();
    let y0 = rigid.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap().y;
    let te_rigid = rigid.te(&y0);
    let r = simulate(&mut rigid, &y0, n as f64 * dt, &Stepping::Rk4 { dt }).unwrap();
    let shift = start.te - te_rigid;
    let te_max = r.outputs.iter().map(|o| o.te.abs()).fold(0.0, f64::max);
    let dev = tr
        .drive
        .outputs
        .iter()
        .zip(&r.outputs)
        .map(|(a, b)| (a.te - b.te).abs())
        .fold(0.0, f64::max);
    let beyond = tr
        .drive
        .outputs
        .iter()
        .zip(&r.outputs)
        .map(|(a, b)| (a.te - b.te - shift).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "fastest mode {:.3e} rad/s, {n} steps per mesh period: max |ΔTE| = {:.3e} of TE, \
         static shift {:.3e}, beyond it {:.3e}",
        modes.fastest,
        dev / te_max,
        shift / te_max,
        beyond / te_max
    );
    assert!(shift > 0.0 && shift < 1.5e-6 * te_max, "{:e}", shift / te_max);
    assert!(dev < 1.5e-6 * te_max, "{:e}", dev / te_max);
    assert!(beyond < 5e-7 * te_max, "{:e}", beyond / te_max);
}

fn example_run(
    omega: f64,
    periods: usize,
) -> (SupportedDynamics<Mesh>, SupportedTrajectory, usize) {
    let supports = Supports::from_json(EXAMPLE).unwrap();
    let mut m = SupportedDynamics::new(mesh(60), drive(), supports).unwrap();
    let start = m.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let modes: CoupledModes = m.linear_modes(&start).unwrap();
    let dt = supported_rk4_step(m.drive(), &modes, omega);
    let spp = (m.drive().mesh_period(omega) / dt).round() as usize;
    let tr = simulate_supported(&mut m, &start.y, dt, spp * periods, &modes).unwrap();
    (m, tr, spp)
}

/// At a steady state the bodies' mean accelerations vanish, so the mean support force equals
/// the mean mesh force, which carries the torque: the mean dynamic reactions are the static
/// ones averaged over the mesh cycle. Over the last 20 of 30 mesh periods at 300 rad/s
/// (mesh frequency well below the body modes), within 1 % of each body's force (resp. moment)
/// magnitude.
#[test]
fn mean_dynamic_support_forces_are_the_static_reactions() {
    let omega = 300.0;
    let (mut m, tr, spp) = example_run(omega, 30);
    let stats = support_force_stats(&tr, spp, 2).unwrap();
    let supports = *m.supports();
    let pitch = 2.0 * std::f64::consts::PI / m.drive().z_p as f64;
    let curve = supported_static_curve(
        m.mesh_mut(),
        100.0,
        0.0,
        pitch,
        16,
        1,
        &supports,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let mut mean = [0.0; 10];
    for e in &curve.points {
        let o = &e.outputs;
        let w = [
            o.force_p[0],
            o.force_p[1],
            o.force_p[2],
            o.moment_p[0],
            o.moment_p[1],
            o.force_g[0],
            o.force_g[1],
            o.force_g[2],
            o.moment_g[0],
            o.moment_g[1],
        ];
        for (a, b) in mean.iter_mut().zip(w) {
            // The reaction balances the mesh wrench.
            *a -= b / curve.points.len() as f64;
        }
    }
    for body in 0..2 {
        let norm =
            |r: std::ops::Range<usize>| r.map(|k| mean[5 * body + k].powi(2)).sum::<f64>().sqrt();
        let (f, mo) = (norm(0..3), norm(3..5));
        for k in 0..5 {
            let c = 5 * body + k;
            let scale = if k < 3 { f } else { mo };
            let d = (stats[c].mean - mean[c]) / scale;
            eprintln!(
                "component {c}: dynamic mean {:.4} static {:.4}: {:.2e} of the magnitude \
                 (peak to peak {:.3}, orders {:?})",
                stats[c].mean, mean[c], d, stats[c].peak_to_peak, stats[c].orders
            );
            assert!(d.abs() < 0.01, "component {c}: {d:e}");
        }
    }
}

/// The power balance of the 28 states: the energy the drive puts in, minus what the brake
/// takes and the shaft and support dampers dissipate, plus the work of the mesh on all four
/// bodies (its torques on the hubs, its force and moments on the bodies), is the change of the
/// kinetic energy and of the springs' energy. The gyroscopic moments do no work. Trapezoidal
/// quadrature over the recorded RK4 steps; residual within 1e-4 of the input work.
#[test]
fn the_power_balance_closes() {
    let omega = 300.0;
    let (m, tr, _) = example_run(omega, 6);
    let d = *m.drive();
    let s = *m.supports();
    let sp = [s.pinion.unwrap(), s.gear.unwrap()];
    let energy = |y: &[f64; N_BODY_STATES]| {
        let mut e = 0.5
            * (d.j1 * y[4] * y[4] + d.j_p * y[5] * y[5] + d.j_g * y[6] * y[6] + d.j2 * y[7] * y[7]);
        e += 0.5 * (d.c1 * (y[0] - y[1]).powi(2) + d.c2 * (y[2] - y[3]).powi(2));
        for (b, sup) in sp.iter().enumerate() {
            for k in 0..5 {
                let v = y[RATE_P + 5 * b + k];
                e += 0.5 * if k < 3 { sup.mass_kg } else { sup.j_transverse_kgm2 } * v * v;
                for l in 0..5 {
                    e += 0.5 * y[POSE_P + 5 * b + k] * sup.stiffness[k][l] * y[POSE_P + 5 * b + l];
                }
            }
        }
        e
    };
    let state = |i: usize| {
        let mut y = [0.0; N_BODY_STATES];
        y[..8].copy_from_slice(&tr.drive.states[i]);
        y[8..].copy_from_slice(&tr.bodies[i]);
        y
    };
    let power = |i: usize| {
        let y = state(i);
        let o = &tr.drive.outputs[i];
        let p_in = d.torque * y[4] + d.brake_torque() * y[7];
        let damp = d.d1 * (y[4] - y[5]).powi(2) + d.d2 * (y[6] - y[7]).powi(2);
        let mut mesh = -(o.m_f_p + o.m_d_p) * y[5] - (o.m_f_g + o.m_d_g) * y[6];
        let w = [
            [o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]],
            [o.force_g[0], o.force_g[1], o.force_g[2], o.moment_g[0], o.moment_g[1]],
        ];
        let mut sup_damp = 0.0;
        for b in 0..2 {
            for k in 0..5 {
                let v = y[RATE_P + 5 * b + k];
                mesh += w[b][k] * v;
                for l in 0..5 {
                    sup_damp += v * sp[b].damping[k][l] * y[RATE_P + 5 * b + l];
                }
            }
        }
        (p_in - damp - sup_damp + mesh, d.torque * y[4])
    };
    let (mut work, mut input) = (0.0, 0.0);
    for i in 1..tr.drive.time.len() {
        let h = tr.drive.time[i] - tr.drive.time[i - 1];
        let (a, ai) = power(i - 1);
        let (b, bi) = power(i);
        work += 0.5 * h * (a + b);
        input += 0.5 * h * (ai + bi);
    }
    let de = energy(&state(tr.drive.time.len() - 1)) - energy(&state(0));
    eprintln!("ΔE = {de:.6e} J, net work {work:.6e} J, input {input:.6e} J");
    assert!((de - work).abs() < 1e-4 * input, "{:e}", (de - work) / input);
}

/// The linearised coupled modes describe the model's own small vibrations: at standstill under
/// the torque (no mesh excitation; supports without damping, the mesh damping of Eq. 14),
/// started from the static equilibrium displaced along the real part of one mode's shape (a
/// displacement of 10 nm), the nonlinear 28-state model vibrates at that mode's frequency
/// Im λ/2π. Measured by the zero crossings of the most displaced coordinate over 12 periods,
/// for every mode above 1 kHz (where the mesh and the bodies move together), within 10⁻³
/// (measured: 2.3·10⁻⁵ at most, 11 modes from 1.23 to 4.53 kHz). This checks the
/// linearisation (its central differences of the mesh) and the mode shapes against the
/// nonlinear model; the sweep's resonances are not measured here.
#[test]
fn the_coupled_modes_are_the_free_vibrations() {
    let mut supports = Supports::from_json(EXAMPLE).unwrap();
    for body in [&mut supports.pinion, &mut supports.gear] {
        body.as_mut().unwrap().damping = [[0.0; 5]; 5];
    }
    let mut m = SupportedDynamics::new(mesh(60), drive(), supports).unwrap();
    let start = m.static_start(0.0, 0.0, &EquilibriumSettings::default()).unwrap();
    let modes = m.linear_modes(&start).unwrap();
    let gp = 0.03;
    // Length scale of each position coordinate: angles times a radius, tilts times g_p.
    let length = |i: usize| match i {
        0..=3 => gp,
        POSE_P..RATE_P if (i - POSE_P) % 5 >= 3 => gp,
        POSE_P..RATE_P => 1.0,
        _ => 0.0,
    };
    let dt = supported_rk4_step(m.drive(), &modes, 0.0);
    let mut tested = 0;
    for (l, v) in modes.eigenvalues.iter().zip(&modes.shapes) {
        let f = l.im / (2.0 * std::f64::consts::PI);
        if f < 1e3 {
            continue;
        }
        let (j, big) = (0..RATE_P)
            .map(|i| (i, v[i].re.abs() * length(i)))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        let scale = 1e-8 / big;
        let mut y0 = start.y;
        for (y, c) in y0.iter_mut().zip(v) {
            *y += c.re * scale;
        }
        let n = (12.0 / f / dt).ceil() as usize;
        let tr = simulate_supported(&mut m, &y0, dt, n, &modes).unwrap();
        let x: Vec<f64> = (0..tr.drive.time.len())
            .map(|k| {
                let y = if j < 8 { tr.drive.states[k][j] } else { tr.bodies[k][j - 8] };
                y - start.y[j]
            })
            .collect();
        let mut crossings = Vec::new();
        for k in 1..x.len() {
            if x[k - 1] != 0.0 && x[k - 1].signum() != x[k].signum() {
                let s = x[k - 1] / (x[k - 1] - x[k]);
                crossings.push(tr.drive.time[k - 1] + s * dt);
            }
        }
        let measured =
            (crossings.len() - 1) as f64 / (2.0 * (crossings[crossings.len() - 1] - crossings[0]));
        let d = measured / f - 1.0;
        eprintln!(
            "mode {f:8.1} Hz (ζ {:.3}), coordinate {j}: free vibration {measured:8.1} Hz, {d:+.2e}",
            -l.re / l.norm()
        );
        assert!(d.abs() < 1e-3, "mode {f} Hz: measured {measured} Hz");
        tested += 1;
    }
    assert!(tested >= 8, "{tested} modes above 1 kHz");
}

/// At table fidelity (the table with its pose sensitivities, `mesh::table::PoseTable`) the
/// supported run follows the full model's: on the example supports at 300 rad/s over 4 mesh
/// periods, TE within 2·10⁻³ of its peak-to-peak (measured 2.1·10⁻⁴), the support forces
/// within 2·10⁻³ of their peak-to-peak (4.4·10⁻⁴) and the coupled modes within 10⁻³
/// (3.1·10⁻⁵).
#[test]
fn the_table_with_poses_runs_the_supported_dynamics() {
    let supports = Supports::from_json(EXAMPLE).unwrap();
    let omega = 300.0;
    let run = |fidelity: helical_gear_mesh::mesh::Fidelity| {
        let m = Mesh::new(
            &GearPair::paper_table1(),
            MeshOptions { fidelity, ..MeshOptions::default() },
        )
        .unwrap();
        let mut d = SupportedDynamics::new(m, drive(), supports).unwrap();
        let start = d.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
        let modes = d.linear_modes(&start).unwrap();
        let dt = supported_rk4_step(d.drive(), &modes, omega);
        let spp = (d.drive().mesh_period(omega) / dt).round() as usize;
        let t0 = std::time::Instant::now();
        let tr = simulate_supported(&mut d, &start.y, dt, 4 * spp, &modes).unwrap();
        (tr, t0.elapsed().as_secs_f64(), modes)
    };
    let (full, t_full, m_full) = run(helical_gear_mesh::mesh::Fidelity::Full);
    let (table, t_table, m_table) = run(helical_gear_mesh::mesh::Fidelity::Table);
    assert_eq!(full.drive.time.len(), table.drive.time.len());
    let te: Vec<f64> = full.drive.outputs.iter().map(|o| o.te).collect();
    let ptp = |x: &[f64]| {
        x.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - x.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let dte = full
        .drive
        .outputs
        .iter()
        .zip(&table.drive.outputs)
        .map(|(a, b)| (a.te - b.te).abs())
        .fold(0.0, f64::max);
    let mut dr = 0.0f64;
    for c in 0..10 {
        let a: Vec<f64> = full.reactions.iter().map(|r| r.values()[c]).collect();
        let b: Vec<f64> = table.reactions.iter().map(|r| r.values()[c]).collect();
        let d = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        dr = dr.max(d / ptp(&a));
    }
    let df = m_full
        .frequencies_hz()
        .iter()
        .zip(m_table.frequencies_hz())
        .map(|(a, b)| (b / a - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "table vs full: TE within {:.2e} of TE's peak-to-peak ({:.3} µm), support forces within \
         {dr:.2e} of their peak-to-peak, modes within {df:.2e}; {:.3} µs against {:.1} µs per \
         mesh evaluation",
        dte / ptp(&te),
        ptp(&te) * 1e6,
        t_table / table.drive.mesh_evaluations as f64 * 1e6,
        t_full / full.drive.mesh_evaluations as f64 * 1e6
    );
    assert!(dte < 2e-3 * ptp(&te) && dr < 2e-3 && df < 1e-3);
}

/// The shaft form (`mesh::shaft`): the gear on a shaft in two bearings, the pinion on the
/// example support. Two bearings hold a shaft statically determinately, so the mean dynamic
/// bearing forces over a steady window are the rigid-shaft statics of `mesh::bearings`
/// (`static --bearings`) for the mean mesh wrench on the gear, within 1 % of the bearing force's
/// magnitude; the radial forces of the two bearings and the mesh force balance.
#[test]
fn shaft_bearing_forces_are_the_statics_on_average() {
    use helical_gear_mesh::dynamics::bodies::bearing_force_stats;
    use helical_gear_mesh::mesh::bearings::ShaftBearings;
    let json = r#"{"pinion": {"mass_kg": 2, "j_transverse_kgm2": 1e-3,
        "stiffness": {"radial_n_per_m": 6e8, "axial_n_per_m": 3e8, "tilt_nm_per_rad": 8e5},
        "damping": {"radial_ns_per_m": 2000, "axial_ns_per_m": 1000, "tilt_nms_per_rad": 2}},
      "gear": {"mass_kg": 5, "j_transverse_kgm2": 1e-2, "shaft": {"bending_stiffness_nm2": 3e4,
        "bearings": [{"z_m": -0.02, "radial_n_per_m": 1e9, "axial_n_per_m": 3e8},
                     {"z_m": 0.035, "radial_n_per_m": 1e9}]},
        "damping": {"radial_ns_per_m": 4000, "axial_ns_per_m": 2000, "tilt_nms_per_rad": 5}}}"#;
    let b = GearPair::paper_table1().face_width_m;
    let supports = Supports::from_json_for(json, b).unwrap();
    let omega = 300.0;
    let mut m = SupportedDynamics::new(mesh(60), drive(), supports).unwrap();
    let start = m.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let modes = m.linear_modes(&start).unwrap();
    let dt = supported_rk4_step(m.drive(), &modes, omega);
    let spp = (m.drive().mesh_period(omega) / dt).round() as usize;
    let tr = simulate_supported(&mut m, &start.y, dt, spp * 30, &modes).unwrap();
    let bs = bearing_force_stats(&tr, &supports, spp, 2);
    assert_eq!(bs.len(), 2);
    // The mean mesh wrench on the gear over the same window.
    let w = spp * (tr.drive.outputs.len() - 1) / spp;
    let win = &tr.drive.outputs[tr.drive.outputs.len() - w..];
    let mean = |f: &dyn Fn(&helical_gear_mesh::mesh::MeshOutputs) -> f64| {
        win.iter().map(f).sum::<f64>() / win.len() as f64
    };
    let force = [mean(&|o| o.force_g[0]), mean(&|o| o.force_g[1]), mean(&|o| o.force_g[2])];
    let moment = [mean(&|o| o.moment_g[0]), mean(&|o| o.moment_g[1])];
    let statics = ShaftBearings { locating_z_m: -0.02, floating_z_m: 0.035 }.reactions(
        0.5 * b,
        force,
        moment,
    );
    for (k, (s, st)) in bs.iter().zip(&statics).enumerate() {
        let mag = st.iter().map(|x| x * x).sum::<f64>().sqrt();
        for (c, (dyn_c, st_c)) in s.components.iter().zip(st).enumerate() {
            let d = (dyn_c.mean - st_c).abs() / mag;
            eprintln!(
                "bearing {k} ({:.3} m) component {c}: dynamic mean {:.3} N, statics {st_c:.3} N \
                 ({d:.2e} of {mag:.1} N), peak to peak {:.2} N",
                s.z_m, dyn_c.mean, dyn_c.peak_to_peak
            );
            assert!(d < 0.01, "bearing {k} component {c}");
        }
    }
}
