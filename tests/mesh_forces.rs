//! Tests of the 3D mesh force and moments (`mesh::forces`) against analytic oracles.
//!
//! Frame (module docs of `mesh::forces`): x from the pinion axis to the gear axis, z along the
//! pinion axis, y = z × x; centres (0, 0, b/2) and (a, 0, b/2).
//!
//! Oracles, derived here:
//!
//! * Newton's third law: every slice's force acts on the pinion and, reversed, on the gear, so
//!   F_g = −F_p exactly; the moments about the two centres then differ by the transfer formula
//!   M_g = −M_p − (C_p − C_g) × F_p: M_g,x = −M_p,x, M_g,y = −M_p,y − a·F_p,z,
//!   M_g,z = −M_p,z + a·F_p,y. The full model sums M_g from the contacts directly.
//! * The involute: a contact on both involutes lies in the plane of action, with the pinion's
//!   outward transverse normal n₀ = (sin α_wt, cos α_wt) (it passes through the pitch point
//!   (r_wp, 0) at arm r_bp = r_wp·cos α_wt) and moment arm s_p = r_bp; the helicoid's normal is
//!   (n₀, −ω_p·r_bp) with ω_p·r_bp = tan β·r_bp/r_p = tan β_b. So the force on the pinion is
//!   −t·(sin α_wt, cos α_wt, −tan β_b) (t > 0): F_x/F_y = tan α_wt and F_z/|F_xy| = tan β_b.
//!   The damping of Eq. 14 acts along the same 3D direction, so the ratios hold with it. Back
//!   flanks: n_b = (sin α_wt, −cos α_wt), s_p = −r_bp: F_x/F_y = −tan α_wt, |F_z|/|F_xy| =
//!   tan β_b, F_z < 0 when the back flanks carry the load.
//! * Torques: a force along a line at arm s from an axis has moment s·|F_t| about it, so the
//!   moment of F_p about the pinion axis is −(M_F,p + M_D,p) and that of F_g about the gear
//!   axis −(M_F,g + M_D,g) (the torques enter Eqs. 2–3 with a minus sign). On the involute
//!   this reads r_bp·(n·F_p,xy) = −(M_F,p + M_D,p), n the side's plane-of-action normal, which
//!   the table (it carries no z moment) must meet too.

mod common;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    Fidelity, Mesh, MeshOptions, MeshOutputs, MeshState, MeshWrench, winkler_compliances,
};

use common::{coarse_options, state_at_rest, table1_pitch};

/// Table 1 (no flank modifications) on a Winkler foundation (no FE run), its table designed
/// for 1 N·m: at light load most states load only slices on both involutes (the contact lines
/// end at the tip relief's corner, where a few states load a relief slice).
fn unmodified(fidelity: Fidelity) -> Mesh {
    let pair = GearPair::paper_table1();
    let (p, g) = winkler_compliances(&pair, 1.4e10).expect("Winkler");
    let options =
        MeshOptions { detail: true, table_design_torque_nm: 1.0, ..coarse_options(fidelity) };
    Mesh::with_compliance(&pair, options, p, g).expect("mesh")
}

/// Table 1 with its embedded compliance data at `fidelity` (coarse options).
fn table1(fidelity: Fidelity) -> Mesh {
    Mesh::new(&GearPair::paper_table1(), coarse_options(fidelity)).expect("Table 1")
}

fn with_speed(mut s: MeshState, w_p: f64, w_g: f64) -> MeshState {
    s.w_p = w_p;
    s.w_g = w_g;
    s
}

