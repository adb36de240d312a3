//! Stress test: huge hub angles lose no precision (docs/robustness.md, "Stress tests").
//!
//! The reference is independent of `helical_gear_mesh::numeric`: TE = Φp·g_p + Φg·g_g exactly
//! in i128 integer arithmetic on the doubles' mantissas, and the pinion phase Φp mod 2π/z_p in
//! 192-bit fixed point with 1/(2π) to 128 bits (hex digits of 2/π, checked against a
//! 124-bit π below). At Φ ≈ 10¹² rad the mesh outputs equal those at the small angles of the
//! reference state, TE to 10⁻¹⁸ m; the naive f64 reduction of the previous code is off by
//! micrometres there, which the test measures and prints.

mod common;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::capi::{HgmOutputs, HgmStatus, hgm_create_default, hgm_evaluate, hgm_free};
use helical_gear_mesh::geometry::PairGeometry;
use helical_gear_mesh::mesh::{Mesh, MeshOptions, MeshOutputs, MeshState};

use common::table1_geometry as geometry;

/// ⌊2¹²⁸/(2π)⌋: the hex digits of 2/π (0.A2F9836E4E441529FC2757D1F534DDC0…) shifted by two.
const INV_TWO_PI_128: u128 = 0x28be_60db_9391_054a_7f09_d5f4_7d4d_3770;
/// ⌊π·2¹²⁴⌋ (0x3.243F6A8885A308D313198A2E0370734…), only to check the constant above.
const PI_124: u128 = 0x3243_f6a8_885a_308d_3131_98a2_e037_0734;

/// x = m·2^e exactly, m a signed integer of at most 53 bits.
fn split(x: f64) -> (i128, i32) {
    if x == 0.0 {
        return (0, 0);
    }
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i128;
    let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | (1 << 52), exp - 1075) };
    (if x < 0.0 { -m } else { m }, e)
}

/// a·b + c·d exactly, rounded once to f64 (i128; exponents of the two products within 20).
fn exact_dot(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let (ma, ea) = split(a);
    let (mb, eb) = split(b);
    let (mc, ec) = split(c);
    let (md, ed) = split(d);
    let (e1, e2) = (ea + eb, ec + ed);
    let base = e1.min(e2);
    assert!((e1 - e2).abs() <= 20, "exponents too far apart for the i128 reference");
    let sum = ((ma * mb) << (e1 - base)) + ((mc * md) << (e2 - base));
    // i128 → f64 rounds to nearest; the power of two is exact.
    (sum as f64) * 2f64.powi(base)
}

/// (r, k): Φ = k·2π/z + r with k the nearest integer, from x = Φ·z/(2π) in fixed point.
fn exact_reduce(phi: f64, z: u32) -> (f64, i64) {
    let (m, e) = split(phi.abs());
    assert!((-64..0).contains(&e), "reference covers 2^-12 ≤ |φ| < 2^53 only");
    let u = (m as u128) * z as u128; // < 2^61
    // u·INV as top·2^64 + low (192 bits).
    let (a, b) = (INV_TWO_PI_128 >> 64, INV_TWO_PI_128 & u64::MAX as u128);
    let p0 = u * b;
    let p1 = u * a;
    let top = p1 + (p0 >> 64);
    // x = top·2^(e−64) (+ below 2^(e−128)): integer part top >> s, fraction the rest.
    let s = (64 - e) as u32;
    let int = top >> s;
    let frac = (top & ((1u128 << s) - 1)) as f64 / 2f64.powi(s as i32);
    let (k, f) = if frac > 0.5 { (int as i64 + 1, frac - 1.0) } else { (int as i64, frac) };
    let pitch = std::f64::consts::TAU / z as f64;
    let (k, r) = (k, f * pitch);
    if phi < 0.0 { (-r, -k) } else { (r, k) }
}

