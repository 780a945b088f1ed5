"""What Python gives, turned into the words of a sepval command.

A command takes files. A path is passed as it is; a value (a DataFrame or a dict of arrays for
telemetry, a dict for a scenario or a factor set) is checked by sepval's own reader, so that it
is refused with the CLI's message, and written to the input store, named by its content: the
commands record the paths of their inputs (``result.json``'s ``inputs``), and ``predict``,
``plan`` and ``envelope`` read them again from there. The store is ``$SEPVAL_INPUT_DIR``, else
``$XDG_CACHE_HOME/sepval/inputs`` (``~/.cache/sepval/inputs``). Every value of a call is
checked before any is written.

Telemetry values become CSV text: a header of the column names, one row a sample (numbers in
the shortest form that reads back as the same double, so nothing is rounded), then the
``attrs`` as ``# key = value`` lines, after the rows so that line 2 is the first row in
messages.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _native

#: A float the scenario's JSON cannot carry (NaN, infinities), as the Rust side reads it back.
_NONFINITE = "__sepval_nonfinite__:"


def store_dir() -> Path:
    """The input store: ``$SEPVAL_INPUT_DIR``, else the user's cache directory."""
    given = os.environ.get("SEPVAL_INPUT_DIR")
    if given:
        return Path(given)
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(cache) / "sepval" / "inputs"


def is_path(value: Any) -> bool:
    """Whether ``value`` names a file."""
    return isinstance(value, (str, os.PathLike))


