//! Measurement programs: studies that report figures rather than check them, each writing a
//! generated markdown page (and CSV where the rows are data) into `docs/bench/` (or `--out DIR`).
//!
//! ```text
//! cargo run --release -p helical-gear-app --example measure -- <study> [--out DIR]
//! ```
//!
//! | study | page | what | run time (2 cores) |
//! | --- | --- | --- | --- |
//! | `fe` | `fe.md` | whole-gear FE of the Table 1 gears: sizes, volume and Jacobian checks of the coarse, default and refined meshes; timings of the default-density influence runs; α* at one flank point for the three densities (mesh convergence) | minutes |
//! | `cosim` | `cosimulation.md`, `cosimulation.csv` | TE error of the co-simulated drive line (cut at the shafts or at the hubs, zero- or first-order hold, hub coupling) against the whole model, H from T_m/16 to 1 ms, at 300 and 532 rad/s | ≈ 40 s |
//! | `units` | `units.md`, `units.csv` | in-process speed of the Drive unit at table fidelity (RK4 sub-steps, DOPRI5 tolerances) with its TE error, and of the Drive and Pair units at full fidelity with the warm start carried or emptied every step | a few minutes |
//! | `jacobian` | `jacobian.md` | cost of one `mesh_jacobian` against one `evaluate`, full and table fidelity | ≈ 30 s |
//! | `iso` | `iso6336.md` | ISO 6336-3 method B nominal root stress σ_F0 and its factors for Table 1 at 100 N·m and two other designs (geometry only, no FE) | < 1 s |
//! | `loads` | `loads.md` | Table 1 at 100 N·m: mean and peak-to-peak of each component of the mesh force and tilting moments over a mesh cycle, full and table fidelity, and the bearing loads of `docs/loads/bearings_table1.json` | ≈ 10 s |
//! | `stress` | `root_stress.md`, `root_stress.csv` | static tooth-root stress (max over the mesh cycle) of Table 1 at 100 N·m for the coarse, default and refined FE meshes and along a refinement of the root fillet, of three designs at the default mesh, and the cost of the root stress per evaluation | a few minutes |
//! | `friction` | `friction.md`, `friction_path.png`/`.csv`, `friction_cycle.png`/`.csv` | Table 1 at 100 N·m and 300 rad/s: mean mesh loss and efficiency with a constant μ and with ISO/TR 14179-2's μ beside μ·H_V; the friction force along the path of contact and the loss over a mesh cycle; the effect on the steady dynamic TE and axial force; the cost per evaluation with friction | ≈ 1 min |
//! | `all` | all of them | | |
//! | `pages` | `docs/performance.md`, `docs/validation.md` | no measurement: renders the performance page from `docs/bench/bench.json` and the paper-run section of the validation page from `docs/paper/summary.json` ([`helical_gear_app::pages`]; run from the repository root) | instant |
//!
//! Every page names the command that regenerates it, the date (UTC), the machine's core count
//! and CPU. Times are wall time on the calling thread (the FE factorisation may use more);
//! run on an idle machine. The co-simulation masters and the FE mesh checks are the ones the
//! tests assert (`tests/common/cosim.rs`, `tests/common/fe.rs`, compiled in here), so the
//! figures and the assertions come from the same code.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use helical_gear_app::bench::{cpu_model, utc_now};
use helical_gear_mesh::compliance::fe::gear_mesh::{GearMesh, GearMeshDensity};
use helical_gear_mesh::compliance::influence_fe::{
    DEFAULT_DEPTH_MN, FeMethod, fe_influence, fe_influence_with,
};
use helical_gear_mesh::dynamics::{DriveUnit, Drivetrain, UnitKind, UnitStepping};
use helical_gear_mesh::geometry::PairGeometry;
use helical_gear_mesh::geometry::inertia::polygon_area;
use helical_gear_mesh::iso6336::nominal_root_stress;
use helical_gear_mesh::mesh::statics::EquilibriumSettings;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions, MeshState, MeshTorques, WarmStart};
use helical_gear_mesh::params::GearPair;

#[allow(dead_code)]
#[path = "../../tests/common/cosim.rs"]
mod cosim;
#[allow(dead_code)]
#[path = "../../tests/common/fe.rs"]
mod fe_checks;

const USAGE: &str =
    "usage: measure <fe|cosim|units|jacobian|iso|loads|stress|friction|all|pages> [--out DIR]";

fn main() {
    if let Err(e) = run() {
        eprintln!("measure: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut study = None;
    let mut out = PathBuf::from("docs/bench");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => out = it.next().ok_or(USAGE)?.into(),
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            s if study.is_none() => study = Some(s.to_string()),
            s => return Err(format!("unexpected argument {s:?}; {USAGE}")),
        }
    }
    let study = study.ok_or(USAGE)?;
    if study == "pages" {
        for (path, text) in helical_gear_app::pages::rendered_pages(Path::new("."))? {
            std::fs::write(&path, text)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            eprintln!("wrote {}", path.display());
        }
        return Ok(());
    }
    std::fs::create_dir_all(&out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let studies: Vec<&str> = match study.as_str() {
        "all" => vec!["fe", "cosim", "units", "jacobian", "iso", "loads", "stress", "friction"],
        s @ ("fe" | "cosim" | "units" | "jacobian" | "iso" | "loads" | "stress" | "friction") => {
            vec![s]
        }
        s => return Err(format!("unknown study {s:?}; {USAGE}")),
    };
    for s in studies {
        let t = Instant::now();
        let files = match s {
            "fe" => fe(&out)?,
            "cosim" => cosimulation(&out)?,
            "units" => units(&out)?,
            "iso" => iso(&out)?,
            "loads" => loads(&out)?,
            "stress" => root_stress(&out)?,
            "friction" => friction(&out)?,
            _ => jacobian(&out)?,
        };
        for f in files {
            eprintln!("wrote {}", f.display());
        }
        eprintln!("{s}: {:.1} s", t.elapsed().as_secs_f64());
    }
    Ok(())
}

/// The page's header: title, the command that regenerates it, date, cores and CPU.
fn header(title: &str, study: &str) -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "# {title}\n\n<!-- Generated file: do not edit; regenerate with the command below. -->\n\n\
         Generated by `cargo run --release -p helical-gear-app --example measure -- {study}` on \
         {} (UTC), on a machine with {cores} cores ({}); load average over the minute before \
         the run: {}. Times are wall time of one run; other work on the machine makes them \
         longer.\n\n",
        today_utc(),
        cpu_model(),
        load_average()
    )
}

/// Writes `text` to `dir/name`, returning the path.
fn write(dir: &Path, name: &str, text: &str) -> Result<PathBuf, String> {
    let p = dir.join(name);
    std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))?;
    Ok(p)
}

/// Today's date (UTC) as YYYY-MM-DD (the date part of the benchmark's [`utc_now`]).
fn today_utc() -> String {
    utc_now()[..10].to_string()
}

/// The 1-minute load average (`/proc/loadavg`), or "unknown".
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}

