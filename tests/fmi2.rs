//! The exported FMI 2.0 functions called directly (no logger): state machine, error paths,
//! direct feedthrough, tunable and fixed parameters, FMU states, step checks, several
//! instances on several threads. Log messages are checked by the Python and C suites, whose
//! loggers are real C variadic functions.

mod common;

use std::ffi::{CString, c_char};
use std::ptr::{null, null_mut};

use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::models::mesh::{VARIABLES, guid};
use helical_gear_mesh::fmi2::types::*;

use common::fmi::{Fmu, vr};

const OUTS: [&str; 5] = ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"];
/// A loaded state of the Table 1 pair: TE = +20 µm (docs/conventions.md, worked example), rolling.
const LOADED: [f64; 4] = [0.01, -0.0060851, 100.0, -100.0 * 30.0 / 47.0];

fn set_loaded(f: &Fmu) {
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
}

#[test]
fn inquiry_functions_and_null_instance() {
    let s = |p: *const c_char| unsafe { std::ffi::CStr::from_ptr(p) }.to_str().unwrap();
    assert_eq!(s(fmi2GetVersion()), "2.0");
    assert_eq!(s(fmi2GetTypesPlatform()), "default");
    unsafe {
        fmi2FreeInstance(null_mut());
        assert_eq!(fmi2Reset(null_mut()), fmi2Status::Error);
        assert_eq!(fmi2DoStep(null_mut(), 0.0, 1.0, FMI2_TRUE), fmi2Status::Error);
    }
    assert_eq!(EXPORTED_FUNCTIONS.len(), 44);
}

#[test]
fn instantiate_rejects_wrong_guid_type_and_name() {
    let name = CString::new("x").unwrap();
    let good = CString::new(guid()).unwrap();
    unsafe {
        let bad = c"{00000000-0000-0000-0000-000000000000}";
        let f = |n: *const c_char, t, g: *const c_char| {
            fmi2Instantiate(n, t, g, null(), null(), FMI2_FALSE, FMI2_FALSE)
        };
        assert!(f(name.as_ptr(), FMI2_CO_SIMULATION, bad.as_ptr()).is_null());
        assert!(f(name.as_ptr(), 2, good.as_ptr()).is_null(), "fmuType 2 is neither ME nor CS");
        let me = f(name.as_ptr(), FMI2_MODEL_EXCHANGE, good.as_ptr());
        assert!(!me.is_null(), "Model Exchange is offered");
        fmi2FreeInstance(me);
        assert!(f(null(), FMI2_CO_SIMULATION, good.as_ptr()).is_null());
        assert!(f(name.as_ptr(), FMI2_CO_SIMULATION, null()).is_null());
        let c = f(name.as_ptr(), FMI2_CO_SIMULATION, good.as_ptr());
        assert!(!c.is_null(), "no resource location is fine");
        fmi2FreeInstance(c);
    }
}

#[test]
fn illegal_calls_are_errors_and_reset_recovers() {
    let f = Fmu::new();
    unsafe {
        // Not yet initialised: no step, no output.
        assert_eq!(fmi2DoStep(f.0, 0.0, 1e-3, FMI2_TRUE), fmi2Status::Error);
        // The instance is now in the error state: even a legal call in `instantiated` fails.
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Error);
        f.reset();
        assert_eq!(f.get(&["M_F_p"]), Err(fmi2Status::Error), "no outputs before initialisation");
        f.reset();
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Error);
        f.reset();
        f.init();
        assert_eq!(fmi2SetupExperiment(f.0, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Error);
        f.reset();
        f.init();
        assert_eq!(fmi2CancelStep(f.0), fmi2Status::Error);
        f.reset();
        f.init();
        for name in ["M_F_p", "J_p"] {
            assert_eq!(f.set(&[name], &[1.0]), fmi2Status::Error, "{name} is not settable");
            f.reset();
            f.init();
        }
        assert_eq!(fmi2Terminate(f.0), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(f.0, 0.0, 1e-3, FMI2_TRUE), fmi2Status::Error);
        f.reset();
    }
    // Usable again with the start values.
    f.init();
    set_loaded(&f);
    let a = f.get(&OUTS).unwrap();
    let fresh = Fmu::initialised();
    set_loaded(&fresh);
    assert_eq!(a, fresh.get(&OUTS).unwrap());
}

