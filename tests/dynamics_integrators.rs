//! Tests of the RK4 and DOPRI5 integrators on problems with known solutions.

mod common;

use std::f64::consts::PI;
use std::ops::ControlFlow;

use helical_gear_mesh::dynamics::integrators::{
    AbsTol, Dopri5, Dopri5Options, FnSystem, OdeError, OdeSystem, Quantity, Rk4,
};

use common::Lcg;

/// Harmonic oscillator y0' = y1, y1' = −ω²·y0 with y(0) = (1, 0): y0 = cos ωt, y1 = −ω sin ωt.
struct Oscillator {
    omega: f64,
}

impl Oscillator {
    fn exact(&self, t: f64) -> [f64; 2] {
        [(self.omega * t).cos(), -self.omega * (self.omega * t).sin()]
    }
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }

    fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) -> Result<(), OdeError> {
        d[0] = y[1];
        d[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
}

/// Kepler problem (μ = 1): q'' = −q/|q|³, state (q1, q2, p1, p2).
struct Kepler;

impl OdeSystem for Kepler {
    fn dim(&self) -> usize {
        4
    }

    fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) -> Result<(), OdeError> {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        d[0] = y[2];
        d[1] = y[3];
        d[2] = -y[0] / r3;
        d[3] = -y[1] / r3;
        Ok(())
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn cont() -> ControlFlow<()> {
    ControlFlow::Continue(())
}

// ----------------------------------------------------------------------------------------------
// RK4
// ----------------------------------------------------------------------------------------------

#[test]
fn rk4_observed_order_is_four() {
    let mut sys = Oscillator { omega: 1.0 };
    let t_end = 2.0;
    let mut errors = Vec::new();
    for n in [10usize, 20, 40, 80] {
        let mut rk4 = Rk4::new(2);
        let mut y = [1.0, 0.0];
        let t = rk4.integrate(&mut sys, 0.0, t_end, n, &mut y, |_, _, _| cont()).unwrap();
        assert_eq!(t, t_end);
        assert_eq!(rk4.rhs_evals(), 4 * n);
        errors.push(max_abs_diff(&y, &sys.exact(t_end)));
    }
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        eprintln!("RK4: error {:.3e} -> {:.3e}, observed order {order:.3}", w[0], w[1]);
        assert!((order - 4.0).abs() < 0.2, "observed order {order}");
    }
}

#[test]
fn rk4_callback_sees_every_step_and_can_stop() {
    let mut sys = Oscillator { omega: 1.0 };
    let mut rk4 = Rk4::new(2);
    let mut y = [1.0, 0.0];
    let mut times = Vec::new();
    let t = rk4
        .integrate(&mut sys, 0.0, 1.0, 10, &mut y, |i, t, _| {
            times.push((i, t));
            if i == 4 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })
        .unwrap();
    assert_eq!(times.len(), 4);
    assert_eq!(t, 0.4);
    assert_eq!(times[3], (4, 0.4));
    let mut y_full = [1.0, 0.0];
    let mut last = 0.0;
    rk4.integrate(&mut sys, 0.0, 1.0, 10, &mut y_full, |_, t, _| {
        last = t;
        cont()
    })
    .unwrap();
    assert_eq!(last, 1.0);
}

#[test]
fn rk4_reports_non_finite_derivative() {
    let mut sys = FnSystem::new(2, |t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[1];
        d[1] = if t > 0.5 { f64::NAN } else { -y[0] };
        Ok(())
    });
    let mut rk4 = Rk4::new(2);
    let mut y = [1.0, 0.0];
    let err = rk4.integrate(&mut sys, 0.0, 1.0, 10, &mut y, |_, _, _| cont()).unwrap_err();
    match err {
        OdeError::NonFinite { t, component, quantity, .. } => {
            assert_eq!(component, 1);
            assert_eq!(quantity, Quantity::Derivative);
            assert!(t > 0.5 && t <= 0.6, "t = {t}");
        }
        e => panic!("unexpected error {e}"),
    }
    // The state is that of the last completed step, still finite.
    assert!(y.iter().all(|v| v.is_finite()));
}

#[test]
fn rk4_reports_blow_up_as_non_finite_state() {
    // y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
    let mut sys = FnSystem::new(1, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[0] * y[0];
        Ok(())
    });
    let mut rk4 = Rk4::new(1);
    let mut y = [1.0];
    let err = rk4.integrate(&mut sys, 0.0, 2.0, 20, &mut y, |_, _, _| cont()).unwrap_err();
    assert!(matches!(err, OdeError::NonFinite { component: 0, .. }), "{err}");
    assert!(err.to_string().contains("non-finite"));
}

