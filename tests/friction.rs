//! Mesh friction (`mesh::friction`) against oracles derived here.
//!
//! * **Kinematics of the involute.** Both gears turn about their axes, the pinion about the
//!   origin, the gear about (a, 0); at the rigid ratio φ̇p·r_wp = −φ̇g·r_wg the two flank
//!   velocities agree at the pitch point C = (r_wp, 0), so v_p − v_g = (φ̇p − φ̇g)·ẑ × (P − C).
//!   A contact on both involutes lies on the line of action through C along the normal n,
//!   P − C = s·n, so the sliding is (φ̇p − φ̇g)·s·(ẑ × n): tangent to the flanks, of speed
//!   |φ̇p − φ̇g|·|s|, and it reverses with s at the pitch point. The friction on the pinion
//!   opposes it: (f·(ẑ × n)) has the sign of −s (φ̇p > 0), magnitude μ·F·g(|v|/v₀).
//! * **Power.** f·v_p and −f·v_g are the powers of the friction on each body, so
//!   M_R,p·φ̇p + M_R,g·φ̇g = P_loss = μ·Σ F·|v|²/√(|v|² + v₀²) ≥ 0 at every state, Q_p + Q_g =
//!   P_loss, and at standstill nothing is lost.
//! * **Mean loss against the loss factor.** With a load per unit length q uniform along every
//!   contact line (a Winkler foundation without tip relief and without the local Hertz term:
//!   every involute slice sees the same overlap TE) and F_n = F_bt/cos β_b, the mean loss over
//!   a mesh cycle is μ·F_n·(φ̇p − φ̇g)·⟨|s|⟩ over the plane of action, ⟨|s|⟩ = (g_a² + g_f²)/
//!   (2·g_α) with g_a = ε₁·p_et, g_f = ε₂·p_et the parts of the path of contact g_α beyond the
//!   pitch point. With P_in = F_bt·r_bp·φ̇p and φ̇p − φ̇g = φ̇p·(u + 1)/u:
//!
//!   ```text
//!   P_loss/(μ·P_in) = π·(u + 1)/(z₁·u·cos β_b) · (ε₁² + ε₂²)/ε_α = H_uniform
//!   ```
//!
//!   ISO/TR 14179-2's H_V has (1 − ε_α + ε₁² + ε₂²) in place of (ε₁² + ε₂²)/ε_α: the spur
//!   gear's load sharing (one pair carries all, two carry half each). The model's true load
//!   sharing lies between and is stated against H_V.
//! * **Energy of a steady run.** Over a whole number of mesh periods of the steady state, the
//!   work of the input torque minus that of the brake equals the energy dissipated (shaft
//!   dampers, mesh damper of Eq. 14, friction loss) plus the net work of the elastic mesh
//!   torques plus the change of the stored energies (kinetic, shafts), each term integrated
//!   along the trajectory with the states (quadrature states of the same RK4 steps). The
//!   elastic term is not zero by construction (the mesh stiffness turns with the phase), so
//!   the test reports it beside the friction loss, and holds the balance itself.
//! * **Scaling.** The loss is linear in μ (μ multiplies every slice), and at speeds far above
//!   v₀ linear in the speed (the sliding is); ISO/TR 14179-2's μ falls as v_Σc^−0.2, so the
//!   loss with it grows as the speed^0.8.

mod common;

use std::ops::ControlFlow;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::contact::{ContactSolver, FlankSide};
use helical_gear_mesh::geometry::SegmentKind;
use helical_gear_mesh::mesh::friction::{FrictionModel, loss_factor_h_v, slice_friction};
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Fidelity, ForceFrame, Friction, Mesh, MeshJacobian, MeshOptions,
    MeshState, MeshTorques, static_curve_with, winkler_compliances,
};

use helical_gear_mesh::dynamics::model::{PHI_1, PHI_2, W_1, W_2, W_G, W_P};
use helical_gear_mesh::dynamics::{
    Drivetrain, GearDynamics, OdeError, OdeSystem, Rk4, SteadyRunOptions, run_to_steady,
};

use common::table1_pitch;

fn options(friction: Friction, fidelity: Fidelity, slices: usize) -> MeshOptions {
    MeshOptions {
        fidelity,
        slices,
        friction,
        table_phase_points: 32,
        table_te_points: 24,
        ..MeshOptions::default()
    }
}

