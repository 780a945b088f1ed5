"""The commands: each builds the words of one ``sepval`` command from its keyword arguments
(checked for their Python types; their values are checked by the command itself, with the
CLI's messages), runs it in this process, and reads what it wrote.

A command that runs long (``fit``, ``diagnose``, ``predict``, ``plan``, ``envelope``) takes:

- ``evaluator``: ``"inproc"`` (threads of this process, the default: no worker executable
  needed) or ``"ipc"`` (``sepval-worker`` processes over shared memory, found as
  ``$SEPVAL_WORKER`` or on the ``PATH``); ``workers``: how many threads or processes (the number
  of cores by default);
- ``progress``: a callable receiving a dict for each event: ``{"event": "start", "stage",
  "steps"}``, ``{"event": "step", "stage", "step", "steps", "evaluations", "j_pos_m",
  "j_att_deg"}``, ``{"event": "finish", "stage"}``; the command waits while it runs, and one
  that raises stops the command and its exception is raised;
- ``out``: the output directory (absent or empty; ``overwrite=True`` clears an earlier sepval
  run), or ``None`` for a new temporary directory that is kept and is the result's ``out``;
- the result object: the numbers as attributes, ``to_dict()`` (the JSON the command wrote),
  ``out``, ``files`` (every file written), ``summary`` (what the CLI prints) and ``log``.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Type, TypeVar

from . import _frames, _native
from . import _inputs as inputs
from ._results import Diagnosis, Envelope, Fit, Plan, Prediction, Result, Update
from ._run import Progress, check_progress, out_dir, run

R = TypeVar("R", bound=Result)


def _run_into(
    kind: Type[R],
    words: List[str],
    stored: Callable[[bool], List[str]],
    out: Any,
    overwrite: bool,
    progress: Progress,
    worker: Optional[str],
) -> R:
    """Runs a command that writes an output directory and reads its result. ``words`` are the
    flags already checked; ``stored(write)`` gives those of the values that go to the input
    store: called once to check them all (``write=False``), once everything else is checked,
    then to write them."""
    if not isinstance(overwrite, bool):
        raise TypeError(f"overwrite: expected a bool, got {type(overwrite).__name__}")
    check_progress(progress)
    stored(False)
    with out_dir(out, kind.command) as path:
        words = [kind.command, *words, *stored(True), "--out", str(path)] + (["--overwrite"] if overwrite else [])
        summary, log = run(words, progress, worker)
        return kind(path, summary, log)


def _source(from_: Any) -> str:
    """The directory a command reads a fit or a diagnosis from: a path or a result."""
    if isinstance(from_, Result):
        return str(from_.out)
    return inputs.path_word("from_", from_)


def _geometry(words: List[str], aircraft: Any, store_shape: Any, clearance_mm: Any) -> None:
    inputs.flags(words, (("aircraft", aircraft, "path"), ("store_shape", store_shape, "path"), ("clearance_mm", clearance_mm, "number")))


def _search(extension: Any, seed: Any, generations: Any, population: Any, lm_budget: Any, sigma: Tuple[Any, Any], strict_tables: Any) -> List[str]:
    """The flags fit and diagnose share: the model's extension, the baseline search, the
    noise that weights the goals, the tables' strictness."""
    words: List[str] = []
    inputs.flags(words, (
        ("extension", extension, "path"),
        ("seed", seed, "int"),
        ("generations", generations, "int"),
        ("population", population, "int"),
        ("lm_budget", lm_budget, "int"),
        ("sigma_pos_m", sigma[0], "number"),
        ("sigma_att_deg", sigma[1], "number"),
        ("strict_tables", strict_tables, "switch"),
    ))
    return words