/// States over a pitch on both flank sides, with speeds that make TE grow and shrink.
fn states(m: &Mesh, te_drive: f64) -> Vec<MeshState> {
    let jt = m.geometry().backlash_te;
    let mut out = Vec::new();
    for i in 0..7 {
        let phi = table1_pitch() * i as f64 / 7.0 + 0.013;
        for (te, w) in [(te_drive, 180.0), (-jt - te_drive, -150.0)] {
            let s = state_at_rest(m, phi, te);
            out.push(s);
            // rate of TE = w_p·r_bp + w_g·r_bg ≠ 0.
            out.push(with_speed(s, w, -0.5 * w));
        }
    }
    out
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

#[test]
fn newton_third_law_and_the_gear_moment_from_the_contacts_obey_the_transfer_formula() {
    let mut m = table1(Fidelity::Full);
    let frame = *m.model().force_frame();
    for s in states(&m, 25e-6) {
        let o = m.evaluate(&s).unwrap();
        assert!(o.n_pairs > 0);
        for k in 0..3 {
            assert_eq!(o.force_g[k], -o.force_p[k]);
        }
        let w = *m.full().workspace().wrench();
        let scale = frame.center_distance * o.force_p.iter().map(|f| f.abs()).fold(0.0, f64::max);
        let t = w.transferred_moment_g(&frame);
        for (k, (direct, transferred)) in w.moment_g.iter().zip(t).enumerate() {
            assert!(rel(*direct, transferred, scale) < 1e-12, "{k}: {direct} vs {transferred}");
        }
        assert_eq!(o.moment_p, [w.moment_p[0], w.moment_p[1]]);
        assert_eq!(o.moment_g, [w.moment_g[0], w.moment_g[1]]);
    }
}

#[test]
fn moments_about_the_gear_axes_are_minus_the_mesh_torques_at_full_fidelity() {
    let mut m = table1(Fidelity::Full);
    // A light and a heavy load (tip contact at the heavy one): any contact, not only the
    // involute, has moment −(M_F + M_D) about each axis.
    let mut tip = false;
    for te in [8e-6, 150e-6] {
        for s in states(&m, te) {
            let o = m.evaluate(&s).unwrap();
            tip |= o.tip_contact;
            let w = m.full().workspace().wrench();
            let (tp, tg) = (o.m_f_p + o.m_d_p, o.m_f_g + o.m_d_g);
            assert!(rel(w.moment_p[2], -tp, tp.abs()) < 1e-12, "{} vs {}", w.moment_p[2], -tp);
            assert!(rel(w.moment_g[2], -tg, tg.abs()) < 1e-12, "{} vs {}", w.moment_g[2], -tg);
        }
    }
    assert!(tip, "the heavy load reaches the tips");
}

/// The largest relative deviation of `o` from the involute oracles (module docs): the
/// ratios F_x/F_y and F_z/|F_xy|, and the moments about both axes from the force along the
/// plane of action; the flank side from `back`.
fn involute_deviation(m: &Mesh, o: &MeshOutputs, back: bool) -> f64 {
    let g = m.geometry();
    let (tan_wt, tan_bb) = (g.alpha_wt.tan(), g.base_helix_angle.tan());
    let f = o.force_p;
    let ft = f[0].hypot(f[1]);
    let sign = if back { -1.0 } else { 1.0 };
    // F_x/F_y = σ·tan α_wt; on either side F_z/|F_xy| = −sign(F_y)·tan β_b.
    let ratio_xy = (f[0] / f[1] - sign * tan_wt).abs() / tan_wt;
    let ratio_z = (f[2] / ft + f[1].signum() * tan_bb).abs() / tan_bb;
    // σ·r_bp·(n·F_p) = −(M_F,p + M_D,p) and σ·r_bg·(n·F_g) = M_F,g + M_D,g.
    let (s, c) = g.alpha_wt.sin_cos();
    let n = [s, sign * c];
    let along = |v: [f64; 3]| n[0] * v[0] + n[1] * v[1];
    let (tp, tg) = (o.m_f_p + o.m_d_p, o.m_f_g + o.m_d_g);
    let mp = rel(sign * g.pinion.rb * along(f), -tp, tp.abs());
    let mg = rel(sign * g.gear.rb * along(o.force_g), tg, tg.abs());
    ratio_xy.max(ratio_z).max(mp).max(mg)
}

#[test]
fn unmodified_pair_on_the_involute_has_the_plane_of_action_ratios_at_full_and_table_fidelity() {
    // At light load the contact lines end at the tip relief's corner; states whose loaded
    // slices all lie on both involutes (by the per-slice detail of the full model) are the
    // oracle's domain, at full fidelity and, at the same states, at table fidelity (its
    // nodes at light load are on the involute too: the design torque is 1 N·m).
    let mut full = unmodified(Fidelity::Full);
    let mut table = unmodified(Fidelity::Table);
    let jt = full.geometry().backlash_te;
    let hi = table.table().unwrap().te_range().1;
    let mut checked = [[0, 0], [0, 0]];
    for i in 0..40 {
        let phi = table1_pitch() * i as f64 / 40.0 + 0.004;
        for (te, w, back) in [(0.3 * hi, 150.0, false), (-jt - 0.3 * hi, -120.0, true)] {
            for s in
                [state_at_rest(&full, phi, te), with_speed(state_at_rest(&full, phi, te), w, 0.0)]
            {
                let o = full.evaluate(&s).unwrap();
                assert!(o.n_pairs > 0 && o.back_contact == back);
                let involute = full
                    .slices()
                    .iter()
                    .filter(|d| d.q_n_per_m > 0.0)
                    .all(|d| d.kind == "involute/involute");
                if !involute {
                    continue;
                }
                assert!(o.m_d_p != 0.0 || s.w_p == 0.0);
                let dev = involute_deviation(&full, &o, back);
                assert!(dev <= 1e-9, "full fidelity: deviation {dev:.3e} at {s:?}");
                checked[0][usize::from(back)] += 1;
                // The table is linear in its node values: exact where all 16 nodes are on the
                // involute; a node with a loaded relief slice (its normal turned off the plane
                // of action) enters at its weight.
                let t = table.evaluate(&s).unwrap();
                let dev = involute_deviation(&full, &t, back);
                assert!(dev <= 1e-4, "table fidelity: deviation {dev:.3e} at {s:?}");
                if dev <= 1e-9 {
                    checked[1][usize::from(back)] += 1;
                }
            }
        }
    }
    eprintln!("states on the involute [full, table to 1e-9] × [driving, back]: {checked:?}");
    assert!(checked[0].iter().all(|&n| n >= 40), "{checked:?}");
    assert!(checked[1].iter().all(|&n| n >= 30), "{checked:?}");
}

#[test]
fn the_driving_force_pushes_the_pinion_away_resists_its_rotation_and_thrusts_along_plus_z() {
    let mut m = table1(Fidelity::Full);
    let o = m.evaluate(&state_at_rest(&m, 0.01, 20e-6)).unwrap();
    assert!(o.force_p[0] < 0.0 && o.force_p[1] < 0.0 && o.force_p[2] > 0.0, "{:?}", o.force_p);
    // The tangential force carries the torque at about the pitch radius.
    let g = m.geometry();
    let r_wp = g.pinion.rb / g.alpha_wt.cos();
    assert!((-o.force_p[1] * r_wp / o.m_f_p - 1.0).abs() < 0.05);
}

#[test]
fn damping_wrench_of_eq_14_has_the_damping_torques_about_both_axes_and_its_lever() {
    // The closed forms of the module docs against the sum over single slices.
    let m = table1(Fidelity::Full);
    let frame = *m.model().force_frame();
    let g = m.geometry();
    let (f, dz) = (37.0, 0.25);
    let zetas = [0.4, 1.9, 3.3];
    let mut sum = MeshWrench::default();
    for z in zetas {
        let (s, c) = g.alpha_wt.sin_cos();
        let force = [-f * dz * s, -f * dz * c, f * dz * frame.tan_beta_b];
        let point = [frame.pitch_radius_p, 0.0, z * frame.module];
        sum.add(&MeshWrench::of_force(&frame, point, force));
    }
    let e = dz * zetas.len() as f64;
    let z1: f64 = zetas.iter().map(|z| z * dz).sum();
    let closed =
        MeshWrench::of_damping(&frame, helical_gear_mesh::contact::FlankSide::Drive, f, e, z1);
    for k in 0..3 {
        assert!((closed.force_p[k] - sum.force_p[k]).abs() < 1e-12 * f);
        assert!((closed.moment_p[k] - sum.moment_p[k]).abs() < 1e-12 * f);
        assert!((closed.moment_g[k] - sum.moment_g[k]).abs() < 1e-12 * f);
    }
    // About the axes: −M_D = −f·E·r_b.
    assert!((closed.moment_p[2] + f * e * g.pinion.rb).abs() < 1e-12 * f * e * g.pinion.rb);
    assert!((closed.moment_g[2] + f * e * g.gear.rb).abs() < 1e-12 * f * e * g.gear.rb);
}

#[test]
fn table_forces_agree_with_the_full_model_within_the_table_accuracy() {
    // The elastic part at rest against the table's own accuracy on M_F; the damping part
    // (the difference made by the speeds) against its accuracy on M_D, which comes from the
    // interpolated loaded extent.
    let mut full = table1(Fidelity::Full);
    let mut table = table1(Fidelity::Table);
    let (lo, hi) = table.table().unwrap().te_range();
    let mut rng = common::XorShift64Star(0x9e37_79b9);
    let (mut worst_f, mut worst_m, mut worst_t) = (0.0f64, 0.0f64, 0.0f64);
    let (mut worst_fd, mut worst_md) = (0.0f64, 0.0f64);
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut n = 0;
    for _ in 0..200 {
        let phi = rng.range(0.0, 10.0);
        let te = rng.range(lo, hi);
        let rest = state_at_rest(&full, phi, te);
        let a = full.evaluate(&rest).unwrap();
        let b = table.evaluate(&rest).unwrap();
        if a.m_f_p.abs() < 1.0 {
            continue;
        }
        n += 1;
        worst_t = worst_t.max((a.m_f_p - b.m_f_p).abs() / a.m_f_p.abs());
        let fmag = norm(a.force_p);
        let mscale = fmag * full.pair().face_width_m;
        for k in 0..3 {
            worst_f = worst_f.max((a.force_p[k] - b.force_p[k]).abs() / fmag);
            assert_eq!(b.force_g[k], -b.force_p[k]);
        }
        for k in 0..2 {
            worst_m = worst_m.max((a.moment_p[k] - b.moment_p[k]).abs() / mscale);
            worst_m = worst_m.max((a.moment_g[k] - b.moment_g[k]).abs() / mscale);
        }
        let moving = with_speed(rest, 120.0, -60.0);
        let (ad, bd) = (full.evaluate(&moving).unwrap(), table.evaluate(&moving).unwrap());
        if ad.m_d_p.abs() > 0.0 && ad.n_pairs == bd.n_pairs {
            worst_md = worst_md.max((ad.m_d_p - bd.m_d_p).abs() / ad.m_d_p.abs());
            let fa: [f64; 3] = std::array::from_fn(|k| ad.force_p[k] - a.force_p[k]);
            let fb: [f64; 3] = std::array::from_fn(|k| bd.force_p[k] - b.force_p[k]);
            for k in 0..3 {
                worst_fd = worst_fd.max((fa[k] - fb[k]).abs() / norm(fa));
            }
        }
    }
    eprintln!(
        "table vs full over {n} states: elastic |ΔF|/|F| {worst_f:.2e}, |ΔM|/(|F|·b) \
         {worst_m:.2e} (M_F {worst_t:.2e}); damping |ΔF_D|/|F_D| {worst_fd:.2e} (M_D {worst_md:.2e})"
    );
    assert!(n > 50);
    // The coarse table's torque accuracy, with room for the force's own interpolation.
    assert!(worst_f <= 2.0 * worst_t + 2e-3, "force {worst_f:.2e} vs torque {worst_t:.2e}");
    assert!(worst_m <= 2.0 * worst_t + 2e-3, "moment {worst_m:.2e} vs torque {worst_t:.2e}");
    assert!(worst_fd <= 2.0 * worst_md + 2e-3, "damping {worst_fd:.2e} vs {worst_md:.2e}");
}

#[test]
fn hgm_outputs_carry_the_force_and_moments_after_the_flags_at_fixed_c_offsets() {
    use helical_gear_mesh::capi::HgmOutputs;
    use std::mem::offset_of;
    // 8 doubles, a uint32_t and 3 bools (71 bytes), padded to the doubles' alignment.
    assert_eq!(offset_of!(HgmOutputs, back_contact), 70);
    assert_eq!(offset_of!(HgmOutputs, force_p), 72);
    assert_eq!(offset_of!(HgmOutputs, moment_p), 96);
    assert_eq!(offset_of!(HgmOutputs, force_g), 112);
    assert_eq!(offset_of!(HgmOutputs, moment_g), 136);
    // Then the two root stresses (double each).
    assert_eq!(offset_of!(HgmOutputs, root_stress_p), 152);
    assert_eq!(offset_of!(HgmOutputs, root_stress_g), 160);
    // Then the six of the friction (double each).
    assert_eq!(offset_of!(HgmOutputs, m_r_p), 168);
    assert_eq!(offset_of!(HgmOutputs, m_r_g), 176);
    assert_eq!(offset_of!(HgmOutputs, p_loss), 184);
    assert_eq!(offset_of!(HgmOutputs, eta_mesh), 192);
    assert_eq!(offset_of!(HgmOutputs, q_p), 200);
    assert_eq!(offset_of!(HgmOutputs, q_g), 208);
    assert_eq!(std::mem::size_of::<HgmOutputs>(), 216);
}

// Bearing loads (`mesh::bearings`): a rigid shaft on a locating and a floating bearing.

/// Statics of the shaft: the reactions and the mesh load sum to zero force, and to zero
/// moment about an arbitrary point of the axis (here z = 0.3 m, not the centre).
#[test]
fn bearing_reactions_hold_the_shaft_in_equilibrium() {
    use helical_gear_mesh::mesh::bearings::BearingArrangement;
    let arrangement =
        BearingArrangement::from_json(include_str!("../docs/loads/bearings_table1.json")).unwrap();
    let mut m = table1(Fidelity::Full);
    let b = m.pair().face_width_m;
    let c = 0.5 * b;
    for s in states(&m, 25e-6) {
        let o = m.evaluate(&s).unwrap();
        let r = arrangement.reactions(b, &o);
        let zs = arrangement.labels().map(|l| l.2);
        for (shaft, force, moment) in [(0, o.force_p, o.moment_p), (1, o.force_g, o.moment_g)] {
            let (rl, rf) = (r[2 * shaft], r[2 * shaft + 1]);
            let (zl, zf) = (zs[2 * shaft], zs[2 * shaft + 1]);
            let scale = force.iter().map(|f| f.abs()).fold(0.0, f64::max);
            for k in 0..3 {
                assert!((rl[k] + rf[k] + force[k]).abs() <= 1e-12 * scale);
            }
            assert_eq!(rf[2], 0.0, "the floating bearing takes no axial load");
            // Moments about (x_axis, 0, z0) of forces on the axis at z: (0, 0, z − z0) × R.
            let z0 = 0.3;
            let mx = -(zl - z0) * rl[1] - (zf - z0) * rf[1] - (c - z0) * force[1] + moment[0];
            let my = (zl - z0) * rl[0] + (zf - z0) * rf[0] + (c - z0) * force[0] + moment[1];
            assert!(mx.abs() <= 1e-11 * scale && my.abs() <= 1e-11 * scale, "{mx} {my}");
        }
    }
}

/// A simply supported beam: a radial load F at distances a from the locating and b from the
/// floating bearing loads them with −F·b/(a + b) and −F·a/(a + b); a pure tilting moment M_y
/// with ±M_y/L; the axial load goes to the locating bearing alone.
#[test]
fn two_bearing_shaft_matches_the_simply_supported_beam() {
    use helical_gear_mesh::mesh::bearings::ShaftBearings;
    let (a, b, c) = (0.03, 0.05, 0.0075);
    let shaft = ShaftBearings { locating_z_m: c - a, floating_z_m: c + b };
    let [l, f] = shaft.reactions(c, [800.0, -2000.0, 350.0], [0.0, 0.0]);
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs().max(1.0);
    assert!(close(l[0], -800.0 * b / (a + b)) && close(f[0], -800.0 * a / (a + b)));
    assert!(close(l[1], 2000.0 * b / (a + b)) && close(f[1], 2000.0 * a / (a + b)));
    assert!(close(l[2], -350.0) && f[2] == 0.0);
    // M_y alone: d_L·R_L,x + d_F·R_F,x = −M_y with R_F,x = −R_L,x and d_F − d_L = a + b.
    let [l, f] = shaft.reactions(c, [0.0; 3], [0.0, 12.0]);
    assert!(close(l[0], 12.0 / (a + b)) && close(f[0], -12.0 / (a + b)));
    // M_x alone: −d_L·R_L,y − d_F·R_F,y = −M_x with R_F,y = −R_L,y.
    let [l, f] = shaft.reactions(c, [0.0; 3], [-9.0, 0.0]);
    assert!(close(l[1], 9.0 / (a + b)) && close(f[1], -9.0 / (a + b)));
}

#[test]
fn bearing_arrangement_errors_name_the_key_and_the_limit() {
    use helical_gear_mesh::mesh::bearings::BearingArrangement;
    let bad = |json: &str| BearingArrangement::from_json(json).unwrap_err().to_string();
    let same = r#"{"pinion": {"locating_z_m": 0.01, "floating_z_m": 0.01},
                  "gear": {"locating_z_m": -0.02, "floating_z_m": 0.035}}"#;
    let e = bad(same);
    assert!(e.contains("pinion.floating_z_m") && e.contains("1e-6"), "{e}");
    let far = r#"{"pinion": {"locating_z_m": 0.01, "floating_z_m": 0.05},
                  "gear": {"locating_z_m": -2e3, "floating_z_m": 0.035}}"#;
    assert!(bad(far).contains("gear.locating_z_m"), "{}", bad(far));
    let e = bad(r#"{"pinion": {"locating_z_m": 0.01}}"#);
    assert!(e.contains("floating_z_m"), "{e}");
}