/// The three FE mesh densities by name.
fn densities() -> [(&'static str, GearMeshDensity); 4] {
    [
        ("coarse", GearMeshDensity::coarse()),
        ("default", GearMeshDensity::default()),
        ("conforming", GearMeshDensity::conforming()),
        ("refined", GearMeshDensity::refined()),
    ]
}

/// The FE page: mesh sizes and checks, default-density timings, α* convergence.
fn fe(dir: &Path) -> Result<Vec<PathBuf>, String> {
    use helical_gear_mesh::compliance::data::ComplianceData;
    use helical_gear_mesh::mesh::static_curve;
    let e = |e: helical_gear_mesh::compliance::fe::FeError| e.to_string();
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).map_err(|e| e.to_string())?;
    let depth = DEFAULT_DEPTH_MN * p.normal_module_m;
    let mut md = header("Whole-gear FE of the Table 1 gears", "fe");

    md.push_str(
        "## Mesh sizes\n\nEach density's hex20 mesh of the pinion and the gear: flank quads, \
         DOFs, elements, the mesh volume against the face width times the transverse outline \
         minus the bore (relative difference; the outline polygon has 400 points), the \
         smallest Jacobian determinant at the 27 Gauss points, and the web's ring radii.\n\n\
         | density | z | quads | DOFs | elements | volume, rel. difference | min det | web radii, mm |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for (name, d) in densities() {
        for g in [&geo.pinion, &geo.gear] {
            let gm = GearMesh::build(g, &p, &d).map_err(e)?;
            let (vol, min_det) = fe_checks::volume_and_min_jacobian(&gm);
            let exact = p.face_width_m
                * (polygon_area(&g.outline(400))
                    - std::f64::consts::PI * (0.5 * p.bore_diameter_m).powi(2));
            let web: Vec<String> = gm.web_radii.iter().map(|r| format!("{:.2}", r * 1e3)).collect();
            writeln!(
                md,
                "| {name} | {} | {} | {} | {} | {:.2e} | {min_det:.2e} | {} |",
                g.z,
                gm.quads,
                3 * gm.mesh.nodes.len(),
                gm.mesh.elements.len(),
                (vol - exact) / exact,
                web.join(", ")
            )
            .ok();
            eprintln!("fe: mesh {name}, z = {}", g.z);
        }
    }

    md.push_str(
        "\n## Default-density influence runs\n\nThe influence data of the default mesh (what \
         the compliance build computes for a design without embedded data): DOFs, the flank \
         grid (profile rows × axial levels), and the time of each stage, one gear at a time, \
         for the method the build uses (`fast`: one axial layer of element stiffnesses turned \
         to the others, AMD on the node graph, selected solves) and the reference \
         (`reference`: every element integrated, AMD on the DOF graph, whole solves); both \
         solve the same discretised problem (`FeMethod` in `compliance::influence_fe`). The \
         last column is the largest difference of the α* blocks, relative to each block's \
         largest value.\n\n\
         | z | method | DOFs | grid | mesh, s | assembly, s | factorisation, s | solve, s (cases) | observe, s | α* difference |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for g in [&geo.pinion, &geo.gear] {
        let fast =
            fe_influence_with(g, &p, &GearMeshDensity::default(), depth, FeMethod::Fast, true)
                .map_err(e)?;
        let reference =
            fe_influence_with(g, &p, &GearMeshDensity::default(), depth, FeMethod::Reference, true)
                .map_err(e)?;
        let diff = fast.grid.alpha.iter().zip(&reference.grid.alpha).fold(0.0f64, |m, (a, b)| {
            let scale = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            let d = a.iter().zip(b).fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
            m.max(d / scale)
        });
        for (name, inf) in [("fast", &fast), ("reference", &reference)] {
            let st = inf.stats;
            let d = if name == "fast" { format!("{diff:.1e}") } else { "—".to_string() };
            writeln!(
                md,
                "| {} | {name} | {} | {} × {} | {:.2} | {:.2} | {:.2} | {:.2} ({}) | {:.2} | {d} |",
                g.z,
                st.dofs,
                inf.grid.profile.len(),
                inf.grid.zeta.len(),
                inf.mesh_s,
                st.assembly_s,
                st.factorisation_s(),
                st.solve_s,
                st.solved_cases,
                inf.observe_s
            )
            .ok();
        }
        eprintln!("fe: influence z = {}", g.z);
    }
    let t0 = std::time::Instant::now();
    helical_gear_mesh::compliance::data::ComplianceData::compute(
        &p,
        &GearMeshDensity::default(),
        depth,
        false,
    )
    .map_err(|e| e.to_string())?;
    writeln!(
        md,
        "\n`ComplianceData::compute` of the pair at the default density (both gears side by \
         side, FE and fits, the fast method): {:.2} s.",
        t0.elapsed().as_secs_f64()
    )
    .ok();

    md.push_str(
        "\n## α* mesh convergence\n\nα* of the pinion (tooth 0 loaded, observed on teeth −1, \
         0 and +1) at profile coordinate 1.0 (one module below the η* reference, linear \
         between the grid rows) in the middle of the face, diagonal entry, for each density \
         (`conforming`: the default without its axial coarsening).\n\n\
         | density | DOFs | factorisation, s | solves, s | α* same tooth, m/N | tooth −1, m/N | tooth +1, m/N |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let mut csv =
        String::from("density,dofs,alpha_same_m_per_n,alpha_minus1_m_per_n,alpha_plus1_m_per_n\n");
    for (name, d) in densities() {
        let inf = fe_influence(&geo.pinion, &p, &d, depth, false).map_err(e)?;
        let grid = &inf.grid;
        let c0 = grid.zeta.len() / 2;
        let r = grid.profile.windows(2).position(|w| w[1] >= 1.0).ok_or("no bracket of 1.0")?;
        let w = (1.0 - grid.profile[r]) / (grid.profile[r + 1] - grid.profile[r]);
        let value = |t: usize| {
            let v = |row: usize| {
                let i = grid.index(row, c0);
                grid.value(t, i, i)
            };
            (1.0 - w) * v(r) + w * v(r + 1)
        };
        let st = inf.stats;
        writeln!(
            md,
            "| {name} | {} | {:.2} | {:.2} | {:.4e} | {:.4e} | {:.4e} |",
            st.dofs,
            st.factorisation_s(),
            st.solve_s,
            value(1),
            value(0),
            value(2)
        )
        .ok();
        writeln!(csv, "{name},{},{:e},{:e},{:e}", st.dofs, value(1), value(0), value(2)).ok();
        eprintln!("fe: α* {name}");
    }

    md.push_str(
        "\n## Axial coarsening\n\nThe default mesh keeps six axial layers only on the loaded \
         tooth, the web beneath it and its neighbours' root blocks; the bodies of the \
         neighbours (fine in the transverse section, observed but never loaded), the coarse \
         teeth's sectors and the rest of the web are extruded in two, with the hanging nodes \
         tied to the taller elements (`compliance::fe::gear_mesh`, \"Axial coarsening\"). \
         Against the same mesh in six layers throughout (`conforming`, the embedded Table 1 \
         data's mesh), each gear on its own: the FE time (assembly, factorisation, solves), and \
         the largest difference of each α* block and of the stored root-stress influence, \
         relative to the block's (the stress data's) largest value.\n\n\
         | z | DOFs | DOFs, conforming | FE, s | FE conforming, s | α* tooth −1 | α* tooth 0 | \
         α* tooth +1 | root stress |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for g in [&geo.pinion, &geo.gear] {
        let c = fe_influence(g, &p, &GearMeshDensity::conforming(), depth, false).map_err(e)?;
        let d = fe_influence(g, &p, &GearMeshDensity::default(), depth, false).map_err(e)?;
        let n = c.grid.points();
        let block = |t: usize| {
            let big = (0..n * n).fold(0.0f64, |m, k| m.max(c.grid.value(t, k / n, k % n).abs()));
            (0..n * n).fold(0.0f64, |m, k| {
                m.max((d.grid.value(t, k / n, k % n) - c.grid.value(t, k / n, k % n)).abs())
            }) / big
        };
        let stress = {
            let (mut big, mut diff) = (0.0f64, 0.0f64);
            for (a, b) in
                d.root_stress.sigma.iter().flatten().zip(c.root_stress.sigma.iter().flatten())
            {
                big = big.max((*b as f64).abs());
                diff = diff.max((*a as f64 - *b as f64).abs());
            }
            diff / big
        };
        writeln!(
            md,
            "| {} | {} | {} | {:.2} | {:.2} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |",
            g.z,
            d.stats.dofs,
            c.stats.dofs,
            d.stats.total_s(),
            c.stats.total_s(),
            block(0),
            block(1),
            block(2),
            stress
        )
        .ok();
        eprintln!("fe: axial coarsening, z = {}", g.z);
    }
    // The pair: static curves from the data of both densities.
    let curves = [GearMeshDensity::default(), GearMeshDensity::conforming()].map(|d| {
        let data = ComplianceData::compute(&p, &d, depth, false).map_err(|x| x.to_string())?;
        let mut m =
            Mesh::from_data(&p, MeshOptions::default(), &data).map_err(|x| x.to_string())?;
        let pitch = m.geometry().pinion.angular_pitch();
        let mut v = Vec::new();
        for torque in [20.0, 100.0, 250.0] {
            let c = static_curve(&mut m, torque, 0.0, pitch, 32, 1).map_err(|x| x.to_string())?;
            v.extend(c.points.iter().map(|s| {
                let o = &s.outputs;
                [o.te, o.root_stress_p, o.root_stress_g]
            }));
        }
        Ok::<_, String>(v)
    });
    let [d, c] = curves;
    let (d, c) = (d?, c?);
    let rel = |q: usize| {
        let big = c.iter().fold(0.0f64, |m, x| m.max(x[q].abs()));
        c.iter().zip(&d).fold(0.0f64, |m, (a, b)| m.max((a[q] - b[q]).abs())) / big
    };
    writeln!(
        md,
        "\nThe pair (both gears' data at each density): static TE and root stresses at 20, 100 \
         and 250 N·m, 32 phases over a mesh cycle each; the largest difference against \
         `conforming`, relative to the largest value: TE {:.1e}, pinion root stress {:.1e}, \
         gear root stress {:.1e}.",
        rel(0),
        rel(1),
        rel(2)
    )
    .ok();
    Ok(vec![write(dir, "fe.md", &md)?, write(dir, "fe_alpha.csv", &csv)?])
}

/// The default table's size, "phase points × TE points".
fn default_table() -> String {
    let [phase, te] = helical_gear_app::bench::default_table_size();
    format!("{phase} × {te}")
}

/// The co-simulation error table.
fn cosimulation(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let (_, drive) = cosim::table_mesh();
    let mut md =
        header("Co-simulation of the drive line: TE error against the whole model", "cosim");
    md.push_str(&format!(
        "Table 1 at table fidelity (default {dt} table). TE error = largest |TE − TE_ref| at \
         the communication points t_k = k·H over ≈ 30 mesh periods, relative to the largest \
         |TE_ref|; reference: `simulate` of Eqs. 1–4, RK4 at ≤ T_m/256; units at 128 RK4 \
         sub-steps per mesh period. Stage cut: J1 and J2 in the master, kinematics in, shaft \
         torques out. Pair cut: J1, J2 and the shafts in the master, the shaft torques held \
         (zero-order hold), taken at mid-step, passed with their time derivatives (first-order \
         hold), and with the shafts' stiffness and damping told to the Pair (hub coupling). The \
         masters are `tests/common/cosim.rs`, which `tests/dynamics_unit.rs` asserts.\n\n\
         | ω_p, rad/s | H | stage cut | pair cut | pair cut, mid-step torque | pair cut, \
         first-order hold | pair cut, hub coupling | pair cut, first-order hold and hub \
         coupling |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n",
        dt = default_table()
    ));
    let mut csv = String::from(
        "omega_rad_s,h_s,stage,pair,pair_mid,pair_foh,pair_coupled,pair_foh_coupled\n",
    );
    for omega in [300.0, 532.0] {
        let t_m = drive.mesh_period(omega);
        for (label, h) in [
            ("T_m/16".to_string(), t_m / 16.0),
            ("1e-4 s".into(), 1e-4),
            ("2.8e-4 s".into(), 2.8e-4),
            ("1e-3 s".into(), 1e-3),
        ] {
            let n = cosim::steps_for(omega, h);
            let r = cosim::reference(omega, h, n);
            let e: Vec<f64> = [
                cosim::stage_cut as fn(f64, f64, usize) -> Vec<f64>,
                cosim::pair_cut,
                cosim::pair_cut_mid,
                cosim::pair_cut_foh,
                cosim::pair_cut_coupled,
                cosim::pair_cut_foh_coupled,
            ]
            .iter()
            .map(|cut| cosim::rel_err(&cut(omega, h, n), &r))
            .collect();
            let cells: Vec<String> = e.iter().map(|v| format!("{v:.1e}")).collect();
            writeln!(md, "| {omega} | {label} ({h:.3e} s) | {} |", cells.join(" | ")).ok();
            let vals: Vec<String> = e.iter().map(|v| format!("{v:e}")).collect();
            writeln!(csv, "{omega},{h:e},{}", vals.join(",")).ok();
            eprintln!("cosim: {omega} rad/s, H = {label}");
        }
    }
    Ok(vec![write(dir, "cosimulation.md", &md)?, write(dir, "cosimulation.csv", &csv)?])
}

/// The drive-line unit speeds: table fidelity (RK4, DOPRI5) and full fidelity (warm or cold).
fn units(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let err = |e: helical_gear_mesh::dynamics::DynamicsError| e.to_string();
    let (omega, h, n) = (532.0, 1e-4, 10_000);
    let mut md = header("Drive-line units in-process: speed and TE error", "units");
    md.push_str(&format!(
        "The engine of the FMUs (`DriveUnit`, in-process) on Table 1 at 532 rad/s from its \
         static equilibrium, communication step H = 1e-4 s, the outputs read after every \
         step.\n\n## Table fidelity\n\nThe Drive unit on the default table ({dt}) over 1 s \
         of drive-line time (10 000 steps): simulated seconds per wall second, and the TE error \
         at the communication points (largest difference over the largest |TE|) against the \
         same unit at 1024 RK4 sub-steps per mesh period. DOPRI5 at atol = 1e-6·rtol.\n\n\
         | integrator in the unit | simulated s per wall s | TE error |\n| --- | --- | --- |\n",
        dt = default_table()
    ));
    let mut csv =
        String::from("fidelity,kind,integrator,setting,warm_start,realtime_factor,te_rel_err\n");
    let run_with = |stepping: UnitStepping| -> Result<(Vec<f64>, f64), String> {
        let mut u = cosim::started(UnitKind::Drive, stepping, omega);
        let t0 = Instant::now();
        let mut te = Vec::with_capacity(n);
        for _ in 0..n {
            u.advance(h).map_err(err)?;
            te.push(u.outputs().map_err(err)?.mesh.te);
        }
        Ok((te, t0.elapsed().as_secs_f64()))
    };
    let (reference, _) = run_with(cosim::rk4(1024))?;
    let rows = [1e-6, 1e-7, 1e-8, 1e-9]
        .map(|rtol| {
            (
                UnitStepping::Dopri5 { rtol, atol: 1e-6 * rtol },
                format!("DOPRI5 rtol {rtol:e}"),
                "dopri5",
                rtol,
            )
        })
        .into_iter()
        .chain([32, 64, 80, 84, 88, 92, 96, 128].map(|s| {
            (cosim::rk4(s), format!("RK4, {s} sub-steps per mesh period"), "rk4", f64::from(s))
        }));
    for (stepping, label, integrator, setting) in rows {
        let (te, wall) = run_with(stepping)?;
        let e = cosim::rel_err(&te, &reference);
        let rt = n as f64 * h / wall;
        writeln!(md, "| {label} | {rt:.1} | {e:.1e} |").ok();
        writeln!(csv, "table,Drive,{integrator},{setting:e},carried,{rt:e},{e:e}").ok();
        eprintln!("units: table, {label}: {rt:.1}× real time, TE error {e:.1e}");
    }

    let n_full = 20;
    md.push_str(&format!(
        "\n## Full fidelity\n\nThe Drive and the Pair unit at full fidelity (200 slices, \
         default options), RK4 at 128 sub-steps per mesh period, {n_full} steps ({:.0e} s) \
         after the static start: real-time factor with the mesh's warm start carried from step \
         to step, and with it emptied before every step (through the snapshot), with the load \
         solver's counts since the start.\n\n\
         | unit | warm start | real-time factor | wall time, s | load solves | Newton iterations | factorisations |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
        n_full as f64 * h
    ));
    let pair = GearPair::paper_table1();
    let mesh = Mesh::new(&pair, MeshOptions::default()).map_err(|e| e.to_string())?;
    let drive = Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1())
        .map_err(|e| e.to_string())?;
    for kind in [UnitKind::Drive, UnitKind::Pair] {
        for cold in [true, false] {
            let mut u = DriveUnit::new(kind, mesh.clone(), drive, cosim::rk4(128)).map_err(err)?;
            u.start_static(0.0, omega, &EquilibriumSettings::default()).map_err(err)?;
            let t0 = Instant::now();
            for _ in 0..n_full {
                if cold {
                    let mut s = u.snapshot();
                    s.warm_start = WarmStart::default();
                    u.restore(&s).map_err(err)?;
                }
                u.advance(h).map_err(err)?;
                u.outputs().map_err(err)?;
            }
            let wall = t0.elapsed().as_secs_f64();
            let st = u.mesh().stats();
            let warm = if cold { "emptied every step" } else { "carried" };
            let rt = n_full as f64 * h / wall;
            writeln!(
                md,
                "| {kind:?} | {warm} | {rt:.5} | {wall:.2} | {} | {} | {} |",
                st.solves, st.iterations, st.factorizations
            )
            .ok();
            let warm_csv = if cold { "emptied" } else { "carried" };
            writeln!(csv, "full,{kind:?},rk4,128,{warm_csv},{rt:e},").ok();
            eprintln!("units: full, {kind:?}, {warm}: {rt:.5}× real time");
        }
    }
    Ok(vec![write(dir, "units.md", &md)?, write(dir, "units.csv", &csv)?])
}

