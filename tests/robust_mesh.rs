//! The stated validity range of the mesh state (`mesh::validity`) at every interface: flank
//! overlaps beyond 0.2·m_n are an error naming TE, the mesh phase and the range (never a huge
//! torque or "separated" with a success status), pinion angles beyond 2⁵³ pitches an error
//! naming the angle and the bound (never an integer wrap); the searches over TE end at the
//! range. Table 1 (embedded compliance), coarse slices and tables.

mod common;

use std::ffi::CString;
use std::ptr::null;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::capi::*;
use helical_gear_mesh::contact::ContactSolver;
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::mesh::{by_name, guid};
use helical_gear_mesh::fmi2::models::unit::PAIR;
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::mesh::validity::MAX_OVERLAP_MN;
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Fidelity, Mesh, MeshError, MeshState, MeshTorques, equilibrium,
};
use helical_gear_mesh::numeric::{MAX_PITCHES, Pitch, two_prod};

use common::{coarse_options as options, table1_pitch as pitch};

fn model(fidelity: Fidelity) -> Mesh {
    Mesh::new(&GearPair::paper_table1(), options(fidelity)).expect("Table 1 model")
}

fn state(m: &Mesh, phi_p: f64, te: f64) -> MeshState {
    MeshState {
        phi_p,
        phi_g: m.geometry().phi_g_for_te(phi_p, te),
        w_p: 100.0,
        w_g: -63.83,
        ..Default::default()
    }
}

/// Asserts that `r` is the out-of-range error of TE outside the validity range (no load-solver
/// cause) and that its message names TE, the phase and the range.
fn assert_out_of_range(r: Result<impl std::fmt::Debug, MeshError>, te: f64, what: &str) {
    match r {
        Err(e @ MeshError::OutOfRange { cause: None, .. }) => {
            let MeshError::OutOfRange { te: t, range, phase, .. } = e else { unreachable!() };
            assert_eq!(t.to_bits(), te.to_bits(), "{what}");
            assert!(phase.abs() <= 0.5 * pitch() * (1.0 + 1e-12), "{what}: phase {phase}");
            let msg = e.to_string();
            for part in ["TE = ", "mesh phase", "validity range", &format!("{:.4e}", range.1)] {
                assert!(msg.contains(part), "{what}: `{part}` missing in {msg}");
            }
        }
        other => panic!("{what}: expected OutOfRange without cause, got {other:?}"),
    }
}

/// Before the range existed, TE = 2–10 mm (overlaps of 0.7–3·m_n) gave 20–30 kN·m with a
/// success status; now every such state, at full and table fidelity, through `evaluate`,
/// `torques` and `mesh_jacobian`, is an error.
#[test]
fn overlap_of_2_mm_is_out_of_range_not_30_knm() {
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = model(fidelity);
        for k in 0..5 {
            let phi = pitch() * (k as f64 / 5.0 - 0.5);
            for te in [2e-3, 5e-3, 10e-3] {
                let s = state(&m, phi, te);
                let te = m.geometry().transmission_error(s.phi_p, s.phi_g);
                let what = format!("{fidelity:?}, φp {phi:.4}, TE {te:e}");
                assert_out_of_range(m.evaluate(&s), te, &what);
                assert_out_of_range(m.torques(&s), te, &what);
                assert_out_of_range(m.mesh_jacobian(&s), te, &what);
                assert_out_of_range(m.evaluate_full(&s), te, &what);
            }
        }
    }
}

/// Beyond about 2 cm the contact search finds no pair at all: the teeth passed through each
/// other and were reported "separated" with zero torque. Now no state beyond the range is
/// ever an `Ok` (separated or not), on either flank, and just inside it the mesh is loaded.
#[test]
fn teeth_passed_through_are_never_separated() {
    let mut full = model(Fidelity::Full);
    let mut table = model(Fidelity::Table);
    let v = *full.validity();
    let mn = GearPair::paper_table1().normal_module_m;
    assert_eq!(v.te_max, MAX_OVERLAP_MN * mn);
    assert_eq!(v.te_min, -full.geometry().backlash_te - MAX_OVERLAP_MN * mn);
    for k in 0..4 {
        let phi = pitch() * (k as f64 / 4.0 - 0.5) + 1e-3;
        let mut tes = vec![v.te_max * (1.0 + 1e-12), -v.te_min + 1.0, v.te_min - 1e-9];
        tes.extend((0..12).map(|i| v.te_max * 1.5f64.powi(i)));
        tes.extend((0..12).map(|i| v.te_min * 1.5f64.powi(i)));
        for m in [&mut full, &mut table] {
            for &te in &tes {
                let s = state(m, phi, te);
                let te = m.geometry().transmission_error(s.phi_p, s.phi_g);
                if v.contains_te(te) {
                    continue;
                }
                assert_out_of_range(m.evaluate(&s), te, &format!("φp {phi:.4}, TE {te:e}"));
            }
            // Just inside both ends: loaded, with torques of the flanks' sign.
            let o = m.evaluate(&state(m, phi, 0.999 * v.te_max)).expect("inside the range");
            assert!(!o.separated && o.m_f_p > 0.0, "{o:?}");
            let o = m.evaluate(&state(m, phi, 0.999 * v.te_min)).expect("inside the range");
            assert!(!o.separated && o.back_contact && o.m_f_p < 0.0, "{o:?}");
        }
    }
}

