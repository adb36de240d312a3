//! Regression tests at the interfaces' boundaries: no non-finite value with a success status,
//! inputs and tunable parameters held to their stated ranges, serialised FMU states and unit
//! snapshots refused whole when their checksum or version does not match, restored states that
//! read back finite, the C API's enum arguments validated as integers, a second thread entering
//! an FMU instance in use refused with fmi2Error, and short numbers in messages.

mod common;

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use helical_gear_mesh::capi::*;
use helical_gear_mesh::dynamics::{
    Clearance, ConstantStiffnessMesh, DriveUnit, Drivetrain, UnitInputs, UnitKind, UnitSnapshot,
    UnitStepping,
};
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::models::mesh::guid;
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::numeric::fnv1a_64;

use common::fmi::{Fmu, vr};

const OUTS: [&str; 8] =
    ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "F_n", "contact_length", "p_max"];
const CALCULATED: [&str; 4] = ["J_p", "J_g", "base_radius_p", "base_radius_g"];
const LOADED: [f64; 4] = [0.01, -0.0060851, 100.0, -63.83];

/// Rewrites the checksum (last 8 bytes) of a serialised state after an edit.
fn reseal(b: &mut [fmi2Byte]) {
    let n = b.len() - 8;
    let payload: Vec<u8> = b[..n].iter().map(|&x| x as u8).collect();
    for (k, byte) in fnv1a_64(&payload).to_le_bytes().iter().enumerate() {
        b[n + k] = *byte as fmi2Byte;
    }
}

fn last_error(h: *const HgmModel) -> String {
    unsafe { CStr::from_ptr(hgm_last_error(h)) }.to_string_lossy().into_owned()
}

/// Every number in `msg` has at most 16 characters.
fn numbers_are_short(msg: &str) -> bool {
    msg.split(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
        .filter(|w| w.starts_with(|c: char| c.is_ascii_digit() || c == '-'))
        .all(|w| w.len() <= 16)
}

#[test]
fn huge_finite_inputs_are_errors_not_infinite_outputs() {
    let f = Fmu::new();
    f.init();
    for (i, name) in ["w_p", "w_g"].iter().enumerate() {
        for bad in [1e308, -1e308, 1.0000001e5] {
            let mut v = LOADED;
            v[2 + i] = bad;
            assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &v), fmi2Status::Error, "{name}");
            f.recover();
        }
    }
    for bad in [1e308, -1.1e15] {
        assert_eq!(f.set(&["phi_p"], &[bad]), fmi2Status::Error);
        f.recover();
    }
    // At the stated limits the outputs are finite.
    assert_eq!(
        f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[0.01, -0.0060851, 1e5, -1e5]),
        fmi2Status::Ok
    );
    let out = f.get(&OUTS).unwrap();
    assert!(out.iter().all(|v| v.is_finite()), "{out:?}");

    let h = hgm_create_default();
    let mut o = HgmOutputs::default();
    for (i, name) in ["phi_p", "phi_g", "w_p", "w_g"].iter().enumerate() {
        let mut v = LOADED;
        v[i] = if i < 2 { 1e308 } else { -1e308 };
        let s = unsafe { hgm_evaluate(h, v[0], v[1], v[2], v[3], &mut o) };
        assert_eq!(s, HgmStatus::InvalidArgument);
        let m = last_error(h);
        assert!(m.contains(&format!("`{name}`")) && numbers_are_short(&m), "{m}");
    }
    unsafe { hgm_free(h) };
}

#[test]
fn tunable_d_mesh_is_held_to_its_parameter_range() {
    let f = Fmu::new();
    f.init();
    for bad in [1e300, 1.0000001e9, -1e-3] {
        assert_eq!(f.set(&["d_mesh"], &[bad]), fmi2Status::Error, "{bad}");
        f.recover();
    }
    assert_eq!(f.set(&["d_mesh"], &[1e9]), fmi2Status::Ok);
    assert!(f.get(&OUTS).unwrap().iter().all(|v| v.is_finite()));
    // Before initialisation too.
    let g = Fmu::new();
    assert_eq!(g.set(&["d_mesh"], &[1e300]), fmi2Status::Error);

    let h = hgm_create_default();
    assert_eq!(unsafe { hgm_set_d_mesh(h, 1e300) }, HgmStatus::ModelError);
    let m = last_error(h);
    assert!(m.contains("d_mesh_n_s_per_m") && m.contains("1.0000e300"), "{m}");
    assert!(numbers_are_short(&m), "{m}");
    assert_eq!(unsafe { hgm_set_d_mesh(h, 1e9) }, HgmStatus::Ok);
    unsafe { hgm_free(h) };
}

