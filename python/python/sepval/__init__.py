"""sepval from Python: post-flight validation of store-separation simulations in a notebook.

The commands of the ``sepval`` command line, run in this process by the same code (the same
checks, the same messages, the same numbers bit for bit), with Python values in and out::

    import sepval
    data = sepval.simulate(noise_seed=7)                 # a DataFrame, metadata in .attrs
    fit = sepval.fit(data, generations=40, seed=3)       # the 17 factors, GA + LM
    fit.factors, fit.std_errors, fit.correlations
    d = sepval.diagnose(data, generations=20)            # what the simulation still gets wrong
    print(d.verdict)
    p = sepval.predict(fit, scenario=dict(sepval.scenario(), flight={...}))

Telemetry comes back as pandas DataFrames (numpy record arrays without pandas) with the
columns ``t_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg``; ``data=`` takes a path, a
DataFrame or a dict of arrays (or a list of them). Scenarios and factor sets are dicts.
Commands that write files return a result object (numbers as attributes, ``to_dict()``,
``out`` and ``files``). sepval's refusals raise ``SepvalError`` with the CLI's message; wrong
Python types raise ``TypeError``. Long commands release the GIL, take ``progress=callable``,
and stop on Ctrl-C (``KeyboardInterrupt``) with nothing half-written.
"""

from ._commands import (
    Goals,
    diagnose,
    effects,
    envelope,
    fit,
    goals,
    plan,
    predict,
    read_telemetry,
    scenario,
    simulate,
    update,
)
from ._errors import SepvalError, SepvalWarning
from ._frames import COLUMNS, Telemetry
from ._native import version as _version
from ._results import Diagnosis, Envelope, Fit, Plan, Prediction, Result, Update

__version__: str = _version()

__all__ = [
    "COLUMNS",
    "Diagnosis",
    "Envelope",
    "Fit",
    "Goals",
    "Plan",
    "Prediction",
    "Result",
    "SepvalError",
    "SepvalWarning",
    "Telemetry",
    "Update",
    "diagnose",
    "effects",
    "envelope",
    "fit",
    "goals",
    "plan",
    "predict",
    "read_telemetry",
    "scenario",
    "simulate",
    "update",
]
