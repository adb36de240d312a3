//! The `min`/`max` of every numeric parameter in the checked-in `modelDescription.xml` of
//! every model are exactly what the library accepts, through the FMI API: a fresh
//! instance, `fmi2SetReal`/`fmi2SetInteger` of the value, `fmi2EnterInitializationMode`,
//! `fmi2ExitInitializationMode`. The bound itself is accepted; one step past it (the next
//! `f64`, or ±1 for integers) is refused with a message that names the parameter and the value.
//!
//! Acceptance of a bound of a parameter that changes the compliance data (geometry, materials)
//! or the size of the slice influence (`slices`) would need an FE run or a large model, one of
//! `fidelity` a table build, and any bound of a stateful model a static start (seconds each); there the
//! instance is given one invalid option besides (`slices` = 9, for `slices` itself
//! `table_te_points` = 7), checked only after the pair's parameter and geometric validation:
//! the refusal then names that option, so the bound passed every check of the pair.
//!
//! [`COMBINED`] lists the bounds that cannot pass initialisation with the other parameters at
//! their start values, and why; their refusal must then name the stated reason, not the
//! parameter's own range.

use std::cell::RefCell;
use std::ffi::{CStr, CString};
use std::ptr::null;

use helical_gear_mesh::error::short_num;
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::MODELS;
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::fmi2::variables::{VarType, Variable, group};

/// Bounds that fail initialisation with the other parameters at their start values for a
/// reason between parameters: (model or `*`, parameter, `true` for max / `false` for min, text
/// the refusal must contain).
const COMBINED: &[(&str, &str, bool, &str)] = &[
    // z = 5 undercuts with the Table 1 rack and zero shift.
    ("*", "z_p", false, "undercut"),
    ("*", "z_g", false, "undercut"),
    // H = 0 with the Table 1 relief δ = 0.015·m_n: a relief needs a zone of positive height.
    ("*", "tip_relief_height_mn", false, "when there is relief"),
    // H = 4.5 (the largest addendum + dedendum) above the Table 1 tooth of 2.25·m_n.
    ("*", "tip_relief_height_mn", true, "addendum_mn + dedendum_mn"),
    // The dedendum must exceed the addendum (tip clearance): 0.3 < 1.0 (Table 1 addendum).
    ("*", "dedendum_mn", false, "tip clearance"),
    // An addendum of 2·m_n with the Table 1 dedendum of 1.25·m_n leaves no tip clearance.
    ("*", "addendum_mn", true, "tip clearance"),
    // A 10 µm module makes the Table 1 face width of 15 mm 1500·m_n (at most 40·m_n), and a
    // 100 m bore does not fit in the Table 1 gears.
    ("*", "normal_module_m", false, "40·normal_module_m"),
    ("*", "bore_diameter_m", true, "rim of at least one module"),
    // α_n = 10° undercuts 30 teeth; α_n = 35° leaves no room for the Table 1 root fillet.
    ("*", "pressure_angle_rad", false, "undercut"),
    ("*", "pressure_angle_rad", true, "root fillets of one tooth space do not overlap"),
    ("*", "rack_fillet_radius_mn", true, "root fillets of one tooth space do not overlap"),
    // Shifts of ±1.5 with the other gear unshifted: undercut or tip interference.
    ("*", "profile_shift_p", false, "undercut"),
    ("*", "profile_shift_p", true, "tip interference"),
    ("*", "profile_shift_g", false, "tip interference"),
    ("*", "profile_shift_g", true, "tip interference"),
    // An addendum of 0.3·m_n gives a total contact ratio below 1 at b = 15 mm.
    ("*", "addendum_mn", false, "contact ratio"),
    // A dedendum of 2.5·m_n undercuts 30 teeth.
    ("*", "dedendum_mn", true, "undercut"),
    // One axis of 4096 points with the other at its start value exceeds the node limit.
    ("*", "table_phase_points", true, "table_phase_points × table_te_points"),
    ("*", "table_te_points", true, "table_phase_points × table_te_points"),
    // b = 10 m is 3333·m_n of the Table 1 module: beyond the widest gears (b <= 40·m_n).
    ("*", "face_width_m", true, "40·normal_module_m"),
];

