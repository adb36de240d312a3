"""The `helical_gear` Python package (built from python/ by test.sh into .venv): the gear-pair
value, errors across the boundary, the vectorised mesh evaluation against the C API (an
independent build of the same library) bit for bit, the static TE against the CLI, pickling,
and design studies: serial against a two-process Dask LocalCluster, error rows, the FE counted
once per compliance key, and a study killed midway and resumed."""

import ctypes
import json
import math
import os
import pickle
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

hg = pytest.importorskip("helical_gear")
pd = pytest.importorskip("pandas")

from conftest import RELEASE, ROOT  # noqa: E402

FAST_SWEEP = dict(sweep=(300.0, 900.0, 3), refine_runs=0, static_points=8, max_periods=400,
                  slices=80, table_size=(16, 12))


# ---------------------------------------------------------------------------------------------
# GearPair and errors


def test_gear_pair_defaults_round_trip_and_pickle():
    p = hg.GearPair()
    assert p.z_p == 30 and p.z_g == 47
    assert p.helix_angle_rad == pytest.approx(math.radians(10.0), rel=0, abs=1e-15)
    assert hg.DriveLine().torque_nm == 100.0
    assert p.beta == p.helix_angle_rad and p.m_n == p.normal_module_m  # ISO symbols
    assert hg.GearPair.from_json(p.to_json()) == p
    assert pickle.loads(pickle.dumps(p)) == p
    q = p.replace(beta=0.2, **{"material_g.poisson_ratio": 0.29})
    assert (q.helix_angle_rad, q.material_g.poisson_ratio, q.z_p) == (0.2, 0.29, 30)
    assert hg.GearPair(material_g={"poisson_ratio": 0.29}, helix_angle_rad=0.2) == q
    assert q.flat()["material_g.poisson_ratio"] == 0.29
    assert hash(q) == hash(hg.GearPair.from_json(q.to_json()))
    with pytest.raises(AttributeError):
        p.z_p = 31


def test_drive_line_defaults_partial_replace_and_pickle():
    d = hg.DriveLine()
    assert (d.torque_nm, d.j1_kgm2, d.c2_nm_per_rad, d.d1_nms_per_rad) == (100.0, 0.62, 984.0, 0.04)
    q = d.replace(torque_nm=50.0)
    assert (q.torque_nm, q.j1_kgm2) == (50.0, 0.62)
    assert hg.DriveLine(T1=50.0) == q == hg.DriveLine.from_json('{"torque_nm": 50}')
    assert json.loads(q.to_json())["torque_nm"] == 50.0
    assert hg.DriveLine.from_json(q.to_json()) == q
    assert pickle.loads(pickle.dumps(q)) == q and hash(q) == hash(hg.DriveLine(torque_nm=50.0))
    with pytest.raises(AttributeError):
        q.torque_nm = 1.0
    with pytest.raises(hg.ParameterError, match="unknown field `torque`"):
        hg.DriveLine(torque=1.0)
    with pytest.raises(hg.ParameterError, match="drive.j1_kgm2"):
        hg.DriveLine(j1_kgm2=0.0)
    with pytest.raises(hg.ParameterError, match="must be an object"):
        hg.DriveLine.from_json("[]")


def test_pair_with_drive_is_refused_pointing_to_drive_line():
    """The drive line is not part of the pair: a `drive` key names where it goes now."""
    for bad in (lambda: hg.GearPair(drive={"torque_nm": 50.0}),
                lambda: hg.GearPair(**{"drive.torque_nm": 50.0}),
                lambda: hg.GearPair.from_json('{"drive": {}}')):
        with pytest.raises(hg.ParameterError) as e:
            bad()
        msg = str(e.value)
        assert "drive=" in msg and "--drive" in msg and "unknown field" not in msg, msg


