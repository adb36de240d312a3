//! Documentation pages generated from machine-readable reports, so that the figures the guides
//! state are the figures a program measured:
//!
//! * [`performance_page`]: the whole of `docs/performance.md`, from the `bench` command's
//!   report (`docs/bench/bench.json`, written by `helical-gear bench --out docs/bench`);
//! * [`paper_section`]: the section "The paper run, measured" of `docs/validation.md` (between
//!   [`PAPER_BEGIN`] and [`PAPER_END`]), from a paper run's `summary.json` (checked in as
//!   `docs/paper/summary.json`, written by `helical-gear paper --out DIR`).
//!
//! `cargo run -p helical-gear-app --example measure -- pages` writes both from the checked-in
//! reports; the test `app/tests/pages.rs` renders them again and fails when a checked-in page
//! differs (no timing run needed). The reports are read as untyped JSON: a missing or
//! mistyped field is an error naming it. Rendering is deterministic (no clock, no machine
//! state): the date, commit, CPU and load average on a page are the report's.
//!
//! Units: the reports' own (µs, ns, s, µm, rad/s, relative errors as fractions); the pages
//! print relative errors in the form `2.8·10⁻⁴`.

use serde_json::Value;

/// The line before the generated paper-run section of `docs/validation.md`.
pub const PAPER_BEGIN: &str = "<!-- paper-run: generated from docs/paper/summary.json by `cargo run -p helical-gear-app \
     --example measure -- pages`; do not edit -->";
/// The line after the generated paper-run section of `docs/validation.md`.
pub const PAPER_END: &str = "<!-- paper-run: end -->";

/// The paper's figures for Table 1 (A. Andersson, L. Vedmar, J. Sound Vib. 260, 2003).
const PAPER_STE_MAX_UM: f64 = 30.5;
/// The paper's main resonance, rad/s.
const PAPER_OMEGA_CRIT: f64 = 660.0;

/// A field of `v` by path (`"a.b"`), as a number.
fn num(v: &Value, path: &str) -> Result<f64, String> {
    field(v, path)?.as_f64().ok_or_else(|| format!("report field `{path}` is not a number"))
}

/// A field of `v` by path, as a string.
fn text<'a>(v: &'a Value, path: &str) -> Result<&'a str, String> {
    field(v, path)?.as_str().ok_or_else(|| format!("report field `{path}` is not a string"))
}

/// A field of `v` by path, as an array.
fn list<'a>(v: &'a Value, path: &str) -> Result<&'a Vec<Value>, String> {
    field(v, path)?.as_array().ok_or_else(|| format!("report field `{path}` is not a list"))
}

/// A field of `v` by a dotted path.
fn field<'a>(v: &'a Value, path: &str) -> Result<&'a Value, String> {
    path.split('.')
        .try_fold(v, |v, key| v.get(key).ok_or_else(|| format!("the report has no field `{path}`")))
}

/// `x` with two significant digits as `2.8·10⁻⁴` (plain for 0.01 ≤ |x| < 1000).
pub fn sci(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if (0.01..1000.0).contains(&x.abs()) {
        return format!("{}", round_sig(x, 2));
    }
    let s = format!("{x:.1e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let sup: String = exp
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            other => other,
        })
        .collect();
    format!("{mantissa}·10{sup}")
}

