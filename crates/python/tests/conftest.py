"""Shared fixtures of the hydrocyl pytest suite.

The CLI comparisons need the `hydrocyl` binary: `cargo xtask test` builds it
and passes its path in HYDROCYL_CLI. Run by hand, the suite looks for it in
$CARGO_TARGET_DIR/debug or <repo>/target/debug and fails (never skips)
when it is not there.
"""

import os
import pathlib
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def repo():
    return REPO


@pytest.fixture(scope="session")
def cli():
    candidates = [os.environ.get("HYDROCYL_CLI")]
    for base in [os.environ.get("CARGO_TARGET_DIR"), REPO / "target"]:
        if base:
            candidates.append(pathlib.Path(base) / "debug" / "hydrocyl")
    for c in candidates:
        if c and pathlib.Path(c).is_file():
            return str(c)
    pytest.fail("the hydrocyl CLI binary is needed: build it (cargo build -p hydrocyl-cli) or set HYDROCYL_CLI")


def run_cli(cli, *args, expect_ok=True):
    """Runs the CLI; returns (returncode, stdout, the error line without the
    `hydrocyl: error: ` prefix)."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    err = p.stderr.strip().splitlines()
    line = err[-1].removeprefix("hydrocyl: error: ") if err else ""
    if expect_ok:
        assert p.returncode == 0, p.stderr
    return p.returncode, p.stdout, line


@pytest.fixture
def step():
    """A valve command step: t [s] and u (normalised spool demand)."""
    t = np.linspace(0.0, 0.2, 401)
    return t, np.where(t < 0.01, 0.0, 0.4)


def write_command(path, t, u, column="command"):
    """The command CSV `hydrocyl simulate --command` reads (`column`:
    `reference` for a closed-loop rig, whose input is the set-point)."""
    with open(path, "w") as f:
        f.write(f"time,{column}\n")
        for a, b in zip(t, u):
            f.write(f"{float(a)!r},{float(b)!r}\n")


def read_csv(path):
    """A CSV of floats as {column: array}."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    # the CLI's header carries units (`position [m]`): key by name
    return {h.split(" [")[0]: data[:, i] for i, h in enumerate(header)}


def path_of(rig, word):
    """The one parameter path whose last segment starts with `word` (paths
    come from the rig, so that renamed paths need no test edits)."""
    hits = [p for p in rig.parameters() if p.rsplit(".", 1)[-1].startswith(word)]
    assert len(hits) == 1, (word, hits)
    return hits[0]


def unaligned(a):
    """A float64 copy of `a` in a buffer at an odd address, as an unpickled
    array may be: not aligned (reading it as it is would be a panic)."""
    a = np.asarray(a, dtype=np.float64)
    out = np.frombuffer(bytearray(a.nbytes + 1), dtype=np.float64, count=a.size, offset=1).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned
    return out
