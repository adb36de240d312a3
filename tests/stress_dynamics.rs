//! Stress test: Eqs. 1–4 from slow running to 3·ω_crit (docs/robustness.md, "Stress tests").
//!
//! A mesh-periodic linear spring (k(φp) = k₀·(1 + a·cos z_p·φp), a = 0.1) with a small
//! backlash puts the mesh mode near the paper's (ω_crit ≈ 660 rad/s): around ω_crit and its
//! fractions the parametric excitation makes the teeth separate, hit the back flanks and
//! re-contact. For d_mesh = 100 and 200 N·s/m and speeds from 0.1 to 3·ω_crit the adaptive
//! DOPRI5 runs must stay finite and bounded, keep the energy bookkeeping (kinetic + shaft
//! springs + mesh spring − work of the torques + dissipation − parametric work of the
//! varying stiffness = const) and shrink the step where the contact changes. The real mesh
//! model (coarse table fidelity) is run at a few speeds up to 3·ω_crit as well, where the
//! tip-rounding contact and the separation of the paper appear.

mod common;

use std::ops::ControlFlow;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::dynamics::model::{PHI_1, PHI_2, PHI_G, PHI_P, W_1, W_2, W_G, W_P};
use helical_gear_mesh::dynamics::{
    Clearance, Dopri5, Dopri5Options, Drivetrain, GearDynamics, OdeError, OdeSystem,
    PeriodicStiffnessMesh, Stepping, simulate,
};
use helical_gear_mesh::mesh::Mesh;
use helical_gear_mesh::mesh::statics::EquilibriumSettings;

use common::{rhs_with_dissipation, small_table_options};

const K0: f64 = 1.2e8;
const A: f64 = 0.1;
const BACKLASH: f64 = 5e-6;

/// Eqs. 1–4 plus two quadratures: y[8] the energy dissipated (d₁, d₂, mesh damper), y[9] the
/// work ∫½·k′(φp)·φ̇p·δ² dt that the varying stiffness does (F = k·δ has no potential).
struct Balanced {
    model: GearDynamics<PeriodicStiffnessMesh>,
    z_p: f64,
}

fn deflection(te: f64) -> f64 {
    if te > 0.0 {
        te
    } else if te < -BACKLASH {
        te + BACKLASH
    } else {
        0.0
    }
}

impl OdeSystem for Balanced {
    fn dim(&self) -> usize {
        10
    }

    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) -> Result<(), OdeError> {
        rhs_with_dissipation(&mut self.model, t, y, d)?;
        let k_prime = -K0 * A * self.z_p * (self.z_p * y[PHI_P]).sin();
        let delta = deflection(self.model.te(&y[..8]));
        d[9] = 0.5 * k_prime * y[W_P] * delta * delta;
        Ok(())
    }
}

fn energy(sys: &Balanced, y: &[f64]) -> f64 {
    let d = sys.model.drive();
    let k = K0 * (1.0 + A * (sys.z_p * y[PHI_P]).cos());
    let delta = deflection(sys.model.te(&y[..8]));
    0.5 * (d.j1 * y[W_1].powi(2)
        + d.j_p * y[W_P].powi(2)
        + d.j_g * y[W_G].powi(2)
        + d.j2 * y[W_2].powi(2))
        + 0.5 * d.c1 * (y[PHI_1] - y[PHI_P]).powi(2)
        + 0.5 * d.c2 * (y[PHI_G] - y[PHI_2]).powi(2)
        + 0.5 * k * delta * delta
}

#[derive(Default, Debug)]
struct RunStats {
    separations: usize,
    recontacts: usize,
    back_steps: usize,
    worst_balance: f64,
    energy_scale: f64,
    h_median: f64,
    h_min_at_change: f64,
    te_max: f64,
    te_min: f64,
    rejected: usize,
}

