"""Bad input from Python: sepval's own messages (file or name, line, column, field), the CLI's
for the same file; wrong Python types as TypeError; and nothing written, neither the output
directory nor the input store."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import sepval
from conftest import BUDGET, cli_error


@pytest.fixture()
def frame():
    return sepval.simulate(noise_seed=3, t_end_s=0.2)


def assert_nothing_written(out, store):
    assert not out.exists(), sorted(out.rglob("*"))
    assert list(store.iterdir()) == []


def test_a_missing_column_in_a_file_is_the_cli_s_message(cli, tmp_path, store):
    (tmp_path / "bad.csv").write_text("t_s,x_m,y_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0\n")
    expected = cli_error(cli(["fit", "--data", "bad.csv", *BUDGET, "--out", "out"], tmp_path))
    assert expected == "bad.csv: line 1: missing column for z: expected `z_m` or `z_ft`"
    with pytest.raises(sepval.SepvalError) as e:
        sepval.fit(str(tmp_path / "bad.csv"), generations=4, out=tmp_path / "out")
    assert str(e.value) == expected.replace("bad.csv", str(tmp_path / "bad.csv"), 1)
    assert_nothing_written(tmp_path / "out", store)


def test_a_missing_column_in_a_dataframe(frame, tmp_path, store):
    with pytest.raises(sepval.SepvalError) as e:
        sepval.fit(frame.drop(columns=["pitch_deg"]), generations=4, out=tmp_path / "out")
    assert str(e.value) == (
        "data (a DataFrame; line 2 is its first row): line 1: missing column for pitch: expected `pitch_deg`"
    )
    assert_nothing_written(tmp_path / "out", store)


def test_nan_in_a_dataframe_names_its_line_and_column(frame, tmp_path, store):
    frame.loc[3, "y_m"] = np.nan
    with pytest.raises(sepval.SepvalError) as e:
        sepval.diagnose(frame, generations=4, out=tmp_path / "out")
    assert str(e.value) == (
        "data (a DataFrame; line 2 is its first row): line 5, column 3 (`y_m`): expected a finite number, found `nan`"
    )
    assert_nothing_written(tmp_path / "out", store)


def test_the_second_release_of_a_list_is_named_and_the_first_is_not_stored(frame, tmp_path, store):
    bad = {c: frame[c].to_numpy() for c in frame.columns}
    bad["t_s"] = bad["t_s"][::-1].copy()
    with pytest.raises(sepval.SepvalError, match=r"^data\[1\] \(a dict of arrays; line 2 is its first row\): line 3, column 1 \(`t_s`\): time"):
        sepval.fit([frame, bad], generations=4, out=tmp_path / "out")
    assert_nothing_written(tmp_path / "out", store)


def test_text_where_a_number_belongs(frame, tmp_path, store):
    frame = frame.astype({"roll_deg": object})
    frame.loc[0, "roll_deg"] = "12,5 deg"
    with pytest.raises(sepval.SepvalError, match=r"line 2, column 5 \(`roll_deg`\): expected a number, found `12;5 deg`"):
        sepval.fit(frame, generations=4, out=tmp_path / "out")
    assert_nothing_written(tmp_path / "out", store)


def test_wrong_python_types_are_type_errors(frame, tmp_path, store):
    out = tmp_path / "out"
    with pytest.raises(TypeError, match="data: expected a path .*, a pandas DataFrame or a dict of arrays, got int"):
        sepval.fit(42, out=out)
    with pytest.raises(TypeError, match=r"seed: expected an integer, got str '3'"):
        sepval.fit(frame, seed="3", out=out)
    with pytest.raises(TypeError, match="generations: expected an integer, got float"):
        sepval.fit(frame, generations=4.0, out=out)
    with pytest.raises(TypeError, match="column 'x_m': expected a one-dimensional array"):
        sepval.fit({**{c: frame[c].to_numpy() for c in frame.columns}, "x_m": np.zeros((3, 2))}, out=out)
    with pytest.raises(TypeError, match="progress: expected a callable"):
        sepval.fit(frame, generations=4, out=out, progress="yes")
    with pytest.raises(ValueError, match="evaluator='threads': expected 'inproc' or 'ipc'"):
        sepval.fit(frame, evaluator="threads", out=out)
    with pytest.raises(ValueError, match=r"columns of different lengths \(t_s 2, x_m 1\)"):
        sepval.goals({"t_s": [0, 1], "x_m": [0]}, frame)
    assert_nothing_written(out, store)


def test_values_sepval_refuses_read_as_the_cli_s(cli, tmp_path, store):
    expected = cli_error(cli(["simulate", "--t-end", "nan", "--out", "x.csv"], tmp_path))
    with pytest.raises(sepval.SepvalError) as e:
        sepval.simulate(t_end_s=float("nan"))
    assert str(e.value) == expected == "--t-end = NaN: expected a finite number > 0"
    expected = cli_error(cli(["fit", "--method", "gaa", "--out", "out"], tmp_path))
    with pytest.raises(sepval.SepvalError) as e:
        sepval.fit(method="gaa", out=tmp_path / "out")
    assert str(e.value) == expected
    assert_nothing_written(tmp_path / "out", store)


def test_a_path_that_is_not_a_file(cli, tmp_path, store):
    expected = cli_error(cli(["fit", "--data", "nowhere.csv", *BUDGET, "--out", "out"], tmp_path))
    with pytest.raises(sepval.SepvalError) as e:
        sepval.fit(tmp_path / "nowhere.csv", out=tmp_path / "out")
    assert str(e.value) == expected.replace("nowhere.csv", str(tmp_path / "nowhere.csv"))
    with pytest.raises(sepval.SepvalError, match="is a directory"):
        sepval.read_telemetry(tmp_path)
    assert_nothing_written(tmp_path / "out", store)


def test_bad_scenario_and_factor_dicts(tmp_path, store):
    scenario = sepval.scenario()
    scenario["flight"]["mach"] = float("nan")
    with pytest.raises(sepval.SepvalError) as e:
        sepval.simulate(scenario=scenario)
    assert str(e.value) == "scenario (a dict): `flight.mach` = NaN: expected a finite value > 0"
    scenario["flight"]["mach"] = None
    with pytest.raises(sepval.SepvalError, match=r"^scenario \(a dict\): `flight.mach`: None, where the scenario needs a value$"):
        sepval.simulate(scenario=scenario)
    with pytest.raises(sepval.SepvalError, match=r"^factors \(a dict\): factor `aftfac` is missing"):
        sepval.simulate(factors={"fwdfac": 0.3})
    with pytest.raises(sepval.SepvalError, match=r"^factors \(a dict\): factor `aftfac` is missing"):
        sepval.simulate(scenario=sepval.scenario(), factors={"fwdfac": 0.3})
    with pytest.raises(ValueError, match=r"factors\['fwdfac'\] = nan: expected a finite number"):
        sepval.simulate(factors={"fwdfac": float("nan")})
    assert list(store.iterdir()) == []