#[test]
fn non_finite_input_is_an_error_and_reset_restores_start_values() {
    let f = Fmu::initialised();
    set_loaded(&f);
    assert!(f.get(&["M_F_p"]).unwrap()[0] > 0.0, "positive torque in normal drive");
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(f.set(&["w_g"], &[bad]), fmi2Status::Error);
        f.reset();
        f.init();
    }
    // Start values: all inputs 0, no load at TE = 0.
    assert_eq!(f.get(&["phi_p", "phi_g", "w_p", "w_g"]).unwrap(), vec![0.0; 4]);
    assert_eq!(f.get(&["M_F_p", "TE"]).unwrap(), vec![0.0, 0.0]);
}

#[test]
fn invalid_parameter_fails_exit_initialization_and_reset_recovers() {
    let f = Fmu::new();
    let r = [vr("z_p")];
    unsafe {
        assert_eq!(fmi2SetInteger(f.0, r.as_ptr(), 1, [12].as_ptr()), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Error);
        f.reset();
        // A value that cannot be represented is refused at once.
        assert_eq!(fmi2SetInteger(f.0, r.as_ptr(), 1, [-3].as_ptr()), fmi2Status::Error);
        f.reset();
        let mut z = 0;
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2GetInteger(f.0, r.as_ptr(), 1, &mut z), fmi2Status::Ok);
        assert_eq!(z, 30, "reset restored the start value");
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
    }
}

#[test]
fn outputs_follow_inputs_directly() {
    let f = Fmu::initialised();
    set_loaded(&f);
    let o1 = f.get(&["TE", "base_radius_p", "base_radius_g"]).unwrap();
    assert!((o1[0] - (LOADED[0] * o1[1] + LOADED[1] * o1[2])).abs() < 1e-18);
    assert!((o1[0] - 20e-6).abs() < 1e-8, "TE of the README's worked example, {}", o1[0]);
    // Several set/get rounds without a step: each get sees the last inputs.
    for k in 1..4 {
        let phi_g = LOADED[1] - 1e-6 * k as f64;
        assert_eq!(f.set(&["phi_g"], &[phi_g]), fmi2Status::Ok);
        let te = f.get(&["TE"]).unwrap()[0];
        assert!((te - (LOADED[0] * o1[1] + phi_g * o1[2])).abs() < 1e-18);
    }
    unsafe {
        let mut n = -1;
        let mut b = [-1; 3];
        let rb = [vr("tip_contact"), vr("separated"), vr("back_contact")];
        assert_eq!(fmi2GetInteger(f.0, [vr("n_pairs")].as_ptr(), 1, &mut n), fmi2Status::Ok);
        assert_eq!(fmi2GetBoolean(f.0, rb.as_ptr(), 3, b.as_mut_ptr()), fmi2Status::Ok);
        assert!(n >= 1);
        assert_eq!(b[1], FMI2_FALSE, "not separated under load");
        // A Real value reference asked as Integer is an error.
        assert_eq!(fmi2GetInteger(f.0, [vr("TE")].as_ptr(), 1, &mut n), fmi2Status::Error);
    }
}

