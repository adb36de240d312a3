//! What a model contributes to the one FMI layer: its description ([`ModelInfo`]: identifier,
//! variable table, defaults, default experiment, documentation) and its physics ([`Engine`]).
//!
//! The FMI layer (the private module `fmi2::instance`, [`super::exports`]) knows nothing of
//! gears: it runs the state machine, dispatches value references through the model's variable
//! table, logs, saves and restores FMU states, and calls the model's [`Engine`] to build, start,
//! evaluate and step.
//! Whatever depends on the physics is the model's: the check of its tunable parameters
//! ([`ModelInfo::check_tunable`], before the engine exists) and their application without a
//! rebuild ([`Engine::tune`]; the layer knows which parameters are tunable from the variable
//! table's variability), the bytes of its state ([`Engine::save`], [`Engine::load`]), whether
//! a serialised FMU state carries its cached outputs ([`ModelInfo::cached_outputs`]), the
//! meaning of its input and output slots (its variable table names a slot of the generic
//! [`InputValues`] / [`OutputValues`] for each input and output, and which inputs' time
//! derivatives it uses; the engine reads and fills those slots), and, for Model Exchange, its
//! states, nominals and exact Jacobian (rows and columns named by the variable names of its
//! table). A new model is one file under `fmi2/models/` with its variable table, its
//! [`ModelInfo`] and its [`Engine`].

use std::sync::OnceLock;

use super::variables::{
    CS_CAPABILITIES, Derived, InputValues, LOG_CATEGORIES, MODEL_VERSION, OutputValues, Settings,
    UNITS, Variable,
};

/// Model Exchange: the most continuous states a model may have; the instance's state buffers
/// are this long, so that a step allocates nothing.
pub const MAX_STATES: usize = 28;

/// The default experiment of a model (`<DefaultExperiment>`), s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Experiment {
    /// Start time, s.
    pub start: f64,
    /// Stop time, s.
    pub stop: f64,
    /// Communication step, s.
    pub step: f64,
}

/// Why a communication step could not be completed.
#[derive(Debug, Clone, PartialEq)]
pub enum StepFailure {
    /// The step cannot be completed, the instance is intact (the state is that at the start of
    /// the step): `fmi2Discard`.
    Discard(String),
    /// The instance cannot go on: `fmi2Error`.
    Error(String),
}

/// The physics of a model behind the FMI layer: built from the parameters at
/// `fmi2ExitInitializationMode`, cloned into FMU states.
pub trait Engine: Send {
    /// A boxed copy (FMU states hold one).
    fn clone_box(&self) -> Box<dyn Engine>;
    /// Applies the tunable parameters of `settings` (already checked by
    /// [`ModelInfo::check_tunable`]) without a rebuild: called after one of them changed, and
    /// on a copy of a built engine whose fixed parameters match.
    fn tune(&mut self, settings: &Settings) -> Result<(), String>;
    /// Puts the engine at its start (time `t0`, s) from the parameters; may overwrite the
    /// inputs with values consistent with the start (the static equilibrium of the stateful
    /// models).
    fn start(
        &mut self,
        settings: &Settings,
        inputs: &mut InputValues,
        t0: f64,
    ) -> Result<(), String>;
    /// The outputs at the current time and state for `inputs`, written in place into `out`:
    /// the model fills the slots its output variables name, the Model Exchange states and
    /// state derivatives included, the same slots at every call (the others keep what they
    /// held, and are not read). After an error `out` holds nothing valid.
    fn outputs(&mut self, inputs: &InputValues, out: &mut OutputValues) -> Result<(), String>;
    /// The outputs a reader of only the model's partial outputs needs
    /// ([`ModelInfo::partial_output`]), written into `out`: every one of those as
    /// [`Engine::outputs`] gives it, and whether the rest is there too (`true`: the whole of
    /// [`Engine::outputs`]; `false`: the other slots are unspecified and are not read). The
    /// default is [`Engine::outputs`], complete.
    fn outputs_partial(
        &mut self,
        inputs: &InputValues,
        out: &mut OutputValues,
    ) -> Result<bool, String> {
        self.outputs(inputs, out).map(|()| true)
    }
    /// Advances from `t` by `h` (s) with `inputs` held over the step.
    fn step(&mut self, inputs: &InputValues, t: f64, h: f64) -> Result<(), StepFailure>;
    /// The engine's own state (beyond parameters and inputs) as bytes, empty for a stateless
    /// model.
    fn save(&self) -> Vec<u8>;
    /// Restores the state written by [`Engine::save`].
    fn load(&mut self, bytes: &[u8]) -> Result<(), String>;

