//! The stateful models through the exported FMI functions: instantiation by GUID, stepping
//! from the static equilibrium, bit-for-bit FMU state restore, a failed step's status; and
//! every model's evaluation of only the outputs a `fmi2GetReal` reads.

mod common;

use std::ffi::CString;
use std::ptr::{null, null_mut};

use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::unit::{DRIVE, PAIR, STAGE};
use helical_gear_mesh::fmi2::models::{gearbox, mesh};
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::fmi2::variables::{Access, Causality};
use helical_gear_mesh::mesh::outputs::MESH_OUTPUT_FIELDS;

use common::fmi::ModelFmu as Fmu;

impl Fmu {
    /// An initialised Co-Simulation instance of `m`.
    fn new(m: &'static ModelInfo) -> Self {
        let f = Fmu::instantiate(m, FMI2_CO_SIMULATION);
        f.init();
        f
    }

    fn run(&self, t: f64, n: usize, h: f64) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                let st = unsafe { fmi2DoStep(self.0, t + i as f64 * h, h, 1) };
                assert_eq!(st, fmi2Status::Ok);
                self.get(&["TE", "w_p", "phi_g", "M_F_p"])
            })
            .collect()
    }
}

#[test]
fn stateful_models_start_in_equilibrium_and_step() {
    for m in [&PAIR, &STAGE, &DRIVE] {
        let f = Fmu::new(m);
        let [te0, w0] = f.get(&["TE", "w_p"])[..] else { unreachable!() };
        assert!(te0 > 0.0 && (w0 - 300.0).abs() < 1e-9, "{}: {te0} {w0}", m.identifier);
        let out = f.run(0.0, 10, 1e-4);
        for o in &out {
            assert!(o.iter().all(|x| x.is_finite()), "{}", m.identifier);
            // Near the equilibrium start: TE within a few µm of the static one.
            assert!((o[0] - te0).abs() < 0.5 * te0, "{}: {} vs {te0}", m.identifier, o[0]);
        }
    }
}

#[test]
fn fmu_state_restores_bit_for_bit_in_memory_and_serialised() {
    let f = Fmu::new(&DRIVE);
    f.run(0.0, 5, 1e-4);
    unsafe {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        let mut n = 0;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, s, &mut n), fmi2Status::Ok);
        let mut bytes = vec![0 as fmi2Byte; n];
        assert_eq!(fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), n), fmi2Status::Ok);
        let first = f.run(5e-4, 5, 1e-4);
        assert_eq!(fmi2SetFMUstate(f.0, s), fmi2Status::Ok);
        assert_eq!(f.run(5e-4, 5, 1e-4), first);
        let g = Fmu::new(&DRIVE);
        let mut s2: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(g.0, bytes.as_ptr(), n, &mut s2), fmi2Status::Ok);
        assert_eq!(fmi2SetFMUstate(g.0, s2), fmi2Status::Ok);
        assert_eq!(g.run(5e-4, 5, 1e-4), first);
        // A state of one model is refused by another.
        let p = Fmu::new(&PAIR);
        let mut s3: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(p.0, bytes.as_ptr(), n, &mut s3), fmi2Status::Error);
        assert_eq!(fmi2FreeFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(g.0, &mut s2), fmi2Status::Ok);
    }
}

#[test]
fn bad_steps_are_errors_and_reset_recovers() {
    let f = Fmu::new(&DRIVE);
    unsafe {
        assert_eq!(fmi2DoStep(f.0, 0.0, -1e-4, 1), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
    }
    assert!(f.run(0.0, 2, 1e-4).iter().flatten().all(|x| x.is_finite()));
}

/// The Pair's hub coupling parameters: a negative stiffness is refused when the model is
/// built (fmi2ExitInitializationMode), the shafts' values are accepted, and a Pair stepped with
/// them from its equilibrium inputs stays near the static TE.
#[test]
fn pair_hub_coupling_is_validated_and_used() {
    let g = CString::new(PAIR.guid()).unwrap();
    let vr = |n: &str| PAIR.by_name(n).unwrap().vr;
    for (c_p, ok) in [(-1.0, false), (984.0, true)] {
        unsafe {
            let c = fmi2Instantiate(
                c"p".as_ptr(),
                FMI2_CO_SIMULATION,
                g.as_ptr(),
                null(),
                null(),
                0,
                0,
            );
            assert!(!c.is_null());
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
            assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::Ok);
            let r = [vr("hub_coupling.c_p_nm_per_rad"), vr("hub_coupling.d_p_nms_per_rad")];
            assert_eq!(fmi2SetReal(c, r.as_ptr(), 2, [c_p, 0.04].as_ptr()), fmi2Status::Ok);
            let st = fmi2ExitInitializationMode(c);
            if ok {
                assert_eq!(st, fmi2Status::Ok);
                let f = Fmu(c, &PAIR);
                let te0 = f.get(&["TE"])[0];
                for o in f.run(0.0, 10, 1e-4) {
                    assert!((o[0] - te0).abs() < 0.5 * te0, "{} vs {te0}", o[0]);
                }
            } else {
                assert_eq!(st, fmi2Status::Error);
                fmi2FreeInstance(c);
            }
        }
    }
}

