//! Regression tests of the stated limits: every advertised bound is usable and one past it is
//! an error naming the value, the limit and what to change, never a late failure deep inside
//! the model or a number with a success status. Speeds (start at ±1e5 rad/s, refused beyond),
//! torques (ISO 6336 rating, the drive line's driving flank, the table's design torque), the
//! face width against the module, tooth numbers (memory independent of z), the work bounds
//! (the TE spectrum by FFT, the table build and the full-fidelity unit step counted in
//! slice-evaluations), the sweep's arguments checked first, and the bearing JSON's messages.

mod common;

use std::ffi::CStr;
use std::ptr::null;

use helical_gear_mesh::capi::*;
use helical_gear_mesh::dynamics::{
    Clearance, ConstantStiffnessMesh, DriveUnit, Drivetrain, GearDynamics, SweepOptions, UnitKind,
    UnitStepping, check_sweep_request,
};
use helical_gear_mesh::geometry::PairGeometry;
use helical_gear_mesh::mesh::statics::EquilibriumSettings;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions};
use helical_gear_mesh::params::{DriveLine, GearPair};

use common::small_table_options;

fn table1_drive() -> Drivetrain {
    Drivetrain::from_pair(&GearPair::paper_table1(), &DriveLine::paper_table1()).unwrap()
}

fn unit_error(u: *const HgmUnit) -> String {
    unsafe { CStr::from_ptr(hgm_unit_last_error(u)) }.to_string_lossy().into_owned()
}

#[test]
fn iso_root_stress_refuses_torques_beyond_1e9_naming_the_torque() {
    use helical_gear_mesh::iso6336::{MAX_TORQUE_NM, nominal_root_stress};
    let p = GearPair::paper_table1();
    let g = PairGeometry::new(&p).unwrap();
    // The bound itself is rated, finite, and σ_F0 is linear in the torque.
    let at = nominal_root_stress(&p, &g, MAX_TORQUE_NM).unwrap();
    let base = nominal_root_stress(&p, &g, 100.0).unwrap();
    let ratio = at.pinion.sigma_f0_pa / base.pinion.sigma_f0_pa;
    assert!((ratio / 1e7 - 1.0).abs() < 1e-9, "σ_F0 linear in T: {ratio:e}");
    for t in [1.0000001e9, 1e12, 1e300, 1e308, -1e308, f64::INFINITY] {
        let e = nominal_root_stress(&p, &g, t).unwrap_err().to_string();
        assert!(e.contains("torque_nm") && e.contains("1e9"), "T = {t:e}: {e}");
        assert!(!e.contains("rack_fillet_radius_mn"), "{e}");
    }
}

/// The amplitude spectrum by FFT against a direct DFT written out here (the oracle), on a
/// prime length and a composite one, and a 10⁶-sample record (the spectrum's bound) in a
/// fraction of the hours the direct DFT took, with its planted line recovered.
#[test]
fn te_spectrum_is_an_fft_equal_to_the_direct_dft() {
    use helical_gear_mesh::numeric::amplitude_spectrum;
    let mut s = 0x9e37_79b9_7f4a_7c15_u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for n in [97usize, 1000, 1410] {
        let x: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let fast = amplitude_spectrum(&x);
        assert_eq!(fast.len(), n / 2 + 1);
        for (j, a) in fast.iter().enumerate() {
            let (mut re, mut im) = (0.0f64, 0.0f64);
            for (i, v) in x.iter().enumerate() {
                let ang = std::f64::consts::TAU * ((i * j) % n) as f64 / n as f64;
                re += v * ang.cos();
                im -= v * ang.sin();
            }
            let scale = if j == 0 || 2 * j == n { 1.0 } else { 2.0 };
            let direct = scale * re.hypot(im) / n as f64;
            assert!((a - direct).abs() < 1e-13, "n {n}, bin {j}: {a:e} vs {direct:e}");
        }
    }
    let n = 1_000_000;
    let x: Vec<f64> = (0..n)
        .map(|i| 1.5 + 0.25 * (std::f64::consts::TAU * 4700.0 * i as f64 / n as f64).cos())
        .collect();
    let t0 = std::time::Instant::now();
    let a = amplitude_spectrum(&x);
    assert!(t0.elapsed().as_secs_f64() < 20.0, "{:?}", t0.elapsed());
    assert!((a[0] - 1.5).abs() < 1e-12 && (a[4700] - 0.25).abs() < 1e-12);
    assert!(a.iter().enumerate().filter(|&(j, _)| j != 0 && j != 4700).all(|(_, v)| *v < 1e-9));
}

