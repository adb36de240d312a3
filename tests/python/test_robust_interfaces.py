"""Regression tests of the Python boundary: inputs beyond their stated ranges and parameters
beyond theirs are errors with short numbers that name the key (never infinite results), and a
design study turns a row that cannot be parsed into an error row naming the column and the
value, without coercing anything and without stopping the other designs."""

import math
import re

import pytest

hg = pytest.importorskip("helical_gear")
pd = pytest.importorskip("pandas")


def _short_numbers(msg):
    return all(len(w) <= 16 for w in re.findall(r"[-+]?\d[\w.+-]*", msg))


def test_evaluate_with_huge_speed_is_a_parameter_error_not_an_infinite_torque():
    model = hg.MeshModel(hg.GearPair())
    for i, name in enumerate(["phi_p", "phi_g", "w_p", "w_g"]):
        v = [[0.01], [-0.0060851], [100.0], [-63.83]]
        v[i] = [1e308]
        with pytest.raises(hg.ParameterError, match=f"`{name}`") as e:
            model.evaluate(*v)
        assert "1.0000e308" in str(e.value) and _short_numbers(str(e.value)), str(e.value)
    out = model.evaluate([0.01], [-0.0060851], [1e5], [-1e5 * 30 / 47])
    assert all(math.isfinite(out[k][0]) for k in ("M_F_p", "M_D_p", "TE"))


def test_d_mesh_beyond_its_range_names_the_key_with_a_short_number():
    with pytest.raises(hg.ParameterError) as e:
        hg.MeshModel(hg.GearPair(d_mesh_n_s_per_m=1e300))
    msg = str(e.value)
    assert "d_mesh_n_s_per_m" in msg and "1.0000e300" in msg and _short_numbers(msg), msg


def test_study_turns_unparsable_speed_cells_into_error_rows():
    designs = pd.DataFrame({
        "_label": ["text", "fraction", "bool", "good"],
        "omega_from_rad_s": ["fast", 300.0, 300.0, 300.0],
        "omega_to_rad_s": [900.0, 900.0, True, 900.0],
        "omega_points": [3, 2.5, 3, 3],
    })
    table = hg.study.run(designs, analyses=("static",), static_points=8, slices=80,
                         progress=False)
    assert list(table["_label"]) == ["text", "fraction", "bool", "good"]
    errors = list(table["error"])
    assert "omega_from_rad_s" in errors[0] and "'fast'" in errors[0], errors[0]
    assert "omega_points" in errors[1] and "2.5" in errors[1], errors[1]
    assert "omega_to_rad_s" in errors[2] and "True" in errors[2], errors[2]
    assert errors[3] is None
    assert math.isfinite(table["ste_max_um"][3]) and table["ste_max_um"][3] > 0
    assert all(math.isnan(table["ste_max_um"][i]) for i in range(3))
