//! `docs/parameters.md`: the designer's parameter reference, one row per key of the gear pair,
//! the drive line, the mesh options and the modifications, with its name at every interface.
//!
//! Each row is read from the code that owns it, so the page cannot drift from it:
//! * the keys, units and ranges of the numeric gear-pair and drive-line parameters from
//!   [`helical_gear_mesh::params::parameter_bounds`] (the `Bounds` constants the checks use);
//! * the defaults from the serialised [`GearPair::paper_table1`] and
//!   [`DriveLine::paper_table1`];
//! * the FMI names, the models that carry them and the meanings from the FMU variable tables
//!   ([`MODELS`]);
//! * the Python keyword aliases from `ISO_SYMBOLS` and `DRIVE_SYMBOLS` of
//!   `python/helical_gear/_pair.py` (read from that file);
//! * the modification keys from the serde schema of [`Modifications`] (every leaf key must
//!   have its row in [`MODIFICATIONS`], or the generation fails).
//!
//! What the code does not state as data is written here once: the ISO 21771 / ISO 6336 symbol
//! of each key ([`ISO_SYMBOLS`]), the mesh options' command-line flags and Python keywords
//! ([`MESH_OPTIONS`]), the modifications' ranges and meanings (the rules of
//! `Modifications::validate`) and the quantities that are not inputs.

use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::MODELS;
use helical_gear_mesh::fmi2::variables::{Variable, format_real};
use helical_gear_mesh::params::modifications::{DeviationMap, Modifications};
use helical_gear_mesh::params::{DriveLine, GearPair, parameter_bounds};

use crate::workspace_root;

/// Path of the page, relative to the workspace root.
pub const PAGE: &str = "docs/parameters.md";

/// The Python file whose `ISO_SYMBOLS` and `DRIVE_SYMBOLS` give the keyword aliases.
pub const PYTHON_PAIR: &str = "python/helical_gear/_pair.py";

/// ISO 21771 / ISO 6336 symbol (or the paper's, for the drive line and d_mesh) of each key.
pub const ISO_SYMBOLS: &[(&str, &str)] = &[
    ("z_p", "z₁"),
    ("z_g", "z₂"),
    ("normal_module_m", "m_n"),
    ("pressure_angle_rad", "α_n"),
    ("helix_angle_rad", "β"),
    ("face_width_m", "b"),
    ("profile_shift_p", "x₁"),
    ("profile_shift_g", "x₂"),
    ("addendum_mn", "h_aP/m_n"),
    ("dedendum_mn", "h_fP/m_n"),
    ("rack_fillet_radius_mn", "ρ_fP/m_n"),
    ("tip_relief_depth_mn", "C_a/m_n (paper: δ)"),
    ("tip_relief_height_mn", "h_Ca/m_n (paper: H)"),
    ("tip_rounding_radius_mn", "ρ_aP/m_n"),
    ("normal_backlash_mn", "j_n/m_n"),
    ("bore_diameter_m", "d_bore"),
    ("material_p.youngs_modulus_pa", "E₁"),
    ("material_p.poisson_ratio", "ν₁"),
    ("material_p.density_kg_m3", "ρ₁"),
    ("material_g.youngs_modulus_pa", "E₂"),
    ("material_g.poisson_ratio", "ν₂"),
    ("material_g.density_kg_m3", "ρ₂"),
    ("d_mesh_n_s_per_m", "d_mesh (Eq. 14)"),
    ("drive.torque_nm", "M (Eq. 4)"),
    ("drive.j1_kgm2", "J₁"),
    ("drive.j2_kgm2", "J₂"),
    ("drive.c1_nm_per_rad", "c₁"),
    ("drive.c2_nm_per_rad", "c₂"),
    ("drive.d1_nms_per_rad", "d₁"),
    ("drive.d2_nms_per_rad", "d₂"),
];