#[test]
fn tunable_d_mesh_between_steps_fixed_parameters_refused() {
    let f = Fmu::initialised();
    set_loaded(&f);
    let d0 = f.get(&["M_D_p", "d_mesh"]).unwrap();
    assert_eq!(f.set(&["d_mesh"], &[2.0 * d0[1]]), fmi2Status::Ok);
    let d1 = f.get(&["M_D_p"]).unwrap()[0];
    assert!((d1 - 2.0 * d0[0]).abs() <= 1e-12 * d0[0].abs().max(1e-300), "{d1} vs {}", d0[0]);
    assert_eq!(unsafe { fmi2DoStep(f.0, 0.0, 1e-4, FMI2_TRUE) }, fmi2Status::Ok);
    assert_eq!(f.set(&["d_mesh"], &[0.0]), fmi2Status::Ok);
    assert_eq!(f.get(&["M_D_p"]).unwrap()[0], 0.0);
    assert_eq!(f.set(&["face_width_m"], &[0.02]), fmi2Status::Error, "fixed after init");
}

#[test]
fn do_step_checks_time_and_step() {
    let f = Fmu::new();
    unsafe {
        assert_eq!(fmi2SetupExperiment(f.0, FMI2_FALSE, 0.0, 1.0, FMI2_TRUE, 1.5), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(f.0, 1.0, 0.1, FMI2_TRUE), fmi2Status::Ok);
        let mut t = 0.0;
        assert_eq!(fmi2GetRealStatus(f.0, 2, &mut t), fmi2Status::Ok);
        assert_eq!(t, 1.1);
        let mut st = fmi2Status::Error;
        assert_eq!(fmi2GetStatus(f.0, 0, &mut st), fmi2Status::Ok);
        assert_eq!(st, fmi2Status::Ok);
        let mut term = FMI2_TRUE;
        assert_eq!(fmi2GetBooleanStatus(f.0, 3, &mut term), fmi2Status::Ok);
        assert_eq!(term, FMI2_FALSE);
        assert_eq!(fmi2GetStringStatus(f.0, 1, null_mut()), fmi2Status::Discard);
        // A state-less rounding difference of the communication point is accepted.
        assert_eq!(fmi2DoStep(f.0, 1.1 + 1e-15, 0.1, FMI2_TRUE), fmi2Status::Ok);
        for (t, h) in [(1.0, 0.1), (1.2, 0.0), (1.2, -0.1), (1.2, f64::NAN), (1.2, 0.4)] {
            assert_eq!(fmi2DoStep(f.0, t, h, FMI2_TRUE), fmi2Status::Error, "t = {t}, h = {h}");
            // Back to the state before the failed step.
            f.reset();
            assert_eq!(fmi2SetupExperiment(f.0, 0, 0.0, 1.2, FMI2_TRUE, 1.5), fmi2Status::Ok);
            assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
            assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
        }
    }
}

#[test]
fn fmu_state_round_trips_exactly() {
    let f = Fmu::initialised();
    set_loaded(&f);
    let before = f.get(&OUTS).unwrap();
    unsafe {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert!(!s.is_null());
        let mut n = 0;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, s, &mut n), fmi2Status::Ok);
        let mut bytes = vec![0 as fmi2Byte; n];
        assert_eq!(fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), n), fmi2Status::Ok);

        // Change inputs, a tunable parameter and time, then restore.
        assert_eq!(f.set(&["phi_g", "d_mesh"], &[-0.0061, 250.0]), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(f.0, 0.0, 0.01, FMI2_TRUE), fmi2Status::Ok);
        assert_ne!(f.get(&OUTS).unwrap(), before);
        assert_eq!(fmi2SetFMUstate(f.0, s), fmi2Status::Ok);
        assert_eq!(f.get(&OUTS).unwrap(), before);
        assert_eq!(f.get(&["d_mesh"]).unwrap(), vec![100.0]);
        let mut t = -1.0;
        assert_eq!(fmi2GetRealStatus(f.0, 2, &mut t), fmi2Status::Ok);
        assert_eq!(t, 0.0);

        // Deserialised into another instance: same outputs, same time.
        let g = Fmu::new();
        let mut s2: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(g.0, bytes.as_ptr(), n, &mut s2), fmi2Status::Ok);
        assert_eq!(fmi2SetFMUstate(g.0, s2), fmi2Status::Ok);
        assert_eq!(g.get(&OUTS).unwrap(), before);
        assert_eq!(fmi2DoStep(g.0, 0.0, 0.01, FMI2_TRUE), fmi2Status::Ok, "in stepComplete");

        // A state of another instance, a short buffer and corrupt bytes are errors.
        assert_eq!(fmi2SetFMUstate(g.0, s), fmi2Status::Error);
        g.reset();
        assert_eq!(fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), n - 1), fmi2Status::Error);
        f.reset();
        let mut s3: fmi2FMUstate = null_mut();
        for corrupt in [&bytes[..n - 1], &bytes[1..]] {
            let st = fmi2DeSerializeFMUstate(g.0, corrupt.as_ptr(), corrupt.len(), &mut s3);
            assert_eq!(st, fmi2Status::Error);
            g.reset();
        }
        // Overwrite an existing state in place, then free both; freeing NULL is a no-op.
        let old = s;
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert_eq!(s, old);
        assert_eq!(fmi2FreeFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert!(s.is_null());
        assert_eq!(fmi2FreeFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(g.0, &mut s2), fmi2Status::Ok);
    }
}

