//! `modelDescription.xml` from the variable table (quick-xml + serde).
//!
//! One description for both interfaces (`<ModelExchange>` and `<CoSimulation>`, one binary).
//!
//! ModelStructure: `Outputs` lists every output with the knowns it depends on — inputs and,
//! for the stateful models, the continuous states of Model Exchange (`dependenciesKind="fixed"`
//! where the output is linear in them with coefficients set by fixed parameters, as TE,
//! `"dependent"` otherwise); `Derivatives` lists the state derivatives the same way (a
//! position's derivative is its rate state, "fixed"); `InitialUnknowns` lists the outputs, the
//! calculated parameters and the states and derivatives computed at initialisation with the
//! inputs and the parameters (by group) they depend on, without `dependenciesKind` (all
//! "dependent").

use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::variables::{
    CS_CAPABILITIES, Causality, LOG_CATEGORIES, MODEL_VERSION, UNITS, VarType, Variable,
    format_real,
};
use serde::Serialize;

/// The FMI 2.0 `author` of every model description.
pub const AUTHOR: &str = "The helical-gear-mesh authors";
/// The FMI 2.0 `copyright` of every model description.
pub const COPYRIGHT: &str = "Copyright (c) 2026 The helical-gear-mesh authors";
/// The FMI 2.0 `license` of every model description: the crate's licence (the files
/// `LICENSE-MIT` and `LICENSE-APACHE` of the repository).
pub const LICENSE: &str = "MIT OR Apache-2.0";

#[derive(Serialize)]
#[serde(rename = "fmiModelDescription")]
struct Fmd {
    #[serde(rename = "@fmiVersion")]
    fmi_version: &'static str,
    #[serde(rename = "@modelName")]
    model_name: &'static str,
    #[serde(rename = "@guid")]
    guid: &'static str,
    #[serde(rename = "@description")]
    description: &'static str,
    #[serde(rename = "@author")]
    author: &'static str,
    #[serde(rename = "@version")]
    version: &'static str,
    #[serde(rename = "@copyright")]
    copyright: &'static str,
    #[serde(rename = "@license")]
    license: &'static str,
    #[serde(rename = "@generationTool")]
    generation_tool: String,
    #[serde(rename = "@variableNamingConvention")]
    naming: &'static str,
    #[serde(rename = "@numberOfEventIndicators")]
    event_indicators: u32,
    #[serde(rename = "ModelExchange")]
    model_exchange: ModelExchange,
    #[serde(rename = "CoSimulation")]
    co_simulation: CoSimulation,
    #[serde(rename = "UnitDefinitions")]
    unit_definitions: UnitDefinitions,
    #[serde(rename = "LogCategories")]
    log_categories: LogCategories,
    #[serde(rename = "DefaultExperiment")]
    default_experiment: DefaultExperiment,
    #[serde(rename = "ModelVariables")]
    model_variables: ModelVariables,
    #[serde(rename = "ModelStructure")]
    model_structure: ModelStructure,
}

#[derive(Serialize)]
struct ModelExchange {
    #[serde(rename = "@modelIdentifier")]
    model_identifier: &'static str,
    #[serde(rename = "@needsExecutionTool")]
    needs_execution_tool: bool,
    #[serde(rename = "@completedIntegratorStepNotNeeded")]
    completed_integrator_step_not_needed: bool,
    #[serde(rename = "@canBeInstantiatedOnlyOncePerProcess")]
    can_be_instantiated_only_once_per_process: bool,
    #[serde(rename = "@canNotUseMemoryManagementFunctions")]
    can_not_use_memory_management_functions: bool,
    #[serde(rename = "@canGetAndSetFMUstate")]
    can_get_and_set_fmu_state: bool,
    #[serde(rename = "@canSerializeFMUstate")]
    can_serialize_fmu_state: bool,
    #[serde(rename = "@providesDirectionalDerivative")]
    provides_directional_derivative: bool,
}