/// The mesh options: FMI name, command-line flag, Python keyword (of `MeshModel` and the
/// calls that build one). "—" where the interface does not offer it.
pub const MESH_OPTIONS: &[(&str, &str, &str)] = &[
    (
        "fidelity",
        "`--fidelity full|table` (`simulate`, `sweep`)",
        "`fidelity=\"full\"` or `\"table\"`",
    ),
    ("slices", "`--slices N` (`contact`, `static`)", "`slices=`"),
    (
        "compliance_model",
        "`--compliance interpolated|fitted|winkler` (`static`)",
        "— (interpolated)",
    ),
    ("neighbour_coupling", "—", "—"),
    ("compute_pressure", "—", "—"),
    ("table_phase_points", "—", "`table_size=(phase, te)`"),
    ("table_te_points", "—", "`table_size=(phase, te)`"),
    ("table_design_torque_nm", "— (the drive line's torque)", "`table_design_torque=`"),
    ("table_slices", "—", "`table_slices=`"),
    (
        "friction",
        "`--friction FILE\\|none` (`static`, `simulate`, `sweep`, `spectrum --dynamic`)",
        "`friction=` (dict, JSON text or None)",
    ),
];

/// The modification keys below `modifications.<gear>.` (and `mesh_misalignment_m` of the
/// pair): leaf key, ISO symbol, unit, range (the rules of `Modifications::validate`), meaning.
pub const MODIFICATIONS: &[(&str, &str, &str, &str, &str)] = &[
    (
        "mesh_misalignment_m",
        "f_ma",
        "m",
        "\\|value\\| ≤ 0.1·m_n",
        "Equivalent mesh misalignment in the plane of action: extra separation at the ζ = b face \
         end relative to the ζ = 0 end (positive opens the ζ = b end); one per pair",
    ),
    (
        "lead_crowning_m",
        "C_β",
        "m",
        "[0, 0.1·m_n]",
        "Lead crowning: separation at each face end relative to mid-face",
    ),
    (
        "helix_slope_m",
        "f_Hβ",
        "m",
        "\\|value\\| ≤ 0.1·m_n",
        "Helix slope modification or deviation: separation at ζ = b relative to ζ = 0",
    ),
    (
        "end_relief.amount_start_m",
        "C_I",
        "m",
        "[0, 0.1·m_n]; 0 unless `length_start_m` > 0",
        "End relief at the ζ = 0 face end",
    ),
    (
        "end_relief.length_start_m",
        "b_I",
        "m",
        "[0, b]",
        "Length of the end-relief zone at the ζ = 0 end",
    ),
    (
        "end_relief.amount_end_m",
        "C_II",
        "m",
        "[0, 0.1·m_n]; 0 unless `length_end_m` > 0",
        "End relief at the ζ = b face end",
    ),
    (
        "end_relief.length_end_m",
        "b_II",
        "m",
        "[0, b − `length_start_m`]",
        "Length of the end-relief zone at the ζ = b end",
    ),
    (
        "end_relief.shape",
        "",
        "",
        "`\"linear\"` or `\"parabolic\"`",
        "Shape of both end reliefs (amount·t or amount·t²)",
    ),
    (
        "profile_crowning_m",
        "C_α",
        "m",
        "[0, 0.1·m_n]",
        "Profile crowning: separation at both ends of the active profile relative to its middle",
    ),
    (
        "profile_slope_m",
        "f_Hα",
        "m",
        "\\|value\\| ≤ 0.1·m_n",
        "Profile slope modification or deviation: separation at the tip end of the active \
         profile relative to its start",
    ),
    (
        "tip_relief.amount_m",
        "C_a",
        "m",
        "[0, 0.1·m_n]",
        "Tip relief given on this gear (on top of the basic rack's) at its tip circle",
    ),
    (
        "tip_relief.start_diameter_m",
        "d_Ca",
        "m",
        "(d_b, d_a) of this gear when `amount_m` > 0",
        "Diameter where that tip relief starts",
    ),
    (
        "tip_relief.shape",
        "",
        "",
        "`\"linear\"` or `\"parabolic\"`",
        "Shape of that tip relief in roll length",
    ),
    (
        "pitch_deviations_m",
        "e_i",
        "m",
        "empty, or exactly z values, each \\|e_i\\| ≤ 0.1·m_n",
        "Position deviation of the flank of each tooth (single pitch deviations f_pt,i = e_i − \
         e_i−1)",
    ),
    (
        "runout_m",
        "e",
        "m",
        "[0, 0.1·m_n]",
        "Eccentricity: tooth i moves by e·cos(2π·i/z − ψ) along the line of action",
    ),
    ("runout_phase_rad", "ψ", "rad", "finite", "Phase of the eccentricity"),
    (
        "deviation_map.roll_length_m",
        "L",
        "m",
        "≥ 2 values, strictly increasing",
        "Roll lengths √(r² − r_b²) of the rows of a measured deviation map",
    ),
    (
        "deviation_map.face_m",
        "z",
        "m",
        "≥ 2 values, strictly increasing",
        "Axial positions of its columns from the ζ = 0 face end",
    ),
    (
        "deviation_map.values_m",
        "",
        "m",
        "rows × columns, each \\|value\\| ≤ 0.1·m_n",
        "Deviation at each node (positive removes material), interpolated bilinearly, constant \
         outside the grid",
    ),
];