/// The mesh element's FMU state carries its load solver's warm start: after a serialised
/// state is restored in another instance, the next evaluation at a new input equals, bit for
/// bit, the original's at the same input.
#[test]
fn serialised_state_carries_the_warm_start() {
    let f = Fmu::initialised();
    set_loaded(&f);
    f.get(&OUTS).unwrap();
    let bytes = unsafe {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        let mut n = 0;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, s, &mut n), fmi2Status::Ok);
        let mut bytes = vec![0 as fmi2Byte; n];
        assert_eq!(fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), n), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(f.0, &mut s), fmi2Status::Ok);
        bytes
    };
    let next = |fmu: &Fmu| {
        assert_eq!(fmu.set(&["phi_g"], &[-0.00608]), fmi2Status::Ok);
        fmu.get(&OUTS).unwrap().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    };
    let original = next(&f);
    let g = Fmu::new();
    unsafe {
        let mut s2: fmi2FMUstate = null_mut();
        let st = fmi2DeSerializeFMUstate(g.0, bytes.as_ptr(), bytes.len(), &mut s2);
        assert_eq!(st, fmi2Status::Ok);
        assert_eq!(fmi2SetFMUstate(g.0, s2), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(g.0, &mut s2), fmi2Status::Ok);
    }
    assert_eq!(next(&g), original);
}

#[test]
fn restore_from_the_error_state() {
    let f = Fmu::initialised();
    set_loaded(&f);
    let before = f.get(&OUTS).unwrap();
    unsafe {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut s), fmi2Status::Ok);
        assert_eq!(f.set(&["phi_p"], &[f64::NAN]), fmi2Status::Error);
        assert_eq!(fmi2SetFMUstate(f.0, s), fmi2Status::Ok);
        assert_eq!(f.get(&OUTS).unwrap(), before);
        assert_eq!(fmi2DoStep(f.0, 0.0, 1e-3, FMI2_TRUE), fmi2Status::Ok);
        // The instance frees states the master forgot.
    }
}

// An instance may move between threads as long as one thread at a time uses it.
unsafe impl Send for Fmu {}