def test_invalid_parameters_raise_the_library_message():
    with pytest.raises(hg.ParameterError) as e:
        hg.GearPair(face_width_m=-0.01)
    assert isinstance(e.value, hg.GearMeshError)
    assert "face_width_m" in str(e.value) and "-0.01" in str(e.value)
    # Unknown keys are forwarded to the library, which names them.
    with pytest.raises(hg.GearMeshError, match="not_a_parameter"):
        hg.GearPair(not_a_parameter=1.0)
    with pytest.raises(hg.ParameterError, match="fidelity"):
        hg.MeshModel(hg.GearPair(), fidelity="exact")


def test_a_rust_panic_arrives_as_gear_mesh_error():
    with pytest.raises(hg.GearMeshError, match="internal error \\(panic\\)"):
        hg._native._panic_for_test()


def test_geometry_of_table1():
    g = hg.geometry()
    # Closed form: base radius g = z·m_n·cos(α_t)/(2·cos β), tan α_t = tan α_n / cos β.
    p = hg.GearPair()
    at = math.atan(math.tan(p.pressure_angle_rad) / math.cos(p.helix_angle_rad))
    rb = p.z_p * p.normal_module_m * math.cos(at) / (2 * math.cos(p.helix_angle_rad))
    assert g.base_radius_p_m == pytest.approx(rb, rel=1e-12)
    assert 1.0 < g.eps_alpha < 2.0 and g.eps_beta > 0


# ---------------------------------------------------------------------------------------------
# Mesh evaluation against the C API, bit for bit


class HgmOutputs(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in (
        "m_f_p", "m_f_g", "m_d_p", "m_d_g", "te", "f_n", "contact_length", "p_max")] + [
        ("n_pairs", ctypes.c_uint32), ("tip_contact", ctypes.c_bool),
        ("separated", ctypes.c_bool), ("back_contact", ctypes.c_bool),
        ("force_p", ctypes.c_double * 3), ("moment_p", ctypes.c_double * 2),
        ("force_g", ctypes.c_double * 3), ("moment_g", ctypes.c_double * 2),
        ("root_stress_p", ctypes.c_double), ("root_stress_g", ctypes.c_double)]


@pytest.fixture(scope="module")
def capi():
    lib_path = RELEASE / "libhelical_gear_mesh.so"
    if not lib_path.exists():
        pytest.fail(f"{lib_path} is missing: build it with `cargo build --release`")
    lib = ctypes.CDLL(str(lib_path))
    lib.hgm_create_default.restype = ctypes.c_void_p
    lib.hgm_evaluate.argtypes = [ctypes.c_void_p] + [ctypes.c_double] * 4 + [
        ctypes.POINTER(HgmOutputs)]
    lib.hgm_evaluate.restype = ctypes.c_int
    lib.hgm_free.argtypes = [ctypes.c_void_p]
    return lib