fn run(d_mesh: f64, omega: f64, periods: f64) -> RunStats {
    let pair = GearPair::paper_table1();
    let geo = helical_gear_mesh::PairGeometry::new(&pair).unwrap();
    let (gp, gg) = (geo.pinion.rb, geo.gear.rb);
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    let mesh =
        PeriodicStiffnessMesh::new(K0, A, drive.z_p, d_mesh, gp, gg, Clearance::Backlash(BACKLASH))
            .unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let mut y = [0.0; 10];
    y[..8].copy_from_slice(&start.y);
    let y0 = y;
    let mut sys = Balanced { model, z_p: f64::from(drive.z_p) };
    let e0 = energy(&sys, &y0);
    let t_end = periods * drive.mesh_period(omega);
    let opts = Dopri5Options { rtol: 1e-10, ..Dopri5Options::with_tolerances(1e-10, 1e-13) };
    let mut dp = Dopri5::new(10, opts).unwrap();
    let mut st =
        RunStats { te_min: f64::INFINITY, te_max: f64::NEG_INFINITY, ..RunStats::default() };
    let mut hs = Vec::new();
    let mut h_change = f64::INFINITY;
    let mut prev_state = 1; // 1 drive, 0 separated, −1 back
    let dr = drive;
    let stats = dp
        .integrate(&mut sys, 0.0, t_end, &mut y, |step| {
            let ye = step.y_end();
            assert!(ye.iter().all(|v| v.is_finite()), "non-finite state at {}", step.t_end());
            let te = ye[PHI_P] * gp + ye[PHI_G] * gg;
            st.te_max = st.te_max.max(te);
            st.te_min = st.te_min.min(te);
            let state = if te > 0.0 {
                1
            } else if te < -BACKLASH {
                -1
            } else {
                0
            };
            if state != prev_state {
                h_change = h_change.min(step.h());
                if state == 0 {
                    st.separations += 1;
                }
                if prev_state == 0 {
                    st.recontacts += 1;
                }
            }
            st.back_steps += usize::from(state == -1);
            prev_state = state;
            hs.push(step.h());
            ControlFlow::Continue(())
        })
        .unwrap_or_else(|e| panic!("d {d_mesh}, ω {omega}: {e}"));
    st.rejected = stats.rejected;
    // Energy bookkeeping at the end (the quadratures are integrated with the same accuracy).
    let work = dr.torque * (y[PHI_1] - y0[PHI_1]) + dr.brake_torque() * (y[PHI_2] - y0[PHI_2]);
    let bal = energy(&sys, &y) - e0 + y[8] - work - y[9];
    st.worst_balance = bal.abs();
    st.energy_scale = y[8].abs() + y[9].abs() + work.abs() + e0.abs();
    hs.sort_by(f64::total_cmp);
    st.h_median = hs[hs.len() / 2];
    st.h_min_at_change = h_change;
    st
}

#[test]
fn zero_to_three_omega_crit_both_dampings() {
    let pair = GearPair::paper_table1();
    let geo = helical_gear_mesh::PairGeometry::new(&pair).unwrap();
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    // The mesh mode of the linear mesh: the highest of the four frequencies; ω_crit = ω_m/z_p.
    let w = drive.linear_frequencies(K0, geo.pinion.rb, geo.gear.rb);
    let omega_mesh = w.iter().copied().fold(0.0, f64::max);
    let omega_crit = omega_mesh / f64::from(drive.z_p);
    let ste = drive.torque / (K0 * geo.pinion.rb);
    let t0 = std::time::Instant::now();
    for d_mesh in [100.0, 200.0] {
        let (mut seps, mut backs, mut recs, mut shrunk) = (0, 0, 0, 0);
        for f in [0.1, 0.34, 0.5, 0.8, 0.95, 1.0, 1.05, 1.3, 2.0, 3.0] {
            let omega = f * omega_crit;
            let s = run(d_mesh, omega, 60.0);
            assert!(
                s.te_max < 30.0 * ste && s.te_min > -30.0 * ste,
                "d {d_mesh}, ω {omega:.0}: TE in [{:.3e}, {:.3e}] m (STE {ste:.3e})",
                s.te_min,
                s.te_max
            );
            let rel = s.worst_balance / s.energy_scale;
            assert!(
                rel < 1e-7,
                "d {d_mesh}, ω {omega:.0}: energy balance off by {rel:.2e} ({s:?})"
            );
            if s.separations > 0 {
                seps += 1;
                recs += usize::from(s.recontacts > 0);
                if s.h_min_at_change < 0.5 * s.h_median {
                    shrunk += 1;
                }
            }
            backs += usize::from(s.back_steps > 0);
            eprintln!(
                "d {d_mesh:>3}, ω {omega:>6.0} rad/s: TE {:+.1}…{:+.1} µm, separations {}, \
                 back steps {}, energy {rel:.1e}, h median {:.2e}, h at contact change \
                 {:.2e}, rejected {}",
                s.te_min * 1e6,
                s.te_max * 1e6,
                s.separations,
                s.back_steps,
                s.h_median,
                s.h_min_at_change,
                s.rejected
            );
        }
        assert!(seps > 0 && recs > 0, "d {d_mesh}: no separation and re-contact");
        assert_eq!(shrunk, seps, "d {d_mesh}: the step did not shrink at every contact change");
        if d_mesh == 100.0 {
            assert!(backs > 0, "no back-flank impact");
        }
    }
    eprintln!("ω_crit {omega_crit:.1} rad/s; {:.1} s", t0.elapsed().as_secs_f64());
}

