//! The 4-DOF torsional model of Eqs. 1–4 and its integrators.
//!
//! * [`integrators`]: the [`OdeSystem`] trait for first-order systems y' = f(t, y), the
//!   classical fixed-step Runge–Kutta method [`Rk4`] and the adaptive Dormand–Prince 5(4)
//!   method [`Dopri5`] with dense output; errors are typed ([`OdeError`]), so a failure of the
//!   mesh-torque evaluation propagates instead of turning into NaN.
//! * [`steady`]: detection of the periodic steady state of the transmission error (period
//!   k·T_m, k = 1 or a small subharmonic multiple), from samples on a uniform grid.

pub mod integrators;
pub mod steady;

pub use integrators::{
    AbsTol, Dopri5, Dopri5Options, Dopri5Stats, Dopri5Step, FnSystem, OdeError, OdeSystem,
    Quantity, Rk4,
};
pub use steady::{PeriodCheck, SteadyError, SteadyOptions, SteadyState, SteadyStatus};
