//! Tests of `results`: every record round-trips through JSON unchanged, `check_finite` names
//! the first non-finite field, and the static record of a constant-stiffness mesh has its
//! closed form (STE = M/(g_p·k), mean stiffness k).

use helical_gear_mesh::dynamics::{Clearance, ConstantStiffnessMesh, SweepResult, Trajectory};
use helical_gear_mesh::mesh::MeshOutputs;
use helical_gear_mesh::mesh::statics::static_curve;
use helical_gear_mesh::results::{
    BearingForceRecord, GeometryRecord, StaticCurveRecord, SupportForceRecord, SupportedRunRecord,
    SweepRecord, TrajectoryRecord,
};
use helical_gear_mesh::{GearPair, PairGeometry};
use serde::Serialize;
use serde::de::DeserializeOwned;

fn round_trip<T: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug>(r: &T) {
    let text = serde_json::to_string(r).unwrap();
    let back: T = serde_json::from_str(&text).unwrap();
    assert_eq!(&back, r, "{text}");
}

fn geometry() -> GeometryRecord {
    let p = GearPair::paper_table1();
    GeometryRecord::new(&PairGeometry::new(&p).unwrap(), &p)
}

/// Constant stiffness k = 4e8 N/m on g_p = 0.05 m, M = 100 N·m: STE = 5 µm everywhere.
fn static_record() -> StaticCurveRecord {
    let (k, g_p) = (4e8, 0.05);
    let mut mesh = ConstantStiffnessMesh::new(k, 0.0, g_p, 0.1, Clearance::Separating).unwrap();
    let curve = static_curve(&mut mesh, 100.0, 0.0, 0.2, 5, 1).unwrap();
    StaticCurveRecord::new(&curve, g_p)
}

fn sweep_record() -> SweepRecord {
    let curve = static_curve(
        &mut ConstantStiffnessMesh::new(4e8, 0.0, 0.05, 0.1, Clearance::Separating).unwrap(),
        100.0,
        0.0,
        0.2,
        4,
        1,
    )
    .unwrap();
    let r = SweepResult {
        ste: curve,
        points: Vec::new(),
        resonances: Vec::new(),
        mesh_stiffness: Some(4e8),
        max_step: Some(1e-5),
        wall_seconds: 0.25,
    };
    let mut s = SweepRecord::new(&r, &[]);
    // The per-speed arrays of a three-speed sweep (the constructor's mapping is the identity).
    s.speeds_rad_s = vec![100.0, 200.0, 300.0];
    s.te_max_over_ste_max = vec![1.1, 1.6, 1.2];
    s.te_min_over_ste_max = vec![0.9, -0.1, 0.8];
    s.separated = vec![false, true, false];
    s.back_contact = vec![false; 3];
    s.tip_contact = vec![false, true, false];
    s.steady = vec![true; 3];
    s.mesh_efficiency_mean = vec![1.0, 0.99, 0.985];
    s.period_multiple = vec![1; 3];
    s.periods = vec![40.0, 52.5, 40.0];
    s.resonances_rad_s = vec![205.0];
    s.resonance_te_max_over_ste_max = vec![1.65];
    s.resonance_brackets_rad_s = vec![[100.0, 300.0]];
    s.peak_te_max_over_ste_max = 1.65;
    s
}

fn trajectory_record() -> TrajectoryRecord {
    let out = MeshOutputs { te: 5e-6, m_f_p: 100.0, m_f_g: 200.0, ..MeshOutputs::default() };
    let tr = Trajectory {
        time: vec![0.0, 1e-4],
        states: vec![[0.1, 0.2, 0.3, 0.4, 100.0, 100.0, 50.0, 50.0]; 2],
        outputs: vec![out; 2],
        steps: 1,
        mesh_evaluations: 4,
    };
    TrajectoryRecord::new(&tr)
}