/// The largest nominal speed, 1e5 rad/s, is an operating point: a unit on the real mesh starts
/// there (and at −1e5, running backwards) and steps, although its vibration takes the state
/// past 1e5 at once (the states' bound is twice that). A start beyond it is an error naming
/// `w_p_start` and the bound, at the library and the C API.
#[test]
fn units_start_and_step_at_the_largest_speed_and_refuse_beyond() {
    let pair = GearPair::paper_table1();
    let mesh = Mesh::new(&pair, small_table_options()).unwrap();
    let drive = table1_drive();
    for w in [1e5, -1e5, -100.0] {
        let mut u = DriveUnit::new(
            UnitKind::Drive,
            mesh.clone(),
            drive,
            UnitStepping::Rk4 { steps_per_mesh_period: 128 },
        )
        .unwrap();
        u.start_static(0.0, w, &EquilibriumSettings::default()).unwrap();
        for _ in 0..4 {
            u.advance(2e-6).unwrap_or_else(|e| panic!("w = {w}: {e}"));
        }
        let wp = u.state()[5];
        assert!((wp - w).abs() < 1e-3 * w.abs(), "w = {w}: ω_p = {wp}");
    }
    let mut u = DriveUnit::new(
        UnitKind::Drive,
        mesh,
        drive,
        UnitStepping::Rk4 { steps_per_mesh_period: 128 },
    )
    .unwrap();
    let e = u.start_static(0.0, 1e9, &EquilibriumSettings::default()).unwrap_err().to_string();
    assert!(e.contains("w_p_start") && e.contains("1e5"), "{e}");
    // The whole-drive model's start (CLI and Python simulate) and its default step.
    let mut g = GearDynamics::new(Mesh::new(&pair, small_table_options()).unwrap(), drive).unwrap();
    g.static_start(0.0, -1e5, &EquilibriumSettings::default()).unwrap();
    let e = g.static_start(0.0, 1.5e5, &EquilibriumSettings::default()).unwrap_err().to_string();
    assert!(e.contains("omega_p") && e.contains("1e5"), "{e}");
    let h = helical_gear_mesh::dynamics::default_rk4_step(&mut g, -100.0, 0.0, 1e-3).unwrap();
    let h_pos = helical_gear_mesh::dynamics::default_rk4_step(&mut g, 100.0, 0.0, 1e-3).unwrap();
    assert_eq!(h, h_pos, "the step depends on |ω_p|");
}

#[test]
fn c_api_start_static_refuses_1e9_rad_s_and_accepts_negative_speeds() {
    let u = unsafe { hgm_unit_create(2, null(), null(), HgmFidelity::Full as i32, 128, 0.0, 0.0) };
    assert!(!u.is_null(), "{}", unit_error(null()));
    unsafe {
        assert_ne!(hgm_unit_start_static(u, 0.0, 1e9), HgmStatus::Ok);
        let m = unit_error(u);
        assert!(m.contains("w_p_start") && m.contains("1e5"), "{m}");
        for w in [-100.0, 0.0, 1e5, -1e5] {
            assert_eq!(hgm_unit_start_static(u, 0.0, w), HgmStatus::Ok, "{}", unit_error(u));
        }
        hgm_unit_free(u);
    }
}

#[test]
fn drive_torque_is_positive_the_pinion_driving() {
    let mut d = DriveLine::paper_table1();
    d.torque_nm = -100.0;
    let e = d.check().unwrap_err().to_string();
    assert!(e.contains("drive.torque_nm") && e.contains("driving flanks"), "{e}");
    // The lower bound, 1 N·m, starts a unit.
    d.torque_nm = 1.0;
    d.check().unwrap();
    let drive = Drivetrain::from_pair(&GearPair::paper_table1(), &d).unwrap();
    let mesh = ConstantStiffnessMesh::new(3e8, 100.0, 0.05, 0.08, Clearance::Bilateral).unwrap();
    let mut u = DriveUnit::new(
        UnitKind::Drive,
        mesh,
        drive,
        UnitStepping::Rk4 { steps_per_mesh_period: 64 },
    )
    .unwrap();
    u.start_static(0.0, 100.0, &EquilibriumSettings::default()).unwrap();
    u.advance(1e-3).unwrap();
}