#[test]
fn instances_with_different_parameters_on_different_threads() {
    let make = |slices: i32, d_mesh: f64| {
        let f = Fmu::new();
        unsafe {
            assert_eq!(
                fmi2SetInteger(f.0, [vr("slices")].as_ptr(), 1, [slices].as_ptr()),
                fmi2Status::Ok
            );
        }
        assert_eq!(f.set(&["d_mesh"], &[d_mesh]), fmi2Status::Ok);
        f
    };
    let run = |f: &Fmu| {
        f.init();
        let mut out = Vec::new();
        for k in 0..20 {
            let phi_p = 1e-3 * k as f64;
            let phi_g = (20e-6 - phi_p * 0.0428606) / 0.0671483;
            assert_eq!(
                f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, 50.0, -31.0]),
                fmi2Status::Ok
            );
            out.push(f.get(&OUTS).unwrap());
        }
        out
    };
    // Both instances computing at the same time on two threads …
    let ((fa, a), (fb, b)) = std::thread::scope(|s| {
        let ha = s.spawn(|| {
            let f = make(200, 100.0);
            let o = run(&f);
            (f, o)
        });
        let hb = s.spawn(|| {
            let f = make(120, 300.0);
            let o = run(&f);
            (f, o)
        });
        (ha.join().unwrap(), hb.join().unwrap())
    });
    assert_ne!(a, b);
    // … give what each gives alone, one after the other on this thread (after fmi2Reset the
    // instance starts from its start values and a fresh copy of its model).
    for (f, slices, d_mesh, expected) in [(&fa, 200, 100.0, &a), (&fb, 120, 300.0, &b)] {
        f.reset();
        unsafe {
            fmi2SetInteger(f.0, [vr("slices")].as_ptr(), 1, [slices].as_ptr());
        }
        assert_eq!(f.set(&["d_mesh"], &[d_mesh]), fmi2Status::Ok);
        assert_eq!(&run(f), expected);
    }
}