#[test]
fn every_record_round_trips_through_json() {
    round_trip(&geometry());
    round_trip(&static_record());
    round_trip(&sweep_record());
    round_trip(&trajectory_record());
    // An absent relief start stays absent (null).
    let mut g = geometry();
    g.relief_start_radius_p_m = None;
    round_trip(&g);
}

#[test]
fn check_finite_names_the_first_non_finite_field() {
    assert_eq!(geometry().check_finite(), Ok(()));
    assert_eq!(static_record().check_finite(), Ok(()));
    assert_eq!(sweep_record().check_finite(), Ok(()));
    assert_eq!(trajectory_record().check_finite(), Ok(()));

    let mut g = geometry();
    g.base_pitch_m = f64::NAN;
    g.j_g_kgm2 = f64::NAN;
    assert!(g.check_finite().unwrap_err().contains("base_pitch_m"), "the first one is named");
    let mut g = geometry();
    g.relief_start_radius_g_m = Some(f64::INFINITY);
    assert!(g.check_finite().unwrap_err().contains("relief_start_radius_g_m"));

    let mut s = static_record();
    s.ste_um[3] = f64::NAN;
    assert!(s.check_finite().unwrap_err().contains("ste_um[3]"));
    let mut s = static_record();
    s.mesh_stiffness_mean_n_per_um = f64::NEG_INFINITY;
    assert!(s.check_finite().unwrap_err().contains("mesh_stiffness_mean_n_per_um"));

    let mut w = sweep_record();
    w.te_max_over_ste_max[1] = f64::NAN;
    assert!(w.check_finite().unwrap_err().contains("te_max_over_ste_max[1]"));
    let mut w = sweep_record();
    w.resonance_brackets_rad_s[0][1] = f64::NAN;
    assert!(w.check_finite().unwrap_err().contains("resonance_brackets_rad_s"));

    let mut t = trajectory_record();
    t.mesh.get_mut("m_d_g_nm").unwrap()[1] = f64::NAN;
    assert!(t.check_finite().unwrap_err().contains("m_d_g_nm[1]"));
}

#[test]
fn static_record_of_a_constant_stiffness_mesh_is_the_closed_form() {
    let s = static_record();
    assert_eq!(s.ste_um.len(), 5);
    for &x in &s.ste_um {
        assert!((x - 5.0).abs() < 1e-6, "STE {x} µm vs M/(g_p·k) = 5 µm");
    }
    assert!((s.ste_max_um - 5.0).abs() < 1e-6 && (s.ste_min_um - 5.0).abs() < 1e-6);
    assert!(s.ste_peak_to_peak_um.abs() < 1e-6);
    assert!((s.mesh_stiffness_mean_n_per_um - 400.0).abs() < 1e-4, "k = 4e8 N/m = 400 N/µm");
    assert_eq!(s.torque_nm, 100.0);
}

#[test]
fn geometry_record_has_the_table1_values() {
    let p = GearPair::paper_table1();
    let g = PairGeometry::new(&p).unwrap();
    let r = GeometryRecord::new(&g, &p);
    assert_eq!(r.eps_alpha, g.eps_alpha);
    assert_eq!(r.base_radius_p_m, g.pinion.rb);
    assert_eq!(r.angular_pitch_p_rad, 2.0 * std::f64::consts::PI / p.z_p as f64);
    assert_eq!(r.assumptions, p.assumptions());
}

