//! The exported `fmi2*` functions: C glue over the FMU instance (`Instance` of the private
//! module `fmi2::instance`).
//!
//! Every function runs its body inside `catch_unwind`: a panic becomes `fmi2Fatal` with a log
//! message (the instance is then in the fatal state), never an unwinding across the C boundary.
//! Each function first checks the state machine (the calling instance's state must be in the
//! function's allowed set; otherwise it logs and returns `fmi2Error`). Any `fmi2Error` moves the
//! instance to the error state, from which `fmi2Reset` or `fmi2SetFMUstate` recover.
//!
//! An `fmi2Component` points to a `Component`: the instance with an atomic in-use flag. Every
//! function sets the flag on entry and clears it on exit; a call that finds it set (a second
//! thread entering an instance in use, which the standard forbids) returns `fmi2Error` at once
//! with a log message and touches nothing (the instance's state is that of the other call),
//! instead of racing on the instance. `fmi2FreeInstance` of an instance in use leaks it rather
//! than freeing memory that another call is using.
//!
//! # Safety (all functions)
//!
//! The pointer arguments must be as the FMI 2.0 standard requires: `c` is NULL or a pointer
//! returned by `fmi2Instantiate` and not yet freed, used by one thread at a time; arrays
//! hold at least the given number of elements; strings are zero-terminated; FMU states were
//! returned by this instance. NULL where a pointer is required is reported as an error.
#![allow(non_snake_case)]

use std::any::Any;
use std::cell::UnsafeCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};

use super::instance::{Func, Instance, Phase, Snapshot, cat, func, log_to, mask_names};
use super::models::{MODELS, by_guid};
use super::types::*;
use super::uri::file_uri_to_path;

fn panic_text(p: &(dyn Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    }
}

/// What an `fmi2Component` points to: the instance behind an in-use flag, with copies of the
/// logger, its environment and the instance name that stay readable while another call holds
/// the instance.
pub(crate) struct Component {
    busy: AtomicBool,
    logger: Option<fmi2CallbackLogger>,
    env: fmi2ComponentEnvironment,
    name: CString,
    inst: UnsafeCell<Instance>,
}

/// Clears the in-use flag when dropped (also when the body panicked).
struct InUse<'a>(&'a AtomicBool);

impl Drop for InUse<'_> {
    fn drop(&mut self) {
        self.0.store(false, Ordering::Release);
    }
}

/// Sets the in-use flag of the component behind `c`; `None` (after logging) when it was set.
///
/// # Safety
/// `c` non-null and from `fmi2Instantiate`, not yet freed.
unsafe fn enter<'a>(c: fmi2Component, f: Func) -> Option<(InUse<'a>, *mut Instance)> {
    // SAFETY: caller contract; only the atomic and the immutable copies are read here.
    let comp = unsafe { &*c.cast::<Component>() };
    if comp.busy.swap(true, Ordering::Acquire) {
        log_to(
            comp.logger,
            comp.env,
            &comp.name,
            fmi2Status::Error,
            cat::ERROR,
            &format!(
                "{}: the instance is in use by another call (an instance may be used by one \
                 thread at a time); nothing was done",
                f.name
            ),
        );
        return None;
    }
    Some((InUse(&comp.busy), comp.inst.get()))
}

/// Runs `body` on the instance behind `c` with the in-use guard, the state-machine check, error
/// logging and panic containment described in the module docs.
fn call(
    c: fmi2Component,
    f: Func,
    body: impl FnOnce(&mut Instance) -> Result<fmi2Status, String>,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Status::Error;
    }
    // SAFETY: `c` came from fmi2Instantiate (caller contract).
    let Some((_guard, p)) = (unsafe { enter(c, f) }) else {
        return fmi2Status::Error;
    };
    call_entered(p, f, body)
}