#[test]
fn restored_state_with_non_finite_cached_outputs_is_refused() {
    let f = Fmu::new();
    f.init();
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
    let before = f.get(&OUTS).unwrap();
    let b = f.serialize();
    // The cached outputs: flag, 8 f64, u32, 3 flags, 10 f64 (force and moments), 2 f64 (root
    // stresses), then the checksum.
    let forces = b.len() - 8 - 12 * 8;
    let first = forces - 3 - 4 - 8 * 8;
    let offsets = (0..8).map(|k| first + 8 * k).chain((0..12).map(|k| forces + 8 * k));
    for (k, at) in offsets.enumerate() {
        for x in [f64::NAN, f64::INFINITY] {
            let mut c = b.clone();
            for (j, byte) in x.to_le_bytes().iter().enumerate() {
                c[at + j] = *byte as fmi2Byte;
            }
            // Unsealed: the checksum refuses it; resealed: the value check does.
            assert_eq!(f.restore(&c), fmi2Status::Error, "output {k} unsealed");
            f.recover();
            reseal(&mut c);
            assert_eq!(f.restore(&c), fmi2Status::Error, "output {k} resealed");
            f.recover();
        }
    }
    // An input beyond its range inside a resealed state is refused.
    let header = 8 + 4 + 4 + guid().len() + 1 + 8 + 8 + 1 + 8;
    let mut c = b.clone();
    for (j, byte) in 1e308f64.to_le_bytes().iter().enumerate() {
        c[header + 16 + j] = *byte as fmi2Byte; // w_p
    }
    reseal(&mut c);
    assert_eq!(f.restore(&c), fmi2Status::Error);
    f.recover();
    assert_eq!(f.restore(&b), fmi2Status::Ok);
    assert_eq!(f.get(&OUTS).unwrap(), before);
}

/// A mesh FMU state whose cached outputs are edited to finite but false values (M_F,p =
/// 1e6 N·m, TE = 0.5 m, σ_F = −5 Pa) and resealed with a recomputed checksum is refused: the
/// cached outputs must be what the restored inputs give. So is a time outside the state's own
/// experiment. The genuine state still restores bit for bit.
#[test]
fn restored_state_with_edited_cached_outputs_is_refused() {
    let f = Fmu::new();
    f.init();
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
    let names = ["M_F_p", "TE", "sigma_F_p"];
    let before = f.get(&OUTS).unwrap();
    let b = f.serialize();
    // Offsets as in `restored_state_with_non_finite_cached_outputs_is_refused`: M_F_p first,
    // TE the fifth of the first eight, sigma_F_p the eleventh of the last twelve.
    let forces = b.len() - 8 - 12 * 8;
    let first = forces - 3 - 4 - 8 * 8;
    for (at, x) in [(first, 1e6), (first + 4 * 8, 0.5), (forces + 10 * 8, -5.0)] {
        let mut c = b.clone();
        for (j, byte) in f64::to_le_bytes(x).iter().enumerate() {
            c[at + j] = *byte as fmi2Byte;
        }
        reseal(&mut c);
        assert_eq!(f.restore(&c), fmi2Status::Error, "edited to {x}");
        f.recover();
    }
    // A tiny edit within the solver's convergence is not a different state.
    let mut c = b.clone();
    let m = f64::from_le_bytes(std::array::from_fn(|j| c[first + j] as u8));
    for (j, byte) in f64::to_le_bytes(m * (1.0 + 1e-12)).iter().enumerate() {
        c[first + j] = *byte as fmi2Byte;
    }
    reseal(&mut c);
    assert_eq!(f.restore(&c), fmi2Status::Ok);
    // The time before the state's start time is refused (header: magic, version, GUID, mode,
    // then the time).
    let at_time = 8 + 4 + 4 + guid().len() + 1;
    let mut c = b.clone();
    for (j, byte) in f64::to_le_bytes(-1.0).iter().enumerate() {
        c[at_time + j] = *byte as fmi2Byte;
    }
    reseal(&mut c);
    assert_eq!(f.restore(&c), fmi2Status::Error);
    f.recover();
    assert_eq!(f.restore(&b), fmi2Status::Ok);
    assert_eq!(f.get(&OUTS).unwrap(), before);
    assert!(f.get(&names).is_ok());
}

