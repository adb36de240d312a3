//! The mesh at a small pose of the gear bodies (`helical_gear_mesh::mesh::pose`) against
//! oracles derived in each test: a rigid motion of both bodies changes nothing, a centre
//! distance change moves every flank by Δa·sin α_wt along the line of action, a tilt is the
//! misalignment it projects to, the Jacobian's pose columns are the derivatives of the model as
//! evaluated, the bounds name the component, and the table, which holds only the rigid-bearing
//! mesh, refuses a pose.

mod common;

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    BodyPose, Fidelity, Mesh, MeshError, MeshOptions, MeshOutputs, MeshState, MeshTorques,
    SliceDetail,
};

use common::state_at_rest as state;

fn winkler(slices: usize) -> MeshOptions {
    MeshOptions {
        slices,
        winkler_c_prime: Some(14e9),
        local_contact: false,
        detail: true,
        ..MeshOptions::default()
    }
}

fn posed(s: MeshState, pose_p: BodyPose, pose_g: BodyPose) -> MeshState {
    MeshState { pose_p, pose_g, ..s }
}

/// An evaluation from a cold start (the result then depends on the state alone).
fn eval(m: &mut Mesh, s: &MeshState) -> (MeshOutputs, Vec<SliceDetail>) {
    m.forget_history();
    let o = m.evaluate(s).unwrap();
    (o, m.slices().to_vec())
}

/// Translating both bodies by the same vector is a rigid motion of the whole pair: the relative
/// pose is exactly zero, so every output is the rigid-bearing one to the last digit (the issue
/// asks for 1e-12 of the torque). Tilting both bodies by the same angle about the pinion centre
/// (the gear centre then moves by θ × (a, 0, 0)) turns the whole pair: the torques stay, the
/// force and moment vectors turn by θ.
#[test]
fn a_rigid_motion_of_both_bodies_changes_nothing() {
    let pair = GearPair::paper_table1();
    let mut m = Mesh::new(&pair, winkler(60)).unwrap();
    let a = m.geometry().center_distance;
    let pitch = m.geometry().pinion.angular_pitch();
    for k in 0..6 {
        let phi = pitch * (k as f64 / 6.0 + 0.1);
        let s0 = MeshState { w_p: 120.0, w_g: -75.0, ..state(&m, phi, 30e-6) };
        let (o0, _) = eval(&mut m, &s0);
        let u = BodyPose { u_x: 37e-6, u_y: -52e-6, u_z: 81e-6, ..BodyPose::default() };
        let (o1, _) = eval(&mut m, &posed(s0, u, u));
        assert_eq!(o0, o1, "common translation at phase {k}");

        let th = [2.1e-4, -3.3e-4];
        let pose_p = BodyPose { th_x: th[0], th_y: th[1], ..BodyPose::default() };
        // θ × (a, 0, 0) = (0, θ_z·a, −θ_y·a) with θ_z = 0.
        let pose_g = BodyPose { u_z: -th[1] * a, ..pose_p };
        let (o2, _) = eval(&mut m, &posed(s0, pose_p, pose_g));
        let tol = 1e-12 * o0.m_f_p.abs();
        assert!((o2.m_f_p - o0.m_f_p).abs() <= tol, "{} {}", o2.m_f_p, o0.m_f_p);
        assert!((o2.m_f_g - o0.m_f_g).abs() <= tol, "{} {}", o2.m_f_g, o0.m_f_g);
        let t = [th[0], th[1], 0.0];
        let turned = |v: [f64; 3]| {
            [
                v[0] + t[1] * v[2] - t[2] * v[1],
                v[1] + t[2] * v[0] - t[0] * v[2],
                v[2] + t[0] * v[1] - t[1] * v[0],
            ]
        };
        let f = turned(o0.force_p);
        let fmax = o0.force_p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..3 {
            assert!(
                (o2.force_p[i] - f[i]).abs() <= 1e-12 * fmax,
                "F_p[{i}] {:?} {f:?}",
                o2.force_p
            );
        }
    }
}