/// [`call`] once the in-use flag is held.
fn call_entered(
    p: *mut Instance,
    f: Func,
    body: impl FnOnce(&mut Instance) -> Result<fmi2Status, String>,
) -> fmi2Status {
    let result = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: `c` came from fmi2Instantiate (caller contract).
        let inst = unsafe { &mut *p };
        let mode = inst.mode();
        if f.mask & (mode as u16) == 0 {
            return Err(format!(
                "not allowed in state {} (allowed in: {})",
                mode.name(),
                mask_names(f.mask)
            ));
        }
        if inst.logs(cat::CALLS) {
            inst.log(fmi2Status::Ok, cat::CALLS, f.name);
        }
        body(inst)
    }));
    let after = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: as above; the borrow inside the closure has ended.
        let inst = unsafe { &mut *p };
        match result {
            Ok(Ok(status)) => status,
            Ok(Err(msg)) => {
                inst.log(fmi2Status::Error, cat::ERROR, &format!("{}: {msg}", f.name));
                if inst.mode() == Phase::Fatal {
                    fmi2Status::Fatal
                } else {
                    inst.set_mode(Phase::Error);
                    fmi2Status::Error
                }
            }
            Err(payload) => {
                inst.set_mode(Phase::Fatal);
                inst.log(
                    fmi2Status::Fatal,
                    cat::FATAL,
                    &format!("{}: internal error (panic): {}", f.name, panic_text(&*payload)),
                );
                fmi2Status::Fatal
            }
        }
    }));
    after.unwrap_or(fmi2Status::Fatal)
}

/// A slice from a C array, or an error naming the argument when it is NULL with `n > 0`.
///
/// # Safety
/// `p` must point to `n` valid elements when non-null.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(format!("argument `{what}` is NULL with {n} elements"))
    } else {
        // SAFETY: caller contract.
        Ok(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// Mutable variant of [`slice`].
///
/// # Safety
/// `p` must point to `n` valid, writable elements when non-null.
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err(format!("argument `{what}` is NULL with {n} elements"))
    } else {
        // SAFETY: caller contract.
        Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

/// Writes `v` to `out`, or errors naming the argument when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or valid for writing.
unsafe fn write<T>(out: *mut T, v: T, what: &str) -> Result<(), String> {
    if out.is_null() {
        return Err(format!("argument `{what}` is NULL"));
    }
    // SAFETY: non-null, caller contract.
    unsafe { out.write(v) };
    Ok(())
}

/// The string behind `s`, or an error naming `what`.
///
/// # Safety
/// `s` must be NULL or a zero-terminated string.
unsafe fn string(s: fmi2String, what: &str) -> Result<String, String> {
    if s.is_null() {
        return Err(format!("argument `{what}` is NULL"));
    }
    // SAFETY: caller contract.
    let c = unsafe { CStr::from_ptr(s) };
    c.to_str().map(str::to_string).map_err(|_| format!("argument `{what}` is not UTF-8"))
}

// ---------------------------------------------------------------- inquiry

/// Returns `"default"`: the FMU uses the standard's default C types.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// Returns `"2.0"`, the FMI version of the exported functions.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// Switches debug logging on or off, for all categories (`n_categories` = 0) or the listed ones
/// (see `LogCategories` in `modelDescription.xml`). Error and fatal messages are always logged.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    call(c, func::fmi2SetDebugLogging, |inst| {
        // SAFETY: caller contract.
        let list = unsafe { slice(categories, n_categories, "categories") }?;
        let names = list
            .iter()
            .enumerate()
            // SAFETY: caller contract.
            .map(|(i, &s)| unsafe { string(s, &format!("categories[{i}]")) })
            .collect::<Result<Vec<_>, _>>()?;
        inst.set_debug_logging(logging_on != FMI2_FALSE, &names)
    })
}

// ---------------------------------------------------------------- life cycle