#[test]
fn table_design_torque_the_pair_cannot_carry_names_the_option() {
    let pair = GearPair::paper_table1();
    let options = MeshOptions { table_design_torque_nm: 1e9, ..small_table_options() };
    let e = Mesh::new(&pair, options).unwrap_err().to_string();
    assert!(
        e.contains("table_design_torque_nm") && e.contains("validity range") && e.contains("lower"),
        "{e}"
    );
}

#[test]
fn table_build_work_is_bounded_in_node_slices_before_any_work() {
    let pair = GearPair::paper_table1();
    // 256 × 256 nodes sampled at 200 slices: two minutes of build, refused at once.
    let options = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: 256,
        table_te_points: 256,
        slices: 200,
        table_slices: 200,
        ..MeshOptions::default()
    };
    let t0 = std::time::Instant::now();
    let e = Mesh::new(&pair, options).unwrap_err().to_string();
    assert!(e.contains("slices") && e.contains("6.5536e6") && e.contains("minute"), "{e}");
    assert!(t0.elapsed().as_secs_f64() < 1.0, "refused before the FE: {:?}", t0.elapsed());
}

#[test]
fn full_fidelity_unit_step_is_bounded_in_slice_evaluations() {
    use helical_gear_mesh::dynamics::limits::MAX_UNIT_SLICE_EVALUATIONS;
    let pair = GearPair::paper_table1();
    let mesh = Mesh::new(&pair, MeshOptions::default()).unwrap();
    let mut u = DriveUnit::new(
        UnitKind::Drive,
        mesh,
        table1_drive(),
        UnitStepping::Rk4 { steps_per_mesh_period: 65_536 },
    )
    .unwrap();
    u.start_static(0.0, 300.0, &EquilibriumSettings::default()).unwrap();
    let (t0, y0) = (u.time(), u.state().to_vec());
    // 1e-2 s at 65 536 sub-steps per mesh period: 9.4e5 sub-steps (within the sub-step bound)
    // × 4 × 200 slices = 7.5e8 slice-evaluations (27 minutes).
    let e = u.advance(1e-2).unwrap_err().to_string();
    assert!(e.contains("slice-evaluations") && e.contains("1e7"), "{e}");
    assert_eq!((u.time(), u.state()), (t0, y0.as_slice()), "state untouched");
    // The message's count is the bound's measure: sub-steps × 4 × 200 slices, above the bound.
    let n: f64 =
        e.split(" RK4 sub-steps").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    assert!(n < 1e6 && 4.0 * n * 200.0 > MAX_UNIT_SLICE_EVALUATIONS, "{n:e}: {e}");
}

#[test]
fn sweep_arguments_are_checked_before_any_work() {
    let ok = SweepOptions::default();
    let e = check_sweep_request(&[], &ok).unwrap_err().to_string();
    assert!(e.contains("speeds") && e.contains("at least one"), "{e}");
    assert!(!e.contains("inf"), "{e}");
    let e = check_sweep_request(&[100.0, 2e5], &ok).unwrap_err().to_string();
    assert!(e.contains("speeds") && e.contains("1e5"), "{e}");
    let e = check_sweep_request(&[100.0], &SweepOptions { threads: Some(0), ..ok.clone() })
        .unwrap_err()
        .to_string();
    assert!(e.contains("threads"), "{e}");
    let bad = SweepOptions { min_prominence: f64::NAN, ..ok.clone() };
    let e = check_sweep_request(&[100.0], &bad).unwrap_err().to_string();
    assert!(e.contains("min_prominence"), "{e}");
    check_sweep_request(&[100.0, 1e5], &ok).unwrap();
}

#[test]
fn face_width_is_bounded_by_40_normal_modules() {
    let mut p = GearPair::paper_table1();
    p.face_width_m = 10.0;
    let e = p.check_params().unwrap_err().to_string();
    assert!(e.contains("face_width_m") && e.contains("40·normal_module_m"), "{e}");
    assert!(e.contains("raise normal_module_m"), "{e}");
    // The bound itself is a valid pair.
    p.face_width_m = 40.0 * p.normal_module_m;
    PairGeometry::new(&p).unwrap();
}