/// A Stage whose far-end rate `w_1` has a derivative (first-order hold) saves and restores
/// that derivative with its state: a fresh instance restored from the serialised state steps
/// bit for bit as the original (a derivative lost on the way would differ from the unit's
/// held one and re-anchor the held inputs, changing the steps).
#[test]
fn fmu_state_with_input_derivatives_restores_bit_for_bit() {
    // Full fidelity: no table to build, a few steps of the full model.
    let full = || {
        let f = Fmu::instantiate(&STAGE, FMI2_CO_SIMULATION);
        let st = unsafe { fmi2SetInteger(f.0, f.vrs(&["fidelity"]).as_ptr(), 1, &0) };
        assert_eq!(st, fmi2Status::Ok);
        f.init();
        f
    };
    let f = full();
    let r = f.vrs(&["w_1"]);
    unsafe {
        let st = fmi2SetRealInputDerivatives(f.0, r.as_ptr(), 1, [1].as_ptr(), &50.0);
        assert_eq!(st, fmi2Status::Ok);
        f.run(0.0, 2, 1e-4);
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        let mut n = 0;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, s, &mut n), fmi2Status::Ok);
        let mut bytes = vec![0 as fmi2Byte; n];
        assert_eq!(fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), n), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(f.0, &mut s), fmi2Status::Ok);
        let first = f.run(2e-4, 3, 1e-4);
        let g = full();
        let mut s2: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(g.0, bytes.as_ptr(), n, &mut s2), fmi2Status::Ok);
        assert_eq!(fmi2SetFMUstate(g.0, s2), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(g.0, &mut s2), fmi2Status::Ok);
        assert_eq!(g.run(2e-4, 3, 1e-4), first);
    }
}

/// The FMU evaluates what a `fmi2GetReal` reads. Reading only outputs of the torques path (the
/// mesh torques, TE, the loaded contact length, the friction torques and loss, a unit's own
/// outputs) gives them bit for bit as a read of every output does; a later read of the other
/// outputs at the same state evaluates them, so they too are bit for bit those of an instance
/// that read everything at once. Every model at table fidelity (the mesh element at a loaded
/// state, the units after steps from their equilibrium). For the mesh element, whose FMU state
/// carries complete cached outputs, the serialised state shows which evaluation ran: after the
/// partial read it is as long as before any read (nothing complete to carry), after the read of
/// everything it carries the outputs; a state serialised after the partial read restores into
/// an instance that then reads every output bit for bit.
#[test]
fn a_read_of_torques_outputs_evaluates_only_those_and_a_later_read_completes() {
    let torques: Vec<&str> =
        MESH_OUTPUT_FIELDS.iter().filter(|f| f.torques).map(|f| f.name).collect();
    assert_eq!(torques.len(), 9, "{torques:?}");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    const LOADED: [f64; 4] = [0.01, -0.0060851, 100.0, -100.0 * 30.0 / 47.0];
    for m in [&mesh::INFO, &PAIR, &STAGE, &DRIVE] {
        let make = || {
            let f = Fmu::instantiate(m, FMI2_CO_SIMULATION);
            let st = unsafe { fmi2SetInteger(f.0, f.vrs(&["fidelity"]).as_ptr(), 1, &1) };
            assert_eq!(st, fmi2Status::Ok);
            f.init();
            if m.stateful {
                f.run(0.0, 3, 1e-4);
            } else {
                f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED);
            }
            f
        };
        let outputs: Vec<&str> = (m.variables.iter())
            .filter(|v| v.causality == Causality::Output)
            .filter(|v| matches!(v.access, Access::RealOutput(_)))
            .map(|v| v.name)
            .collect();
        let mut partial: Vec<&str> = torques.clone();
        partial.extend(outputs.iter().filter(|n| ["w_p", "a_g", "tau_2", "phi_1"].contains(n)));
        let (a, b) = (make(), make());
        let everything = b.get(&outputs);
        let before = a.serialize().len();
        let read = a.get(&partial);
        let after_partial = a.serialize();
        let expected: Vec<f64> = partial
            .iter()
            .map(|n| everything[outputs.iter().position(|o| o == n).unwrap()])
            .collect();
        assert_eq!(bits(&read), bits(&expected), "{}: the partial read", m.identifier);
        assert_eq!(bits(&a.get(&outputs)), bits(&everything), "{}: then all", m.identifier);
        // The complete read found outputs the partial one had not evaluated.
        assert!(
            outputs.iter().any(|n| !partial.contains(n)
                && everything[outputs.iter().position(|o| o == n).unwrap()] != 0.0),
            "{}",
            m.identifier
        );
        if m.cached_outputs {
            assert_eq!(after_partial.len(), before, "{}: nothing complete cached", m.identifier);
            assert!(a.serialize().len() > before, "{}: complete outputs cached", m.identifier);
            let c = make();
            assert_eq!(c.restore(&after_partial), fmi2Status::Ok, "{}", m.identifier);
            assert_eq!(bits(&c.get(&outputs)), bits(&everything), "{}: restored", m.identifier);
        }
    }
}

/// Which outputs a partial evaluation gives, per model: for the mesh element and the units
/// the torques path's mesh outputs and the units' own outputs, every state derivative among
/// them (`fmi2GetDerivatives` reads the partial outputs); none for the gearbox, whose engine
/// evaluates everything.
#[test]
fn partial_outputs_are_the_torques_path_and_include_every_derivative() {
    for m in [&mesh::INFO, &PAIR, &STAGE, &DRIVE, &gearbox::GEARBOX] {
        for v in m.variables {
            let partial = (m.partial_output)(v);
            let computed = matches!(
                v.access,
                Access::RealOutput(_) | Access::IntOutput(_) | Access::BoolOutput(_)
            );
            if !computed || std::ptr::eq(m, &gearbox::GEARBOX) {
                assert!(!partial, "{}: {}", m.identifier, v.name);
                continue;
            }
            let field = MESH_OUTPUT_FIELDS.iter().find(|f| f.name == v.name);
            assert_eq!(partial, field.is_none_or(|f| f.torques), "{}: {}", m.identifier, v.name);
            if v.derivative_of.is_some() {
                assert!(partial, "{}: derivative {}", m.identifier, v.name);
            }
        }
    }
}