/// Creates an instance of the model whose GUID is `fmu_guid` (one binary serves every model of
/// the family). Returns NULL (after logging why, if a logger was given) when `fmu_type` is not
/// Co-Simulation, the GUID is none of the models', or the name is NULL.
/// A resource location that cannot be decoded is logged as a warning and otherwise ignored:
/// the model needs no file from `resources/`.
///
/// # Safety
/// Strings zero-terminated or NULL; `functions` NULL (then nothing is logged) or valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    fmu_guid: fmi2String,
    fmu_resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    // Part of the standard signature, not used by this FMU.
    let _ = (visible,);
    let r = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: caller contract (NULL allowed).
        let (logger, env) = match unsafe { functions.as_ref() } {
            Some(f) => (f.logger, f.componentEnvironment),
            None => (None, std::ptr::null_mut()),
        };
        // SAFETY: caller contract.
        let name = unsafe { string(instance_name, "instanceName") };
        let shown = CString::new(name.clone().unwrap_or_else(|_| "?".into())).unwrap_or_default();
        let fail = |msg: String| {
            log_to(
                logger,
                env,
                &shown,
                fmi2Status::Error,
                cat::ERROR,
                &format!("fmi2Instantiate: {msg}"),
            );
            std::ptr::null_mut()
        };
        let name = match name {
            Ok(n) => n,
            Err(e) => return fail(e),
        };
        // SAFETY: caller contract.
        let model = match unsafe { string(fmu_guid, "fmuGUID") } {
            Ok(g) => match by_guid(&g) {
                Some(m) => m,
                None => {
                    let known: Vec<String> =
                        MODELS.iter().map(|m| format!("{} {}", m.identifier, m.guid())).collect();
                    return fail(format!(
                        "fmuGUID `{g}` is the GUID of no model in this binary (known: {}; \
                         modelDescription.xml and binary from different builds?)",
                        known.join(", ")
                    ));
                }
            },
            Err(e) => return fail(e),
        };
        if fmu_type != FMI2_CO_SIMULATION && fmu_type != FMI2_MODEL_EXCHANGE {
            return fail(format!(
                "fmuType = {fmu_type}: allowed 0 (Model Exchange) or 1 (Co-Simulation)"
            ));
        }
        let mut warning = None;
        let resources = if fmu_resource_location.is_null() {
            None
        } else {
            // SAFETY: caller contract.
            match unsafe { string(fmu_resource_location, "fmuResourceLocation") }
                .and_then(|u| file_uri_to_path(&u))
            {
                Ok(p) => Some(p),
                Err(e) => {
                    warning = Some(e);
                    None
                }
            }
        };
        let inst = Instance::new(
            model,
            fmu_type == FMI2_MODEL_EXCHANGE,
            CString::new(name).unwrap_or_default(),
            logger,
            env,
            logging_on != FMI2_FALSE,
            resources,
        );
        if let Some(w) = warning {
            inst.log(fmi2Status::Warning, cat::WARNING, &format!("fmi2Instantiate: {w}"));
        }
        let comp = Component {
            busy: AtomicBool::new(false),
            logger,
            env,
            name: inst.name.clone(),
            inst: UnsafeCell::new(inst),
        };
        Box::into_raw(Box::new(comp)).cast()
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// Frees the instance and every FMU state it created. NULL is a no-op.
///
/// # Safety
/// `c` NULL or from `fmi2Instantiate`; it must not be used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from fmi2Instantiate (caller contract).
    let Some((guard, p)) = (unsafe { enter(c, func::fmi2FreeInstance) }) else {
        // In use by another call: leaked rather than freed under it.
        return;
    };
    // The mask admits every state, so the body runs; whatever it returns, the instance goes.
    call_entered(p, func::fmi2FreeInstance, |inst| {
        inst.free_all_states();
        Ok(fmi2Status::Ok)
    });
    std::mem::forget(guard);
    let _ = catch_unwind(|| {
        // SAFETY: created by Box::into_raw in fmi2Instantiate; the caller does not use it again.
        drop(unsafe { Box::from_raw(c.cast::<Component>()) });
    });
}

/// Sets the start time and the optional stop time (the tolerance is not used: the model has no
/// internal integrator).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: fmi2Real,
    start_time: fmi2Real,
    stop_time_defined: fmi2Boolean,
    stop_time: fmi2Real,
) -> fmi2Status {
    // Part of the standard signature, not used by this FMU.
    let _ = (tolerance_defined, tolerance);
    call(c, func::fmi2SetupExperiment, |inst| {
        inst.setup_experiment(start_time, (stop_time_defined != FMI2_FALSE).then_some(stop_time))
    })
}