/// The table's designed range (4× the nominal static TE on the driving flanks, half of that
/// beyond the backlash on the back flanks) lies well inside the validity range: Table 1 needs
/// 0.04·m_n of the 0.2·m_n, and nothing is cut.
#[test]
fn validity_range_contains_the_table_range() {
    let m = model(Fidelity::Table);
    let v = *m.validity();
    let t = m.table().expect("table built");
    let (lo, hi) = t.te_range();
    assert!(t.truncations().is_empty(), "{:?}", t.truncations());
    assert!(v.te_min < lo && hi < v.te_max, "table [{lo:e}, {hi:e}] vs {v:?}");
    // The margin: the designed range is at most a quarter of the bound.
    assert!(hi < 0.25 * v.te_max, "table end {hi:e} vs {:e}", v.te_max);
    let nominal = hi / 4.0;
    eprintln!(
        "validity [{:.1}, {:.1}] µm, table [{:.1}, {:.1}] µm, nominal static TE {:.1} µm \
         = {:.4}·m_n",
        v.te_min * 1e6,
        v.te_max * 1e6,
        lo * 1e6,
        hi * 1e6,
        nominal * 1e6,
        nominal / m.pair().normal_module_m
    );
}

/// The static equilibrium's bracket search ends at the range: a torque no TE inside it can
/// carry is an equilibrium error naming the bound, not an evaluation of crushed teeth; the
/// nominal torque is found as before.
#[test]
fn equilibrium_search_ends_at_the_validity_range() {
    let mut m = model(Fidelity::Full);
    let te_max = m.validity().te_max;
    let eq = equilibrium(&mut m, 0.01, 100.0, 1e-5, &EquilibriumSettings::default())
        .expect("nominal torque");
    assert!(eq.te > 0.0 && eq.te < 0.1 * te_max, "{}", eq.te);
    // 10 MN·m: far beyond what 0.2·m_n of overlap carries (a few kN·m for Table 1).
    for guess in [1e-5, 1.0] {
        match equilibrium(&mut m, 0.01, 1e7, guess, &EquilibriumSettings::default()) {
            Err(MeshError::Equilibrium(msg)) => {
                assert!(msg.contains("validity range") && msg.contains(&format!("{te_max:.4e}")));
                eprintln!("{msg}");
            }
            other => panic!("guess {guess}: {other:?}"),
        }
    }
    match equilibrium(&mut m, 0.01, -1e7, -1e-4, &EquilibriumSettings::default()) {
        Err(MeshError::Equilibrium(msg)) => assert!(msg.contains("validity range"), "{msg}"),
        other => panic!("{other:?}"),
    }
}

/// Angles ≳ 1.9·10¹⁸ rad overflowed an i64 in the contact search (a panic with debug
/// assertions, a wrap in release). Beyond 2⁵³ pinion pitches the angle is now an error naming
/// the angle and the bound, at both fidelities; the contact search alone gives no contacts.
#[test]
fn angle_of_1e19_rad_is_an_error_not_a_wrap() {
    let bound = MAX_PITCHES * Pitch::of_teeth(GearPair::paper_table1().z_p).hi;
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = model(fidelity);
        assert_eq!(m.validity().phi_p_max, bound);
        for phi_p in [1e19, -1e19, 1.9e18, 2.0e16, bound * (1.0 + 1e-15), f64::MAX] {
            let s = state(&m, phi_p, 20e-6);
            for r in [m.evaluate(&s).err(), m.torques(&s).err(), m.mesh_jacobian(&s).err()] {
                match r {
                    Some(MeshError::AngleOutOfRange { name: "phi_p", value, bound: b }) => {
                        assert_eq!((value, b), (phi_p, bound));
                        let msg = r.unwrap().to_string();
                        assert!(msg.contains(&format!("{phi_p:.4e}")), "{msg}");
                        assert!(msg.contains(&format!("{bound:.4e}")), "{msg}");
                    }
                    other => panic!("{fidelity:?}, φp {phi_p:e}: {other:?}"),
                }
            }
        }
    }
    let m = model(Fidelity::Full);
    let cs = ContactSolver::new(m.geometry());
    let zetas = cs.slice_zetas(10);
    let mut out = Vec::new();
    for phi_p in [1e19, -1.9e18, 9.3e18] {
        cs.contacts(phi_p, m.geometry().phi_g_for_te(phi_p, 20e-6), &zetas, &mut out);
        assert!(out.is_empty(), "φp {phi_p:e}: {} contacts", out.len());
    }
}

