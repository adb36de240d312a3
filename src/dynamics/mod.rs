//! The 4-DOF torsional model of Eqs. 1–4 and its integrators.
//!
//! * [`integrators`]: the [`OdeSystem`] trait for first-order systems y' = f(t, y), the
//!   classical fixed-step Runge–Kutta method [`Rk4`] and the adaptive Dormand–Prince 5(4)
//!   method [`Dopri5`] with dense output; errors are typed ([`OdeError`]), so a failure of the
//!   mesh-torque evaluation propagates instead of turning into NaN.
//! * [`steady`]: detection of the periodic steady state of the transmission error (period
//!   k·T_m, k = 1 or a small subharmonic multiple), from samples on a uniform grid.
//! * [`limits`]: the one stable RK4 step rule of every integration and the bounds on the work
//!   a request may ask for.
//! * [`model`]: Eqs. 1–4 as an [`OdeSystem`] over any [`crate::mesh::MeshTorques`], the
//!   drivetrain data, the static-equilibrium start and the linearised natural frequencies.
//! * [`simulate`](mod@simulate): trajectories and runs to the steady state.
//! * [`sweep`](mod@sweep): speed sweeps in parallel, the static TE curve and the location of resonances.
//! * [`unit`](mod@unit): stateful drive-line units (pair, stage, whole drive) with their own
//!   state and integrator, for co-simulation and Model Exchange.
//! * [`relative`]: the relative coordinates (TE, shaft twists) in which a Model Exchange master
//!   integrates a unit.
//! * [`bodies`]: both gear bodies on elastic supports coupled to Eqs. 1–4 (28 states), their
//!   static start, linearised coupled modes and trajectories with the support forces.
//! * [`supported_sweep`]: speed sweeps with the bodies on their supports (steady TE and support
//!   forces per speed).
//! * [`analytic_mesh`]: linear-spring mesh models with closed-form behaviour, for verification.

pub mod analytic_mesh;
pub mod bodies;
pub mod integrators;
pub mod kind;
pub mod limits;
pub mod model;
pub mod relative;
pub mod simulate;
pub mod steady;
pub mod supported_sweep;
pub mod sweep;
pub mod unit;

pub use analytic_mesh::{Clearance, ConstantStiffnessMesh, PeriodicStiffnessMesh};
pub use integrators::{
    AbsTol, Dopri5, Dopri5Options, Dopri5Stats, Dopri5Step, FnSystem, OdeError, OdeSystem,
    Quantity, Rk4,
};
pub use limits::{
    MAX_REFINE_RUNS, MAX_SPECTRUM_SAMPLES, MAX_STEADY_STEPS, MAX_SWEEP_SPEEDS,
    MAX_TRAJECTORY_SAMPLES, MAX_UNIT_SUBSTEPS, MAX_WINDOW_SAMPLES, RK4_MAX_OMEGA_H,
    STEPS_PER_FAST_PERIOD, check_rk4_step, fastest_mode, stable_rk4_step,
};
pub use model::{Drivetrain, DynamicsError, GearDynamics, StaticStart, mesh_stiffness};
pub use simulate::{
    DEFAULT_STEPS_PER_MESH_PERIOD, SteadyMethod, SteadyResponse, SteadyRunOptions, SteadyWarning,
    Stepping, Trajectory, WindowSample, default_rk4_step, run_to_steady, simulate,
};
pub use steady::{PeriodCheck, SteadyError, SteadyOptions, SteadyState, SteadyStatus};
pub use sweep::{
    PeakOverStatic, Resonance, StaticPeaks, SweepOptions, SweepPoint, SweepResult,
    check_sweep_request, find_peaks, static_te_curve, sweep,
};
pub use unit::{
    DriveUnit, HeldInputs, HubCoupling, HubReference, UnitInputRates, UnitInputs, UnitKind,
    UnitLinearization, UnitOutputs, UnitQuantity, UnitSnapshot, UnitStepping,
};