#[test]
fn reference_constants_are_consistent() {
    // π·(1/(2π)) = ½: (π·2¹²⁴)·(2¹²⁸/(2π)) ≈ 2²⁵¹, checked on the leading 64 bits of each.
    let prod = (PI_124 >> 64) * (INV_TWO_PI_128 >> 64); // ≈ 2^(251−128) = 2^123
    let half = 1u128 << 123;
    let rel = (prod as f64 - half as f64).abs() / half as f64;
    assert!(rel < 1e-18, "{rel:e}");
    assert_eq!(INV_TWO_PI_128 as f64 / 2f64.powi(128), 1.0 / std::f64::consts::TAU);
    // The reduction reference on exactly known cases.
    let (r, k) = exact_reduce(1.0, 30);
    assert_eq!(k, 5);
    assert!((r - (1.0 - 5.0 * std::f64::consts::TAU / 30.0)).abs() < 1e-15);
    let (r, k) = exact_reduce(-0.3, 30);
    assert_eq!(k, -1);
    assert!((r - (-0.3 + std::f64::consts::TAU / 30.0)).abs() < 1e-15);
}

/// Huge states (Φp, Φg) of the Table 1 pair near a target TE, and their exact small-angle
/// twins from the independent reference.
fn huge_states(geo: &PairGeometry) -> Vec<(MeshState, MeshState)> {
    let (gp, gg) = (geo.pinion.rb, geo.gear.rb);
    let mut out = Vec::new();
    for (phi_p, te) in [
        (1e12, 20e-6),
        (-1e12 + 0.123, 31e-6),
        (7.77e11, 25e-6),
        (1.6e11 * std::f64::consts::TAU, 28e-6),
        (3.3e9, 12e-6),
        (1.0e12 + 0.05, -230e-6), // back flanks
    ] {
        let phi_g = geo.phi_g_for_te(phi_p, te);
        let te_ref = exact_dot(phi_p, gp, phi_g, gg);
        let (rp, _) = exact_reduce(phi_p, geo.pinion.z);
        let rg = (te_ref - rp * gp) / gg;
        let w = (150.0, -150.0 * 30.0 / 47.0);
        out.push((
            MeshState { phi_p, phi_g, w_p: w.0, w_g: w.1, ..Default::default() },
            MeshState { phi_p: rp, phi_g: rg, w_p: w.0, w_g: w.1, ..Default::default() },
        ));
    }
    out
}

/// The reduction of the previous code (plain f64 pitches), for the before/after report.
fn naive_te(geo: &PairGeometry, phi_p: f64, phi_g: f64) -> f64 {
    let pp = geo.pinion.angular_pitch();
    let pg = geo.gear.angular_pitch();
    let k = (phi_p / pp).round();
    let rp = (-k).mul_add(pp, phi_p);
    let rg = k.mul_add(pg, phi_g);
    rp * geo.pinion.rb + rg * geo.gear.rb
}

fn assert_same(big: &MeshOutputs, small: &MeshOutputs, what: &str) {
    assert!((big.te - small.te).abs() <= 1e-18, "{what}: TE {:e} vs {:e}", big.te, small.te);
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale.max(1.0);
    for (a, b, n) in [
        (big.m_f_p, small.m_f_p, "M_F_p"),
        (big.m_f_g, small.m_f_g, "M_F_g"),
        (big.m_d_p, small.m_d_p, "M_D_p"),
        (big.m_d_g, small.m_d_g, "M_D_g"),
    ] {
        assert!(close(a, b, b.abs()), "{what}: {n} {a} vs {b}");
    }
    assert!(close(big.f_n, small.f_n, small.f_n), "{what}: F_n");
    assert!(
        close(big.p_max, small.p_max, small.p_max),
        "{what}: p_max {} vs {}",
        big.p_max,
        small.p_max
    );
    assert_eq!(
        (big.n_pairs, big.tip_contact, big.separated, big.back_contact),
        (small.n_pairs, small.tip_contact, small.separated, small.back_contact),
        "{what}: flags"
    );
}

