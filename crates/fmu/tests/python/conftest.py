"""Shared set-up of the FMPy tests: the hydrocyl binary, FMUs exported from
it, and a work-around for FMPy's input derivatives.

Run by ``crates/fmu/tests/run_fmpy_tests.sh`` (which builds hydrocyl and the
slave library and sets ``HYDROCYL``); the FMUs are exported once per session.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import fmpy.simulation as _sim

HYDROCYL = os.environ.get("HYDROCYL", "hydrocyl")


# FMPy 0.3.32's `Input` allocates nine derivative slots whatever the number of
# continuous inputs, so `set_input_derivatives=True` fails ("Can only assign
# sequence of same size") unless an FMU has nine inputs. Size them right.
_input_init = _sim.Input.__init__


def _input_init_sized(self, *args, **kwargs):
    _input_init(self, *args, **kwargs)
    if hasattr(self, "continuous"):
        self.continuous = [
            c._replace(derivatives=(type(c.derivatives)._type_ * len(c.vrs))())
            for c in self.continuous
        ]


_sim.Input.__init__ = _input_init_sized


def hydrocyl(*args, **kwargs):
    """Runs the hydrocyl CLI; raises on a non-zero exit."""
    return subprocess.run([HYDROCYL, *map(str, args)], check=True,
                          capture_output=True, text=True, **kwargs)


def presets():
    return hydrocyl("fmu", "--list-presets").stdout.split()


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def export(fmu_dir):
    """export(rig, *sets) -> path of the FMU (cached per arguments)."""
    cache = {}

    def _export(rig, *sets):
        key = (rig, *sets)
        if key not in cache:
            out = fmu_dir / f"{rig}-{len(cache)}.fmu"
            args = ["fmu", "--rig", rig, "--out", out]
            for s in sets:
                args += ["--set", s]
            hydrocyl(*args)
            cache[key] = out
        return cache[key]

    return _export


def nrmse(a, b):
    """The measured-data spec's NRMSE: RMSE(a - b) / (max b - min b); for a
    flat reference (a constant supply pressure) relative to its value."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    span = b.max() - b.min()
    if span == 0:
        span = max(abs(b[0]), 1e-300)
    return float(np.sqrt(np.mean((a - b) ** 2)) / span)


def read_csv(path):
    # the CLI's header carries units (`position [m]`): name the fields by name
    with open(path) as f:
        names = [h.split(" [")[0] for h in f.readline().strip().split(",")]
    return np.genfromtxt(path, delimiter=",", skip_header=1, names=names)
