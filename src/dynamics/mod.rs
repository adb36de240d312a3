//! The 4-DOF torsional model of Eqs. 1–4 and its integrators.
//!
//! * [`integrators`]: the [`OdeSystem`] trait for first-order systems y' = f(t, y), the
//!   classical fixed-step Runge–Kutta method [`Rk4`] and the adaptive Dormand–Prince 5(4)
//!   method [`Dopri5`] with dense output; errors are typed ([`OdeError`]), so a failure of the
//!   mesh-torque evaluation propagates instead of turning into NaN.

pub mod integrators;

pub use integrators::{
    AbsTol, Dopri5, Dopri5Options, Dopri5Stats, Dopri5Step, FnSystem, OdeError, OdeSystem, Rk4,
};