#[test]
fn mesh_outputs_at_1e12_rad_equal_the_exact_small_angle_state() {
    let geo = geometry();
    let mut model = Mesh::new(&GearPair::paper_table1(), MeshOptions::default()).unwrap();
    let mut worst_new: f64 = 0.0;
    let mut worst_old: f64 = 0.0;
    for (big, small) in huge_states(&geo) {
        let te_ref = exact_dot(big.phi_p, geo.pinion.rb, big.phi_g, geo.gear.rb);
        // Fresh solver state for both (warm starts must not matter beyond 1e-9 anyway).
        let ob = model.evaluate(&big).unwrap();
        let os = model.evaluate(&small).unwrap();
        assert_eq!(ob.te, te_ref, "TE of Φp = {:e} is not the correctly rounded value", big.phi_p);
        assert_same(&ob, &os, &format!("Φp = {:e}", big.phi_p));
        worst_new = worst_new.max((ob.te - te_ref).abs());
        worst_old = worst_old.max((naive_te(&geo, big.phi_p, big.phi_g) - te_ref).abs());
    }
    eprintln!(
        "TE error at up to 1e12 rad: {worst_new:e} m now, {worst_old:e} m with the naive f64 \
         reduction"
    );
    assert!(worst_old > 1e-7, "the naive reduction should be visibly off ({worst_old:e})");
}

#[test]
fn table_fidelity_and_dynamics_te_at_1e12_rad() {
    let geo = geometry();
    // The table path has its own reduction: a coarse table is enough to compare big and small.
    let options = MeshOptions {
        fidelity: helical_gear_mesh::mesh::Fidelity::Table,
        slices: 60,
        table_phase_points: 16,
        table_te_points: 12,
        ..MeshOptions::default()
    };
    let mut model = Mesh::new(&GearPair::paper_table1(), options).unwrap();
    for (big, small) in huge_states(&geo) {
        let ob = model.evaluate(&big).unwrap();
        let os = model.evaluate(&small).unwrap();
        assert_same(&ob, &os, &format!("table, Φp = {:e}", big.phi_p));
    }
}

/// Whole turns of both gears (pinion N·z_g turns, gear N·z_p turns, i.e.
/// k = N·z_p·z_g pitches) keep the physical state; the outputs at the shifted angles agree
/// with the small ones to within what the rounding of the shifted inputs allows:
/// |ΔTE| ≤ ½ulp(Φp)·g_p + ½ulp(Φg)·g_g + |k|·|2π/z_p·g_p − 2π/z_g·g_g| (the last term: the
/// base radii as doubles are not exactly in the ratio z_p/z_g) plus 10⁻¹⁸ m.
#[test]
fn whole_turns_agree_within_the_input_rounding() {
    let geo = geometry();
    let (gp, gg) = (geo.pinion.rb, geo.gear.rb);
    let (zp, zg) = (geo.pinion.z as f64, geo.gear.z as f64);
    let mut model = Mesh::new(&GearPair::paper_table1(), MeshOptions::default()).unwrap();
    let ulp = |x: f64| f64::from_bits(x.abs().to_bits() + 1) - x.abs();
    // Defect of the base radii per pitch, to double precision from the exact reference.
    let pitch_p = helical_gear_mesh::numeric::Pitch::of_teeth(geo.pinion.z);
    let pitch_g = helical_gear_mesh::numeric::Pitch::of_teeth(geo.gear.z);
    let defect = exact_dot(pitch_p.hi, gp, -pitch_g.hi, gg) + pitch_p.lo * gp - pitch_g.lo * gg;
    let mut worst_ratio: f64 = 0.0;
    for n in [1e3, 1e6, 1e9, 3.386e9] {
        let k = n * zp * zg;
        for (phi0, te0) in [(0.0, 20e-6), (0.07, 30e-6), (-0.05, 5e-6)] {
            let small = MeshState {
                phi_p: phi0,
                phi_g: geo.phi_g_for_te(phi0, te0),
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            };
            // Φ = φ + k·pitch, rounded once (double-double pitch).
            let shift = |phi: f64, p: &helical_gear_mesh::numeric::Pitch, sign: f64| {
                let (h, e) = helical_gear_mesh::numeric::two_prod(sign * k, p.hi);
                h + (e + sign * k * p.lo + phi)
            };
            let big = MeshState {
                phi_p: shift(small.phi_p, &pitch_p, 1.0),
                phi_g: shift(small.phi_g, &pitch_g, -1.0),
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            };
            let bound =
                0.5 * ulp(big.phi_p) * gp + 0.5 * ulp(big.phi_g) * gg + (k * defect).abs() + 1e-18;
            let ob = model.evaluate(&big).unwrap();
            let os = model.evaluate(&small).unwrap();
            let d = (ob.te - os.te).abs();
            assert!(d <= bound, "N = {n:e}: |ΔTE| = {d:e} > bound {bound:e}");
            worst_ratio = worst_ratio.max(d / bound);
            // The torques lie within what the TE and phase perturbation allow: the spread of
            // M_F,p over the box (φ ± ulp(Φp), TE ± bound) at the small angles.
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for a in [-1.0, 0.0, 1.0] {
                for b in [-1.0, 0.0, 1.0] {
                    let phi = phi0 + a * ulp(big.phi_p);
                    let s = MeshState {
                        phi_p: phi,
                        phi_g: geo.phi_g_for_te(phi, os.te + b * bound),
                        w_p: 0.0,
                        w_g: 0.0,
                        ..Default::default()
                    };
                    let m = model.evaluate(&s).unwrap().m_f_p;
                    lo = lo.min(m);
                    hi = hi.max(m);
                }
            }
            let slack = 1e-9 * hi.abs().max(1.0);
            assert!(
                ob.m_f_p >= lo - slack && ob.m_f_p <= hi + slack,
                "N = {n:e}: M_F_p {} outside [{lo}, {hi}]",
                ob.m_f_p
            );
        }
    }
    eprintln!("whole turns: largest |ΔTE|/bound = {worst_ratio:.3}");
}