def test_vectorised_evaluate_equals_the_c_api_bit_for_bit(capi):
    pair = hg.GearPair()
    g = hg.geometry(pair)
    gp, gg = g.base_radius_p_m, g.base_radius_g_m
    phi_p = np.linspace(0.0, g.angular_pitch_p_rad, 9)
    te = np.array([5e-6, 20e-6, 35e-6])[:, None]  # (3, 1) against (9,): broadcast to (3, 9)
    phi_g = (te - phi_p * gp) / gg
    w_p = 300.0  # a scalar, broadcast
    w_g = -300.0 * pair.z_p / pair.z_g + np.linspace(-1.0, 1.0, 9)
    model = hg.MeshModel(pair)
    out = model.evaluate(phi_p, phi_g, w_p, w_g)
    assert out["TE"].shape == (3, 9)
    # The C API: a fresh model of the same pair, the same states in C order.
    h = capi.hgm_create_default()
    assert h
    try:
        states = np.broadcast_arrays(phi_p, phi_g, np.float64(w_p), w_g)
        o = HgmOutputs()
        for idx in np.ndindex(3, 9):
            s = [float(a[idx]) for a in states]
            assert capi.hgm_evaluate(h, *s, ctypes.byref(o)) == 0
            for py_name, c_name in [("M_F_p", "m_f_p"), ("M_F_g", "m_f_g"), ("M_D_p", "m_d_p"),
                                    ("M_D_g", "m_d_g"), ("TE", "te"), ("F_n", "f_n"),
                                    ("contact_length", "contact_length"), ("p_max", "p_max"),
                                    ("sigma_F_p", "root_stress_p"),
                                    ("sigma_F_g", "root_stress_g")]:
                a, b = out[py_name][idx], getattr(o, c_name)
                assert a.tobytes() == np.float64(b).tobytes(), (py_name, idx, a, b)
            forces = list(o.force_p) + list(o.moment_p) + list(o.force_g) + list(o.moment_g)
            for py_name, b in zip(hg.FORCE_NAMES, forces):
                a = out[py_name][idx]
                assert a.tobytes() == np.float64(b).tobytes(), (py_name, idx, a, b)
            assert out["n_pairs"][idx] == o.n_pairs
            assert bool(out["tip_contact"][idx]) == o.tip_contact
    finally:
        capi.hgm_free(h)
    # Loaded states: positive torques, M_F_g/M_F_p = g_g/g_p in the plane of action.
    assert np.all(out["M_F_p"] > 0)
    np.testing.assert_allclose(out["M_F_g"] / out["M_F_p"], gg / gp, rtol=2e-2)
    # Pickled model: rebuilt, the same numbers from a fresh model.
    again = pickle.loads(pickle.dumps(model)).evaluate(phi_p, phi_g, w_p, w_g)
    assert again["M_F_p"].tobytes() == hg.MeshModel(pair).evaluate(
        phi_p, phi_g, w_p, w_g)["M_F_p"].tobytes()
    with pytest.raises(hg.ParameterError, match="phi_p"):
        model.evaluate([0.0, np.nan], 0.0, 0.0, 0.0)


def test_evaluate_computes_only_the_outputs_asked_for():
    # `outputs=`: the keys asked for, in their order, each value bit for bit as the complete
    # evaluation gives it: on the table's torques path (torques outputs only, friction on) and
    # on the complete path (any other output among them); unknown names are refused by name.
    assert hg.TORQUES_OUTPUTS == ("M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "contact_length",
                                  "M_R_p", "M_R_g", "P_loss")
    assert set(hg.TORQUES_OUTPUTS) <= set(hg.OUTPUT_NAMES)
    pair = hg.GearPair()
    g = hg.geometry(pair)
    gp, gg = g.base_radius_p_m, g.base_radius_g_m
    phi_p = np.linspace(0.0, 3.0 * g.angular_pitch_p_rad, 40)
    te = np.linspace(-260e-6, 90e-6, 40)  # back flanks, backlash, driving flanks
    phi_g = (te - phi_p * gp) / gg
    for fidelity in ("table", "full"):
        model = hg.MeshModel(pair, fidelity=fidelity, slices=60,
                             friction={"model": "constant", "mu": 0.05})
        full = model.evaluate(phi_p, phi_g, 300.0, -190.0)
        for ask in (["TE", "M_F_p"], list(hg.TORQUES_OUTPUTS), ["F_n", "M_F_g", "n_pairs"]):
            part = model.evaluate(phi_p, phi_g, 300.0, -190.0, outputs=ask)
            assert list(part) == ask
            for k in ask:
                assert part[k].tobytes() == full[k].tobytes(), (fidelity, k)
        assert list(model.evaluate(0.0, 0.0, outputs="TE")) == ["TE"]
        assert list(model.evaluate(0.0, 0.0, outputs=["TE", "TE"])) == ["TE"]
        with pytest.raises(hg.ParameterError, match='"colour"'):
            model.evaluate(0.0, 0.0, outputs=["TE", "colour"])


def test_state_outside_the_validity_range_raises():
    # Flank overlaps beyond 0.2 m_n (TE of 2 mm, back flanks 3 mm past the backlash) and pinion
    # angles beyond 2^53 pitches are errors, never a torque or "separated".
    pair = hg.GearPair()
    g = hg.geometry(pair)
    gp, gg = g.base_radius_p_m, g.base_radius_g_m
    model = hg.MeshModel(pair)
    for te in (2e-3, -3e-3):
        with pytest.raises(hg.SolverError, match="validity range"):
            model.evaluate(0.01, (te - 0.01 * gp) / gg, 0.0, 0.0)
    with pytest.raises(hg.ParameterError, match="phi_p"):
        model.evaluate(1e19, (20e-6 - 1e19 * gp) / gg, 0.0, 0.0)
    assert issubclass(hg.SolverError, hg.GearMeshError)


