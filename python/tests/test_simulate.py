"""simulate, read_telemetry, goals, scenario and effects against the CLI: the same bits."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pandas as pd
import pytest

import sepval
from conftest import cli_ok


def columns_of_csv(path):
    """The seven columns of a telemetry CSV, parsed by Python's own float(), as an
    independent reference of the bits the CLI wrote."""
    with open(path, encoding="utf-8") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    header, body = rows[0], rows[1:]
    return {h: np.array([float(r[k]) for r in body]) for k, h in enumerate(header)}


def same_bits(a, b) -> bool:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_simulate_is_the_cli_bit_for_bit(cli, tmp_path):
    cli_ok(cli(["simulate", "--noise-seed", "7", "--t-end", "0.6", "--rate", "250",
                "--effect", "roll_due_to_sideslip=-0.3", "--out", "cli.csv"], tmp_path))
    df = sepval.simulate(noise_seed=7, t_end_s=0.6, rate_hz=250, effects={"roll_due_to_sideslip": -0.3})
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == list(sepval.COLUMNS)
    reference = columns_of_csv(tmp_path / "cli.csv")
    assert len(df) == len(reference["t_s"]) == 151
    for c in sepval.COLUMNS:
        assert same_bits(df[c].to_numpy(), reference[c]), c
    assert df.attrs["noise_seed"] == "7"
    assert df.attrs["effects"].startswith("roll_due_to_sideslip")
    # With out=, the very file the CLI writes.
    sepval.simulate(noise_seed=7, t_end_s=0.6, rate_hz=250, effects=["roll_due_to_sideslip=-0.3"], out=tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


def test_scenario_and_factor_dicts_simulate_as_their_files(cli, tmp_path):
    cli_ok(cli(["scenario", "--out", "s.toml"], tmp_path))
    text = (tmp_path / "s.toml").read_text().replace("mach = 0.95", "mach = 0.8")
    (tmp_path / "s.toml").write_text(text)
    (tmp_path / "f.json").write_text(
        '{"fwdfac": 0.3, "aftfac": 0.7, "xinerfac": 1.0, "yinerfac": 1.0, "zinerfac": 1.0, "caoff": 0.0,'
        ' "cyoff": 0.0, "czoff": 0.0, "cmoff": 0.0, "cnoff": 0.0, "cloff": 0.0, "caintfac": 1.0,'
        ' "cyintfac": 1.0, "czintfac": 1.0, "cmintfac": 1.0, "cnintfac": 1.0, "clintfac": 1.0}'
    )
    cli_ok(cli(["simulate", "--scenario", "s.toml", "--factors", "f.json", "--out", "cli.csv"], tmp_path))
    scenario = sepval.scenario()
    assert scenario["flight"]["mach"] == 0.95
    scenario["flight"]["mach"] = 0.8
    assert sepval.scenario(tmp_path / "s.toml") == scenario
    factors = json.loads((tmp_path / "f.json").read_text())
    df = sepval.simulate(scenario=scenario, factors=factors)
    reference = columns_of_csv(tmp_path / "cli.csv")
    for c in sepval.COLUMNS:
        assert same_bits(df[c].to_numpy(), reference[c]), c
    assert df.attrs["mach"] == "0.8"


def test_read_telemetry_keeps_the_metadata_and_reads_feet(tmp_path):
    (tmp_path / "ft.csv").write_text(
        "# event = drop 3\n# mach = 0.85\nt_s,x_ft,y_ft,z_ft,roll_deg,pitch_deg,yaw_deg\n"
        "0,0,0,0,0,0,0\n0.01,1,2,3,0.5,0.25,-1\n"
    )
    df = sepval.read_telemetry(tmp_path / "ft.csv")
    assert df.attrs == {"event": "drop 3", "mach": "0.85"}
    assert df["z_m"].iloc[1] == 3 * 0.3048
    assert df["yaw_deg"].iloc[1] == -1.0


def test_goals_are_the_cli_s_unrounded(cli, tmp_path):
    cli_ok(cli(["simulate", "--noise-seed", "7", "--out", "a.csv"], tmp_path))
    cli_ok(cli(["simulate", "--out", "b.csv"], tmp_path))
    printed = cli_ok(cli(["goals", "--data", "a.csv", "--sim", "b.csv"], tmp_path)).stdout.split()
    g = sepval.goals(tmp_path / "a.csv", sepval.read_telemetry(tmp_path / "b.csv"))
    assert f"{g.j_pos_m:.9f}" == printed[2] and f"{g.j_att_deg:.9f}" == printed[6]
    j_pos, j_att = sepval.goals(sepval.read_telemetry(tmp_path / "a.csv"), tmp_path / "b.csv")
    assert (j_pos, j_att) == g
    assert math.isfinite(j_pos) and j_pos > 0


def test_effects_list_the_catalogue(cli, tmp_path):
    listed = cli_ok(cli(["effects"], tmp_path)).stdout
    ids = [e["id"] for e in sepval.effects()]
    assert ids and all(f"\n{i}\n" in listed for i in ids)
    first = sepval.effects()[0]
    assert {"name", "unit", "neutral", "min", "max"} <= set(first["params"][0])


def test_without_pandas_telemetry_is_a_record_array_with_attrs(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas" or name.startswith("pandas."):
            raise ImportError("no pandas here")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    records = sepval.simulate(t_end_s=0.1)
    assert isinstance(records, np.recarray) and isinstance(records, sepval.Telemetry)
    assert records.dtype.names == sepval.COLUMNS
    assert records.attrs["noise"] == "none"
    assert records.t_s[-1] == 0.1
    # Given back as data, it reads as the same release.
    assert sepval.goals(records, records) == (0.0, 0.0)
