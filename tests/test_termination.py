"""A run that is terminated (SIGTERM, what `timeout` and batch schedulers send) or hung
up (SIGHUP, its terminal closed) while it writes --out leaves the earlier file whole and
no temporary file behind; --out asks for a history, so a scenario that keeps none is
refused; whole-number and boolean arguments of the Python API refuse floats and strings
by name."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

import vibroimpact as vi
from test_interrupted_writes import long_writer, wait_for
from vibroimpact import _core

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.timeout(120)
@pytest.mark.parametrize(
    ("ending", "status", "message"),
    [("SIGTERM", 143, "terminated"), ("SIGHUP", 129, "hung up")],
)
def test_sigterm_or_sighup_while_writing_out_keeps_the_old_file_and_no_temporary(
    tmp_path: Path, ending: str, status: int, message: str
) -> None:
    # SIGHUP (a closed terminal) left `.h.csv.*.tmp` (58 MB): it ends the run as
    # SIGTERM and Ctrl-C do.
    if not hasattr(signal, ending):
        pytest.skip(f"no {ending} here")
    out = tmp_path / "history.csv"
    out.write_text("OLD CONTENT\n")
    proc = long_writer(tmp_path, out)
    try:
        wait_for(lambda: list(tmp_path.glob(".history.csv.*")), proc, "the temporary file")
        proc.send_signal(getattr(signal, ending))
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == status, stderr
    assert message in stderr and "Traceback" not in stderr
    assert out.read_text() == "OLD CONTENT\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["history.csv", "long.toml"]


def test_out_without_a_history_is_refused(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "rattling_damper.toml").read_text()
    scenario = tmp_path / "none.toml"
    scenario.write_text(text.replace("every = 100", "every = 100\nhistory = false"))
    done = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "simulate", str(scenario), "--out", "h.csv"],
        capture_output=True,
        text=True,
        timeout=50,
        cwd=tmp_path,
    )
    assert done.returncode == 2, done.stderr
    assert "--out writes the history" in done.stderr and "history = false" in done.stderr
    assert not (tmp_path / "h.csv").exists()


SYSTEM = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01)
CONTACT = vi.Contact("hertz", stiffness=3000.0)
START = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("max_steps", 1e9),
        ("every", 2.5),
        ("every", float("nan")),
        ("max_rows", float("inf")),
        ("every", "10"),
        ("history", "no"),
        ("history", 1),
    ],
)
def test_whole_and_boolean_arguments_refuse_other_types_by_name(field: str, value: object) -> None:
    with pytest.raises(vi.InvalidInputError, match=rf"^{field} must be") as err:
        # The binding's own function: the suite's fixture rewrites max_steps=1e9.
        _core.simulate(SYSTEM, CONTACT, START, method="rk4", dt=1e-4, t_end=1e-3, **{field: value})
    assert "\n" not in str(err.value) and len(str(err.value)) < 200


@pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="no SIGHUP here")
def test_a_sighup_ignored_as_under_nohup_stays_ignored() -> None:
    from vibroimpact.cli import command as cli

    before = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        previous = cli._handle_endings()
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) == cli._terminate
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
        previous = cli._handle_endings()
        assert signal.getsignal(signal.SIGHUP) == cli._terminate
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    finally:
        signal.signal(signal.SIGHUP, before)