/// Reads a Python `Mapping` literal `NAME: … = MappingProxyType({ "a": "b", … })` from
/// `text`: the pairs (alias, key).
fn python_aliases(text: &str, name: &str) -> Result<Vec<(String, String)>, String> {
    let start =
        text.find(&format!("\n{name}:")).ok_or_else(|| format!("{PYTHON_PAIR}: no `{name}`"))?;
    let body = &text[start..];
    let open = body.find('{').ok_or_else(|| format!("{PYTHON_PAIR}: `{name}` has no {{"))?;
    let close = body.find('}').ok_or_else(|| format!("{PYTHON_PAIR}: `{name}` has no }}"))?;
    let mut out = Vec::new();
    for item in body[open + 1..close].split(',') {
        let item = item.trim();
        if item.is_empty() {
            continue;
        }
        let (a, k) = item
            .split_once(':')
            .ok_or_else(|| format!("{PYTHON_PAIR}: `{name}` entry `{item}` is not \"a\": \"b\""))?;
        let unquote = |s: &str| s.trim().trim_matches('"').to_string();
        out.push((unquote(a), unquote(k)));
    }
    Ok(out)
}

/// The value at a dotted `key` of a JSON object.
fn json_at<'a>(v: &'a serde_json::Value, key: &str) -> Option<&'a serde_json::Value> {
    key.split('.').try_fold(v, |v, k| v.get(k))
}

/// The leaf keys of a JSON object, dotted, in schema order.
fn leaf_keys(v: &serde_json::Value, prefix: &str, out: &mut Vec<String>) {
    if let serde_json::Value::Object(m) = v {
        for (k, x) in m {
            let key = format!("{prefix}{k}");
            if x.is_object() {
                leaf_keys(x, &format!("{key}."), out);
            } else {
                out.push(key);
            }
        }
    }
}

/// The FMI variable named `name` in the first model that has it, and the models that have it.
fn fmi(name: &str) -> Option<(&'static Variable, Vec<&'static ModelInfo>)> {
    let models: Vec<&'static ModelInfo> =
        MODELS.iter().copied().filter(|m| m.by_name(name).is_some()).collect();
    models.first().and_then(|m| m.by_name(name)).map(|v| (v, models))
}

/// Markdown cell text: `|` escaped, `*` escaped.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('*', "\\*")
}

/// A bound as the error messages write it (plain or exponent form).
fn bound(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) { format_real(x) } else { format!("{x:e}") }
}

/// A default value from the JSON of the Table 1 pair or drive line.
fn default_cell(v: Option<&serde_json::Value>) -> String {
    match v {
        Some(serde_json::Value::Number(n)) => n
            .as_f64()
            .map_or_else(|| n.to_string(), |x| if n.is_f64() { bound(x) } else { n.to_string() }),
        Some(x) => x.to_string(),
        None => String::new(),
    }
}

/// The short name of a model in the tables: `Mesh`, `Pair`, `Stage`, `Drive`, `Gearbox`.
fn short_name(m: &ModelInfo) -> &'static str {
    match m.identifier.strip_prefix("HelicalGear") {
        Some(s) if s.starts_with(char::is_uppercase) => s,
        _ => m.identifier.trim_start_matches("Helical"),
    }
}

