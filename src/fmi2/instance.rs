//! One FMU instance of any model: the state machine, the variable values and the model's
//! [`Engine`] behind them.
//!
//! This is plain Rust with no raw pointers except the logger; [`super::exports`] turns C calls
//! into calls of these methods. Every operation returns `Ok(status)` or `Err(message)`; the
//! caller logs the message, moves the instance to the error state and returns `fmi2Error`.
//! Nothing here knows a model: the variable table, the defaults and the physics come from the
//! instance's [`ModelInfo`]. The instance owns the values as generic slots: the inputs in an
//! [`InputValues`] (values, the time derivatives the model uses, the `fresh` flag), the
//! outputs of the last evaluation in an [`OutputValues`]; a variable's [`Access`] names its
//! slot, and the model's [`Engine`] reads the input slots and fills the output slots. Which
//! inputs' derivatives are kept (`fmi2SetRealInputDerivatives`) is the variable's flag
//! (`Access::Input { derivative }`); the state derivatives of Model Exchange are the Real
//! slots of the model's derivative variables.
//!
//! Boundaries: an input is checked against its stated range when set or restored
//! ([`Variable::check_input`]: |angle| ≤ 1e15 rad, |speed| ≤ 1e5 rad/s, |torque| ≤ 1e9 N·m),
//! a tunable parameter by the model's own check ([`ModelInfo::check_tunable`]) before the
//! model applies it ([`Engine::tune`]), and every value a getter or a step hands out with a
//! success status passes one check, [`ensure_finite`]: a non-finite value is an error naming
//! the variable, never a result. Serialised FMU states
//! carry a format version and a checksum (see the layout below).

use std::ffi::CString;
use std::path::PathBuf;

use super::model::{Engine, Jacobian, MAX_STATES, ModelInfo, StepFailure};
use super::types::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use super::variables::{
    Access, Causality, Derived, InputValues, LOG_CATEGORIES, OutputValues, Settings, VarType,
    Variability, Variable,
};
use crate::error::short_num;

/// States of the FMI 2.0 state machines of co-simulation (section 4.2.4) and model exchange
/// (section 3.2.3), as bits so that each function can carry the set of states it is allowed
/// in. An instance runs one of the two machines (its `fmuType`); `stepInProgress` never occurs
/// (steps are synchronous); "start/end" is the absence of an instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u16)]
pub(crate) enum Phase {
    Instantiated = 1,
    InitializationMode = 2,
    StepComplete = 4,
    StepFailed = 8,
    StepCanceled = 16,
    Terminated = 32,
    Error = 64,
    Fatal = 128,
    /// Model exchange: event mode.
    EventMode = 256,
    /// Model exchange: continuous-time mode.
    ContinuousTimeMode = 512,
}

/// Every state, in bit order.
const ALL_PHASES: [Phase; 10] = [
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::StepCanceled,
    Phase::Terminated,
    Phase::Error,
    Phase::Fatal,
    Phase::EventMode,
    Phase::ContinuousTimeMode,
];

impl Phase {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Phase::Instantiated => "instantiated",
            Phase::InitializationMode => "initializationMode",
            Phase::StepComplete => "stepComplete",
            Phase::StepFailed => "stepFailed",
            Phase::StepCanceled => "stepCanceled",
            Phase::Terminated => "terminated",
            Phase::Error => "error",
            Phase::Fatal => "fatal",
            Phase::EventMode => "eventMode",
            Phase::ContinuousTimeMode => "continuousTimeMode",
        }
    }

    /// Position of the state's bit (its code in a serialised state).
    fn code(self) -> u8 {
        (self as u16).trailing_zeros() as u8
    }

    /// The state with code `b`; never the fatal state (a saved state is never fatal).
    fn from_code(b: u8) -> Option<Phase> {
        ALL_PHASES.into_iter().find(|m| m.code() == b && *m != Phase::Fatal)
    }
}

/// An FMI function with the set of states it may be called in.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Func {
    pub(crate) name: &'static str,
    pub(crate) mask: u16,
}

const INST: u16 = Phase::Instantiated as u16;
const INIT: u16 = Phase::InitializationMode as u16;
const DONE: u16 = Phase::StepComplete as u16;
const FAILED: u16 = Phase::StepFailed as u16;
const CANCELED: u16 = Phase::StepCanceled as u16;
const TERM: u16 = Phase::Terminated as u16;
const ERR: u16 = Phase::Error as u16;
const EVENT: u16 = Phase::EventMode as u16;
const CONT: u16 = Phase::ContinuousTimeMode as u16;
const LIVE: u16 = INST | INIT | DONE | FAILED | CANCELED | TERM | ERR | EVENT | CONT;
const GETTABLE: u16 = INIT | DONE | FAILED | CANCELED | TERM | ERR | EVENT | CONT;
const SETTABLE: u16 = INST | INIT | DONE | EVENT | CONT;
/// Model exchange: where the state vector, derivatives and event indicators may be read.
const ME_GETTABLE: u16 = INIT | EVENT | CONT | TERM | ERR;

macro_rules! funcs {
    ($($id:ident = $mask:expr;)*) => {
        /// The FMI functions with the states they are allowed in (the tables of sections 3.2.3
        /// and 4.2.4 of the FMI 2.0 standard, one mask over the states of both machines;
        /// `fmi2FreeInstance` is also accepted in the fatal state so that an instance is never
        /// leaked). Which inputs and parameters may be set in a state is checked per variable
        /// ([`Instance::set_real`] and its siblings).
        #[allow(non_upper_case_globals, dead_code)]
        pub(crate) mod func {
            use super::*;
            $(pub(crate) const $id: Func = Func { name: stringify!($id), mask: $mask };)*
        }
    };
}

funcs! {
    fmi2SetDebugLogging = LIVE;
    fmi2FreeInstance = LIVE | Phase::Fatal as u16;
    fmi2SetupExperiment = INST;
    fmi2EnterInitializationMode = INST;
    fmi2ExitInitializationMode = INIT;
    fmi2Terminate = DONE | FAILED | EVENT | CONT;
    fmi2Reset = LIVE;
    fmi2GetReal = GETTABLE;
    fmi2GetInteger = GETTABLE;
    fmi2GetBoolean = GETTABLE;
    fmi2GetString = GETTABLE;
    fmi2SetReal = SETTABLE;
    fmi2SetInteger = SETTABLE;
    fmi2SetBoolean = SETTABLE;
    fmi2SetString = SETTABLE;
    fmi2GetFMUstate = LIVE;
    fmi2SetFMUstate = LIVE;
    fmi2FreeFMUstate = LIVE;
    fmi2SerializedFMUstateSize = LIVE;
    fmi2SerializeFMUstate = LIVE;
    fmi2DeSerializeFMUstate = LIVE;
    fmi2GetDirectionalDerivative = GETTABLE;
    fmi2SetRealInputDerivatives = SETTABLE;
    fmi2GetRealOutputDerivatives = DONE | FAILED | CANCELED | TERM | ERR;
    fmi2DoStep = DONE;
    fmi2CancelStep = 0;
    fmi2GetStatus = DONE | FAILED | CANCELED | TERM;
    fmi2GetRealStatus = DONE | FAILED | CANCELED | TERM;
    fmi2GetIntegerStatus = DONE | FAILED | CANCELED | TERM;
    fmi2GetBooleanStatus = DONE | FAILED | CANCELED | TERM;
    fmi2GetStringStatus = DONE | FAILED | CANCELED | TERM;
    fmi2EnterEventMode = EVENT | CONT;
    fmi2NewDiscreteStates = EVENT;
    fmi2EnterContinuousTimeMode = EVENT;
    fmi2CompletedIntegratorStep = CONT;
    fmi2SetTime = EVENT | CONT;
    fmi2SetContinuousStates = CONT;
    fmi2GetDerivatives = ME_GETTABLE;
    fmi2GetEventIndicators = ME_GETTABLE;
    fmi2GetContinuousStates = ME_GETTABLE;
    fmi2GetNominalsOfContinuousStates = INST | EVENT | CONT | TERM | ERR;
}

