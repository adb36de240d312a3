//! Stress test: extreme inputs through the FMU functions and the C API (docs/robustness.md,
//! "Stress tests"): NaN and ±Inf in every input, 10¹² rad angles, zero and negative speeds,
//! NULL and garbage pointers' contents, illegal call orders, corrupt serialized FMU states,
//! and 1 000 instantiate/free cycles. Every failure must be a status (fmi2Error, an HGM error
//! code), never a crash; the instance stays recoverable. The log texts are checked by the C
//! program (tests/c/test_capi.c), whose logger is a real variadic C function; it also runs
//! under valgrind for leaks when valgrind is installed (tests/python/test_c_api.py).

mod common;

use std::ffi::CString;
use std::ptr::{null, null_mut};

use helical_gear_mesh::capi::*;
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::models::mesh::guid;
use helical_gear_mesh::fmi2::types::*;

use common::fmi::{Fmu, vr};

const INPUTS: [&str; 4] = ["phi_p", "phi_g", "w_p", "w_g"];
const OUTS: [&str; 8] =
    ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "F_n", "contact_length", "p_max"];
const G_P: f64 = 0.042_860_629_350_090_065;
const G_G: f64 = 0.067_148_319_315_141_12;

#[test]
fn non_finite_inputs_are_errors_in_every_input_and_state() {
    let f = Fmu::new();
    f.init();
    for name in INPUTS {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -f64::NAN] {
            assert_eq!(f.set(&[name], &[bad]), fmi2Status::Error, "{name} = {bad}");
            // Error state: no step until reset (getters stay allowed for diagnostics).
            assert_eq!(unsafe { fmi2DoStep(f.0, 0.0, 1e-3, FMI2_TRUE) }, fmi2Status::Error);
            f.recover();
            // Also in a batch with valid values before it: nothing half-applied.
            let mut v = [0.01, -0.0060851, 100.0, -63.83];
            let i = INPUTS.iter().position(|n| *n == name).unwrap();
            v[i] = bad;
            assert_eq!(f.set(&INPUTS, &v), fmi2Status::Error);
            f.recover();
            assert_eq!(f.get(&INPUTS).unwrap(), vec![0.0; 4], "start values after reset");
        }
    }
    // Non-finite fixed parameters fail the initialisation; the tunable d_mesh at once.
    for p in ["normal_module_m", "material_p.youngs_modulus_pa", "d_mesh"] {
        let g = Fmu::new();
        let s = g.set(&[p], &[f64::NAN]);
        if s == fmi2Status::Ok {
            unsafe {
                assert_eq!(fmi2EnterInitializationMode(g.0), fmi2Status::Ok);
                assert_eq!(fmi2ExitInitializationMode(g.0), fmi2Status::Error, "{p}");
            }
        }
        let g = Fmu::new();
        g.init();
        if p == "d_mesh" {
            assert_eq!(g.set(&[p], &[f64::INFINITY]), fmi2Status::Error, "{p}");
        }
    }
}

#[test]
fn huge_angles_zero_and_negative_speeds_give_finite_outputs() {
    let f = Fmu::new();
    f.init();
    for &(phi_p, te) in &[(1e12, 20e-6), (-1e12, 25e-6), (0.0, 20e-6), (1e15, 20e-6)] {
        let phi_g = (te - phi_p * G_P) / G_G;
        for &(w_p, w_g) in &[(0.0, 0.0), (-100.0, 63.83), (100.0, -63.83), (-1e4, 0.0), (0.0, -1e4)]
        {
            assert_eq!(f.set(&INPUTS, &[phi_p, phi_g, w_p, w_g]), fmi2Status::Ok);
            let o = f.get(&OUTS).unwrap_or_else(|s| panic!("φp {phi_p}: {s:?}"));
            assert!(o.iter().all(|v| v.is_finite()), "φp {phi_p}, w {w_p}/{w_g}: {o:?}");
            // The damping torque opposes the approach speed dTE/dt (zero at rest).
            let dte = w_p * G_P + w_g * G_G;
            assert!(o[2] * dte >= 0.0, "M_D_p {} vs dTE/dt {dte}", o[2]);
            if w_p == 0.0 && w_g == 0.0 {
                assert_eq!((o[2], o[3]), (0.0, 0.0));
            }
        }
    }
    // Steps of any length on a huge time axis are accepted; negative or NaN ones are not.
    unsafe {
        assert_eq!(fmi2DoStep(f.0, 0.0, 1e-6, FMI2_TRUE), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(f.0, 1e-6, -1.0, FMI2_TRUE), fmi2Status::Error);
    }
    f.recover();
    unsafe {
        assert_eq!(fmi2DoStep(f.0, 0.0, f64::INFINITY, FMI2_TRUE), fmi2Status::Error);
    }
}