/// Moving the gear by Δa along x (the line of centres) moves its flanks by Δa along x; along
/// the driving flanks' common normal n = (sin α_wt, cos α_wt) that is Δa·sin α_wt, so every
/// involute contact's overlap falls by Δa·sin α_wt (the no-load contact moves by that along
/// the line of action). The back flanks' normal is (sin α_wt, −cos α_wt) mirrored: their
/// overlap falls by as much, so the free play along the line of action grows by
/// 2·Δa·sin α_wt, which is the transverse (circumferential, at the operating pitch circle)
/// backlash 2·Δa·tan α_wt times cos α_wt. The relation is first order in Δa/a; 1 % holds.
#[test]
fn a_centre_distance_change_opens_the_flanks_by_its_projection() {
    let pair = GearPair::paper_table1();
    let mut m = Mesh::new(&pair, winkler(40)).unwrap();
    let geo = m.geometry().clone();
    let sin_wt = geo.alpha_wt.sin();
    let pitch = geo.pinion.angular_pitch();
    let da = 20e-6;
    let gear = BodyPose { u_x: da, ..BodyPose::default() };
    let mut checked = [0usize; 2];
    for (te, back) in [(40e-6, false), (-geo.backlash_te - 40e-6, true)] {
        for k in 0..5 {
            let phi = pitch * (k as f64 / 5.0 + 0.05);
            let s0 = state(&m, phi, te);
            let (_, d0) = eval(&mut m, &s0);
            let (_, d1) = eval(&mut m, &posed(s0, BodyPose::default(), gear));
            for a in d0.iter().filter(|d| d.kind == "involute/involute" && d.back == back) {
                let Some(b) =
                    d1.iter().find(|b| b.pair == a.pair && b.zeta == a.zeta && b.back == back)
                else {
                    continue;
                };
                let shift = a.overlap_m - b.overlap_m;
                assert!(
                    (shift - da * sin_wt).abs() <= 0.01 * da * sin_wt,
                    "back {back}: overlap falls by {shift:e}, Δa·sin α_wt = {:e}",
                    da * sin_wt
                );
                checked[usize::from(back)] += 1;
            }
        }
    }
    // Both flank sides open by Δa·sin α_wt: the free play along the line of action grows by
    // 2·Δa·sin α_wt, the transverse backlash 2·Δa·tan α_wt.
    assert!(checked[0] > 20 && checked[1] > 20, "{checked:?}");
}

/// The load along the face: the sum of the line loads of all driving pairs at each slice
/// position ζ (N/m), in ascending ζ.
fn face_load(d: &[SliceDetail]) -> Vec<f64> {
    let mut z: Vec<(f64, f64)> = Vec::new();
    for s in d.iter().filter(|s| !s.back) {
        match z.iter_mut().find(|(zeta, _)| *zeta == s.zeta) {
            Some(e) => e.1 += s.q_n_per_m,
            None => z.push((s.zeta, s.q_n_per_m)),
        }
    }
    z.sort_by(|a, b| a.0.total_cmp(&b.0));
    z.into_iter().map(|(_, q)| q).collect()
}

