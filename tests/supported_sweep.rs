//! Speed sweeps with both gear bodies on their supports (`dynamics::supported_sweep`): the
//! resonances the sweep finds are where the mesh meets the linearised coupled modes.

use helical_gear_mesh::dynamics::supported_sweep::{SupportedSweepOptions, sweep_supported};
use helical_gear_mesh::dynamics::{Drivetrain, bodies::SupportedDynamics, find_peaks};
use helical_gear_mesh::mesh::{EquilibriumSettings, Fidelity, Mesh, MeshOptions, Supports};
use helical_gear_mesh::{DriveLine, GearPair};

/// The guide's example supports (the file its figures were made with), damping of a few per cent.
const EXAMPLE: &str = include_str!("../docs/gear-bodies/supports.json");

/// Table 1 at 100 N·m on the guide's example supports, at table fidelity with its pose
/// sensitivities, 170–720 rad/s every 2.5 rad/s: every peak of the steady TE_max/STE_max
/// (prominence ≥ 0.01) lies within 3 % of a speed where mesh order 1 or 2 meets a coupled mode
/// of the model linearised at that speed (about the static equilibrium at φp = 0: the mesh's
/// stiffness and damping there, the supports, the gyroscopic terms): z_p·k·ω_p = 2π·f.
/// Measured: 5 peaks, at most 2.1 % from their mode (197.5, 250, 392.5, 502.5 and 690 rad/s;
/// the first two are the second mesh order of the modes at 1.89 and 2.38 kHz).
#[test]
fn the_coupled_modes_predict_the_sweep_resonances() {
    let pair = GearPair::paper_table1();
    let drive = Drivetrain::from_pair(&pair, &DriveLine::paper_table1()).unwrap();
    let mesh =
        Mesh::new(&pair, MeshOptions { fidelity: Fidelity::Table, ..MeshOptions::default() })
            .unwrap();
    let supports = Supports::from_json(EXAMPLE).unwrap();
    let speeds: Vec<f64> = (0..=220).map(|i| 170.0 + 2.5 * i as f64).collect();
    let sw = sweep_supported(&mesh, &drive, &supports, &speeds, &SupportedSweepOptions::default())
        .unwrap();
    assert!(sw.points.iter().all(|p| p.steady), "every run steady");
    let ratio: Vec<f64> = sw.points.iter().map(|p| p.te_max / sw.ste_max).collect();
    let peaks = find_peaks(&ratio, 0.01);
    assert!(peaks.len() >= 4, "{peaks:?}");
    let mut model = SupportedDynamics::new(mesh.clone(), drive, supports).unwrap();
    let z_p = drive.z_p as f64;
    for (i, _) in peaks {
        let w = speeds[i];
        let start = model.static_start(0.0, w, &EquilibriumSettings::default()).unwrap();
        let modes = model.linear_modes(&start).unwrap();
        let (best, order, f) = modes
            .frequencies_hz()
            .iter()
            .flat_map(|&f| [1.0, 2.0].map(|k| (2.0 * std::f64::consts::PI * f / (k * z_p), k, f)))
            .min_by(|a, b| (a.0 - w).abs().total_cmp(&(b.0 - w).abs()))
            .unwrap();
        let d = w / best - 1.0;
        eprintln!(
            "peak at {w:.1} rad/s (TE_max/STE_max {:.4}): mode {f:.1} Hz meets mesh order {order} \
             at {best:.1} rad/s ({d:+.2e})",
            ratio[i]
        );
        assert!(d.abs() <= 0.03, "peak {w} rad/s, nearest {best} rad/s");
    }
}

/// Work is bounded before it starts: supports so stiff that their modes need 10⁵ steps per mesh
/// period are refused at once, naming the step count, instead of running for hours.
#[test]
fn stiff_supports_are_refused_before_the_work() {
    let pair = GearPair::paper_table1();
    let drive = Drivetrain::from_pair(&pair, &DriveLine::paper_table1()).unwrap();
    let mesh = Mesh::new(&pair, MeshOptions { slices: 40, ..MeshOptions::default() }).unwrap();
    let stiff = r#"{"mass_kg": 0.01, "j_transverse_kgm2": 1e-6,
        "stiffness": {"radial_n_per_m": 1e15, "axial_n_per_m": 1e15, "tilt_nm_per_rad": 1e9}}"#;
    let supports = Supports::from_json(&format!(r#"{{"gear": {stiff}}}"#)).unwrap();
    let t0 = std::time::Instant::now();
    let e = sweep_supported(&mesh, &drive, &supports, &[300.0], &SupportedSweepOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("RK4 steps") && e.contains("max_periods"), "{e}");
    assert!(t0.elapsed().as_secs_f64() < 30.0);
}