def test_geometry_equals_the_cli(tmp_path):
    cli = RELEASE / "helical-gear"
    if not cli.exists():
        pytest.fail(f"{cli} is missing: build it with `cargo build --release --bin helical-gear`")
    run = subprocess.run([str(cli), "geometry", "--json"], capture_output=True, text=True,
                         check=True)
    ref = json.loads(run.stdout)
    g = hg.geometry()
    assert set(g) == set(ref)
    assert all(g[k] == ref[k] for k in ref), [k for k in ref if g[k] != ref[k]]


def test_static_curve_equals_the_cli(tmp_path):
    cli = RELEASE / "helical-gear"
    if not cli.exists():
        pytest.fail(f"{cli} is missing: build it with `cargo build --release --bin helical-gear`")
    pair = hg.GearPair()
    drive = hg.DriveLine(torque_nm=80.0)
    params = tmp_path / "pair.json"
    params.write_text(pair.to_json())
    drive_file = tmp_path / "drive.json"
    drive_file.write_text(drive.to_json())
    run = subprocess.run([str(cli), "static", "--params", str(params), "--drive",
                          str(drive_file), "--json", "--points-per-pitch", "6"],
                         capture_output=True, text=True, check=True)
    ref = json.loads(run.stdout)
    c = hg.static_curve(pair, points_per_pitch=6, drive=drive)
    # Python reads the same record as the CLI prints (µm), in m.
    assert c.ste_max == ref["ste_max_um"] * 1e-6
    assert c.ste_peak_to_peak * 1e6 == pytest.approx(ref["ste_peak_to_peak_um"], rel=1e-12)
    assert c.mesh_stiffness_mean == ref["mesh_stiffness_mean_n_per_um"] * 1e6
    assert [p["ste_um"] * 1e-6 for p in ref["points"]] == list(c.ste)
    assert ref["ste_um"] == [p["ste_um"] for p in ref["points"]]
    df = c.to_dataframe()
    assert list(df.columns)[:2] == ["phi_p", "ste"] and len(df) == 6



def test_iso_root_stress_is_the_cli_static_iso_keys(tmp_path):
    """ISO 6336-3 method B from Python (`iso_root_stress`, `static_curve`'s summary) is the
    record the CLI's ``static --json`` prints, linear in |torque|, and a pair the method cannot
    rate is a ParameterError naming the key."""
    cli = RELEASE / "helical-gear"
    if not cli.exists():
        pytest.fail(f"{cli} is missing: build it with `cargo build --release --bin helical-gear`")
    run = subprocess.run([str(cli), "static", "--json", "--torque", "80", "--points-per-pitch",
                          "2", "--slices", "40"], capture_output=True, text=True, check=True)
    ref = json.loads(run.stdout)
    iso = hg.iso_root_stress(hg.GearPair(), 80.0)
    assert iso == ref["iso6336"]
    assert iso["pinion"]["sigma_f0_pa"] == ref["root_stress_iso_p_pa"]
    assert iso["gear"]["sigma_f0_pa"] == ref["root_stress_iso_g_pa"]
    assert set(iso["pinion"]) == {"y_f", "y_s", "y_beta", "y_b", "y_dt", "s_fn_m", "h_fe_m",
                                  "rho_f_m", "alpha_fen_rad", "z_n", "sigma_f0_pa"}
    c = hg.static_curve(points_per_pitch=2, slices=40, torque=80.0)
    assert c.root_stress_iso_p_pa == ref["root_stress_iso_p_pa"]
    assert c.root_stress_iso_g_pa == ref["root_stress_iso_g_pa"]
    assert c.iso6336 == iso and c.iso6336_error is None
    half = hg.iso_root_stress(torque=-40.0)
    assert half["gear"]["sigma_f0_pa"] == pytest.approx(0.5 * iso["gear"]["sigma_f0_pa"],
                                                        rel=1e-14)
    with pytest.raises(hg.ParameterError, match="addendum_mn"):
        hg.iso_root_stress(hg.GearPair(h_aP=0.5, b=0.06))