#[test]
fn c_api_at_1e12_rad() {
    let geo = geometry();
    let h = hgm_create_default();
    assert!(!h.is_null());
    for (big, small) in huge_states(&geo) {
        let mut ob = HgmOutputs::default();
        let mut os = HgmOutputs::default();
        unsafe {
            let s = hgm_evaluate(h, big.phi_p, big.phi_g, big.w_p, big.w_g, &mut ob);
            assert_eq!(s, HgmStatus::Ok);
            let s = hgm_evaluate(h, small.phi_p, small.phi_g, small.w_p, small.w_g, &mut os);
            assert_eq!(s, HgmStatus::Ok);
        }
        assert!((ob.te - os.te).abs() <= 1e-18);
        assert!((ob.m_f_p - os.m_f_p).abs() <= 1e-9 * os.m_f_p.abs().max(1.0));
        assert!((ob.m_f_g - os.m_f_g).abs() <= 1e-9 * os.m_f_g.abs().max(1.0));
        assert_eq!(ob.n_pairs, os.n_pairs);
    }
    unsafe { hgm_free(h) };
}

#[test]
fn fmu_at_1e12_rad() {
    use helical_gear_mesh::fmi2::exports::*;
    use helical_gear_mesh::fmi2::models::mesh::{by_name, guid};
    use helical_gear_mesh::fmi2::types::*;
    let vr = |n: &str| by_name(n).unwrap().vr;
    let inputs: Vec<u32> = ["phi_p", "phi_g", "w_p", "w_g"].iter().map(|n| vr(n)).collect();
    let outputs: Vec<u32> =
        ["TE", "M_F_p", "M_F_g", "M_D_p", "F_n"].iter().map(|n| vr(n)).collect();
    let geo = geometry();
    let g = std::ffi::CString::new(guid()).unwrap();
    unsafe {
        let c = fmi2Instantiate(
            c"big".as_ptr(),
            FMI2_CO_SIMULATION,
            g.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            FMI2_FALSE,
            FMI2_FALSE,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::Ok);
        let eval = |s: &MeshState| {
            let v = [s.phi_p, s.phi_g, s.w_p, s.w_g];
            assert_eq!(fmi2SetReal(c, inputs.as_ptr(), 4, v.as_ptr()), fmi2Status::Ok);
            let mut o = [0.0; 5];
            assert_eq!(fmi2GetReal(c, outputs.as_ptr(), 5, o.as_mut_ptr()), fmi2Status::Ok);
            o
        };
        for (big, small) in huge_states(&geo) {
            let (ob, os) = (eval(&big), eval(&small));
            assert!((ob[0] - os[0]).abs() <= 1e-18, "TE {:e} vs {:e}", ob[0], os[0]);
            for i in 1..5 {
                assert!((ob[i] - os[i]).abs() <= 1e-9 * os[i].abs().max(1.0), "{ob:?} vs {os:?}");
            }
        }
        fmi2FreeInstance(c);
    }
}