fn table1(friction: Friction, fidelity: Fidelity, slices: usize) -> Mesh {
    Mesh::new(&GearPair::paper_table1(), options(friction, fidelity, slices)).expect("Table 1")
}

/// A running state at pinion angle `phi_p`, TE `te`, pinion speed `w_p` at the rigid ratio
/// plus a TE rate `te_rate` (m/s).
fn running(m: &Mesh, phi_p: f64, te: f64, w_p: f64, te_rate: f64) -> MeshState {
    let g = m.geometry();
    let (gp, gg) = (g.pinion.rb, g.gear.rb);
    MeshState {
        phi_p,
        phi_g: g.phi_g_for_te(phi_p, te),
        w_p,
        w_g: -w_p * gp / gg + te_rate / gg,
        ..Default::default()
    }
}

/// Mean loss over a mesh cycle at torque 100 N·m and `w_p`, over μ·P_in.
fn mean_loss_ratio(m: &mut Mesh, mu: f64, w_p: f64) -> f64 {
    let s = EquilibriumSettings { w_p, ..EquilibriumSettings::default() };
    let c = static_curve_with(m, 100.0, 0.0, table1_pitch(), 64, 1, &s).expect("static curve");
    let loss = c.points.iter().map(|e| e.outputs.p_loss).sum::<f64>() / c.points.len() as f64;
    loss / (mu * 100.0 * w_p)
}

#[test]
fn zero_friction_reproduces_the_frictionless_model_bit_for_bit() {
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut none = table1(Friction::none(), fidelity, 60);
        let mut zero = table1(Friction::constant(0.0), fidelity, 60);
        for k in 0..12 {
            let s = running(&none, 0.05 * k as f64, 2e-5 + 2e-6 * k as f64, 300.0, 1e-3);
            let (a, b) = (none.evaluate(&s).unwrap(), zero.evaluate(&s).unwrap());
            assert_eq!(a, b, "{fidelity:?} state {k}");
            assert_eq!(b.p_loss, 0.0);
            assert_eq!(b.eta_mesh, 1.0);
        }
    }
}

#[test]
fn sliding_on_the_involute_reverses_at_the_pitch_point() {
    let pair = GearPair::paper_table1();
    let m = table1(Friction::none(), Fidelity::Full, 60);
    let geo = m.geometry();
    let frame = ForceFrame::new(geo);
    let cs = ContactSolver::new(geo);
    let (sin_wt, cos_wt) = geo.alpha_wt.sin_cos();
    let r_wp = geo.pinion.rb / cos_wt;
    let w_p = 300.0;
    let w_g = -w_p * geo.pinion.rb / geo.gear.rb;
    let zetas: Vec<f64> = (0..40).map(|i| (i as f64 + 0.5) * geo.b0() / 40.0).collect();
    let mut contacts = Vec::new();
    let (mut ahead, mut behind, mut checked) = (0, 0, 0);
    for k in 0..40 {
        let phi_p = table1_pitch() * k as f64 / 40.0;
        let phi_g = geo.phi_g_for_te(phi_p, 2e-5);
        cs.contacts_on(FlankSide::Drive, phi_p, phi_g, &zetas, &mut contacts);
        for c in &contacts {
            if c.kind_p != SegmentKind::Involute || c.kind_g != SegmentKind::Involute {
                continue;
            }
            let n = c.normal_angle.sin_cos();
            let n = [n.1, n.0];
            // The normal of the plane of action passes through the pitch point.
            assert!((n[0] - sin_wt).abs() < 1e-9 && (n[1] - cos_wt).abs() < 1e-9, "{n:?}");
            let s = (c.point_p[0] - r_wp) * n[0] + c.point_p[1] * n[1];
            let t = [-n[1], n[0]];
            let sf = slice_friction(&frame, c, 1.0, w_p, w_g, 0.05);
            let speed = (w_p - w_g) * s.abs();
            assert!(
                (sf.sliding_speed - speed).abs() <= 1e-9 * speed.max(1e-3),
                "speed {} vs {speed}",
                sf.sliding_speed
            );
            let f = sf.wrench.force_p;
            let ft = f[0] * t[0] + f[1] * t[1];
            if speed > 0.5 {
                // Coulomb far outside the band: the whole μ·F, against the pinion's sliding.
                let f_n = (1.0 + (frame.twist_p * c.arm_p_m).powi(2)).sqrt();
                let f = f_n * speed / (speed * speed + 0.05f64.powi(2)).sqrt();
                assert!((sf.force - f).abs() < 1e-9 * f, "{} vs {f}", sf.force);
                assert_eq!(ft.signum(), -s.signum(), "s = {s:e}");
                if s > 0.0 { ahead += 1 } else { behind += 1 }
            }
            checked += 1;
        }
    }
    let _ = pair;
    assert!(checked > 500 && ahead > 100 && behind > 100, "{checked} {ahead} {behind}");
}