#[test]
fn order_amplitudes_recover_a_sampled_harmonic() {
    use helical_gear_mesh::mesh::bearings::order_amplitudes;
    // 2 pitches of 20 points: 3.0 + 2.5·cos(2π·order 1) + 0.75·sin(2π·order 3).
    let n = 40;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / 20.0;
            3.0 + 2.5 * (std::f64::consts::TAU * t).cos()
                + 0.75 * (3.0 * std::f64::consts::TAU * t).sin()
        })
        .collect();
    let a = order_amplitudes(&x, 2, 10);
    assert_eq!(a.len(), 10);
    for (k, want) in [(0, 2.5), (1, 0.0), (2, 0.75), (3, 0.0)] {
        assert!((a[k] - want).abs() < 1e-12, "order {}: {}", k + 1, a[k]);
    }
}

/// The HelicalGearMesh FMU reports the force and moments (value references 400–409) as the
/// library computes them: Newton's third law, the transfer formula between the centres, and
/// the tangential force of the torque at the pitch radius.
#[test]
fn fmu_outputs_carry_the_force_and_moments() {
    use common::fmi::{Fmu, vr};
    let names =
        ["F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y", "F_g_x", "F_g_y", "F_g_z", "M_g_x", "M_g_y"];
    for (k, n) in names.iter().enumerate() {
        assert_eq!(vr(n), 400 + k as u32);
    }
    let g = common::table1_geometry();
    let fmu = Fmu::initialised();
    let phi_p = 0.02;
    let phi_g = g.phi_g_for_te(phi_p, 20e-6);
    assert_eq!(fmu.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, 0.0, 0.0]), fmi2ok());
    let v = fmu.get(&names).unwrap();
    let m = fmu.get(&["M_F_p"]).unwrap()[0];
    assert!(v[0] < 0.0 && v[1] < 0.0 && v[2] > 0.0, "{v:?}");
    for k in 0..3 {
        assert_eq!(v[5 + k], -v[k]);
    }
    let a = g.center_distance;
    assert!((v[8] + v[3]).abs() <= 1e-9 * v[3].abs().max(1.0));
    assert!((v[9] + v[4] + a * v[2]).abs() <= 1e-9 * (a * v[2]).abs());
    let r_wp = g.pinion.rb / g.alpha_wt.cos();
    assert!((-v[1] * r_wp / m - 1.0).abs() < 0.05, "{} vs {m}", -v[1] * r_wp);
}

