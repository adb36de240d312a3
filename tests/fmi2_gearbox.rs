//! `HelicalGearbox` through the exported FMI functions: the library's supported dynamics
//! (`dynamics::bodies`) behind the FMI layer. Oracles: the FMU repeats the library's
//! trajectory; supports 10⁶ times stiffer than the mesh give the `HelicalGearDrive`
//! trajectory; the start is a static equilibrium (support forces balance the mesh's, every
//! rate zero); a restored FMU state continues bit for bit; Model Exchange sees the state;
//! bad supports are refused.

mod common;

use std::ffi::CString;

use helical_gear_mesh::dynamics::Drivetrain;
use helical_gear_mesh::dynamics::bodies::{SupportedDynamics, simulate_supported};
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::models::gearbox::GEARBOX;
use helical_gear_mesh::fmi2::models::unit::DRIVE;
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::mesh::{EquilibriumSettings, Mesh, MeshOptions, Supports};
use helical_gear_mesh::{DriveLine, GearPair};

use common::fmi::ModelFmu as Fmu;

/// The guide's example supports: the defaults of the Real support parameters.
const EXAMPLE: &str = include_str!("../docs/gear-bodies/supports.json");

const SLICES: i32 = 40;

/// A Co-Simulation instance at full fidelity with 40 slices (cheap evaluations, no table).
fn full(m: &'static helical_gear_mesh::fmi2::model::ModelInfo, reals: &[(&str, f64)]) -> Fmu {
    let f = Fmu::instantiate(m, FMI2_CO_SIMULATION);
    set_ints(&f, &[("fidelity", 0), ("slices", SLICES)]);
    for (n, v) in reals {
        f.set(&[n], &[*v]);
    }
    f.init();
    f
}

fn set_ints(f: &Fmu, v: &[(&str, i32)]) {
    for (n, x) in v {
        let r = f.vrs(&[n]);
        assert_eq!(unsafe { fmi2SetInteger(f.0, r.as_ptr(), 1, x) }, fmi2Status::Ok, "{n}");
    }
}

fn step(f: &Fmu, t: f64, h: f64) {
    assert_eq!(unsafe { fmi2DoStep(f.0, t, h, 1) }, fmi2Status::Ok, "step at {t}");
}

fn te_max(te: &[f64]) -> f64 {
    te.iter().map(|x| x.abs()).fold(0.0, f64::max)
}

/// With the default supports (the Real parameters' defaults; the library is given the guide's
/// example file, so this also holds the defaults to that file) and communication steps of the
/// library's RK4 step, the FMU takes one sub-step per communication step: its TE and support force
/// repeat `simulate_supported` from the same static start. The FMU starts its load solver
/// cold at each step, the library warm-starts it: the two agree to the solver's tolerance
/// (the torque to ~10⁻¹¹).
#[test]
fn the_fmu_repeats_the_library_trajectory() {
    let pair = GearPair::paper_table1();
    let options = MeshOptions { slices: SLICES as usize, ..MeshOptions::default() };
    let mesh = Mesh::new(&pair, options).unwrap();
    let drive = Drivetrain::from_pair(&pair, &DriveLine::paper_table1()).unwrap();
    let supports = Supports::from_json_for(EXAMPLE, pair.face_width_m).unwrap();
    let mut lib = SupportedDynamics::new(mesh, drive, supports).unwrap();
    let omega = 300.0;
    let start = lib.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap();
    let modes = lib.linear_modes(&start).unwrap();
    let dt = helical_gear_mesh::dynamics::bodies::supported_rk4_step(&drive, &modes, omega);
    let n = 128;
    let tr = simulate_supported(&mut lib, &start.y, dt, n, &modes).unwrap();

    // The FMU's sub-step follows the current speed (T_m/N at w_p); with N = 100 the library's
    // step (T_m/128 or shorter at the nominal speed) stays one sub-step as the speed varies.
    let f = Fmu::instantiate(&GEARBOX, FMI2_CO_SIMULATION);
    set_ints(&f, &[("fidelity", 0), ("slices", SLICES), ("rk4_steps_per_mesh_period", 100)]);
    f.init();
    let te0 = f.get(&["TE"])[0];
    assert!((te0 - start.te).abs() <= 1e-12 * start.te.abs(), "{te0} {}", start.te);
    let (mut te, mut ry) = (vec![te0], vec![f.get(&["R_p_y"])[0]]);
    for i in 0..n {
        step(&f, i as f64 * dt, dt);
        let v = f.get(&["TE", "R_p_y"]);
        te.push(v[0]);
        ry.push(v[1]);
    }
    let te_lib: Vec<f64> = tr.drive.outputs.iter().map(|o| o.te).collect();
    let ry_lib: Vec<f64> = tr.reactions.iter().map(|r| r.pinion[1]).collect();
    let dev = te.iter().zip(&te_lib).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let dev_r = ry.iter().zip(&ry_lib).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let scale_r = te_max(&ry_lib);
    eprintln!(
        "{n} steps of {dt:.3e} s: max |ΔTE| = {:.2e} of TE, max |ΔR_p_y| = {:.2e} of R_p_y",
        dev / te_max(&te_lib),
        dev_r / scale_r
    );
    assert!(dev <= 1e-9 * te_max(&te_lib), "{dev}");
    assert!(dev_r <= 1e-9 * scale_r, "{dev_r}");
}