#[test]
fn rk4_rejects_wrong_dimension() {
    let mut sys = Oscillator { omega: 1.0 };
    let mut rk4 = Rk4::new(3);
    let mut y = [1.0, 0.0];
    let err = rk4.step(&mut sys, 0.0, 0.1, &mut y).unwrap_err();
    assert!(matches!(err, OdeError::DimensionMismatch { .. }));
}

// ----------------------------------------------------------------------------------------------
// DOPRI5
// ----------------------------------------------------------------------------------------------

fn dopri(tol: f64) -> Dopri5Options {
    Dopri5Options::with_tolerances(tol, tol)
}

#[test]
fn dopri5_oscillator_meets_tolerance_over_many_periods() {
    // ω = 2π: period 1 s, 20 periods, rtol = atol = tol. The step-size control bounds the local
    // error per step, so the (mostly phase) error grows about linearly with the number of
    // periods: check it per period, and check that it is proportional to tol.
    let mut sys = Oscillator { omega: 2.0 * PI };
    let mut ratios = Vec::new();
    for tol in [1e-6, 1e-9] {
        let mut solver = Dopri5::new(2, dopri(tol)).unwrap();
        let mut y = [1.0, 0.0];
        let mut max_err_first: f64 = 0.0;
        let mut max_err: f64 = 0.0;
        let stats = solver
            .integrate(&mut sys, 0.0, 20.0, &mut y, |s| {
                let e = sys_exact_err(2.0 * PI, s.t_end(), s.y_end());
                if s.t_end() <= 1.0 {
                    max_err_first = max_err_first.max(e);
                }
                max_err = max_err.max(e);
                // Linear growth bound: after n periods the error is below 15·n·tol.
                assert!(e < 15.0 * tol * s.t_end().ceil(), "t = {}, error {e:e}", s.t_end());
                cont()
            })
            .unwrap();
        assert_eq!(stats.t_end, 20.0);
        eprintln!(
            "DOPRI5 oscillator tol {tol:e}: max error over the 1st period {max_err_first:.3e} \
             ({:.2}·tol), over 20 periods {max_err:.3e} ({:.1}·tol); {} accepted, {} rejected, \
             {} rhs",
            max_err_first / tol,
            max_err / tol,
            stats.accepted,
            stats.rejected,
            stats.rhs_evals
        );
        assert!(max_err_first < 15.0 * tol);
        ratios.push(max_err / tol);
        // FSAL: 6 evaluations per attempted step, plus f(t0) and the initial-step heuristic.
        assert_eq!(stats.rhs_evals, 6 * (stats.accepted + stats.rejected) + 2);
    }
    // Tolerance proportionality: 1000× tighter tolerance gives 300…3000× smaller error.
    assert!(ratios[1] / ratios[0] < 3.0 && ratios[1] / ratios[0] > 1.0 / 3.0, "{ratios:?}");
}

fn sys_exact_err(omega: f64, t: f64, y: &[f64]) -> f64 {
    max_abs_diff(y, &Oscillator { omega }.exact(t))
}

