"""A rig file that is not a preset exports too: the hybrid drive's solenoid
variant (a netlist with the `solenoid_four_way` valve, section 9.2) passes
`fmpy validate`, and FMPy's run of it equals `hydrocyl simulate` on the same
constant drive voltage."""

import subprocess
import sys
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu

from conftest import hydrocyl, nrmse, read_csv

REPO = Path(__file__).resolve().parents[4]


def test_a_variant_file_exports_validates_and_equals_the_cli(tmp_path):
    rig = REPO / "fixtures/rigs/wang-hybrid-solenoid.json"
    fmu = tmp_path / "solenoid.fmu"
    hydrocyl("fmu", "--rig", rig, "--out", fmu)
    fmpy_cli = Path(sys.executable).parent / "fmpy"
    r = subprocess.run([str(fmpy_cli), "validate", str(fmu)], capture_output=True, text=True)
    assert "No problems found" in r.stdout, r.stdout + r.stderr
    names = {v.name for v in read_model_description(str(fmu)).modelVariables}
    assert {"command", "position", "p1", "p2"} <= names
    assert "relief_1.cracked" not in names  # the solenoid four-way valve makes reliefs 1 and 2 unnecessary

    t_end, dt, u = 0.5, 1e-3, 2.0  # 2 V: extending
    t = np.round(np.arange(0.0, t_end + dt / 2, dt), 12)
    cmd = tmp_path / "cmd.csv"
    np.savetxt(cmd, np.column_stack([t, np.full_like(t, u)]), delimiter=",",
               header="time,command", comments="", fmt="%.17g")
    out = tmp_path / "sim.csv"
    hydrocyl("simulate", "--rig", rig, "--command", cmd, "--out", out,
             "--solver", "rosenbrock", "--rtol", "1e-9")
    cli = read_csv(out)
    table = np.array([(0.0, u), (t_end, u)], dtype=[("time", float), ("command", float)])
    res = simulate_fmu(str(fmu), stop_time=t_end, output_interval=dt, input=table,
                       start_values={"solver.method": 1, "solver.rtol": 1e-9})
    assert len(res) == len(t)
    for c in ["position", "velocity", "p1", "p2"]:
        assert nrmse(res[c], cli[c]) < 1e-5, (c, nrmse(res[c], cli[c]))
    assert cli["position"][-1] > cli["position"][0]  # it extended