/// Enters initialisation mode (parameters and inputs may still be set).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2EnterInitializationMode, Instance::enter_initialization_mode)
}

/// Validates the parameters and builds the mesh model (loads the cached compliance for the
/// Table 1 default, or runs the FE for other gears: its time is `fe_compliance_s` in
/// docs/performance.md). An invalid parameter gives `fmi2Error` with a message naming it, its
/// value and the allowed range.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2ExitInitializationMode, Instance::exit_initialization_mode)
}

/// Ends the simulation run (values can still be read).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2Terminate, Instance::terminate)
}

/// Back to the instantiated state with every variable at its start value (also from the error
/// state).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2Reset, Instance::reset)
}

// ---------------------------------------------------------------- get and set

/// Reads Real variables. Outputs are recomputed first when an input changed since the last
/// evaluation (direct feedthrough).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    call(c, func::fmi2GetReal, |inst| {
        // SAFETY: caller contract.
        let (vr, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        inst.get_real(vr, out)
    })
}

/// Reads Integer variables (see `fmi2GetReal`).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    call(c, func::fmi2GetInteger, |inst| {
        // SAFETY: caller contract.
        let (vr, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        inst.get_integer(vr, out)
    })
}

/// Reads Boolean variables (see `fmi2GetReal`).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    call(c, func::fmi2GetBoolean, |inst| {
        // SAFETY: caller contract.
        let (vr, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        let mut b = vec![false; vr.len()];
        let st = inst.get_boolean(vr, &mut b)?;
        for (o, x) in out.iter_mut().zip(b) {
            *o = if x { FMI2_TRUE } else { FMI2_FALSE };
        }
        Ok(st)
    })
}

/// Gets String parameters (`modifications`). The returned pointers stay valid until the next
/// `fmi2GetString` of the same instance.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    call(c, func::fmi2GetString, |inst| {
        // SAFETY: caller contract.
        let vr = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: caller contract.
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        let texts = inst.get_string(vr)?;
        inst.strings = texts
            .into_iter()
            .map(|t| CString::new(t).map_err(|_| "a String value contains a NUL byte".to_string()))
            .collect::<Result<_, _>>()?;
        for (o, s) in out.iter_mut().zip(&inst.strings) {
            *o = s.as_ptr();
        }
        Ok(fmi2Status::Ok)
    })
}

/// Sets Real inputs and parameters. A NaN or infinite input is an error naming the input;
/// `fixed` parameters can be set only before `fmi2ExitInitializationMode`, `d_mesh` also
/// between steps.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    call(c, func::fmi2SetReal, |inst| {
        // SAFETY: caller contract.
        let (vr, v) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        inst.set_real(vr, v)
    })
}

/// Sets Integer parameters (see `fmi2SetReal`).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    call(c, func::fmi2SetInteger, |inst| {
        // SAFETY: caller contract.
        let (vr, v) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        inst.set_integer(vr, v)
    })
}

/// Sets Boolean parameters (see `fmi2SetReal`); any non-zero value is true.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    call(c, func::fmi2SetBoolean, |inst| {
        // SAFETY: caller contract.
        let (vr, v) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        let b: Vec<bool> = v.iter().map(|&x| x != FMI2_FALSE).collect();
        inst.set_boolean(vr, &b)
    })
}

/// Sets String parameters (`modifications`: the JSON object of `docs/modifications.md`). Malformed JSON or an unknown key is an error naming it; the
/// values are checked against the geometry at `fmi2ExitInitializationMode` (errors name the
/// key, e.g. `modifications.pinion.lead_crowning_m`).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    call(c, func::fmi2SetString, |inst| {
        // SAFETY: caller contract.
        let vr = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: caller contract.
        let ptrs = unsafe { slice(value, nvr, "value") }?;
        let texts = ptrs
            .iter()
            .enumerate()
            // SAFETY: caller contract (zero-terminated strings).
            .map(|(i, &p)| unsafe { string(p, &format!("value[{i}]")) })
            .collect::<Result<Vec<_>, _>>()?;
        inst.set_string(vr, &texts)
    })
}