/// The keys of a serialised record, sorted.
fn keys<T: Serialize>(r: &T) -> Vec<String> {
    let v = serde_json::to_value(r).unwrap();
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

/// The records of the CLI's run outputs (static, simulate, sweep, spectrum, harris) round-trip
/// through JSON and keep the keys users parse, the run records with their inner record's keys
/// at the top level.
#[test]
fn run_records_round_trip_with_their_keys() {
    use helical_gear_mesh::results::{
        DynamicSpectrumRecord, HarrisRecord, HarrisVariantRecord, IsoRootStressSummary,
        SpectrumRecord, StaticFrictionSummary, StaticPointRecord, StaticRunRecord, SteadyRunRecord,
        SweepRunRecord, TrajectoryRunRecord,
    };
    let point = StaticPointRecord {
        phi_p_rad: 0.01,
        ste_um: 5.0,
        n_pairs: 2,
        p_max_pa: 1e9,
        tip_contact: false,
        contact_length_m: 0.05,
        k_h_beta: 1.2,
        line_load_max_n_per_mm: 300.0,
        line_load_mean_n_per_mm: 250.0,
        force_p_n: [-1.2e3, -3.4e3, 0.6e3],
        moment_p_nm: [1.5, -2.5],
        force_g_n: [1.2e3, 3.4e3, -0.6e3],
        moment_g_nm: [-1.5, 6.0],
        root_stress_p_pa: 1.4e8,
        root_stress_g_pa: 1.2e8,
        p_loss_w: 250.0,
        eta_mesh: 0.992,
        m_r_p_nm: 0.4,
        m_r_g_nm: -0.7,
        q_p_w: 120.0,
        q_g_w: 130.0,
        pose_p: None,
        pose_g: Some([1e-6, -2e-6, 0.5e-6, 1e-5, -2e-5]),
    };
    let st = StaticRunRecord {
        curve: static_record(),
        slices: 40,
        k_h_beta_max: 1.3,
        k_h_beta_cycle: 1.1,
        k_h_beta_iso: 1.2,
        f_beta_y_um: 10.0,
        c_gamma_n_per_mm_per_um: 18.0,
        model_build_s: 0.5,
        seconds: 1.0,
        iso: IsoRootStressSummary::new(
            &PairGeometry::new(&GearPair::paper_table1()).unwrap(),
            100.0,
        ),
        friction: StaticFrictionSummary {
            omega_p_rad_s: 300.0,
            mesh_loss_mean_w: 250.0,
            mesh_efficiency_mean: 1.0 - 250.0 / 30_000.0,
            loss_factor_h_v: 0.12,
            mu_mean: Some(0.05),
        },
        points: vec![point],
        bearings: None,
    };
    round_trip(&st);
    st.check_finite().unwrap();
    let mut expected = keys(&static_record());
    expected.extend(
        [
            "slices",
            "k_h_beta_max",
            "k_h_beta_cycle",
            "k_h_beta_iso",
            "f_beta_y_um",
            "c_gamma_n_per_mm_per_um",
            "model_build_s",
            "seconds",
            "root_stress_iso_p_pa",
            "root_stress_iso_g_pa",
            "iso6336",
            "iso6336_error",
            "omega_p_rad_s",
            "mesh_loss_mean_w",
            "mesh_efficiency_mean",
            "loss_factor_h_v",
            "mu_mean",
            "points",
        ]
        .map(String::from),
    );
    expected.sort();
    assert_eq!(keys(&st), expected);
    let mut bad = st.clone();
    bad.points[0].k_h_beta = f64::NAN;
    assert!(bad.check_finite().unwrap_err().contains("points[0].k_h_beta"));
    let mut bad = st.clone();
    bad.points[0].p_loss_w = f64::NAN;
    assert!(bad.check_finite().unwrap_err().contains("points[0].p_loss_w"));
    let mut bad = st.clone();
    bad.friction.mu_mean = Some(f64::INFINITY);
    assert!(bad.check_finite().unwrap_err().contains("mu_mean"));
    // Without friction μ is null.
    let mut none = st.clone();
    none.friction.mu_mean = None;
    round_trip(&none);
    assert!(serde_json::to_string(&none).unwrap().contains("\"mu_mean\":null"));

    let tr = TrajectoryRunRecord {
        trajectory: trajectory_record(),
        omega_p_rad_s: 0.0,
        t_end_s: 1e-3,
        method: "rk4".into(),
        dt_s: Some(1e-5),
        fidelity: "table".into(),
        mesh_period_s: None,
        te_static_start_m: 5e-6,
        columns: vec!["time_s".into()],
        supports: None,
    };
    round_trip(&tr);
    tr.check_finite().unwrap();
    let text = serde_json::to_string(&tr).unwrap();
    assert!(text.contains("\"mesh_period_s\":null"));
    // Rigid bearings: no bodies' columns, no supports block.
    assert!(!text.contains("\"bodies\"") && !text.contains("\"supports\""), "{text}");

    // On supports: the bodies' columns and the support-force statistics round-trip, and a
    // non-finite statistic is named.
    let mut on = tr.clone();
    let n = on.trajectory.time_s.len();
    on.trajectory.bodies.insert("u_p_x".into(), vec![1e-6; n]);
    on.trajectory.bodies.insert("R_p_x".into(), vec![-800.0; n]);
    on.supports = Some(SupportedRunRecord {
        modes_hz: vec![6.3, 1230.9],
        modes_damping_ratio: vec![0.001, 0.03],
        window_mesh_periods: 20,
        support_forces: [(
            "R_p_x".to_string(),
            SupportForceRecord {
                reaction_mean_n: -800.0,
                reaction_peak_to_peak_n: 350.0,
                orders: vec![11.8, 123.7],
            },
        )]
        .into(),
        bearings: vec![BearingForceRecord {
            shaft: "gear".into(),
            bearing: 0,
            z_m: -0.02,
            reaction_mean_n: vec![-906.6, -1091.3, 385.8],
            reaction_peak_to_peak_n: vec![258.3, 593.0, 42.7],
            orders: vec![vec![10.0, 20.0]; 3],
        }],
    });
    round_trip(&on);
    on.check_finite().unwrap();
    let cols: Vec<&str> = on.trajectory.columns().iter().map(|c| c.0).collect();
    assert_eq!(&cols[cols.len() - 2..], &["u_p_x", "R_p_x"]);
    let mut bad = on.clone();
    bad.supports.as_mut().unwrap().support_forces.get_mut("R_p_x").unwrap().orders[1] = f64::NAN;
    assert!(bad.check_finite().unwrap_err().contains("R_p_x.orders"));

    let sw = SweepRunRecord {
        sweep: sweep_record(),
        d_mesh_n_s_per_m: 1000.0,
        fidelity: "table".into(),
        steps_per_period: 64,
        supports: None,
    };
    round_trip(&sw);
    sw.check_finite().unwrap();
    let mut expected = keys(&sweep_record());
    expected.extend(["d_mesh_n_s_per_m", "fidelity", "steps_per_period"].map(String::from));
    expected.sort();
    assert_eq!(keys(&sw), expected);

    let sp = SpectrumRecord {
        torque_nm: 500.0,
        hunting_meshes: 30,
        pinion_revolutions: 1.0,
        ste_mean_um: 20.0,
        ste_peak_to_peak_um: 2.0,
        orders: vec![0.0, 30.0],
        amplitudes_um: vec![20.0, 1.0],
        seconds: 1.0,
    };
    round_trip(&sp);
    sp.check_finite().unwrap();
    let dy = DynamicSpectrumRecord {
        dynamic: SteadyRunRecord {
            speed_rad_s: 300.0,
            steady: true,
            mesh_periods_integrated: 120.5,
            te_max_um: 30.0,
            te_min_um: 10.0,
            separated: false,
        },
        period_meshes: 1,
        pinion_revolutions: 1.0 / 30.0,
        te_mean_um: 20.0,
        te_peak_to_peak_um: 20.0,
        orders: vec![0.0, 30.0],
        amplitudes_um: vec![20.0, 9.0],
        seconds: 1.0,
    };
    round_trip(&dy);
    dy.check_finite().unwrap();
    let ha = HarrisRecord {
        torques_nm: vec![50.0, 100.0],
        variants: vec![HarrisVariantRecord {
            name: "none".into(),
            ste_peak_to_peak_um: vec![1.0, f64::INFINITY],
        }],
    };
    assert!(ha.check_finite().unwrap_err().contains("none.ste_peak_to_peak_um[1]"));
}