def simulate(
    scenario: Any = None,
    factors: Any = "truth",
    effects: Any = None,
    extension: Any = None,
    t_end_s: Optional[float] = None,
    rate_hz: Optional[float] = None,
    noise_seed: Optional[int] = None,
    strict_tables: bool = False,
    out: Any = None,
) -> Any:
    """Simulates a release (``sepval simulate``): its trajectory as a DataFrame (a numpy record
    array without pandas) with the telemetry columns and the file's metadata in ``attrs``.

    ``scenario``: a path, a dict (as ``scenario()`` returns) or None for the embedded default;
    ``factors``: ``"truth"``, ``"nominal"``, a JSON file or a dict of the 17 factors;
    ``effects``: catalogue effects switched on, ``{"roll_due_to_sideslip": -0.3}`` (see
    ``effects()``); ``extension``: a TOML file of terms (``diagnose`` writes one);
    ``t_end_s``, ``rate_hz``: the event's length and rate (the scenario's by default);
    ``noise_seed``: measurement noise (0.003 m, 0.1 deg) from this seed, none without;
    ``strict_tables``: refuse a run that leaves one of the scenario's tables; ``out``: also
    write the CSV there, exactly as the CLI does."""
    words = ["simulate"]
    inputs.flag(words, "extension", extension)
    words += inputs.effect_words(effects)
    inputs.flag(words, "noise_seed", noise_seed, "int")
    inputs.flag(words, "t_end", t_end_s, "number")
    inputs.flag(words, "rate", rate_hz, "number")
    inputs.flag(words, "strict_tables", strict_tables, "switch")
    inputs.scenario_path(scenario, write=False)
    inputs.factors_word(factors, scenario, write=False)
    inputs.flag(words, "scenario", inputs.scenario_path(scenario))
    words += ["--factors", inputs.factors_word(factors, scenario)]
    if out is not None:
        path = Path(inputs.path_word("out", out))
        run(words + ["--out", str(path)])
        return read_telemetry(path)
    scratch = Path(tempfile.mkdtemp(prefix="sepval-simulate-"))
    try:
        run(words + ["--out", str(scratch / "simulated.csv")])
        return read_telemetry(scratch / "simulated.csv")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def read_telemetry(path: Any) -> Any:
    """Reads a telemetry CSV (docs/model.md section 6) as sepval reads it: a DataFrame (a numpy
    record array without pandas) with ``attrs`` holding its ``# key = value`` metadata. A file
    sepval refuses raises ``SepvalError`` naming the line and column."""
    return _frames.table(_native.read_telemetry(inputs.path_word("path", path)))


def goals(data: Any, sim: Any) -> "Goals":
    """J_pos [m] and J_att [deg] of ``sim`` against ``data`` (``sepval goals``, unrounded):
    each a path, a DataFrame or a dict of arrays, at the same sample times."""
    j = _native.goals(inputs.telemetry_source(data, "data"), inputs.telemetry_source(sim, "sim"))
    return Goals(*j)


class Goals(NamedTuple):
    """J_pos [m] and J_att [deg] of a trajectory against data."""

    #: RMS position error [m].
    j_pos_m: float
    #: RMS attitude error [deg].
    j_att_deg: float