/// Names of the states in `mask`, for messages.
pub(crate) fn mask_names(mask: u16) -> String {
    let names: Vec<&str> =
        ALL_PHASES.iter().filter(|m| mask & (**m as u16) != 0).map(|m| m.name()).collect();
    if names.is_empty() {
        "none (this FMU never runs a step asynchronously)".into()
    } else {
        names.join(", ")
    }
}

/// The one check between computed values and the importer: every value a getter or step
/// hands out with a success status is finite. `name(i)` names value `i` for the message; the
/// first non-finite value is reported as an error (the call then returns `fmi2Error`).
pub(crate) fn ensure_finite(
    what: &str,
    values: &[f64],
    name: impl Fn(usize) -> String,
) -> Result<(), String> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!(
            "{what}: `{}` = {} is not finite (the model left its valid range; the last \
             inputs and parameters are kept)",
            name(i),
            values[i]
        )),
    }
}

/// Log category indices into [`LOG_CATEGORIES`].
pub(crate) mod cat {
    pub(crate) const ERROR: usize = 0;
    pub(crate) const WARNING: usize = 1;
    pub(crate) const DISCARD: usize = 2;
    pub(crate) const FATAL: usize = 3;
    pub(crate) const MODEL: usize = 4;
    pub(crate) const CALLS: usize = 5;
}

/// A built engine with the settings it was built from and the derived quantities.
#[derive(Clone)]
pub(crate) struct Built {
    engine: Box<dyn Engine>,
    derived: Derived,
    settings: Settings,
    /// True once [`Engine::start`] ran.
    started: bool,
}

/// Everything an FMU state captures.
#[derive(Clone)]
pub(crate) struct Data {
    pub(crate) mode: Phase,
    pub(crate) time: f64,
    pub(crate) start_time: f64,
    pub(crate) stop_time: Option<f64>,
    pub(crate) settings: Settings,
    pub(crate) inputs: InputValues,
    built: Option<Built>,
    /// The outputs of the last evaluation, written in place by the engine (every slot 0 until
    /// it writes it; an engine writes the same slots every time); valid as `held` says.
    outputs_buf: OutputValues,
    /// What `outputs_buf` holds for the current inputs and state: nothing when an input, a
    /// parameter or the state changed since.
    held: Held,
}

/// What an instance's output buffer holds for the current inputs and state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Held {
    /// Nothing valid.
    Nothing,
    /// The model's partial outputs ([`ModelInfo::partial_output`], [`Engine::outputs_partial`]).
    Partial,
    /// Every output ([`Engine::outputs`]).
    Complete,
}

impl Data {
    fn start(model: &ModelInfo) -> Self {
        Self {
            mode: Phase::Instantiated,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            settings: (model.default_settings)(),
            inputs: (model.default_inputs)(),
            built: None,
            outputs_buf: OutputValues::default(),
            held: Held::Nothing,
        }
    }

    /// The outputs for the current inputs and state, if evaluated.
    fn outputs(&self) -> Option<&OutputValues> {
        (self.held != Held::Nothing).then_some(&self.outputs_buf)
    }

    /// Forgets the outputs (an input, a parameter or the state changed).
    fn forget_outputs(&mut self) {
        self.held = Held::Nothing;
    }
}

/// A saved FMU state (`fmi2FMUstate` points to one of these).
pub(crate) struct Snapshot {
    data: Data,
}

/// One FMU instance.
pub(crate) struct Instance {
    /// The model this instance runs.
    pub(crate) model: &'static ModelInfo,
    /// True for a Model Exchange instance (`fmuType` = fmi2ModelExchange), false for
    /// Co-Simulation.
    pub(crate) me: bool,
    pub(crate) name: CString,
    logger: Option<fmi2CallbackLogger>,
    env: fmi2ComponentEnvironment,
    logging_on: bool,
    /// Bit i set: category i of [`LOG_CATEGORIES`] is logged when `logging_on`.
    enabled: u32,
    resources: Option<PathBuf>,
    pub(crate) data: Data,
    /// The last engine built from start (or any) settings, before its start, kept so that
    /// `fmi2Reset` and deserialised states reuse it instead of building again; a clone of it
    /// repeats a fresh instance's results bit for bit.
    pristine: Option<Built>,
    /// FMU states created by this instance and not yet freed.
    pub(crate) states: Vec<*mut Snapshot>,
    /// The texts returned by the last `fmi2GetString` (valid until the next call).
    pub(crate) strings: Vec<CString>,
    /// Index into the model's variable table by value reference (`u16::MAX`: none), so that
    /// a `fmi2Get…`/`fmi2Set…` finds each variable at once.
    by_vr: Vec<u16>,
}

/// The index of each variable of `model` by value reference ([`Instance::by_vr`]); value
/// references beyond 65 535, or a table of as many variables, are left to
/// [`ModelInfo::by_vr`].
fn vr_index(model: &ModelInfo) -> Vec<u16> {
    let small = |v: &Variable| v.vr < u32::from(u16::MAX);
    let n = model.variables.iter().filter(|v| small(v)).map(|v| v.vr as usize + 1).max();
    let mut index = vec![u16::MAX; n.unwrap_or(0)];
    for (i, v) in model.variables.iter().enumerate().filter(|(_, v)| small(v)) {
        index[v.vr as usize] = u16::try_from(i).unwrap_or(u16::MAX);
    }
    index
}

/// True when `a` and `b` differ at most in `model`'s tunable parameters (an engine built
/// from `a` then serves `b` after [`Engine::tune`]).
fn settings_eq_but_tunable(model: &ModelInfo, a: &Settings, b: &Settings) -> bool {
    let mut b2 = b.clone();
    for v in model.variables.iter().filter(|v| v.variability == Variability::Tunable) {
        if let Access::RealParam(get, set) = v.access {
            set(&mut b2, get(a));
        }
    }
    *a == b2
}

impl Instance {
    pub(crate) fn new(
        model: &'static ModelInfo,
        me: bool,
        name: CString,
        logger: Option<fmi2CallbackLogger>,
        env: fmi2ComponentEnvironment,
        logging_on: bool,
        resources: Option<PathBuf>,
    ) -> Self {
        Self {
            model,
            me,
            name,
            logger,
            env,
            logging_on,
            enabled: u32::MAX,
            resources,
            data: Data::start(model),
            pristine: None,
            states: Vec::new(),
            strings: Vec::new(),
            by_vr: vr_index(model),
        }
    }

    pub(crate) fn mode(&self) -> Phase {
        self.data.mode
    }

    pub(crate) fn set_mode(&mut self, m: Phase) {
        self.data.mode = m;
    }

    /// True when a message of `category` would reach the logger.
    pub(crate) fn logs(&self, category: usize) -> bool {
        self.logger.is_some()
            && (matches!(category, cat::ERROR | cat::DISCARD | cat::FATAL)
                || (self.logging_on && self.enabled & (1 << category) != 0))
    }