thread_local! {
    static LOG: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// Logger: records the message (a printf format with `%` escaped as `%%`). The FMU passes no
/// variadic arguments, so the fixed five are all there is to read.
unsafe extern "C" fn logger(
    _env: fmi2ComponentEnvironment,
    _name: fmi2String,
    _status: fmi2Status,
    _category: fmi2String,
    message: fmi2String,
) {
    let m = unsafe { CStr::from_ptr(message) }.to_string_lossy().replace("%%", "%");
    LOG.with(|l| l.borrow_mut().push(m));
}

/// Value of an attribute `key="…"` in `text`.
fn attr<'a>(text: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!(" {key}=\"");
    let i = text.find(&pat)? + pat.len();
    Some(&text[i..i + text[i..].find('"')?])
}

/// The numeric parameters of the model's checked-in `modelDescription.xml`: name, type
/// element, min, max (as written).
fn xml_parameters(m: &ModelInfo) -> Vec<(String, String, Option<String>, Option<String>)> {
    let path = format!(
        "{}/modelDescription/{}/modelDescription.xml",
        env!("CARGO_MANIFEST_DIR"),
        m.identifier
    );
    let xml = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut out = Vec::new();
    for chunk in xml.split("<ScalarVariable").skip(1) {
        let chunk = &chunk[..chunk.find("</ScalarVariable>").unwrap()];
        if attr(chunk, "causality") != Some("parameter") {
            continue;
        }
        let ty = chunk.split('<').nth(1).unwrap().split([' ', '/', '>']).next().unwrap();
        if ty != "Real" && ty != "Integer" {
            continue;
        }
        let elem = &chunk[chunk.find(&format!("<{ty}")).unwrap()..];
        out.push((
            attr(chunk, "name").unwrap().to_string(),
            ty.to_string(),
            attr(elem, "min").map(str::to_string),
            attr(elem, "max").map(str::to_string),
        ));
    }
    out
}

/// Outcome of one initialisation: `Ok` or the logged messages of the refusal.
fn initialise(m: &ModelInfo, sets: &[(&Variable, f64)]) -> Result<(), String> {
    LOG.with(|l| l.borrow_mut().clear());
    let functions = fmi2CallbackFunctions {
        // SAFETY: the FMU calls the logger with exactly the five fixed arguments.
        logger: Some(unsafe {
            std::mem::transmute::<
                unsafe extern "C" fn(
                    fmi2ComponentEnvironment,
                    fmi2String,
                    fmi2Status,
                    fmi2String,
                    fmi2String,
                ),
                fmi2CallbackLogger,
            >(logger)
        }),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let guid = CString::new(m.guid()).unwrap();
    let c = unsafe {
        fmi2Instantiate(c"b".as_ptr(), FMI2_CO_SIMULATION, guid.as_ptr(), null(), &functions, 0, 0)
    };
    assert!(!c.is_null(), "{}", m.identifier);
    let mut ok = true;
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
        for (v, x) in sets {
            let st = match v.var_type() {
                VarType::Real => fmi2SetReal(c, &v.vr, 1, x),
                VarType::Integer => fmi2SetInteger(c, &v.vr, 1, &(*x as i32)),
                _ => unreachable!(),
            };
            ok &= st == fmi2Status::Ok;
        }
        if ok {
            ok &= fmi2EnterInitializationMode(c) == fmi2Status::Ok;
        }
        if ok {
            ok &= fmi2ExitInitializationMode(c) == fmi2Status::Ok;
        }
        fmi2FreeInstance(c);
    }
    if ok { Ok(()) } else { Err(LOG.with(|l| l.borrow().join("\n"))) }
}

/// The invalid option that is checked after the pair's validation, for a bound whose full
/// initialisation would need an FE run, a large model, a table build or a static start (the
/// stateful models; their options are checked before the mesh is built) — see the module docs.
fn accomplice(m: &ModelInfo, v: &Variable) -> Option<&'static str> {
    if v.name == "slices" {
        Some("table_te_points")
    } else if m.stateful
        || v.name == "fidelity"
        || v.group & (group::GEOMETRY | group::ELASTIC | group::DENSITY) != 0
    {
        Some("slices")
    } else {
        None
    }
}

