//! End-to-end tests of the `helical-gear` binary: the JSON contract of `geometry` and `contact`
//! and clear errors for bad input.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_helical-gear")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn geometry_json_has_the_contract_keys_and_table1_values() {
    let (ok, stdout, _) = run(&["geometry", "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    for key in [
        "eps_alpha",
        "eps_beta",
        "base_radius_p_m",
        "base_radius_g_m",
        "tip_radius_p_m",
        "tip_radius_g_m",
        "center_distance_m",
        "j_p_kgm2",
        "j_g_kgm2",
    ] {
        assert!(v[key].as_f64().is_some_and(f64::is_finite), "missing {key}");
    }
    assert!((v["eps_alpha"].as_f64().unwrap() - 1.663).abs() < 0.005);
    assert!((v["base_radius_p_m"].as_f64().unwrap() - 42.861e-3).abs() < 5e-6);
    assert!(v["assumptions"].as_array().is_some_and(|a| !a.is_empty()));
}

#[test]
fn contact_json_lists_slices() {
    let (ok, stdout, _) = run(&["contact", "--phi-p", "0.01", "--te", "20e-6", "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let slices = v["slices"].as_array().unwrap();
    assert!(!slices.is_empty());
    for s in slices {
        for key in ["zeta", "pair", "kind", "overlap_m", "rho_p_m", "rho_g_m", "arm_p_m", "arm_g_m"]
        {
            assert!(!s[key].is_null(), "missing {key}");
        }
        if s["kind"] == "involute/involute" {
            assert!((s["overlap_m"].as_f64().unwrap() - 20e-6).abs() < 1e-12);
        }
    }
}

#[test]
fn bad_parameters_give_a_clear_error() {
    let dir = std::env::temp_dir().join(format!("hg-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("p.json");
    let (_, template, _) = run(&["params"]);
    std::fs::write(&file, template.replace("\"z_p\": 30", "\"z_p\": 12")).unwrap();
    let (ok, stdout, stderr) = run(&["geometry", "--json", "--params", file.to_str().unwrap()]);
    assert!(!ok && stdout.is_empty());
    assert!(stderr.contains("z_p") && stderr.contains("undercut"), "{stderr}");
    let (ok, _, stderr) =
        run(&["geometry", "--params", dir.join("missing.json").to_str().unwrap()]);
    assert!(!ok && stderr.contains("no such file") && stderr.contains("missing.json"), "{stderr}");
    let (ok, _, stderr) = run(&["contact", "--phi-p", "NaN", "--te", "0"]);
    assert!(!ok && stderr.contains("finite"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn simulate_and_sweep_reject_bad_arguments_before_building_the_model() {
    let cases: [(&[&str], &str); 5] = [
        (&["simulate", "--omega-p", "-2e5", "--t-end", "1e-3"], "--omega-p"),
        (&["simulate", "--omega-p", "100", "--t-end", "1e-3", "--dt", "3e-4"], "whole number"),
        (&["simulate", "--omega-p", "100", "--t-end", "-1"], "--t-end"),
        (&["sweep", "--from", "500", "--to", "400", "--points", "3"], "--from"),
        (&["sweep", "--from", "400", "--to", "500", "--points", "1"], "--points"),
    ];
    for (args, needle) in cases {
        let (ok, stdout, stderr) = run(args);
        assert!(!ok, "{args:?} succeeded");
        assert!(stdout.is_empty());
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("building the mesh model"), "{args:?} built the model first");
    }
    // --csv and --json exclude each other.
    let (ok, _, stderr) =
        run(&["simulate", "--omega-p", "100", "--t-end", "1e-3", "--csv", "--json"]);
    assert!(!ok && stderr.contains("cannot be used with"), "{stderr}");
}

/// `simulate --dt` is the fixed-step RK4 reference: times i·dt exactly, the static-equilibrium
/// start, and the same numbers as the library's `simulate` with the same mesh model.
/// Ignored by default: builds the FE compliance of Table 1 twice (about 20 s in the test
/// profile on two cores); run with `cargo test --test cli -- --ignored`.
#[test]
#[ignore]
fn simulate_json_is_the_library_rk4_trajectory() {
    use helical_gear_mesh::dynamics::{Drivetrain, GearDynamics, Stepping, simulate};
    use helical_gear_mesh::mesh::{EquilibriumSettings, Mesh, MeshOptions};

    let (omega, dt, t_end) = (600.0, 1e-5, 2e-4);
    let (ok, stdout, stderr) =
        run(&["simulate", "--omega-p", "600", "--t-end", "2e-4", "--dt", "1e-5", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let col = |k: &str| -> Vec<f64> {
        v[k].as_array()
            .unwrap_or_else(|| panic!("missing {k}"))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let time = col("time_s");
    assert_eq!(time.len(), 21);
    // Printed exactly (shortest round-trip form); serde_json's default parser may be off by
    // an ulp, hence the 1e-15.
    for (i, t) in time.iter().enumerate() {
        assert!((*t - i as f64 * dt).abs() <= 1e-15 * t.abs(), "time {i}: {t}");
    }

    let pair = helical_gear_mesh::GearPair::paper_table1();
    let mesh = Mesh::new(&pair, MeshOptions::default()).unwrap();
    let drive =
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap();
    let mut model = GearDynamics::new(mesh, drive).unwrap();
    let y0 = model.static_start(0.0, omega, &EquilibriumSettings::default()).unwrap().y;
    let tr = simulate(&mut model, &y0, t_end, &Stepping::Rk4 { dt }).unwrap();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-30);
    let names = helical_gear_mesh::dynamics::model::STATE_NAMES;
    for (j, name) in names.iter().enumerate() {
        for (i, x) in col(name).iter().enumerate() {
            assert!(close(*x, tr.states[i][j]), "{name}[{i}]: {x} vs {}", tr.states[i][j]);
        }
    }
    type Field = fn(&helical_gear_mesh::mesh::MeshOutputs) -> f64;
    let outs: [(&str, Field); 5] = [
        ("te_m", |o| o.te),
        ("m_f_p_nm", |o| o.m_f_p),
        ("m_f_g_nm", |o| o.m_f_g),
        ("m_d_p_nm", |o| o.m_d_p),
        ("m_d_g_nm", |o| o.m_d_g),
    ];
    for (name, f) in outs {
        for (i, x) in col(name).iter().enumerate() {
            assert!(close(*x, f(&tr.outputs[i])), "{name}[{i}]");
        }
    }
    // Every Real mesh output of the core's table is a column under its result name.
    for f in helical_gear_mesh::mesh::outputs::real_fields() {
        let c = col(f.column);
        assert_eq!(c.len(), tr.outputs.len(), "{}", f.column);
        for (i, x) in c.iter().enumerate() {
            assert!(close(*x, f.real(&tr.outputs[i]).unwrap()), "{}[{i}]", f.column);
        }
    }
    // The start is the static equilibrium: M_F,p = M.
    let torque = helical_gear_mesh::DriveLine::paper_table1().torque_nm;
    assert!((col("m_f_p_nm")[0] - torque).abs() < 1e-8 * torque);
}

fn run_env(args: &[&str], env: (&str, &std::path::Path)) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_helical-gear"))
        .args(args)
        .env(env.0, env.1)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `compliance` on Table 1 uses the embedded data: the contract keys, the fit target and a
/// finite pair stiffness; the text form names the stiffness and the fit quality.
#[test]
fn compliance_json_from_the_embedded_data() {
    let (ok, stdout, stderr) = run(&["compliance", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(v["source"], "embedded");
    for key in [
        "fe_dofs_p",
        "fe_dofs_g",
        "fe_seconds",
        "e_rel_std_p",
        "e_rel_std_g",
        "pair_stiffness_n_per_mm_per_um",
        "fe_assembly_s_p",
        "fe_factorisation_s_g",
        "fe_solve_s_p",
        "depth_h_m",
        "grid_rows",
        "grid_columns",
    ] {
        assert!(v[key].as_f64().is_some_and(|x| x.is_finite() && x > 0.0), "missing {key}");
    }
    assert_eq!(v["fe_dofs_p"].as_u64(), Some(67_590));
    // The embedded data's mesh: the default without its axial coarsening.
    assert_eq!(v["density"], "conforming");
    assert!((v["depth_h_m"].as_f64().unwrap() - 0.6e-3).abs() < 1e-12);
    for key in ["e_rel_std_p", "e_rel_std_g"] {
        assert!(v[key].as_f64().unwrap() <= 0.03, "{key} = {}", v[key]);
    }
    let shares: f64 = ["pair_share_global_p", "pair_share_global_g", "pair_share_local"]
        .iter()
        .map(|k| v[*k].as_f64().unwrap())
        .sum();
    assert!((shares - 1.0).abs() < 1e-9);
    let (ok, text, _) = run(&["compliance"]);
    assert!(ok && text.contains("c′ =") && text.contains("σ(e_rel)"), "{text}");
}

/// `HELICAL_GEAR_CACHE_DIR` is the disk cache of `compliance`: a cache file for a pair with
/// twice Table 1's Young's modulus (made from the embedded data with α* halved) and its
/// root-stress file beside it (the embedded one: stresses under given loads do not depend on
/// E) are read, not recomputed, and the global deflections halve.
#[test]
fn compliance_reads_the_cache_dir_from_the_environment() {
    use helical_gear_mesh::compliance::data::{ComplianceData, ComplianceKey, RootStressData};
    use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
    let dir = std::env::temp_dir().join(format!("hg-cli-cache-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut p = helical_gear_mesh::GearPair::paper_table1();
    p.material_p.youngs_modulus_pa *= 2.0;
    p.material_g.youngs_modulus_pa *= 2.0;
    let mut data = (*ComplianceData::embedded_table1().unwrap()).clone();
    data.provenance.key = ComplianceKey::of(&p);
    // A cache file is trusted only at the default density; the embedded data's own mesh is
    // the conforming one.
    data.provenance.density = GearMeshDensity::default();
    for m in [&mut data.pinion, &mut data.gear] {
        m.fit.alpha_ref_m_per_n *= 0.5;
        for block in &mut m.grid.alpha {
            block.iter_mut().for_each(|v| *v *= 0.5);
        }
    }
    data.write_file(&dir.join(ComplianceData::cache_file_name(&p))).unwrap();
    let mut stress = (*RootStressData::embedded_table1().unwrap()).clone();
    stress.key = ComplianceKey::of(&p);
    stress.density = GearMeshDensity::default();
    stress.write_file(&dir.join(RootStressData::cache_file_name(&p))).unwrap();
    let params = dir.join("p.json");
    std::fs::write(&params, serde_json::to_string(&p).unwrap()).unwrap();
    let env = ("HELICAL_GEAR_CACHE_DIR", dir.as_path());
    let (ok, stdout, stderr) =
        run_env(&["compliance", "--json", "--params", params.to_str().unwrap()], env);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["source"], "disk", "{stderr}");
    let (_, table1, _) = run(&["compliance", "--json"]);
    let t: serde_json::Value = serde_json::from_str(&table1).unwrap();
    for key in ["pair_u_global_p_um", "pair_u_global_g_um"] {
        let (a, b) = (v[key].as_f64().unwrap(), t[key].as_f64().unwrap());
        assert!((a - 0.5 * b).abs() < 1e-6 * b, "{key}: {a} vs {b}/2");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn paper_quick_writes_the_summary_with_the_contract_keys() {
    let dir = std::env::temp_dir().join(format!("helical-gear-paper-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let (ok, stdout, stderr) = run(&["paper", "--out", d, "--quick", "--json"]);
    assert!(ok, "stderr: {stderr}");
    assert!(stderr.contains("paper: static"), "stage progress on stderr: {stderr}");
    let from_stdout: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["ste_max_um"], from_stdout["ste_max_um"]);
    for key in [
        "ste_max_um",
        "omega_crit_rad_s",
        "omega_crit_2_rad_s",
        "omega_crit_3_rad_s",
        "separation_d100_rad_s",
        "separation_d200_rad_s",
        "tip_rounding_contact_570",
        "runtime_s",
        "stages",
        "assumptions",
        "sensitivity",
        "tip_contact_te_threshold_um",
        "tip_contact_te_threshold_rim_um",
        "tip_margins",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    // The static onset of tip contact lies above the static TE (no static tip contact), and
    // the compliance referred to the rim is a sensitivity case with a stiffer mesh.
    let thr = v["tip_contact_te_threshold_um"].as_f64().expect("threshold found");
    assert!(thr > v["ste_max_um"].as_f64().unwrap(), "threshold {thr} µm");
    let cases = v["sensitivity"].as_array().unwrap();
    let rim = cases
        .iter()
        .find(|c| c["case"].as_str().unwrap().starts_with("compliance referred to the rim"))
        .expect("rim-fixed case");
    let k = |c: &serde_json::Value| c["mesh_stiffness_n_per_um"].as_f64().unwrap();
    assert!(k(rim) > k(&cases[0]), "rim {} vs default {}", k(rim), k(&cases[0]));
    assert!(rim["ste_max_um"].as_f64().unwrap() < cases[0]["ste_max_um"].as_f64().unwrap());
    let margins = v["tip_margins"].as_array().unwrap();
    assert!(margins.iter().any(|m| m["compliance"] == "rim-fixed"));
    assert!(margins.iter().all(|m| m["te_max_um"].as_f64().unwrap() > 0.0));
    let ste = v["ste_max_um"].as_f64().unwrap();
    assert!(ste.is_finite() && (20.0..45.0).contains(&ste), "STE max {ste} µm");
    let w = v["omega_crit_rad_s"].as_f64().unwrap();
    assert!(w.is_finite() && (300.0..900.0).contains(&w), "ω_crit {w} rad/s");
    assert!(v["tip_rounding_contact_570"].is_boolean());
    assert!(v["runtime_s"].as_f64().unwrap() > 0.0);
    for f in [
        "summary.md",
        "static_te.csv",
        "waterfall_static.csv",
        "sweep.csv",
        "fig10_te.csv",
        "tip_threshold.csv",
    ] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `bench --quick --json` (a smoke run of the work-precision benchmark): the contract keys,
/// errors against the reference that shrink with the resolution, the plots and tables.
#[test]
fn bench_quick_reports_the_contract_keys() {
    let dir = std::env::temp_dir().join(format!("helical-gear-bench-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let (ok, stdout, stderr) = run(&["bench", "--quick", "--no-paper", "--json", "--out", d]);
    assert!(ok, "stderr: {stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    for key in ["full_eval_us", "table_eval_ns", "table_max_rel_err", "paper_runtime_s", "mesh"] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    // What a user waits for: every key measured, the design the sum of its parts.
    for key in [
        "full_eval_warm_us",
        "full_eval_max_rel_err",
        "table_build_s",
        "table_deviation_build_s",
        "fe_compliance_s",
        "design_s",
        "table_eval_torques_ns",
    ] {
        assert!(v[key].as_f64().is_some_and(|x| x.is_finite() && x > 0.0), "{key}: {}", v[key]);
    }
    let d = &v["design"];
    let parts: f64 = ["fe_compliance_s", "static_s", "table_build_s", "sweep_s"]
        .map(|k| d[k].as_f64().unwrap())
        .iter()
        .sum();
    assert!((parts - v["design_s"].as_f64().unwrap()).abs() <= 1e-12 * parts);
    assert_eq!(v["fe_compliance_s"], d["fe_compliance_s"]);
    assert!(v["full_eval_us"].as_f64().unwrap() > 0.0);
    assert!(v["table_eval_ns"].as_f64().unwrap() > 0.0);
    let e = v["table_max_rel_err"].as_f64().unwrap();
    assert!(e.is_finite() && e < 0.01, "table error {e}");
    assert!(v["paper_runtime_s"].is_null());
    // What the performance page's header states: the commit, the date and the load.
    for key in ["commit", "date_utc", "load_average"] {
        assert!(v[key].as_str().is_some_and(|s| !s.is_empty()), "missing {key}: {}", v[key]);
    }
    // Full fidelity, interpolated compliance: the error against the reference falls with the
    // number of slices.
    let full: Vec<(u64, f64)> = v["mesh"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["family"] == "full interpolated")
        .map(|c| (c["slices"].as_u64().unwrap(), c["max_rel_err"].as_f64().unwrap()))
        .collect();
    assert!(full.len() >= 2 && full[1].1 < full[0].1, "{full:?}");
    // The headline error is the error of the headline evaluation's row.
    let general_slices = v["mesh"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["family"] == "full interpolated, general assembly")
        .and_then(|c| c["slices"].as_u64())
        .unwrap();
    let row = full.iter().find(|c| c.0 == general_slices).unwrap();
    assert_eq!(v["full_eval_max_rel_err"].as_f64().unwrap(), row.1);
    // The general assembly gives the same torques as the slice kernel.
    let general = v["mesh"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["family"] == "full interpolated, general assembly")
        .unwrap();
    let same = full.iter().find(|c| c.0 == general["slices"].as_u64().unwrap()).unwrap();
    assert!((general["max_rel_err"].as_f64().unwrap() - same.1).abs() < 1e-9);
    for f in ["bench_mesh.png", "bench_dynamics.png", "bench_mesh.csv", "bench.json"] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A reader that closes stdout early (`… | head -1`) ends the program quietly: no panic, no
/// "Broken pipe" message.
#[test]
fn closed_stdout_ends_quietly() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    for args in [
        &["contact", "--phi-p", "0.01", "--te", "20e-6", "--slices", "4000", "--json"][..],
        &["simulate", "--omega-p", "150", "--t-end", "2e-3", "--dt", "2e-6", "--csv"][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_helical-gear"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
        assert!(!first.is_empty());
        // The reader is dropped here: the pipe is closed with most of the output unread.
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn geometry_json_is_the_geometry_record() {
    let (ok, stdout, _) = run(&["geometry", "--json"]);
    assert!(ok);
    let r: helical_gear_mesh::results::GeometryRecord =
        serde_json::from_str(&stdout).expect("the record's keys");
    let p = helical_gear_mesh::GearPair::paper_table1();
    let g = helical_gear_mesh::PairGeometry::new(&p).unwrap();
    assert_eq!(r, helical_gear_mesh::results::GeometryRecord::new(&g, &p));
}

/// `compliance --json` on Table 1 is the library's `ComplianceRecord` of the embedded data and
/// its pitch-point stiffness (200 slices), value for value.
#[test]
fn compliance_json_is_the_compliance_record() {
    use helical_gear_mesh::compliance::data::ComplianceData;
    use helical_gear_mesh::results::ComplianceRecord;
    let (ok, stdout, stderr) = run(&["compliance", "--json"]);
    assert!(ok, "{stderr}");
    let r: ComplianceRecord = serde_json::from_str(&stdout).expect("the record's keys");
    let p = helical_gear_mesh::GearPair::paper_table1();
    let g = helical_gear_mesh::PairGeometry::new(&p).unwrap();
    let data = ComplianceData::embedded_table1().unwrap();
    let st = data.pair_stiffness(&g, 200, 100.0).unwrap();
    assert_eq!(r, ComplianceRecord::new(&data, &st));
    assert_eq!(r.fit_seconds, r.fit_seconds_p + r.fit_seconds_g);
}

/// `contact --json` is the library's `ContactRecord` of the same contact search.
#[test]
fn contact_json_is_the_contact_record() {
    use helical_gear_mesh::contact::{ContactSolver, FlankSide};
    use helical_gear_mesh::results::ContactRecord;
    let (ok, stdout, stderr) = run(&["contact", "--phi-p", "0.01", "--te", "20e-6", "--json"]);
    assert!(ok, "{stderr}");
    let r: ContactRecord = serde_json::from_str(&stdout).expect("the record's keys");
    let p = helical_gear_mesh::GearPair::paper_table1();
    let g = helical_gear_mesh::PairGeometry::new(&p).unwrap();
    let solver = ContactSolver::new(&g);
    let phi_g = g.phi_g_for_te(0.01, 20e-6);
    let mut cs = Vec::new();
    let red = solver.contacts_on(FlankSide::Drive, 0.01, phi_g, &solver.slice_zetas(20), &mut cs);
    assert_eq!(r, ContactRecord::new(0.01, phi_g, red.te, &cs));
    assert!(r.slices.iter().all(|s| s.side == "drive"));
}

/// The drive line is not part of the gear pair: a `--params` file with a `drive` key is
/// refused with a message that points to `--drive`; `--drive FILE` takes a partial drive line
/// (missing keys from Table 1's, here the pair stiffness's torque), `params --drive` prints
/// Table 1's, and a bad drive file is an error naming the key and the file.
#[test]
fn drive_line_is_its_own_file() {
    let dir = std::env::temp_dir().join(format!("hg-cli-drive-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pair = dir.join("pair.json");
    std::fs::write(&pair, r#"{"helix_angle_rad": 0.2, "drive": {"torque_nm": 50}}"#).unwrap();
    let (ok, stdout, stderr) = run(&["geometry", "--json", "--params", pair.to_str().unwrap()]);
    assert!(!ok && stdout.is_empty());
    assert!(stderr.contains("--drive") && !stderr.contains("unknown field"), "{stderr}");

    let (ok, template, _) = run(&["params", "--drive"]);
    assert!(ok);
    let t: serde_json::Value = serde_json::from_str(&template).expect("one JSON object");
    assert_eq!(t["torque_nm"], 100.0);
    assert_eq!(t["j1_kgm2"], 0.62);

    let drive = dir.join("drive.json");
    std::fs::write(&drive, r#"{"torque_nm": 200}"#).unwrap();
    let (ok, stdout, stderr) = run(&["compliance", "--json", "--drive", drive.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(v["pair_torque_nm"], 200.0);
    let (ok, stdout, _) = run(&["compliance", "--json"]);
    assert!(ok);
    let d: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(d["pair_torque_nm"], 100.0);

    std::fs::write(&drive, r#"{"torque": 200}"#).unwrap();
    let (ok, _, stderr) = run(&["static", "--drive", drive.to_str().unwrap()]);
    assert!(!ok && stderr.contains("unknown field `torque`"), "{stderr}");
    assert!(stderr.contains("drive.json"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `static --json` carries ISO 6336-3 method B at the run's torque: `root_stress_iso_p_pa`,
/// `root_stress_iso_g_pa` and the factors in `iso6336`, the library's `iso6336` numbers
/// bit for bit, proportional to the torque.
#[test]
fn static_json_reports_the_iso_6336_root_stress_at_the_run_torque() {
    use helical_gear_mesh::iso6336::nominal_root_stress;
    use helical_gear_mesh::{GearPair, PairGeometry};
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).unwrap();
    let mut sigma = Vec::new();
    for torque in [100.0, 50.0] {
        let t = format!("{torque}");
        let args =
            ["static", "--json", "--torque", &t, "--points-per-pitch", "2", "--slices", "40"];
        let (ok, stdout, stderr) = run(&args);
        assert!(ok, "{stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
        let lib = nominal_root_stress(&p, &geo, torque).unwrap();
        assert_eq!(v["root_stress_iso_p_pa"].as_f64(), Some(lib.pinion.sigma_f0_pa));
        assert_eq!(v["root_stress_iso_g_pa"].as_f64(), Some(lib.gear.sigma_f0_pa));
        assert!(v["iso6336_error"].is_null());
        let iso = &v["iso6336"];
        assert_eq!(iso["tangential_force_n"].as_f64(), Some(lib.tangential_force_n));
        for (gear, g) in [("pinion", &lib.pinion), ("gear", &lib.gear)] {
            for (key, want) in [
                ("y_f", g.y_f),
                ("y_s", g.y_s),
                ("y_beta", g.y_beta),
                ("y_b", g.y_b),
                ("y_dt", g.y_dt),
                ("s_fn_m", g.s_fn_m),
                ("h_fe_m", g.h_fe_m),
                ("rho_f_m", g.rho_f_m),
                ("alpha_fen_rad", g.alpha_fen_rad),
                ("z_n", g.z_n),
                ("sigma_f0_pa", g.sigma_f0_pa),
            ] {
                assert_eq!(iso[gear][key].as_f64(), Some(want), "iso6336.{gear}.{key}");
            }
        }
        sigma.push(lib.pinion.sigma_f0_pa);
    }
    assert!((sigma[1] - 0.5 * sigma[0]).abs() <= 1e-12 * sigma[0], "linear in the torque");
    // The Table 1 pinion at 100 N·m: about 128 MPa (Y_F ≈ 1.34, Y_S ≈ 2.00).
    assert!((sigma[0] * 1e-6 - 127.6).abs() < 0.5, "{}", sigma[0]);
}

/// `static --json` reports the mesh force and moments per point and over the cycle, and with
/// `--bearings` the loads of the four bearings of the arrangement (docs/loads.md); a bad
/// arrangement is refused naming the key.
#[test]
fn static_json_has_the_force_and_bearing_keys() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/loads/bearings_table1.json");
    let args =
        ["static", "--json", "--slices", "40", "--points-per-pitch", "8", "--bearings", file];
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for key in ["force_p_mean_n", "force_p_peak_to_peak_n"] {
        assert_eq!(v[key].as_array().unwrap_or_else(|| panic!("{key}")).len(), 3);
    }
    let p = &v["points"][0];
    for (key, n) in [("force_p_n", 3), ("moment_p_nm", 2), ("force_g_n", 3), ("moment_g_nm", 2)] {
        assert_eq!(p[key].as_array().unwrap_or_else(|| panic!("{key}")).len(), n);
    }
    let b = v["bearings"].as_array().expect("bearings");
    assert_eq!(b.len(), 4);
    for (r, (shaft, bearing)) in b.iter().zip([
        ("pinion", "locating"),
        ("pinion", "floating"),
        ("gear", "locating"),
        ("gear", "floating"),
    ]) {
        assert_eq!((r["shaft"].as_str(), r["bearing"].as_str()), (Some(shaft), Some(bearing)));
        for key in ["reaction_mean_n", "reaction_peak_to_peak_n"] {
            assert_eq!(r[key].as_array().unwrap().len(), 3);
        }
        assert!(!r["reaction_order_amplitudes_n"].as_array().unwrap().is_empty());
    }
    // The pinion's bearings carry the mean mesh force on the pinion, with opposite sign.
    let mean = |x: &serde_json::Value, k: usize| x["reaction_mean_n"][k].as_f64().unwrap();
    for k in 0..3 {
        let f = v["force_p_mean_n"][k].as_f64().unwrap();
        assert!((mean(&b[0], k) + mean(&b[1], k) + f).abs() <= 1e-9 * f.abs().max(1.0));
    }

    let dir = std::env::temp_dir().join(format!("hg-bearings-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("same.json");
    std::fs::write(
        &bad,
        r#"{"pinion": {"locating_z_m": 0.01, "floating_z_m": 0.01}, "gear": {"locating_z_m": 0, "floating_z_m": 0.05}}"#,
    )
    .unwrap();
    let (ok, _, stderr) = run(&["static", "--json", "--bearings", bad.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).ok();
    assert!(!ok && stderr.contains("pinion.floating_z_m"), "{stderr}");
}

/// Negative numbers are values (`--torque -100`, `--omega-p -100`), not unknown options: the
/// command's own check answers, naming the option and its range. A negative speed is an
/// operating point (running backwards), refused only beyond |ω_p| = 1e5 rad/s.
#[test]
fn negative_numbers_reach_the_commands_checks() {
    let (ok, _, stderr) = run(&["static", "--torque", "-100"]);
    assert!(!ok && stderr.contains("--torque = -100") && stderr.contains("allowed"), "{stderr}");
    assert!(!stderr.contains("unexpected argument"), "{stderr}");
    // -100 rad/s passes the speed check: the next argument's check answers, before the build.
    let (ok, _, stderr) = run(&["simulate", "--omega-p", "-100", "--t-end", "-1"]);
    assert!(!ok && stderr.contains("--t-end") && !stderr.contains("--omega-p"), "{stderr}");
    let (ok, _, stderr) = run(&["simulate", "--omega-p", "-1e9", "--t-end", "1e-3"]);
    assert!(!ok && stderr.contains("--omega-p") && stderr.contains("1e5"), "{stderr}");
}

/// Every argument of `sweep` and `spectrum` is checked before the mesh is built.
#[test]
fn sweep_and_spectrum_arguments_are_checked_before_the_build() {
    for (args, needle) in [
        (
            &["sweep", "--from", "100", "--to", "200", "--points", "3", "--threads", "0"][..],
            "threads",
        ),
        (
            &["sweep", "--from", "100", "--to", "200", "--points", "3", "--min-prominence", "NaN"],
            "min_prominence",
        ),
        (&["sweep", "--from", "100", "--to", "2e5", "--points", "3"], "1e5"),
        (&["spectrum", "--max-order", "NaN"], "--max-order"),
        (&["spectrum", "--max-order", "-1"], "--max-order"),
    ] {
        let t0 = std::time::Instant::now();
        let (ok, stdout, stderr) = run(args);
        assert!(!ok && stdout.is_empty(), "{args:?} succeeded");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("building"), "{args:?} built the model first: {stderr}");
        assert!(t0.elapsed().as_secs_f64() < 10.0, "{args:?}: {:?}", t0.elapsed());
    }
}

/// A parameter file that is missing, a directory, endless or not UTF-8 is refused naming the
/// option, the path and the cause; at most 16 MiB are read.
#[test]
fn params_files_are_read_bounded_and_named() {
    let dir = std::env::temp_dir().join(format!("hg-cli-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let latin1 = dir.join("latin1.json");
    std::fs::write(&latin1, b"{\"z_p\": 30, \"x\": \"\xe9\"}").unwrap();
    let big = dir.join("big.json");
    std::fs::write(&big, vec![b' '; 16 * 1024 * 1024 + 1]).unwrap();
    let missing = dir.join("tabel1.json");
    let cases = [
        (missing.to_str().unwrap(), "no such file"),
        (dir.to_str().unwrap(), "is a directory"),
        (latin1.to_str().unwrap(), "not UTF-8"),
        (big.to_str().unwrap(), "16 MiB"),
        ("/dev/zero", "16 MiB"),
    ];
    for (path, needle) in cases {
        if path == "/dev/zero" && !std::path::Path::new(path).exists() {
            continue;
        }
        let t0 = std::time::Instant::now();
        let (ok, _, stderr) = run(&["geometry", "--params", path]);
        assert!(!ok && stderr.contains("--params") && stderr.contains(path), "{stderr}");
        assert!(stderr.contains(needle), "{path}: {stderr}");
        assert!(t0.elapsed().as_secs_f64() < 10.0, "{path}: {:?}", t0.elapsed());
    }
    let (ok, _, stderr) = run(&["static", "--bearings", missing.to_str().unwrap()]);
    assert!(!ok && stderr.contains("--bearings") && stderr.contains("no such file"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
