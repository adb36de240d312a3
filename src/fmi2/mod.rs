//! The FMI 2.0 Co-Simulation interface of the mesh model (model identifier
//! `HelicalGearMesh`).
//!
//! The FMU is a thin layer over the mesh model façade: inputs are the hub angles and speeds
//! (φp, φg, φ̇p, φ̇g), outputs the mesh torques of Eqs. 13–14 with diagnostics. It has no state
//! of its own, so every output is a direct function of the inputs (direct feedthrough): a
//! master may set the inputs and read the outputs as often as it likes between communication
//! points (for example at every stage of a Runge–Kutta step); the outputs are recomputed
//! lazily, on the first read after an input changed. `fmi2DoStep` only advances the time.
//!
//! * [`variables`] — the one variable table (names, value references, units, start values);
//!   `modelDescription.xml`, the GUID, the documentation and the reference pages `docs/fmu/`
//!   are generated from it.
//! * [`exports`] — the 34 exported `fmi2*` functions (common and co-simulation).
//! * [`types`] — the C types of the standard.
//! * [`uri`] — decoding of the resource-location URI.
//!
//! Conventions (as in the rest of the crate): SI units; φp and φg are measured in the same
//! absolute sense, TE = φp·g_p + φg·g_g (Eq. 16) with the base radii g; the mesh torques enter
//! the pinion and gear equations (Eqs. 2–3) with a minus sign and are positive in normal drive.
//!
//! State machine: the one of the FMI 2.0 standard for co-simulation (section 4.2.4), enforced
//! per function; an illegal call logs "`fmi2X`: not allowed in state …" and returns
//! `fmi2Error`. Any `fmi2Error` leaves the instance in the error state, from which `fmi2Reset`
//! (start values) or `fmi2SetFMUstate` (a saved state) recover. Fixed parameters may be set
//! until `fmi2ExitInitializationMode`, which validates them and builds the model; `d_mesh` is
//! tunable. The one String parameter, `modifications` (the JSON object of the gear pair's
//! `modifications` key), is parsed by `fmi2SetString` (bad JSON or an unknown key: an error
//! naming it) and validated with the other parameters. Errors are always passed to the logger, with `%` escaped; debug categories
//! (`logModel`, `logCalls`, …) only when debug logging is on.
//!
//! Resources: the model needs no file at run time. The compliance data of the default gear
//! pair is compiled into the library (the FMU's `resources/compliance_table1.json` is a copy
//! for reference); other gear data run the FE at `fmi2ExitInitializationMode` and are cached on
//! disk only when `HELICAL_GEAR_CACHE_DIR` is set (see [`crate::compliance::data`]). The decoded
//! `resources/` path is only reported in the `logModel` category.

mod instance;

pub mod exports;
pub mod model;
pub mod models;
pub mod types;
pub mod uri;
pub mod variables;