    /// Passes `msg` to the importer's logger (errors and fatal errors always, the other
    /// categories when debug logging is on for them). `%` is escaped as `%%` because the
    /// logger treats the message as a printf format.
    pub(crate) fn log(&self, status: fmi2Status, category: usize, msg: &str) {
        if !self.logs(category) {
            return;
        }
        log_to(self.logger, self.env, &self.name, status, category, msg);
    }

    pub(crate) fn set_debug_logging(
        &mut self,
        on: bool,
        categories: &[String],
    ) -> Result<fmi2Status, String> {
        let mut mask = 0u32;
        for c in categories {
            match LOG_CATEGORIES.iter().position(|(n, _)| n == c) {
                Some(i) => mask |= 1 << i,
                None => {
                    let known: Vec<&str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return Err(format!(
                        "unknown log category `{c}`: allowed {}",
                        known.join(", ")
                    ));
                }
            }
        }
        self.logging_on = on;
        self.enabled = if categories.is_empty() { u32::MAX } else { mask };
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn setup_experiment(
        &mut self,
        start: f64,
        stop: Option<f64>,
    ) -> Result<fmi2Status, String> {
        if !start.is_finite() {
            return Err(format!("startTime = {start} is not finite"));
        }
        if let Some(t) = stop
            && !(t.is_finite() && t >= start)
        {
            return Err(format!(
                "stopTime = {}: allowed finite and >= startTime = {}",
                short_num(t),
                short_num(start)
            ));
        }
        self.data.start_time = start;
        self.data.time = start;
        self.data.stop_time = stop;
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn enter_initialization_mode(&mut self) -> Result<fmi2Status, String> {
        self.data.time = self.data.start_time;
        self.data.mode = Phase::InitializationMode;
        if let Some(dir) = &self.resources
            && self.logs(cat::MODEL)
        {
            self.log(
                fmi2Status::Ok,
                cat::MODEL,
                &format!("resources directory: {}", dir.display()),
            );
        }
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn exit_initialization_mode(&mut self) -> Result<fmi2Status, String> {
        self.ensure_started()?;
        self.data.mode = if self.me { Phase::EventMode } else { Phase::StepComplete };
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn terminate(&mut self) -> Result<fmi2Status, String> {
        self.data.mode = Phase::Terminated;
        Ok(fmi2Status::Ok)
    }

    /// Back to the instantiated state with the start values of every variable.
    pub(crate) fn reset(&mut self) -> Result<fmi2Status, String> {
        self.data = Data::start(self.model);
        Ok(fmi2Status::Ok)
    }

    /// Builds the engine for the current settings unless it exists.
    fn ensure_built(&mut self) -> Result<&mut Built, String> {
        if self.data.built.is_none() {
            let s = &self.data.settings;
            let built = match &self.pristine {
                Some(p) if settings_eq_but_tunable(self.model, &p.settings, s) => {
                    let mut b = p.clone();
                    b.engine.tune(s)?;
                    b.settings = s.clone();
                    b
                }
                _ => {
                    let t0 = std::time::Instant::now();
                    let (engine, derived) = (self.model.build)(s)?;
                    let b = Built { engine, derived, settings: s.clone(), started: false };
                    if self.logs(cat::MODEL) {
                        self.log(
                            fmi2Status::Ok,
                            cat::MODEL,
                            &format!(
                                "{} built in {:.3} s (base radii {:.6} / {:.6} mm)",
                                self.model.identifier,
                                t0.elapsed().as_secs_f64(),
                                b.derived.base_radius_p * 1e3,
                                b.derived.base_radius_g * 1e3
                            ),
                        );
                    }
                    self.pristine = Some(b.clone());
                    b
                }
            };
            self.data.built = Some(built);
        }
        Ok(self.data.built.as_mut().expect("built above"))
    }

    /// Builds the engine and puts it at its start unless that is done.
    fn ensure_started(&mut self) -> Result<&mut Built, String> {
        self.ensure_built()?;
        let d = &mut self.data;
        let built = d.built.as_mut().expect("built above");
        if !built.started {
            built.engine.start(&d.settings, &mut d.inputs, d.time)?;
            built.started = true;
            d.held = Held::Nothing;
        }
        Ok(built)
    }

    /// Makes `outputs` those of the current inputs and state, evaluating the model if anything
    /// changed: every output when `complete`, else at least the model's partial outputs
    /// ([`ModelInfo::partial_output`]). Outputs kept from an earlier call serve when they
    /// hold what is asked for.
    fn ensure_outputs(&mut self, complete: bool) -> Result<(), String> {
        match (self.data.held, complete) {
            (Held::Complete, _) | (Held::Partial, false) => return Ok(()),
            _ => {}
        }
        self.ensure_started()?;
        let d = &mut self.data;
        let engine = &mut d.built.as_mut().expect("started above").engine;
        d.held = Held::Nothing;
        let all = if complete {
            engine.outputs(&d.inputs, &mut d.outputs_buf)?;
            true
        } else {
            engine.outputs_partial(&d.inputs, &mut d.outputs_buf)?
        };
        d.held = if all { Held::Complete } else { Held::Partial };
        Ok(())
    }

    /// The variable of value reference `vr`, of type `want`.
    fn lookup(&self, vr: u32, want: VarType) -> Result<&'static Variable, String> {
        let v = self.var(vr).ok_or_else(|| format!("unknown value reference {vr}"))?;
        let ty = v.var_type();
        if ty != want {
            return Err(format!(
                "value reference {vr} (`{}`) is of type {}, not {}",
                v.name,
                ty.as_str(),
                want.as_str()
            ));
        }
        Ok(v)
    }

    /// The variable of value reference `vr`, if any (one index, [`Instance::by_vr`]; the
    /// table's scan for a reference the index does not hold).
    fn var(&self, vr: u32) -> Option<&'static Variable> {
        match self.by_vr.get(vr as usize) {
            Some(&i) if i != u16::MAX => self.model.variables.get(usize::from(i)),
            _ => self.model.by_vr(vr),
        }
    }

    /// Checks that the value references `vrs` are variables of type `ty` and prepares the
    /// values that reading them needs: the built model for a calculated parameter; for
    /// outputs, the model's outputs, only its partial ones ([`ModelInfo::partial_output`])
    /// when every output read is one.
    fn prepare(&mut self, vrs: &[u32], ty: VarType) -> Result<(), String> {
        let (mut calculated, mut computed, mut complete) = (false, false, false);
        for &r in vrs {
            let v = self.lookup(r, ty)?;
            calculated |= v.causality == Causality::CalculatedParameter;
            if matches!(
                v.access,
                Access::RealOutput(_) | Access::IntOutput(_) | Access::BoolOutput(_)
            ) {
                computed = true;
                complete |= !(self.model.partial_output)(v);
            }
        }
        if calculated {
            self.ensure_built()?;
        }
        if computed {
            self.ensure_outputs(complete)?;
        }
        Ok(())
    }

    /// The variable of a value reference that [`Instance::prepare`] checked.
    fn checked(&self, vr: u32) -> &'static Variable {
        self.var(vr).expect("checked by prepare")
    }

    fn read_real(&self, v: &Variable) -> f64 {
        let d = &self.data;
        match v.access {
            Access::RealParam(get, _) => get(&d.settings),
            Access::Input { slot, .. } => d.inputs.values[slot],
            Access::RealOutput(slot) => d.outputs().map_or(f64::NAN, |o| o.reals[slot]),
            Access::Calculated(get) => d.built.as_ref().map_or(f64::NAN, |b| get(&b.derived)),
            _ => f64::NAN,
        }
    }

    pub(crate) fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Result<fmi2Status, String> {
        self.prepare(vrs, VarType::Real)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = self.read_real(self.checked(r));
        }
        ensure_finite("fmi2GetReal", out, |i| self.checked(vrs[i]).name.to_string())?;
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn get_integer(
        &mut self,
        vrs: &[u32],
        out: &mut [i32],
    ) -> Result<fmi2Status, String> {
        self.prepare(vrs, VarType::Integer)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = match self.checked(r).access {
                Access::IntParam(get, _) => get(&self.data.settings),
                Access::IntOutput(slot) => self.data.outputs().map_or(0, |o| o.ints[slot]),
                _ => 0,
            };
        }
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn get_boolean(
        &mut self,
        vrs: &[u32],
        out: &mut [bool],
    ) -> Result<fmi2Status, String> {
        self.prepare(vrs, VarType::Boolean)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = match self.checked(r).access {
                Access::BoolParam(get, _) => get(&self.data.settings),
                Access::BoolOutput(slot) => self.data.outputs().is_some_and(|o| o.bools[slot]),
                _ => false,
            };
        }
        Ok(fmi2Status::Ok)
    }

