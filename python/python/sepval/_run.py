"""Running one sepval command in this process, and the directory it writes into.

The words go to the CLI's own parser and the command runs the CLI's own code (``_native.run``)
on a thread of its own, the GIL released: other Python threads go on, Ctrl-C stops the command
within a second and raises ``KeyboardInterrupt``, and a progress callback that raises stops it
and its exception is raised. One command runs at a time in a process (sepval's cancellation
flag is process-wide); a second call waits for the first.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import warnings
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, Optional, Tuple

from . import _native
from ._errors import SepvalWarning

Progress = Optional[Callable[[Dict[str, Any]], Any]]


def check_progress(progress: Progress) -> None:
    """A progress callback is a callable or None."""
    if progress is not None and not callable(progress):
        raise TypeError(f"progress: expected a callable taking a dict, got {type(progress).__name__}")


def run(words: List[str], progress: Progress = None, worker: Optional[str] = None) -> Tuple[str, List[str]]:
    """Runs ``sepval WORDS...``; returns what it printed: its summary (stdout) and its notes
    (stderr lines). Its warnings (``warning: ...``) are also issued as ``SepvalWarning``."""
    check_progress(progress)
    out, err = _native.run(words, progress, worker)
    for line in err:
        if line.startswith("warning: "):
            warnings.warn(line[len("warning: "):], SepvalWarning, stacklevel=3)
    return out, err


@contextlib.contextmanager
def out_dir(out: Any, command: str) -> Iterator[Path]:
    """The output directory: ``out``, or with ``None`` a new temporary directory
    (``tempfile.mkdtemp``), kept after a call that succeeds (the result's ``out``; figures,
    pages, and ``from_`` of ``predict``, ``plan`` and ``envelope`` use it) and removed after
    one that fails."""
    if out is not None:
        if not isinstance(out, (str, os.PathLike)):
            raise TypeError(f"out: expected a path (str or os.PathLike) or None, got {type(out).__name__}")
        yield Path(os.fspath(out))
        return
    path = Path(tempfile.mkdtemp(prefix=f"sepval-{command}-"))
    try:
        yield path
    except BaseException:
        shutil.rmtree(path, ignore_errors=True)
        raise


def written(out: Path) -> List[Path]:
    """The files a command wrote into ``out`` (its lock and marker left out), sorted."""
    bookkeeping = set(_native.BOOKKEEPING)
    return sorted(p for p in out.rglob("*") if p.is_file() and p.name not in bookkeeping)