// ---------------------------------------------------------------- FMU state

/// Saves the instance's state (state machine, time, parameters, inputs, model with its warm
/// start, cached outputs) into a new FMU state (`*state` NULL) or overwrites `*state`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    call(c, func::fmi2GetFMUstate, |inst| {
        if state.is_null() {
            return Err("argument `FMUstate` is NULL".into());
        }
        // SAFETY: non-null, caller contract.
        let existing = unsafe { *state }.cast::<Snapshot>();
        let p = inst.get_state(existing)?;
        // SAFETY: as above.
        unsafe { *state = p.cast() };
        Ok(fmi2Status::Ok)
    })
}

/// Restores a state saved by `fmi2GetFMUstate` or `fmi2DeSerializeFMUstate` (also from
/// the error state).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    call(c, func::fmi2SetFMUstate, |inst| inst.set_state(state.cast()))
}

/// Frees an FMU state and sets `*state` to NULL (`*state` NULL is a no-op).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    call(c, func::fmi2FreeFMUstate, |inst| {
        if state.is_null() {
            return Err("argument `FMUstate` is NULL".into());
        }
        // SAFETY: non-null, caller contract.
        let st = inst.free_state(unsafe { *state }.cast())?;
        // SAFETY: as above.
        unsafe { *state = std::ptr::null_mut() };
        Ok(st)
    })
}

/// Size in bytes of the serialised form of `state`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    call(c, func::fmi2SerializedFMUstateSize, |inst| {
        let n = inst.serialize_state(state.cast())?.len();
        // SAFETY: caller contract.
        unsafe { write(size, n, "size") }?;
        Ok(fmi2Status::Ok)
    })
}

/// Serialises `state` into `serialized_state` (versioned little-endian bytes: parameters,
/// inputs, time, state-machine state and cached outputs; the model is rebuilt on
/// deserialisation).
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    serialized_state: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    call(c, func::fmi2SerializeFMUstate, |inst| {
        let bytes = inst.serialize_state(state.cast())?;
        if size < bytes.len() {
            return Err(format!(
                "buffer of {size} bytes is too small: the state needs {} (see \
                 fmi2SerializedFMUstateSize)",
                bytes.len()
            ));
        }
        // SAFETY: caller contract.
        let out =
            unsafe { slice_mut(serialized_state.cast::<u8>(), bytes.len(), "serializedState") }?;
        out.copy_from_slice(&bytes);
        Ok(fmi2Status::Ok)
    })
}

/// Creates an FMU state from bytes written by `fmi2SerializeFMUstate` (of an FMU with the
/// same GUID). Builds the mesh model when the state is past initialisation and no model with
/// the same parameters exists in this instance.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serialized_state: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    call(c, func::fmi2DeSerializeFMUstate, |inst| {
        if state.is_null() {
            return Err("argument `FMUstate` is NULL".into());
        }
        // SAFETY: caller contract.
        let bytes = unsafe { slice(serialized_state.cast::<u8>(), size, "serializedState") }?;
        let p = inst.deserialize_state(bytes)?;
        // SAFETY: non-null, caller contract.
        unsafe { *state = p.cast() };
        Ok(fmi2Status::Ok)
    })
}

// ---------------------------------------------------------------- not provided