/// A tilt of the gear about x moves its axis in slice z by o = (0, −Θ_x·(z − b/2)); along the
/// driving flanks' normal the overlap changes by −o·n = Θ_x·cos α_wt·(z − b/2): a linear
/// separation across the face, the misalignment f_ma = −Θ_x·b·cos α_wt of ISO 6336-1 in the
/// plane of action plus a uniform +f_ma/2 (a TE offset). The tilt also displaces the gear's
/// flanks axially by Θ_x·ρ_y, which the helix turns into a separation that varies along the
/// path of contact (not across the face). So the load across the face, and K_Hβ, equal those of
/// `mesh_misalignment_m = f_ma` at TE + f_ma/2, within the axial part (the oracle:
/// K_Hβ within 2 %).
#[test]
fn a_tilt_is_the_misalignment_it_projects_to() {
    let base = GearPair::paper_table1();
    let f_ma = 10e-6;
    let mut mis = base.clone();
    mis.modifications.mesh_misalignment_m = f_ma;
    let opts = winkler(60);
    let mut mt = Mesh::new(&base, opts).unwrap();
    let mut mm = Mesh::new(&mis, opts).unwrap();
    let geo = mt.geometry().clone();
    let b = geo.params.face_width_m;
    let th_x = -f_ma / (b * geo.alpha_wt.cos());
    let gear = BodyPose { th_x, ..BodyPose::default() };
    let pitch = geo.pinion.angular_pitch();
    let te = 30e-6;
    let mut worst: f64 = 0.0;
    for k in 0..8 {
        let phi = pitch * (k as f64 / 8.0 + 0.03);
        let st = posed(state(&mt, phi, te), BodyPose::default(), gear);
        let sm = state(&mm, phi, te + 0.5 * f_ma);
        let (ot, dt) = eval(&mut mt, &st);
        let (om, dm) = eval(&mut mm, &sm);
        let (lt, lm) = (face_load(&dt), face_load(&dm));
        assert_eq!(lt.len(), lm.len());
        let k_h = |l: &[f64]| {
            let mean = l.iter().sum::<f64>() / l.len() as f64;
            l.iter().fold(0.0f64, |a, &v| a.max(v)) / mean
        };
        let (kt, km) = (k_h(&lt), k_h(&lm));
        worst = worst.max((kt / km - 1.0).abs());
        assert!(
            (kt / km - 1.0).abs() <= 0.02,
            "phase {k}: K_Hβ tilt {kt:.4}, misalignment {km:.4}"
        );
        assert!(
            (ot.m_f_p / om.m_f_p - 1.0).abs() <= 0.02,
            "phase {k}: M_F,p tilt {:.3}, misalignment {:.3}",
            ot.m_f_p,
            om.m_f_p
        );
    }
    eprintln!("largest K_Hβ difference: {:.3} %", 100.0 * worst);
}

/// A pose component beyond 0.05·m_n (tilt: 0.05·m_n/b), a rate beyond 2e5 rad/s times that, or
/// a non-finite one is an error naming it; every limit is usable (the bound itself evaluates); the table, which holds only the
/// rigid-bearing mesh, refuses a pose instead of ignoring it.
#[test]
fn the_bounds_name_the_component_and_rigid_only_paths_refuse() {
    let pair = GearPair::paper_table1();
    let mut m = Mesh::new(&pair, winkler(30)).unwrap();
    let mn = pair.normal_module_m;
    let b = pair.face_width_m;
    let s0 = state(&m, 0.01, 30e-6);
    let at_bound =
        BodyPose { u_x: 0.05 * mn, u_y: -0.05 * mn, th_y: 0.05 * mn / b, ..BodyPose::default() };
    m.evaluate(&posed(s0, BodyPose::default(), at_bound)).expect("the bound is usable");
    let beyond = BodyPose { u_y: 0.051 * mn, ..BodyPose::default() };
    let e = m.evaluate(&posed(s0, BodyPose::default(), beyond)).unwrap_err().to_string();
    assert!(e.contains("u_g_y") && e.contains("0.05"), "{e}");
    let tilt = BodyPose { th_x: 0.06 * mn / b, ..BodyPose::default() };
    let e = m.evaluate(&posed(s0, tilt, BodyPose::default())).unwrap_err().to_string();
    assert!(e.contains("th_p_x"), "{e}");
    let nan = MeshState { rate_g: BodyPose { u_z: f64::NAN, ..BodyPose::default() }, ..s0 };
    let e = m.evaluate(&nan).unwrap_err().to_string();
    assert!(e.contains("v_g_z"), "{e}");
    // Rates up to 2e5 rad/s times the pose bound: 30 m/s and 2 000 rad/s for Table 1; the
    // bounds themselves evaluate, beyond them an error.
    let (v_max, om_max) = (2e5 * 0.05 * mn, 2e5 * 0.05 * mn / b);
    let fast = BodyPose { u_x: v_max, th_y: -om_max, ..BodyPose::default() };
    let o = m.evaluate(&MeshState { rate_p: fast, rate_g: fast, ..s0 }).unwrap();
    assert!(o.m_d_p.is_finite() && o.m_d_g.is_finite());
    let e = m
        .evaluate(&MeshState {
            rate_g: BodyPose { u_y: 1.01 * v_max, ..BodyPose::default() },
            ..s0
        })
        .unwrap_err()
        .to_string();
    assert!(e.contains("v_g_y"), "{e}");
    let e = m
        .evaluate(&MeshState { rate_p: BodyPose { th_x: 1e300, ..BodyPose::default() }, ..s0 })
        .unwrap_err()
        .to_string();
    assert!(e.contains("om_p_x"), "{e}");

    let small = BodyPose { u_x: 1e-6, ..BodyPose::default() };
    // The Jacobian at a pose is provided (`the_pose_jacobian_matches_central_differences`).
    assert!(m.mesh_jacobian(&posed(s0, BodyPose::default(), small)).unwrap().1.pose.is_some());
    let topts = MeshOptions { fidelity: Fidelity::Table, ..common::small_table_options() };
    let mut t = Mesh::new(&pair, topts).unwrap();
    // The table evaluates a pose (`tests/table_pose.rs` measures its error), but its Jacobian
    // at a pose is refused, never given as if the bodies were at rest.
    assert!(t.evaluate(&posed(s0, BodyPose::default(), small)).is_ok());
    let e = t.mesh_jacobian(&posed(s0, BodyPose::default(), small)).unwrap_err();
    assert!(matches!(e, MeshError::Unsupported(_)), "{e}");
    assert!(e.to_string().contains("full fidelity"), "{e}");
}

