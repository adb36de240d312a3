//! The C types of the FMI 2.0 standard (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`),
//! spelled as in the standard so that the generated declarations of the exported functions use
//! the standard's type names and a C compiler can check them against the standard's headers.
//!
//! Enumerations that the importer passes *in* (`fmi2Type`, `fmi2StatusKind`) are plain `c_int`
//! here: a Rust enum must never hold a value outside its variants, and the importer may pass
//! anything. `fmi2Status` is a Rust enum because the FMU only ever returns (or writes) it.
#![allow(non_camel_case_types)]

use std::ffi::{c_char, c_double, c_int, c_uint, c_void};

/// Pointer to an FMU instance (`fmi2Component`).
pub type fmi2Component = *mut c_void;
/// Pointer to the importer's environment, passed back in callbacks.
pub type fmi2ComponentEnvironment = *mut c_void;
/// Pointer to a saved FMU state.
pub type fmi2FMUstate = *mut c_void;
/// Value reference of a variable.
pub type fmi2ValueReference = c_uint;
/// Real value (C `double`).
pub type fmi2Real = c_double;
/// Integer value (C `int`).
pub type fmi2Integer = c_int;
/// Boolean value (C `int`, `fmi2False` = 0, `fmi2True` = 1).
pub type fmi2Boolean = c_int;
/// Character (C `char`).
pub type fmi2Char = c_char;
/// Zero-terminated string (C `const char*`).
pub type fmi2String = *const fmi2Char;
/// Byte of a serialised FMU state (C `char`).
pub type fmi2Byte = c_char;
/// Kind of FMU requested from `fmi2Instantiate` (0 = Model Exchange, 1 = Co-Simulation).
pub type fmi2Type = c_int;
/// Kind of status asked for with `fmi2Get*Status` (0 = DoStepStatus, 1 = PendingStatus,
/// 2 = LastSuccessfulTime, 3 = Terminated).
pub type fmi2StatusKind = c_int;

/// `fmi2True`.
pub const FMI2_TRUE: fmi2Boolean = 1;
/// `fmi2False`.
pub const FMI2_FALSE: fmi2Boolean = 0;
/// `fmi2CoSimulation` value of [`fmi2Type`].
pub const FMI2_CO_SIMULATION: fmi2Type = 1;
/// `fmi2ModelExchange` value of [`fmi2Type`].
pub const FMI2_MODEL_EXCHANGE: fmi2Type = 0;

/// What `fmi2NewDiscreteStates` reports (`fmi2EventInfo`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case)]
pub struct fmi2EventInfo {
    /// Another event iteration is needed.
    pub newDiscreteStatesNeeded: fmi2Boolean,
    /// The model asks to end the simulation.
    pub terminateSimulation: fmi2Boolean,
    /// The nominal values of the continuous states changed.
    pub nominalsOfContinuousStatesChanged: fmi2Boolean,
    /// The values of the continuous states changed.
    pub valuesOfContinuousStatesChanged: fmi2Boolean,
    /// `nextEventTime` holds the time of the next time event.
    pub nextEventTimeDefined: fmi2Boolean,
    /// Time of the next time event, s.
    pub nextEventTime: fmi2Real,
}

/// Return status of every FMI function (`fmi2Status`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum fmi2Status {
    /// All well.
    Ok = 0,
    /// Things are not quite right, but the computation can continue.
    Warning = 1,
    /// The result of this call is not usable; the instance itself is fine.
    Discard = 2,
    /// The instance cannot continue; `fmi2Reset`, `fmi2SetFMUstate` or `fmi2FreeInstance`.
    Error = 3,
    /// The instance is irreparably corrupted; only `fmi2FreeInstance` remains.
    Fatal = 4,
    /// An asynchronous step is running (never returned by this FMU).
    Pending = 5,
}

/// The importer's logger: `printf`-like, `message` is a format string (variadic).
pub type fmi2CallbackLogger = unsafe extern "C" fn(
    env: fmi2ComponentEnvironment,
    instance_name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    message: fmi2String,
    ...
);

/// Callback functions passed to `fmi2Instantiate` (`fmi2CallbackFunctions`).
///
/// Only `logger` and `componentEnvironment` are used: the FMU allocates with Rust's allocator
/// (`canNotUseMemoryManagementFunctions="true"`) and never runs asynchronously.
#[repr(C)]
#[allow(non_snake_case)]
pub struct fmi2CallbackFunctions {
    /// Logger (may be NULL: then nothing is logged).
    pub logger: Option<fmi2CallbackLogger>,
    /// Memory allocation (unused).
    pub allocateMemory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// Memory release (unused).
    pub freeMemory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// End of an asynchronous step (unused).
    pub stepFinished: Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>,
    /// Passed back as the first argument of `logger`.
    pub componentEnvironment: fmi2ComponentEnvironment,
}