#[test]
fn friction_power_balances_the_loss_and_standstill_loses_nothing() {
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = table1(Friction::constant(0.07), fidelity, 60);
        let mut worst: f64 = 0.0;
        for k in 0..24 {
            let w_p = [300.0, -120.0, 0.3, 1e-4][k % 4];
            let te = 1e-5 + 2.5e-6 * k as f64;
            // The full model at any TE rate; the table's friction assumes the rigid ratio
            // (module docs of `mesh::table`, "Friction"), so there the TE rate is zero.
            let te_rate = if fidelity == Fidelity::Full { 2e-3 * (k as f64 - 12.0) } else { 0.0 };
            let s = running(&m, 0.031 * k as f64, te, w_p, te_rate);
            let o = m.evaluate(&s).unwrap();
            let balance = o.m_r_p * s.w_p + o.m_r_g * s.w_g - o.p_loss;
            worst = worst.max(balance.abs() / o.p_loss.max(1e-9 * w_p.abs() * 100.0));
            assert!(o.p_loss >= 0.0);
            assert!((o.q_p + o.q_g - o.p_loss).abs() <= 1e-12 * o.p_loss.max(1e-300));
            assert!((0.0..=1.0).contains(&o.eta_mesh));
            assert!(balance.abs() <= 1e-9 * o.p_loss.max(1e-6), "{balance:e} of {}", o.p_loss);
            let rest = m.evaluate(&running(&m, 0.031 * k as f64, te, 0.0, 0.0)).unwrap();
            assert_eq!((rest.p_loss, rest.m_r_p, rest.m_r_g), (0.0, 0.0, 0.0));
        }
        eprintln!("{fidelity:?}: power balance of the friction, worst relative {worst:.2e}");
    }
}

#[test]
fn uniform_load_sharing_gives_the_loss_factor_of_the_uniform_plane_of_action() {
    // Winkler foundation, no tip relief, no local term: q is the same at every involute slice.
    let mut pair = GearPair::paper_table1();
    pair.tip_relief_depth_mn = 0.0;
    let (p, g) = winkler_compliances(&pair, 1.4e10).unwrap();
    let opts = MeshOptions {
        local_contact: false,
        ..options(Friction::constant(0.05), Fidelity::Full, 400)
    };
    let mut m = Mesh::with_compliance(&pair, opts, p, g).unwrap();
    let geo = m.geometry().clone();
    let (s, c) = geo.alpha_wt.sin_cos();
    let e1 = ((geo.pinion.ra.powi(2) - geo.pinion.rb.powi(2)).sqrt() - geo.pinion.rb / c * s)
        / geo.base_pitch;
    let e2 =
        ((geo.gear.ra.powi(2) - geo.gear.rb.powi(2)).sqrt() - geo.gear.rb / c * s) / geo.base_pitch;
    let u = geo.gear.z as f64 / geo.pinion.z as f64;
    let k =
        std::f64::consts::PI * (u + 1.0) / (geo.pinion.z as f64 * u * geo.base_helix_angle.cos());
    let h_uniform = k * (e1 * e1 + e2 * e2) / (e1 + e2);
    let h_v = k * (1.0 - (e1 + e2) + e1 * e1 + e2 * e2);
    assert!((loss_factor_h_v(&geo) - h_v).abs() < 1e-12);
    let ratio = mean_loss_ratio(&mut m, 0.05, 300.0);
    eprintln!(
        "uniform load: P_loss/(μ·P_in) = {ratio:.5}, H_uniform {h_uniform:.5} ({:+.2} %), \
         H_V {h_v:.5}",
        100.0 * (ratio / h_uniform - 1.0)
    );
    assert!((ratio / h_uniform - 1.0).abs() < 0.02, "{ratio} vs {h_uniform}");
}