/// Eq. 14 damps the approach rate. A gear body moving at v along x opens the driving flanks at
/// v·sin α_wt, which is the approach rate of a gear speed lower by v·sin α_wt/r_bg... so the
/// damping torques equal those of that speed, to rounding (module docs of `pose`, "Damping").
#[test]
fn body_velocity_enters_the_damping_as_an_approach_rate() {
    let pair = GearPair::paper_table1();
    let mut m = Mesh::new(&pair, winkler(40)).unwrap();
    let geo = m.geometry().clone();
    let s0 = MeshState { w_p: 100.0, w_g: -63.0, ..state(&m, 0.02, 30e-6) };
    let v = 0.01;
    let moving = MeshState { rate_g: BodyPose { u_x: v, ..BodyPose::default() }, ..s0 };
    let (o1, _) = eval(&mut m, &moving);
    let slower = MeshState { w_g: s0.w_g - v * geo.alpha_wt.sin() / geo.gear.rb, ..s0 };
    let (o2, _) = eval(&mut m, &slower);
    assert!(o1.m_d_p != 0.0);
    assert!((o1.m_d_p - o2.m_d_p).abs() <= 1e-12 * o2.m_d_p.abs(), "{} {}", o1.m_d_p, o2.m_d_p);
    assert!((o1.m_d_g - o2.m_d_g).abs() <= 1e-12 * o2.m_d_g.abs());
    // The elastic part does not see a rate.
    assert_eq!(o1.m_f_p, eval(&mut m, &s0).0.m_f_p);
}