/// The next `f64` above a finite `x`.
fn next_up(x: f64) -> f64 {
    if x == 0.0 {
        f64::from_bits(1)
    } else if x > 0.0 {
        f64::from_bits(x.to_bits() + 1)
    } else {
        f64::from_bits(x.to_bits() - 1)
    }
}

fn combined(model: &str, name: &str, is_max: bool) -> Option<&'static str> {
    COMBINED
        .iter()
        .find(|(m, n, mx, _)| (*m == "*" || *m == model) && *n == name && *mx == is_max)
        .map(|c| c.3)
}

#[test]
fn xml_bounds_are_exactly_what_the_library_accepts() {
    let mut checked = 0;
    let mut failures = Vec::new();
    for m in MODELS {
        let params = xml_parameters(m);
        assert!(!params.is_empty(), "{}", m.identifier);
        for (name, ty, min, max) in params {
            let v = m.by_name(&name).unwrap();
            let (Some(min), Some(max)) = (min, max) else {
                panic!("{}: parameter `{name}` has no min/max in the XML", m.identifier);
            };
            let lo: f64 = min.parse().unwrap();
            let hi: f64 = max.parse().unwrap();
            assert_eq!(Some(lo), v.min, "{}: {name}", m.identifier);
            assert_eq!(Some(hi), v.max, "{}: {name}", m.identifier);
            let int = ty == "Integer";
            for (bound, is_max) in [(lo, false), (hi, true)] {
                let past = match (int, is_max) {
                    (true, false) => bound - 1.0,
                    (true, true) => bound + 1.0,
                    (false, false) => -next_up(-bound),
                    (false, true) => next_up(bound),
                };
                let what = format!(
                    "{}: {name} = {bound} ({})",
                    m.identifier,
                    ["min", "max"][is_max as usize]
                );
                // One step past the bound: refused, the message names the parameter (or its
                // JSON key) and the value.
                let key = v.json_key();
                match initialise(m, &[(v, past)]) {
                    Ok(()) => failures.push(format!("{what}: {past:e} past it is accepted")),
                    Err(err) => {
                        if !((err.contains(&format!("`{name}`"))
                            || err.contains(&format!("`{key}`")))
                            && err.contains(&short_num(past)))
                        {
                            failures.push(format!(
                                "{what}: refusal of {past:e} does not name it: {err}"
                            ));
                        }
                    }
                }
                // The bound itself.
                if let Some(reason) = combined(m.identifier, &name, is_max) {
                    match initialise(m, &[(v, bound)]) {
                        Err(err) if err.contains(reason) => {}
                        r => failures.push(format!("{what}: expected `{reason}`: {r:?}")),
                    }
                } else if let Some(other) = accomplice(m, v) {
                    let o = m.by_name(other).unwrap();
                    let bad = if other == "slices" { 9.0 } else { 7.0 };
                    match initialise(m, &[(v, bound), (o, bad)]) {
                        Err(err)
                            if err.contains(&format!("`{other}`"))
                                && !err.contains(&format!("`{key}`")) => {}
                        r => failures.push(format!("{what}: the bound is refused: {r:?}")),
                    }
                } else if let Err(e) = initialise(m, &[(v, bound)]) {
                    failures.push(format!("{what}: {e}"));
                }
                checked += 1;
            }
        }
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
    assert!(checked > 200, "{checked}");
}

/// The type element's attribute scan sees the parameters of every model.
#[test]
fn every_numeric_parameter_of_the_tables_is_in_the_xml() {
    for m in MODELS {
        let xml: Vec<String> = xml_parameters(m).into_iter().map(|p| p.0).collect();
        for v in m.variables.iter().filter(|v| {
            v.causality == helical_gear_mesh::fmi2::variables::Causality::Parameter
                && matches!(v.var_type(), VarType::Real | VarType::Integer)
        }) {
            assert!(xml.iter().any(|n| n == v.name), "{}: {}", m.identifier, v.name);
        }
    }
}