    /// Model Exchange: number of continuous states (0 for a model without states).
    fn n_states(&self) -> usize {
        0
    }

    /// Model Exchange: sets the time (s) at which the next evaluations apply.
    fn set_time(&mut self, t: f64) -> Result<(), String> {
        let _ = t;
        Ok(())
    }

    /// Model Exchange: the continuous states (length [`Engine::n_states`], in the order of the
    /// model's derivative variables).
    fn get_states(&self, x: &mut [f64]) {
        let _ = x;
    }

    /// Model Exchange: sets the continuous states.
    fn set_states(&mut self, x: &[f64]) -> Result<(), String> {
        if x.is_empty() { Ok(()) } else { Err("this model has no continuous states".into()) }
    }

    /// Model Exchange: nominal magnitudes of the continuous states (> 0).
    fn nominals(&self, x: &mut [f64]) {
        x.fill(1.0);
    }

    /// Model Exchange: the event indicators at the current time, state and inputs (as many
    /// as [`ModelInfo::event_indicators`]).
    fn event_indicators(&mut self, z: &mut [f64]) -> Result<(), String> {
        let _ = z;
        Ok(())
    }

    /// The exact partial derivatives of the model's outputs and state derivatives with respect
    /// to its continuous states and inputs at the current time, state and `inputs`
    /// (`fmi2GetDirectionalDerivative`).
    fn jacobian(&mut self, inputs: &InputValues) -> Result<Jacobian, String>;
}

/// Partial derivatives ∂row/∂col of some of a model's unknowns (outputs, state derivatives)
/// with respect to its knowns (continuous states, inputs), dense, row-major, in SI units;
/// rows and columns named by FMI variable name.
#[derive(Debug, Clone, PartialEq)]
pub struct Jacobian {
    /// Unknowns (variable names).
    pub rows: Vec<&'static str>,
    /// Knowns (variable names).
    pub cols: Vec<&'static str>,
    /// `values[r * cols.len() + c]` = ∂`rows[r]`/∂`cols[c]`.
    pub values: Vec<f64>,
}

impl Clone for Box<dyn Engine> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// Builds the engine of a model and the calculated parameters from the parameters.
pub type BuildFn = fn(&Settings) -> Result<(Box<dyn Engine>, Derived), String>;

/// Everything a model contributes besides its physics.
pub struct ModelInfo {
    /// Model identifier (name of the model and of the FMU's shared library).
    pub identifier: &'static str,
    /// One-line description (`description` attribute of the model description).
    pub description: &'static str,
    /// Documentation paragraphs (HTML) for the FMU's `documentation/index.html`.
    pub doc_html: &'static str,
    /// Every variable, in `modelDescription.xml` order.
    pub variables: &'static [Variable],
    /// Default parameter values (the start values of the parameters).
    pub default_settings: fn() -> Settings,
    /// Default input values (the start values of the inputs).
    pub default_inputs: fn() -> InputValues,
    /// The default experiment.
    pub experiment: Experiment,
    /// Model Exchange: number of event indicators (`numberOfEventIndicators`).
    pub event_indicators: usize,
    /// True when the engine has a state of its own (stateful models): a communication step
    /// advances it ([`Engine::step`]) and a serialised FMU state carries it ([`Engine::save`]).
    pub stateful: bool,
    /// True when a serialised FMU state carries the cached outputs (the values of the last
    /// evaluation, kept so that a restored instance reads them without evaluating again: the
    /// value of every output variable of the table, in table order); false when they are not
    /// serialised because they follow from the engine's state.
    pub cached_outputs: bool,
    /// True for an output variable that [`Engine::outputs_partial`] gives: when every
    /// computed variable a `fmi2Get…` call (or `fmi2GetDerivatives`) reads is one of these,
    /// the instance evaluates only those, and the whole of [`Engine::outputs`] when it reads
    /// any other. `fmi2GetDerivatives` asks for the partial outputs: a model whose engine's
    /// partial evaluation is partial names every derivative variable among them.
    pub partial_output: fn(&Variable) -> bool,
    /// True when `fmi2GetDirectionalDerivative` is provided (the engine's exact
    /// [`Engine::jacobian`]): the `providesDirectionalDerivative` attribute of both interfaces.
    pub provides_directional_derivative: bool,
    /// Builds the engine.
    pub build: BuildFn,
    /// Checks the values of the tunable parameters in the given settings against their ranges
    /// (the model's own checks, also before the engine exists); the error names the value
    /// and its limit.
    pub check_tunable: fn(&Settings) -> Result<(), String>,
    /// The GUID, computed on first use.
    pub guid_cell: &'static OnceLock<String>,
}