def integer(name: str, value: Any) -> int:
    """An integer argument (an int or a numpy integer; not a bool)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__} {value!r}")
    return int(value)


def number(name: str, value: Any) -> float:
    """A real argument (int or float, numpy's too; NaN passes, for sepval to refuse)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__} {value!r}")
    return float(value)


def word(value: float) -> str:
    """A float as a command-line word that reads back as the same double."""
    return repr(float(value))


def path_word(name: str, value: Any) -> str:
    """A path argument as a word."""
    if not is_path(value):
        raise TypeError(f"{name}: expected a path (str or os.PathLike), got {type(value).__name__}")
    return os.fspath(value)


def flag(words: List[str], name: str, value: Any, kind: str = "path") -> None:
    """Appends ``--name value`` when ``value`` is given, checked as ``kind`` (path, int,
    number, range: two numbers LO:HI, or axis: LO:HI:N), or ``--name`` alone for a switch
    (a bool) that is on."""
    if value is None:
        return
    option = "--" + name.replace("_", "-")
    if kind == "switch":
        if not isinstance(value, bool):
            raise TypeError(f"{name}: expected a bool, got {type(value).__name__}")
        if value:
            words.append(option)
        return
    if kind == "path":
        text = path_word(name, value)
    elif kind == "int":
        text = str(integer(name, value))
    elif kind == "number":
        text = word(number(name, value))
    elif kind == "range":
        text = _numbers(name, value, 2, "(lo, hi)")
    elif kind == "axis":
        text = _numbers(name, value, 3, "(lo, hi, n)")
    else:
        raise ValueError(f"unknown kind of flag {kind}")
    words += [option, text]


def flags(words: List[str], given: Sequence[Tuple[str, Any, str]]) -> None:
    """``flag`` for each ``(name, value, kind)``."""
    for name, value, kind in given:
        flag(words, name, value, kind)


def _numbers(name: str, value: Any, count: int, shape: str) -> str:
    if not isinstance(value, (tuple, list)) or len(value) != count:
        raise TypeError(f"{name}: expected {shape}, got {value!r}")
    parts = [word(number(name, v)) for v in value[:2]]
    if count == 3:
        parts.append(str(integer(name, value[2])))
    return ":".join(parts)


def evaluator_words(evaluator: str, workers: Optional[int]) -> Tuple[List[str], Optional[str]]:
    """The evaluator flags and the worker executable. ``inproc`` (threads of this process,
    ``workers`` of them) needs nothing else; ``ipc`` starts ``workers`` ``sepval-worker``
    processes, found as ``$SEPVAL_WORKER`` or on the ``PATH``."""
    if evaluator not in ("inproc", "ipc"):
        raise ValueError(f"evaluator={evaluator!r}: expected 'inproc' or 'ipc'")
    words = ["--evaluator", evaluator]
    if workers is not None:
        words += ["--threads" if evaluator == "inproc" else "--workers", str(integer("workers", workers))]
    worker = None
    if evaluator == "ipc":
        worker = os.environ.get("SEPVAL_WORKER") or shutil.which("sepval-worker")
    return words, worker


# --- telemetry -----------------------------------------------------------------------------


def _is_frame(value: Any) -> bool:
    try:
        import pandas
    except ImportError:
        return False
    return isinstance(value, pandas.DataFrame)


def _cell(text: str) -> str:
    # The telemetry reader splits rows on commas and takes a quote as a field's enclosure: text
    # that is no number is refused whatever it holds, so only its shape is kept.
    return text.replace(",", ";").replace('"', "'").replace("\n", " ").replace("\r", " ")


def _cells(name: str, column: str, values: Any) -> List[str]:
    array = np.asarray(values)
    if array.ndim != 1:
        raise TypeError(f"{name}: column {column!r}: expected a one-dimensional array, got {array.ndim} dimensions")
    if array.dtype.kind == "f":
        return [repr(v) for v in array.astype(np.float64).tolist()]
    if array.dtype.kind in "iu":
        return [str(v) for v in array.tolist()]
    return [_cell(str(v)) for v in array.tolist()]


def _columns(value: Any, name: str) -> Tuple[List[str], List[List[str]], Mapping]:
    """The headers, the cells of each column and the metadata of a table of telemetry."""
    kind = _kind(value)
    if kind == "a DataFrame":
        headers = [str(c) for c in value.columns]
        cells = [_cells(name, h, value[c].to_numpy()) for h, c in zip(headers, value.columns)]
        return headers, cells, value.attrs
    if kind == "a record array":
        headers = list(value.dtype.names)
        cells = [_cells(name, h, value[h]) for h in headers]
        return headers, cells, getattr(value, "attrs", {}) or {}
    headers = [str(k) for k in value]
    cells = [_cells(name, h, v) for h, v in zip(headers, value.values())]
    return headers, cells, {}


def telemetry_text(value: Any, name: str) -> str:
    """CSV text of a DataFrame, a numpy record array or a dict of arrays."""
    headers, cells, attrs = _columns(value, name)
    lengths = {len(c) for c in cells}
    if len(lengths) > 1:
        counts = ", ".join(f"{h} {len(c)}" for h, c in zip(headers, cells))
        raise ValueError(f"{name}: columns of different lengths ({counts})")
    lines = [",".join(_cell(h) for h in headers)]
    lines += [",".join(row) for row in zip(*cells)]
    lines += [f"# {_cell(str(k))} = {_cell(str(v))}" for k, v in attrs.items()]
    return "\n".join(lines) + "\n"


def _kind(value: Any) -> Optional[str]:
    """What kind of table of telemetry ``value`` is, in words; None for none."""
    if _is_frame(value):
        return "a DataFrame"
    if isinstance(value, np.ndarray) and value.dtype.names:
        return "a record array"
    if isinstance(value, Mapping):
        return "a dict of arrays"
    return None


def telemetry_name(value: Any, name: str) -> str:
    """How messages name a value given as telemetry (a TypeError for no such value)."""
    kind = _kind(value)
    if kind is None:
        raise TypeError(
            f"{name}: expected a path (str or os.PathLike), a pandas DataFrame or a dict of arrays, "
            f"got {type(value).__name__}"
        )
    return f"{name} ({kind}; line 2 is its first row)"


def telemetry_source(value: Any, name: str) -> Tuple[str, str, str]:
    """A trajectory for the native readers: ``("path", PATH, "")`` or ``("text", CSV, NAME)``."""
    if is_path(value):
        return ("path", os.fspath(value), "")
    label = telemetry_name(value, name)
    return ("text", telemetry_text(value, label), label)


def releases(value: Any, name: str) -> List[Any]:
    """One release or several (a list or tuple of them); none for ``None``."""
    if value is None:
        return []
    if isinstance(value, (list, tuple)):
        return list(value)
    return [value]


def data_words(option: str, value: Any, name: str, write: bool = True) -> List[str]:
    """``--option FILE`` for each release of ``value``: paths as given, values checked and
    stored (all checked before any is written; nothing written without ``write``)."""
    items = releases(value, name)
    listed = isinstance(value, (list, tuple))
    texts = []
    for k, item in enumerate(items):
        if not is_path(item):
            label = telemetry_name(item, f"{name}[{k}]" if listed else name)
            texts.append((telemetry_text(item, label), label))
    stored = iter(_native.store_telemetry(texts, store_dir(), write) if texts else [])
    words: List[str] = []
    for item in items:
        words += [option, os.fspath(item) if is_path(item) else os.fspath(next(stored))]
    return words


# --- scenarios and factor sets -------------------------------------------------------------


def _carried(value: Any) -> Any:
    """``value`` for JSON: non-finite floats marked for the Rust side, numpy scalars as
    Python's."""
    if isinstance(value, Mapping):
        return {str(k): _carried(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_carried(v) for v in value]
    if isinstance(value, (float, np.floating)) and not math.isfinite(value):
        return _NONFINITE + repr(float(value))
    if isinstance(value, np.generic):
        return value.item()
    return value


def _scenario_json(scenario: Mapping) -> str:
    return json.dumps(_carried(scenario))


def scenario_path(scenario: Any, write: bool = True) -> Optional[str]:
    """The scenario file of ``scenario``: a path, or a dict checked and stored (nothing
    written without ``write``); ``None`` for the embedded default."""
    if scenario is None:
        return None
    if is_path(scenario):
        return os.fspath(scenario)
    if not isinstance(scenario, Mapping):
        raise TypeError(f"scenario: expected a path or a dict, got {type(scenario).__name__}")
    return os.fspath(_native.store_scenario(_scenario_json(scenario), "(a dict)", store_dir(), write))


def scenario_words(scenario: Any, write: bool = True) -> List[str]:
    """``--scenario FILE`` for a scenario given (see ``scenario_path``)."""
    path = scenario_path(scenario, write)
    return [] if path is None else ["--scenario", path]


def factors_word(factors: Any, scenario: Any, write: bool = True) -> str:
    """``--factors``: ``truth``, ``nominal``, a path, or a dict checked against the factor
    table of ``scenario`` (as given: None, a path or a dict) and stored (nothing written
    without ``write``)."""
    if isinstance(factors, str) and factors in ("truth", "nominal"):
        return factors
    if is_path(factors):
        return os.fspath(factors)
    if not isinstance(factors, Mapping):
        raise TypeError(f"factors: expected 'truth', 'nominal', a path or a dict, got {type(factors).__name__}")
    values = {}
    for k, v in factors.items():
        values[str(k)] = number(f"factors[{k!r}]", v)
        if not math.isfinite(values[str(k)]):
            raise ValueError(f"factors[{k!r}] = {v!r}: expected a finite number")
    given = {"scenario_path": os.fspath(scenario)} if is_path(scenario) else {}
    if isinstance(scenario, Mapping):
        given = {"scenario_json": _scenario_json(scenario)}
    path = _native.store_factors(json.dumps(values), "(a dict)", store_dir(), write, **given)
    return os.fspath(path)


def effect_words(effects: Any) -> List[str]:
    """``--effect ID=V1,V2`` for each effect: a dict of id to a value or a list of values, or a
    list of ``"ID=V1,V2"`` strings."""
    if effects is None:
        return []
    if isinstance(effects, Mapping):
        specs = []
        for k, v in effects.items():
            values = v if isinstance(v, (list, tuple)) else [v]
            specs.append(f"{k}=" + ",".join(word(number(f"effects[{k!r}]", x)) for x in values))
    elif isinstance(effects, (list, tuple)) and all(isinstance(e, str) for e in effects):
        specs = list(effects)
    else:
        raise TypeError("effects: expected a dict of id to values, or a list of 'ID=V1,V2' strings")
    words: List[str] = []
    for s in specs:
        words += ["--effect", s]
    return words
