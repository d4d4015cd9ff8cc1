"""
A study on a Dask cluster, resumed after an interruption
========================================================

A study's runs are shared out in chunks (``chunk_size`` runs each); on a Dask cluster each
chunk is a task, and each finished chunk is kept beside the output (``RESULT.nc.parts/``)
as soon as it completes. A study interrupted (Ctrl-C, a lost allocation, a killed job)
loses at most the chunks in flight: run again into the same output, it goes on where it
stopped and writes the same file, byte for byte, as a study never interrupted.

Here the cluster is a ``distributed.LocalCluster`` in this process (no network beyond
localhost); on a real cluster, give the scheduler's address instead (``dask scheduler``
on one machine, ``dask worker tcp://HOST:8786`` on the others, where vibroimpact is
installed). From the command line the same is
``vibroimpact study FILE.toml --out RESULT.nc --dask tcp://HOST:8786``.
"""

# %%
# The study
# ---------
# The impact damper of the first tutorials, its steady amplitude over its clearance and
# the forcing frequency: 6 x 12 = 72 runs in chunks of 8.
import logging
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import xarray as xr
from dask.distributed import LocalCluster

import vibroimpact as vi
import vibroimpact.study

system = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),  # kg, N/m, N s/m
    dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)],
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
    solver=vi.Solver(method="exact", t_end=1.0),
    analyses={
        "study": {
            "analysis": "steady-state",
            "metrics": ["amplitude", "settled"],
            "chunk_size": 8,
            "axes": {
                "damper.0.clearance": {"start": 0.002, "stop": 0.012, "count": 6},  # m
                "excitation.0.frequency": {"start": 8.0, "stop": 12.0, "count": 12},  # Hz
            },
        }
    },
)
study = vi.study_of(system)
print(f"{study.runs} runs in {len(study.chunks())} chunks")
folder = Path(tempfile.mkdtemp())
out = folder / "study.nc"

# %%
# An interruption
# ---------------
# Interrupting a build by hand is not possible, so the progress callback (called as each
# chunk is kept) raises ``KeyboardInterrupt`` after the third chunk, as Ctrl-C would.
# The error's note says what is kept and how to resume.
cluster = LocalCluster(
    n_workers=1,
    threads_per_worker=2,
    processes=False,
    dashboard_address=None,
    # The scheduler's HTTP server on a free port, not 8787 (a cluster already running).
    scheduler_kwargs={"dashboard_address": ":0"},
    silence_logs=logging.ERROR,
)


def stop_after_three(done: int, total: int, rate: float) -> None:
    if done >= 24:
        raise KeyboardInterrupt


try:
    vibroimpact.study.run(study, out, dask=cluster.scheduler_address, progress=stop_after_three)
except KeyboardInterrupt as stop:
    print("interrupted:", *stop.__notes__)
kept = sorted(p.name for p in (folder / "study.nc.parts").glob("chunk-*.npz"))
print(f"kept: {kept}; the output exists: {out.exists()}")

# %%
# Resumed
# -------
# The same call again: the kept chunks are read back, the others run on the cluster, and
# the file is written whole.
notices: list[str] = []
resumed = vibroimpact.study.run(study, out, dask=cluster.scheduler_address, notice=notices.append)
cluster.close()
print(*notices)
resumed_bytes = out.read_bytes()

# %%
# The same file as a study never interrupted
# ------------------------------------------
# Here on this process's threads (no Dask): results are the same bit for bit whatever the
# engine, the number of workers or the chunks' order of completion.
uninterrupted = folder / "uninterrupted.nc"
vibroimpact.study.run(study, uninterrupted)
uninterrupted_bytes = uninterrupted.read_bytes()
print("byte for byte the same:", resumed_bytes == uninterrupted_bytes)

with xr.open_dataset(out) as dataset:
    amplitude = dataset["amplitude"].sel(coordinate=0).load()
shutil.rmtree(folder)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for clearance in amplitude["damper.0.clearance"].values:
    ax.plot(
        amplitude["excitation.0.frequency"],
        1e3 * amplitude.sel({"damper.0.clearance": clearance}),
        "o-",
        ms=3,
        label=f"{1e3 * clearance:.0f} mm",
    )
ax.set(xlabel="forcing frequency (Hz)", ylabel="steady amplitude (mm)", title="The resumed study")
ax.legend(title="clearance", ncols=2)
