"""FMPy's simulation of the leaney-moog FMU on a piecewise-linear command
(knots every 10 ms, square edges ramped over one interval) equals
`hydrocyl simulate` on the same command, at communication steps 1 ms and
10 ms (NRMSE <= 1e-6 on every channel)."""

import time

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import hydrocyl, nrmse, read_csv

import os

T_END = 1.0
KNOT = 0.01
# the tolerance of both runs: the difference is integration error (NRMSE
# ~2e-5 at the default 1e-6, ~5e-7 at 1e-8, ~4e-8 at 1e-9)
RTOL = float(os.environ.get("HYDROCYL_FMU_TEST_RTOL", "1e-9"))


def knots():
    """Square ±0.15 (period 0.4 s) whose edges ramp over one 10 ms interval."""
    t = np.round(np.arange(0.0, T_END + KNOT / 2, KNOT), 12)
    u = np.where((np.floor(t / 0.2) % 2) == 0, 0.15, -0.15)
    u[0] = 0.0  # ramp up from rest over the first interval
    return t, u


def cli_run(tmp_path, dt):
    """`hydrocyl simulate` on the same piecewise-linear command, sampled every dt."""
    tk, uk = knots()
    t = np.round(np.arange(0.0, T_END + dt / 2, dt), 12)
    cmd = tmp_path / f"cmd-{dt}.csv"
    np.savetxt(cmd, np.column_stack([t, np.interp(t, tk, uk)]), delimiter=",",
               header="time,command", comments="", fmt="%.17g")
    out = tmp_path / f"sim-{dt}.csv"
    start = time.perf_counter()
    hydrocyl("simulate", "--rig", "leaney-moog", "--command", cmd, "--out", out,
             "--rtol", RTOL)
    return read_csv(out), time.perf_counter() - start


def fmu_input():
    """The knots as an FMPy input table. Each knot is given twice: FMPy takes
    the slope of the segment *before* a sample that falls on the
    communication point, and the slope *after* it only when the sample is a
    time event (a repeated time); the FMU must get the slope after. A knot
    one interval before the start (the command held) makes the first knot
    such an event too (FMPy gives slope 0 at the table's first sample)."""
    tk, uk = knots()
    tk, uk = np.concatenate([[-KNOT], tk]), np.concatenate([[uk[0]], uk])
    t2, u2 = np.repeat(tk, 2), np.repeat(uk, 2)
    return np.array(list(zip(t2, u2)), dtype=[("time", float), ("command", float)])


@pytest.mark.parametrize("step", [1e-3, 1e-2])
def test_fmu_equals_cli(step, export, tmp_path):
    fmu = export("leaney-moog")
    res = simulate_fmu(str(fmu), stop_time=T_END, output_interval=step,
                       input=fmu_input(), set_input_derivatives=True,
                       start_values={"solver.rtol": RTOL})
    ref, _ = cli_run(tmp_path, step)
    assert np.allclose(res["time"], ref["time"], atol=1e-9)
    outputs = [n for n in res.dtype.names if n != "time"]
    assert {"position", "velocity", "p1", "p2"} <= set(outputs)
    worst = {}
    for name in outputs:
        worst[name] = nrmse(res[name], ref[name])
    print(f"step {step}: NRMSE per channel {worst}")
    assert all(e <= 1e-6 for e in worst.values()), worst
    # the run moved: the comparison is not of two flat lines
    assert np.ptp(ref["position"]) > 0.01