/// Cost of one exact mesh Jacobian against one evaluation.
fn jacobian(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut md = header("Cost of the exact mesh Jacobian", "jacobian");
    md.push_str(&format!(
        "`MeshTorques::mesh_jacobian` against `evaluate` on Table 1 along a warm-started \
         trajectory: one pitch in 64 steps at TE = 30 µm, 300 rad/s with a TE rate of 1 mm/s; \
         the time per call is the fastest of five passes. Full fidelity at 200 slices \
         (default options) and table fidelity (default {dt} table).\n\n\
         | fidelity | evaluate, µs | mesh_jacobian, µs | ratio |\n| --- | --- | --- | --- |\n",
        dt = default_table()
    ));
    let p = GearPair::paper_table1();
    let pitch = std::f64::consts::TAU / f64::from(p.z_p);
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = Mesh::new(&p, MeshOptions { fidelity, ..MeshOptions::default() })
            .map_err(|e| e.to_string())?;
        let geo = m.geometry().clone();
        let states: Vec<MeshState> = (0..64)
            .map(|k| {
                let phi_p = pitch * k as f64 / 64.0;
                let w_p = 300.0;
                let w_g = (1e-3 - w_p * geo.pinion.rb) / geo.gear.rb;
                MeshState {
                    phi_p,
                    phi_g: geo.phi_g_for_te(phi_p, 30e-6),
                    w_p,
                    w_g,
                    ..Default::default()
                }
            })
            .collect();
        let mut time = |jac: bool| -> Result<f64, String> {
            let mut best = f64::INFINITY;
            for _ in 0..5 {
                let t0 = Instant::now();
                for s in &states {
                    if jac {
                        std::hint::black_box(m.mesh_jacobian(s).map_err(|e| e.to_string())?);
                    } else {
                        std::hint::black_box(m.evaluate(s).map_err(|e| e.to_string())?);
                    }
                }
                best = best.min(t0.elapsed().as_secs_f64() / states.len() as f64);
            }
            Ok(best * 1e6)
        };
        let (e, j) = (time(false)?, time(true)?);
        writeln!(md, "| {fidelity:?} | {e:.3} | {j:.3} | {:.2} |", j / e).ok();
        eprintln!("jacobian: {fidelity:?}: evaluate {e:.3} µs, mesh_jacobian {j:.3} µs");
    }
    Ok(vec![write(dir, "jacobian.md", &md)?])
}