def fit(
    data: Any = None,
    method: str = "ga+lm",
    scenario: Any = None,
    extension: Any = None,
    seed: int = 1,
    generations: Optional[int] = None,
    population: Optional[int] = None,
    lm_budget: Optional[int] = None,
    hill_budget: Optional[int] = None,
    sigma_pos_m: Optional[float] = None,
    sigma_att_deg: Optional[float] = None,
    resume: Any = None,
    figures: bool = True,
    strict_tables: bool = False,
    aircraft: Any = None,
    store_shape: Any = None,
    clearance_mm: Optional[float] = None,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Fit:
    """Fits the 17 factors to measured releases (``sepval fit``).

    ``data``: a release or a list of them (paths, DataFrames or dicts of arrays; their
    ``# mach = ...`` metadata sets each one's flight condition), None for the embedded
    synthetic flight test; ``method``: ``"ga+lm"`` (the study's GA, then Levenberg-Marquardt to
    the noise floor with standard errors and correlations), ``"hill+lm"``, ``"ga"``,
    ``"hill"`` or ``"both"``; ``seed``, ``generations`` (500), ``population`` (100),
    ``lm_budget`` (5000), ``hill_budget`` (500): the searches (CLI defaults in brackets);
    ``sigma_pos_m``, ``sigma_att_deg``: the noise that weights the goals (estimated from the
    data by default); ``resume``: a checkpoint ``OUT/generations/gen-NNNN.json`` to go on from;
    ``figures``: draw ``figures/*.png``; ``aircraft``, ``store_shape``, ``clearance_mm``: the
    clearance of the best fit's trajectories. See the module's notes for ``evaluator``,
    ``workers``, ``out``, ``overwrite`` and ``progress``."""
    if not isinstance(method, str):
        raise TypeError(f"method: expected a str, got {type(method).__name__}")
    words = ["--method", method]
    words += _search(extension, seed, generations, population, lm_budget, (sigma_pos_m, sigma_att_deg), strict_tables)
    inputs.flags(words, (("hill_budget", hill_budget, "int"), ("resume", resume, "path")))
    if not isinstance(figures, bool):
        raise TypeError(f"figures: expected a bool, got {type(figures).__name__}")
    inputs.flag(words, "no_figures", not figures, "switch")
    _geometry(words, aircraft, store_shape, clearance_mm)
    flags, worker = inputs.evaluator_words(evaluator, workers)
    stored = lambda write: inputs.data_words("--data", data, "data", write) + inputs.scenario_words(scenario, write)
    return _run_into(Fit, words + flags, stored, out, overwrite, progress, worker)


def diagnose(
    data: Any = None,
    validate: Any = None,
    scenario: Any = None,
    extension: Any = None,
    seed: int = 1,
    generations: Optional[int] = None,
    population: Optional[int] = None,
    lm_budget: Optional[int] = None,
    sigma_pos_m: Optional[float] = None,
    sigma_att_deg: Optional[float] = None,
    strict_tables: bool = False,
    aircraft: Any = None,
    store_shape: Any = None,
    clearance_mm: Optional[float] = None,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Diagnosis:
    """What the simulation still gets wrong after a fit, and why (``sepval diagnose``).

    ``data``: the releases to fit (as for ``fit``); ``validate``: releases that take no part
    in any fit, predicted by the baseline, the answer and the alternatives; ``seed``,
    ``generations`` (60), ``population`` (100), ``lm_budget`` (3000): the baseline fit's
    search; the rest as for ``fit``."""
    words = _search(extension, seed, generations, population, lm_budget, (sigma_pos_m, sigma_att_deg), strict_tables)
    _geometry(words, aircraft, store_shape, clearance_mm)
    flags, worker = inputs.evaluator_words(evaluator, workers)

    def stored(write: bool) -> List[str]:
        releases = inputs.data_words("--data", data, "data", write)
        return releases + inputs.data_words("--validate", validate, "validate", write) + inputs.scenario_words(scenario, write)

    return _run_into(Diagnosis, words + flags, stored, out, overwrite, progress, worker)


def predict(
    from_: Any,
    scenario: Any,
    extension: Any = None,
    samples: Optional[int] = None,
    level: Optional[float] = None,
    seed: int = 1,
    with_noise: bool = False,
    data: Any = None,
    validate: Any = None,
    aircraft: Any = None,
    store_shape: Any = None,
    clearance_mm: Optional[float] = None,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Prediction:
    """A release not flown, with bands (``sepval predict``).

    ``from_``: a fit (``method="ga+lm"`` or ``"hill+lm"``) or a diagnosis: its result or its
    directory; ``scenario``: the condition to predict, a scenario (path or dict) of the store
    fitted with the condition in ``flight``; ``samples`` (1000), ``level`` (0.95), ``seed``:
    the draws; ``with_noise``: include the measurement noise; ``data``: a release flown at the
    condition, checked against the bands; ``validate``: releases held out of the fit that
    calibrate the model-form discrepancy; ``aircraft``...: the clearance of every sample."""
    words = ["--from", _source(from_)]
    if scenario is None:
        raise TypeError("scenario: expected the condition to predict, a path or a dict")
    inputs.flag(words, "extension", extension)
    inputs.flag(words, "samples", samples, "int")
    inputs.flag(words, "level", level, "number")
    inputs.flags(words, (("seed", seed, "int"), ("with_noise", with_noise, "switch")))
    if isinstance(data, (list, tuple)):
        raise TypeError("data: expected one release flown at the condition, got a list")
    _geometry(words, aircraft, store_shape, clearance_mm)
    flags, worker = inputs.evaluator_words(evaluator, workers)

    def stored(write: bool) -> List[str]:
        releases = inputs.data_words("--data", data, "data", write)
        releases += inputs.data_words("--validate", validate, "validate", write)
        return releases + ["--scenario", inputs.scenario_path(scenario, write) or ""]

    return _run_into(Prediction, words + flags, stored, out, overwrite, progress, worker)


def plan(
    from_: Any,
    mach: Optional[Sequence[float]] = None,
    altitude_m: Optional[Sequence[float]] = None,
    alpha_deg: Optional[Sequence[float]] = None,
    beta_deg: Optional[Sequence[float]] = None,
    gamma_deg: Optional[Sequence[float]] = None,
    points: Optional[int] = None,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Plan:
    """The next release to fly (``sepval plan``), from a diagnosis (its result or directory).

    Each axis given is a range ``(lo, hi)`` of candidate conditions, ``points`` (9) per axis;
    an axis not given stays at the first release's condition."""
    words = ["--from", _source(from_)]
    for name, value in (("mach", mach), ("altitude_m", altitude_m), ("alpha_deg", alpha_deg), ("beta_deg", beta_deg), ("gamma_deg", gamma_deg)):
        inputs.flag(words, name, value, "range")
    inputs.flag(words, "points", points, "int")
    flags, worker = inputs.evaluator_words(evaluator, workers)
    return _run_into(Plan, words + flags, lambda write: [], out, overwrite, progress, worker)


def envelope(
    from_: Any,
    aircraft: Any,
    mach: Optional[Sequence[float]] = None,
    altitude_m: Optional[Sequence[float]] = None,
    alpha_deg: Optional[Sequence[float]] = None,
    beta_deg: Optional[Sequence[float]] = None,
    gamma_deg: Optional[Sequence[float]] = None,
    extension: Any = None,
    samples: Optional[int] = None,
    seed: int = 1,
    validate: Any = None,
    store_shape: Any = None,
    clearance_mm: Optional[float] = None,
    resume: bool = False,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Envelope:
    """The separation envelope (``sepval envelope``): the clearance to ``aircraft`` predicted
    over a grid of conditions from a fit (``ga+lm``) or a diagnosis.

    Each axis given is ``(lo, hi, n)``; ``samples`` (1000) per condition; ``resume=True`` goes
    on with the interrupted sweep in ``out``."""
    words = ["--from", _source(from_)]
    for name, value in (("mach", mach), ("altitude_m", altitude_m), ("alpha_deg", alpha_deg), ("beta_deg", beta_deg), ("gamma_deg", gamma_deg)):
        inputs.flag(words, name, value, "axis")
    inputs.flag(words, "extension", extension)
    inputs.flag(words, "samples", samples, "int")
    inputs.flag(words, "seed", seed, "int")
    _geometry(words, aircraft, store_shape, clearance_mm)
    inputs.flag(words, "resume", resume, "switch")
    flags, worker = inputs.evaluator_words(evaluator, workers)
    stored = lambda write: inputs.data_words("--validate", validate, "validate", write)
    return _run_into(Envelope, words + flags, stored, out, overwrite, progress, worker)


def update(
    data: Any,
    validate: Any = None,
    scenario: Any = None,
    extension: Any = None,
    free: Optional[List[str]] = None,
    seed: int = 1,
    generations: Optional[int] = None,
    population: Optional[int] = None,
    lm_budget: Optional[int] = None,
    sigma_pos_m: Optional[float] = None,
    sigma_att_deg: Optional[float] = None,
    evaluator: str = "inproc",
    workers: Optional[int] = None,
    out: Any = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Update:
    """The store's aerodynamic data updated from its releases (``sepval update``): corrections
    as tables in the scenario's own form, fitted with the factors and kept only as far as they
    predict a release they were not fitted to.

    ``data``: the releases (as for ``fit``; their metadata sets each flight condition);
    ``validate``: releases never fitted, predicted by the data as given, the factors alone and
    the updated store; ``free``: the factors fitted with the corrections (names; all 17 by
    default); ``seed``, ``generations`` (60), ``population`` (100), ``lm_budget`` (3000): the
    baseline fit's search; the rest as for ``fit``. The result's ``scenario_path`` and
    ``factors_path`` are the updated store and its factors."""
    words = _search(extension, seed, generations, population, lm_budget, (sigma_pos_m, sigma_att_deg), None)
    if free is not None:
        if isinstance(free, str) or not all(isinstance(f, str) for f in free):
            raise TypeError("free: expected a list of factor names (str)")
        words += ["--free", ",".join(free)]
    flags, worker = inputs.evaluator_words(evaluator, workers)

    def stored(write: bool) -> List[str]:
        releases = inputs.data_words("--data", data, "data", write)
        return releases + inputs.data_words("--validate", validate, "validate", write) + inputs.scenario_words(scenario, write)

    return _run_into(Update, words + flags, stored, out, overwrite, progress, worker)


def scenario(path: Any = None) -> Dict[str, Any]:
    """A scenario as a dict (the embedded default, Eglin benchmark store, without ``path``):
    what ``sepval scenario`` writes, its tables inline. Change it and give it back as
    ``scenario=``."""
    import json

    return json.loads(_native.scenario_json(None if path is None else inputs.path_word("path", path)))


def effects() -> List[Dict[str, Any]]:
    """The effect catalogue (``sepval effects``): ``id``, ``adds`` and ``params`` (``name``,
    ``unit``, ``neutral``, ``min``, ``max``) of each."""
    return list(_native.effects())


__all__: Tuple[str, ...] = (
    "simulate",
    "read_telemetry",
    "goals",
    "Goals",
    "fit",
    "diagnose",
    "predict",
    "plan",
    "envelope",
    "scenario",
    "effects",
)