fn models_cell(models: &[&ModelInfo]) -> String {
    if models.len() == MODELS.len() {
        "every model".to_string()
    } else {
        models.iter().map(|m| short_name(m)).collect::<Vec<_>>().join(", ")
    }
}

/// The page `docs/parameters.md`.
pub fn parameters_page() -> Result<String, String> {
    let py_path = workspace_root().join(PYTHON_PAIR);
    let py = std::fs::read_to_string(&py_path)
        .map_err(|e| format!("reading {}: {e}", py_path.display()))?;
    let iso = python_aliases(&py, "ISO_SYMBOLS")?;
    let drive_aliases = python_aliases(&py, "DRIVE_SYMBOLS")?;
    let pair_json = serde_json::to_value(GearPair::paper_table1()).map_err(|e| e.to_string())?;
    let drive_json = serde_json::to_value(DriveLine::paper_table1()).map_err(|e| e.to_string())?;

    let mut pair_rows = String::new();
    let mut drive_rows = String::new();
    for (key, min, max, unit) in parameter_bounds() {
        let symbol = ISO_SYMBOLS
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, s)| *s)
            .ok_or_else(|| format!("no ISO symbol for `{key}` in ISO_SYMBOLS"))?;
        let fmi_name = if key == "d_mesh_n_s_per_m" { "d_mesh".to_string() } else { key.clone() };
        let (var, models) =
            fmi(&fmi_name).ok_or_else(|| format!("`{key}`: no FMI variable `{fmi_name}`"))?;
        let integer = matches!(key.as_str(), "z_p" | "z_g");
        let range = if integer {
            format!("[{}, {}]", min as i64, max as i64)
        } else {
            format!("[{}, {}]", bound(min), bound(max))
        };
        let unit = if unit.is_empty() { "—".to_string() } else { unit.to_string() };
        if let Some(field) = key.strip_prefix("drive.") {
            let alias: Vec<String> = drive_aliases
                .iter()
                .filter(|(_, k)| k == field)
                .map(|(a, _)| format!("`{a}`"))
                .collect();
            let python = std::iter::once(format!("`{field}`")).chain(alias).collect::<Vec<_>>();
            drive_rows.push_str(&format!(
                "| `{field}` | `{fmi_name}` ({}) | {} | {} | {unit} | {} | {range} | {} |\n",
                models_cell(&models),
                python.join(" or "),
                cell(symbol),
                default_cell(json_at(&drive_json, field)),
                cell(var.description),
            ));
        } else {
            let python = match key.split_once('.') {
                Some((group, sub)) => format!("`{group}={{\"{sub}\": …}}`"),
                None => {
                    let alias: Vec<String> = iso
                        .iter()
                        .filter(|(_, k)| *k == key)
                        .map(|(a, _)| format!("`{a}`"))
                        .collect();
                    std::iter::once(format!("`{key}`"))
                        .chain(alias)
                        .collect::<Vec<_>>()
                        .join(" or ")
                }
            };
            pair_rows.push_str(&format!(
                "| `{key}` | `{fmi_name}` | {python} | {} | {unit} | {} | {range} | {} |\n",
                cell(symbol),
                default_cell(json_at(&pair_json, &key)),
                cell(var.description),
            ));
        }
    }
    // Every Python alias names a key of the page.
    for (alias, key) in iso.iter().chain(&drive_aliases) {
        let known = parameter_bounds()
            .iter()
            .any(|(k, ..)| k == key || k.strip_prefix("drive.") == Some(key.as_str()));
        if !known {
            return Err(format!("{PYTHON_PAIR}: alias `{alias}` names `{key}`, not a parameter"));
        }
    }

    let mut option_rows = String::new();
    for (name, cli, python) in MESH_OPTIONS {
        let (v, models) =
            fmi(name).ok_or_else(|| format!("mesh option `{name}`: no FMI variable"))?;
        // The start value in each model that carries it; models with another start are named.
        let mut starts: Vec<(String, Vec<&str>)> = Vec::new();
        for m in &models {
            let s = m.by_name(name).and_then(|w| m.start(w)).unwrap_or_default();
            let id = short_name(m);
            match starts.iter_mut().find(|(x, _)| *x == s) {
                Some((_, ids)) => ids.push(id),
                None => starts.push((s, vec![id])),
            }
        }
        let default = if starts.len() == 1 {
            starts[0].0.clone()
        } else {
            starts
                .iter()
                .map(|(s, ids)| format!("{s} ({})", ids.join(", ")))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let range = match (v.min, v.max) {
            (Some(a), Some(b)) => format!("[{}, {}]", bound(a), bound(b)),
            _ => "true / false".to_string(),
        };
        option_rows.push_str(&format!(
            "| `{name}` ({}) | {} | {} | {default} | {range} | {} |\n",
            models_cell(&models),
            cell(cli),
            cell(python),
            cell(v.description),
        ));
    }

    // The modification keys from the schema, each with its row.
    let full = Modifications {
        pinion: helical_gear_mesh::params::modifications::FlankModification {
            deviation_map: Some(DeviationMap::default()),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut keys = Vec::new();
    leaf_keys(&serde_json::to_value(&full).map_err(|e| e.to_string())?, "", &mut keys);
    for key in keys.iter().filter(|k| !k.starts_with("gear.")) {
        let leaf = key.strip_prefix("pinion.").unwrap_or(key);
        if !MODIFICATIONS.iter().any(|(k, ..)| *k == leaf) {
            return Err(format!("modification key `{key}` has no row in MODIFICATIONS"));
        }
    }
    let mut mod_rows = String::new();
    for (leaf, sym, unit, range, meaning) in MODIFICATIONS {
        let per_gear = keys.iter().any(|k| k.strip_prefix("pinion.") == Some(leaf));
        let path = if per_gear {
            format!("`modifications.pinion.{leaf}`, `modifications.gear.{leaf}`")
        } else {
            format!("`modifications.{leaf}`")
        };
        let unit = if unit.is_empty() { "—" } else { unit };
        let sym = if sym.is_empty() { "—" } else { sym };
        mod_rows.push_str(&format!("| {path} | {sym} | {unit} | {range} | {meaning} |\n"));
    }
    for (k, ..) in MODIFICATIONS {
        if !keys.iter().any(|key| key == k || key.strip_prefix("pinion.") == Some(k)) {
            return Err(format!("MODIFICATIONS row `{k}` is not a key of the schema"));
        }
    }

    Ok(format!(
        "{GENERATED}\n\n\
         # Parameters\n\n\
         Every parameter a gear designer enters, with its name at every interface: the key of \
         the gear-pair JSON (`--params FILE` of the command line, `GearPair.from_json` in \
         Python, `hgm_create_from_json` in C; nested keys joined by a dot), the FMI parameter \
         of the FMUs, the Python keyword of `GearPair(...)` (the JSON key or its ISO alias), the \
         ISO 21771 / ISO 6336 symbol, the unit, the default (Table 1 of the paper, and what \
         the paper does not give as assumed in every run summary) and the range every \
         interface checks (inclusive; an error names the key, the value and the range). A \
         value inside its range may still be refused in combination with others (undercut, \
         pointed tooth, tip interference, contact ratio below 1, a bore outside the root \
         circle): the error then names the parameter to change and the limit. Every key is \
         optional: a missing one takes its default, so `{{\"helix_angle_rad\": 0.2}}` is \
         Table 1 with β = 0.2 rad.\n\n\
         SI units inside: m, rad, Pa, kg/m3, N.m, N.s/m; the basic-rack quantities (keys ending \
         `_mn`) are in units of the normal module m_n. The same names in the FMUs' variable \
         tables: [fmu/parameters.md](fmu/parameters.md).\n\n\
         ## Gear pair\n\n\
         | JSON key | FMI | Python keyword | ISO symbol | unit | default | range | meaning |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n\
         {pair_rows}\n\
         ### What cannot be entered, and how to reach it\n\n\
         * **Centre distance**: not an input. It is the zero-backlash operating centre distance \
         of the profile shifts: a = (z₁ + z₂)·m_n/(2·cos β)·cos α_t/cos α_wt with inv α_wt = \
         inv α_t + 2·tan α_n·(x₁ + x₂)/(z₁ + z₂). Reach a given centre distance through the sum \
         of the profile shifts `profile_shift_p` + `profile_shift_g`; `helical-gear geometry` \
         (and Python `geometry(pair)`) prints the result as `center_distance_m`. The backlash \
         `normal_backlash_mn` thins the teeth and does not move the centres.\n\
         * **Tip diameter**: not an input. d_a = d + 2·(x + h_aP/m_n)·m_n for each gear, with the \
         one basic rack of both gears: reach it through `addendum_mn` (both gears) and the \
         profile shift of that gear (printed as `tip_radius_p_m`, `tip_radius_g_m`). There is no \
         tip shortening.\n\
         * **Separate face widths**: not available. `face_width_m` is the face width of both \
         gears and the length of the contact lines; a wider gear's overhanging face is not \
         modelled.\n\
         * **Separate bores**: not available. `bore_diameter_m` is the hub bore of both gears, \
         where both FE models are fixed.\n\
         * **Separate basic racks**: not available; the rack (`addendum_mn`, `dedendum_mn`, \
         `rack_fillet_radius_mn`, tip relief and rounding) is shared. A tip relief of one gear \
         only is `modifications.<gear>.tip_relief` (below).\n\
         * **Separate materials**: available (`material_p`, `material_g`).\n\n\
         ### What `d_mesh` multiplies\n\n\
         The damping of Eq. 14 is a viscous force along the plane of action, \
         f_D = d_mesh·(ω_p·g_p + ω_g·g_g)·E, with the rate of the transmission error \
         ω_p·g_p + ω_g·g_g in m/s and E = Σ(ζ_e − ζ_b) the loaded axial extent of all \
         contact lines in contact, **in units of m_n** (dimensionless); the damping torques are \
         M_D,p = f_D·g_p and M_D,g = f_D·g_g. So `d_mesh` in N·s/m is the damping force per m/s \
         of TE rate for each normal module of loaded axial extent: a viscous coefficient of \
         d_mesh/m_n N·s/m per metre of loaded face width, not the total coefficient of the \
         mesh. The total is d_mesh·E, and E changes over the mesh cycle; the paper run's \
         sensitivity study has a row for the other reading (d_mesh as the total coefficient, \
         [validation.md](validation.md#the-paper-run-measured)). In the FMUs it is `d_mesh`, the \
         one tunable parameter.\n\n\
         ## Drive line\n\n\
         Not part of the gear pair: its own JSON object (`--drive FILE`, Python \
         `DriveLine(...)` passed as `drive=`, C `drive_json`); in the FMUs the `drive.*` \
         parameters of the models that use them (the models in brackets).\n\n\
         | JSON key | FMI | Python keyword (`DriveLine`) | symbol | unit | default | range | meaning |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n\
         {drive_rows}\n\
         ## Mesh options\n\n\
         How the mesh is evaluated, not what the gears are: FMU parameters (the models in \
         brackets), command-line flags and Python keywords of `MeshModel` and the calls that \
         build one.\n\n\
         | FMI | command line | Python | default | range | meaning |\n\
         | --- | --- | --- | --- | --- | --- |\n\
         {option_rows}\n\
         ## Modifications\n\n\
         The `modifications` object of the gear-pair JSON (in the FMUs the String parameter \
         `modifications` holds the same JSON object; in Python `modifications={{\"pinion\": \
         {{…}}}}`): every key optional, missing means zero. Lengths in m along the transverse \
         line of action, positive removes material; ζ runs over the face from 0 to b. Signs, \
         formulas and examples: [modifications.md](modifications.md).\n\n\
         | JSON key | ISO symbol | unit | range | meaning |\n\
         | --- | --- | --- | --- | --- |\n\
         {mod_rows}"
    ))
}

/// The first line of the page.
const GENERATED: &str = "<!-- generated from the Rust sources and python/helical_gear/_pair.py \
                         by `cargo run -p fmu-build -- --write-generated`; do not edit -->";