/// `x` rounded to `digits` significant digits.
fn round_sig(x: f64, digits: i32) -> f64 {
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

/// A time in µs with three significant digits and a fitting unit (ns, µs, ms, s).
pub fn time_us(us: f64) -> String {
    let three = |v: f64| {
        if v >= 100.0 {
            format!("{v:.0}")
        } else if v >= 10.0 {
            format!("{v:.1}")
        } else {
            format!("{v:.2}")
        }
    };
    if us < 1.0 {
        format!("{} ns", three(us * 1e3))
    } else if us < 1e3 {
        format!("{} µs", three(us))
    } else if us < 1e6 {
        format!("{} ms", three(us * 1e-3))
    } else {
        format!("{} s", three(us * 1e-6))
    }
}

/// Thousands separated by a thin space, as in `180 481`.
fn count(n: f64) -> String {
    let digits = format!("{:.0}", n);
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// Renders `docs/performance.md` from the `bench` report `bench` (the parsed `bench.json`).
pub fn performance_page(bench: &Value) -> Result<String, String> {
    let mut p = String::new();
    let push = |p: &mut String, s: &str| {
        p.push_str(s);
        p.push('\n');
    };
    push(&mut p, "# Performance");
    push(&mut p, "");
    push(
        &mut p,
        "<!-- Generated from docs/bench/bench.json by `cargo run -p helical-gear-app --example \
         measure -- pages`; do not edit. -->",
    );
    push(&mut p, "");
    let cores = num(bench, "cores")?;
    // A loaded machine: say so first, and what that does to the figures.
    if let Some(load1) = crate::bench::loaded(text(bench, "load_average")?, cores) {
        p.push_str(&format!(
            "> **Measured on a loaded machine**: the 1-minute load average was {load1} on {cores} \
             cores when the run started, more than half the cores busy with other work. Every \
             time on this page is longer and noisier than on an idle machine, most of all the \
             differences between neighbouring rows (the option costs below); the errors and the \
             evaluation counts do not depend on the load. Regenerate it on an idle machine \
             with the two commands below.\n\n"
        ));
    }
    p.push_str(&format!(
        "Measured by `cargo run --release -- bench --out docs/bench` at commit `{}` on {} (UTC), \
         on a machine with {} cores ({}), load average {} (1, 5, 15 minutes) when the run \
         started: other work on the machine makes every time longer (`bench --out` refuses to \
         start when the 1-minute load average exceeds half the cores, unless given \
         `--allow-loaded`). The report is `docs/bench/bench.json`, the rows are in \
         `docs/bench/*.csv`; this page is rendered from the report by `cargo run -p \
         helical-gear-app --example measure -- pages`.\n\n",
        text(bench, "commit")?,
        text(bench, "date_utc")?,
        cores,
        text(bench, "cpu")?,
        text(bench, "load_average")?,
    ));
    push(
        &mut p,
        "After reading this you will know what a mesh evaluation, a dynamic run, the paper run \
         and the drive-line units cost on that machine, how accurate each setting is, and which \
         fidelity and options to choose for a job. `--json` prints the report on stdout; \
         `--quick` is a smoke run for the tests, not a measurement. The other generated \
         measurement pages are [bench/cosimulation.md](bench/cosimulation.md), \
         [bench/units.md](bench/units.md), [bench/jacobian.md](bench/jacobian.md) and \
         [bench/fe.md](bench/fe.md); measurements of earlier days, with what changed between \
         them, are in the [CHANGELOG](../CHANGELOG.md).",
    );
    push(&mut p, "");

    let mesh = list(bench, "mesh")?;
    // The default table's size (reports before it was recorded: 64 × 48, the default then).
    let default_size =
        bench.get("table_default_size").cloned().unwrap_or_else(|| serde_json::json!([64, 48]));
    let dsize = format!("{} × {}", default_size[0], default_size[1]);
    let table_default = mesh
        .iter()
        .find(|c| c["family"] == "table" && c.get("table_size") == Some(&default_size))
        .ok_or(format!("the report has no table case of the default size {dsize}"))?;
    let paper_s = bench.get("paper_runtime_s").and_then(Value::as_f64);
    push(&mut p, "| key | value |");
    push(&mut p, "| --- | --- |");
    // What a user waits for (reports before these keys existed render without them).
    let opt = |k: &str| bench.get(k).and_then(Value::as_f64);
    if let (Some(cold), Some(warm), Some(e)) =
        (opt("full_eval_us"), opt("full_eval_warm_us"), opt("full_eval_max_rel_err"))
    {
        let secs = |k: &str| opt(k).map_or("not measured".into(), |v| format!("{v:.2} s"));
        p.push_str(&format!(
            "| `full_eval_us` (one full evaluation, 200 slices, interpolated compliance, default \
             options, cold start) | {} |\n{}| `full_eval_warm_us` (the same warm-started from \
             the state before, as along a trajectory) | {} |\n| `full_eval_max_rel_err` (its \
             M_F,p \
             error against the reference) | {} |\n| `table_build_s` (the default {dsize} \
             table of the driving flanks) | {} |\n{}| `table_deviation_build_s` (the per-pair table with pitch \
             deviations, [hunting case](#tooth-deviations-on-the-table-a-dynamic-run-over-a-hunting-period)) | {} |\n| \
             `fe_compliance_s` (FE compliance of a new pair, default mesh, no cache) | {} \
             |\n| `design_s` (one design of `helical_gear.study.run` with `static` and \
             `sweep` at their defaults: FE with both gears in parallel, static TE, table rows on \
             every core, sweep on one thread) | {} |\n| \
             `table_eval_torques_ns` (a table evaluation of the torques and TE only) | {} |\n",
            time_us(cold),
            opt("full_eval_cold_from_zero_us").map_or(String::new(), |v| format!(
                "| `full_eval_cold_from_zero_us` (the same cold evaluation with the load solver \
                 started from q = 0, the method before the coarse pre-solve) | {} |\n",
                time_us(v)
            )),
            time_us(warm),
            sci(e),
            secs("table_build_s"),
            opt("table_back_build_s").map_or(String::new(), |v| format!(
                "| `table_back_build_s` (its back-flank axis, sampled at the first state with \
                 TE < −j_t) | {v:.2} s |\n"
            )),
            secs("table_deviation_build_s"),
            secs("fe_compliance_s"),
            secs("design_s"),
            opt("table_eval_torques_ns").map_or("not measured".into(), |v| time_us(v * 1e-3)),
        ));
    } else {
        p.push_str(&format!(
            "| `full_eval_us` (full fidelity, 200 slices, interpolated compliance, default \
             options, warm) | {} |\n",
            time_us(num(bench, "full_eval_us")?)
        ));
    }
    p.push_str(&format!(
        "| `table_eval_ns` (table fidelity, {dsize} nodes) | {} |\n| `table_max_rel_err` \
         (the same table against the {}-slice reference) | {} |\n| `paper_runtime_s` (the whole \
         `paper` run, quiet) | {} |\n\n",
        time_us(num(bench, "table_eval_ns")? * 1e-3),
        num(bench, "reference_slices")?,
        sci(num(bench, "table_max_rel_err")?),
        paper_s.map_or("not run".into(), |s| format!("{s:.1} s")),
    ));
    if let Some(n) = bench.get("build_runs").and_then(Value::as_u64).filter(|&n| n > 1) {
        p.push_str(&format!(
            "Each build time (the tables, the FE compliance, the design's FE and table) is the \
             fastest of {n} builds, as each evaluation time is the fastest of several passes; \
             the back-flank axis is sampled once, at its first use.\n\n"
        ));
    }

    // Mesh evaluation.
    p.push_str(&format!(
        "## Mesh evaluation\n\nThe {} states sweep one pitch at each of three TE levels (16, 32 \
         and 48 µm) at 300 rad/s, which warm-starts each call as a trajectory would. The time is \
         the fastest of at least 1 s of passes on one thread. The error is the largest relative \
         error of M_F,p against the full model at {} slices.\n\n",
        num(bench, "states")?,
        num(bench, "reference_slices")?
    ));
    push(
        &mut p,
        "| fidelity, compliance | slices | time per evaluation | max error of M_F,p | LU \
         factorisations per solve |",
    );
    push(&mut p, "| --- | --- | --- | --- | --- |");
    let mut first_fitted = true;
    for c in mesh {
        let family = text(c, "family")?;
        let slices = num(c, "slices")?;
        let factorizations = c
            .get("factorizations_per_solve")
            .and_then(Value::as_f64)
            .map_or(String::new(), |f| format!("{f:.1}"));
        let name = match family {
            "full interpolated" => "full, interpolated".to_string(),
            "full interpolated, general assembly" => {
                "full, interpolated, without the slice kernel".to_string()
            }
            "full fitted" if first_fitted => {
                first_fitted = false;
                "full, fitted (Eqs. 5–8)".to_string()
            }
            "full fitted" => "full, fitted".to_string(),
            "table" | "table, sampled at the full model's slices" => {
                let size = list(c, "table_size")?;
                let (a, b) = (size[0].as_f64().unwrap_or(0.0), size[1].as_f64().unwrap_or(0.0));
                let build = num(c, "build_s")?;
                // Reports before the table had its own sample slices have no such key.
                let sampled = c
                    .get("sample_slices")
                    .and_then(Value::as_f64)
                    .map_or(String::new(), |n| format!(", sampled at {n} slices"));
                if family != "table" {
                    format!(
                        "table {a} × {b}{sampled}, the method before 2026-11-28 ({build:.1} s to build)"
                    )
                } else if [Some(a), Some(b)] == [default_size[0].as_f64(), default_size[1].as_f64()]
                {
                    format!("table {a} × {b}, the default{sampled} ({build:.1} s to build)")
                } else {
                    format!("table {a} × {b}{sampled} ({build:.1} s to build)")
                }
            }
            other => other.to_string(),
        };
        p.push_str(&format!(
            "| {name} | {slices} | {} | {} | {factorizations} |\n",
            time_us(num(c, "eval_us")?),
            sci(num(c, "max_rel_err")?),
        ));
    }
    push(&mut p, "");
    push(&mut p, "![Mesh evaluation: error against time](bench/bench_mesh.png)");
    push(&mut p, "");
    let tables: Vec<&Value> = mesh.iter().filter(|c| c["family"] == "table").collect();
    // The smallest and the largest grid by nodes (the default may come last in the report).
    let nodes = |c: &Value| {
        list(c, "table_size").map_or(0.0, |s| s.iter().filter_map(Value::as_f64).product())
    };
    let by_nodes = |a: &&Value, b: &&Value| nodes(a).total_cmp(&nodes(b));
    let smallest = tables.iter().copied().min_by(by_nodes).ok_or("the report has no table case")?;
    let largest = tables.iter().copied().max_by(by_nodes).ok_or("the report has no table case")?;
    let size = |c: &Value| -> Result<String, String> {
        let s = list(c, "table_size")?;
        Ok(format!("{} × {}", s[0], s[1]))
    };
    let full_at = |family: &str, slices: f64| {
        mesh.iter().find(|c| c["family"] == family && c["slices"].as_f64() == Some(slices))
    };
    let interp200 = full_at("full interpolated", 200.0).ok_or("no full case at 200 slices")?;
    let interp400 = full_at("full interpolated", 400.0).ok_or("no full case at 400 slices")?;
    let fitted200 = full_at("full fitted", 200.0).ok_or("no fitted case at 200 slices")?;
    p.push_str(&format!(
        "Which to use when:\n\
         * **Dynamics, sweeps, the FMU in a drivetrain:** the table. It costs the same at every \
         size ({} at {dsize}); its error falls from {} at {} to {} at the default {dsize} and \
         {} at {} ({:.1} s to build).\n\
         * **Static analysis, pressure waterfalls, per-slice detail, references:** full \
         fidelity at 100–200 slices ({} at 200 slices, error {}; 400 slices: {}, {}).\n\
         * **Interpolated or fitted compliance:** the fitted Eqs. 5–8 evaluate a formula for \
         each matrix entry and carry the fit's error ({} at 200 slices against {} \
         interpolated, error {} against {}). They are kept to compare with the paper's \
         method.\n\n",
        time_us(num(table_default, "eval_us")?),
        sci(num(smallest, "max_rel_err")?),
        size(smallest)?,
        sci(num(table_default, "max_rel_err")?),
        sci(num(largest, "max_rel_err")?),
        size(largest)?,
        num(largest, "build_s")?,
        time_us(num(interp200, "eval_us")?),
        sci(num(interp200, "max_rel_err")?),
        time_us(num(interp400, "eval_us")?),
        sci(num(interp400, "max_rel_err")?),
        time_us(num(fitted200, "eval_us")?),
        time_us(num(interp200, "eval_us")?),
        sci(num(fitted200, "max_rel_err")?),
        sci(num(interp200, "max_rel_err")?),
    ));

    // The fast full solve: what makes it fast, with the kernel's effect measured now.
    p.push_str(&format!(
        "**What makes the full solve fast.** The slices sit at fixed ζ_k, so \
         `compliance::interpolated::SliceInfluence` keeps the FE grid already interpolated in ζ \
         for every slice position: 16 multiplies and adds per matrix entry, on 256-bit \
         vectors where the CPU has AVX2 (the same operations in the same order as the portable \
         code, so the same matrix bit for bit), with the same rounding as the general \
         interpolation ({} per \
         evaluation with the slice kernel, {} without it, at 200 slices). Simplified Newton \
         steps reuse the LU factors held within a solve, and a warm start's loaded slices stay \
         in the first working set (the factorisations per solve are in the table above). A \
         cold solve starts from the loads of a coarse pre-solve on every fourth slice of each \
         contact line ({}; {} from q = 0). The \
         steady path allocates nothing (`tests/mesh_alloc.rs`). What remains is the matrix of \
         non-symmetric entries from an FE grid (the observation at depth h makes α* \
         non-reciprocal to 5 %) and one LU factorisation of the loaded slices per Newton \
         step; the table is the fast path.\n\n",
        time_us(opt("full_eval_warm_us").map_or_else(|| num(bench, "full_eval_us"), Ok)?),
        time_us(num(bench, "full_eval_general_us")?),
        time_us(num(bench, "full_eval_us")?),
        opt("full_eval_cold_from_zero_us").map_or("not measured".into(), time_us),
    ));

    // Tooth deviations on the table.
    let h = field(bench, "hunting")?;
    let evals = num(h, "mesh_evaluations")?;
    let run_s = num(h, "run_s")?;
    p.push_str(&format!(
        "## Tooth deviations on the table (a dynamic run over a hunting period)\n\n\
         The `hunting` case: Table 1 with the pitch errors and runouts of \
         `docs/modifications/table1_pitch_errors.json` (pinion deviations within ±1.9 µm, \
         runouts 5 and 8 µm) on the per-pair table ({} slices, {dsize}), RK4 at {} steps per \
         mesh period from the static start at 500 rad/s over {} meshes (the whole hunting \
         period); the torque error is |ΔM_F,p| against full fidelity at the same slices at {} \
         states sampled evenly from the run, over the nominal torque.\n\n\
         | key | value |\n| --- | --- |\n\
         | table build with deviations ({} slices, {dsize}) | {:.1} s |\n\
         | the run: {} meshes, {} mesh evaluations | {:.3} s ({} per evaluation, RK4 included) |\n\
         | table evaluation at the run's states | {} |\n\
         | M_F,p error against full fidelity, largest / RMS | {:.2} % / {:.2} % of the nominal \
         torque |\n\n\
         At single states at light load the per-pair table is off by up to 1.2 % (see \
         [Modifications, misalignment and deviations](modifications.md)). Full fidelity would \
         take about {} × {} ≈ {:.0} s for the same run.\n\n",
        num(h, "slices")?,
        num(h, "steps_per_mesh")?,
        count(num(h, "meshes")?),
        num(h, "sampled_states")?,
        num(h, "slices")?,
        num(h, "build_s")?,
        count(num(h, "meshes")?),
        count(evals),
        run_s,
        time_us(run_s / evals * 1e6),
        time_us(num(h, "table_eval_ns")? * 1e-3),
        100.0 * num(h, "max_torque_err")?,
        100.0 * num(h, "rms_torque_err")?,
        time_us(num(bench, "full_eval_us")?),
        count(evals),
        num(bench, "full_eval_us")? * 1e-6 * evals,
    ));

    // Jacobian (its times are a page of their own).
    push(
        &mut p,
        "## Mesh Jacobian\n\n`MeshTorques::mesh_jacobian` gives the outputs with their exact \
         partial derivatives ∂(M_F,p, M_F,g, M_D,p, M_D,g)/∂(φp, φg, φ̇p, φ̇g): at table \
         fidelity the derivative of the table's interpolant, at full fidelity the sensitivity \
         of the load solution at its loaded set (contact geometry, compliance interpolant and \
         Hertz radius all differentiated; nothing neglected). Both agree with central \
         differences of `evaluate` to better than 10⁻⁵ of each row (`tests/mesh_jacobian.rs`; \
         with profile modifications on both gears, whose separation moves with each contact's \
         roll position, to 3.6·10⁻⁷ of the row). One Jacobian costs about two evaluations (at \
         full fidelity one extra LU factorisation of the loaded set and four derivative blocks \
         of the compliance matrix); the measured times are the generated page \
         [docs/bench/jacobian.md](bench/jacobian.md) (`cargo run --release -p \
         helical-gear-app --example measure -- jacobian`).\n",
    );

    // Options.
    push(
        &mut p,
        "## Skip what a scene does not need\n\nFull fidelity, 200 slices; the saving against \
         the defaults (negative: extra cost) and the largest change of M_F,p.\n",
    );
    push(&mut p, "| option | work it skips | time per evaluation | saving | change of M_F,p |");
    push(&mut p, "| --- | --- | --- | --- | --- |");
    for o in list(bench, "options")? {
        let name = text(o, "option")?;
        let skips = if name.starts_with("defaults") {
            ""
        } else if name.starts_with("pressure") {
            "the Hertz pressure of each loaded slice (one square root)"
        } else if name.starts_with("damping") {
            "Eq. 14"
        } else if name.contains("detail") {
            "nothing: it adds the per-slice records"
        } else if name.contains("neighbour") {
            "nothing: it changes the model"
        } else {
            ""
        };
        p.push_str(&format!(
            "| {name} | {skips} | {} | {:+.1} % | {} |\n",
            time_us(num(o, "eval_us")?),
            num(o, "saving_percent")?,
            sci(num(o, "max_rel_change")?),
        ));
    }
    push(
        &mut p,
        "\n`fidelity = table` replaces the contact search, the compliance matrix and the load \
         solve by one Hermite lookup per call, and fewer `slices` save matrix entries (n²) and \
         factorisations (n³): both are in the mesh table above. The contact search outside the plane of \
         action is not an option: it is what excites the gears (the point of the paper). At \
         table fidelity the outputs read decide the work: the torques path (the mesh torques, \
         TE, the contact length, the friction torques and loss) interpolates 3 of the table's \
         13 node values (`table_eval_torques_ns` against `table_eval_ns` in the first table). \
         Python's `evaluate(..., outputs=...)` and the C API's `hgm_evaluate_outputs` \
         take it when only those are asked for, and the FMUs when a `fmi2GetReal` reads only \
         those (and a unit's own outputs) ([FMUs](fmus.md)).\n",
    );

    // Dynamics.
    push(
        &mut p,
        "## Dynamics\n\nThe run starts from the static equilibrium at 500 rad/s, near the main \
         resonance, and covers 30 mesh periods on the default table mesh. The error is that of \
         the maximum TE over the last five periods, sampled every T_m/16, against RK4 at 2048 \
         steps per mesh period. DOPRI5 controls its error in relative coordinates (φp, the \
         shaft twists, TE and their rates), so its tolerance bounds the TE error.\n",
    );
    push(&mut p, "| integrator | setting | run time | mesh evaluations | error of max TE |");
    push(&mut p, "| --- | --- | --- | --- | --- |");
    let dynamics = list(bench, "dynamics")?;
    for d in dynamics {
        let setting = num(d, "setting")?;
        let (name, setting) = if text(d, "integrator")? == "rk4" {
            let default = if setting == 128.0 { " (the default)" } else { "" };
            ("RK4", format!("{setting} steps per mesh period{default}"))
        } else {
            ("DOPRI5", format!("rtol {}", sci(setting)))
        };
        p.push_str(&format!(
            "| {name} | {setting} | {} | {} | {} |\n",
            time_us(num(d, "run_s")? * 1e6),
            count(num(d, "mesh_evaluations")?),
            sci(num(d, "max_te_rel_err")?),
        ));
    }
    push(&mut p, "");
    push(&mut p, "![Dynamics: error against run time](bench/bench_dynamics.png)");
    push(&mut p, "");
    let rk = |steps: f64| {
        dynamics.iter().find(|d| d["integrator"] == "rk4" && d["setting"].as_f64() == Some(steps))
    };
    let dp = |rtol: f64| {
        dynamics.iter().find(|d| {
            d["integrator"] == "dopri5"
                && d["setting"].as_f64().is_some_and(|s| (s / rtol - 1.0).abs() < 1e-9)
        })
    };
    if let (Some(r), Some(d)) = (rk(128.0), dp(1e-6)) {
        let (r_err, r_t) = (num(r, "max_te_rel_err")?, num(r, "run_s")?);
        let (d_err, d_t) = (num(d, "max_te_rel_err")?, num(d, "run_s")?);
        p.push_str(&format!(
            "On a smooth mesh, fixed-step RK4 on the mesh-period grid reaches {} at 128 steps per \
             mesh period ({} mesh evaluations, {}), DOPRI5 {} at rtol 10⁻⁶ ({} evaluations, {}); \
             the evaluation counts do not depend on the machine's load. DOPRI5 earns its cost \
             through impacts (separation and back-flank contact), where it shrinks the step by \
             10⁴ and more; see [Numerical robustness](robustness.md).\n\n",
            sci(r_err),
            count(num(r, "mesh_evaluations")?),
            time_us(r_t * 1e6),
            sci(d_err),
            count(num(d, "mesh_evaluations")?),
            time_us(d_t * 1e6),
        ));
    }

    // Paper run.
    push(&mut p, "## Paper run\n");
    match paper_s {
        Some(total) => {
            let mut stages: Vec<(String, f64)> = list(bench, "paper_stages")?
                .iter()
                .map(|s| Ok((text(s, "stage")?.to_string(), num(s, "seconds")?)))
                .collect::<Result<_, String>>()?;
            stages.sort_by(|a, b| b.1.total_cmp(&a.1));
            let largest: Vec<String> =
                stages.iter().take(5).map(|(n, s)| format!("{n} ({s:.1} s)")).collect();
            p.push_str(&format!(
                "{total:.1} s in total. The largest stages: {}. The per-stage times are in \
                 `bench.json` (`paper_stages`) and in each run's `summary.md`; what the run \
                 computes, and how it compares with the paper, is in \
                 [Validation](validation.md#the-paper-run-measured).\n\n",
                largest.join(", ")
            ));
        }
        None => push(&mut p, "Not timed in this report (`--no-paper`).\n"),
    }

    // Drive-line units.
    push(
        &mut p,
        "## The drive-line units and FMUs\n\nThe engine of the `HelicalGearDrive` FMU \
         (`DriveUnit`, in-process, as the C API's `hgm_unit_advance` runs it) on Table 1 at \
         532 rad/s from its static equilibrium, communication step H = 1e-4 s, the outputs read \
         after every step, table fidelity unless stated. The table build is paid once at \
         initialisation and not counted. The TE error is taken at the communication points \
         against the same unit at 1024 sub-steps per mesh period.\n",
    );
    push(
        &mut p,
        "| in-process, 532 rad/s, H = 1e-4 s | simulated time | simulated s per wall s | TE error |",
    );
    push(&mut p, "| --- | --- | --- | --- |");
    for u in list(bench, "drive_units")? {
        let fidelity = text(u, "fidelity")?;
        let steps = num(u, "steps_per_mesh_period")?;
        let integrator = match (text(u, "integrator")?, u.get("rtol").and_then(Value::as_f64)) {
            ("dopri5", Some(rtol)) => {
                format!("DOPRI5 rtol {rtol:.0e} (error control on TE and the twists)")
            }
            _ => {
                let default = if steps == 128.0 { " (the FMU default)" } else { "" };
                format!("RK4 {steps} sub-steps per mesh period{default}")
            }
        };
        let name = if fidelity == "table" {
            format!("table, {integrator}")
        } else {
            format!("full fidelity (200 slices), {integrator}")
        };
        let rate = num(u, "realtime_factor")?;
        let rate = if rate >= 0.1 { format!("{rate:.1}") } else { sci(rate) };
        p.push_str(&format!(
            "| {name} | {} s | {rate} | {} |\n",
            num(u, "simulated_s")?,
            u.get("te_rel_err").and_then(Value::as_f64).map_or("—".into(), sci),
        ));
    }
    push(
        &mut p,
        "\nSet `rk4_steps_per_mesh_period` to the smallest count whose TE error meets the job: \
         over a whole second the phase error of coarse grids accumulates. Finer sub-step counts, \
         DOPRI5 at rtol 1e-6 to 1e-9, and the full-fidelity Drive and Pair units with the warm \
         start carried or emptied every step are the generated page \
         [docs/bench/units.md](bench/units.md) (`cargo run --release -p helical-gear-app \
         --example measure -- units`); the error of each co-simulation cut is \
         [docs/bench/cosimulation.md](bench/cosimulation.md). Full fidelity is three to four \
         orders of magnitude slower: every communication step restarts the load solver cold so \
         that FMU states continue bit for bit. The Drive FMU repeats `helical-gear simulate` at \
         the same step (`tests/python/test_fmu_family.py`, ≤ 1e-6; bit for bit in \
         `tests/dynamics_unit.rs`). Through fmpy (`tests/python/bench_fmu_me.py`) the FMU adds \
         the importer's own cost per communication step; Model Exchange against Co-Simulation \
         is compared in [Model Exchange or \
         Co-Simulation](fmus.md#model-exchange-or-co-simulation).",
    );
    push(
        &mut p,
        "\n## Design studies\n\n`RAYON_NUM_THREADS=1 python python/bench/bench_study.py \
         --designs 6` measures a Latin hypercube over helix angle 8–20°, face width 10–20 mm \
         and tip relief 0.005–0.03·m_n, serially and on a Dask `LocalCluster`, with the cost of \
         each design's FE run, table build, static TE and sweep. The FE run and the table build \
         dominate a design. `RAYON_NUM_THREADS=1` keeps each design's FE run on one thread; \
         the table build splits its phase rows over every core the process's CPU affinity \
         allows (the script pins its serial run to one core), so two unpinned workers on two \
         cores run up to four threads while they build tables. See [the Python \
         guide](python.md).",
    );
    Ok(p)
}

/// A number of rad/s rounded to whole rad/s.
fn rad_s(v: f64) -> String {
    format!("{v:.0}")
}

/// `none`, or the interval `a … b` of a separation (rad/s).
fn interval(v: Option<&Value>) -> String {
    match v.and_then(Value::as_array) {
        Some(a) if a.len() == 2 => format!(
            "{} … {}",
            rad_s(a[0].as_f64().unwrap_or(f64::NAN)),
            rad_s(a[1].as_f64().unwrap_or(f64::NAN))
        ),
        _ => "none".into(),
    }
}

/// `+3 %`: the deviation of `model` from `paper` in whole per cent.
fn deviation(model: f64, paper: f64) -> String {
    let d = 100.0 * (model / paper - 1.0);
    if d < 0.0 { format!("−{:.0} %", -d) } else { format!("+{d:.0} %") }
}

/// Renders the section "The paper run, measured" of `docs/validation.md` (the lines between
/// [`PAPER_BEGIN`] and [`PAPER_END`], without them) from a paper run's `summary.json`.
pub fn paper_section(summary: &Value) -> Result<String, String> {
    let mut p = String::new();
    let ste = num(summary, "ste_max_um")?;
    let w = num(summary, "omega_crit_rad_s")?;
    let (w2, w3) = (num(summary, "omega_crit_2_rad_s")?, num(summary, "omega_crit_3_rad_s")?);
    p.push_str(&format!(
        "`cargo run --release -- paper --out paper-run` (Table 1, {} slices, dynamics on the {} \
         fidelity). The tables below are rendered from the summary of such a run, checked in as \
         [docs/paper/summary.json](paper/summary.json) (with its \
         [summary.md](paper/summary.md), which adds the sweeps, the waterfalls, the tip-contact \
         margins, the assumptions and the stage times); that run took {:.0} s{}, and the paper \
         run's time on the benchmark's machine is in [Performance](performance.md#paper-run).\n\n",
        num(summary, "slices")?,
        text(summary, "fidelity_dynamics")?,
        num(summary, "runtime_s")?,
        summary["peak_memory_mb"].as_f64().map_or(String::new(), |mb| format!(
            " with a peak resident memory of {mb:.0} MB (the run's own process; a `cargo run` \
             that compiles first peaks higher, in the compiler)"
        )),
    ));
    // The smallest TE_min/STE_max of the d_mesh = 100 sweep, where it is.
    let sweeps = list(summary, "sweeps")?;
    let d100 = sweeps
        .iter()
        .find(|s| s["d_mesh_n_s_per_m"].as_f64() == Some(100.0))
        .ok_or("the summary has no sweep at d_mesh = 100 N·s/m")?;
    let (w_min, te_min) = list(d100, "rows")?
        .iter()
        .filter_map(|r| Some((r["omega_p_rad_s"].as_f64()?, r["te_min_over_ste_max"].as_f64()?)))
        .fold((f64::NAN, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    let sep100 = match summary.get("separation_d100_rad_s") {
        Some(Value::Array(_)) => interval(summary.get("separation_d100_rad_s")),
        _ => format!("none (smallest TE_min/STE_max {te_min:.3} at {} rad/s)", rad_s(w_min)),
    };
    let yes_no = |path: &str| -> Result<&str, String> {
        field(summary, path)?
            .as_bool()
            .map(|b| if b { "yes" } else { "no" })
            .ok_or_else(|| format!("report field `{path}` is not a boolean"))
    };
    p.push_str("| quantity | paper | this model |\n| --- | --- | --- |\n");
    p.push_str(&format!(
        "| max static TE, 100 N·m | {PAPER_STE_MAX_UM} µm | {ste:.1} µm ({}) |\n",
        deviation(ste, PAPER_STE_MAX_UM)
    ));
    p.push_str(&format!(
        "| main resonance ω_crit | {PAPER_OMEGA_CRIT:.0} rad/s | {} rad/s ({}) |\n",
        rad_s(w),
        deviation(w, PAPER_OMEGA_CRIT)
    ));
    p.push_str(&format!(
        "| second, third resonance | 330, 220 rad/s (ω_crit/2, ω_crit/3) | {}, {} rad/s \
         ({:.3}·ω_crit, {:.3}·ω_crit) |\n",
        rad_s(w2),
        rad_s(w3),
        w2 / w,
        w3 / w
    ));
    p.push_str(&format!(
        "| separation, d_mesh = 100 N·s/m | an interval near ω_crit | {sep100} |\n"
    ));
    p.push_str(&format!(
        "| separation, d_mesh = 200 N·s/m | none | {} |\n",
        interval(summary.get("separation_d200_rad_s"))
    ));
    p.push_str(&format!(
        "| tip rounding in contact, static | no | {} |\n",
        yes_no("tip_rounding_contact_static")?
    ));
    p.push_str(&format!(
        "| tip rounding in contact at 570 rad/s | yes | {} |\n",
        yes_no("tip_rounding_contact_570")?
    ));
    p.push_str(&format!(
        "| tip rounding in contact at ω_crit·570/660 | yes (570 rad/s) | {} ({} rad/s) |\n\n",
        yes_no("tip_rounding_contact_equivalent")?,
        rad_s(num(summary, "omega_equivalent_570_rad_s")?)
    ));
    p.push_str(
        "Sensitivity (short sweeps at d_mesh = 100 N·s/m centred on ω_crit·ω_lin/ω_lin,default; \
         ω_lin the linearised natural frequency, k the linearised mesh stiffness at φp = 0; J_p, \
         J_g as multiples of the default's):\n\n\
         | case | J_p, J_g | ω_crit (rad/s) | ω_lin (rad/s) | k (N/µm) | STE max (µm) | peak \
         TE_max/STE_max | separation d = 100 | separation d = 200 |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let cases = list(summary, "sensitivity")?;
    let first = cases.first().ok_or("the summary has no sensitivity case")?;
    let (jp0, jg0) = (num(first, "j_p_kgm2")?, num(first, "j_g_kgm2")?);
    for c in cases {
        let d200 = if c["d200_swept"].as_bool() == Some(true) {
            interval(c.get("separation_d200_rad_s"))
        } else {
            "—".into()
        };
        p.push_str(&format!(
            "| {} | ×{:.2}, ×{:.2} | {} | {} | {:.1} | {:.1} | {:.2} | {} | {d200} |\n",
            text(c, "case")?,
            num(c, "j_p_kgm2")? / jp0,
            num(c, "j_g_kgm2")? / jg0,
            rad_s(num(c, "omega_crit_rad_s")?),
            rad_s(num(c, "omega_linear_rad_s")?),
            num(c, "mesh_stiffness_n_per_um")?,
            num(c, "ste_max_um")?,
            num(c, "peak_te_max_over_ste_max")?,
            interval(c.get("separation_d100_rad_s")),
        ));
    }
    Ok(p)
}

/// The argument the paper run writes from its own numbers into its `summary.md`, section
/// "Deviations beyond 10 % from the paper", as a subsection of the generated paper-run
/// section (a blank line, its heading one level lower, its text verbatim). An error says that
/// the summary has no such section.
pub fn deviations_section(summary_md: &str) -> Result<String, String> {
    const HEADING: &str = "## Deviations beyond 10 % from the paper";
    let start = summary_md
        .find(HEADING)
        .ok_or_else(|| format!("docs/paper/summary.md has no section `{HEADING}`"))?;
    let body = &summary_md[start + HEADING.len()..];
    let end = body.find("\n## ").map_or(body.len(), |i| i + 1);
    Ok(format!("\n#{HEADING}\n\n{}\n", body[..end].trim()))
}

/// `page` with the lines between the line `begin` and the line `end` replaced by `body`
/// (which should end in a newline); an error names a missing marker.
pub fn replace_section(page: &str, begin: &str, end: &str, body: &str) -> Result<String, String> {
    let start =
        page.find(begin).ok_or_else(|| format!("the page has no marker `{begin}`"))? + begin.len();
    let stop =
        page[start..].find(end).ok_or_else(|| format!("the page has no marker `{end}`"))? + start;
    Ok(format!("{}\n{}{}", &page[..start], body, &page[stop..]))
}

/// The generated pages of the repository at `root`, rendered from its checked-in reports:
/// `(path, content)` for `docs/performance.md` (from `docs/bench/bench.json`) and
/// `docs/validation.md` (its current text with the paper-run section rendered from
/// `docs/paper/summary.json`). Errors name the file that cannot be read or parsed.
pub fn rendered_pages(root: &std::path::Path) -> Result<Vec<(std::path::PathBuf, String)>, String> {
    let read = |rel: &str| {
        let path = root.join(rel);
        std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
    };
    let json = |rel: &str| -> Result<Value, String> {
        serde_json::from_str(&read(rel)?).map_err(|e| format!("{rel} is not JSON: {e}"))
    };
    let performance = performance_page(&json("docs/bench/bench.json")?)?;
    let mut section = paper_section(&json("docs/paper/summary.json")?)?;
    section.push_str(&deviations_section(&read("docs/paper/summary.md")?)?);
    let validation =
        replace_section(&read("docs/validation.md")?, PAPER_BEGIN, PAPER_END, &section)?;
    Ok(vec![
        (root.join("docs/performance.md"), performance),
        (root.join("docs/validation.md"), validation),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_compactly() {
        assert_eq!(sci(2.7595e-4), "2.8·10⁻⁴");
        assert_eq!(sci(0.687), "0.69");
        assert_eq!(sci(1e-8), "1.0·10⁻⁸");
        assert_eq!(time_us(0.0685), "68.5 ns");
        assert_eq!(time_us(595.9), "596 µs");
        assert_eq!(time_us(2500.3), "2.50 ms");
        assert_eq!(count(180_481.0), "180 481");
        assert_eq!(deviation(31.4, 30.5), "+3 %");
        assert_eq!(deviation(532.0, 660.0), "−19 %");
    }

    #[test]
    fn sections_are_replaced_between_their_markers() {
        let page = "a\nB\nold\nE\nz\n";
        assert_eq!(replace_section(page, "B", "E", "new\n").unwrap(), "a\nB\nnew\nE\nz\n");
        assert!(replace_section(page, "X", "E", "").unwrap_err().contains("`X`"));
    }
}