#[test]
fn illegal_call_orders_and_bad_pointers_are_errors() {
    let f = Fmu::new();
    let r = [vr("M_F_p")];
    let mut x = 0.0;
    unsafe {
        // Before initialisation.
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        assert_eq!(fmi2Terminate(f.0), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(f.0, 0.0, 1e-3, FMI2_TRUE), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        assert_eq!(fmi2GetReal(f.0, r.as_ptr(), 1, &mut x), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        // Twice into initialisation mode; set-up inside it.
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2SetupExperiment(f.0, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Error);
        assert_eq!(fmi2Reset(f.0), fmi2Status::Ok);
        // NULL arrays with n > 0, an unknown value reference, n = 0 with NULL (fine).
        f.init();
        assert_eq!(fmi2GetReal(f.0, null(), 1, &mut x), fmi2Status::Error);
        f.recover();
        assert_eq!(fmi2GetReal(f.0, r.as_ptr(), 1, null_mut()), fmi2Status::Error);
        f.recover();
        assert_eq!(fmi2SetReal(f.0, [vr("phi_p")].as_ptr(), 1, null()), fmi2Status::Error);
        f.recover();
        assert_eq!(fmi2GetReal(f.0, [9999].as_ptr(), 1, &mut x), fmi2Status::Error);
        f.recover();
        assert_eq!(fmi2GetReal(f.0, null(), 0, null_mut()), fmi2Status::Ok);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(f.0, null_mut()), fmi2Status::Error);
        f.recover();
        // Corrupt and truncated serialized states.
        assert_eq!(fmi2GetFMUstate(f.0, &mut st), fmi2Status::Ok);
        let mut size = 0usize;
        assert_eq!(fmi2SerializedFMUstateSize(f.0, st, &mut size), fmi2Status::Ok);
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(f.0, st, bytes.as_mut_ptr(), size), fmi2Status::Ok);
        assert_eq!(fmi2SerializeFMUstate(f.0, st, bytes.as_mut_ptr(), size / 2), fmi2Status::Error);
        f.recover();
        // Random corruption of the header, the inputs and the cached outputs (a corrupted
        // parameter that stays valid is another gear pair, whose FE run is not for a loop),
        // random truncation, and non-finite numbers written over inputs and parameters.
        let header = 8 + 4 + 4 + guid().len() + 1 + 8 + 8 + 1 + 8;
        let inputs_end = header + 32;
        let outputs_start = size - (1 + 8 * 8 + 4 + 3);
        let mut rng = 0x1234_5678_9abc_def0u64;
        for trial in 0..300 {
            let mut b = bytes.clone();
            let len = if trial % 3 == 0 { (rng % size as u64) as usize } else { size };
            for _ in 0..4 {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                let mut i = (rng % size as u64) as usize;
                if i >= inputs_end && i < outputs_start {
                    i = (i - inputs_end) % inputs_end;
                }
                b[i] = (rng >> 32) as fmi2Byte;
            }
            if trial % 5 == 1 {
                // NaN or ±Inf over an input or over normal_module_m (after z_p, z_g).
                let k = ((rng >> 8) % 5) as usize;
                let at = header + 8 * k + if k == 4 { 8 } else { 0 };
                let x = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][(rng % 3) as usize];
                for (k, byte) in x.to_le_bytes().iter().enumerate() {
                    b[at + k] = *byte as fmi2Byte;
                }
            }
            let mut out: fmi2FMUstate = null_mut();
            match fmi2DeSerializeFMUstate(f.0, b.as_ptr(), len, &mut out) {
                fmi2Status::Ok => {
                    // A corruption that still parses is a valid state: it can be set or refused.
                    let s = fmi2SetFMUstate(f.0, out);
                    assert!(matches!(s, fmi2Status::Ok | fmi2Status::Error));
                    assert_eq!(fmi2FreeFMUstate(f.0, &mut out), fmi2Status::Ok);
                    f.recover();
                }
                s => {
                    assert_eq!(s, fmi2Status::Error);
                    f.recover();
                }
            }
        }
        // Non-finite inputs or parameters inside a state are refused (they were accepted).
        for at in [header, header + 24, header + 40] {
            let mut b = bytes.clone();
            for (k, byte) in f64::NAN.to_le_bytes().iter().enumerate() {
                b[at + k] = *byte as fmi2Byte;
            }
            let mut out: fmi2FMUstate = null_mut();
            assert_eq!(
                fmi2DeSerializeFMUstate(f.0, b.as_ptr(), size, &mut out),
                fmi2Status::Error,
                "NaN at byte {at}"
            );
            f.recover();
        }
        assert_eq!(fmi2FreeFMUstate(f.0, &mut st), fmi2Status::Ok);
        // After termination only reset or free.
        assert_eq!(fmi2Terminate(f.0), fmi2Status::Ok);
        assert_eq!(f.set(&["phi_p"], &[0.1]), fmi2Status::Error);
        f.recover();
        assert!(f.get(&["M_F_p"]).is_ok());
    }
}