def test_long_calls_release_the_gil():
    import sys
    import threading
    import time

    # A loaded state (TE about 20 um, contact on every point) at full fidelity: each point solves
    # the load distribution, so the call lasts a tenth of a second or more.
    model = hg.MeshModel()
    phi = np.linspace(0.0, 0.2, 400)
    phi_g = -phi * 30 / 47 + 3e-4
    window = {}
    started = threading.Event()

    def work():
        started.set()
        window["start"] = time.perf_counter()
        out = model.evaluate(phi, phi_g, 300.0, -191.0)
        window["end"] = time.perf_counter()
        window["loaded"] = bool(np.all(out["F_n"] > 0.0))

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    stamps = []
    last = 0.0
    while t.is_alive():
        now = time.perf_counter()
        if now - last > 1e-3:
            stamps.append(now)
            last = now
    t.join()
    assert window["loaded"]
    duration = window["end"] - window["start"]
    # The test is meaningful only if the call outlasts the interpreter's switch interval many
    # times over: a thread that holds the GIL can lose it only at the edges of the call.
    assert duration > 20 * sys.getswitchinterval(), duration
    # With the GIL held for the whole Rust call this thread could not run in its middle half.
    lo = window["start"] + 0.25 * duration
    hi = window["start"] + 0.75 * duration
    inside = [s for s in stamps if lo < s < hi]
    assert len(inside) >= 10, (duration, len(stamps), len(inside))


def test_two_threads_on_one_shared_model_give_the_results_of_one_thread():
    import threading

    # One model shared by two threads (no lock around it: each call has its own workspace and
    # starts cold), each evaluating loaded full-fidelity states at the same time; both results
    # equal, bit for bit, those of the same call on one thread.
    model = hg.MeshModel(slices=60)
    phi = np.linspace(0.0, 0.2, 40)
    phi_g = -phi * 30 / 47 + 3e-4
    args = (phi, phi_g, 300.0, -191.0)
    alone = model.evaluate(*args)
    results = [None, None]

    def work(k):
        results[k] = model.evaluate(*args)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert np.all(alone["F_n"] > 0.0)
    for r in results:
        for key, a in alone.items():
            assert np.asarray(r[key]).tobytes() == np.asarray(a).tobytes(), key


def test_results_plot_and_tabulate():
    import matplotlib

    matplotlib.use("Agg")
    c = hg.static_curve(points_per_pitch=4)
    ax = c.plot()
    (line,) = ax.get_lines()
    assert np.array_equal(line.get_ydata(), c.ste * 1e6)
    assert len(c.to_dataframe()) == 4


def test_simulate_equals_the_cli(tmp_path):
    cli = RELEASE / "helical-gear"
    pair = hg.GearPair()
    t_m = 2 * math.pi / (pair.z_p * 300.0)  # mesh period at 300 rad/s
    dt = t_m / 64
    t_end = 64 * dt
    run = subprocess.run([str(cli), "simulate", "--omega-p", "300", "--t-end", repr(t_end),
                          "--dt", repr(dt), "--json"], capture_output=True, text=True, check=True)
    ref = json.loads(run.stdout)
    tr = hg.simulate(pair, 300.0, t_end, dt=dt)
    assert list(tr.time) == ref["time_s"]
    assert list(tr.TE) == ref["te_m"] and list(tr.M_F_p) == ref["m_f_p_nm"]
    assert list(tr.w_p_rad_s) == ref["w_p_rad_s"]
    assert tr.steps == ref["steps"] == 64
    assert set(tr.to_dataframe().columns) >= {"time", "TE", "phi_p_rad", "M_F_g"}


