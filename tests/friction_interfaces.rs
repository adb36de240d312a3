//! The mesh friction option at the interfaces: its JSON names, and the C API's
//! `hgm_set_friction`: a valid option turns the loss outputs on at a running state, a bad one
//! is refused with a message naming the key and leaves the handle as it was, NULL and `none`
//! turn it off.

use std::ffi::{CStr, CString};
use std::ptr::null;

use helical_gear_mesh::capi::*;
use helical_gear_mesh::mesh::{Friction, FrictionModel};

/// A loaded, running state of Table 1: φp = 0.01 rad at about 100 N·m, ω_p = 100 rad/s with
/// the gear at the rigid ratio.
const STATE: [f64; 4] = [0.01, -0.0060851, 100.0, -63.83];

fn evaluate(h: *mut HgmModel) -> HgmOutputs {
    let mut out = HgmOutputs::default();
    let [a, b, c, d] = STATE;
    assert_eq!(unsafe { hgm_evaluate(h, a, b, c, d, &mut out) }, HgmStatus::Ok);
    out
}

fn last_error(h: *mut HgmModel) -> String {
    unsafe { CStr::from_ptr(hgm_last_error(h)) }.to_string_lossy().into_owned()
}

#[test]
fn every_model_name_parses_and_round_trips() {
    for model in [FrictionModel::None, FrictionModel::Constant, FrictionModel::IsoTr14179_2] {
        let text = format!("{{\"model\": \"{}\"}}", model.name());
        let f = Friction::from_json(&text).unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(f.model, model);
        assert_eq!(Friction::from_json(&f.to_json()).unwrap(), f);
    }
    assert_eq!(Friction::from_json("none").unwrap(), Friction::none());
    assert_eq!(Friction::from_json("").unwrap(), Friction::none());
}

#[test]
fn set_friction_turns_the_loss_on_and_off() {
    let h = hgm_create_default();
    assert!(!h.is_null());
    let plain = evaluate(h);
    assert_eq!((plain.p_loss, plain.m_r_p, plain.eta_mesh), (0.0, 0.0, 1.0));

    let json = CString::new(r#"{"model": "constant", "mu": 0.05}"#).unwrap();
    assert_eq!(unsafe { hgm_set_friction(h, json.as_ptr()) }, HgmStatus::Ok);
    let with = evaluate(h);
    assert!(with.p_loss > 0.0, "P_loss = {}", with.p_loss);
    assert!(with.eta_mesh > 0.9 && with.eta_mesh < 1.0, "eta_mesh = {}", with.eta_mesh);
    assert!(with.m_r_p != 0.0 && with.m_r_g != 0.0);
    // The heat splits the loss; the friction torques are inside M_F.
    assert!(((with.q_p + with.q_g) - with.p_loss).abs() <= 1e-9 * with.p_loss);
    assert!(((with.m_f_p - with.m_r_p) - plain.m_f_p).abs() < 1e-6 * plain.m_f_p.abs());

    // NULL: no friction again, bit for bit the frictionless outputs (a fresh warm start
    // both times).
    assert_eq!(unsafe { hgm_set_friction(h, null()) }, HgmStatus::Ok);
    let off = evaluate(h);
    assert_eq!(off.p_loss, 0.0);
    assert_eq!(off.m_f_p.to_bits(), plain.m_f_p.to_bits());
    let none = CString::new("none").unwrap();
    assert_eq!(unsafe { hgm_set_friction(h, none.as_ptr()) }, HgmStatus::Ok);
    assert_eq!(evaluate(h).m_f_p.to_bits(), plain.m_f_p.to_bits());
    unsafe { hgm_free(h) };
}

#[test]
fn set_friction_keeps_the_mesh_damping() {
    let h = hgm_create_default();
    assert_eq!(unsafe { hgm_set_d_mesh(h, 0.0) }, HgmStatus::Ok);
    let json = CString::new(r#"{"model": "constant", "mu": 0.05}"#).unwrap();
    assert_eq!(unsafe { hgm_set_friction(h, json.as_ptr()) }, HgmStatus::Ok);
    let mut out = HgmOutputs::default();
    // A TE rate of several m/s: no damping torque with d_mesh = 0.
    assert_eq!(unsafe { hgm_evaluate(h, 0.01, -0.0060851, 100.0, 0.0, &mut out) }, HgmStatus::Ok);
    assert_eq!(out.m_d_p, 0.0);
    unsafe { hgm_free(h) };
}

#[test]
fn bad_friction_is_refused_with_the_key_and_changes_nothing() {
    let h = hgm_create_default();
    let good = CString::new(r#"{"model": "constant", "mu": 0.05}"#).unwrap();
    assert_eq!(unsafe { hgm_set_friction(h, good.as_ptr()) }, HgmStatus::Ok);
    let before = evaluate(h);
    for (text, key) in [
        (r#"{"model": "constant", "mu": 2}"#, "friction.mu"),
        (r#"{"model": "constant", "muu": 0.05}"#, "muu"),
        (r#"{"model": "coulomb"}"#, "coulomb"),
        (r#"{"model": "constant", "regularisation_speed_m_s": 0}"#, "regularisation_speed_m_s"),
        ("{not json", "friction JSON"),
    ] {
        let json = CString::new(text).unwrap();
        assert_eq!(unsafe { hgm_set_friction(h, json.as_ptr()) }, HgmStatus::InvalidArgument);
        let m = last_error(h);
        assert!(m.contains("hgm_set_friction") && m.contains(key), "{text}: {m}");
        // The previous option holds.
        assert_eq!(evaluate(h).p_loss.to_bits(), before.p_loss.to_bits(), "{text}");
    }
    // Not UTF-8.
    let bytes = CString::new(vec![b'{', 0xff, b'}']).unwrap();
    assert_eq!(unsafe { hgm_set_friction(h, bytes.as_ptr()) }, HgmStatus::InvalidArgument);
    assert!(last_error(h).contains("UTF-8"));
    // A NULL handle.
    assert_eq!(
        unsafe { hgm_set_friction(std::ptr::null_mut(), good.as_ptr()) },
        HgmStatus::InvalidArgument
    );
    let m = unsafe { CStr::from_ptr(hgm_last_error(std::ptr::null())) }.to_string_lossy();
    assert!(m.contains("NULL"), "{m}");
    unsafe { hgm_free(h) };
}
