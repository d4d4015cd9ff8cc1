"""The wheel: `maturin build --release` makes one abi3 wheel (every CPython from 3.11), and it
installs and runs in a fresh virtual environment with no Rust toolchain on the PATH."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

import vibroimpact as vi

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "rattling_damper.toml"


def build_wheel(out: Path) -> Path:
    """The README's wheel command, into ``out``: cargo reuses what `pip install .` compiled,
    so this takes seconds after the install (minutes from nothing)."""
    maturin = shutil.which("maturin")
    assert maturin is not None, 'maturin is in the test extra: pip install ".[test]"'
    subprocess.run(
        [maturin, "build", "--release", "--out", str(out)],
        cwd=ROOT,
        check=True,
        capture_output=True,
        timeout=1500,
    )
    wheels = sorted(out.glob("vibroimpact-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


def without_rust(environment: dict[str, str], bin_dir: Path) -> dict[str, str]:
    """``environment`` with the virtual environment's scripts first and no folder that holds
    cargo or rustc on the PATH (nor Rust's own variables)."""
    folders = [
        folder
        for folder in environment.get("PATH", "").split(os.pathsep)
        if folder and not any(Path(folder, tool).exists() for tool in ("cargo", "rustc", "maturin"))
    ]
    env = {k: v for k, v in environment.items() if not k.startswith(("CARGO", "RUST"))}
    env["PATH"] = os.pathsep.join([str(bin_dir), *folders])
    env.pop("PYTHONPATH", None)
    return env


@pytest.mark.timeout(1800)
def test_the_abi3_wheel_installs_and_runs_without_rust(tmp_path: Path) -> None:
    wheel = build_wheel(tmp_path / "dist")
    # One wheel for every Python from 3.11: the stable ABI's tag, and the module built for it.
    assert "-cp311-abi3-" in wheel.name, wheel.name
    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.startswith("vibroimpact/_core") and n.endswith(".abi3.so") for n in names), names

    # A fresh environment: its own site-packages holds the wheel alone; numpy, scipy and the
    # rest come from this interpreter's (installing them would download).
    env_dir = tmp_path / "env"
    venv.EnvBuilder(system_site_packages=True, with_pip=True, symlinks=True).create(env_dir)
    bin_dir = env_dir / "bin"
    env = without_rust(dict(os.environ), bin_dir)
    assert shutil.which("cargo", path=env["PATH"]) is None
    assert shutil.which("rustc", path=env["PATH"]) is None
    python = str(bin_dir / "python")
    subprocess.run(
        # --ignore-installed: the interpreter's own vibroimpact (`pip install .`) would
        # otherwise count as installed, and the wheel be skipped.
        [python, "-m", "pip", "install", "--no-deps", "--no-index", "--ignore-installed", "-q"]
        + [str(wheel)],
        check=True,
        env=env,
        cwd=tmp_path,
        capture_output=True,
        timeout=300,
    )

    # Run from outside the clone, so that nothing of its source tree can be imported.
    code = (
        "import json, vibroimpact as vi, vibroimpact._core as core\n"
        f"sol = vi.simulate(vi.load({str(EXAMPLE)!r}))\n"
        "print(json.dumps({'package': vi.__file__, 'core': core.__file__,"
        " 'contacts': len(sol.contacts), 'steps': sol.steps,"
        " 'final': {k: v.tolist() for k, v in sol.final_state.items()}}))\n"
    )
    ran = subprocess.run(
        [python, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert ran.returncode == 0, ran.stderr
    out = json.loads(ran.stdout)
    assert Path(out["package"]).is_relative_to(env_dir), out["package"]
    assert out["core"].endswith(".abi3.so"), out["core"]
    # The wheel's engine is this one: the same run, bit for bit.
    here = vi.simulate(vi.load(EXAMPLE))
    assert out["contacts"] == len(here.contacts) > 0
    assert out["steps"] == here.steps
    assert out["final"] == {k: v.tolist() for k, v in here.final_state.items()}

    # Its command line is installed too.
    cli = subprocess.run(
        [str(bin_dir / "vibroimpact"), "--help"],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert cli.returncode == 0 and "simulate" in cli.stdout, cli.stderr
    assert sys.version_info >= (3, 11)