/// Inside the exact range the reduction is exact up to its bound: at k up to 2⁵³ − 1 pitches
/// (where the quotient φ·z/2π is off by up to two pitches before the correction, and the ulp
/// of φ exceeds a pitch) k is the nearest whole number and the remainder is exact, and the
/// mesh outputs equal those of the reduced small-angle state.
#[test]
fn angles_up_to_2_pow_53_pitches_reduce_exactly() {
    let z = GearPair::paper_table1().z_p;
    let p = Pitch::of_teeth(z);
    for k in [MAX_PITCHES - 1.0, MAX_PITCHES - 12_345.0, 2f64.powi(52) + 7.0, -(2f64.powi(51))] {
        // φ = fl(k·hi): the exact remainder is −(e + k·lo) with k·hi = φ + e.
        let (phi, e) = two_prod(k, p.hi);
        let mut expected = -(e + k * p.lo);
        let mut k = k;
        // fl(k·hi) may lie nearer to the next multiple (its ulp exceeds a pitch near 2⁵³).
        if expected.abs() > 0.5 * p.hi {
            let s = expected.signum();
            expected = (expected - s * p.hi) - s * p.lo;
            k += s;
        }
        let (r, kk) = p.reduce(phi);
        assert_eq!(kk, k, "k {k:e}");
        assert!((r - expected).abs() <= 2e-17, "k {k:e}: {r:e} vs {expected:e}");
        assert!(r.abs() <= 0.5 * p.hi * (1.0 + 1e-12), "k {k:e}: |r| {r:e}");
    }
    let mut m = model(Fidelity::Full);
    for phi_p in [0.999 * p.max_angle(), -1.0e15, 1.0e12] {
        let big = loaded_huge_state(&m, phi_p);
        let te = m.geometry().transmission_error(big.phi_p, big.phi_g);
        let phi_p = big.phi_p;
        let (rp, _) = p.reduce(phi_p);
        let small = MeshState { phi_p: rp, phi_g: m.geometry().phi_g_for_te(rp, te), ..big };
        let a = m.evaluate(&big).expect("inside the exact range");
        m.forget_warm_start();
        let b = m.evaluate(&small).expect("small angles");
        m.forget_warm_start();
        assert_eq!(a.te, te);
        let tol = 1e-9 * b.m_f_p.abs().max(1.0);
        assert!((a.m_f_p - b.m_f_p).abs() <= tol, "φp {phi_p:e}: {} vs {}", a.m_f_p, b.m_f_p);
    }
}

/// A state near pinion angle `phi_p` (rad) with 1 µm < TE < 0.9·TE_max. At 10¹⁵ rad an
/// angle's ulp is 0.125 rad, a TE step of centimetres: the pair of doubles is found by
/// stepping φp by ulps and taking φg nearest to TE = 20 µm, until the exact TE lands in the
/// window (g_p/g_g = 30/47 puts the reachable TEs on a lattice of ulp(φg)·g_g/47, 357 µm at
/// 2⁵³ pitches).
fn loaded_huge_state(m: &Mesh, phi_p: f64) -> MeshState {
    let geo = m.geometry();
    let mut p = phi_p;
    for _ in 0..100_000 {
        let s = state(m, p, 20e-6);
        let te = geo.transmission_error(s.phi_p, s.phi_g);
        if (1e-6..0.9 * m.validity().te_max).contains(&te) {
            return s;
        }
        p = f64::from_bits(p.to_bits() + 1);
    }
    panic!("no state with a small TE near φp = {phi_p:e}");
}

// --- Interfaces -----------------------------------------------------------------------------

fn vr_of(info: &ModelInfo, name: &str) -> u32 {
    info.by_name(name).unwrap_or_else(|| panic!("no variable {name}")).vr
}

unsafe fn get(c: fmi2Component, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
    let mut out = vec![0.0; vrs.len()];
    let s = unsafe { fmi2GetReal(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
    (s, out)
}

unsafe fn instantiate(guid: &str) -> fmi2Component {
    let g = CString::new(guid).unwrap();
    let c = unsafe {
        fmi2Instantiate(c"robust".as_ptr(), FMI2_CO_SIMULATION, g.as_ptr(), null(), null(), 0, 0)
    };
    assert!(!c.is_null());
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::Ok);
    }
    c
}