fn fmi2ok() -> helical_gear_mesh::fmi2::types::fmi2Status {
    helical_gear_mesh::fmi2::types::fmi2Status::Ok
}

/// The sweep's dynamic factor of the mesh force: max |F_p| over each speed's steady window
/// against the largest static |F_p| over a mesh cycle at the same torque. Near standstill the
/// response is quasi-static (the factor tends to 1 from above, as TE_max/STE_max does);
/// it follows TE_max/STE_max, since the force is the mesh's stiffness times TE.
#[test]
fn sweep_reports_the_peak_mesh_force_and_root_stress_over_their_static_peaks() {
    use helical_gear_mesh::DriveLine;
    use helical_gear_mesh::dynamics::{Drivetrain, SweepOptions, sweep};
    let pair = GearPair::paper_table1();
    let mesh = Mesh::new(&pair, common::small_table_options()).unwrap();
    let drive = Drivetrain::from_pair(&pair, &DriveLine::paper_table1()).unwrap();
    let mut opts =
        SweepOptions { static_points: 16, refine_runs: 0, threads: Some(2), ..Default::default() };
    opts.run.max_periods = 300;
    let speeds = [60.0, 450.0];
    let r = sweep(&mesh, &drive, &speeds, &opts).unwrap();
    for p in &r.points {
        let f = p.over_static.mesh_force.expect("a mesh with contact geometry");
        eprintln!(
            "ω_p {}: F_max/F_static {f:.4}, TE_max/STE_max {:.4}",
            p.omega_p, p.te_max_over_ste_max
        );
        assert!(f.is_finite() && f > 0.9, "{f}");
        assert!((f - p.te_max_over_ste_max).abs() < 0.1 * p.te_max_over_ste_max, "{f}");
        // The root stress is linear in the loads (`compliance::root_stress`): its dynamic
        // factor follows the same load amplification.
        let s = p.over_static.root_stress.expect("a mesh with FE data");
        eprintln!("ω_p {}: σ_F,max/σ_F,static {s:.4}", p.omega_p);
        assert!(s.is_finite() && s > 0.9, "{s}");
        assert!((s - p.te_max_over_ste_max).abs() < 0.15 * p.te_max_over_ste_max, "{s}");
    }
    let record = helical_gear_mesh::results::SweepRecord::new(&r, &speeds);
    assert_eq!(record.mesh_force_max_over_static.len(), 2);
    assert_eq!(record.root_stress_max_over_static.len(), 2);
    record.check_finite().unwrap();
}

