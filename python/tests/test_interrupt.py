"""KeyboardInterrupt and exceptions raised while a command runs: the command stops (sepval's
cancellation flag), the exception is raised, nothing is half-written (the checkpoints of the
generations done stay, as after Ctrl-C on the CLI; no result.json), and the next call runs
(the flag was withdrawn)."""

from __future__ import annotations

import signal
import threading

import pytest

import sepval


def test_a_callback_raising_keyboardinterrupt_stops_the_fit(tmp_path):
    seen = []

    def interrupt(event):
        seen.append(event)
        if event["event"] == "step" and event["step"] == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sepval.fit(generations=500, population=40, workers=2, out=tmp_path / "run", progress=interrupt)
    # It stopped at once: no step after the one that raised, no result.
    assert seen[-1]["step"] == 2
    assert not (tmp_path / "run" / "result.json").exists()
    checkpoints = sorted(p.name for p in (tmp_path / "run" / "generations").iterdir())
    assert checkpoints == ["gen-0001.json", "gen-0002.json"]
    # The flag is down again: the next call runs, and resumes from the checkpoint kept.
    fit = sepval.fit(generations=4, population=40, workers=2, out=tmp_path / "run",
                     resume=tmp_path / "run" / "generations" / "gen-0002.json", figures=False)
    assert fit.to_dict()["methods"]["ga+lm"]["stop"] == "4 generations"


def test_another_exception_of_the_callback_is_raised_as_it_is(tmp_path):
    class Enough(Exception):
        pass

    def stop(event):
        if event["event"] == "step":
            raise Enough("seen enough")

    with pytest.raises(Enough, match="seen enough"):
        sepval.diagnose(generations=60, out=tmp_path / "d", progress=stop)
    assert not (tmp_path / "d" / "diagnosis.json").exists()
    assert sepval.simulate(t_end_s=0.05).shape == (11, 7)


def test_ctrl_c_while_the_command_runs(tmp_path):
    """A real SIGINT, sent once the fit runs (from its first step), reaches the waiting thread:
    the fit stops and KeyboardInterrupt is raised wherever the signal lands."""
    main = threading.main_thread().ident
    senders = []

    def send_sigint(event):
        if event["event"] == "step" and not senders:
            sender = threading.Thread(target=signal.pthread_kill, args=(main, signal.SIGINT))
            senders.append(sender)
            sender.start()

    # Python's own Ctrl-C handler, whatever the runner left: a test runner started in the
    # background by a non-interactive shell inherits SIGINT ignored, and Python then installs
    # no handler, so the signal never reaches the fit (seen 2026-12-02, a cold .ci/run begun
    # with `&`).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            sepval.fit(generations=500, population=40, workers=2, out=tmp_path / "run", progress=send_sigint)
    finally:
        signal.signal(signal.SIGINT, previous)
    senders[0].join(timeout=60)
    assert not senders[0].is_alive()
    assert not (tmp_path / "run" / "result.json").exists()
    assert sepval.goals(sepval.simulate(t_end_s=0.05), sepval.simulate(t_end_s=0.05)) == (0.0, 0.0)


def test_a_callback_cannot_start_another_command(tmp_path):
    def nested(event):
        if event["event"] == "step":
            sepval.simulate(t_end_s=0.05)

    with pytest.raises(sepval.SepvalError, match="a sepval command is already running on this thread"):
        sepval.fit(generations=4, population=40, out=tmp_path / "run", progress=nested)
    assert not (tmp_path / "run" / "result.json").exists()