#[test]
fn dopri5_nonlinear_problems_meet_tolerance() {
    // y' = −y², y(0) = 1: y = 1/(1 + t).
    let mut riccati =
        FnSystem::new(1, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
            d[0] = -y[0] * y[0];
            Ok(())
        });
    let mut prev = f64::INFINITY;
    for tol in [1e-6, 1e-9] {
        let mut solver = Dopri5::new(1, dopri(tol)).unwrap();
        let mut y = [1.0];
        let mut max_err: f64 = 0.0;
        let stats = solver
            .integrate(&mut riccati, 0.0, 10.0, &mut y, |s| {
                max_err = max_err.max((s.y_end()[0] - 1.0 / (1.0 + s.t_end())).abs());
                cont()
            })
            .unwrap();
        eprintln!(
            "DOPRI5 y'=-y^2 on [0,10] tol {tol:e}: max error {max_err:.3e} ({:.2}·tol), {} steps",
            max_err / tol,
            stats.accepted
        );
        assert!(max_err < 10.0 * tol);
        assert!(max_err < prev / 100.0);
        prev = max_err;
    }

    // Kepler orbit, eccentricity 0.5, two revolutions (period 2π): back to the initial state.
    let e: f64 = 0.5;
    let y0 = [1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()];
    let mut prev = f64::INFINITY;
    for tol in [1e-6, 1e-9] {
        let mut solver = Dopri5::new(4, dopri(tol)).unwrap();
        let mut y = y0;
        let stats = solver.integrate(&mut Kepler, 0.0, 4.0 * PI, &mut y, |_| cont()).unwrap();
        let err = max_abs_diff(&y, &y0);
        eprintln!(
            "DOPRI5 Kepler e=0.5, 2 revolutions, tol {tol:e}: error {err:.3e} ({:.1}·tol), \
             {} accepted, {} rejected, h in [{:.2e}, {:.2e}]",
            err / tol,
            stats.accepted,
            stats.rejected,
            stats.h_min_used,
            stats.h_max_used
        );
        // Kepler's problem amplifies local errors (an energy error changes the period, and at
        // pericentre the velocity and acceleration are large), so the constant is larger.
        assert!(err < 1000.0 * tol);
        assert!(err < prev / 300.0);
        assert!(stats.h_max_used > 3.0 * stats.h_min_used, "step adapts along the orbit");
        prev = err;
    }
}

#[test]
fn dopri5_local_orders_of_step_and_dense_output() {
    // One step of y' = y from y(0) = 1 with a forced step h: local error of the step O(h⁶),
    // of the dense output at θ = 1/2 O(h⁵).
    let mut sys = FnSystem::new(1, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[0];
        Ok(())
    });
    let mut step_err = Vec::new();
    let mut dense_err = Vec::new();
    for h in [0.2, 0.1, 0.05, 0.025] {
        let opts = Dopri5Options {
            h_init: Some(h),
            h_max: Some(h),
            ..Dopri5Options::with_tolerances(1.0, 1.0)
        };
        let mut solver = Dopri5::new(1, opts).unwrap();
        let mut y = [1.0];
        let mut mid = 0.0;
        solver
            .integrate(&mut sys, 0.0, h, &mut y, |s| {
                mid = s.dense_component(0, 0.5 * h).unwrap();
                cont()
            })
            .unwrap();
        step_err.push((y[0] - h.exp()).abs());
        dense_err.push((mid - (0.5 * h).exp()).abs());
    }
    for (name, errs, expect) in [("step", &step_err, 6.0), ("dense", &dense_err, 5.0)] {
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            eprintln!("DOPRI5 local {name} error {:.3e} -> {:.3e}: order {order:.2}", w[0], w[1]);
            assert!((order - expect).abs() < 0.3, "{name} order {order}");
        }
    }
}

#[test]
fn dopri5_dense_output_accuracy_and_end_points() {
    let omega = 2.0 * PI;
    let mut sys = Oscillator { omega };
    let mut rng = Lcg(12345);
    for tol in [1e-6, 1e-9] {
        let mut solver = Dopri5::new(2, dopri(tol)).unwrap();
        let mut y = [1.0, 0.0];
        let (mut step_err, mut dense_err): (f64, f64) = (0.0, 0.0);
        let mut buf = [0.0; 2];
        let mut n_steps = 0;
        solver
            .integrate(&mut sys, 0.0, 5.0, &mut y, |s| {
                n_steps += 1;
                step_err = step_err.max(sys_exact_err(omega, s.t_end(), s.y_end()));
                for _ in 0..5 {
                    let t = s.t_start() + rng.uniform() * s.h();
                    s.dense_output(t, &mut buf).unwrap();
                    dense_err = dense_err.max(sys_exact_err(omega, t, &buf));
                }
                // θ = 1 and θ = 0 reproduce the step's end and start states exactly.
                s.dense_output(s.t_end(), &mut buf).unwrap();
                assert_eq!(buf, [s.y_end()[0], s.y_end()[1]]);
                s.dense_output(s.t_start(), &mut buf).unwrap();
                assert_eq!(buf, [s.y_start()[0], s.y_start()[1]]);
                assert!(s.dense_output(s.t_end() + 1e-9 * s.h().max(1.0), &mut buf).is_err());
                cont()
            })
            .unwrap();
        eprintln!(
            "DOPRI5 dense output tol {tol:e}: max step-end error {step_err:.3e}, max dense error \
             at random interior points {dense_err:.3e} (ratio {:.2}), {n_steps} steps",
            dense_err / step_err
        );
        assert!(dense_err < 5.0 * step_err.max(tol));
    }
}

