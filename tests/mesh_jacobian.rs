//! The exact mesh Jacobian (`MeshTorques::mesh_jacobian` of `Mesh`) against central
//! differences of `evaluate`, at full and at table fidelity, light, nominal and overload,
//! several phases, with damping; the plane-of-action identity; table against full.
//!
//! Agreement is measured per row and per column group: the largest |exact − central
//! difference| over the angle columns (φp, φg) relative to the largest |entry| of that row
//! over the angle columns, and likewise over the rate columns (φ̇p, φ̇g), which carry
//! different units. Full-fidelity states are used only where the loaded set of slices is
//! the same at ±step (checked with the per-slice detail).

mod common;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Fidelity, Mesh, MeshError, MeshJacobian, MeshOptions, MeshOutputs,
    MeshState, MeshTorques, equilibrium,
};

use common::{coarse_options, table1_pitch as pitch};

fn model(options: MeshOptions) -> Mesh {
    Mesh::new(&GearPair::paper_table1(), options).expect("model")
}

/// A running state with pinion angle `phi_p`, transmission error `te` and a TE rate of
/// 1 mm/s on top of 300 rad/s, so that the damping torques are non-zero.
fn state(m: &Mesh, phi_p: f64, te: f64) -> MeshState {
    let geo = m.geometry();
    let w_p = 300.0;
    let w_g = (1e-3 - w_p * geo.pinion.rb) / geo.gear.rb;
    MeshState { phi_p, phi_g: geo.phi_g_for_te(phi_p, te), w_p, w_g, ..Default::default() }
}

fn torques(o: &MeshOutputs) -> [f64; 4] {
    [o.m_f_p, o.m_f_g, o.m_d_p, o.m_d_g]
}

/// Loaded slices (pair, back flank, ζ) of the last evaluation (needs `detail`).
fn loaded(m: &Mesh) -> Vec<(i64, bool, u64)> {
    m.slices()
        .iter()
        .filter(|s| s.q_n_per_m > 0.0)
        .map(|s| (s.pair, s.back, s.zeta.to_bits()))
        .collect()
}