#[test]
fn every_parameter_round_trips_through_set_and_get() {
    let f = Fmu::new();
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        for v in VARIABLES {
            let Some(start) = v.start() else { continue };
            let r = [v.vr];
            match v.var_type() {
                helical_gear_mesh::fmi2::variables::VarType::Real => {
                    let mut x = 0.0;
                    assert_eq!(fmi2GetReal(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
                    assert_eq!(x, start.parse::<f64>().unwrap(), "{}", v.name);
                    assert_eq!(fmi2SetReal(f.0, r.as_ptr(), 1, &x), fmi2Status::Ok);
                }
                helical_gear_mesh::fmi2::variables::VarType::Integer => {
                    let mut x = 0;
                    assert_eq!(fmi2GetInteger(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
                    assert_eq!(x, start.parse::<i32>().unwrap(), "{}", v.name);
                }
                helical_gear_mesh::fmi2::variables::VarType::Boolean => {
                    let mut x = 0;
                    assert_eq!(fmi2GetBoolean(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
                    assert_eq!(x != 0, start == "true", "{}", v.name);
                }
                helical_gear_mesh::fmi2::variables::VarType::String => {
                    let mut x: fmi2String = null();
                    assert_eq!(fmi2GetString(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
                    let text = std::ffi::CStr::from_ptr(x).to_str().unwrap().to_string();
                    assert_eq!(text, start, "{}", v.name);
                    let c = CString::new(text).unwrap();
                    let p = [c.as_ptr()];
                    assert_eq!(fmi2SetString(f.0, r.as_ptr(), 1, p.as_ptr()), fmi2Status::Ok);
                }
            }
        }
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
    }
}

#[test]
fn debug_logging_categories_are_checked() {
    let f = Fmu::new();
    unsafe {
        let ok = [c"logModel".as_ptr()];
        assert_eq!(fmi2SetDebugLogging(f.0, FMI2_TRUE, 1, ok.as_ptr()), fmi2Status::Ok);
        assert_eq!(fmi2SetDebugLogging(f.0, FMI2_TRUE, 0, null()), fmi2Status::Ok);
        let bad = [c"logNothing".as_ptr()];
        assert_eq!(fmi2SetDebugLogging(f.0, FMI2_TRUE, 1, bad.as_ptr()), fmi2Status::Error);
        f.reset();
        assert_eq!(fmi2SetDebugLogging(f.0, FMI2_TRUE, 1, null()), fmi2Status::Error);
    }
}

#[test]
fn unsupported_functions_are_errors() {
    let f = Fmu::initialised();
    unsafe {
        let r = [vr("M_F_p")];
        let mut x = 0.0;
        assert_eq!(
            fmi2GetDirectionalDerivative(f.0, r.as_ptr(), 1, r.as_ptr(), 1, &x, &mut x),
            fmi2Status::Error
        );
        f.reset();
        f.init();
        assert_eq!(
            fmi2GetRealOutputDerivatives(f.0, r.as_ptr(), 1, [1].as_ptr(), &mut x),
            fmi2Status::Error
        );
        f.reset();
        assert_eq!(
            fmi2SetRealInputDerivatives(f.0, r.as_ptr(), 1, [1].as_ptr(), &x),
            fmi2Status::Error
        );
        f.reset();
        f.init();
        assert_eq!(fmi2GetString(f.0, r.as_ptr(), 0, null_mut()), fmi2Status::Ok, "nothing asked");
        let mut x: fmi2String = null();
        assert_eq!(fmi2GetString(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Error, "a Real");
    }
}

/// The String parameter `modifications` (the JSON object of docs/modifications.md): a
/// pinion pitch deviation set through `fmi2SetString` gives exactly the outputs of the library model of the
/// same pair (so the same static TE), differs from the perfect pair on the deviated tooth,
/// survives an FMU state round trip; malformed JSON or an unknown key is refused by
/// `fmi2SetString`, a value beyond its limit by `fmi2ExitInitializationMode`, and the messages
/// name the key (checked on the library side: the FMU logs the same text).
#[test]
fn modifications_string_parameter() {
    use helical_gear_mesh::GearPair;
    use helical_gear_mesh::mesh::{Mesh, MeshOptions, MeshState};
    let mut p = GearPair::paper_table1();
    p.modifications.pinion.pitch_deviations_m = vec![0.0; 30];
    p.modifications.pinion.pitch_deviations_m[0] = 3e-6;
    let json = serde_json::to_string(&p.modifications).unwrap();
    let set = |f: &Fmu, text: &str| {
        let c = CString::new(text).unwrap();
        let ptr = [c.as_ptr()];
        let r = [vr("modifications")];
        unsafe { fmi2SetString(f.0, r.as_ptr(), 1, ptr.as_ptr()) }
    };
    let f = Fmu::new();
    assert_eq!(set(&f, &json), fmi2Status::Ok);
    f.init();
    let mut lib = Mesh::new(&p, MeshOptions::default()).unwrap();
    let mut perfect = Mesh::new(&GearPair::paper_table1(), MeshOptions::default()).unwrap();
    let mut differs = false;
    for k in 0..5 {
        let phi_p = -0.04 + 0.02 * k as f64;
        let phi_g = lib.geometry().phi_g_for_te(phi_p, 25e-6);
        assert_eq!(
            f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, 0.0, 0.0]),
            fmi2Status::Ok
        );
        let got = f.get(&["M_F_p", "TE"]).unwrap();
        let s = MeshState { phi_p, phi_g, w_p: 0.0, w_g: 0.0, ..Default::default() };
        let o = lib.evaluate(&s).unwrap();
        assert_eq!(got[0].to_bits(), o.m_f_p.to_bits(), "φp = {phi_p}");
        assert_eq!(got[1].to_bits(), o.te.to_bits());
        differs |= (perfect.evaluate(&s).unwrap().m_f_p - o.m_f_p).abs() > 1e-3;
    }
    assert!(differs);
    // The text reads back and survives a serialised FMU state.
    unsafe {
        let r = [vr("modifications")];
        let mut x: fmi2String = null();
        assert_eq!(fmi2GetString(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
        let back = std::ffi::CStr::from_ptr(x).to_str().unwrap();
        assert_eq!(helical_gear_mesh::Modifications::from_json(back).unwrap(), p.modifications);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, &mut st), fmi2Status::Ok);
        let mut n = 0usize;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, st, &mut n), fmi2Status::Ok);
        let mut bytes = vec![0 as c_char; n];
        assert_eq!(fmi2SerializeFMUstate(f.0, st, bytes.as_mut_ptr(), n), fmi2Status::Ok);
        let g = Fmu::new();
        let mut st2: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(g.0, bytes.as_ptr(), n, &mut st2), fmi2Status::Ok);
        assert_eq!(fmi2SetFMUstate(g.0, st2), fmi2Status::Ok);
        let mut y: fmi2String = null();
        assert_eq!(fmi2GetString(g.0, r.as_ptr(), 1, &mut y), fmi2Status::Ok);
        assert_eq!(std::ffi::CStr::from_ptr(y).to_str().unwrap(), back);
        fmi2FreeFMUstate(f.0, &mut st);
        fmi2FreeFMUstate(g.0, &mut st2);
    }
    // Errors.
    let bad = Fmu::new();
    assert_eq!(set(&bad, "{\"pinion\": {\"runout\": 1e-6}}"), fmi2Status::Error);
    bad.reset();
    assert_eq!(set(&bad, "{not json"), fmi2Status::Error);
    bad.reset();
    assert_eq!(set(&bad, "{\"gear\": {\"lead_crowning_m\": 0.01}}"), fmi2Status::Ok);
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(bad.0, FMI2_FALSE, 0.0, 0.0, FMI2_FALSE, 0.0),
            fmi2Status::Ok
        );
        assert_eq!(fmi2EnterInitializationMode(bad.0), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(bad.0), fmi2Status::Error);
    }
    let e = helical_gear_mesh::Modifications::from_json("{\"pinion\": {\"runout\": 1e-6}}");
    assert!(e.unwrap_err().contains("runout"));
}

/// The String parameter `friction` (docs/friction.md): set through `fmi2SetString`, the
/// mesh element gives exactly the library model's outputs with that friction at a running
/// state (loss, efficiency, heat, friction torques inside M_F), reads back, survives a reset
/// to none; a bad value or an unknown key is refused naming it.
#[test]
fn friction_string_parameter() {
    use helical_gear_mesh::GearPair;
    use helical_gear_mesh::mesh::{Friction, Mesh, MeshOptions, MeshState};
    let set = |f: &Fmu, text: &str| {
        let c = CString::new(text).unwrap();
        let ptr = [c.as_ptr()];
        let r = [vr("friction")];
        unsafe { fmi2SetString(f.0, r.as_ptr(), 1, ptr.as_ptr()) }
    };
    let json = r#"{"model": "constant", "mu": 0.06}"#;
    let f = Fmu::new();
    assert_eq!(set(&f, json), fmi2Status::Ok);
    f.init();
    let friction = Friction::from_json(json).unwrap();
    let options = MeshOptions { friction, ..MeshOptions::default() };
    let mut lib = Mesh::new(&GearPair::paper_table1(), options).unwrap();
    let names = ["M_F_p", "M_F_g", "M_R_p", "M_R_g", "P_loss", "eta_mesh", "Q_p", "Q_g", "F_p_y"];
    for k in 0..4 {
        let phi_p = -0.04 + 0.02 * k as f64;
        let phi_g = lib.geometry().phi_g_for_te(phi_p, 25e-6);
        let (w_p, w_g) = (300.0, -300.0 * 30.0 / 47.0);
        assert_eq!(
            f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, w_p, w_g]),
            fmi2Status::Ok
        );
        let got = f.get(&names).unwrap();
        let o = lib.evaluate(&MeshState { phi_p, phi_g, w_p, w_g, ..Default::default() }).unwrap();
        let want =
            [o.m_f_p, o.m_f_g, o.m_r_p, o.m_r_g, o.p_loss, o.eta_mesh, o.q_p, o.q_g, o.force_p[1]];
        for ((n, g), w) in names.iter().zip(&got).zip(want) {
            assert_eq!(g.to_bits(), w.to_bits(), "{n} at φp = {phi_p}");
        }
        assert!(o.p_loss > 0.0 && o.eta_mesh < 1.0);
    }
    unsafe {
        let r = [vr("friction")];
        let mut x: fmi2String = null();
        assert_eq!(fmi2GetString(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Ok);
        let back = std::ffi::CStr::from_ptr(x).to_str().unwrap();
        assert_eq!(Friction::from_json(back).unwrap(), friction);
    }
    // Errors name the key; `none` is the default.
    let bad = Fmu::new();
    assert_eq!(set(&bad, r#"{"mu": 2}"#), fmi2Status::Error);
    bad.reset();
    assert_eq!(set(&bad, r#"{"model": "constant", "viscosity": 1}"#), fmi2Status::Error);
    bad.reset();
    assert_eq!(set(&bad, "none"), fmi2Status::Ok);
    let e = Friction::from_json(r#"{"mu": 2}"#).unwrap_err();
    assert!(e.contains("friction.mu"), "{e}");
    let e = Friction::from_json(r#"{"viscosity": 1}"#).unwrap_err();
    assert!(e.contains("viscosity"), "{e}");
}

/// The mesh element's table is sized by its parameter `table_design_torque_nm`: built for
/// 500 N·m it covers the static TE at 500 N·m, which lies beyond the range of the table built
/// for the default 100 N·m, and the FMU's outputs there are the library's table mesh at that
/// design torque, bit for bit (the default table hands the state to the full model instead).
#[test]
fn mesh_fmu_table_covers_its_design_torque() {
    use helical_gear_mesh::GearPair;
    use helical_gear_mesh::mesh::statics::{EquilibriumSettings, equilibrium};
    use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions, MeshState};
    let torque = 500.0;
    let opts = MeshOptions {
        fidelity: Fidelity::Table,
        slices: 40,
        table_phase_points: 16,
        table_te_points: 12,
        table_design_torque_nm: torque,
        ..MeshOptions::default()
    };
    let pair = GearPair::paper_table1();
    let mut lib = Mesh::new(&pair, opts).unwrap();
    let hi = lib.table().expect("table").te_range().1;
    let mut default = Mesh::new(&pair, MeshOptions { table_design_torque_nm: 100.0, ..opts })
        .expect("default table");
    let hi_default = default.table().expect("table").te_range().1;
    let phi_p = 0.013;
    let eq = equilibrium(&mut lib, phi_p, torque, 1e-5, &EquilibriumSettings::default()).unwrap();
    eprintln!("static TE at {torque} N.m: {:.3e} m; table up to {hi:.3e} m", eq.te);
    eprintln!("default table (100 N.m) up to {hi_default:.3e} m");
    assert!(eq.te < hi, "the table covers its design torque's static TE");
    assert!(eq.te > hi_default, "beyond the default table");
    // Through the FMI API: the same table.
    let f = Fmu::new();
    let ints = [(vr("fidelity"), 1), (vr("slices"), 40)];
    let sizes = [(vr("table_phase_points"), 16), (vr("table_te_points"), 12)];
    for (r, v) in ints.into_iter().chain(sizes) {
        assert_eq!(unsafe { fmi2SetInteger(f.0, &r, 1, &v) }, fmi2Status::Ok);
    }
    assert_eq!(f.set(&["table_design_torque_nm"], &[torque]), fmi2Status::Ok);
    f.init();
    let phi_g = lib.geometry().phi_g_for_te(phi_p, eq.te);
    let s = MeshState { phi_p, phi_g, w_p: 0.0, w_g: 0.0, ..Default::default() };
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, 0.0, 0.0]), fmi2Status::Ok);
    let got = f.get(&["M_F_p", "TE"]).unwrap();
    let o = lib.evaluate(&s).unwrap();
    assert_eq!(got[0].to_bits(), o.m_f_p.to_bits(), "{} vs {}", got[0], o.m_f_p);
    assert_eq!(got[1].to_bits(), o.te.to_bits());
    assert!((o.m_f_p - torque).abs() < 0.02 * torque, "static: M_F_p = {}", o.m_f_p);
    let d = default.evaluate(&s).unwrap();
    assert_ne!(d.m_f_p.to_bits(), o.m_f_p.to_bits(), "the default table falls back to full");
}