#[derive(Serialize)]
struct CoSimulation {
    #[serde(rename = "@modelIdentifier")]
    model_identifier: &'static str,
    #[serde(rename = "@needsExecutionTool")]
    needs_execution_tool: bool,
    #[serde(rename = "@canHandleVariableCommunicationStepSize")]
    can_handle_variable_communication_step_size: bool,
    #[serde(rename = "@canInterpolateInputs")]
    can_interpolate_inputs: bool,
    #[serde(rename = "@maxOutputDerivativeOrder")]
    max_output_derivative_order: u32,
    #[serde(rename = "@canRunAsynchronuously")]
    can_run_asynchronuously: bool,
    #[serde(rename = "@canBeInstantiatedOnlyOncePerProcess")]
    can_be_instantiated_only_once_per_process: bool,
    #[serde(rename = "@canNotUseMemoryManagementFunctions")]
    can_not_use_memory_management_functions: bool,
    #[serde(rename = "@canGetAndSetFMUstate")]
    can_get_and_set_fmu_state: bool,
    #[serde(rename = "@canSerializeFMUstate")]
    can_serialize_fmu_state: bool,
    #[serde(rename = "@providesDirectionalDerivative")]
    provides_directional_derivative: bool,
}

#[derive(Serialize)]
struct UnitDefinitions {
    #[serde(rename = "Unit")]
    units: Vec<Unit>,
}

#[derive(Serialize)]
struct Unit {
    #[serde(rename = "@name")]
    name: &'static str,
    #[serde(rename = "BaseUnit")]
    base: BaseUnit,
    #[serde(rename = "DisplayUnit")]
    display: Vec<DisplayUnit>,
}

#[derive(Serialize, Default)]
struct BaseUnit {
    #[serde(rename = "@kg", skip_serializing_if = "Option::is_none")]
    kg: Option<i32>,
    #[serde(rename = "@m", skip_serializing_if = "Option::is_none")]
    m: Option<i32>,
    #[serde(rename = "@s", skip_serializing_if = "Option::is_none")]
    s: Option<i32>,
    #[serde(rename = "@rad", skip_serializing_if = "Option::is_none")]
    rad: Option<i32>,
}

#[derive(Serialize)]
struct DisplayUnit {
    #[serde(rename = "@name")]
    name: &'static str,
    #[serde(rename = "@factor")]
    factor: String,
}

#[derive(Serialize)]
struct LogCategories {
    #[serde(rename = "Category")]
    categories: Vec<Category>,
}

#[derive(Serialize)]
struct Category {
    #[serde(rename = "@name")]
    name: &'static str,
    #[serde(rename = "@description")]
    description: &'static str,
}

#[derive(Serialize)]
struct DefaultExperiment {
    #[serde(rename = "@startTime")]
    start_time: String,
    #[serde(rename = "@stopTime")]
    stop_time: String,
    #[serde(rename = "@stepSize")]
    step_size: String,
}

#[derive(Serialize)]
struct ModelVariables {
    #[serde(rename = "ScalarVariable")]
    variables: Vec<ScalarVariable>,
}

#[derive(Serialize)]
struct ScalarVariable {
    #[serde(rename = "@name")]
    name: &'static str,
    #[serde(rename = "@valueReference")]
    value_reference: u32,
    #[serde(rename = "@description")]
    description: &'static str,
    #[serde(rename = "@causality")]
    causality: &'static str,
    #[serde(rename = "@variability")]
    variability: &'static str,
    #[serde(rename = "@initial", skip_serializing_if = "Option::is_none")]
    initial: Option<&'static str>,
    #[serde(rename = "$value")]
    ty: TypeElement,
}

#[derive(Serialize)]
enum TypeElement {
    Real(RealAttrs),
    Integer(IntegerAttrs),
    Boolean(BooleanAttrs),
    String(BooleanAttrs),
}

#[derive(Serialize)]
struct RealAttrs {
    #[serde(rename = "@quantity", skip_serializing_if = "Option::is_none")]
    quantity: Option<&'static str>,
    #[serde(rename = "@unit", skip_serializing_if = "Option::is_none")]
    unit: Option<&'static str>,
    #[serde(rename = "@displayUnit", skip_serializing_if = "Option::is_none")]
    display_unit: Option<&'static str>,
    #[serde(rename = "@min", skip_serializing_if = "Option::is_none")]
    min: Option<String>,
    #[serde(rename = "@max", skip_serializing_if = "Option::is_none")]
    max: Option<String>,
    #[serde(rename = "@start", skip_serializing_if = "Option::is_none")]
    start: Option<String>,
    #[serde(rename = "@derivative", skip_serializing_if = "Option::is_none")]
    derivative: Option<usize>,
}

#[derive(Serialize)]
struct IntegerAttrs {
    #[serde(rename = "@min", skip_serializing_if = "Option::is_none")]
    min: Option<i32>,
    #[serde(rename = "@max", skip_serializing_if = "Option::is_none")]
    max: Option<i32>,
    #[serde(rename = "@start", skip_serializing_if = "Option::is_none")]
    start: Option<String>,
}

