"""Result objects: what a command wrote, read back from its JSON into attributes.

Every result has ``out`` (the output directory), ``files`` (every file written), ``summary``
(what the CLI prints on stdout), ``log`` (its notes and warnings) and ``to_dict()`` (the whole
JSON file, as written: its format is in docs/model.md). ``Fit.load(DIR)`` (and the others')
reads a directory written earlier, by the CLI or by Python.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path
from typing import Any, ClassVar, Dict, List, Optional

from . import _frames
from ._run import written

#: The six channels of a trajectory, as prediction.json names them.
CHANNELS = ("x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg")


class Result:
    """What one command wrote into its output directory."""

    #: The command (``fit``, ``diagnose``, ...).
    command: ClassVar[str] = ""
    #: The JSON file the attributes come from.
    record: ClassVar[str] = ""

    def __init__(self, out: Path, summary: str = "", log: Optional[List[str]] = None) -> None:
        #: The output directory.
        self.out: Path = Path(out)
        #: What the CLI prints on stdout for this run.
        self.summary: str = summary
        #: The CLI's notes and warnings (stderr), one per entry.
        self.log: List[str] = list(log or [])
        with open(self.out / self.record, encoding="utf-8") as f:
            self._record: Dict[str, Any] = json.load(f)
        #: Every file the command wrote (its lock and marker left out).
        self.files: List[Path] = written(self.out)
        self._read(self._record)

    @classmethod
    def load(cls, out: Any) -> "Result":
        """The result in a directory written earlier (by the CLI or by Python)."""
        return cls(Path(os.fspath(out)))

    def _read(self, r: Dict[str, Any]) -> None:
        raise NotImplementedError

    def to_dict(self) -> Dict[str, Any]:
        """The JSON file the command wrote, as a dict (a copy)."""
        return copy.deepcopy(self._record)

    @property
    def path(self) -> Path:
        """The JSON file the attributes come from."""
        return self.out / self.record

    def __repr__(self) -> str:
        return f"<sepval.{type(self).__name__} {self.out}>"


def _identifiability(r: Optional[Dict[str, Any]]) -> Dict[str, Any]:
    """Standard errors (by name; None where the data do not determine one) and the
    correlation matrix (a DataFrame, or a dict of dicts without pandas) of a refined fit."""
    if not r:
        return {"std_errors": {}, "correlations": None}
    names = r["names"]
    errors = {p["name"]: p["std_error"] for p in r["parameters"]}
    rows = {a: dict(zip(names, row)) for a, row in zip(names, r["correlation"])}
    try:
        import pandas
    except ImportError:
        return {"std_errors": errors, "correlations": rows}
    return {"std_errors": errors, "correlations": pandas.DataFrame(r["correlation"], index=names, columns=names)}


class Fit(Result):
    """A fit (``result.json``). The numbers are those of the best method (the smallest
    J_pos/sigma_pos + J_att/sigma_att): ``method``, ``factors`` (dict), ``j_pos_m``,
    ``j_att_deg``, ``evaluations``; ``std_errors`` (dict) and ``correlations`` (DataFrame) of
    the refinement (``+lm`` methods; empty and None otherwise); ``sigma_pos_m``,
    ``sigma_att_deg``; ``methods`` (every method's entry of result.json); ``truth`` (the true
    factors of synthetic data, else None)."""

    command = "fit"
    record = "result.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.methods: Dict[str, Any] = r["methods"]
        best = min(self.methods, key=lambda m: self.methods[m]["best"]["weighted"])
        b = self.methods[best]["best"]
        self.method: str = best
        self.factors: Dict[str, float] = dict(b["factors"])
        self.j_pos_m: float = b["j_pos_m"]
        self.j_att_deg: float = b["j_att_deg"]
        self.evaluations: int = b["evaluations"]
        self.sigma_pos_m: float = r["sigma_pos_m"]
        self.sigma_att_deg: float = r["sigma_att_deg"]
        self.truth: Optional[Dict[str, float]] = r.get("truth")
        self.identifiability: Optional[Dict[str, Any]] = r.get("identifiability")
        ident = _identifiability(self.identifiability)
        self.std_errors: Dict[str, Optional[float]] = ident["std_errors"]
        self.correlations: Any = ident["correlations"]

    def __repr__(self) -> str:
        return f"<sepval.Fit {self.method}: J_pos {self.j_pos_m:.4g} m, J_att {self.j_att_deg:.4g} deg in {self.out}>"


class Diagnosis(Result):
    """A diagnosis (``diagnosis.json``): ``verdict`` (the answer in words), ``explained``,
    ``causes`` (catalogue effects named), ``discovered`` (terms found beyond the catalogue),
    ``rivals`` (models the data cannot tell from the answer), ``caution``,
    ``baseline_converged``; ``baseline`` and ``extended`` (goals, chi2, per-channel RMS);
    ``factors`` (the answer's), ``parameters`` (each cause's, with standard errors),
    ``std_errors`` and ``correlations`` (the answer's refit), ``validation`` (held-out releases
    predicted); ``extension``: the ``extension.toml`` written when terms were found, else
    None."""

    command = "diagnose"
    record = "diagnosis.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.verdict: str = r["verdict"]
        self.explained: bool = r["explained"]
        self.causes: List[str] = r["causes"]
        self.discovered: List[Dict[str, Any]] = r["discovered"]
        self.rivals: List[Dict[str, Any]] = r["rivals"]
        self.caution: Optional[str] = r.get("caution")
        self.baseline_converged: bool = r["baseline_converged"]
        self.baseline: Dict[str, Any] = r["baseline"]
        self.extended: Dict[str, Any] = r["extended"]
        self.factors: Dict[str, float] = dict(r["model"]["factors"])
        self.parameters: Dict[str, List[Dict[str, Any]]] = r["parameters"]
        self.validation: List[Dict[str, Any]] = r["validation"]
        self.sigma_pos_m: float = r["sigma_pos_m"]
        self.sigma_att_deg: float = r["sigma_att_deg"]
        self.evaluations: int = r["evaluations"]
        self.identifiability: Optional[Dict[str, Any]] = r.get("identifiability")
        ident = _identifiability(self.identifiability)
        self.std_errors: Dict[str, Optional[float]] = ident["std_errors"]
        self.correlations: Any = ident["correlations"]
        extension = self.out / "extension.toml"
        self.extension: Optional[Path] = extension if extension.is_file() else None

    def __repr__(self) -> str:
        return f"<sepval.Diagnosis {self.verdict!r} in {self.out}>"


class Prediction(Result):
    """A prediction (``prediction.json``): ``level``, ``samples``, ``condition`` (dict),
    ``t_s``; ``bands``: a DataFrame of ``t_s`` and ``CHANNEL_lo``/``_mid``/``_hi`` for the six
    channels; ``sources``: each source's share of the band (``factors``, ``model_form``,
    ``measurement``) with ``dominant``; ``check``: the post-flight check of ``data=`` (with its
    ``verdict``), else None; ``verdict``: the check's verdict, else None; ``clearance``: the
    clearance distribution with ``aircraft=``, else None."""

    command = "predict"
    record = "prediction.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.level: float = r["level"]
        self.samples: int = r["samples"]
        self.condition: Dict[str, float] = r["condition"]
        self.t_s: List[float] = r["t_s"]
        self.bands: Any = _frames.band_table(r["t_s"], {c: r[c] for c in CHANNELS})
        sources = r["sources"]
        self.sources: Dict[str, Any] = {k: v["share"] for k, v in sources.items() if isinstance(v, dict) and "share" in v}
        self.dominant: Optional[str] = sources.get("dominant")
        self.check: Optional[Dict[str, Any]] = r.get("check")
        self.verdict: Optional[str] = (self.check or {}).get("verdict")
        self.clearance: Optional[Dict[str, Any]] = r.get("clearance")
        self.evaluations: int = r["evaluations"]

    def __repr__(self) -> str:
        return f"<sepval.Prediction at {self.condition} ({self.samples} samples) in {self.out}>"


class Plan(Result):
    """A plan (``plan.json``): ``conditions`` (a DataFrame, best first), ``recommended`` (the
    first condition, a dict, or None), ``ranked_by`` (``separation`` with rivals, else
    ``information``), ``models`` (the answer and its rivals)."""

    command = "plan"
    record = "plan.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.ranked_by: str = r["ranked_by"]
        self.models: List[Dict[str, Any]] = r["models"]
        self.recommended: Optional[Dict[str, Any]] = r["conditions"][0] if r["conditions"] else None
        self.conditions: Any = _frames.rows(r["conditions"])
        self.evaluations: int = r["evaluations"]

    def __repr__(self) -> str:
        best = self.recommended
        where = "nothing" if best is None else f"Mach {best['mach']}, alpha {best['alpha_deg']} deg, beta {best['beta_deg']} deg"
        return f"<sepval.Plan recommends {where} in {self.out}>"


class Envelope(Result):
    """An envelope (``envelope.json``): ``headline`` and ``lines`` (the answer in words),
    ``cleared`` of ``conditions``, ``criterion_mm``; ``rows``: a DataFrame, one row per
    condition (its flight condition, the clearance percentiles, the probabilities, whether it
    is cleared)."""

    command = "envelope"
    record = "envelope.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.headline: str = r["headline"]
        self.lines: List[str] = r["summary"]
        self.cleared: int = r["cleared"]
        self.conditions: int = r["conditions"]
        self.criterion_mm: float = r["criterion_mm"]
        flat = []
        for row in r["rows"]:
            item = {k: v for k, v in row.items() if k != "condition"}
            item.update(row["condition"])
            flat.append(item)
        self.rows: Any = _frames.rows(flat)
        self.evaluations: int = r["evaluations"]

    def __repr__(self) -> str:
        return f"<sepval.Envelope {self.headline!r} in {self.out}>"


class Update(Result):
    """An update of the store's aerodynamic data (``update.json``): ``verdict`` (the answer in
    words), ``corrections`` (a list of dicts: ``name``, ``field``, ``variable``,
    ``breakpoints``, ``values``, ``std``, ``explored``), ``factors`` (fitted with them),
    ``folds`` (a DataFrame: what each fold left out, and the RMS errors the data as given, the
    factors alone and the updated store predict for it), ``cannot_tell``, ``notes``; and the
    updated store, which every command takes as it is: ``scenario_path`` (``scenario.toml``, its
    tables under ``tables/``) and ``factors_path`` (``factors.json``)."""

    command = "update"
    record = "update.json"

    def _read(self, r: Dict[str, Any]) -> None:
        self.verdict: str = r["verdict"]
        self.corrections: List[Dict[str, Any]] = r["corrections"]
        self.factors: Dict[str, float] = r["fitted"]["factors"]
        self.goals: Dict[str, Optional[float]] = r["fitted"]["goals"]
        self.cannot_tell: List[str] = r["cannot_tell"]
        self.notes: List[str] = r["notes"]
        self.effective_parameters: float = r["effective_parameters"]
        flat = []
        for f in r["cross_validation"]["folds"]:
            item: Dict[str, Any] = {"held_out": f["held_out"]}
            for model in ("baseline", "factors_only", "updated"):
                item[f"{model}_j_pos_m"] = f[model]["j_pos_m"]
                item[f"{model}_j_att_deg"] = f[model]["j_att_deg"]
            flat.append(item)
        self.folds: Any = _frames.rows(flat)
        self.validation: List[Dict[str, Any]] = r["validation"]
        self.scenario_path: Path = self.out / "scenario.toml"
        self.factors_path: Path = self.out / "factors.json"
        self.evaluations: int = r["evaluations"]

    def __repr__(self) -> str:
        return f"<sepval.Update {len(self.corrections)} correction(s) in {self.out}>"