/// The real mesh (Table 1, embedded compliance, coarse table) from slow running to
/// 3·ω_crit, each run kicked by ±150 rad/s on the pinion so that TE swings through the
/// backlash onto the back flanks and up onto the tip roundings (where the table hands over to
/// the full model): adaptive DOPRI5, finite and bounded, and separation, back-flank impacts,
/// re-contact and tip-rounding contact all occur.
#[test]
fn real_mesh_kicked_up_to_three_omega_crit() {
    kicked_real_mesh(&[(532.0, -150.0), (1600.0, 150.0)], 3e-3);
}

/// The longer variant: four speeds from slow running to 3·ω_crit, 8 ms each (about 20 s):
/// `cargo test --test stress_dynamics -- --ignored`.
#[test]
#[ignore]
fn real_mesh_kicked_long() {
    kicked_real_mesh(&[(60.0, 150.0), (532.0, -150.0), (570.0, 150.0), (1600.0, 150.0)], 8e-3);
}

fn kicked_real_mesh(runs: &[(f64, f64)], t_end: f64) {
    let pair = GearPair::paper_table1();
    let options = small_table_options();
    let t0 = std::time::Instant::now();
    let mesh = Mesh::new(&pair, options).unwrap();
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    let (mut tip, mut sep, mut back, mut recontact) = (0, 0, 0, 0);
    for d_mesh in [100.0, 200.0] {
        for &(omega, kick) in runs {
            let mut m = mesh.clone();
            m.set_d_mesh(d_mesh).unwrap();
            let mut model = GearDynamics::new(m, drive).unwrap();
            let start = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
            let mut y0 = start.y;
            y0[W_P] += kick;
            let stepping = Stepping::Dopri5 {
                options: Dopri5Options::with_tolerances(1e-8, 1e-12),
                output_dt: None,
            };
            let tr = simulate(&mut model, &y0, t_end, &stepping)
                .unwrap_or_else(|e| panic!("d {d_mesh}, ω {omega}: {e}"));
            let (mut te_lo, mut te_hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut was_sep = false;
            for (y, o) in tr.states.iter().zip(&tr.outputs) {
                assert!(y.iter().all(|v| v.is_finite()) && o.m_f_p.is_finite());
                te_lo = te_lo.min(o.te);
                te_hi = te_hi.max(o.te);
                tip += usize::from(o.tip_contact);
                sep += usize::from(o.separated);
                back += usize::from(o.back_contact);
                recontact += usize::from(was_sep && !o.separated);
                was_sep = o.separated;
            }
            // Bounded: the kick's energy cannot carry TE beyond a few backlashes.
            assert!(te_hi < 1e-3 && te_lo > -1e-3, "d {d_mesh}, ω {omega}: blow-up");
            // And the last steps are back near the static TE (decaying, not growing).
            let last = tr.outputs.last().unwrap().te;
            assert!((last - start.te).abs() < (te_hi - te_lo), "d {d_mesh}, ω {omega}: growing");
            eprintln!(
                "real mesh d {d_mesh}, ω {omega}, kick {kick}: TE {:.1}…{:.1} µm, {} steps, \
                 {} mesh evaluations",
                te_lo * 1e6,
                te_hi * 1e6,
                tr.steps,
                tr.mesh_evaluations
            );
        }
    }
    eprintln!(
        "tip {tip}, separated {sep}, back {back}, re-contacts {recontact} (output steps); {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    assert!(tip > 0, "no tip-rounding contact");
    assert!(sep > 0 && back > 0 && recontact > 0, "no separation, back contact or re-contact");
}