def test_compliance_summary_equals_the_cli():
    """`Compliance.summary()` is the record of `helical-gear compliance --json` (the library's
    `results::ComplianceRecord`): on Table 1's embedded data the same keys and values."""
    cli = RELEASE / "helical-gear"
    run = subprocess.run([str(cli), "compliance", "--json"], capture_output=True, text=True,
                         check=True)
    s = dict(hg.compliance().summary())
    assert s == json.loads(run.stdout)
    assert s["source"] == "embedded" and s["fit_seconds"] == s["fit_seconds_p"] + s["fit_seconds_g"]


def test_compliance_pickles_losslessly():
    c = hg.compliance()  # Table 1: the embedded data
    assert c.source == "embedded"
    c2 = pickle.loads(pickle.dumps(c))
    args = (np.linspace(0.0, 0.2, 5), -0.0001 - np.linspace(0.0, 0.2, 5) * 30 / 47, 300.0, -191.0)
    a = hg.MeshModel(compliance=c).evaluate(*args)
    b = hg.MeshModel(compliance=c2).evaluate(*args)
    assert all(a[k].tobytes() == b[k].tobytes() for k in hg.OUTPUT_NAMES)


# ---------------------------------------------------------------------------------------------
# Design studies

DESIGNS = [
    {"helix_angle_rad": 0.17, "face_width_m": 0.015},
    {"helix_angle_rad": 0.25, "face_width_m": 0.012},
    {"helix_angle_rad": 0.17, "face_width_m": 0.015},  # = the first: shares everything
    {"helix_angle_rad": 0.17, "face_width_m": 0.015, "d_mesh_n_s_per_m": 200.0},  # same FE
    {"helix_angle_rad": 0.17, "face_width_m": -0.015},  # invalid
]


def _events(path):
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines()]


def _results(df):
    cols = ["ste_max_um", "ste_peak_to_peak_um", "mesh_stiffness_mean_n_per_um",
            "omega_crit_rad_s", "peak_te_ratio", "error", "design_key"]
    out = df[["helix_angle_rad", "face_width_m", *cols]].copy()
    # Parquet gives pandas' string dtype, the study object: compare the values.
    out["error"] = [None if pd.isna(e) else str(e) for e in out["error"]]
    out["error"] = out["error"].astype(object)
    out["design_key"] = out["design_key"].astype(object)
    return out


@pytest.fixture(scope="module")
def serial_study(tmp_path_factory):
    d = tmp_path_factory.mktemp("study")
    events = d / "events.jsonl"
    os.environ[hg.study.EVENTS_ENV] = str(events)
    try:
        t0 = time.perf_counter()
        table = hg.study.run(pd.DataFrame(DESIGNS), fe_density="coarse", out=d / "r.parquet",
                             progress=False, **FAST_SWEEP)
        print(f"serial study of {len(DESIGNS)} designs: {time.perf_counter() - t0:.1f} s")
    finally:
        del os.environ[hg.study.EVENTS_ENV]
    return table, _events(events), d


def test_serial_study_rows_errors_and_fe_count(serial_study):
    table, events, d = serial_study
    assert len(table) == len(DESIGNS)
    assert list(table["helix_angle_rad"]) == [r["helix_angle_rad"] for r in DESIGNS]
    ok = table["error"].isna()
    assert list(ok) == [True, True, True, True, False]
    assert "face_width_m" in table["error"][4]
    # Physical sanity: positive STE, stiffness and resonance speed in the swept range.
    assert (table["ste_max_um"][ok] > 0).all()
    assert (table["mesh_stiffness_mean_n_per_um"][ok] > 0).all()
    assert (table["peak_te_ratio"][ok] > 1.0).all()
    # Identical designs give identical rows; the damping changes no static result.
    assert table.iloc[0]["design_key"] == table.iloc[2]["design_key"]
    assert table.iloc[0]["ste_max_um"] == table.iloc[3]["ste_max_um"]
    # FE once per compliance key (two keys), one analysis per distinct valid design (three).
    fe = [e["key"] for e in events if e["event"] == "fe"]
    assert sorted(fe) == sorted(set(fe)) and len(fe) == 2
    assert len([e for e in events if e["event"] == "design"]) == 3
    # The Parquet output holds the table; the journal is gone.
    back = pd.read_parquet(d / "r.parquet")
    pd.testing.assert_frame_equal(_results(back), _results(table))
    assert not (d / "r.parquet.parts").exists()


