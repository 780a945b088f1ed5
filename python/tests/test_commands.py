"""diagnose, predict, plan and envelope against the CLI on small cases: the same numbers, the
result objects, and results passed from one command to the next."""

from __future__ import annotations

import pandas as pd
import pytest

import sepval
from conftest import REPO, cli_ok, deterministic, read_json

AIRCRAFT = REPO / "examples" / "geometry" / "aircraft.toml"


@pytest.fixture(scope="module")
def fitted(releases, tmp_path_factory, cli_binary):
    """A `ga+lm` fit of the two releases, by the CLI."""
    import subprocess

    d = tmp_path_factory.mktemp("fitted")
    cli_ok(subprocess.run([str(cli_binary), "fit", "--data", str(releases / "a.csv"), "--data", str(releases / "b.csv"),
                           "--method", "ga+lm", "--generations", "4", "--population", "40", "--evaluator", "inproc",
                           "--threads", "2", "--no-figures", "--out", str(d / "fit")], capture_output=True, text=True, timeout=600))
    return d / "fit"


def condition():
    """The condition to predict, as a dict: the default store at Mach 0.7, alpha 1.5, beta -2
    (releases' cond.toml)."""
    s = sepval.scenario()
    s["flight"].update(mach=0.7, alpha_deg=1.5, beta_deg=-2.0)
    return s


def test_predict_is_the_cli_bit_for_bit(cli, fitted, releases, tmp_path):
    cli_ok(cli(["predict", "--from", fitted, "--scenario", releases / "cond.toml", "--samples", "400", "--seed", "4",
                "--evaluator", "inproc", "--threads", "2", "--out", tmp_path / "cli"], tmp_path))
    p = sepval.predict(fitted, scenario=condition(), samples=400, seed=4, out=tmp_path / "py")
    expected = read_json(tmp_path / "cli" / "prediction.json")
    assert deterministic(p.to_dict()) == deterministic(expected)
    assert p.condition == {"mach": 0.7, "altitude_m": 7924.8, "alpha_deg": 1.5, "beta_deg": -2.0, "gamma_deg": 0.0}
    assert isinstance(p.bands, pd.DataFrame) and len(p.bands) == len(expected["t_s"])
    assert p.bands["pitch_deg_hi"].tolist() == expected["pitch_deg"]["hi"]
    assert set(p.sources) == {"factors", "model_form", "measurement"}
    assert p.check is None and p.verdict is None
    assert (tmp_path / "py" / "bands.csv") in p.files


def test_a_flown_release_is_checked_against_the_bands(fitted, tmp_path):
    s = condition()
    flown = sepval.simulate(scenario=s, noise_seed=9)
    p = sepval.predict(sepval.Fit.load(fitted), scenario=s, samples=400, data=flown, with_noise=True)
    assert p.check is not None and p.verdict == p.check["verdict"]
    assert p.verdict.startswith(("inside the predicted bands", "outside from"))


def test_diagnose_plan_and_their_results(cli, tmp_path):
    cli_ok(cli(["diagnose", "--generations", "12", "--evaluator", "inproc", "--threads", "2", "--out", "cli"], tmp_path))
    d = sepval.diagnose(generations=12, workers=2, out=tmp_path / "py")
    assert deterministic(d.to_dict()) == deterministic(read_json(tmp_path / "cli" / "diagnosis.json"))
    assert d.explained and d.causes == [] and d.verdict.startswith("the baseline model explains the data")
    assert d.factors == d.to_dict()["model"]["factors"] and d.extension is None
    assert d.correlations.shape == (17, 17)
    assert d.summary.splitlines()[0] == "answer:    nothing named"
    plan = sepval.plan(d, mach=(0.6, 0.9), points=4)
    cli_ok(cli(["plan", "--from", "py", "--mach", "0.6:0.9", "--points", "4", "--evaluator", "inproc", "--out", "plan"], tmp_path))
    assert deterministic(plan.to_dict()) == deterministic(read_json(tmp_path / "plan" / "plan.json"))
    assert plan.ranked_by == "information" and len(plan.conditions) == 4
    assert plan.recommended == plan.to_dict()["conditions"][0]


def test_envelope_is_the_cli_s(cli, fitted, tmp_path):
    cli_ok(cli(["envelope", "--from", fitted, "--aircraft", AIRCRAFT, "--mach", "0.6:0.9:3", "--samples", "400",
                "--evaluator", "inproc", "--threads", "2", "--out", tmp_path / "cli"], tmp_path))
    e = sepval.envelope(fitted, aircraft=AIRCRAFT, mach=(0.6, 0.9, 3), samples=400, out=tmp_path / "py")
    expected = read_json(tmp_path / "cli" / "envelope.json")
    assert deterministic(e.to_dict()) == deterministic(expected)
    assert e.conditions == 3 and len(e.rows) == 3 and list(e.rows["mach"]) == [0.6, 0.75, 0.9]
    assert e.headline == expected["headline"]


def test_update_is_the_cli_s_and_its_store_is_a_scenario(cli, releases, tmp_path):
    a, b = releases / "a.csv", releases / "b.csv"
    cli_ok(cli(["update", "--data", a, "--data", b, "--generations", "4", "--population", "40",
                "--evaluator", "inproc", "--threads", "2", "--out", tmp_path / "cli"], tmp_path))
    u = sepval.update([a, b], generations=4, population=40, workers=2, out=tmp_path / "py")
    assert deterministic(u.to_dict()) == deterministic(read_json(tmp_path / "cli" / "update.json"))
    assert (tmp_path / "py" / "scenario.toml").read_text() == (tmp_path / "cli" / "scenario.toml").read_text()
    assert u.verdict == u.to_dict()["verdict"] and isinstance(u.corrections, list)
    assert isinstance(u.folds, pd.DataFrame) and len(u.folds) == 2
    assert len(u.factors) == 17
    # The updated store is a scenario every command takes, with its factors. Its flight
    # condition is the default's, Mach 0.95, beyond the releases' 0.8 and 0.9: a correction
    # over Mach is held at its edge there, and the simulation says so.
    with pytest.warns(sepval.SepvalWarning, match=r"left table `aero\.\w+` .* beyond \[0\.8, 0\.9\]"):
        sim = sepval.simulate(scenario=u.scenario_path, factors=u.factors_path)
    assert len(sim) == 201
    with pytest.raises(TypeError, match="free"):
        sepval.update([a], free="fwdfac")
    with pytest.raises(sepval.SepvalError, match="--free wingfac: not one of the 17 factors"):
        sepval.update([a], free=["wingfac"], out=tmp_path / "bad")
    assert not (tmp_path / "bad").exists()