/// Σ_j ∂unknown_i/∂known_j·dvKnown_j for outputs and state derivatives (unknowns) with
/// respect to inputs and continuous states (knowns), from the model's exact derivatives (the
/// mesh Jacobian: the table's interpolant or the load solution's sensitivity), not finite
/// differences. An unknown the model does not differentiate (F_n, contact_length, p_max) or
/// a parameter as known is an error that names it.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    v_unknown_ref: *const fmi2ValueReference,
    n_unknown: usize,
    v_known_ref: *const fmi2ValueReference,
    n_known: usize,
    dv_known: *const fmi2Real,
    dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    call(c, func::fmi2GetDirectionalDerivative, |inst| {
        // SAFETY: caller contract.
        let (unknowns, knowns, seed, out) = unsafe {
            (
                slice(v_unknown_ref, n_unknown, "vUnknown_ref")?,
                slice(v_known_ref, n_known, "vKnown_ref")?,
                slice(dv_known, n_known, "dvKnown")?,
                slice_mut(dv_unknown, n_unknown, "dvUnknown")?,
            )
        };
        inst.directional_derivative(unknowns, knowns, seed, out)
    })
}

/// First derivatives (order 1) of Real inputs for the stateful models' first-order hold over
/// the following communication steps (`canInterpolateInputs="true"`); setting an input's
/// value resets its derivative to 0. Other orders, non-inputs and non-finite values are errors
/// that name them.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    call(c, func::fmi2SetRealInputDerivatives, |inst| {
        // SAFETY: caller contract.
        let (vrs, orders, values) = unsafe {
            (slice(vr, nvr, "vr")?, slice(order, nvr, "order")?, slice(value, nvr, "value")?)
        };
        inst.set_input_derivatives(vrs, orders, values)
    })
}

/// Not provided (`maxOutputDerivativeOrder="0"`): logs and returns `fmi2Error`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    // Part of the standard signature, not used by this FMU.
    let _ = (vr, nvr, order, value);
    call(c, func::fmi2GetRealOutputDerivatives, |_| {
        Err("not provided by this FMU (maxOutputDerivativeOrder=\"0\")".into())
    })
}

// ---------------------------------------------------------------- model exchange

/// Enters event mode. The models have no events (no event indicators, no time events): the
/// event iteration ends at once.
///
/// # Safety
/// `c` from `fmi2Instantiate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2EnterEventMode, |inst| {
        inst.set_mode(Phase::EventMode);
        Ok(fmi2Status::Ok)
    })
}

/// One event iteration: nothing changes (no discrete states, no time events).
///
/// # Safety
/// `c` from `fmi2Instantiate`; `event_info` valid for writing.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    event_info: *mut fmi2EventInfo,
) -> fmi2Status {
    call(c, func::fmi2NewDiscreteStates, |_| {
        let info = fmi2EventInfo {
            newDiscreteStatesNeeded: FMI2_FALSE,
            terminateSimulation: FMI2_FALSE,
            nominalsOfContinuousStatesChanged: FMI2_FALSE,
            valuesOfContinuousStatesChanged: FMI2_FALSE,
            nextEventTimeDefined: FMI2_FALSE,
            nextEventTime: 0.0,
        };
        // SAFETY: caller contract.
        unsafe { write(event_info, info, "fmi2eventInfo")? };
        Ok(fmi2Status::Ok)
    })
}

/// Enters continuous-time mode.
///
/// # Safety
/// `c` from `fmi2Instantiate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2EnterContinuousTimeMode, |inst| {
        inst.set_mode(Phase::ContinuousTimeMode);
        Ok(fmi2Status::Ok)
    })
}

/// Nothing to do after an integrator step (`completedIntegratorStepNotNeeded="true"`):
/// reports no step event and no termination.
///
/// # Safety
/// `c` from `fmi2Instantiate`; the two flags valid for writing.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    no_set_fmu_state_prior_to_current_point: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> fmi2Status {
    let _ = no_set_fmu_state_prior_to_current_point;
    call(c, func::fmi2CompletedIntegratorStep, |_| {
        // SAFETY: caller contract.
        unsafe {
            write(enter_event_mode, FMI2_FALSE, "enterEventMode")?;
            write(terminate_simulation, FMI2_FALSE, "terminateSimulation")?;
        }
        Ok(fmi2Status::Ok)
    })
}

/// Sets the time (s) of the next evaluations.
///
/// # Safety
/// `c` from `fmi2Instantiate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    call(c, func::fmi2SetTime, |inst| inst.me_set_time(time))
}