    /// The texts of String variables `vrs` (`fmi2GetString` keeps them in
    /// [`Instance::strings`] until its next call).
    pub(crate) fn get_string(&mut self, vrs: &[u32]) -> Result<Vec<String>, String> {
        let vars =
            vrs.iter().map(|&r| self.lookup(r, VarType::String)).collect::<Result<Vec<_>, _>>()?;
        Ok(vars
            .iter()
            .map(|v| match v.access {
                Access::StringParam(get, _) => get(&self.data.settings),
                _ => String::new(),
            })
            .collect())
    }

    pub(crate) fn set_string(
        &mut self,
        vrs: &[u32],
        values: &[String],
    ) -> Result<fmi2Status, String> {
        for (&r, x) in vrs.iter().zip(values) {
            let v = self.lookup(r, VarType::String)?;
            self.check_settable(v)?;
            if let Access::StringParam(_, set) = v.access {
                let mut settings = self.data.settings.clone();
                set(&mut settings, x)?;
                if settings != self.data.settings {
                    self.data.settings = settings;
                    self.fixed_parameter_changed();
                }
            }
        }
        Ok(fmi2Status::Ok)
    }

    /// Checks that `v` may be set now.
    fn check_settable(&self, v: &Variable) -> Result<(), String> {
        let mode = self.data.mode;
        match (v.causality, v.variability) {
            (Causality::Input, _) | (Causality::Parameter, Variability::Tunable) => Ok(()),
            (Causality::Parameter, _) => {
                if matches!(mode, Phase::Instantiated | Phase::InitializationMode) {
                    Ok(())
                } else {
                    Err(format!(
                        "parameter `{}` is fixed: it can be set only before \
                         fmi2ExitInitializationMode (state is {})",
                        v.name,
                        mode.name()
                    ))
                }
            }
            (c, _) => Err(format!("`{}` is a {} and cannot be set", v.name, c.as_str())),
        }
    }

    /// Marks the model stale after a fixed parameter changed.
    fn fixed_parameter_changed(&mut self) {
        self.data.built = None;
        self.data.forget_outputs();
    }