#[derive(Serialize)]
struct BooleanAttrs {
    #[serde(rename = "@start", skip_serializing_if = "Option::is_none")]
    start: Option<String>,
}

#[derive(Serialize)]
struct ModelStructure {
    #[serde(rename = "Outputs")]
    outputs: Unknowns,
    #[serde(rename = "Derivatives", skip_serializing_if = "Option::is_none")]
    derivatives: Option<Unknowns>,
    #[serde(rename = "InitialUnknowns")]
    initial_unknowns: Unknowns,
}

#[derive(Serialize)]
struct Unknowns {
    #[serde(rename = "Unknown")]
    unknowns: Vec<Unknown>,
}

#[derive(Serialize)]
struct Unknown {
    #[serde(rename = "@index")]
    index: usize,
    #[serde(rename = "@dependencies")]
    dependencies: String,
    #[serde(rename = "@dependenciesKind", skip_serializing_if = "Option::is_none")]
    dependencies_kind: Option<String>,
}

/// 1-based ScalarVariable index of `name` in `model`.
fn index_of(model: &ModelInfo, name: &str) -> usize {
    model
        .variables
        .iter()
        .position(|w| w.name == name)
        .unwrap_or_else(|| panic!("dependency `{name}` is not a variable of {}", model.identifier))
        + 1
}

fn join<T: ToString>(items: impl IntoIterator<Item = T>) -> String {
    items.into_iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
}

/// True when `name` is a known of Model Exchange or Co-Simulation in `model`: an input or a
/// continuous state.
fn is_known(model: &ModelInfo, name: &str) -> bool {
    model.by_name(name).is_some_and(|v| v.causality == Causality::Input)
        || model.state_names().contains(&name)
}

/// `Outputs` and `Derivatives` entry: the inputs and continuous states the unknown depends
/// on (`dependenciesKind="fixed"` when it is linear in them with coefficients set by fixed
/// parameters, `"dependent"` otherwise).
fn outputs_entry(model: &ModelInfo, i: usize, v: &Variable) -> Unknown {
    let d = v.depends.expect("outputs and derivatives declare their dependencies");
    let mut idx: Vec<usize> =
        d.inputs.iter().filter(|n| is_known(model, n)).map(|n| index_of(model, n)).collect();
    idx.sort_unstable();
    idx.dedup();
    let kind = if d.linear_fixed { "fixed" } else { "dependent" };
    Unknown {
        index: i + 1,
        dependencies_kind: (!idx.is_empty()).then(|| join(idx.iter().map(|_| kind))),
        dependencies: join(&idx),
    }
}

/// `InitialUnknowns` entry: the inputs and the parameters (by group) it depends on at
/// initialisation (the states are unknowns there, not knowns).
fn initial_entry(model: &ModelInfo, i: usize, v: &Variable) -> Unknown {
    let d = v.depends.expect("initial unknowns declare their dependencies");
    let mut idx: Vec<usize> = d
        .inputs
        .iter()
        .filter(|n| model.by_name(n).is_some_and(|w| w.causality == Causality::Input))
        .map(|n| index_of(model, n))
        .collect();
    idx.extend(
        model
            .variables
            .iter()
            .enumerate()
            .filter(|(_, p)| p.causality == Causality::Parameter && p.group & d.groups != 0)
            .map(|(j, _)| j + 1),
    );
    idx.sort_unstable();
    idx.dedup();
    Unknown {
        index: i + 1,
        // All "dependent": the attribute is left out, which means exactly that.
        dependencies_kind: None,
        dependencies: join(&idx),
    }
}

