"""Shared fixtures of the Python package's tests: the `sepval` binary to compare with (the
CLI's results are the reference, bit for bit), an input store of each test's own, and small
releases made by the CLI.

The binary is ``$SEPVAL_BIN``, else ``target/release/sepval`` of this clone (``cargo build
--release`` makes it; ``.ci/run`` builds it before pytest). Without it the comparisons are
skipped, except under CI (``CI`` set), where they fail.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any, Dict, List

import pytest

REPO = Path(__file__).resolve().parents[2]

#: The reduced budget of these tests: a few generations in process on two threads.
BUDGET = ["--generations", "4", "--population", "40", "--evaluator", "inproc", "--threads", "2"]


def _binary() -> Path:
    given = os.environ.get("SEPVAL_BIN")
    return Path(given) if given else REPO / "target" / "release" / "sepval"


@pytest.fixture(scope="session")
def cli_binary() -> Path:
    path = _binary()
    if not path.is_file():
        message = f"{path} is missing: build it with `cargo build --release` or set SEPVAL_BIN"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def worker_binary(cli_binary: Path) -> Path:
    """The `sepval-worker` built beside the `sepval` binary."""
    path = cli_binary.with_name("sepval-worker")
    if not path.is_file():
        pytest.fail(f"{path} is missing: build it with `cargo build --release`")
    return path


@pytest.fixture()
def cli(cli_binary: Path):
    """Runs the CLI: ``cli(args, cwd) -> CompletedProcess`` (text, never raises)."""

    def run(args: List[str], cwd: Path) -> subprocess.CompletedProcess:
        return subprocess.run([str(cli_binary), *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=600)

    return run


def cli_ok(result: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    assert result.returncode == 0, result.stderr
    return result


def cli_error(result: subprocess.CompletedProcess) -> str:
    """The CLI's message of a refusal (what follows `sepval: error:`)."""
    assert result.returncode == 2, (result.returncode, result.stderr)
    line = result.stderr.strip().splitlines()[-1]
    prefix = "sepval: error: "
    assert line.startswith(prefix), result.stderr
    return result.stderr.strip()[len(prefix):] if result.stderr.startswith(prefix) else line[len(prefix):]


@pytest.fixture(autouse=True)
def store(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Each test's own input store (``SEPVAL_INPUT_DIR``), so that nothing it writes outlives
    it and a test can see that nothing was written."""
    path = tmp_path_factory.mktemp("store")
    monkeypatch.setenv("SEPVAL_INPUT_DIR", str(path))
    return path


def deterministic(record: Any) -> Any:
    """A result file without what depends on the run rather than on its inputs: wall times,
    `run`, where the inputs and the source were (paths), the names of the events (paths), and
    the record's `digest` (of all of it, those included)."""
    if isinstance(record, dict):
        return {
            k: deterministic(v)
            for k, v in record.items()
            if k not in ("wall_s", "run", "inputs", "from", "name", "event", "release", "progress", "digest")
        }
    if isinstance(record, list):
        return [deterministic(v) for v in record]
    return record


def read_json(path: Path) -> Dict[str, Any]:
    with open(path, encoding="utf-8") as f:
        return json.load(f)


@pytest.fixture(scope="session")
def releases(tmp_path_factory: pytest.TempPathFactory, cli_binary: Path) -> Path:
    """Two noisy releases of the default store made by the CLI, at Mach 0.8 and at Mach 0.9
    with alpha 3 deg (their metadata carries the condition), and `cond.toml`, a condition to
    predict (Mach 0.7, alpha 1.5 deg, beta -2 deg)."""
    d = tmp_path_factory.mktemp("releases")
    run = lambda *a: cli_ok(subprocess.run([str(cli_binary), *a], cwd=d, capture_output=True, text=True, timeout=600))
    run("scenario", "--out", "default.toml")
    text = (d / "default.toml").read_text()
    for name, mach, alpha, beta in (("a", 0.8, 0.0, 0.0), ("b", 0.9, 3.0, 0.0), ("cond", 0.7, 1.5, -2.0)):
        (d / f"{name}.toml").write_text(
            text.replace("mach = 0.95", f"mach = {mach}")
            .replace("alpha_deg = 0.0", f"alpha_deg = {alpha}", 1)
            .replace("beta_deg = 0.0", f"beta_deg = {beta}", 1)
        )
    run("simulate", "--scenario", "a.toml", "--noise-seed", "1", "--out", "a.csv")
    run("simulate", "--scenario", "b.toml", "--noise-seed", "2", "--out", "b.csv")
    return d