#[test]
fn mean_loss_against_iso_loss_factor_with_the_true_load_sharing() {
    // The FE compliance: without tip relief the true load sharing is close to H_V's (a few
    // per cent); Table 1's tip relief unloads the ends of the path of contact, where the
    // sliding is fastest, and the loss falls well below μ·H_V·P_in.
    let mut plain = GearPair::paper_table1();
    plain.tip_relief_depth_mn = 0.0;
    let opts = options(Friction::constant(0.05), Fidelity::Full, 200);
    let mut m_plain = Mesh::new(&plain, opts).unwrap();
    let mut m_relief = table1(Friction::constant(0.05), Fidelity::Full, 200);
    let h_v = loss_factor_h_v(m_relief.geometry());
    let r_plain = mean_loss_ratio(&mut m_plain, 0.05, 300.0);
    let r_relief = mean_loss_ratio(&mut m_relief, 0.05, 300.0);
    eprintln!(
        "H_V {h_v:.5}; P_loss/(μ·P_in): without tip relief {r_plain:.5} ({:+.1} %), Table 1 \
         {r_relief:.5} ({:+.1} %)",
        100.0 * (r_plain / h_v - 1.0),
        100.0 * (r_relief / h_v - 1.0)
    );
    assert!((0.11..0.14).contains(&h_v), "{h_v}");
    assert!((r_plain / h_v - 1.0).abs() < 0.06, "{r_plain} vs {h_v}");
    assert!(r_relief < r_plain);
}

#[test]
fn loss_scales_with_mu_and_speed_as_the_laws_say() {
    // A narrow regularisation band (1 mm/s), so that the sliding is Coulomb at every slice
    // but those within a few µm of the pitch line.
    let v0 = 1e-3;
    let constant = |mu| Friction { regularisation_speed_m_s: v0, ..Friction::constant(mu) };
    let mut a = table1(constant(0.05), Fidelity::Full, 100);
    let mut b = table1(constant(0.10), Fidelity::Full, 100);
    let iso = Friction {
        model: FrictionModel::IsoTr14179_2,
        regularisation_speed_m_s: v0,
        ..Friction::default()
    };
    let mut c = table1(iso, Fidelity::Full, 100);
    for k in 0..8 {
        let phi = 0.02 * k as f64;
        let s1 = running(&a, phi, 3e-5, 300.0, 0.0);
        let s2 = running(&a, phi, 3e-5, 600.0, 0.0);
        let (o1, o2) = (a.evaluate(&s1).unwrap(), a.evaluate(&s2).unwrap());
        let ob = b.evaluate(&s1).unwrap();
        assert!((ob.p_loss / o1.p_loss - 2.0).abs() < 1e-12, "μ: {}", ob.p_loss / o1.p_loss);
        assert!((ob.m_r_p / o1.m_r_p - 2.0).abs() < 1e-12);
        assert!((o2.p_loss / o1.p_loss - 2.0).abs() < 2e-4, "speed: {}", o2.p_loss / o1.p_loss);
        let (i1, i2) = (c.evaluate(&s1).unwrap(), c.evaluate(&s2).unwrap());
        let expected = 2f64.powf(0.8);
        let r = i2.p_loss / i1.p_loss / expected - 1.0;
        assert!(r.abs() < 2e-4, "ISO speed: {r:e}");
    }
}

#[test]
fn table_friction_agrees_with_the_full_model_at_running_speed() {
    let mut full = table1(Friction::constant(0.05), Fidelity::Full, 100);
    let mut table = table1(Friction::constant(0.05), Fidelity::Table, 100);
    let (mut worst_loss, mut worst_torque, mut worst_mf): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for k in 0..40 {
        let phi = table1_pitch() * (k as f64 + 0.37) / 40.0;
        let te = 1.5e-5 + 4e-7 * k as f64;
        let s = running(&full, phi, te, 300.0, 0.0);
        let (f, t) = (full.evaluate(&s).unwrap(), table.evaluate(&s).unwrap());
        worst_loss = worst_loss.max((t.p_loss - f.p_loss).abs() / f.p_loss);
        // Friction torques change sign over the cycle: relative to the nominal torque.
        worst_torque = worst_torque.max((t.m_r_p - f.m_r_p).abs() / 100.0);
        worst_mf = worst_mf.max((t.m_f_p - f.m_f_p).abs() / f.m_f_p);
    }
    eprintln!(
        "table vs full at 300 rad/s: P_loss {worst_loss:.2e} relative, M_R,p {worst_torque:.2e} \
         of the nominal torque, M_F,p {worst_mf:.2e}"
    );
    assert!(worst_loss < 0.02 && worst_torque < 5e-3 && worst_mf < 0.02);
}