#[test]
fn dopri5_dense_end_point_equals_step_end_on_nonlinear_problem() {
    // Same check on every step of the Kepler orbit, component by component, bit for bit.
    let e: f64 = 0.7;
    let mut y = [1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()];
    let mut solver = Dopri5::new(4, dopri(1e-8)).unwrap();
    let mut checked = 0;
    solver
        .integrate(&mut Kepler, 0.0, 2.0 * PI, &mut y, |s| {
            for i in 0..4 {
                assert_eq!(s.dense_component(i, s.t_end()).unwrap(), s.y_end()[i]);
            }
            checked += 1;
            cont()
        })
        .unwrap();
    assert!(checked > 50);
}

#[test]
fn dopri5_rejects_steps_at_a_sharp_transient_then_grows_again() {
    // y' = −y + 100·exp(−((t − 5)/0.01)²): smooth except for a pulse of width ~0.01 s at t = 5.
    let mut sys = FnSystem::new(1, |t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        let s = (t - 5.0) / 0.01;
        d[0] = -y[0] + 100.0 * (-s * s).exp();
        Ok(())
    });
    let opts = Dopri5Options { h_max: Some(0.5), ..dopri(1e-8) };
    let mut solver = Dopri5::new(1, opts).unwrap();
    let mut y = [1.0];
    let mut steps = Vec::new();
    let stats = solver
        .integrate(&mut sys, 0.0, 10.0, &mut y, |s| {
            steps.push((s.t_start(), s.h()));
            cont()
        })
        .unwrap();
    let max_h = |a: f64, b: f64| {
        steps.iter().filter(|(t, _)| *t >= a && *t < b).map(|s| s.1).fold(0.0, f64::max)
    };
    let h_before = max_h(2.0, 4.5);
    let h_pulse =
        steps.iter().filter(|(t, _)| (*t - 5.0).abs() < 0.05).map(|s| s.1).fold(1.0, f64::min);
    let h_after = max_h(7.0, 10.0);
    eprintln!(
        "DOPRI5 pulse: {} accepted, {} rejected; max step before {h_before:.3e}, min step in \
         the pulse {h_pulse:.3e}, max step after {h_after:.3e}",
        stats.accepted, stats.rejected
    );
    assert!(stats.rejected > 0);
    assert!(h_pulse < 0.01);
    assert!(h_before > 20.0 * h_pulse);
    assert!(h_after > 20.0 * h_pulse);
    // Exact solution after the pulse: y = e^(−t) + 100·∫ e^(−(t−s))·pulse(s) ds
    // ≈ e^(−t) + 100·0.01·√π·e^(−(t−5))·e^(0.01²/4).
    let exact = (-10.0f64).exp()
        + 100.0 * 0.01 * PI.sqrt() * (-5.0f64).exp() * (0.01f64 * 0.01 / 4.0).exp();
    assert!((y[0] - exact).abs() < 1e-6, "y(10) = {}, exact {exact}", y[0]);
}

#[test]
fn dopri5_rejects_steps_on_a_stiff_problem() {
    // y' = −1000·(y − cos t), y(0) = 0: after the initial layer the step is limited by
    // stability (|hλ| ≲ 3.3), not accuracy. The I controller (β = 0) keeps probing beyond the
    // limit and is rejected; the PI controller (default β = 0.04) smooths this out.
    let mut rejected = Vec::new();
    for beta in [0.0, 0.04] {
        let mut sys =
            FnSystem::new(1, |t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
                d[0] = -1000.0 * (y[0] - t.cos());
                Ok(())
            });
        let mut solver = Dopri5::new(1, Dopri5Options { beta, ..dopri(1e-3) }).unwrap();
        let mut y = [0.0];
        let stats = solver.integrate(&mut sys, 0.0, 1.0, &mut y, |_| cont()).unwrap();
        eprintln!(
            "DOPRI5 stiff (λ = −1000, tol 1e-3, β = {beta}): {} accepted, {} rejected, \
             h in [{:.2e}, {:.2e}]",
            stats.accepted, stats.rejected, stats.h_min_used, stats.h_max_used
        );
        assert!(stats.h_max_used < 5.0e-3);
        // Particular solution (10⁶·cos t + 10³·sin t)/(10⁶ + 1); the e^(−1000t) part is gone.
        let exact = (1e6 * 1f64.cos() + 1e3 * 1f64.sin()) / (1e6 + 1.0);
        assert!((y[0] - exact).abs() < 1e-3, "y(1) = {}, exact {exact}", y[0]);
        rejected.push(stats.rejected);
    }
    assert!(rejected[0] > 10);
    assert!(rejected[1] < rejected[0]);
}