/// ISO 6336-3:2006 method B (the library's `iso6336`) for Table 1 and two other designs at
/// 100 N·m on the pinion: σ_F0 and every factor, per gear.
fn iso(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut md = header("ISO 6336-3 method B: nominal tooth-root stress", "iso");
    md.push_str(
        "σ_F0 = F_t/(b·m_n)·Y_F·Y_S·Y_β·Y_B·Y_DT of ISO 6336-3:2006 method B (the library's \
         `iso6336::nominal_root_stress`, `helical-gear static --json` keys \
         `root_stress_iso_p_pa`, `root_stress_iso_g_pa` and `iso6336`) at a pinion torque of \
         100 N·m, from each pair's basic rack and nominal profile shifts. The designs: Table 1 \
         of the paper (its unstated data as assumed in every run summary); the same pair as a \
         spur pair (β = 0, so Y_β = 1 and z_n = z); and a pair with fewer pinion teeth, \
         profile shift and a larger helix angle (z = 19/61, x = +0.4/−0.4, β = 20°, \
         b = 25 mm, otherwise Table 1). Geometry only: no FE, no load distribution.\n\n",
    );
    let table1 = GearPair::paper_table1();
    let designs = [
        ("Table 1", table1.clone()),
        ("Table 1, spur (β = 0)", GearPair { helix_angle_rad: 0.0, ..table1.clone() }),
        (
            "z = 19/61, x = +0.4/−0.4, β = 20°, b = 25 mm",
            GearPair {
                z_p: 19,
                z_g: 61,
                profile_shift_p: 0.4,
                profile_shift_g: -0.4,
                helix_angle_rad: 20f64.to_radians(),
                face_width_m: 25e-3,
                ..table1.clone()
            },
        ),
    ];
    for (name, p) in designs {
        let geo = PairGeometry::new(&p).map_err(|e| format!("{name}: {e}"))?;
        let r = nominal_root_stress(&p, &geo, 100.0).map_err(|e| format!("{name}: {e}"))?;
        writeln!(
            md,
            "## {name}\n\nz = {}/{}, m_n = {} mm, β = {:.1}°, b = {} mm, ε_α = {:.4}, \
             ε_β = {:.4}; F_t = {:.1} N.\n\n| quantity | pinion | gear |\n| --- | --- | --- |",
            p.z_p,
            p.z_g,
            p.normal_module_m * 1e3,
            p.helix_angle_rad.to_degrees(),
            p.face_width_m * 1e3,
            geo.eps_alpha,
            geo.eps_beta,
            r.tangential_force_n
        )
        .ok();
        let (a, b) = (&r.pinion, &r.gear);
        for (q, x, y) in [
            ("virtual number of teeth z_n", a.z_n, b.z_n),
            ("root chord s_Fn, mm", a.s_fn_m * 1e3, b.s_fn_m * 1e3),
            ("fillet radius ρ_F, mm", a.rho_f_m * 1e3, b.rho_f_m * 1e3),
            ("bending arm h_Fe, mm", a.h_fe_m * 1e3, b.h_fe_m * 1e3),
            ("load angle α_Fen, °", a.alpha_fen_rad.to_degrees(), b.alpha_fen_rad.to_degrees()),
            ("tooth form factor Y_F", a.y_f, b.y_f),
            ("stress correction factor Y_S", a.y_s, b.y_s),
            ("helix angle factor Y_β", a.y_beta, b.y_beta),
            ("rim thickness factor Y_B", a.y_b, b.y_b),
            ("deep tooth factor Y_DT", a.y_dt, b.y_dt),
            ("nominal root stress σ_F0, MPa", a.sigma_f0_pa * 1e-6, b.sigma_f0_pa * 1e-6),
        ] {
            writeln!(md, "| {q} | {x:.4} | {y:.4} |").ok();
        }
        md.push('\n');
        eprintln!(
            "iso: {name}: sigma_F0 {:.2} / {:.2} MPa",
            a.sigma_f0_pa * 1e-6,
            b.sigma_f0_pa * 1e-6
        );
    }
    md.push_str(
        "σ_F0 is proportional to the torque (the factors are geometry): at T N·m multiply by \
         T/100. The agreement with a published rating (KISSsoft reports of ISO 6336:2006 \
         method B) and the check of s_Fn and ρ_F against the generated fillet are tests \
         (`tests/iso6336.rs`).\n",
    );
    Ok(vec![write(dir, "iso6336.md", &md)?])
}