#[test]
fn friction_jacobian_matches_differences_of_the_evaluation() {
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = table1(Friction::constant(0.05), fidelity, 60);
        let s = running(&m, 0.11, 2.5e-5, 300.0, 1e-3);
        let (_, jac) = m.mesh_jacobian(&s).unwrap();
        for (col, h) in [(MeshJacobian::PHI_P, 2e-6), (MeshJacobian::W_P, 1e-2)] {
            let at = |d: f64| {
                let mut x = s;
                if col == MeshJacobian::PHI_P {
                    x.phi_p += d
                } else {
                    x.w_p += d
                }
                x
            };
            let (p, q) = (m.evaluate(&at(h)).unwrap(), m.evaluate(&at(-h)).unwrap());
            let fd = (p.m_f_p - q.m_f_p) / (2.0 * h);
            let row = jac.d[MeshJacobian::M_F_P];
            let scale = row.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            eprintln!("{fidelity:?} col {col}: jacobian {:.6e}, differences {fd:.6e}", row[col]);
            assert!((row[col] - fd).abs() < 2e-3 * scale, "{} vs {fd}", row[col]);
        }
    }
}

/// Eqs. 1–4 with quadrature states: [8] shaft dampers, [9] mesh damper, [10] friction loss,
/// [11] power of the elastic mesh torques into the mesh, (M_F − M_R)·φ̇ of both gears.
struct Quadrature {
    model: GearDynamics<Mesh>,
}

impl OdeSystem for Quadrature {
    fn dim(&self) -> usize {
        12
    }

    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) -> Result<(), OdeError> {
        self.model.rhs(t, &y[..8], &mut d[..8])?;
        let o = self.model.outputs(&y[..8]).map_err(|e| OdeError::rhs(t, e))?;
        let dr = self.model.drive();
        d[8] = dr.d1 * (y[W_1] - y[W_P]).powi(2) + dr.d2 * (y[W_G] - y[W_2]).powi(2);
        d[9] = o.m_d_p * y[W_P] + o.m_d_g * y[W_G];
        d[10] = o.p_loss;
        d[11] = (o.m_f_p - o.m_r_p) * y[W_P] + (o.m_f_g - o.m_r_g) * y[W_G];
        Ok(())
    }
}