/// The complete `modelDescription.xml` text of `model`.
pub fn model_description_xml(model: &ModelInfo) -> String {
    let c = CS_CAPABILITIES;
    let units = UNITS
        .iter()
        .map(|u| {
            let mut base = BaseUnit::default();
            for &(name, e) in u.base {
                match name {
                    "kg" => base.kg = Some(e),
                    "m" => base.m = Some(e),
                    "s" => base.s = Some(e),
                    "rad" => base.rad = Some(e),
                    other => panic!("base unit {other} not handled"),
                }
            }
            Unit {
                name: u.name,
                base,
                display: u
                    .display
                    .iter()
                    .map(|&(name, f)| DisplayUnit { name, factor: format_real(f) })
                    .collect(),
            }
        })
        .collect();
    let variables = model
        .variables
        .iter()
        .map(|v| ScalarVariable {
            name: v.name,
            value_reference: v.vr,
            description: v.description,
            causality: v.causality.as_str(),
            variability: v.variability.as_str(),
            initial: v.initial(),
            ty: match v.var_type() {
                VarType::Real => TypeElement::Real(RealAttrs {
                    quantity: v.quantity,
                    unit: v.unit,
                    display_unit: v.display_unit,
                    min: v.min.map(format_real),
                    max: v.max.map(format_real),
                    start: model.start(v),
                    derivative: v.derivative_of.map(|n| index_of(model, n)),
                }),
                VarType::Integer => TypeElement::Integer(IntegerAttrs {
                    min: v.min.map(|x| x as i32),
                    max: v.max.map(|x| x as i32),
                    start: model.start(v),
                }),
                VarType::Boolean => TypeElement::Boolean(BooleanAttrs { start: model.start(v) }),
                VarType::String => TypeElement::String(BooleanAttrs { start: model.start(v) }),
            },
        })
        .collect();
    let outputs = model
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, v)| outputs_entry(model, i, v))
        .collect();
    let states = model.state_names();
    let derivatives: Vec<Unknown> = model
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.derivative_of.is_some())
        .map(|(i, v)| outputs_entry(model, i, v))
        .collect();
    // Outputs and calculated parameters, and the states and derivatives computed at
    // initialisation (the locals among them; the state outputs are outputs already).
    let initial_unknowns = model
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| {
            matches!(v.causality, Causality::Output | Causality::CalculatedParameter)
                || v.derivative_of.is_some()
                || states.contains(&v.name)
        })
        .map(|(i, v)| initial_entry(model, i, v))
        .collect();
    let fmd = Fmd {
        fmi_version: "2.0",
        model_name: model.identifier,
        guid: model.guid(),
        description: model.description,
        author: AUTHOR,
        version: MODEL_VERSION,
        copyright: COPYRIGHT,
        license: LICENSE,
        generation_tool: format!("fmu-build {}", env!("CARGO_PKG_VERSION")),
        naming: "structured",
        event_indicators: model.event_indicators as u32,
        model_exchange: ModelExchange {
            model_identifier: model.identifier,
            needs_execution_tool: c.needs_execution_tool,
            completed_integrator_step_not_needed: c.completed_integrator_step_not_needed,
            can_be_instantiated_only_once_per_process: c.can_be_instantiated_only_once_per_process,
            can_not_use_memory_management_functions: c.can_not_use_memory_management_functions,
            can_get_and_set_fmu_state: c.can_get_and_set_fmu_state,
            can_serialize_fmu_state: c.can_serialize_fmu_state,
            provides_directional_derivative: c.provides_directional_derivative
                && model.provides_directional_derivative,
        },
        co_simulation: CoSimulation {
            model_identifier: model.identifier,
            needs_execution_tool: c.needs_execution_tool,
            can_handle_variable_communication_step_size: c
                .can_handle_variable_communication_step_size,
            can_interpolate_inputs: c.can_interpolate_inputs,
            max_output_derivative_order: c.max_output_derivative_order,
            can_run_asynchronuously: c.can_run_asynchronuously,
            can_be_instantiated_only_once_per_process: c.can_be_instantiated_only_once_per_process,
            can_not_use_memory_management_functions: c.can_not_use_memory_management_functions,
            can_get_and_set_fmu_state: c.can_get_and_set_fmu_state,
            can_serialize_fmu_state: c.can_serialize_fmu_state,
            provides_directional_derivative: c.provides_directional_derivative
                && model.provides_directional_derivative,
        },
        unit_definitions: UnitDefinitions { units },
        log_categories: LogCategories {
            categories: LOG_CATEGORIES
                .iter()
                .map(|&(name, description)| Category { name, description })
                .collect(),
        },
        default_experiment: DefaultExperiment {
            start_time: format_real(model.experiment.start),
            stop_time: format_real(model.experiment.stop),
            step_size: format_real(model.experiment.step),
        },
        model_variables: ModelVariables { variables },
        model_structure: ModelStructure {
            outputs: Unknowns { unknowns: outputs },
            derivatives: (!derivatives.is_empty()).then_some(Unknowns { unknowns: derivatives }),
            initial_unknowns: Unknowns { unknowns: initial_unknowns },
        },
    };
    let mut body = String::new();
    let mut ser = quick_xml::se::Serializer::new(&mut body);
    ser.indent(' ', 2);
    fmd.serialize(ser).expect("the model description serialises");
    format!("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{body}\n")
}