/// Supports 10⁶ times stiffer than the tooth pair (the library test
/// `stiff_supports_give_the_torsional_trajectory` derives the figures: the bodies move by 10⁻⁶
/// of TE) give the Drive's trajectory: one mesh period at 300 rad/s, both FMUs stepped with
/// communication steps of T_m/128. The Gearbox takes ~30 RK4 sub-steps per step for its stiff
/// body modes; the Drive is given 4096 sub-steps per mesh period (32 per step), so that both
/// are converged in the step (with one sub-step per communication step the Drive's own RK4
/// error at 40 slices, where slices enter contact one by one, is 1.5·10⁻⁵ of TE). The
/// difference is then the supports' static deflection along the line of action, a shift of
/// 0.9·10⁻⁶ of TE, and its variation over the mesh cycle, measured 2.4·10⁻⁷: bounds
/// 1.5·10⁻⁶ and 5·10⁻⁷.
#[test]
fn stiff_supports_give_the_drive_trajectory() {
    let mut stiff = Vec::new();
    for b in ["pinion", "gear"] {
        for (k, v) in [
            ("mass_kg", 50.0),
            ("j_transverse_kgm2", 0.05),
            ("radial_n_per_m", 2e14),
            ("axial_n_per_m", 2e14),
            ("tilt_nm_per_rad", 7e10),
        ] {
            stiff.push((format!("supports.{b}.{k}"), v));
        }
    }
    let stiff: Vec<(&str, f64)> = stiff.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    let gb = full(&GEARBOX, &stiff);
    let dr = Fmu::instantiate(&DRIVE, FMI2_CO_SIMULATION);
    set_ints(&dr, &[("fidelity", 0), ("slices", SLICES), ("rk4_steps_per_mesh_period", 4096)]);
    dr.init();
    let t_m = 2.0 * std::f64::consts::PI / (30.0 * 300.0);
    let h = t_m / 128.0;
    let (mut a, mut b) = (vec![gb.get(&["TE"])[0]], vec![dr.get(&["TE"])[0]]);
    for i in 0..128 {
        step(&gb, i as f64 * h, h);
        step(&dr, i as f64 * h, h);
        a.push(gb.get(&["TE"])[0]);
        b.push(dr.get(&["TE"])[0]);
    }
    let scale = te_max(&b);
    let dev = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
    let shift = a[0] - b[0];
    let beyond = a.iter().zip(&b).map(|(x, y)| (x - y - shift).abs()).fold(0.0, f64::max) / scale;
    eprintln!(
        "stiff supports against the Drive: max |ΔTE| = {dev:.2e} of TE, static shift {:.2e}, \
         beyond it {beyond:.2e}",
        shift / scale
    );
    assert!(dev <= 1.5e-6, "{dev}");
    assert!(beyond <= 5e-7, "{beyond}");
}