#[test]
fn states_saved_in_initialization_terminated_or_error_mode_read_back_finite() {
    for mode in ["initialization", "terminated", "error"] {
        let f = Fmu::new();
        f.setup();
        match mode {
            "initialization" => {}
            "terminated" => unsafe {
                assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Ok);
                assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
                f.get(&OUTS).unwrap();
                assert_eq!(fmi2Terminate(f.0), fmi2Status::Ok);
            },
            _ => {
                assert_eq!(unsafe { fmi2ExitInitializationMode(f.0) }, fmi2Status::Ok);
                assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
                f.get(&OUTS).unwrap();
                assert_eq!(f.set(&["w_p"], &[f64::NAN]), fmi2Status::Error);
            }
        }
        let b = f.serialize();
        // Restored into a fresh instance (no engine built yet) and into this one.
        for g in [Fmu::new(), f] {
            assert_eq!(g.restore(&b), fmi2Status::Ok, "{mode}");
            match g.get(&CALCULATED) {
                Ok(v) => assert!(v.iter().all(|x| x.is_finite() && *x > 0.0), "{mode}: {v:?}"),
                Err(s) => assert_eq!(s, fmi2Status::Error, "{mode}"),
            }
            assert_eq!(g.restore(&b), fmi2Status::Ok, "{mode}");
            let mut both = CALCULATED.to_vec();
            both.extend(OUTS);
            match g.get(&both) {
                Ok(v) => assert!(v.iter().all(|x| x.is_finite()), "{mode}: {v:?}"),
                Err(s) => assert_eq!(s, fmi2Status::Error, "{mode}"),
            }
        }
    }
}

#[test]
fn unit_create_refuses_out_of_range_kind_and_fidelity() {
    for (kind, fidelity, arg) in [
        (3, 0, "`kind` = 3"),
        (-1, 0, "`kind` = -1"),
        (0, 2, "`fidelity` = 2"),
        (1, 77, "`fidelity` = 77"),
    ] {
        let u = unsafe { hgm_unit_create(kind, null(), null(), fidelity, 128, 0.0, 0.0) };
        assert!(u.is_null());
        let m =
            unsafe { CStr::from_ptr(hgm_unit_last_error(null())) }.to_string_lossy().into_owned();
        assert!(m.contains(arg) && m.contains("allowed"), "{m}");
    }
}

#[test]
fn flipped_bits_in_a_serialised_fmu_state_are_refused_whole() {
    let f = Fmu::new();
    f.init();
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
    f.get(&OUTS).unwrap();
    let b = f.serialize();
    let mut refused = 0;
    for i in 0..b.len() {
        for bit in 0..8 {
            let mut c = b.clone();
            c[i] ^= 1 << bit;
            let mut st: fmi2FMUstate = null_mut();
            let s = unsafe { fmi2DeSerializeFMUstate(f.0, c.as_ptr(), c.len(), &mut st) };
            assert_eq!(s, fmi2Status::Error, "bit {bit} of byte {i} accepted");
            refused += 1;
        }
    }
    eprintln!("{refused} single-bit corruptions of a {}-byte state refused", b.len());
    // Another format version is refused even with a valid checksum.
    let mut c = b.clone();
    c[8] = 3;
    reseal(&mut c);
    assert_eq!(f.restore(&c), fmi2Status::Error);
}

