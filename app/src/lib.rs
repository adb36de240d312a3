//! # helical_gear_app
//!
//! The applications of the `helical_gear_mesh` model library, kept out of it so that the
//! library (and with it the FMUs and the C API) links neither the figures nor the command line:
//!
//! * [`paper`]: the paper run (static TE, speed sweeps, dynamic waterfalls, sensitivity) into
//!   CSV, PNG, `summary.json` and `summary.md`;
//! * [`bench`](mod@bench): the work-precision benchmark (`helical-gear bench`);
//! * [`pages`]: the documentation pages generated from the benchmark's and the paper run's
//!   reports (`docs/performance.md`, the paper-run section of `docs/validation.md`);
//! * [`plot`]: PNG figures (plotters, embedded DejaVu Sans) and CSV tables; no physics.
//!
//! The `helical-gear` binary (`src/main.rs`, commands in `src/cli/`) and the Python package's
//! `helical_gear.paper` are built on it. Units are those of the model library: SI throughout.

pub mod bench;
pub mod pages;
pub mod paper;
pub mod plot;