/// The start is the static equilibrium with the bodies displaced: each support's force and
/// moment balance the mesh's on its body, the bodies are at rest (Model Exchange derivatives
/// of the pose rates zero to round-off against F/m), and the states and derivatives of Model
/// Exchange are those Co-Simulation steps from: the derivative of each pose is its rate.
#[test]
fn the_start_balances_the_supports_and_model_exchange_sees_the_state() {
    let f = Fmu::instantiate(&GEARBOX, FMI2_MODEL_EXCHANGE);
    set_ints(&f, &[("fidelity", 0), ("slices", SLICES)]);
    f.init();
    let mesh = f.get(&["F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y", "F_g_x", "F_g_y", "F_g_z"]);
    let r = f.get(&["R_p_x", "R_p_y", "R_p_z", "R_p_mx", "R_p_my", "R_g_x", "R_g_y", "R_g_z"]);
    let scale = mesh.iter().map(|x| x.abs()).fold(0.0, f64::max);
    for (k, (m, s)) in mesh.iter().zip(&r).enumerate() {
        assert!((m + s).abs() <= 1e-6 * scale, "component {k}: mesh {m}, support {s}");
    }
    let nx = GEARBOX.state_names().len();
    assert_eq!(nx, 28);
    let mut x = vec![0.0; nx];
    let mut dx = vec![0.0; nx];
    unsafe {
        assert_eq!(fmi2EnterContinuousTimeMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2GetContinuousStates(f.0, x.as_mut_ptr(), nx), fmi2Status::Ok);
        assert_eq!(fmi2GetDerivatives(f.0, dx.as_mut_ptr(), nx), fmi2Status::Ok);
    }
    let names = GEARBOX.state_names();
    let poses = f.get(&names[8..18]);
    assert_eq!(&x[8..18], &poses[..], "pose states are the pose outputs");
    assert!(poses[0] != 0.0 && poses[6] != 0.0, "the bodies are displaced: {poses:?}");
    for i in 8..18 {
        assert_eq!(dx[i], x[i + 10], "der({}) is its rate", names[i]);
    }
    // Accelerations of the bodies at rest in equilibrium: round-off of F/m.
    let f_over_m = scale / 2.0;
    for i in 18..28 {
        assert!(dx[i].abs() <= 1e-5 * f_over_m, "der of {} = {}", names[i], dx[i]);
    }
    // Setting the states back changes nothing.
    unsafe {
        assert_eq!(fmi2SetContinuousStates(f.0, x.as_ptr(), nx), fmi2Status::Ok);
        let mut again = vec![0.0; nx];
        assert_eq!(fmi2GetDerivatives(f.0, again.as_mut_ptr(), nx), fmi2Status::Ok);
        assert_eq!(again, dx);
        let mut nominal = vec![0.0; nx];
        assert_eq!(
            fmi2GetNominalsOfContinuousStates(f.0, nominal.as_mut_ptr(), nx),
            fmi2Status::Ok
        );
        assert!(nominal.iter().all(|v| v.is_finite() && *v > 0.0), "{nominal:?}");
        // No directional derivatives (the capability flag says so).
        let (unk, kn) = (f.vrs(&["der(v_p_x)"]), f.vrs(&["u_p_x"]));
        let mut d = [0.0];
        let st = fmi2GetDirectionalDerivative(
            f.0,
            unk.as_ptr(),
            1,
            kn.as_ptr(),
            1,
            [1.0].as_ptr(),
            d.as_mut_ptr(),
        );
        assert_ne!(st, fmi2Status::Ok);
    }
}

/// An FMU state taken mid-run and restored (in memory and serialised) continues bit for bit.
#[test]
fn a_restored_state_continues_bit_for_bit() {
    let f = full(&GEARBOX, &[]);
    let h = 2e-5;
    for i in 0..5 {
        step(&f, i as f64 * h, h);
    }
    let mut s: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2GetFMUstate(f.0, &mut s) }, fmi2Status::Ok);
    let mut size = 0usize;
    assert_eq!(unsafe { fmi2SerializedFMUstateSize(f.0, s, &mut size) }, fmi2Status::Ok);
    let mut bytes = vec![0 as fmi2Byte; size];
    assert_eq!(unsafe { fmi2SerializeFMUstate(f.0, s, bytes.as_mut_ptr(), size) }, fmi2Status::Ok);
    let names = ["TE", "u_g_x", "R_p_y", "th_p_x", "w_p"];
    let run = |f: &Fmu| {
        (5..10)
            .map(|i| {
                f.set(&["M"], &[100.0 + i as f64]);
                step(f, i as f64 * h, h);
                f.get(&names)
            })
            .collect::<Vec<_>>()
    };
    let first = run(&f);
    assert_eq!(unsafe { fmi2SetFMUstate(f.0, s) }, fmi2Status::Ok);
    assert_eq!(run(&f), first, "in memory");
    let mut d: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe { fmi2DeSerializeFMUstate(f.0, bytes.as_ptr(), size, &mut d) },
        fmi2Status::Ok
    );
    assert_eq!(unsafe { fmi2SetFMUstate(f.0, d) }, fmi2Status::Ok);
    assert_eq!(run(&f), first, "serialised");
    unsafe {
        fmi2FreeFMUstate(f.0, &mut s);
        fmi2FreeFMUstate(f.0, &mut d);
    }
}