/// Sets the continuous states (the model's relative coordinates, in the order of its
/// derivative variables).
///
/// # Safety
/// `c` from `fmi2Instantiate`; `x` with `nx` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    call(c, func::fmi2SetContinuousStates, |inst| {
        // SAFETY: caller contract.
        let x = unsafe { slice(x, nx, "x")? };
        inst.me_set_states(x)
    })
}

/// The state derivatives at the current time, states and inputs.
///
/// # Safety
/// `c` from `fmi2Instantiate`; `derivatives` with `nx` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    call(c, func::fmi2GetDerivatives, |inst| {
        // SAFETY: caller contract.
        let dx = unsafe { slice_mut(derivatives, nx, "derivatives")? };
        inst.me_get_derivatives(dx)
    })
}

/// The model's event indicators (`numberOfEventIndicators`; none in the current models: state
/// events at a change of contact kind were measured not to help an importer's solver, see
/// `docs/fmus.md`).
///
/// # Safety
/// `c` from `fmi2Instantiate`; `event_indicators` with `ni` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    event_indicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    call(c, func::fmi2GetEventIndicators, |inst| {
        // SAFETY: caller contract.
        let z = unsafe { slice_mut(event_indicators, ni, "eventIndicators")? };
        inst.me_event_indicators(z)
    })
}

/// The continuous states.
///
/// # Safety
/// `c` from `fmi2Instantiate`; `x` with `nx` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    call(c, func::fmi2GetContinuousStates, |inst| {
        // SAFETY: caller contract.
        let x = unsafe { slice_mut(x, nx, "x")? };
        inst.me_get_states(x)
    })
}

/// Nominal magnitudes of the continuous states (for the importer's absolute tolerances).
///
/// # Safety
/// `c` from `fmi2Instantiate`; `x_nominal` with `nx` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    call(c, func::fmi2GetNominalsOfContinuousStates, |inst| {
        // SAFETY: caller contract.
        let x = unsafe { slice_mut(x_nominal, nx, "x_nominal")? };
        inst.me_nominals(x)
    })
}

// ---------------------------------------------------------------- co-simulation

/// Advances the communication time from `current_communication_point` (which must equal the
/// end of the previous step) by `communication_step_size` (> 0, not beyond the stop time).
/// The mesh element has no state of its own: the outputs depend on the inputs only.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    no_set_fmu_state_prior_to_current_point: fmi2Boolean,
) -> fmi2Status {
    // Part of the standard signature, not used by this FMU.
    let _ = (no_set_fmu_state_prior_to_current_point,);
    call(c, func::fmi2DoStep, |inst| {
        inst.do_step(current_communication_point, communication_step_size)
    })
}

/// Steps are never asynchronous, so there is nothing to cancel: logs and returns `fmi2Error`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    call(c, func::fmi2CancelStep, |_| Ok(fmi2Status::Ok))
}

fn no_status(inst: &Instance, kind: fmi2StatusKind, what: &str) -> Result<fmi2Status, String> {
    inst.log(
        fmi2Status::Discard,
        cat::WARNING,
        &format!(
            "{what}: status kind {kind} is not available from this FMU (steps are synchronous)"
        ),
    );
    Ok(fmi2Status::Discard)
}

/// `fmi2DoStepStatus` (kind 0): `fmi2OK` (every step completes synchronously); other kinds
/// return `fmi2Discard`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    call(c, func::fmi2GetStatus, |inst| {
        if kind != 0 {
            return no_status(inst, kind, "fmi2GetStatus");
        }
        // SAFETY: caller contract.
        unsafe { write(value, fmi2Status::Ok, "value") }?;
        Ok(fmi2Status::Ok)
    })
}

/// `fmi2LastSuccessfulTime` (kind 2): the current communication time; other kinds return
/// `fmi2Discard`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    call(c, func::fmi2GetRealStatus, |inst| {
        if kind != 2 {
            return no_status(inst, kind, "fmi2GetRealStatus");
        }
        // SAFETY: caller contract.
        unsafe { write(value, inst.time(), "value") }?;
        Ok(fmi2Status::Ok)
    })
}

