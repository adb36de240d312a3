//! End-to-end tests of the `helical-gear` binary's work bounds and low-speed operating points:
//! requests whose cost grows with an input are refused with exit status 1 before the model is
//! built, and low speed and standstill are integrated stably.

use helical_gear_mesh::GearPair;

/// Runs the `helical-gear` binary: (success, stdout, stderr).
fn cli(args: &[&str]) -> (bool, String, String) {
    let out =
        std::process::Command::new(env!("CARGO_BIN_EXE_helical-gear")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_simulate_refuses_a_64_gb_trajectory_before_building_the_model() {
    // --dt 1e-12 over 1 ms: 1e9 samples (144 GB), refused with exit status 1, not an abort.
    let (ok, _, err) = cli(&["simulate", "--omega-p", "100", "--t-end", "1e-3", "--dt", "1e-12"]);
    assert!(!ok && err.contains("samples") && err.contains("at most"), "{err}");
    assert!(!err.contains("building the mesh model"), "refused before the build: {err}");
}

#[test]
fn cli_spectrum_refuses_a_hunting_period_of_1e10_meshes() {
    let mut pair = GearPair::paper_table1();
    pair.z_p = 99991;
    pair.z_g = 99989;
    let path = std::env::temp_dir().join(format!("robust_dynamics_{}.json", std::process::id()));
    std::fs::write(&path, serde_json::to_string(&pair).unwrap()).unwrap();
    let (ok, _, err) = cli(&["spectrum", "--params", path.to_str().unwrap()]);
    std::fs::remove_file(&path).ok();
    assert!(!ok && err.contains("static equilibria") && err.contains("at most"), "{err}");
}

#[test]
fn cli_simulate_default_step_is_stable_at_8_rad_s() {
    let (ok, out, err) =
        cli(&["simulate", "--omega-p", "8", "--t-end", "0.005", "--fidelity", "table", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let te0 = v["te_static_start_m"].as_f64().unwrap();
    let te: Vec<f64> = v["te_m"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    let dev = te.iter().map(|t| (t - te0).abs()).fold(0.0, f64::max);
    assert!(dev < 0.5 * te0, "TE deviates {dev:e} m from the static {te0:e} m");
    assert!(v["dt_s"].as_f64().unwrap() < 2e-5, "the mesh mode sets the step");
}

#[test]
fn cli_simulate_at_standstill_holds_the_static_equilibrium() {
    // ω_p = 0 is an operating point: the static equilibrium under the torque at rest, held.
    let (ok, out, err) =
        cli(&["simulate", "--omega-p", "0", "--t-end", "0.002", "--fidelity", "table", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let te0 = v["te_static_start_m"].as_f64().unwrap();
    assert!(te0 > 0.0, "loaded at rest: {te0:e} m");
    let record: helical_gear_mesh::results::TrajectoryRunRecord =
        serde_json::from_str(&out).expect("simulate --json is the TrajectoryRunRecord");
    assert_eq!(record.mesh_period_s, None, "infinite at rest: null");
    assert_eq!(record.columns[0], "time_s");
    let te: Vec<f64> = v["te_m"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    let dev = te.iter().map(|t| (t - te0).abs()).fold(0.0, f64::max);
    // Measured: 4.4e-16 of the static TE over 2 ms (161 steps of 1.24e-5 s).
    assert!(dev < 1e-8 * te0, "TE drifts {dev:e} m from the static {te0:e} m at rest");
}

#[test]
fn cli_sweep_at_0_01_rad_s_ends_within_bounds() {
    let (ok, _, err) =
        cli(&["sweep", "--from", "0.01", "--to", "0.02", "--points", "2", "--refine-runs", "0"]);
    assert!(!ok && err.contains("RK4 steps") && err.contains("at most"), "{err}");
    let (ok, _, err) = cli(&[
        "sweep",
        "--from",
        "300",
        "--to",
        "400",
        "--points",
        "2",
        "--refine-runs",
        "1000000000",
    ]);
    assert!(!ok && err.contains("refine"), "{err}");
}