    pub(crate) fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result<fmi2Status, String> {
        for (&r, &x) in vrs.iter().zip(values) {
            let v = self.lookup(r, VarType::Real)?;
            self.check_settable(v)?;
            match v.access {
                Access::Input { slot, derivative } => {
                    v.check_input(x)?;
                    let inputs = &mut self.data.inputs;
                    inputs.fresh = true;
                    if derivative {
                        inputs.rates[slot] = 0.0;
                    }
                    if inputs.values[slot].to_bits() != x.to_bits() {
                        inputs.values[slot] = x;
                        self.data.forget_outputs();
                    }
                }
                Access::RealParam(get, set) => {
                    if get(&self.data.settings).to_bits() == x.to_bits() {
                        continue;
                    }
                    if v.variability == Variability::Tunable {
                        // The model checks its own values now, also before it exists; a
                        // refused value leaves the settings as they were.
                        let old = get(&self.data.settings);
                        set(&mut self.data.settings, x);
                        if let Err(e) = (self.model.check_tunable)(&self.data.settings) {
                            set(&mut self.data.settings, old);
                            return Err(format!("{e} (FMI parameter `{}`)", v.name));
                        }
                        if let Some(b) = self.data.built.as_mut() {
                            set(&mut b.settings, x);
                            if let Err(e) = b.engine.tune(&b.settings) {
                                set(&mut b.settings, old);
                                set(&mut self.data.settings, old);
                                return Err(e);
                            }
                        }
                        self.data.forget_outputs();
                    } else {
                        set(&mut self.data.settings, x);
                        self.fixed_parameter_changed();
                    }
                }
                _ => unreachable!("check_settable admits only inputs and parameters"),
            }
        }
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn set_integer(
        &mut self,
        vrs: &[u32],
        values: &[i32],
    ) -> Result<fmi2Status, String> {
        for (&r, &x) in vrs.iter().zip(values) {
            let v = self.lookup(r, VarType::Integer)?;
            self.check_settable(v)?;
            if let Access::IntParam(get, set) = v.access
                && get(&self.data.settings) != x
            {
                set(&mut self.data.settings, x).map_err(|allowed| {
                    format!("parameter `{}` = {x}: allowed {allowed}", v.name)
                })?;
                self.fixed_parameter_changed();
            }
        }
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn set_boolean(
        &mut self,
        vrs: &[u32],
        values: &[bool],
    ) -> Result<fmi2Status, String> {
        for (&r, &x) in vrs.iter().zip(values) {
            let v = self.lookup(r, VarType::Boolean)?;
            self.check_settable(v)?;
            if let Access::BoolParam(get, set) = v.access
                && get(&self.data.settings) != x
            {
                set(&mut self.data.settings, x);
                self.fixed_parameter_changed();
            }
        }
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn do_step(&mut self, t: f64, h: f64) -> Result<fmi2Status, String> {
        if !t.is_finite() || !h.is_finite() || h <= 0.0 {
            return Err(format!(
                "communication step from t = {} s with h = {} s: allowed finite t and h > 0",
                short_num(t),
                short_num(h)
            ));
        }
        let now = self.data.time;
        let tol = 1e-9 * now.abs().max(h).max(1e-9);
        if (t - now).abs() > tol {
            return Err(format!(
                "currentCommunicationPoint = {} s differs from the FMU's time {} s (the end \
                 of the previous step)",
                short_num(t),
                short_num(now)
            ));
        }
        if let Some(stop) = self.data.stop_time
            && t + h > stop + 1e-9 * stop.abs().max(h)
        {
            return Err(format!(
                "step to t + h = {} s beyond stopTime = {} s",
                short_num(t + h),
                short_num(stop)
            ));
        }
        if self.model.stateful {
            self.ensure_started()?;
            let d = &mut self.data;
            let engine = &mut d.built.as_mut().expect("started above").engine;
            match engine.step(&d.inputs, now, h) {
                Ok(()) => {
                    d.held = Held::Nothing;
                    d.inputs.fresh = false;
                    // At most MAX_STATES states: no allocation per step.
                    let mut buf = [0.0; MAX_STATES];
                    let x = &mut buf[..engine.n_states()];
                    engine.get_states(x);
                    ensure_finite("fmi2DoStep", x, |i| self.model.state_name(i))?;
                }
                Err(StepFailure::Discard(msg)) => {
                    self.data.mode = Phase::StepFailed;
                    self.log(fmi2Status::Discard, cat::DISCARD, &format!("fmi2DoStep: {msg}"));
                    return Ok(fmi2Status::Discard);
                }
                Err(StepFailure::Error(msg)) => return Err(msg),
            }
        }
        self.data.time = t + h;
        Ok(fmi2Status::Ok)
    }

    /// `fmi2SetRealInputDerivatives`: first derivatives (`order` 1) of Real inputs, used as a
    /// first-order hold over the following communication steps until the input is set again.
    pub(crate) fn set_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<fmi2Status, String> {
        for ((&r, &order), &x) in vrs.iter().zip(orders).zip(values) {
            let v = self.lookup(r, VarType::Real)?;
            if v.causality != Causality::Input {
                return Err(format!("`{}` is not an input: derivatives are set on inputs", v.name));
            }
            if order != 1 {
                return Err(format!(
                    "derivative of order {order} of input `{}`: allowed 1 (first-order hold)",
                    v.name
                ));
            }
            if !x.is_finite() {
                return Err(format!("derivative of input `{}` = {x} is not finite", v.name));
            }
            self.data.inputs.fresh = true;
            if let Access::Input { slot, derivative: true } = v.access {
                self.data.inputs.rates[slot] = x;
            }
        }
        Ok(fmi2Status::Ok)
    }

    /// Current communication time, s.
    pub(crate) fn time(&self) -> f64 {
        self.data.time
    }

    // ---- Model Exchange

    /// Number of continuous states of the model (its derivative variables).
    pub(crate) fn n_states(&self) -> usize {
        self.model.derivatives().count()
    }

    fn check_nx(&self, n: usize, what: &str) -> Result<(), String> {
        let nx = self.n_states();
        if n != nx {
            return Err(format!(
                "{what}: nx = {n}, but {} has {nx} continuous states",
                self.model.identifier
            ));
        }
        Ok(())
    }

    fn engine(&mut self) -> Result<&mut Box<dyn Engine>, String> {
        Ok(&mut self.ensure_started()?.engine)
    }

    /// `fmi2SetTime`: the time of the next evaluations, s (finite).
    pub(crate) fn me_set_time(&mut self, t: f64) -> Result<fmi2Status, String> {
        if !t.is_finite() {
            return Err(format!("time = {t} s is not finite"));
        }
        self.engine()?.set_time(t)?;
        self.data.time = t;
        self.data.forget_outputs();
        Ok(fmi2Status::Ok)
    }

    /// `fmi2SetContinuousStates` (relative coordinates, every value finite).
    pub(crate) fn me_set_states(&mut self, x: &[f64]) -> Result<fmi2Status, String> {
        self.check_nx(x.len(), "fmi2SetContinuousStates")?;
        if let Some((i, v)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let names = self.model.state_names();
            return Err(format!("state {} (`{}`) = {v} is not finite", i + 1, names[i]));
        }
        self.engine()?.set_states(x)?;
        self.data.forget_outputs();
        Ok(fmi2Status::Ok)
    }

    /// `fmi2GetContinuousStates`.
    pub(crate) fn me_get_states(&mut self, x: &mut [f64]) -> Result<fmi2Status, String> {
        self.check_nx(x.len(), "fmi2GetContinuousStates")?;
        self.engine()?.get_states(x);
        ensure_finite("fmi2GetContinuousStates", x, |i| self.model.state_name(i))?;
        Ok(fmi2Status::Ok)
    }

    /// `fmi2GetDerivatives`: the state derivatives at the current time, states and inputs (the
    /// values of the `der(…)` variables).
    pub(crate) fn me_get_derivatives(&mut self, dx: &mut [f64]) -> Result<fmi2Status, String> {
        self.check_nx(dx.len(), "fmi2GetDerivatives")?;
        self.ensure_outputs(false)?;
        let o = self.data.outputs().expect("evaluated above");
        for (d, v) in dx.iter_mut().zip(self.model.derivatives()) {
            *d = match v.access {
                Access::RealOutput(slot) => o.reals[slot],
                _ => f64::NAN,
            };
        }
        // The names are looked up only for the message (no allocation per call).
        ensure_finite("fmi2GetDerivatives", dx, |i| {
            self.model
                .derivatives()
                .nth(i)
                .map_or_else(|| format!("derivative {}", i + 1), |v| v.name.to_string())
        })?;
        Ok(fmi2Status::Ok)
    }

    /// `fmi2GetEventIndicators`.
    pub(crate) fn me_event_indicators(&mut self, z: &mut [f64]) -> Result<fmi2Status, String> {
        let ni = self.model.event_indicators;
        if z.len() != ni {
            return Err(format!(
                "ni = {}, but {} has {ni} event indicators",
                z.len(),
                self.model.identifier
            ));
        }
        if ni > 0 {
            self.engine()?.event_indicators(z)?;
            ensure_finite("fmi2GetEventIndicators", z, |i| format!("event indicator {}", i + 1))?;
        }
        Ok(fmi2Status::Ok)
    }

    /// `fmi2GetNominalsOfContinuousStates`.
    pub(crate) fn me_nominals(&mut self, x: &mut [f64]) -> Result<fmi2Status, String> {
        self.check_nx(x.len(), "fmi2GetNominalsOfContinuousStates")?;
        if !x.is_empty() {
            self.ensure_built()?.engine.nominals(x);
            ensure_finite("fmi2GetNominalsOfContinuousStates", x, |i| self.model.state_name(i))?;
        }
        Ok(fmi2Status::Ok)
    }

    /// `fmi2GetDirectionalDerivative`: Σ_j ∂unknown_i/∂known_j·seed_j from the model's exact
    /// Jacobian ([`Engine::jacobian`]). Unknowns: outputs and state derivatives; knowns:
    /// inputs and continuous states.
    pub(crate) fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<fmi2Status, String> {
        let states = self.model.state_names();
        let name_of = |vr: u32, what: &str| -> Result<&'static Variable, String> {
            let v = self
                .model
                .by_vr(vr)
                .ok_or_else(|| format!("unknown value reference {vr} ({what})"))?;
            if v.var_type().as_str() != "Real" {
                return Err(format!("`{}` ({what}) is not a Real variable", v.name));
            }
            Ok(v)
        };
        let mut rows = Vec::with_capacity(unknowns.len());
        for &vr in unknowns {
            let v = name_of(vr, "unknown")?;
            if !(v.causality == Causality::Output || v.derivative_of.is_some()) {
                return Err(format!(
                    "`{}` is a {} variable: directional derivatives are provided for outputs and state derivatives",
                    v.name,
                    v.causality.as_str()
                ));
            }
            rows.push(v.name);
        }
        let mut cols = Vec::with_capacity(knowns.len());
        for &vr in knowns {
            let v = name_of(vr, "known")?;
            if !(v.causality == Causality::Input || states.contains(&v.name)) {
                return Err(format!(
                    "`{}` is neither an input nor a continuous state: directional derivatives are \
                     provided with respect to inputs and states only",
                    v.name
                ));
            }
            cols.push(v.name);
        }
        if let Some(s) = seed.iter().find(|s| !s.is_finite()) {
            return Err(format!("seed value {s} is not finite"));
        }
        let inputs = self.data.inputs;
        let j: Jacobian = self.engine()?.jacobian(&inputs)?;
        let w = j.cols.len();
        let ci: Vec<usize> = cols
            .iter()
            .map(|c| {
                j.cols
                    .iter()
                    .position(|k| k == c)
                    .ok_or_else(|| format!("no derivatives with respect to `{c}`"))
            })
            .collect::<Result<_, _>>()?;
        for (o, r) in out.iter_mut().zip(&rows) {
            let ri = j.rows.iter().position(|k| k == r).ok_or_else(|| {
                format!(
                    "the directional derivative of `{r}` is not provided (provided: {})",
                    j.rows.join(", ")
                )
            })?;
            *o = ci.iter().zip(seed).map(|(&c, s)| j.values[ri * w + c] * s).sum();
        }
        if let Some(v) = out.iter().find(|v| !v.is_finite()) {
            return Err(format!("directional derivative {v} is not finite"));
        }
        Ok(fmi2Status::Ok)
    }

    // ---- FMU states

    fn owns(&self, s: *mut Snapshot) -> bool {
        self.states.contains(&s)
    }

    /// Saves the current state into `existing` (if given and owned) or a new snapshot.
    pub(crate) fn get_state(&mut self, existing: *mut Snapshot) -> Result<*mut Snapshot, String> {
        if existing.is_null() {
            let p = Box::into_raw(Box::new(Snapshot { data: self.data.clone() }));
            self.states.push(p);
            Ok(p)
        } else if self.owns(existing) {
            // SAFETY: owned snapshots are live boxes created above and not yet freed.
            unsafe { (*existing).data = self.data.clone() };
            Ok(existing)
        } else {
            Err("*FMUstate is neither NULL nor an FMU state of this instance".into())
        }
    }

    pub(crate) fn set_state(&mut self, s: *mut Snapshot) -> Result<fmi2Status, String> {
        if !self.owns(s) {
            return Err("FMUstate is not a live FMU state of this instance".into());
        }
        // SAFETY: owned snapshots are live boxes.
        self.data = unsafe { (*s).data.clone() };
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn free_state(&mut self, s: *mut Snapshot) -> Result<fmi2Status, String> {
        if s.is_null() {
            return Ok(fmi2Status::Ok);
        }
        let i = self
            .states
            .iter()
            .position(|&p| p == s)
            .ok_or("FMUstate is not a live FMU state of this instance")?;
        self.states.swap_remove(i);
        // SAFETY: created by Box::into_raw in get_state/deserialize and removed from the list.
        drop(unsafe { Box::from_raw(s) });
        Ok(fmi2Status::Ok)
    }

    pub(crate) fn serialize_state(&self, s: *mut Snapshot) -> Result<Vec<u8>, String> {
        if !self.owns(s) {
            return Err("FMUstate is not a live FMU state of this instance".into());
        }
        // SAFETY: owned snapshots are live boxes.
        Ok(serialize(self.model, unsafe { &(*s).data }))
    }

    pub(crate) fn deserialize_state(&mut self, bytes: &[u8]) -> Result<*mut Snapshot, String> {
        let (mut data, engine_state) = deserialize(self.model, bytes)?;
        if matches!(
            data.mode,
            Phase::StepComplete
                | Phase::StepFailed
                | Phase::StepCanceled
                | Phase::EventMode
                | Phase::ContinuousTimeMode
        ) || engine_state.is_some()
            || data.outputs().is_some()
        {
            // Attach an engine (a clone of the pristine one when the settings match) with the
            // saved state.
            let saved = std::mem::replace(&mut self.data, data);
            let cached = self.data.outputs().copied();
            let inputs = self.data.inputs;
            let model = self.model;
            let r = self.ensure_built().and_then(|b| {
                if let Some(bytes) = &engine_state {
                    b.engine.load(bytes)?;
                    b.started = true;
                }
                // Cached outputs are not trusted: they must be what the restored inputs give
                // (evaluated on a copy, so the restored warm start stays as it was).
                match cached {
                    Some(o) => {
                        let mut fresh = OutputValues::default();
                        b.engine.clone_box().outputs(&inputs, &mut fresh)?;
                        check_cached_outputs(model, &o, &fresh)
                    }
                    None => Ok(()),
                }
            });
            data = std::mem::replace(&mut self.data, saved);
            r?;
        }
        let p = Box::into_raw(Box::new(Snapshot { data }));
        self.states.push(p);
        Ok(p)
    }

    /// Frees all snapshots (when the instance is freed).
    pub(crate) fn free_all_states(&mut self) {
        for p in self.states.drain(..) {
            // SAFETY: every entry is a live box created by this instance.
            drop(unsafe { Box::from_raw(p) });
        }
    }
}

/// Sends one message to `logger` (see [`Instance::log`]).
pub(crate) fn log_to(
    logger: Option<fmi2CallbackLogger>,
    env: fmi2ComponentEnvironment,
    name: &CString,
    status: fmi2Status,
    category: usize,
    msg: &str,
) {
    let Some(logger) = logger else { return };
    let text = msg.replace('%', "%%").replace('\0', " ");
    let text = CString::new(text).unwrap_or_default();
    let category = CString::new(LOG_CATEGORIES[category].0).unwrap_or_default();
    // SAFETY: the importer's logger, called with valid zero-terminated strings and no
    // variadic arguments (all `%` are escaped).
    unsafe { logger(env, name.as_ptr(), status, category.as_ptr(), text.as_ptr()) };
}

// ---- serialised FMU state
//
// Layout (little endian): magic `HGMSTATE`, format version u32, GUID (u32 length + bytes),
// state-machine state u8 (its bit position), time f64, start time f64, stop time (u8 flag +
// f64), then every parameter and input in table order (Real f64, Integer i32, Boolean u8,
// String u32 length + UTF-8 bytes), then the time derivative (f64) of every input whose
// variable says the model uses it (`Access::Input { derivative: true }`), in table order, and
// the `fresh` flag (u8); then the engine's state (u32 length, 0 before the start or when it
// has none, + bytes: a unit's snapshot text, warm start included; the mesh element's
// load-solver warm start, `mesh::WarmStart::to_bytes`, so that a restored element evaluates
// bit for bit as the original); last the cached outputs (u8 flag, then, for a model with
// `ModelInfo::cached_outputs` whose cached outputs are complete, the value of every output and
// local variable in table order: Real f64, Integer i32, Boolean u8; models without, the
// stateful ones, always write 0: their outputs follow from the state; partial outputs,
// `Engine::outputs_partial`'s, are not written: the element's partial evaluation is the
// table's, which depends on the inputs alone, or the full model's, which is complete). The
// engine itself (the mesh model) is not serialised: it is rebuilt from the parameters (or
// cloned from the instance's last build with the same parameters). The last 8 bytes are the
// 64-bit FNV-1a checksum (`numeric::fnv1a_64`) of everything before them. A state is refused whole when the magic, the version, the GUID or
// the checksum does not match, and every value read is checked: finite times, parameters and
// input derivatives (the parameters' ranges when the model is rebuilt), inputs within their
// stated ranges (`Variable::check_input`), cached outputs finite and flags 0 or 1.
//
// Version 6: the input derivatives are those the model's variables flag, in table order
// (version 5 wrote five named derivatives for every model).

const MAGIC: &[u8; 8] = b"HGMSTATE";
const FORMAT_VERSION: u32 = 6;

fn serialize(model: &ModelInfo, d: &Data) -> Vec<u8> {
    let mut b = Vec::with_capacity(512);
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    let g = model.guid().as_bytes();
    b.extend_from_slice(&(g.len() as u32).to_le_bytes());
    b.extend_from_slice(g);
    b.push(d.mode.code());
    b.extend_from_slice(&d.time.to_le_bytes());
    b.extend_from_slice(&d.start_time.to_le_bytes());
    b.push(u8::from(d.stop_time.is_some()));
    b.extend_from_slice(&d.stop_time.unwrap_or(0.0).to_le_bytes());
    for v in model.variables {
        match v.access {
            Access::RealParam(get, _) => b.extend_from_slice(&get(&d.settings).to_le_bytes()),
            Access::IntParam(get, _) => b.extend_from_slice(&get(&d.settings).to_le_bytes()),
            Access::BoolParam(get, _) => b.push(u8::from(get(&d.settings))),
            Access::Input { slot, .. } => b.extend_from_slice(&d.inputs.values[slot].to_le_bytes()),
            Access::StringParam(get, _) => {
                let text = get(&d.settings);
                b.extend_from_slice(&(text.len() as u32).to_le_bytes());
                b.extend_from_slice(text.as_bytes());
            }
            _ => {}
        }
    }
    for v in model.variables {
        if let Access::Input { slot, derivative: true } = v.access {
            b.extend_from_slice(&d.inputs.rates[slot].to_le_bytes());
        }
    }
    b.push(u8::from(d.inputs.fresh));
    let state = match &d.built {
        Some(built) if built.started => built.engine.save(),
        _ => Vec::new(),
    };
    b.extend_from_slice(&(state.len() as u32).to_le_bytes());
    b.extend_from_slice(&state);
    if model.cached_outputs && d.held == Held::Complete {
        b.push(1);
        save_outputs(model, &d.outputs_buf, &mut b);
    } else {
        b.push(0);
    }
    let sum = crate::numeric::fnv1a_64(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

/// Relative agreement required between a restored state's cached outputs and the outputs its
/// restored inputs give (the load solver converges far below it; a value edited in a state is
/// far above it).
const CACHED_OUTPUT_TOLERANCE: f64 = 1e-6;

/// Checks the cached outputs `cached` of a restored state against `fresh`, the outputs of its
/// restored inputs: every count and flag equal, every Real within [`CACHED_OUTPUT_TOLERANCE`]
/// of the largest magnitude among the model's outputs of the same unit (so that a value near
/// zero is compared on the scale of its kind). The error names the first that differs.
fn check_cached_outputs(
    model: &ModelInfo,
    cached: &OutputValues,
    fresh: &OutputValues,
) -> Result<(), String> {
    let scale = |unit: Option<&str>| {
        (model.variables.iter())
            .filter_map(|w| match w.access {
                Access::RealOutput(k) if w.unit == unit => Some(fresh.reals[k].abs()),
                _ => None,
            })
            .fold(0.0, f64::max)
    };
    for v in model.variables {
        let (a, b) = match v.access {
            Access::RealOutput(k) => {
                let (a, b) = (cached.reals[k], fresh.reals[k]);
                if (a - b).abs() <= CACHED_OUTPUT_TOLERANCE * scale(v.unit).max(b.abs()) {
                    continue;
                }
                (a.to_string(), b.to_string())
            }
            Access::IntOutput(k) if cached.ints[k] != fresh.ints[k] => {
                (cached.ints[k].to_string(), fresh.ints[k].to_string())
            }
            Access::BoolOutput(k) if cached.bools[k] != fresh.bools[k] => {
                (cached.bools[k].to_string(), fresh.bools[k].to_string())
            }
            _ => continue,
        };
        return Err(format!(
            "serialised state: cached output `{}` = {a} is not what the restored inputs give \
             ({b}); the state was altered",
            v.name
        ));
    }
    Ok(())
}

/// Appends the cached outputs `o` of `model` (every output and local variable of its table, in
/// table order: Real f64, Integer i32, Boolean u8, little endian).
pub(crate) fn save_outputs(model: &ModelInfo, o: &OutputValues, b: &mut Vec<u8>) {
    for v in model.variables {
        match v.access {
            Access::RealOutput(slot) => b.extend_from_slice(&o.reals[slot].to_le_bytes()),
            Access::IntOutput(slot) => b.extend_from_slice(&o.ints[slot].to_le_bytes()),
            Access::BoolOutput(slot) => b.push(u8::from(o.bools[slot])),
            _ => {}
        }
    }
}

/// Number of bytes [`save_outputs`] writes for `model`.
fn outputs_len(model: &ModelInfo) -> usize {
    (model.variables.iter())
        .map(|v| match v.access {
            Access::RealOutput(_) => 8,
            Access::IntOutput(_) => 4,
            Access::BoolOutput(_) => 1,
            _ => 0,
        })
        .sum()
}

/// Reads the cached outputs written by [`save_outputs`] from the start of `bytes` (the rest
/// of the state follows) and returns them with the number of bytes read; every Real is
/// checked finite, every flag 0 or 1, a short input is refused as truncated.
pub(crate) fn load_outputs(
    model: &ModelInfo,
    bytes: &[u8],
) -> Result<(OutputValues, usize), String> {
    let len = outputs_len(model);
    let b = bytes.get(..len).ok_or_else(|| {
        format!("serialised state truncated in the cached outputs ({} of {len} bytes)", bytes.len())
    })?;
    let mut r = Reader { b, at: 0 };
    let mut o = OutputValues::default();
    for v in model.variables {
        match v.access {
            Access::RealOutput(slot) => {
                let x = r.f64()?;
                ensure_finite("serialised state: cached output", &[x], |_| v.name.to_string())?;
                o.reals[slot] = x;
            }
            Access::IntOutput(slot) => o.ints[slot] = r.i32()?,
            Access::BoolOutput(slot) => {
                o.bools[slot] = match r.u8()? {
                    0 => false,
                    1 => true,
                    x => {
                        return Err(format!(
                            "serialised state: cached output flag byte {x} (allowed 0 or 1)"
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    Ok((o, len))
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let s = self
            .b
            .get(self.at..self.at + N)
            .ok_or_else(|| format!("serialised state truncated at byte {}", self.at))?;
        self.at += N;
        Ok(s.try_into().expect("length checked"))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take()?))
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    fn i32(&mut self) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.take()?))
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take::<1>()?[0])
    }
    fn bool(&mut self) -> Result<bool, String> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            x => Err(format!("serialised state: boolean byte {x} at {}", self.at - 1)),
        }
    }
}

/// The data of a serialised state and, for a stateful model that had started, the engine's
/// state.
fn deserialize(model: &ModelInfo, bytes: &[u8]) -> Result<(Data, Option<Vec<u8>>), String> {
    let mut r = Reader { b: bytes, at: 0 };
    if &r.take::<8>()? != MAGIC {
        return Err("not a serialised state of this FMU (bad magic bytes)".into());
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "serialised state has format version {version}; this FMU reads version \
             {FORMAT_VERSION}"
        ));
    }
    if bytes.len() < 8 + 4 + 8 {
        return Err(format!("serialised state truncated: {} bytes", bytes.len()));
    }
    let (payload, tail) = bytes.split_at(bytes.len() - 8);
    let stored = u64::from_le_bytes(tail.try_into().expect("8 bytes"));
    let sum = crate::numeric::fnv1a_64(payload);
    if stored != sum {
        return Err(format!(
            "serialised state truncated or corrupted: checksum mismatch (stored \
             {stored:016x}, computed {sum:016x})"
        ));
    }
    let bytes = payload;
    let mut r = Reader { b: bytes, at: r.at };
    let n = r.u32()? as usize;
    let g = r.b.get(r.at..r.at + n).ok_or("serialised state truncated in the GUID")?;
    r.at += n;
    if g != model.guid().as_bytes() {
        return Err(format!(
            "serialised state belongs to FMU {}, not {} ({})",
            String::from_utf8_lossy(g),
            model.guid(),
            model.identifier
        ));
    }
    let m = r.u8()?;
    let mode = Phase::from_code(m).ok_or_else(|| format!("serialised state: bad mode {m}"))?;
    let mut d = Data::start(model);
    d.mode = mode;
    d.time = r.f64()?;
    d.start_time = r.f64()?;
    let has_stop = r.bool()?;
    let stop = r.f64()?;
    d.stop_time = has_stop.then_some(stop);
    for v in model.variables {
        match v.access {
            Access::RealParam(_, set) => {
                let x = r.f64()?;
                if !x.is_finite() {
                    return Err(format!(
                        "serialised state: parameter `{}` = {x} is not finite",
                        v.name
                    ));
                }
                set(&mut d.settings, x)
            }
            Access::IntParam(_, set) => {
                let x = r.i32()?;
                set(&mut d.settings, x).map_err(|a| {
                    format!("serialised state: parameter `{}` = {x}: allowed {a}", v.name)
                })?;
            }
            Access::BoolParam(_, set) => set(&mut d.settings, r.bool()?),
            Access::Input { slot, .. } => {
                let x = r.f64()?;
                v.check_input(x).map_err(|e| format!("serialised state: {e}"))?;
                d.inputs.values[slot] = x;
            }
            Access::StringParam(_, set) => {
                let n = r.u32()? as usize;
                let t = r.b.get(r.at..r.at + n).ok_or_else(|| {
                    format!("serialised state truncated in parameter `{}`", v.name)
                })?;
                r.at += n;
                let text = std::str::from_utf8(t)
                    .map_err(|e| format!("serialised state: parameter `{}`: {e}", v.name))?;
                set(&mut d.settings, text).map_err(|e| format!("serialised state: {e}"))?;
            }
            _ => {}
        }
    }
    for v in model.variables {
        if let Access::Input { slot, derivative: true } = v.access {
            let x = r.f64()?;
            if !x.is_finite() {
                return Err(format!(
                    "serialised state: derivative of input `{}` = {x} is not finite",
                    v.name
                ));
            }
            d.inputs.rates[slot] = x;
        }
    }
    d.inputs.fresh = r.bool()?;
    for (name, t) in [("time", d.time), ("start time", d.start_time), ("stop time", stop)] {
        if !t.is_finite() {
            return Err(format!("serialised state: {name} = {t} is not finite"));
        }
    }
    // The state's time lies in its own experiment: from the start time to the stop time.
    if d.time < d.start_time || d.stop_time.is_some_and(|stop| d.time > stop) {
        return Err(format!(
            "serialised state: time = {} outside its experiment [{}, {}]",
            d.time,
            d.start_time,
            d.stop_time.map_or("no stop time".to_string(), |s| s.to_string())
        ));
    }
    let mut engine_state = None;
    let n = r.u32()? as usize;
    let s = r.b.get(r.at..r.at + n).ok_or("serialised state truncated in the model state")?;
    r.at += n;
    if n > 0 {
        engine_state = Some(s.to_vec());
    }
    if r.bool()? {
        if !model.cached_outputs {
            return Err(format!(
                "serialised state: cached outputs in a state of {}",
                model.identifier
            ));
        }
        let (o, n) = load_outputs(model, &r.b[r.at..])?;
        r.at += n;
        d.outputs_buf = o;
        d.held = Held::Complete;
    }
    if r.at != bytes.len() {
        return Err(format!(
            "serialised state has {} bytes; this FMU's state has {}",
            bytes.len(),
            r.at
        ));
    }
    Ok((d, engine_state))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::models::MODELS;
    use crate::fmi2::models::unit::{PAIR, STAGE};

    /// The index by value reference finds every variable of every model as the table's scan
    /// does, and nothing for a reference that no variable has (between, beyond, the largest
    /// u32); the type check names the variable and both types.
    #[test]
    fn every_value_reference_is_found_as_by_the_scan_and_no_other() {
        for &model in MODELS {
            let inst =
                Instance::new(model, false, c"i".into(), None, std::ptr::null_mut(), false, None);
            let largest = model.variables.iter().map(|v| v.vr).max().unwrap();
            for vr in (0..=largest + 2).chain([u32::from(u16::MAX), u32::MAX]) {
                let found = inst.var(vr).map(|v| v.name);
                assert_eq!(found, model.by_vr(vr).map(|v| v.name), "{} {vr}", model.identifier);
            }
            for v in model.variables {
                assert!(inst.lookup(v.vr, v.var_type()).is_ok_and(|w| std::ptr::eq(w, v)));
            }
            let v = model.by_name("TE").unwrap();
            let e = inst.lookup(v.vr, VarType::Integer).err().unwrap();
            assert!(e.contains("`TE`") && e.contains("Real") && e.contains("Integer"), "{e}");
            let e = inst.lookup(largest + 1, VarType::Real).err().unwrap();
            assert!(e.contains("unknown value reference"), "{e}");
        }
    }

    /// The input derivatives a model uses travel in a serialised state and come back bit for
    /// bit; the state re-serialises to the same bytes.
    #[test]
    fn serialised_state_carries_the_input_derivatives_a_model_uses_bit_for_bit() {
        for model in [&PAIR, &STAGE] {
            let mut d = Data::start(model);
            d.time = 0.125;
            d.inputs.fresh = true;
            let mut k = 0.0;
            for v in model.variables {
                if let Access::Input { slot, derivative } = v.access {
                    k += 1.0;
                    d.inputs.values[slot] = 0.1 * k + 1e-17;
                    if derivative {
                        d.inputs.rates[slot] = -3.0 * k + 1e-13;
                    }
                }
            }
            assert!(
                d.inputs.rates.iter().filter(|&&r| r != 0.0).count() == 2,
                "{}",
                model.identifier
            );
            let b = serialize(model, &d);
            let (back, engine) = deserialize(model, &b).unwrap();
            assert!(engine.is_none());
            assert_eq!(back.inputs, d.inputs, "{}", model.identifier);
            assert_eq!(back.time.to_bits(), d.time.to_bits());
            assert_eq!(serialize(model, &back), b, "{}", model.identifier);
        }
    }

    /// A state of another format version is refused with a message naming both versions.
    #[test]
    fn serialised_state_of_format_version_5_is_refused_naming_both_versions() {
        let mut b = serialize(&PAIR, &Data::start(&PAIR));
        b[8..12].copy_from_slice(&5u32.to_le_bytes());
        let n = b.len() - 8;
        let sum = crate::numeric::fnv1a_64(&b[..n]);
        b[n..].copy_from_slice(&sum.to_le_bytes());
        let e = deserialize(&PAIR, &b).err().expect("refused");
        assert!(e.contains("format version 5") && e.contains("reads version 6"), "{e}");
    }
}
