"""The exception and the warning of sepval."""

from ._native import SepvalError


class SepvalWarning(UserWarning):
    """What the CLI prints as ``warning: ...`` (a table left by a run, ...)."""


__all__ = ["SepvalError", "SepvalWarning"]