/// The pose columns of the Jacobian, in the order pose_p, pose_g, rate_p, rate_g (five
/// components each), and the angle and speed columns, against central differences of
/// `evaluate`, at a state where the loaded set of slices is the same at ±step; at rest and at a
/// pose with every component non-zero. Per row and per group of columns of one unit (angles,
/// speeds, translations, tilts, translation rates, tilt rates), the largest disagreement beyond
/// the difference quotient's rounding (1e3·ε·|torque|/step) must stay within 1e-5 of the
/// group's largest entry.
#[test]
fn the_pose_jacobian_matches_central_differences() {
    let pair = GearPair::paper_table1();
    let mut m =
        Mesh::new(&pair, MeshOptions { slices: 50, detail: true, ..MeshOptions::default() })
            .unwrap();
    let geo = m.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let w_p = 300.0;
    let w_g = (1e-3 - w_p * geo.pinion.rb) / geo.gear.rb;
    let pose_p = BodyPose { u_x: -3e-6, u_y: 2e-6, u_z: 5e-6, th_x: 1.5e-4, th_y: -1e-4 };
    let pose_g = BodyPose { u_x: 4e-6, u_y: -1e-6, u_z: -6e-6, th_x: -2e-4, th_y: 2.5e-4 };
    let rate = BodyPose { u_x: 1e-3, u_y: -2e-3, u_z: 5e-4, th_x: 0.02, th_y: -0.01 };
    let torques = |o: &MeshOutputs| [o.m_f_p, o.m_f_g, o.m_d_p, o.m_d_g];
    let loaded = |m: &Mesh| -> Vec<(i64, bool, u64)> {
        m.slices()
            .iter()
            .filter(|s| s.q_n_per_m > 0.0)
            .map(|s| (s.pair, s.back, s.zeta.to_bits()))
            .collect()
    };
    let (mut checked, mut worst) = (0, 0.0f64);
    for at_rest in [true, false] {
        for k in 0..4 {
            let phi_p = pitch * (k as f64 + 0.3) / 4.0;
            let mut s = MeshState {
                phi_p,
                phi_g: geo.phi_g_for_te(phi_p, 40e-6),
                w_p,
                w_g,
                ..Default::default()
            };
            if !at_rest {
                s = MeshState {
                    pose_p,
                    pose_g,
                    rate_p: rate,
                    rate_g: BodyPose { u_x: -rate.u_y, ..rate },
                    ..s
                };
            }
            m.forget_history();
            let (out, jac) = m.mesh_jacobian(&s).unwrap();
            let pj = jac.pose.expect("full fidelity provides the pose columns");
            // Exact columns: angles and speeds, then the 20 pose columns.
            let mut exact = [[0.0; 24]; 4];
            for i in 0..4 {
                exact[i][..4].copy_from_slice(&jac.d[i]);
                for (b, block) in
                    [pj.d_pose_p, pj.d_pose_g, pj.d_rate_p, pj.d_rate_g].iter().enumerate()
                {
                    exact[i][4 + 5 * b..9 + 5 * b].copy_from_slice(&block[i]);
                }
            }
            m.forget_history();
            m.evaluate(&s).unwrap();
            let base = loaded(&m);
            let step = |j: usize| match j {
                0 | 1 => 3e-9,
                2 | 3 => 1e-3,
                _ => match ((j - 4) / 5, (j - 4) % 5) {
                    (0 | 1, 0..=2) => 1e-10,
                    (0 | 1, _) => 1e-8,
                    _ => 1e-3,
                },
            };
            let mut fd = [[0.0; 24]; 4];
            let mut same = true;
            for j in 0..24 {
                let h = step(j);
                let mut at = |sign: f64| {
                    let mut x = s;
                    match j {
                        0 => x.phi_p += sign * h,
                        1 => x.phi_g += sign * h,
                        2 => x.w_p += sign * h,
                        3 => x.w_g += sign * h,
                        _ => {
                            let body = match (j - 4) / 5 {
                                0 => &mut x.pose_p,
                                1 => &mut x.pose_g,
                                2 => &mut x.rate_p,
                                _ => &mut x.rate_g,
                            };
                            let mut v = body.values();
                            v[(j - 4) % 5] += sign * h;
                            *body = BodyPose::from_values(v);
                        }
                    }
                    m.forget_history();
                    let o = m.evaluate(&x).unwrap();
                    (torques(&o), loaded(&m) == base)
                };
                let ((plus, sp), (minus, sm)) = (at(1.0), at(-1.0));
                same &= sp && sm;
                for i in 0..4 {
                    fd[i][j] = (plus[i] - minus[i]) / (2.0 * h);
                }
            }
            if !same {
                continue;
            }
            let t = torques(&out);
            let groups: [std::ops::Range<usize>; 10] =
                [0..2, 2..4, 4..7, 7..9, 9..12, 12..14, 14..17, 17..19, 19..22, 22..24];
            for i in 0..4 {
                for g in groups.iter().cloned() {
                    let scale = g
                        .clone()
                        .map(|j| fd[i][j].abs().max(exact[i][j].abs()))
                        .fold(0.0, f64::max);
                    for j in g {
                        let noise = 1e3 * f64::EPSILON * t[i].abs() / step(j);
                        let e = ((exact[i][j] - fd[i][j]).abs() - noise).max(0.0);
                        if e > 0.0 {
                            let rel = e / (1e-5 * scale);
                            worst = worst.max(rel);
                            assert!(
                                rel <= 1.0,
                                "rest {at_rest}, phase {k}, row {i}, column {j}: exact {:e}, differences {:e}",
                                exact[i][j],
                                fd[i][j]
                            );
                        }
                    }
                }
            }
            checked += 1;
        }
    }
    eprintln!("pose Jacobian: {checked} states, worst disagreement {worst:.3}·1e-5 of the group");
    assert!(checked >= 5, "only {checked} states kept their loaded set");
}