/// With tooth-by-tooth deviations the table keeps the force and moments per tooth pair as it
/// keeps the torques (pitch errors of `docs/modifications/table1_pitch_errors.json`), against
/// the full model with the same deviations. On a Winkler foundation the pairs are uncoupled
/// and the per-pair sum is exact but for the contacts off the plane of action: force and
/// moments agree as the torque does (measured: M_F 1.1e-2 of nominal, F 1.0e-2, tilting
/// moments 8.8e-3 of F_nominal·b). With the FE compliance the per-pair table neglects the
/// coupling of the pairs through the bodies beyond first order, which moves load between
/// pairs (at different places on the face) more than it changes their sum: the tilting
/// moments differ by up to 2.3e-2 of F_nominal·b (5e-4 without deviations), the torque by
/// 7.2e-3 of nominal.
#[test]
fn per_pair_table_with_pitch_deviations_carries_the_force_and_moments() {
    let text = include_str!("../docs/modifications/table1_pitch_errors.json");
    let p = GearPair::from_json(text).unwrap();
    let full_opts = MeshOptions { slices: 60, ..MeshOptions::default() };
    let table_opts = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: 32,
        table_te_points: 24,
        ..full_opts
    };
    let (wp, wg) = winkler_compliances(&p, 1.4e10).unwrap();
    let winkler = (
        Mesh::with_compliance(&p, table_opts, wp.clone(), wg.clone()).unwrap(),
        Mesh::with_compliance(&p, full_opts, wp, wg).unwrap(),
    );
    let fe = (Mesh::new(&p, table_opts).unwrap(), Mesh::new(&p, full_opts).unwrap());
    for (name, (mut t, mut f)) in [("Winkler", winkler), ("FE", fe)] {
        assert!(t.table().is_some_and(|t| t.has_tooth_deviations()));
        let g = t.geometry().clone();
        let pitch = g.pinion.angular_pitch();
        // Nominal transverse force (100 N·m) and its lever over the face.
        let nominal = 100.0 / g.pinion.rb;
        let b = p.face_width_m;
        let (mut worst_t, mut worst_f, mut worst_m) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..40 {
            let mesh = (k * 467) % 1410;
            let phi = pitch * (mesh as f64 + (k as f64 * 0.618_034).fract() - 0.5);
            for te in [20e-6, 45e-6] {
                let s = with_speed(state_at_rest(&t, phi, te), 150.0, -95.7);
                let (a, c) = (t.evaluate(&s).unwrap(), f.evaluate(&s).unwrap());
                worst_t = worst_t.max((a.m_f_p - c.m_f_p).abs() / 100.0);
                for i in 0..3 {
                    worst_f = worst_f.max((a.force_p[i] - c.force_p[i]).abs() / nominal);
                    assert_eq!(a.force_g[i], -a.force_p[i]);
                }
                for i in 0..2 {
                    let mb = nominal * b;
                    worst_m = worst_m.max((a.moment_p[i] - c.moment_p[i]).abs() / mb);
                    worst_m = worst_m.max((a.moment_g[i] - c.moment_g[i]).abs() / mb);
                }
            }
        }
        eprintln!(
            "{name}: per-pair table vs full: M_F {worst_t:.2e}, F {worst_f:.2e}, M {worst_m:.2e}"
        );
        assert!(worst_f <= 2.0 * worst_t + 2e-3, "{name}: force {worst_f:.2e} vs {worst_t:.2e}");
        let moment_bound = if name == "Winkler" { 2.0 * worst_t + 2e-3 } else { 3e-2 };
        assert!(worst_m <= moment_bound, "{name}: moment {worst_m:.2e} vs torque {worst_t:.2e}");
    }
}