/// The mesh force and moments of Table 1 at 100 N·m over a mesh cycle (static curve, full and
/// table fidelity) and the loads of the bearings of `docs/loads/bearings_table1.json`.
fn loads(dir: &Path) -> Result<Vec<PathBuf>, String> {
    use helical_gear_mesh::mesh::bearings::BearingArrangement;
    use helical_gear_mesh::mesh::static_curve;
    use helical_gear_mesh::results::{BearingLoadRecord, StaticCurveRecord};
    let mut md = header("Mesh force, tilting moments and bearing loads of Table 1", "loads");
    let (torque, points) = (100.0, 40);
    md.push_str(&format!(
        "Table 1 at M = {torque} N·m on the pinion, static equilibrium at {points} pinion \
         angles over one pitch (`mesh::static_curve`, default options: 200 slices; the table \
         {dt}). Frame and signs: [the guide](../loads.md) (x from the pinion axis to the \
         gear axis, z along the pinion axis, y = z × x; moments about each gear's centre at \
         mid-face). The gear's force is the pinion's negated.\n\n",
        dt = default_table()
    ));
    let p = GearPair::paper_table1();
    let text = std::fs::read_to_string("docs/loads/bearings_table1.json")
        .map_err(|e| format!("docs/loads/bearings_table1.json: {e}"))?;
    let arrangement = BearingArrangement::from_json(&text).map_err(|e| e.to_string())?;
    let mut full_curve = None;
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let mut m = Mesh::new(&p, MeshOptions { fidelity, ..MeshOptions::default() })
            .map_err(|e| e.to_string())?;
        let geo = m.geometry().clone();
        let pitch = geo.pinion.angular_pitch();
        let curve =
            static_curve(&mut m, torque, 0.0, pitch, points, 1).map_err(|e| e.to_string())?;
        let rec = StaticCurveRecord::new(&curve, geo.pinion.rb);
        writeln!(md, "## {fidelity:?} fidelity\n").ok();
        md.push_str("| component | mean | peak-to-peak |\n| --- | --- | --- |\n");
        let comp = |v: Vec<f64>| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (mean, hi - lo)
        };
        let rows: [(&str, Vec<f64>); 10] = [
            ("F_p,x (N)", rec.force_p_n.iter().map(|f| f[0]).collect()),
            ("F_p,y (N)", rec.force_p_n.iter().map(|f| f[1]).collect()),
            ("F_p,z (N)", rec.force_p_n.iter().map(|f| f[2]).collect()),
            ("M_p,x (N·m)", rec.moment_p_nm.iter().map(|f| f[0]).collect()),
            ("M_p,y (N·m)", rec.moment_p_nm.iter().map(|f| f[1]).collect()),
            ("F_g,x (N)", rec.force_g_n.iter().map(|f| f[0]).collect()),
            ("F_g,y (N)", rec.force_g_n.iter().map(|f| f[1]).collect()),
            ("F_g,z (N)", rec.force_g_n.iter().map(|f| f[2]).collect()),
            ("M_g,x (N·m)", rec.moment_g_nm.iter().map(|f| f[0]).collect()),
            ("M_g,y (N·m)", rec.moment_g_nm.iter().map(|f| f[1]).collect()),
        ];
        for (name, v) in rows {
            let (mean, ptp) = comp(v);
            writeln!(md, "| {name} | {mean:.4} | {ptp:.4} |").ok();
        }
        md.push('\n');
        if fidelity == Fidelity::Full {
            full_curve = Some((curve, p.face_width_m));
        }
    }
    let (curve, b) = full_curve.expect("full fidelity ran");
    let outs: Vec<_> = curve.points.iter().map(|e| e.outputs).collect();
    md.push_str(&format!(
        "## Bearing loads\n\nThe arrangement `docs/loads/bearings_table1.json` (each shaft: \
         locating bearing at z = {:.3} m, floating at z = {:.3} m, 20 mm outside the end \
         faces; `mesh::bearings`), full fidelity. Reaction of each bearing on its shaft, N; \
         order 1 is the amplitude at the mesh frequency.\n\n\
         | shaft | bearing | z, m | mean (x, y, z) | peak-to-peak (x, y, z) | order 1 (x, y, z) |\n\
         | --- | --- | --- | --- | --- | --- |\n",
        arrangement.pinion.locating_z_m, arrangement.pinion.floating_z_m
    ));
    let v3 = |v: [f64; 3]| format!("{:.2}, {:.2}, {:.2}", v[0], v[1], v[2]);
    for r in BearingLoadRecord::over_cycle(&arrangement, b, &outs, 1) {
        let o1 = r.reaction_order_amplitudes_n.first().copied().unwrap_or([0.0; 3]);
        writeln!(
            md,
            "| {} | {} | {:.3} | {} | {} | {} |",
            r.shaft,
            r.bearing,
            r.z_m,
            v3(r.reaction_mean_n),
            v3(r.reaction_peak_to_peak_n),
            v3(o1)
        )
        .ok();
    }
    Ok(vec![write(dir, "loads.md", &md)?])
}

/// One row of the root-stress page: a design at an FE density and its static root stress.
struct StressRow {
    design: &'static str,
    density: &'static str,
    /// Largest static root stress over the mesh cycle, pinion and gear, Pa.
    sigma_p: f64,
    sigma_g: f64,
    /// Nominal bending stress F_t/(b·m_n) at the reference circle, Pa.
    nominal: f64,
    /// FE wall time of both gears, s.
    fe_s: f64,
    /// ISO 6336-3 method B nominal root stress σ_F0 of pinion and gear at the same torque, Pa.
    iso: [f64; 2],
}