#[test]
fn thousand_instantiate_free_cycles() {
    let t0 = std::time::Instant::now();
    for _ in 0..1000 {
        drop(Fmu::new());
    }
    // And some full cycles with the model built and evaluated (at TE = 20 µm: a fixed φg
    // with φp up to 0.19 rad would be an overlap of 8 mm, outside the model's range).
    for i in 0..20 {
        let f = Fmu::new();
        f.init();
        let phi_p = 0.01 * i as f64;
        let phi_g = (20e-6 - phi_p * G_P) / G_G;
        assert_eq!(f.set(&INPUTS, &[phi_p, phi_g, 100.0, -63.83]), fmi2Status::Ok);
        assert!(f.get(&["M_F_p"]).unwrap()[0].is_finite());
    }
    for _ in 0..1000 {
        let h = hgm_create_default();
        assert!(!h.is_null());
        unsafe { hgm_free(h) };
    }
    eprintln!("1000 + 20 FMU and 1000 C API cycles: {:.2} s", t0.elapsed().as_secs_f64());
}

#[test]
fn c_api_extreme_inputs() {
    let h = hgm_create_default();
    assert!(!h.is_null());
    let mut o = HgmOutputs::default();
    let msg = |h: *const HgmModel| {
        unsafe { std::ffi::CStr::from_ptr(hgm_last_error(h)) }.to_string_lossy().into_owned()
    };
    unsafe {
        for i in 0..4 {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut v = [0.01, -0.0060851, 100.0, -63.83];
                v[i] = bad;
                let s = hgm_evaluate(h, v[0], v[1], v[2], v[3], &mut o);
                assert_eq!(s, HgmStatus::InvalidArgument);
                assert!(msg(h).contains(INPUTS[i]), "{}", msg(h));
            }
        }
        for &(phi_p, w_p) in &[(1e12, 0.0), (-1e12, -500.0), (1e15, 1e4), (0.0, -1e4)] {
            let phi_g = (20e-6 - phi_p * G_P) / G_G;
            let s = hgm_evaluate(h, phi_p, phi_g, w_p, -w_p * 30.0 / 47.0, &mut o);
            assert_eq!(s, HgmStatus::Ok, "{}", msg(h));
            assert!(o.m_f_p.is_finite() && o.m_d_p.is_finite() && o.te.is_finite());
        }
        for d in [f64::NAN, f64::INFINITY, -1.0] {
            assert_ne!(hgm_set_d_mesh(h, d), HgmStatus::Ok);
        }
        assert_eq!(hgm_evaluate(h, 0.01, -0.0060851, 0.0, 0.0, &mut o), HgmStatus::Ok);
        assert_eq!(hgm_set_d_mesh(null_mut(), 1.0), HgmStatus::InvalidArgument);
        for json in [
            "",
            "null",
            "[]",
            "{\"z_p\": -1}",
            "{\"z_p\": 1e400}",
            "{\"normal_module_m\": \"x\"}",
            "\u{0}",
        ] {
            let c = CString::new(json.replace('\u{0}', "")).unwrap();
            assert!(hgm_create_from_json(c.as_ptr()).is_null(), "{json}");
            assert!(!msg(null()).is_empty());
        }
        hgm_free(h);
    }
}