/// Bad supports are refused (the library's `tests/supports.rs` checks that the messages name
/// the key; `tests/fmi2_bounds.rs` the Real parameters' bounds).
#[test]
fn bad_supports_are_refused() {
    let f = Fmu::instantiate(&GEARBOX, FMI2_CO_SIMULATION);
    let vr = f.vrs(&["supports"]);
    for json in [
        r#"{"pinion": {"mass_kg": -1, "j_transverse_kgm2": 1e-3,
             "stiffness": {"radial_n_per_m": 1e8, "axial_n_per_m": 1e8, "tilt_nm_per_rad": 1e5}}}"#,
        r#"{"gear": {"mass_kg": 1, "j_transverse_kgm2": 1e-3}}"#,
        r#"{"wheel": {}}"#,
        "not json",
    ] {
        let c = CString::new(json).unwrap();
        let p = c.as_ptr();
        assert_eq!(unsafe { fmi2SetString(f.0, vr.as_ptr(), 1, &p) }, fmi2Status::Error, "{json}");
        unsafe { assert_eq!(fmi2Reset(f.0), fmi2Status::Ok) };
    }
    // A bad Real is refused at initialisation, naming it.
    f.set(&["supports.gear.mass_kg"], &[0.0]);
    unsafe {
        assert_eq!(fmi2SetupExperiment(f.0, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
        assert_eq!(fmi2EnterInitializationMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2ExitInitializationMode(f.0), fmi2Status::Error);
    }
}

/// `start_from_equilibrium` = false starts from the explicit rotational state with both bodies
/// on their bearing axes at rest: at the static equilibrium's rotational state the support
/// forces are zero and each body accelerates at the mesh force over its mass
/// (m·ü = F + R with R = 0 and no gyroscopic term at rest), so Model Exchange's derivatives
/// of the pose rates are F/m and J_t·θ̈ = M.
#[test]
fn an_explicit_start_puts_the_bodies_on_their_axes_at_rest() {
    let eq = Fmu::instantiate(&GEARBOX, FMI2_CO_SIMULATION);
    set_ints(&eq, &[("fidelity", 0), ("slices", SLICES)]);
    eq.init();
    let rot = ["phi_1", "phi_p", "phi_g", "phi_2", "w_1", "w_p", "w_g", "w_2"];
    let y0 = eq.get(&rot);
    let f = Fmu::instantiate(&GEARBOX, FMI2_MODEL_EXCHANGE);
    set_ints(&f, &[("fidelity", 0), ("slices", SLICES)]);
    let starts = ["phi_1_0", "phi_p_0", "phi_g_0", "phi_2_0", "w_1_0", "w_p_0", "w_g_0", "w_2_0"];
    f.set(&starts, &y0);
    let b = f.vrs(&["start_from_equilibrium"]);
    assert_eq!(unsafe { fmi2SetBoolean(f.0, b.as_ptr(), 1, &FMI2_FALSE) }, fmi2Status::Ok);
    f.init();
    assert_eq!(f.get(&rot), y0);
    let names = GEARBOX.state_names();
    assert!(f.get(&names[8..18]).iter().all(|&p| p == 0.0));
    assert!(f.get(&["R_p_x", "R_p_y", "R_g_x", "R_g_my"]).iter().all(|&r| r == 0.0));
    let nx = names.len();
    let mut dx = vec![0.0; nx];
    unsafe {
        assert_eq!(fmi2EnterContinuousTimeMode(f.0), fmi2Status::Ok);
        assert_eq!(fmi2GetDerivatives(f.0, dx.as_mut_ptr(), nx), fmi2Status::Ok);
    }
    let w = f.get(&["F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y", "F_g_x", "F_g_y", "F_g_z"]);
    let m = f.get(&[
        "supports.pinion.mass_kg",
        "supports.pinion.j_transverse_kgm2",
        "supports.gear.mass_kg",
    ]);
    let expected = [
        w[0] / m[0],
        w[1] / m[0],
        w[2] / m[0],
        w[3] / m[1],
        w[4] / m[1],
        w[5] / m[2],
        w[6] / m[2],
        w[7] / m[2],
    ];
    let got = [dx[18], dx[19], dx[20], dx[21], dx[22], dx[23], dx[24], dx[25]];
    for (k, (a, e)) in got.iter().zip(expected).enumerate() {
        assert!((a - e).abs() <= 1e-12 * e.abs().max(1.0), "component {k}: {a} against {e}");
    }
}

/// Every bound of the Real support parameters is usable: each one at its bound, the others at
/// their defaults and the drive torque at its least, 1 N·m (the least stiffnesses are sized
/// for it), initialises in static equilibrium and takes a communication step of 1 µs
/// (the fastest body modes of the extremes, ~10¹¹ s⁻¹, need ~10⁵ RK4 sub-steps for it).
#[test]
fn every_support_bound_is_usable() {
    let mut checked = 0;
    for v in GEARBOX.variables.iter().filter(|v| v.name.starts_with("supports.")) {
        let (Some(lo), Some(hi)) = (v.min, v.max) else { continue };
        for x in [lo, hi] {
            let f = Fmu::instantiate(&GEARBOX, FMI2_CO_SIMULATION);
            set_ints(&f, &[("fidelity", 0), ("slices", SLICES)]);
            f.set(&["drive.torque_nm", v.name], &[1.0, x]);
            f.init();
            step(&f, 0.0, 1e-6);
            let te = f.get(&["TE", "u_g_x", "R_p_y"]);
            assert!(te.iter().all(|t| t.is_finite()), "{} = {x}: {te:?}", v.name);
            checked += 1;
        }
    }
    assert_eq!(checked, 32);
}