#[test]
fn dopri5_non_finite_derivative_is_an_error() {
    let mut sys = FnSystem::new(3, |t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[1];
        d[1] = -y[0];
        d[2] = if t > 1.0 { f64::INFINITY } else { 0.0 };
        Ok(())
    });
    let mut solver = Dopri5::new(3, Dopri5Options::default()).unwrap();
    let mut y = [1.0, 0.0, 0.0];
    let err = solver.integrate(&mut sys, 0.0, 2.0, &mut y, |_| cont()).unwrap_err();
    match &err {
        OdeError::NonFinite { t, component: 2, quantity: Quantity::Derivative, value } => {
            assert!(*t > 1.0 && *t <= 2.0);
            assert_eq!(*value, f64::INFINITY);
        }
        e => panic!("unexpected error {e}"),
    }
    assert!(err.to_string().contains("component 2"), "{err}");
    assert!(y.iter().all(|v| v.is_finite()));
    assert!(solver.stats().accepted > 0);
}

#[test]
fn dopri5_blow_up_is_an_error_not_nan() {
    // y' = y², y(0) = 1: singular at t = 1.
    let mut sys = FnSystem::new(1, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[0] * y[0];
        Ok(())
    });
    let mut solver = Dopri5::new(1, Dopri5Options::default()).unwrap();
    let mut y = [1.0];
    let err = solver.integrate(&mut sys, 0.0, 2.0, &mut y, |_| cont()).unwrap_err();
    eprintln!("DOPRI5 on y' = y² through t = 1: {err}");
    assert!(matches!(
        err,
        OdeError::StepSizeTooSmall { .. }
            | OdeError::NonFinite { .. }
            | OdeError::TooManySteps { .. }
    ));
    assert!(y[0].is_finite() && y[0] > 1e3);
}

#[test]
fn dopri5_step_collapse_below_h_min_is_reported() {
    // y' = y², y(0) = 1: y = 1/(1 − t); the step needed near t = 1 falls below h_min = 1e-4.
    let mut sys = FnSystem::new(1, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = y[0] * y[0];
        Ok(())
    });
    let opts = Dopri5Options { h_min: 1e-4, ..dopri(1e-8) };
    let mut solver = Dopri5::new(1, opts).unwrap();
    let mut y = [1.0];
    let err = solver.integrate(&mut sys, 0.0, 2.0, &mut y, |_| cont()).unwrap_err();
    eprintln!("DOPRI5 with h_min = 1e-4 on y' = y²: {err}");
    assert!(err.to_string().contains("minimum step"));
    match err {
        OdeError::StepSizeTooSmall { t, h, h_min } => {
            assert_eq!(h_min, 1e-4);
            assert!(h < h_min);
            assert!(t < 1.0 && t > 0.9);
            assert!((y[0] - 1.0 / (1.0 - t)).abs() < 1e-6 * y[0]);
        }
        e => panic!("unexpected error {e}"),
    }
}

#[derive(Debug)]
struct LoadSolverFailed {
    iterations: usize,
}

impl std::fmt::Display for LoadSolverFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "load solver did not converge in {} iterations", self.iterations)
    }
}

impl std::error::Error for LoadSolverFailed {}

#[test]
fn rhs_failure_propagates_with_its_source() {
    let mut sys = FnSystem::new(1, |t: f64, _y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        if t > 0.32 {
            return Err(OdeError::rhs(t, LoadSolverFailed { iterations: 50 }));
        }
        d[0] = 1.0;
        Ok(())
    });
    let mut solver = Dopri5::new(1, Dopri5Options::default()).unwrap();
    let mut y = [0.0];
    let err = solver.integrate(&mut sys, 0.0, 1.0, &mut y, |_| cont()).unwrap_err();
    assert!(err.to_string().contains("did not converge"), "{err}");
    let src = std::error::Error::source(&err).unwrap();
    assert_eq!(src.downcast_ref::<LoadSolverFailed>().unwrap().iterations, 50);

    let mut rk4 = Rk4::new(1);
    let mut y = [0.0];
    let err = rk4.integrate(&mut sys, 0.0, 1.0, 10, &mut y, |_, _, _| cont()).unwrap_err();
    assert!(matches!(err, OdeError::Rhs { t, .. } if t > 0.32));
    // Failed in the fourth step (0.3 → 0.4); y is the state after three steps.
    assert!((y[0] - 0.3).abs() < 1e-12);
}