fn analytic_unit(kind: UnitKind) -> DriveUnit<ConstantStiffnessMesh> {
    let (gp, gg) = (0.04286, 0.06715);
    let mesh = ConstantStiffnessMesh::new(2e8, 100.0, gp, gg, Clearance::Separating).unwrap();
    let drive = Drivetrain::from_pair(
        &helical_gear_mesh::GearPair::paper_table1(),
        &helical_gear_mesh::DriveLine::paper_table1(),
    )
    .unwrap();
    DriveUnit::new(kind, mesh, drive, UnitStepping::Rk4 { steps_per_mesh_period: 64 }).unwrap()
}

#[test]
fn flipped_bits_in_a_unit_snapshot_are_refused_or_harmless() {
    let mut u = analytic_unit(UnitKind::Pair);
    u.set_state(&[0.01, -0.006, 100.0, -63.8]).unwrap();
    u.set_inputs(UnitInputs { tau_p: 500.0, tau_g: -780.0, ..UnitInputs::default() }).unwrap();
    let snap = u.snapshot();
    let text = snap.to_text();
    assert_eq!(UnitSnapshot::from_text(&text).unwrap(), snap);
    let bytes = text.as_bytes();
    let (mut refused, mut same) = (0, 0);
    for i in 0..bytes.len() {
        for bit in 0..7 {
            let mut c = bytes.to_vec();
            c[i] ^= 1 << bit;
            let Ok(t) = std::str::from_utf8(&c) else { continue };
            match UnitSnapshot::from_text(t) {
                Err(_) => refused += 1,
                Ok(s) => {
                    // Only a change of spelling that keeps every value (1e-5 for 1E-5) passes.
                    assert_eq!(s, snap, "bit {bit} of byte {i} gave another snapshot");
                    same += 1;
                }
            }
        }
    }
    eprintln!("unit snapshot: {refused} flips refused, {same} harmless");
    assert!(refused > 7 * bytes.len() / 2);
    // A value beyond its range with a matching checksum is refused by the restore.
    let mut bad = snap.clone();
    bad.state[2] = 1e308;
    let back = UnitSnapshot::from_text(&bad.to_text()).unwrap();
    let e = u.restore(&back).unwrap_err().to_string();
    assert!(e.contains("`w_p`") && numbers_are_short(&e), "{e}");
    bad = snap.clone();
    bad.inputs.values.tau_p = -1e300;
    assert!(u.restore(&bad).is_err());
    assert_eq!(u.snapshot(), snap, "a refused restore changes nothing");
    // Another format version.
    let other = text.replacen("\"format_version\":2", "\"format_version\":3", 1);
    assert!(UnitSnapshot::from_text(&other).unwrap_err().contains("format version"));
}

#[test]
fn c_api_unit_snapshot_with_altered_value_is_refused() {
    let u = unsafe { hgm_unit_create(2, null(), null(), HgmFidelity::Full as i32, 128, 0.0, 0.0) };
    if u.is_null() {
        panic!("{}", unsafe { CStr::from_ptr(hgm_unit_last_error(null())) }.to_string_lossy());
    }
    unsafe {
        let text = CStr::from_ptr(hgm_unit_snapshot(u)).to_string_lossy().into_owned();
        assert!(text.starts_with("{\"format_version\":2,\"checksum\":"), "{text}");
        let altered = text.replacen("\"time\":0.0", "\"time\":1.0", 1);
        assert_ne!(altered, text);
        let c = CString::new(altered).unwrap();
        assert_eq!(hgm_unit_restore(u, c.as_ptr()), HgmStatus::InvalidArgument);
        let m = CStr::from_ptr(hgm_unit_last_error(u)).to_string_lossy().into_owned();
        assert!(m.contains("checksum"), "{m}");
        let c = CString::new(text).unwrap();
        assert_eq!(hgm_unit_restore(u, c.as_ptr()), HgmStatus::Ok);
        let bad = HgmUnitInputs { torque: 1e308, ..HgmUnitInputs::default() };
        assert_eq!(hgm_unit_set_inputs(u, &bad), HgmStatus::InvalidArgument);
        hgm_unit_free(u);
    }
}