def test_local_cluster_gives_the_serial_table(serial_study, tmp_path):
    from distributed import Client, LocalCluster

    table, _, _ = serial_study
    events = tmp_path / "events.jsonl"
    os.environ[hg.study.EVENTS_ENV] = str(events)
    try:
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            dist = hg.study.run(pd.DataFrame(DESIGNS), fe_density="coarse", client=client,
                                progress=False, **FAST_SWEEP)
    finally:
        del os.environ[hg.study.EVENTS_ENV]
    pd.testing.assert_frame_equal(_results(dist), _results(table))
    ev = _events(events)
    assert len({e["pid"] for e in ev}) >= 1
    assert len([e for e in ev if e["event"] == "fe"]) == 2
    assert len([e for e in ev if e["event"] == "design"]) == 3


def test_killed_study_resumes_without_recomputing(tmp_path):
    n = 6
    designs = pd.DataFrame({"helix_angle_rad": np.linspace(0.12, 0.27, n),
                            "face_width_m": np.full(n, 0.014)})
    csv = tmp_path / "designs.csv"
    designs.to_csv(csv, index=False)
    out = tmp_path / "out.parquet"
    parts = tmp_path / "out.parquet.parts"
    cmd = [sys.executable, "-m", "helical_gear", "study", str(csv), "--out", str(out),
           "--analyses", "static", "--fe-density", "coarse", "--no-progress"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 240
    while not (parts.exists() and any(parts.glob("part-*.parquet"))):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no row was written in time"
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = pd.concat([pd.read_parquet(f) for f in parts.glob("part-*.parquet")])
    assert 0 < len(done) < n, "the kill came too late to test resuming"
    assert not out.exists()

    events = tmp_path / "events.jsonl"
    os.environ[hg.study.EVENTS_ENV] = str(events)
    try:
        table = hg.study.run(pd.read_csv(csv), analyses=("static",), out=out,
                             fe_density="coarse", progress=False)
    finally:
        del os.environ[hg.study.EVENTS_ENV]
    recomputed = [e["key"] for e in _events(events) if e["event"] == "design"]
    assert len(recomputed) == n - len(done)
    assert not set(recomputed) & set(done["design_key"])
    assert table["error"].isna().all() and (table["ste_max_um"] > 0).all()
    assert len(pd.read_parquet(out)) == n and not parts.exists()


def test_study_routes_drive_columns_to_the_drive_line():
    """`drive.*` design columns are the design's drive line: the static analysis runs at its
    torque, as `static_curve(..., drive=...)` does."""
    designs = pd.DataFrame([{"_name": "T1"}, {"_name": "half", "drive.torque_nm": 50.0}])
    table = hg.study.run(designs, analyses=("static",), static_points=6, slices=80,
                         progress=False)
    assert list(table["error"]) == [None, None]
    for torque, ste in zip((100.0, 50.0), table["ste_max_um"]):
        c = hg.static_curve(hg.GearPair(), points_per_pitch=6, slices=80,
                            drive=hg.DriveLine(torque_nm=torque))
        assert ste == c.ste_max * 1e6
    assert table["ste_max_um"][1] < table["ste_max_um"][0]


def test_bounds_are_the_library_ranges():
    """`BOUNDS` holds the library's range of every numeric key; a value past one is refused."""
    assert hg.BOUNDS["normal_module_m"] == (1e-5, 1.0, "m")
    assert hg.BOUNDS["z_p"][:2] == (5, 100000)
    assert hg.BOUNDS["drive.torque_nm"] == (1.0, 1e9, "N.m")
    lo, hi, _ = hg.BOUNDS["material_p.poisson_ratio"]
    hg.GearPair(**{"material_p.poisson_ratio": hi})
    with pytest.raises(hg.ParameterError, match="poisson_ratio"):
        hg.GearPair(**{"material_p.poisson_ratio": hi * 1.001})