/// Central differences of the four torques with respect to the four state components;
/// `None` when the loaded set differs at ±step (full fidelity with detail only).
fn central(m: &mut Mesh, s: &MeshState, check_set: bool) -> Option<[[f64; 4]; 4]> {
    m.evaluate(s).expect("centre");
    let base = if check_set { loaded(m) } else { Vec::new() };
    let mut d = [[0.0; 4]; 4];
    for (j, &h) in STEPS.iter().enumerate() {
        let mut at = |sign: f64| {
            let mut x = *s;
            match j {
                0 => x.phi_p += sign * h,
                1 => x.phi_g += sign * h,
                2 => x.w_p += sign * h,
                _ => x.w_g += sign * h,
            }
            let o = m.evaluate(&x).expect("evaluate");
            (torques(&o), !check_set || loaded(m) == base)
        };
        let ((plus, same_p), (minus, same_m)) = (at(1.0), at(-1.0));
        if !(same_p && same_m) {
            return None;
        }
        for i in 0..4 {
            d[i][j] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    Some(d)
}

/// Step of the central differences per state component (rad, rad, rad/s, rad/s).
const STEPS: [f64; 4] = [3e-9, 3e-9, 1e-3, 1e-3];

/// Largest disagreement per row and column group (see the file docs) in units of 1e-5 of
/// the group's scale, after allowing for the rounding noise of the difference quotient,
/// 1e3·ε·|torque|/step (ε the machine epsilon): ≤ 1 passes.
fn disagreement(exact: &MeshJacobian, fd: &[[f64; 4]; 4], out: &MeshOutputs) -> f64 {
    let t = torques(out);
    let mut worst: f64 = 0.0;
    for i in 0..4 {
        for cols in [0..2, 2..4] {
            let scale =
                cols.clone().map(|j| fd[i][j].abs().max(exact.d[i][j].abs())).fold(0.0, f64::max);
            for j in cols {
                let noise = 1e3 * f64::EPSILON * t[i].abs() / STEPS[j];
                let e = ((exact.d[i][j] - fd[i][j]).abs() - noise).max(0.0);
                if e > 0.0 {
                    worst = worst.max(e / (1e-5 * scale));
                }
            }
        }
    }
    worst
}

/// Static TE at the nominal torque (100 N·m) and phase `phi_p`.
fn nominal_te(m: &mut Mesh, phi_p: f64) -> f64 {
    let torque = helical_gear_mesh::DriveLine::paper_table1().torque_nm;
    equilibrium(m, phi_p, torque, 1e-5, &EquilibriumSettings::default()).expect("equilibrium").te
}

#[test]
fn full_fidelity_matches_central_differences() {
    let mut m = model(MeshOptions { slices: 50, detail: true, ..MeshOptions::default() });
    let te_nom = nominal_te(&mut m, 0.1 * pitch());
    let (mut checked, mut worst, mut tip, mut back) = (0, 0.0f64, 0, 0);
    let jt = m.geometry().backlash_te;
    // Light (near the onset), nominal, overload up to tip contact; back flanks.
    let mut tes: Vec<f64> = [0.02, 1.0, 3.0, 8.0, 15.0].iter().map(|l| l * te_nom).collect();
    tes.extend([1.0, 3.0].iter().map(|l| -jt - l * te_nom));
    for (load, &te) in tes.iter().enumerate() {
        for k in 0..5 {
            let phi_p = pitch() * (k as f64 + 0.3) / 5.0;
            let s = state(&m, phi_p, te);
            let (out, jac) = m.mesh_jacobian(&s).expect("jacobian");
            assert_eq!(torques(&out), torques(&m.evaluate(&s).unwrap()), "outputs as evaluate");
            assert!(jac.d[0][0] > 0.0 && jac.d[2][2] > 0.0, "stiffness and damping positive");
            let Some(fd) = central(&mut m, &s, true) else { continue };
            tip += usize::from(out.tip_contact);
            back += usize::from(out.back_contact);
            let e = disagreement(&jac, &fd, &out);
            assert!(e <= 1.0, "TE #{load}, phase {k}: error {e:.3}·1e-5\n{jac:?}\n{fd:?}");
            worst = worst.max(e);
            checked += 1;
        }
    }
    eprintln!(
        "full fidelity: {checked} states ({tip} with tip contact, {back} on the back flanks), worst disagreement \
         {worst:.3}·1e-5 of the row"
    );
    assert!(checked >= 20, "only {checked} states kept their loaded set");
    assert!(tip >= 2 && back >= 4, "tip {tip}, back {back}: the off-plane terms need testing");
}

#[test]
fn table_fidelity_matches_central_differences() {
    let opts = MeshOptions { slices: 50, fidelity: Fidelity::Table, ..MeshOptions::default() };
    let mut m = model(opts);
    let (lo, hi) = m.table().expect("table").te_range();
    let te_nom = nominal_te(&mut m, 0.1 * pitch());
    let mut worst = 0.0f64;
    // Light, nominal, overload inside the table; back flanks; beyond the table (full fallback).
    let jt = m.geometry().backlash_te;
    assert!(lo < -jt - 1.5 * te_nom);
    let tes =
        [0.02 * te_nom, te_nom, 3.0 * te_nom, -jt - 0.5 * te_nom, -jt - 1.5 * te_nom, 1.2 * hi];
    for (n, &te) in tes.iter().enumerate() {
        for k in 0..4 {
            let phi_p = pitch() * (k as f64 + 0.37) / 4.0;
            let s = state(&m, phi_p, te);
            let (out, jac) = m.mesh_jacobian(&s).expect("jacobian");
            assert_eq!(torques(&out), torques(&m.evaluate(&s).unwrap()), "outputs as evaluate");
            let fd = central(&mut m, &s, false).expect("differences");
            let e = disagreement(&jac, &fd, &out);
            assert!(e <= 1.0, "TE #{n}, phase {k}: error {e:.3}·1e-5\n{jac:?}\n{fd:?}");
            worst = worst.max(e);
        }
    }
    eprintln!("table fidelity: worst disagreement {worst:.3}·1e-5 of the row");
}

/// In the plane of action every moment arm is the base radius, so M_F,g = (g_g/g_p)·M_F,p
/// identically and so are its derivatives.
#[test]
fn plane_of_action_identity() {
    let mut m = model(MeshOptions { slices: 50, detail: true, ..MeshOptions::default() });
    let geo = m.geometry().clone();
    let ratio = geo.gear.rb / geo.pinion.rb;
    let mut checked = 0;
    for k in 0..20 {
        let s = state(&m, pitch() * k as f64 / 20.0, 10e-6);
        let (_, jac) = m.mesh_jacobian(&s).expect("jacobian");
        if !m.slices().iter().filter(|s| s.q_n_per_m > 0.0).all(|s| s.kind == "involute/involute") {
            continue;
        }
        for j in 0..2 {
            let (p, g) = (jac.d[0][j], jac.d[1][j]);
            assert!((g - ratio * p).abs() <= 1e-10 * p.abs().max(jac.d[0][0]), "{g} vs {p}");
        }
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} phases with all loads in the plane of action");
}

/// The table's derivative agrees with the full model's to the table's own accuracy
/// ([`MeshTable::max_rel_err`] of the values, relative to the mesh stiffness ∂M_F,p/∂φp).
#[test]
fn table_derivative_agrees_with_full() {
    let opts = MeshOptions { slices: 50, ..MeshOptions::default() };
    let mut full = model(opts);
    let mut table = model(MeshOptions { fidelity: Fidelity::Table, ..opts });
    let te_nom = nominal_te(&mut full, 0.1 * pitch());
    let err = table.table().unwrap().max_rel_err();
    let mut worst = 0.0f64;
    for k in 0..8 {
        let s = state(&full, pitch() * (k as f64 + 0.5) / 8.0, te_nom);
        let (_, jf) = full.mesh_jacobian(&s).unwrap();
        let (_, jt) = table.mesh_jacobian(&s).unwrap();
        let scale = jf.d[0][0];
        for i in 0..2 {
            for j in 0..2 {
                worst = worst.max((jt.d[i][j] - jf.d[i][j]).abs() / scale);
            }
        }
    }
    eprintln!("table vs full derivative: {worst:e} of the stiffness (table value error {err:e})");
    // The derivative of a C¹ interpolant with O(h³) values is O(h²): one order less accurate
    // than the values; measured 2.5 times the table's value error here.
    assert!(worst < 10.0 * err, "table derivative off by {worst:e} of the stiffness");
}

/// A state far outside the model (teeth crushed through: TE = −2 mm, an overlap of 0.59·m_n
/// on the back flanks), where the load problem is not well posed at some phases, is reported
/// as outside the model's range with TE and the phase, by `evaluate` and `mesh_jacobian` alike.
#[test]
fn state_far_outside_the_model_is_named() {
    let mut m = model(MeshOptions::default());
    let mut named = 0;
    for k in 0..64 {
        let s = state(&m, pitch() * k as f64 / 64.0 - 2e-5, -2e-3);
        let Err(e) = m.evaluate(&s) else { continue };
        let msg = e.to_string();
        assert!(matches!(e, MeshError::OutOfRange { .. }), "{msg}");
        assert!(msg.contains("TE = -") && msg.contains("outside"), "{msg}");
        assert!(msg.contains("mesh phase") && msg.contains("m_n"), "{msg}");
        assert!(matches!(m.mesh_jacobian(&s), Err(MeshError::OutOfRange { .. })), "phase {k}");
        if named == 0 {
            eprintln!("{msg}");
        }
        named += 1;
    }
    assert!(named > 0, "no phase at TE = -2 mm fails; pick a harder state");
}

/// Invalid states are rejected as by `evaluate`; a compliance representation without an
/// analytic derivative (the fitted Eqs. 5–8) says so instead of guessing.
#[test]
fn jacobian_rejects_what_it_cannot_do() {
    let mut m = model(MeshOptions { slices: 50, ..MeshOptions::default() });
    let mut s = state(&m, 0.0, 10e-6);
    s.w_g = f64::NAN;
    assert!(matches!(m.mesh_jacobian(&s), Err(MeshError::NonFinite { name: "w_g", .. })));
    let opts = MeshOptions {
        slices: 50,
        compliance: helical_gear_mesh::mesh::ComplianceModel::Fitted,
        ..MeshOptions::default()
    };
    let mut f = model(opts);
    let s = state(&f, 0.0, 10e-6);
    let e = f.mesh_jacobian(&s).expect_err("fitted");
    assert!(matches!(e, MeshError::Unsupported(_)), "{e}");
    // Separated: outputs and derivatives are zero.
    let (o, j) = m.mesh_jacobian(&state(&m, 0.0, -1e-6)).unwrap();
    assert!(o.separated && j.d.iter().flatten().all(|&v| v == 0.0));
}

/// A pair with profile modifications on both gears (profile crowning, profile slope, tip
/// relief given on the gear, lead crowning and misalignment): the separation depends on the
/// roll position of each contact, which moves with the angles, so the overlap's derivative
/// carries ∂s/∂r·∂r/∂Θ besides the moment arm. The exact Jacobian against central differences
/// at light, nominal and overload TE and several phases.
#[test]
fn profile_modified_pair_matches_central_differences() {
    use helical_gear_mesh::modifications::{ReliefShape, TipRelief};
    let mut p = GearPair::paper_table1();
    let geo = helical_gear_mesh::geometry::PairGeometry::new(&p).unwrap();
    p.modifications.pinion.profile_crowning_m = 4e-6;
    p.modifications.pinion.profile_slope_m = 3e-6;
    p.modifications.pinion.lead_crowning_m = 2e-6;
    p.modifications.gear.profile_slope_m = 5e-6;
    p.modifications.gear.tip_relief = TipRelief {
        amount_m: 8e-6,
        start_diameter_m: 2.0 * (geo.gear.r + 0.5 * (geo.gear.ra - geo.gear.r)),
        shape: ReliefShape::Parabolic,
    };
    p.modifications.mesh_misalignment_m = 4e-6;
    let mut m =
        Mesh::new(&p, MeshOptions { slices: 50, detail: true, ..MeshOptions::default() }).unwrap();
    let te_nom = nominal_te(&mut m, 0.1 * pitch());
    let (mut checked, mut worst) = (0, 0.0f64);
    for (load, te) in [0.3, 1.0, 3.0].iter().map(|l| l * te_nom).enumerate() {
        for k in 0..6 {
            let phi_p = pitch() * (k as f64 + 0.3) / 6.0;
            let s = state(&m, phi_p, te);
            let (out, jac) = m.mesh_jacobian(&s).expect("jacobian");
            let Some(fd) = central(&mut m, &s, true) else { continue };
            let e = disagreement(&jac, &fd, &out);
            assert!(e <= 1.0, "TE #{load}, phase {k}: error {e:.3}·1e-5\n{jac:?}\n{fd:?}");
            worst = worst.max(e);
            checked += 1;
        }
    }
    eprintln!("profile-modified pair: {checked} states, worst disagreement {worst:.3}·1e-5");
    assert!(checked >= 10, "only {checked} states kept their loaded set");
}

/// The table with tooth deviations (per-pair values, each pair at its own TE − e_k): its exact
/// Jacobian against central differences of its `evaluate`, at phases across the hunting
/// period, light to overload, and on the back flanks.
#[test]
fn table_with_tooth_deviations_matches_central_differences() {
    let mut p = GearPair::paper_table1();
    p.modifications.pinion.pitch_deviations_m =
        (0..p.z_p).map(|i| 1.5e-6 * (i as f64 * 1.3).sin()).collect();
    p.modifications.gear.runout_m = 6e-6;
    let opts = coarse_options(Fidelity::Table);
    let mut m = Mesh::new(&p, opts).unwrap();
    assert!(m.table().is_some_and(|t| t.has_tooth_deviations()));
    let te_nom = nominal_te(&mut m, 0.1 * pitch());
    let jt = m.geometry().backlash_te;
    let mut worst = 0.0f64;
    for (n, &te) in [0.3 * te_nom, te_nom, 2.5 * te_nom, -jt - te_nom].iter().enumerate() {
        for k in 0..6 {
            let phi_p = pitch() * (k as f64 * 233.0 + 0.37);
            let s = state(&m, phi_p, te);
            let (out, jac) = m.mesh_jacobian(&s).expect("jacobian");
            assert_eq!(torques(&out), torques(&m.evaluate(&s).unwrap()), "outputs as evaluate");
            let fd = central(&mut m, &s, false).expect("differences");
            let e = disagreement(&jac, &fd, &out);
            assert!(e <= 1.0, "TE #{n}, mesh {k}: error {e:.3}·1e-5\n{jac:?}\n{fd:?}");
            worst = worst.max(e);
        }
    }
    eprintln!("table with deviations: worst disagreement {worst:.3}·1e-5 of the row");
}