impl ModelInfo {
    /// The variable with value reference `vr`, if any.
    pub fn by_vr(&self, vr: u32) -> Option<&'static Variable> {
        // A linear scan over ~60 entries costs less than a hash; the table is small and fixed.
        self.variables.iter().find(|v| v.vr == vr)
    }

    /// The variable named `name`, if any.
    pub fn by_name(&self, name: &str) -> Option<&'static Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// Model Exchange: the derivative variables in state order (their order in the table).
    pub fn derivatives(&self) -> impl Iterator<Item = &'static Variable> + '_ {
        self.variables.iter().filter(|v| v.derivative_of.is_some())
    }

    /// Model Exchange: the continuous-state variable names, in state order.
    pub fn state_names(&self) -> Vec<&'static str> {
        self.derivatives().filter_map(|v| v.derivative_of).collect()
    }

    /// The name of Model Exchange state `i` (0-based), or `state <i+1>` if there is none: for
    /// messages, without collecting the names.
    pub fn state_name(&self, i: usize) -> String {
        self.derivatives()
            .filter_map(|v| v.derivative_of)
            .nth(i)
            .map_or_else(|| format!("state {}", i + 1), str::to_string)
    }

    /// The start value of `v` in this model.
    pub fn start(&self, v: &Variable) -> Option<String> {
        v.start_in(&(self.default_settings)(), &(self.default_inputs)())
    }

    /// Canonical text of everything a master relies on (model identifier, version,
    /// capabilities, units, log categories, default experiment, and every variable with type,
    /// causality, variability, unit, start value, range and dependencies); the GUID is its
    /// hash.
    pub fn canonical_description(&self) -> String {
        let mut s =
            format!("{} {MODEL_VERSION} fmi2 cs me\n{CS_CAPABILITIES:?}\n", self.identifier);
        s.push_str(&format!("{:?} events {}\n", self.experiment, self.event_indicators));
        s.push_str(&format!("directional {}\n", self.provides_directional_derivative));
        for u in UNITS {
            s.push_str(&format!("{u:?}\n"));
        }
        for (k, _) in LOG_CATEGORIES {
            s.push_str(&format!("log {k}\n"));
        }
        for v in self.variables {
            s.push_str(&format!(
                "{}|{}|{}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}\n",
                v.name,
                v.vr,
                v.var_type().as_str(),
                v.causality.as_str(),
                v.variability.as_str(),
                v.unit,
                self.start(v),
                v.min,
                v.max,
                v.depends.map(|d| (d.inputs, d.linear_fixed, d.groups)),
                v.group,
                v.derivative_of
            ));
        }
        s
    }

    /// The GUID of the model: `{…}` formed from the 128-bit FNV-1a hash of
    /// [`ModelInfo::canonical_description`] (with the RFC 9562 version-8 and variant bits
    /// set). It changes whenever a variable, a start value, a capability or the crate version
    /// changes, and differs between models.
    pub fn guid(&self) -> &'static str {
        self.guid_cell.get_or_init(|| guid_of(&self.canonical_description()))
    }
}

/// 128-bit FNV-1a hash.
fn fnv1a_128(bytes: &[u8]) -> u128 {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u128::from(b)).wrapping_mul(PRIME))
}

/// A GUID `{xxxxxxxx-xxxx-8xxx-xxxx-xxxxxxxxxxxx}` from the hash of `text`.
fn guid_of(text: &str) -> String {
    let mut h = fnv1a_128(text.as_bytes());
    h = (h & !(0xF_u128 << 76)) | (0x8_u128 << 76); // version 8 (custom)
    h = (h & !(0x3_u128 << 62)) | (0x2_u128 << 62); // RFC variant
    let x = format!("{h:032x}");
    format!("{{{}-{}-{}-{}-{}}}", &x[0..8], &x[8..12], &x[12..16], &x[16..20], &x[20..32])
}
