"""`fmpy validate` passes on the FMU of every preset, and the FMU holds what
docs/fmu.md says."""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from conftest import presets


@pytest.mark.parametrize("rig", presets())
def test_fmpy_validate_passes(rig, export):
    fmu = export(rig)
    fmpy_cli = Path(sys.executable).parent / "fmpy"
    r = subprocess.run([str(fmpy_cli), "validate", str(fmu)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "No problems found" in r.stdout, r.stdout
    names = zipfile.ZipFile(fmu).namelist()
    md = read_model_description(str(fmu))
    ident = md.coSimulation.modelIdentifier
    assert sorted(names) == sorted(["modelDescription.xml", "resources/rig.json",
                                    f"binaries/linux64/{ident}.so"])
    cs = md.coSimulation
    assert cs.canHandleVariableCommunicationStepSize and cs.canInterpolateInputs
    by = {v.name: v for v in md.modelVariables}
    # one input: the command, or a closed-loop rig's set-point `reference`
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    assert inputs in (["command"], ["reference"]), inputs
    # every rig moves a rod; a cylinder rig has its chamber pressures, a
    # friction bench its load-cell force
    wanted = ["position", "velocity"] + (["p1", "p2"] if "p1" in by else ["force"])
    for out in wanted:
        assert by[out].causality == "output", out
    assert by["position"].unit == "m"
    assert "p1" not in by or by["p1"].unit == "Pa"
    assert "force" not in by or by["force"].unit == "N"
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert by["solver.method"].causality == "parameter"
    params = [v for v in md.modelVariables if v.causality == "parameter"]
    assert len(params) > 10 and all(v.start is not None for v in params)