/// A Pair driven out of the range within one step (1 MN·m on the pinion hub) returns
/// fmi2Discard, and its state is bit for bit the state at the start of the step.
#[test]
fn fmu_unit_step_out_of_range_is_discarded_and_rolled_back() {
    unsafe {
        let c = instantiate(PAIR.guid());
        let names = ["phi_p", "phi_g", "w_p", "w_g", "TE", "M_F_p"];
        let vrs: Vec<u32> = names.iter().map(|n| vr_of(&PAIR, n)).collect();
        assert_eq!(fmi2DoStep(c, 0.0, 1e-4, 1), fmi2Status::Ok);
        let (s, before) = get(c, &vrs);
        assert_eq!(s, fmi2Status::Ok);
        let tau = [vr_of(&PAIR, "tau_p"), vr_of(&PAIR, "tau_g")];
        assert_eq!(fmi2SetReal(c, tau.as_ptr(), 2, [1e6, -1e6].as_ptr()), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(c, 1e-4, 1e-2, 1), fmi2Status::Discard);
        let (s, after) = get(c, &vrs);
        assert_eq!(s, fmi2Status::Ok);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&after), bits(&before), "{after:?} vs {before:?}");
        fmi2FreeInstance(c);
    }
}

/// The mesh element returns fmi2Error for a state outside the range (TE = 2 mm) and for a
/// pinion angle beyond the exact range.
#[test]
fn mesh_element_out_of_range_is_fmi2_error() {
    let gp = GearPair::paper_table1();
    let m = model(Fidelity::Full);
    let vr = |n: &str| by_name(n).unwrap().vr;
    let inputs: Vec<u32> = ["phi_p", "phi_g", "w_p", "w_g"].iter().map(|n| vr(n)).collect();
    let outs: Vec<u32> = ["M_F_p", "TE"].iter().map(|n| vr(n)).collect();
    assert_eq!(gp.z_p, 30);
    for (phi_p, te) in [(0.01, 2e-3), (0.01, -2e-3), (1e19, 20e-6)] {
        unsafe {
            let c = instantiate(guid());
            let v = [phi_p, m.geometry().phi_g_for_te(phi_p, te), 100.0, -63.83];
            let set = fmi2SetReal(c, inputs.as_ptr(), 4, v.as_ptr());
            if phi_p.abs() > 1e15 {
                // Beyond the inputs' stated range (|angle| <= 1e15 rad, inside the exact range
                // of 2^53 pitches) the angle is refused where it enters.
                assert_eq!(set, fmi2Status::Error, "φp {phi_p:e}");
            } else {
                assert_eq!(set, fmi2Status::Ok);
                let (s, _) = get(c, &outs);
                assert_eq!(s, fmi2Status::Error, "φp {phi_p:e}, TE {te:e}");
            }
            fmi2FreeInstance(c);
        }
    }
    // Inside the range: Ok.
    unsafe {
        let c = instantiate(guid());
        let v = [0.01, m.geometry().phi_g_for_te(0.01, 20e-6), 100.0, -63.83];
        assert_eq!(fmi2SetReal(c, inputs.as_ptr(), 4, v.as_ptr()), fmi2Status::Ok);
        let (s, o) = get(c, &outs);
        assert_eq!(s, fmi2Status::Ok);
        assert!(o[0] > 0.0);
        fmi2FreeInstance(c);
    }
}

/// The C API returns an error status with the message for both kinds of state.
#[test]
fn c_api_out_of_range_is_an_error_status_with_the_message() {
    let m = model(Fidelity::Full);
    let h = hgm_create_default();
    assert!(!h.is_null());
    let msg = |h: *const HgmModel| {
        unsafe { std::ffi::CStr::from_ptr(hgm_last_error(h)) }.to_string_lossy().into_owned()
    };
    let mut o = HgmOutputs::default();
    unsafe {
        for (phi_p, te, part, status) in [
            (0.01, 2e-3, "validity range", HgmStatus::ModelError),
            (0.01, 0.05, "validity range", HgmStatus::ModelError),
            (0.01, -3e-3, "validity range", HgmStatus::ModelError),
            // Beyond the inputs' stated range: refused as an argument, naming it.
            (1e19, 20e-6, "phi_p", HgmStatus::InvalidArgument),
        ] {
            let g = m.geometry().phi_g_for_te(phi_p, te);
            let s = hgm_evaluate(h, phi_p, g, 0.0, 0.0, &mut o);
            assert_eq!(s, status, "φp {phi_p:e}, TE {te:e}");
            assert!(msg(h).contains(part), "{}", msg(h));
        }
        let g = m.geometry().phi_g_for_te(0.01, 20e-6);
        assert_eq!(hgm_evaluate(h, 0.01, g, 0.0, 0.0, &mut o), HgmStatus::Ok);
        hgm_free(h);
    }
}