#[test]
fn two_threads_on_one_instance_get_errors_not_a_crash() {
    let f = Fmu::new();
    f.init();
    let c = f.0 as usize;
    let hammer = |seed: f64| {
        move || {
            let c = c as fmi2Component;
            let (mut ok, mut refused) = (0, 0);
            let ins: Vec<u32> = ["phi_p", "phi_g", "w_p", "w_g"].iter().map(|n| vr(n)).collect();
            let outs: Vec<u32> = OUTS.iter().map(|n| vr(n)).collect();
            for k in 0..150 {
                let v = [0.01 + seed * 1e-4 + k as f64 * 1e-6, -0.0060851, 100.0, -63.83];
                let mut o = [0.0; 8];
                for s in unsafe {
                    [
                        fmi2SetReal(c, ins.as_ptr(), 4, v.as_ptr()),
                        fmi2GetReal(c, outs.as_ptr(), 8, o.as_mut_ptr()),
                    ]
                } {
                    match s {
                        fmi2Status::Ok => ok += 1,
                        fmi2Status::Error => refused += 1,
                        other => panic!("status {other:?}"),
                    }
                }
            }
            (ok, refused)
        }
    };
    let a = std::thread::spawn(hammer(1.0));
    let b = std::thread::spawn(hammer(2.0));
    let (ra, rb) = (a.join().unwrap(), b.join().unwrap());
    eprintln!("thread A: {ra:?}, thread B: {rb:?} (ok, refused)");
    assert_eq!(ra.0 + ra.1 + rb.0 + rb.1, 600);
    // A refused call changes nothing: the instance works on (reset if a call errored).
    if f.get(&OUTS).is_err() {
        f.recover();
    }
    assert_eq!(f.set(&["phi_p", "phi_g", "w_p", "w_g"], &LOADED), fmi2Status::Ok);
    assert!(f.get(&OUTS).unwrap().iter().all(|v| v.is_finite()));
}

#[test]
fn error_messages_carry_short_numbers_and_name_the_key() {
    let mut pair = serde_json::to_value(helical_gear_mesh::GearPair::paper_table1()).unwrap();
    pair["face_width_m"] = serde_json::json!(1e300);
    let j = CString::new(pair.to_string()).unwrap();
    assert!(unsafe { hgm_create_from_json(j.as_ptr()) }.is_null());
    let m = last_error(null());
    assert!(m.contains("face_width_m") && numbers_are_short(&m), "{m}");
    let mut u = analytic_unit(UnitKind::Stage);
    let e = u.set_inputs(UnitInputs { w_1: 1e300, ..UnitInputs::default() }).unwrap_err();
    let e = e.to_string();
    assert!(e.contains("`w_1`") && numbers_are_short(&e), "{e}");
}

#[test]
fn two_threads_on_one_c_api_handle_get_errors_not_a_crash() {
    let h = hgm_create_default() as usize;
    let hammer = |seed: f64| {
        move || {
            let h = h as *mut HgmModel;
            let (mut ok, mut refused) = (0, 0);
            for k in 0..100 {
                let mut o = HgmOutputs::default();
                let phi_p = 0.01 + seed * 1e-4 + k as f64 * 1e-6;
                match unsafe { hgm_evaluate(h, phi_p, -0.0060851, 100.0, -63.83, &mut o) } {
                    HgmStatus::Ok => {
                        assert!(o.m_f_p.is_finite());
                        ok += 1;
                    }
                    HgmStatus::InvalidArgument => refused += 1,
                    other => panic!("status {other:?}"),
                }
            }
            (ok, refused)
        }
    };
    let a = std::thread::spawn(hammer(1.0));
    let b = std::thread::spawn(hammer(2.0));
    let (ra, rb) = (a.join().unwrap(), b.join().unwrap());
    eprintln!("C API thread A: {ra:?}, thread B: {rb:?} (ok, refused)");
    assert_eq!(ra.0 + ra.1 + rb.0 + rb.1, 200);
    let mut o = HgmOutputs::default();
    let h = h as *mut HgmModel;
    assert_eq!(unsafe { hgm_evaluate(h, 0.01, -0.0060851, 100.0, -63.83, &mut o) }, HgmStatus::Ok);
    unsafe { hgm_free(h) };
}