#[test]
fn dopri5_too_many_steps_and_bad_options() {
    let mut sys = Oscillator { omega: 2.0 * PI };
    let opts = Dopri5Options { max_steps: 10, ..dopri(1e-10) };
    let mut solver = Dopri5::new(2, opts).unwrap();
    let mut y = [1.0, 0.0];
    let err = solver.integrate(&mut sys, 0.0, 10.0, &mut y, |_| cont()).unwrap_err();
    assert!(matches!(err, OdeError::TooManySteps { max_steps: 10, .. }));

    for opts in [
        Dopri5Options { rtol: -1.0, ..Default::default() },
        Dopri5Options { rtol: 0.0, atol: 0.0.into(), ..Default::default() },
        Dopri5Options { safety: 1.5, ..Default::default() },
        Dopri5Options { h_init: Some(f64::NAN), ..Default::default() },
        Dopri5Options { atol: AbsTol::PerComponent(vec![1e-9]), ..Default::default() },
    ] {
        assert!(Dopri5::new(2, opts).is_err());
    }
    let mut solver = Dopri5::new(2, Dopri5Options::default()).unwrap();
    let mut y = [1.0, f64::NAN];
    assert!(matches!(
        solver.integrate(&mut sys, 0.0, 1.0, &mut y, |_| cont()),
        Err(OdeError::NonFinite { component: 1, quantity: Quantity::State, .. })
    ));
    let mut y = [1.0, 0.0];
    assert!(solver.integrate(&mut sys, 1.0, 0.0, &mut y, |_| cont()).is_err());
}

#[test]
fn dopri5_callback_break_and_uniform_sampling_with_dense_output() {
    // Sample the oscillator on a uniform grid of 0.01 s from the dense output and stop at 0.5 s.
    let omega = 2.0 * PI;
    let mut sys = Oscillator { omega };
    let mut solver = Dopri5::new(2, dopri(1e-9)).unwrap();
    let mut y = [1.0, 0.0];
    let dt = 0.01;
    let mut next = 1usize;
    let mut samples = Vec::new();
    let mut buf = [0.0; 2];
    let stats = solver
        .integrate(&mut sys, 0.0, 10.0, &mut y, |s| {
            while next as f64 * dt <= s.t_end() {
                let t = next as f64 * dt;
                s.dense_output(t, &mut buf).unwrap();
                samples.push((t, buf[0]));
                next += 1;
            }
            if s.t_end() >= 0.5 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })
        .unwrap();
    assert!(stats.t_end >= 0.5 && stats.t_end < 10.0);
    assert!(samples.len() >= 50);
    for (t, x) in samples {
        assert!((x - (omega * t).cos()).abs() < 1e-7);
    }
    // Continue from where it stopped with the proposed step.
    let opts = Dopri5Options { h_init: Some(stats.h_next), ..dopri(1e-9) };
    let mut solver = Dopri5::new(2, opts).unwrap();
    let stats2 = solver.integrate(&mut sys, stats.t_end, 3.0, &mut y, |_| cont()).unwrap();
    assert_eq!(stats2.rhs_evals, 6 * (stats2.accepted + stats2.rejected) + 1);
    assert!(sys_exact_err(omega, 3.0, &y) < 1e-7);
}

#[test]
fn dopri5_pure_relative_tolerance_with_a_zero_component() {
    // atol = 0: the component that stays exactly 0 must not make the error norm 0/0.
    let mut sys = FnSystem::new(2, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
        d[0] = -y[0];
        d[1] = 0.0;
        Ok(())
    });
    let mut solver = Dopri5::new(2, Dopri5Options::with_tolerances(1e-8, 0.0)).unwrap();
    let mut y = [1.0, 0.0];
    let stats = solver.integrate(&mut sys, 0.0, 2.0, &mut y, |_| cont()).unwrap();
    assert!((y[0] - (-2.0f64).exp()).abs() < 1e-7);
    assert_eq!(y[1], 0.0);
    assert!(stats.accepted < 100);
}