#[test]
fn steady_drive_line_balances_input_output_and_the_losses() {
    let pair = GearPair::paper_table1();
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    let omega = 300.0;
    for mu in [0.0, 0.05] {
        let opts = MeshOptions {
            table_design_torque_nm: drive.torque,
            ..options(Friction::constant(mu), Fidelity::Table, 100)
        };
        let mesh = Mesh::new(&pair, opts).unwrap();
        let mut model = GearDynamics::new(mesh, drive).unwrap();
        let r = run_to_steady(&mut model, omega, &SteadyRunOptions::default()).unwrap();
        assert!(r.steady);
        let (n_per, periods) = (r.samples_per_period, 16usize);
        let t_m = r.mesh_period;
        let mut y = [0.0; 12];
        y[..8].copy_from_slice(&r.y_end);
        let y0 = y;
        let mut sys = Quadrature { model };
        let d = *sys.model.drive();
        let stored = |sys: &mut Quadrature, y: &[f64]| {
            0.5 * (d.j1 * y[W_1].powi(2)
                + d.j_p * y[W_P].powi(2)
                + d.j_g * y[W_G].powi(2)
                + d.j2 * y[W_2].powi(2))
                + 0.5 * d.c1 * (y[PHI_1] - y[1]).powi(2)
                + 0.5 * d.c2 * (y[2] - y[PHI_2]).powi(2)
                + 0.0 * sys.model.te(&y[..8])
        };
        let e0 = stored(&mut sys, &y0);
        let (mut te, mut fz) = (Vec::new(), Vec::new());
        let mut rk4 = Rk4::new(12);
        let mut yy = y;
        let mut samples = Vec::new();
        rk4.integrate(&mut sys, 0.0, periods as f64 * t_m, periods * n_per, &mut yy, |_, _, y| {
            samples.push(*<&[f64; 12]>::try_from(y).unwrap());
            ControlFlow::Continue(())
        })
        .unwrap();
        for s in &samples {
            let o = sys.model.outputs(&s[..8]).unwrap();
            te.push(o.te);
            fz.push(o.force_p[2]);
        }
        y = yy;
        let t = periods as f64 * t_m;
        let input = d.torque * (y[PHI_1] - y0[PHI_1]) / t;
        let output = -d.brake_torque() * (y[PHI_2] - y0[PHI_2]) / t;
        let (shafts, damper, friction, elastic) = (y[8] / t, y[9] / t, y[10] / t, y[11] / t);
        let change = (stored(&mut sys, &y) - e0) / t;
        let residual = input - output - shafts - damper - friction - elastic - change;
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let p2p = |v: &[f64]| {
            v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
        };
        eprintln!(
            "μ = {mu}: input {input:.4} W, output {output:.4} W; shafts {shafts:.4e}, mesh damper \
             {damper:.4e}, friction {friction:.4} W, elastic mesh work {elastic:.4e} W, stored \
             {change:.3e} W; residual {:.2e} of the input; TE mean {:.4} µm, p-p {:.4} µm; F_p,z \
             mean {:.3} N, p-p {:.3} N",
            residual / input,
            mean(&te) * 1e6,
            p2p(&te) * 1e6,
            mean(&fz),
            p2p(&fz)
        );
        assert!(residual.abs() < 1e-6 * input, "balance {residual:e} W of {input} W");
        if mu > 0.0 {
            // The dynamic mean loss is the quasi-static one of the same mesh cycle (the brake
            // was set from it) within the small dynamic TE.
            let quasi_static = 1.0 - sys.model.drive().brake_factor;
            let dynamic = friction / input;
            eprintln!("mean loss over input: dynamic {dynamic:.5}, quasi-static {quasi_static:.5}");
            assert!((dynamic / quasi_static - 1.0).abs() < 0.02);
        }
    }
}

/// The Drive unit (the engine of the Drive FMU) with friction: its static start sets the brake
/// to take the power the mesh delivers, so the drive line keeps its mean speed (without it the
/// brake would take 0.44 % more power than arrives and the line would slow down).
#[test]
fn drive_unit_with_friction_keeps_its_speed() {
    use helical_gear_mesh::dynamics::{DriveUnit, UnitKind, UnitStepping};
    let pair = GearPair::paper_table1();
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    let opts = MeshOptions {
        table_design_torque_nm: drive.torque,
        ..options(Friction::constant(0.05), Fidelity::Table, 100)
    };
    let mesh = Mesh::new(&pair, opts).unwrap();
    let stepping = UnitStepping::Rk4 { steps_per_mesh_period: 64 };
    let mut u = DriveUnit::new(UnitKind::Drive, mesh, drive, stepping).unwrap();
    let omega = 300.0;
    u.start_static(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let (mut loss, n) = (0.0, 4000);
    let (mut first, mut last) = (0.0, 0.0);
    for k in 0..n {
        u.advance(5e-5).unwrap();
        let o = u.outputs().unwrap();
        loss += o.mesh.p_loss / n as f64;
        if k < n / 4 {
            first += o.w_p / (n / 4) as f64;
        } else if k >= n - n / 4 {
            last += o.w_p / (n / 4) as f64;
        }
    }
    // A brake that did not take the loss off would decelerate the line by the loss torque
    // over the inertia reduced to the pinion.
    let r = drive.z_p as f64 / drive.z_g as f64;
    let j = drive.j1 + drive.j_p + (drive.j_g + drive.j2) * r * r;
    let drift_unbalanced = loss / omega / j * 0.15;
    eprintln!(
        "Drive unit, μ = 0.05: mean ω_p {first:.4} rad/s over the first 0.05 s, {last:.4} over \
         the last 0.05 s (an unbalanced brake: −{drift_unbalanced:.3} rad/s); mean loss {loss:.2} W"
    );
    assert!((last - first).abs() < 0.1 * drift_unbalanced, "{first} → {last}");
    assert!(loss > 0.003 * drive.torque * omega && loss < 0.006 * drive.torque * omega, "{loss}");
}
