//! Flank modifications, misalignment and tooth deviations (`helical_gear_mesh::modifications`)
//! against analytic oracles derived in the comments of each test.

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    EquilibriumSettings, MeshModel, MeshOptions, MeshState, equilibrium, face_load,
    k_h_beta_crowned, k_h_beta_iso,
};
use helical_gear_mesh::modifications::{Modifications, ReliefShape, TipRelief};

/// Tooth-pair stiffness per unit contact length of the Winkler tests, N/m² (14 N/(mm·µm),
/// ISO 6336's typical single stiffness c′).
const C_PRIME: f64 = 14e9;

fn winkler_options(slices: usize) -> MeshOptions {
    MeshOptions {
        slices,
        winkler_c_prime: Some(C_PRIME),
        local_contact: false,
        detail: true,
        ..MeshOptions::default()
    }
}

/// Table 1 as a spur pair: in the single-contact zone the loaded pair's contact is
/// involute/involute, so its overlap is TE − separation, and the contact line spans the whole
/// face; the tip relief keeps the neighbouring pairs' tips off the flanks (the tests check it).
fn spur() -> GearPair {
    let mut p = GearPair::paper_table1();
    p.helix_angle_rad = 0.0;
    p
}

fn state(m: &MeshModel, phi_p: f64, te: f64) -> MeshState {
    MeshState { phi_p, phi_g: m.geometry().phi_g_for_te(phi_p, te), w_p: 0.0, w_g: 0.0 }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Zero modifications given explicitly (a zero list of pitch deviations per gear, zero
/// misalignment) run the modification code and must reproduce the unmodified model to the
/// last digit; a pair without the key serialises exactly as before.
#[test]
fn zero_modifications_are_bit_for_bit() {
    let base = GearPair::paper_table1();
    let text = serde_json::to_string(&base).unwrap();
    assert!(!text.contains("modifications"), "default must not be serialised");
    assert_eq!(GearPair::from_json(&text).unwrap(), base);
    let mut zero = base.clone();
    zero.modifications.pinion.pitch_deviations_m = vec![0.0; base.z_p as usize];
    zero.modifications.gear.pitch_deviations_m = vec![0.0; base.z_g as usize];
    zero.modifications.mesh_misalignment_m = 0.0;
    assert!(!zero.modifications.is_default());
    let back = GearPair::from_json(&serde_json::to_string(&zero).unwrap()).unwrap();
    assert_eq!(back, zero);
    let options = MeshOptions { slices: 100, ..MeshOptions::default() };
    let mut a = MeshModel::new(&base, options).unwrap();
    let mut b = MeshModel::new(&zero, options).unwrap();
    let pitch = a.geometry().pinion.angular_pitch();
    for k in 0..12 {
        let phi = pitch * (k as f64 / 4.0 - 1.3) + 40.0 * std::f64::consts::TAU;
        for te in [2e-6, 25e-6, 60e-6] {
            let s = MeshState { w_p: 150.0, w_g: -95.0, ..state(&a, phi, te) };
            let (oa, ob) = (a.evaluate(&s).unwrap(), b.evaluate(&s).unwrap());
            assert_eq!(oa, ob, "φp = {phi}, TE = {te}");
        }
        let ea = equilibrium(&mut a, phi, 100.0, 2e-5, &EquilibriumSettings::default()).unwrap();
        let eb = equilibrium(&mut b, phi, 100.0, 2e-5, &EquilibriumSettings::default()).unwrap();
        assert_eq!(ea.te.to_bits(), eb.te.to_bits());
    }
}

/// Bad input is rejected at construction with the parameter's key and its limit.
#[test]
fn bad_modifications_name_parameter_and_limit() {
    let check = |f: &dyn Fn(&mut Modifications), key: &str, limit: &str| {
        let mut p = GearPair::paper_table1();
        f(&mut p.modifications);
        let e = p.validate().expect_err(key);
        assert_eq!(e.name, key, "{e}");
        assert!(e.allowed.contains(limit), "{e}");
        assert!(MeshModel::new(&p, MeshOptions::default()).is_err());
    };
    // A crowning that removes more than a tenth of the module (more than the tip thickness
    // can give).
    check(&|m| m.pinion.lead_crowning_m = 1e-3, "modifications.pinion.lead_crowning_m", "0.1·m_n");
    check(&|m| m.gear.profile_crowning_m = -1e-6, "modifications.gear.profile_crowning_m", "[0,");
    check(&|m| m.mesh_misalignment_m = f64::NAN, "modifications.mesh_misalignment_m", "finite");
    check(
        &|m| m.pinion.pitch_deviations_m = vec![1e-6; 29],
        "modifications.pinion.pitch_deviations_m",
        "z = 30",
    );
    check(
        &|m| {
            m.gear.pitch_deviations_m = vec![0.0; 47];
            m.gear.pitch_deviations_m[5] = f64::INFINITY;
        },
        "modifications.gear.pitch_deviations_m[5]",
        "finite",
    );
    check(
        &|m| {
            m.pinion.tip_relief =
                TipRelief { amount_m: 5e-6, start_diameter_m: 0.2, shape: ReliefShape::Linear }
        },
        "modifications.pinion.tip_relief.start_diameter_m",
        "tip diameter",
    );
    check(
        &|m| {
            m.gear.end_relief.amount_start_m = 5e-6;
            m.gear.end_relief.length_start_m = 0.02;
        },
        "modifications.gear.end_relief.length_start_m",
        "face width",
    );
    // Unknown keys and wrong types are JSON errors.
    let text = serde_json::to_string(&GearPair::paper_table1()).unwrap();
    let bad = text.replacen('{', r#"{"modifications":{"pinion":{"crowning":1}},"#, 1);
    assert!(GearPair::from_json(&bad).unwrap_err().contains("crowning"));
}

/// Phase of the spur pair where a single tooth pair carries the load in the middle of its
/// path (pair 0 at the pitch point).
const PHI_SINGLE: f64 = 0.0;

/// Linear misalignment f across the face on a Winkler foundation: line load
/// w(ζ) = c_γ·(δ − f·ζ/b₀) with c_γ = c′ per pair (spur, one pair), whose K_Hβ is ISO 6336-1's
/// elastic-foundation result (derivation in `mesh::face_load`): 1 + f·c_γ·b/(2F) with contact
/// over the whole face, √(2f·c_γ·b/F) over part of it.
#[test]
fn misaligned_winkler_pair_matches_elastic_foundation() {
    let f = 20e-6;
    let mut p = spur();
    p.modifications.mesh_misalignment_m = f;
    let mut m = MeshModel::new(&p, winkler_options(200)).unwrap();
    let b = p.face_width_m;
    for (te, full) in [(40e-6, true), (26e-6, true), (12e-6, false), (5e-6, false)] {
        let o = m.evaluate(&state(&m, PHI_SINGLE, te)).unwrap();
        assert_eq!(o.n_pairs, 1, "TE {te}");
        assert!(m.slices().iter().all(|s| s.kind == "involute/involute" || s.q_n_per_m == 0.0));
        let fl = face_load(&m);
        let w_m = o.f_n / b;
        assert!(rel(fl.mean(), w_m) < 1e-12, "mean line load {} vs F/b {w_m}", fl.mean());
        let k_iso = k_h_beta_iso(f, C_PRIME, w_m);
        assert_eq!(k_iso <= 2.0, full);
        // Discretisation: the largest load sits at the first slice centre ζ = Δζ/2, not at
        // ζ = 0, which lowers K by exactly (K − 1)/n over the whole face (the mean of a linear
        // load is exact); over part of the face the patch end adds O(1/n).
        let n = m.slices_per_line() as f64;
        if full {
            let dk = fl.k_h_beta() - k_iso;
            assert!(
                (dk + (k_iso - 1.0) / n).abs() < 1e-9,
                "TE {te}: K {} vs {k_iso}",
                fl.k_h_beta()
            );
        } else {
            // Bound: one slice of the loaded patch, relative.
            let loaded = fl.line_load.iter().filter(|w| **w > 0.0).count() as f64;
            assert!(
                rel(fl.k_h_beta(), k_iso) < 1.0 / loaded,
                "TE {te}: K {} vs {k_iso}",
                fl.k_h_beta()
            );
        }
    }
}

/// Lead crowning C (sum of both gears) on a Winkler foundation: w(ζ) = c_γ·(δ − C·(2ζ/b₀ − 1)²),
/// whose K_Hβ is 1 + c_γ·C·b/(3F) (whole face) or (3/2)·√(C/δ) (central patch).
#[test]
fn crowned_winkler_pair_matches_elastic_foundation() {
    let mut p = spur();
    p.modifications.pinion.lead_crowning_m = 6e-6;
    p.modifications.gear.lead_crowning_m = 4e-6;
    let c = 10e-6;
    let mut m = MeshModel::new(&p, winkler_options(200)).unwrap();
    let b = p.face_width_m;
    for (te, full) in [(40e-6, true), (15e-6, true), (6e-6, false), (2e-6, false)] {
        let o = m.evaluate(&state(&m, PHI_SINGLE, te)).unwrap();
        assert_eq!(o.n_pairs, 1, "TE {te}");
        let fl = face_load(&m);
        let w_m = o.f_n / b;
        let k = k_h_beta_crowned(c, C_PRIME, w_m);
        assert_eq!(k <= 1.5, full);
        let tol = if full { 1e-3 } else { 1.5e-2 };
        assert!(rel(fl.k_h_beta(), k) < tol, "TE {te}: K {} vs {k}", fl.k_h_beta());
        // The peak line load is c′·δ at the crown's middle.
        assert!(rel(fl.max(), C_PRIME * te) < 2e-3, "peak {} vs {}", fl.max(), C_PRIME * te);
    }
}

/// A crowned pair under a misalignment that keeps the contact patch inside the face: the gap
/// C·u² + f·(u + 1)/2 (u = 2ζ/b₀ − 1) is the same parabola shifted by u* = −f/(4C), so under
/// the same torque the patch only moves and the peak line load is unchanged.
#[test]
fn crowned_patch_shifts_under_misalignment() {
    let torque = 20.0;
    let peak = |f: f64| {
        let mut p = spur();
        p.modifications.pinion.lead_crowning_m = 10e-6;
        p.modifications.gear.lead_crowning_m = 10e-6;
        p.modifications.mesh_misalignment_m = f;
        let mut m = MeshModel::new(&p, winkler_options(400)).unwrap();
        let eq =
            equilibrium(&mut m, PHI_SINGLE, torque, 5e-6, &EquilibriumSettings::default()).unwrap();
        m.evaluate(&state(&m, PHI_SINGLE, eq.te)).unwrap();
        let fl = face_load(&m);
        // The loaded patch (first and last loaded slice).
        let loaded: Vec<f64> =
            fl.zeta.iter().zip(&fl.line_load).filter(|(_, w)| **w > 0.0).map(|(z, _)| *z).collect();
        (fl.max(), loaded[0], *loaded.last().unwrap(), m.geometry().b0())
    };
    let (p0, lo0, hi0, b0) = peak(0.0);
    let (p1, lo1, hi1, _) = peak(10e-6);
    // Patch inside the face and shifted towards ζ = 0 by b₀·f/(8C) = b₀/16.
    assert!(lo0 > 0.1 && hi0 < b0 - 0.1 && lo1 > 0.05 && hi1 < b0 - 0.1, "{lo0} {hi0} {lo1} {hi1}");
    let shift = 0.5 * ((lo0 + hi0) - (lo1 + hi1));
    assert!((shift - b0 / 16.0).abs() < 2.0 * b0 / 200.0, "shift {shift} vs {}", b0 / 16.0);
    assert!(rel(p1, p0) < 5e-3, "peak {p1} vs {p0}");
}