/// The designs of the root-stress page: Table 1, its spur variant, and a wider variant with a
/// larger helix angle.
fn stress_designs() -> [(&'static str, GearPair); 3] {
    let t1 = GearPair::paper_table1();
    let spur = GearPair { helix_angle_rad: 0.0, ..t1.clone() };
    let wide = GearPair { helix_angle_rad: 20f64.to_radians(), face_width_m: 25e-3, ..t1.clone() };
    [
        ("Table 1 (β = 10°, b = 15 mm)", t1),
        ("spur (β = 0°)", spur),
        ("Table 1 with β = 20°, b = 25 mm", wide),
    ]
}

/// The refined FE density in four axial layers with the root fillet's region refined further:
/// elements along the fillet (`fillet`) and across the half tooth (`across`), by name. The root
/// stress is observed in the fillet, so these are its convergence path beyond the refined mesh;
/// four layers instead of eight keep the runs short (the root page's refined row in eight
/// layers shows what the layers change). From `across` 7 on the Table 1 gear's root block is
/// relaxed (`compliance::fe::gear_mesh`, "Folded blocks"); the pinion's keeps its Coons map.
fn fillet_refinements() -> [(&'static str, GearMeshDensity); 8] {
    let d = |fillet, across| GearMeshDensity {
        fillet,
        across,
        layers: 4,
        ..GearMeshDensity::refined()
    };
    [
        ("refined, 4 layers (fillet 3, across 4)", d(3, 4)),
        ("fillet 6, across 4", d(6, 4)),
        ("fillet 6, across 6", d(6, 6)),
        ("fillet 8, across 6", d(8, 6)),
        ("fillet 12, across 6", d(12, 6)),
        ("fillet 16, across 6", d(16, 6)),
        ("fillet 16, across 8", d(16, 8)),
        ("fillet 16, across 10", d(16, 10)),
    ]
}

/// The static root stress of `pair` at `torque` (N·m) over one pinion pitch (32 points) with
/// FE data at `density`, full fidelity.
fn static_root_stress(
    design: &'static str,
    density_name: &'static str,
    pair: &GearPair,
    density: &GearMeshDensity,
    torque: f64,
) -> Result<StressRow, String> {
    use helical_gear_mesh::compliance::data::ComplianceData;
    let data =
        ComplianceData::compute(pair, density, DEFAULT_DEPTH_MN * pair.normal_module_m, false)
            .map_err(|e| e.to_string())?;
    let mut m = Mesh::from_data(pair, MeshOptions::default(), &data).map_err(|e| e.to_string())?;
    let geo = m.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let curve = helical_gear_mesh::mesh::static_curve(&mut m, torque, 0.0, pitch, 32, 1)
        .map_err(|e| e.to_string())?;
    let max = |f: fn(&helical_gear_mesh::mesh::MeshOutputs) -> f64| {
        curve.points.iter().map(|e| f(&e.outputs)).fold(0.0, f64::max)
    };
    let row = StressRow {
        design,
        density: density_name,
        sigma_p: max(|o| o.root_stress_p),
        sigma_g: max(|o| o.root_stress_g),
        nominal: torque / geo.pinion.r / (pair.face_width_m * pair.normal_module_m),
        fe_s: data.fe_seconds(),
        iso: {
            let r =
                nominal_root_stress(pair, &geo, torque).map_err(|e| format!("{design}: {e}"))?;
            [r.pinion.sigma_f0_pa, r.gear.sigma_f0_pa]
        },
    };
    eprintln!(
        "stress: {design}, {density_name}: σ_F p {:.2} MPa, g {:.2} MPa (FE {:.1} s)",
        row.sigma_p * 1e-6,
        row.sigma_g * 1e-6,
        row.fe_s
    );
    Ok(row)
}

/// The root-stress page: convergence in the FE density, designs, cost per evaluation.
fn root_stress(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let torque = 100.0;
    let mut md = header("Tooth-root stress from the FE model", "stress");
    md.push_str(
        "The largest maximum principal stress at the tension-side root fillets \
         (`MeshOutputs::root_stress_p`, `root_stress_g`; method: `docs/loads.md`) \
         at the static equilibrium of 100 N·m on the pinion, the largest over 32 pinion angles \
         of one pitch, full fidelity with 200 slices. `F_t/(b·m_n)` is the nominal bending \
         stress (F_t = M/r at the reference circle); the ratios are the stress over it. FE data \
         computed afresh for every row (the time is both gears' FE run). Beside it the nominal \
         tooth-root stress σ_F0 of ISO 6336-3:2006 method B at the same torque (the library's \
         `iso6336`, [docs/iso6336.md](../iso6336.md)); why the two differ: \
         [docs/loads.md](../loads.md#fe-root-stress-against-iso-6336-3).\n\n",
    );
    let mut rows = Vec::new();
    let t1 = GearPair::paper_table1();
    for (name, d) in densities() {
        rows.push(static_root_stress("Table 1 (β = 10°, b = 15 mm)", name, &t1, &d, torque)?);
    }
    for (name, d) in fillet_refinements() {
        rows.push(static_root_stress("Table 1 (β = 10°, b = 15 mm)", name, &t1, &d, torque)?);
    }
    for (design, pair) in stress_designs().into_iter().skip(1) {
        rows.push(static_root_stress(
            design,
            "default",
            &pair,
            &GearMeshDensity::default(),
            torque,
        )?);
    }
    // The table: one row per (design, density); further columns (e.g. a standard's nominal
    // stress) go at the end of `columns` and `cells`.
    let columns = [
        "design",
        "FE density",
        "σ_F pinion, MPa",
        "σ_F gear, MPa",
        "F_t/(b·m_n), MPa",
        "σ_F,p / nominal",
        "σ_F,g / nominal",
        "FE, s",
        "ISO σ_F0 pinion, MPa",
        "ISO σ_F0 gear, MPa",
        "σ_F,p / σ_F0,p",
        "σ_F,g / σ_F0,g",
    ];
    let cells = |r: &StressRow| -> Vec<String> {
        vec![
            r.design.to_string(),
            r.density.to_string(),
            format!("{:.2}", r.sigma_p * 1e-6),
            format!("{:.2}", r.sigma_g * 1e-6),
            format!("{:.2}", r.nominal * 1e-6),
            format!("{:.3}", r.sigma_p / r.nominal),
            format!("{:.3}", r.sigma_g / r.nominal),
            format!("{:.1}", r.fe_s),
            format!("{:.2}", r.iso[0] * 1e-6),
            format!("{:.2}", r.iso[1] * 1e-6),
            format!("{:.3}", r.sigma_p / r.iso[0]),
            format!("{:.3}", r.sigma_g / r.iso[1]),
        ]
    };
    md.push_str("## Convergence in the FE mesh density (Table 1)\n\n");
    let table = |rows: &mut dyn Iterator<Item = &StressRow>| {
        let mut t = format!("| {} |\n|{}\n", columns.join(" | "), " --- |".repeat(columns.len()));
        for r in rows {
            writeln!(t, "| {} |", cells(r).join(" | ")).ok();
        }
        t
    };
    let n = densities().len();
    md.push_str(&table(&mut rows.iter().take(n)));
    let (c, d, r) = (&rows[0], &rows[1], &rows[n - 1]);
    writeln!(
        md,
        "\nChange from the default to the refined mesh: pinion {:+.1} %, gear {:+.1} %; from \
         the coarse to the default mesh: pinion {:+.1} %, gear {:+.1} %.\n",
        100.0 * (r.sigma_p / d.sigma_p - 1.0),
        100.0 * (r.sigma_g / d.sigma_g - 1.0),
        100.0 * (d.sigma_p / c.sigma_p - 1.0),
        100.0 * (d.sigma_g / c.sigma_g - 1.0)
    )
    .ok();
    let nf = fillet_refinements().len();
    let fillet_rows = &rows[n..n + nf];
    let finest = &fillet_rows[nf - 1];
    md.push_str(&format!(
        "## Refinement of the root fillet (Table 1)\n\n\
         The refined mesh refines the whole gear, but the fillet, where the stress is observed, \
         only from 2 to 3 elements along it and from 3 to 4 across the half tooth. Below, \
         from the refined mesh in four axial layers, the elements along the fillet \
         (`fillet`) and across the half tooth (`across`) are refined further. From `across` \
         = 7 on, the Table 1 gear's root block is relaxed (its Coons map would fold; \
         `compliance::fe::gear_mesh`, \"Folded blocks\"), a slightly different discretisation \
         of the same gear; the pinion's is not.\n\n{}\n\
         Change from the default mesh to the finest row ({}): pinion {:+.1} %, gear {:+.1} %; \
         from the refined mesh to it: pinion {:+.1} %, gear {:+.1} %.\n\n",
        table(&mut fillet_rows.iter()),
        finest.density,
        100.0 * (finest.sigma_p / d.sigma_p - 1.0),
        100.0 * (finest.sigma_g / d.sigma_g - 1.0),
        100.0 * (finest.sigma_p / r.sigma_p - 1.0),
        100.0 * (finest.sigma_g / r.sigma_g - 1.0),
    ));
    md.push_str("## Designs at the default FE density\n\n");
    md.push_str(&table(&mut rows.iter().skip(1).take(1).chain(rows.iter().skip(n + nf))));
    // Cost per evaluation, with and without the root stress.
    md.push_str(&format!(
        "\n## Cost per evaluation\n\nTable 1 along one pitch at TE = 30 µm (64 states, \
         warm-started), fastest of nine passes alternating between the two models; the same model \
         without the root-stress data \
         for comparison (full fidelity 200 slices, table fidelity the default {dt} \
         table).\n\n| fidelity | without, µs | with root stress, µs | ratio |\n| --- | --- | --- | --- |\n",
        dt = default_table()
    ));
    for fidelity in [Fidelity::Full, Fidelity::Table] {
        let (without, with) = evaluation_cost(fidelity)?;
        writeln!(md, "| {fidelity:?} | {without:.2} | {with:.2} | {:.3} |", with / without).ok();
        eprintln!("stress: {fidelity:?}: {without:.2} µs without, {with:.2} µs with root stress");
    }
    let mut csv = String::from(
        "design,density,root_stress_max_p_pa,root_stress_max_g_pa,nominal_pa,fe_s,iso_sigma_f0_p_pa,iso_sigma_f0_g_pa\n",
    );
    for r in &rows {
        writeln!(
            csv,
            "\"{}\",{},{:.6e},{:.6e},{:.6e},{:.2},{:.6e},{:.6e}",
            r.design, r.density, r.sigma_p, r.sigma_g, r.nominal, r.fe_s, r.iso[0], r.iso[1]
        )
        .ok();
    }
    md.push_str("\nThe rows as data: [root_stress.csv](root_stress.csv).\n");
    Ok(vec![write(dir, "root_stress.md", &md)?, write(dir, "root_stress.csv", &csv)?])
}

/// Time per evaluation (µs) of Table 1 at `fidelity` without and with the root stress.
fn evaluation_cost(fidelity: Fidelity) -> Result<(f64, f64), String> {
    use helical_gear_mesh::compliance::data::ComplianceData;
    use helical_gear_mesh::geometry::Member;
    use helical_gear_mesh::mesh::model::GearCompliance;
    let p = GearPair::paper_table1();
    let options = MeshOptions { fidelity, ..MeshOptions::default() };
    let data = ComplianceData::embedded_table1().map_err(|e| e.to_string())?;
    let interp = |m| -> Result<GearCompliance, String> {
        Ok(GearCompliance::Interpolated(std::sync::Arc::new(
            data.interpolated(m).map_err(|e| e.to_string())?,
        )))
    };
    let mut without =
        Mesh::with_compliance(&p, options, interp(Member::Pinion)?, interp(Member::Gear)?)
            .map_err(|e| e.to_string())?;
    let mut with = Mesh::from_data(&p, options, &data).map_err(|e| e.to_string())?;
    let geo = with.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let states: Vec<MeshState> = (0..64)
        .map(|k| {
            let phi_p = pitch * k as f64 / 64.0;
            MeshState {
                phi_p,
                phi_g: geo.phi_g_for_te(phi_p, 30e-6),
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            }
        })
        .collect();
    let pass = |m: &mut Mesh| -> Result<f64, String> {
        let t0 = Instant::now();
        for s in &states {
            std::hint::black_box(m.evaluate(s).map_err(|e| e.to_string())?);
        }
        Ok(t0.elapsed().as_secs_f64() / states.len() as f64 * 1e6)
    };
    // Passes alternate between the two models, so that other load on the machine hits both
    // alike; the fastest pass of each counts.
    let (mut a, mut b) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..9 {
        a = a.min(pass(&mut without)?);
        b = b.min(pass(&mut with)?);
    }
    Ok((a, b))
}

/// Mesh friction of Table 1: efficiency against ISO/TR 14179-2, figures, dynamic effect, cost.
fn friction(dir: &Path) -> Result<Vec<PathBuf>, String> {
    use helical_gear_app::plot::{LineChart, Series, SeriesStyle, line_chart, write_csv};
    use helical_gear_mesh::contact::{ContactSolver, FlankSide};
    use helical_gear_mesh::dynamics::{GearDynamics, SteadyRunOptions, run_to_steady};
    use helical_gear_mesh::mesh::friction::{FrictionConst, loss_factor_h_v, slice_friction};
    use helical_gear_mesh::mesh::{Friction, FrictionModel, static_curve_with};
    let e = |e: helical_gear_mesh::mesh::MeshError| e.to_string();
    let (torque, w_p, points) = (100.0, 300.0, 64);
    let pair = GearPair::paper_table1();
    let iso = Friction { model: FrictionModel::IsoTr14179_2, ..Friction::default() };
    let constant = Friction::constant(0.05);
    let mut md = header("Mesh friction and efficiency of Table 1", "friction");
    writeln!(
        md,
        "Table 1 at M = {torque} N·m on the pinion and ω_p = {w_p} rad/s: quasi-static states \
         (static equilibrium at {points} pinion angles over one pitch, the gear at the rigid \
         ratio), full fidelity (200 slices). Mean loss P̄_loss over the cycle, mean efficiency \
         1 − P̄_loss/(M·ω_p), and ISO/TR 14179-2's mean loss μ·H_V·M·ω_p with H_V from the \
         geometry. The model: [the guide](../friction.md).\n"
    )
    .ok();
    md.push_str(
        "| friction | μ | mean loss P̄_loss, W | mean efficiency | μ·H_V·P_in, W | P̄_loss/(μ·H_V·P_in) |\n\
         | --- | --- | --- | --- | --- | --- |\n",
    );
    let geo = PairGeometry::new(&pair).map_err(|e| e.to_string())?;
    let h_v = loss_factor_h_v(&geo);
    let pitch = geo.pinion.angular_pitch();
    let settings = EquilibriumSettings { w_p, ..EquilibriumSettings::default() };
    let mut cycle_series = Vec::new();
    let mut cycle_csv: Vec<Vec<f64>> =
        (0..points).map(|k| vec![k as f64 / points as f64]).collect();
    let mut path_states = Vec::new();
    let variants = [
        ("constant μ = 0.05", constant, pair.clone()),
        ("ISO/TR 14179-2 (η_oil 0.05 Pa·s, Ra 0.5 µm, X_L 1)", iso, pair.clone()),
        ("constant μ = 0.05, Table 1 without tip relief", constant, {
            let mut p = pair.clone();
            p.tip_relief_depth_mn = 0.0;
            p
        }),
    ];
    for (k, (label, friction, p)) in variants.iter().enumerate() {
        let mut m = Mesh::new(p, MeshOptions { friction: *friction, ..MeshOptions::default() })
            .map_err(e)?;
        let curve =
            static_curve_with(&mut m, torque, 0.0, pitch, points, 1, &settings).map_err(e)?;
        let n = curve.points.len() as f64;
        let loss = curve.points.iter().map(|q| q.outputs.p_loss).sum::<f64>() / n;
        let fc = FrictionConst::new(m.geometry(), *friction);
        let mu =
            curve.points.iter().map(|q| fc.mu(q.outputs.m_f_p - q.outputs.m_r_p, w_p)).sum::<f64>()
                / n;
        let p_in = torque * w_p;
        writeln!(
            md,
            "| {label} | {mu:.4} | {loss:.2} | {:.5} | {:.2} | {:.3} |",
            1.0 - loss / p_in,
            mu * h_v * p_in,
            loss / (mu * h_v * p_in)
        )
        .ok();
        if k < 2 {
            let pts: Vec<(f64, f64)> = curve
                .points
                .iter()
                .enumerate()
                .map(|(i, q)| (i as f64 / n, q.outputs.p_loss))
                .collect();
            for (row, (_, y)) in cycle_csv.iter_mut().zip(&pts) {
                row.push(*y);
            }
            cycle_series.push(Series {
                name: format!("P_loss, {label}"),
                points: pts,
                style: SeriesStyle::Line,
            });
            cycle_series.push(Series {
                name: format!("μ·H_V·P_in, {}", if k == 0 { "μ = 0.05" } else { "μ_mz" }),
                points: vec![(0.0, mu * h_v * p_in), (1.0, mu * h_v * p_in)],
                style: SeriesStyle::Line,
            });
        }
        if k == 0 {
            path_states = curve.points.iter().step_by(points / 16).copied().collect();
        }
    }
    writeln!(
        md,
        "\nH_V = {h_v:.4} (ISO/TR 14179-2, Ohlendorf: the spur gear's load sharing, one pair \
         all, two pairs half each). The model's loss follows its own load sharing: without tip \
         relief it is within a few per cent of μ·H_V·P_in; Table 1's tip relief unloads the \
         ends of the path of contact, where the sliding is fastest, and the loss falls well \
         below it (the guide explains, `tests/friction.rs` holds both, and the uniform-load \
         limit to 2 %).\n"
    )
    .ok();
    line_chart(
        &dir.join("friction_cycle.png"),
        &LineChart {
            title: format!("Mesh loss over a mesh cycle, Table 1, {torque} N·m, {w_p} rad/s"),
            x_label: "pinion angle / pinion pitch".into(),
            y_label: "P_loss (W)".into(),
            series: cycle_series,
            ..LineChart::default()
        },
        (900, 500),
    )
    .map_err(|e| e.to_string())?;
    write_csv(
        &dir.join("friction_cycle.csv"),
        &["phase_per_pitch", "p_loss_constant_w", "p_loss_iso_w"],
        cycle_csv,
    )
    .map_err(|e| e.to_string())?;

    // The friction force per unit length along the path of contact: every loaded slice of 16
    // static states over the cycle.
    let mut m = Mesh::new(
        &pair,
        MeshOptions { friction: constant, detail: true, ..MeshOptions::default() },
    )
    .map_err(e)?;
    let (gp, gg) = (geo.pinion.rb, geo.gear.rb);
    let cs = ContactSolver::new(&geo);
    let frame = helical_gear_mesh::mesh::ForceFrame::new(&geo);
    let (sin_wt, cos_wt) = geo.alpha_wt.sin_cos();
    let r_wp = gp / cos_wt;
    let dz = geo.b0() / m.slices_per_line() as f64;
    let axial = pair.normal_module_m * dz;
    let (mut tip, mut root) = (Vec::new(), Vec::new());
    let mut path_csv = Vec::new();
    let mut contacts = Vec::new();
    for (k, eq) in path_states.iter().enumerate() {
        let state = MeshState {
            phi_p: eq.phi_p,
            phi_g: eq.phi_g,
            w_p,
            w_g: -w_p * gp / gg,
            ..Default::default()
        };
        m.evaluate(&state).map_err(e)?;
        let detail = m.slices().to_vec();
        let zetas: Vec<f64> = detail.iter().map(|d| d.zeta).collect();
        cs.contacts_on(FlankSide::Drive, state.phi_p, state.phi_g, &zetas, &mut contacts);
        for d in detail.iter().filter(|d| d.q_n_per_m > 0.0 && !d.back) {
            let Some(c) = contacts.iter().find(|c| c.pair == d.pair && c.zeta == d.zeta) else {
                continue;
            };
            let s = (c.point_p[0] - r_wp) * sin_wt + c.point_p[1] * cos_wt;
            let sf = slice_friction(&frame, c, d.q_n_per_m * axial, state.w_p, state.w_g, 0.05);
            let t = [-c.normal_angle.sin(), c.normal_angle.cos()];
            let f = &sf.wrench.force_p;
            let ft = 0.05 * (f[0] * t[0] + f[1] * t[1]) / (axial / geo.base_helix_angle.cos());
            let on_involute = d.kind == "involute/involute";
            if on_involute { &mut root } else { &mut tip }.push((s * 1e3, ft * 1e-3));
            path_csv.push(vec![
                k as f64,
                d.pair as f64,
                d.zeta,
                s * 1e3,
                d.q_n_per_m * 1e-3,
                ft * 1e-3,
                sf.sliding_speed,
                f64::from(u8::from(on_involute)),
            ]);
        }
    }
    line_chart(
        &dir.join("friction_path.png"),
        &LineChart {
            title: format!(
                "Friction on the pinion along the path of contact, μ = 0.05, {torque} N·m, {w_p} rad/s"
            ),
            x_label: "position on the line of action from the pitch point (mm; + towards the pinion tip)".into(),
            y_label: "friction per unit contact length along the profile (N/mm)".into(),
            series: vec![
                Series {
                    name: "slices on both involutes".into(),
                    points: root,
                    style: SeriesStyle::Points,
                },
                Series {
                    name: "slices off the involute (tip relief or rounding)".into(),
                    points: tip,
                    style: SeriesStyle::Points,
                },
            ],
            ..LineChart::default()
        },
        (900, 500),
    )
    .map_err(|e| e.to_string())?;
    write_csv(
        &dir.join("friction_path.csv"),
        &[
            "state",
            "pair",
            "zeta",
            "s_mm",
            "q_n_per_mm",
            "friction_n_per_mm",
            "sliding_speed_m_s",
            "on_involute",
        ],
        path_csv,
    )
    .map_err(|e| e.to_string())?;
    md.push_str(
        "![Friction along the path of contact](friction_path.png)\n\n\
         The friction per unit length of contact line on the pinion flank, along the profile \
         (positive towards the pinion tip), at every loaded slice of 16 static states over the \
         mesh cycle: it reverses at the pitch point (s = 0), where the sliding does, and falls \
         towards the ends of the path with the load (tip relief).\n\n\
         ![Loss over a mesh cycle](friction_cycle.png)\n\n",
    );

    // Dynamic effect: steady runs at table fidelity with and without friction.
    writeln!(
        md,
        "## Effect on the dynamics\n\nSteady runs of Eqs. 1–4 (`run_to_steady`, RK4, table \
         fidelity {dt}), Table 1 drive line, with and without constant μ = 0.05 (the brake \
         set to take the power the mesh delivers). Means and peak-to-peak over the steady \
         window.\n\n\
         | ω_p, rad/s | friction | TE mean, µm | TE p-p, µm | F_p,z mean, N | F_p,z p-p, N | M_R,p p-p, N·m | mean P_loss, W | mean efficiency |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        dt = default_table()
    )
    .ok();
    let drive_line = helical_gear_mesh::DriveLine::paper_table1();
    let drive = Drivetrain::from_pair(&pair, &drive_line).map_err(|e| e.to_string())?;
    for omega in [300.0, 532.0] {
        for (label, friction) in [("none", Friction::none()), ("μ = 0.05", constant)] {
            let opts =
                MeshOptions { fidelity: Fidelity::Table, friction, ..MeshOptions::default() }
                    .sized_for(&drive_line);
            let mesh = Mesh::new(&pair, opts).map_err(e)?;
            let mut model = GearDynamics::new(mesh, drive).map_err(|e| e.to_string())?;
            let r = run_to_steady(&mut model, omega, &SteadyRunOptions::default())
                .map_err(|e| e.to_string())?;
            let w = &r.window;
            let stat = |f: &dyn Fn(&helical_gear_mesh::dynamics::WindowSample) -> f64| {
                let v: Vec<f64> = w.iter().map(f).collect();
                let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (mean, hi - lo)
            };
            let (te_m, te_pp) = stat(&|s| s.outputs.te * 1e6);
            let (fz_m, fz_pp) = stat(&|s| s.outputs.force_p[2]);
            let (_, mr_pp) = stat(&|s| s.outputs.m_r_p);
            let (loss, _) = stat(&|s| s.outputs.p_loss);
            let (p_in, _) = stat(&|s| (s.outputs.m_f_p + s.outputs.m_d_p) * s.y[5]);
            writeln!(
                md,
                "| {omega} | {label} | {te_m:.4} | {te_pp:.4} | {fz_m:.2} | {fz_pp:.2} | {mr_pp:.3} | {loss:.2} | {:.5} |",
                1.0 - loss / p_in
            )
            .ok();
            eprintln!("friction: dynamics {omega} rad/s, {label}");
        }
    }

    // Cost per evaluation.
    md.push_str(
        "\n## Cost per evaluation\n\nMean wall time per `evaluate` over 400 running states \
         (50 pinion angles × 8 TEs around the static TE, 300 rad/s, each from the previous \
         state's warm start), without and with constant μ = 0.05.\n\n\
         | fidelity, outputs | no friction | with friction | added |\n| --- | --- | --- | --- |\n",
    );
    // (label, fidelity, torques only: the right-hand side's `MeshTorques::torques`)
    for (label, fidelity, torques_only) in [
        ("Full, every output", Fidelity::Full, false),
        ("Table, every output", Fidelity::Table, false),
        ("Table, torques only (right-hand side)", Fidelity::Table, true),
    ] {
        let mut times = Vec::new();
        for friction in [Friction::none(), constant] {
            let mut m =
                Mesh::new(&pair, MeshOptions { fidelity, friction, ..MeshOptions::default() })
                    .map_err(e)?;
            let states: Vec<MeshState> = (0..400)
                .map(|i| {
                    let phi_p = pitch * (i / 8) as f64 / 50.0;
                    let te = 2.6e-5 + 1e-6 * (i % 8) as f64;
                    MeshState {
                        phi_p,
                        phi_g: geo.phi_g_for_te(phi_p, te),
                        w_p,
                        w_g: -w_p * gp / gg,
                        ..Default::default()
                    }
                })
                .collect();
            let reps = if fidelity == Fidelity::Full { 1 } else { 200 };
            let mut sink = 0.0;
            let one = |m: &mut Mesh, s: &MeshState| -> Result<f64, String> {
                Ok(if torques_only {
                    m.torques(s).map_err(e)?.0.m_f_p
                } else {
                    m.evaluate(s).map_err(e)?.m_f_p
                })
            };
            for s in &states {
                sink += one(&mut m, s)?;
            }
            let t0 = Instant::now();
            for _ in 0..reps {
                for s in &states {
                    sink += one(&mut m, s)?;
                }
            }
            std::hint::black_box(sink);
            times.push(t0.elapsed().as_secs_f64() / (reps * states.len()) as f64);
        }
        let (unit, scale) = if fidelity == Fidelity::Full { ("µs", 1e6) } else { ("ns", 1e9) };
        writeln!(
            md,
            "| {label} | {:.1} {unit} | {:.1} {unit} | {:+.1} % |",
            times[0] * scale,
            times[1] * scale,
            100.0 * (times[1] / times[0] - 1.0)
        )
        .ok();
    }
    Ok(vec![
        write(dir, "friction.md", &md)?,
        dir.join("friction_path.png"),
        dir.join("friction_path.csv"),
        dir.join("friction_cycle.png"),
        dir.join("friction_cycle.csv"),
    ])
}