/// No integer status exists in FMI 2.0: returns `fmi2Discard`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    // Part of the standard signature, not used by this FMU.
    let _ = (value,);
    call(c, func::fmi2GetIntegerStatus, |inst| no_status(inst, kind, "fmi2GetIntegerStatus"))
}

/// `fmi2Terminated` (kind 3): false (the FMU never asks to stop); other kinds return
/// `fmi2Discard`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    call(c, func::fmi2GetBooleanStatus, |inst| {
        if kind != 3 {
            return no_status(inst, kind, "fmi2GetBooleanStatus");
        }
        // SAFETY: caller contract.
        unsafe { write(value, FMI2_FALSE, "value") }?;
        Ok(fmi2Status::Ok)
    })
}

/// `fmi2PendingStatus` is never available (no asynchronous steps): returns `fmi2Discard`.
///
/// # Safety
/// Pointer arguments as the FMI 2.0 standard requires: `c` from `fmi2Instantiate`, arrays with
/// the given number of elements (NULL is reported as an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    // Part of the standard signature, not used by this FMU.
    let _ = (value,);
    call(c, func::fmi2GetStringStatus, |inst| no_status(inst, kind, "fmi2GetStringStatus"))
}

/// Names of all exported `fmi2*` functions (the 25 common, the 9 co-simulation and the 10
/// model-exchange functions of FMI 2.0).
pub const EXPORTED_FUNCTIONS: [&str; 44] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
    "fmi2EnterEventMode",
    "fmi2NewDiscreteStates",
    "fmi2EnterContinuousTimeMode",
    "fmi2CompletedIntegratorStep",
    "fmi2SetTime",
    "fmi2SetContinuousStates",
    "fmi2GetDerivatives",
    "fmi2GetEventIndicators",
    "fmi2GetContinuousStates",
    "fmi2GetNominalsOfContinuousStates",
];

#[cfg(test)]
mod tests {
    use super::*;

    /// A Co-Simulation instance of the mesh element named `name`.
    fn instantiate_cs(name: &std::ffi::CStr) -> fmi2Component {
        let g = CString::new(crate::fmi2::models::mesh::guid()).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                name.as_ptr(),
                FMI2_CO_SIMULATION,
                g.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                FMI2_FALSE,
                FMI2_FALSE,
            )
        };
        assert!(!c.is_null());
        c
    }

    #[test]
    fn a_panic_becomes_fatal_and_the_instance_can_still_be_freed() {
        let c = instantiate_cs(c"p");
        assert_eq!(call(c, func::fmi2Reset, |_| panic!("boom")), fmi2Status::Fatal);
        // Fatal is final: every further call but fmi2FreeInstance is refused as fatal.
        assert_eq!(unsafe { fmi2Reset(c) }, fmi2Status::Fatal);
        assert_eq!(unsafe { fmi2DoStep(c, 0.0, 1.0, FMI2_TRUE) }, fmi2Status::Fatal);
        unsafe { fmi2FreeInstance(c) };
    }

    #[test]
    fn a_call_entering_an_instance_in_use_is_refused_and_changes_nothing() {
        let c = instantiate_cs(c"busy");
        // While one call holds the instance, another (here from inside it) is refused.
        let inner = call(c, func::fmi2Reset, |inst| {
            assert_eq!(unsafe { fmi2Reset(c) }, fmi2Status::Error);
            assert_eq!(unsafe { fmi2EnterInitializationMode(c) }, fmi2Status::Error);
            // fmi2FreeInstance of an instance in use leaves it alive.
            unsafe { fmi2FreeInstance(c) };
            assert_eq!(inst.mode(), Phase::Instantiated);
            Ok(fmi2Status::Ok)
        });
        assert_eq!(inner, fmi2Status::Ok);
        // The refused calls left the state machine as it was, and the flag is cleared.
        assert_eq!(unsafe { fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) }, fmi2Status::Ok);
        unsafe { fmi2FreeInstance(c) };
    }
}