/// The body inertia from one tooth times z equals the whole outline's polygon moment (the
/// oracle), and z = 100 000 (the bound) costs no memory in proportion to z: its inertia lies
/// between those of the root and the tip discs.
#[test]
fn tooth_numbers_up_to_the_bound_take_memory_independent_of_z() {
    use helical_gear_mesh::geometry::inertia::{gear_body_inertia, polygon_polar_moment};
    let p = GearPair::paper_table1();
    let g = PairGeometry::new(&p).unwrap();
    let (b, rb, rho) = (p.face_width_m, 0.5 * p.bore_diameter_m, p.material_p.density_kg_m3);
    for gear in [&g.pinion, &g.gear] {
        let whole = rho
            * b
            * (polygon_polar_moment(&gear.outline(120)) - std::f64::consts::PI * rb.powi(4) / 2.0);
        let fast = gear_body_inertia(gear, b, rb, rho);
        assert!((fast / whole - 1.0).abs() < 1e-12, "{fast:e} vs {whole:e}");
    }
    let mut big = p.clone();
    big.z_p = 100_000;
    big.z_g = 100_000;
    big.normal_module_m = 1e-4;
    big.face_width_m = 2e-3;
    let t0 = std::time::Instant::now();
    let g = PairGeometry::new(&big).unwrap();
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
    let disc =
        |r: f64| rho * big.face_width_m * std::f64::consts::PI / 2.0 * (r.powi(4) - rb.powi(4));
    let j = gear_body_inertia(&g.pinion, big.face_width_m, rb, rho);
    assert!(disc(g.pinion.rf) < j && j < disc(g.pinion.ra), "{j:e}");
}

#[test]
fn bearing_json_errors_name_the_key() {
    use helical_gear_mesh::mesh::bearings::BearingArrangement;
    let bad = |t: &str| BearingArrangement::from_json(t).unwrap_err().to_string();
    let e = bad("bearings.json");
    assert!(e.contains("not JSON") && !e.contains("NaN"), "{e}");
    let e = bad(r#"{"pinion": {"locating_z_m": 0.0, "floating_z_m": "x"}, "gear": {}}"#);
    assert!(e.contains("pinion.floating_z_m") && e.contains("number"), "{e}");
    let e = bad(
        r#"{"pinion": {"locating_z_m": 0.0, "floating_z_m": 0.05}, "gear": {"locating_z_m": 0.0}}"#,
    );
    assert!(e.contains("gear.floating_z_m") && e.contains("missing"), "{e}");
    let e = bad(r#"{"pinion": {"locating_z_m": 0.0, "floating_z_m": 0.05, "x": 1}, "gear": {}}"#);
    assert!(e.contains("pinion.x") && e.contains("unknown"), "{e}");
    let e = bad(r#"{"pinion": {"locating_z_m": 0.0, "floating_z_m": 0.05},
                     "gear": {"locating_z_m": 0.0, "floating_z_m": 5e3}}"#);
    assert!(e.contains("gear.floating_z_m") && e.contains("1000"), "{e}");
    assert!(!e.contains("`bearings` = NaN"), "{e}");
}

/// The FMUs take the same start speeds as the library and the C API: −100 rad/s (running
/// backwards) starts and steps the Drive; beyond ±1e5 rad/s `w_p_start` is refused when set.
#[test]
fn fmu_drive_starts_backwards_and_refuses_speeds_beyond_the_bound() {
    use common::fmi::ModelFmu;
    use helical_gear_mesh::fmi2::exports::*;
    use helical_gear_mesh::fmi2::models::unit::DRIVE;
    use helical_gear_mesh::fmi2::types::*;
    let coarse = |f: &ModelFmu| {
        for (n, v) in [("slices", 30), ("table_phase_points", 24), ("table_te_points", 16)] {
            let vr = DRIVE.by_name(n).unwrap().vr;
            assert_eq!(unsafe { fmi2SetInteger(f.0, &vr, 1, &v) }, fmi2Status::Ok);
        }
    };
    // Parameters are checked when initialisation ends.
    let g = ModelFmu::instantiate(&DRIVE, FMI2_CO_SIMULATION);
    coarse(&g);
    g.set(&["w_p_start"], &[1e9]);
    unsafe {
        assert_eq!(fmi2SetupExperiment(g.0, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(g.0), fmi2Status::Ok);
        assert_ne!(fmi2ExitInitializationMode(g.0), fmi2Status::Ok);
    }
    let f = ModelFmu::instantiate(&DRIVE, FMI2_CO_SIMULATION);
    coarse(&f);
    f.set(&["w_p_start"], &[-100.0]);
    f.init();
    for k in 0..4 {
        let st = unsafe { fmi2DoStep(f.0, k as f64 * 1e-4, 1e-4, 1) };
        assert_eq!(st, fmi2Status::Ok);
    }
    let [w, te] = f.get(&["w_p", "TE"])[..] else { unreachable!() };
    assert!((w + 100.0).abs() < 1.0 && te.is_finite() && te > 0.0, "w_p {w}, TE {te:e}");
}
