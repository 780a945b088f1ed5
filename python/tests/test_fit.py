"""fit against `sepval fit`: the same inputs and seed give result.json's numbers bit for bit,
whether the data are given as files or as DataFrames; the result object; progress."""

from __future__ import annotations

import json

import pytest

import sepval
from conftest import BUDGET, cli_ok, deterministic, read_json


def test_fit_is_the_cli_bit_for_bit(cli, releases, tmp_path):
    cli_ok(cli(["fit", "--data", releases / "a.csv", "--data", releases / "b.csv", "--method", "ga+lm",
                "--seed", "5", *BUDGET, "--no-figures", "--out", tmp_path / "cli"], tmp_path))
    frames = [sepval.read_telemetry(releases / "a.csv"), sepval.read_telemetry(releases / "b.csv")]
    fit = sepval.fit(frames, seed=5, generations=4, population=40, workers=2, figures=False, out=tmp_path / "py")
    expected = read_json(tmp_path / "cli" / "result.json")
    assert deterministic(fit.to_dict()) == deterministic(expected)
    # Exactly: the JSON text of the numbers, not only their values.
    assert json.dumps(deterministic(fit.to_dict())) == json.dumps(deterministic(expected))
    # The data were stored as files that the result records, so that predict finds them.
    stored = fit.to_dict()["inputs"]["data"]
    assert len(stored) == 2 and all(sepval.read_telemetry(p).attrs["mach"] for p in stored)
    # The same fit from the files themselves.
    again = sepval.fit([releases / "a.csv", releases / "b.csv"], seed=5, generations=4, population=40, figures=False)
    assert deterministic(again.to_dict()) == deterministic(expected)


def test_the_result_has_the_numbers_as_attributes(tmp_path):
    events = []
    fit = sepval.fit(seed=2, generations=4, population=40, out=tmp_path / "run", progress=events.append)
    record = fit.to_dict()
    assert fit.method == "ga+lm" and fit.out == tmp_path / "run"
    assert fit.factors == record["methods"]["ga+lm"]["best"]["factors"]
    assert fit.j_pos_m == record["methods"]["ga+lm"]["best"]["j_pos_m"]
    assert set(fit.std_errors) == set(fit.factors)
    assert fit.correlations.shape == (17, 17)
    assert fit.correlations.loc["fwdfac", "fwdfac"] == pytest.approx(1.0)
    assert fit.truth == record["truth"] and fit.truth["fwdfac"] == 0.25
    assert (tmp_path / "run" / "result.json") in fit.files
    assert any(p.suffix == ".png" for p in fit.files)
    assert fit.summary.startswith("fit of embedded default synthetic flight test")
    assert sepval.Fit.load(tmp_path / "run").to_dict() == record
    # Progress: plain dicts, the GA's steps in order, then the refinement's.
    assert events[0] == {"event": "start", "stage": "ga", "steps": 4}
    steps = [e for e in events if e["event"] == "step" and e["stage"] == "ga"]
    assert [e["step"] for e in steps] == [1, 2, 3, 4]
    assert all(isinstance(e["j_pos_m"], float) for e in steps)
    assert {"start", "step", "finish"} == {e["event"] for e in events}


def test_out_none_writes_into_a_temporary_directory_that_stays(tmp_path):
    fit = sepval.fit(method="ga", generations=2, population=40, figures=False)
    try:
        assert fit.out.is_dir() and fit.out.name.startswith("sepval-fit-")
        assert (fit.out / "result.json").is_file()
        assert fit.std_errors == {} and fit.correlations is None
    finally:
        import shutil

        shutil.rmtree(fit.out)


def test_a_refused_fit_into_a_temporary_directory_leaves_nothing(tmp_path, monkeypatch):
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with pytest.raises(sepval.SepvalError, match="generations = 0: expected at least 1"):
        sepval.fit(generations=0)
    assert list(tmp_path.iterdir()) == []


def test_out_is_protected_as_the_cli_protects_it(cli, tmp_path):
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    expected = cli(["fit", *BUDGET, "--out", "busy"], tmp_path)
    with pytest.raises(sepval.SepvalError) as e:
        sepval.fit(generations=4, population=40, workers=2, out=tmp_path / "busy")
    assert "busy is not empty (it holds notes.txt)" in str(e.value)
    assert "busy is not empty (it holds notes.txt)" in expected.stderr
    with pytest.raises(sepval.SepvalError, match="not a sepval output directory"):
        sepval.fit(generations=4, population=40, out=tmp_path / "busy", overwrite=True)
    assert (tmp_path / "busy" / "notes.txt").read_text() == "mine"


def test_ipc_workers_give_the_same_bits(worker_binary, tmp_path, monkeypatch):
    monkeypatch.setenv("SEPVAL_WORKER", str(worker_binary))
    inproc = sepval.fit(seed=4, generations=3, population=40, figures=False, out=tmp_path / "inproc")
    ipc = sepval.fit(seed=4, generations=3, population=40, figures=False, evaluator="ipc", workers=2, out=tmp_path / "ipc")
    assert ipc.to_dict()["run"]["evaluator"].startswith("ipc")
    assert deterministic(ipc.to_dict()) == deterministic(inproc.to_dict())
