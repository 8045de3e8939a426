"""Defects found by a test user (FMPy 0.3.32): value references that must
reach the parameters the model description names (item 1: a slave library
of another build mapped them to the next parameter), an instance freed twice
(the host must go on), the output dependencies declared for every value of
the parameters, which of rig or build differs when the GUID does not match,
messages naming parameters by their `--set` paths, and NaN setting back a
parameter the rig computes."""

import math
import re
import shutil
import subprocess
import sys
import zipfile

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException

from test_cosim import open_fmu, start

VR_PRESETS = ["leaney-moog", "wang-hybrid", "leaney-moog-generalised",
              "tudelft-seal-25", "wang-valve-c10", "emps"]


@pytest.mark.parametrize("rig", VR_PRESETS)
def test_every_parameter_reads_back_its_start_through_its_value_reference(rig, export):
    """The user's f12_vr_map.py: each parameter's start value in the model
    description is what the instance returns for its value reference."""
    path = export(rig)
    md = read_model_description(str(path))
    s, vr, d = open_fmu(path)
    params = [v for v in md.modelVariables if v.causality == "parameter"]
    assert len(params) > 10
    bad = []
    for v in params:
        if v.type == "Integer":
            got = s.getInteger([v.valueReference])[0]
            if got != int(v.start):
                bad.append((v.name, v.start, got))
            continue
        start_value, got = float(v.start), s.getReal([v.valueReference])[0]
        if not (got == start_value or (math.isnan(got) and math.isnan(start_value))):
            bad.append((v.name, v.start, got))
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    assert bad == []


FREE_TWICE = """
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
path = sys.argv[1]
md = read_model_description(path)
s = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
s.instantiate()
c = s.component
s.fmi2FreeInstance(c)
s.fmi2FreeInstance(c)             # illegal per FMI: must be ignored
try:
    s.doStep(0.0, 1e-3)           # a freed instance: refused, not used
    print("accepted")
except Exception as e:
    print("refused", e)
s.freeLibrary()
t = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="y")
t.instantiate(); t.setupExperiment(startTime=0.0); t.enterInitializationMode()
t.exitInitializationMode(); t.doStep(0.0, 1e-3); t.terminate(); t.freeInstance()
print("alive")
"""


def test_an_instance_freed_twice_leaves_the_host_running(export, tmp_path):
    """In a child process, so that a crash fails this test, not the run."""
    script = tmp_path / "free_twice.py"
    script.write_text(FREE_TWICE)
    r = subprocess.run([sys.executable, str(script), str(export("leaney-moog"))],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.split("\n")
    assert lines[-2] == "alive", r.stdout
    assert lines[0].startswith("refused"), r.stdout


def declared_dependencies(path):
    """{output name: declared dependency indices} of the ModelStructure."""
    xml = zipfile.ZipFile(path).read("modelDescription.xml").decode()
    md = read_model_description(str(path))
    names = [v.name for v in md.modelVariables]
    outputs = re.search(r"<Outputs>(.*?)</Outputs>", xml, re.S).group(1)
    deps = {}
    for index, dep in re.findall(r'<Unknown index="(\d+)" dependencies="([^"]*)"', outputs):
        deps[names[int(index) - 1]] = set(dep.split())
    return deps, names


@pytest.mark.parametrize("sigma1", [0.0, 100.0])
def test_declared_dependencies_hold_after_a_parameter_change(export, sigma1):
    """The user's bug_fmu_feedthrough.py: the friction bench exported at
    sigma1 = 0, the host sets sigma1; every output that then changes with
    the input at a fixed state is declared to depend on it."""
    path = export("tudelft-seal-25")
    deps, names = declared_dependencies(path)
    s, vr, d = open_fmu(path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([vr["friction.sigma1"]], [sigma1])
    s.exitInitializationMode()
    s.setReal([vr["command"]], [0.01])
    s.doStep(0.0, 0.01)
    outs = list(deps)
    rows = []
    for cmd in (0.01, 0.0, 0.05):
        s.setReal([vr["command"]], [cmd])  # no step: the state is fixed
        rows.append(s.getReal([vr[o] for o in outs]))
    s.terminate()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    input_index = str(names.index("command") + 1)
    moved = [o for k, o in enumerate(outs) if len({r[k] for r in rows}) > 1]
    assert "friction_force" in moved or sigma1 == 0.0
    for o in moved:
        assert input_index in deps[o], (o, deps[o])


def instantiate_message(path):
    """Instantiates the extracted FMU at `path` (a folder); returns the
    logged messages (instantiation must fail)."""
    messages = []
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
    from fmpy.fmi2 import defaultCallbacks
    md = read_model_description(str(path / "modelDescription.xml"))
    s = FMU2Slave(guid=md.guid, unzipDirectory=str(path),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda e, n, st, c, m: messages.append(m.decode()))
    cb.allocateMemory = defaultCallbacks.allocateMemory
    cb.freeMemory = defaultCallbacks.freeMemory
    with pytest.raises(Exception):
        s.instantiate(callbacks=cb)
    return messages


def test_an_edited_rig_is_named_as_the_rig_not_the_version(export, tmp_path):
    d = tmp_path / "x"
    zipfile.ZipFile(export("leaney-moog")).extractall(d)
    rig = d / "resources" / "rig.json"
    rig.write_text(rig.read_text().replace('"mass": 100.0', '"mass": 50.0'))
    msgs = instantiate_message(d)
    assert len(msgs) == 1, msgs
    assert "the rig differs" in msgs[0], msgs
    assert "version" not in msgs[0] and "build differs" not in msgs[0], msgs


def test_a_relation_broken_in_initialisation_is_named_cleanly(export):
    """The user's f5_abuse.py: the message names `cylinder.chamber_length_1`
    as --set does, once, and says the rule."""
    messages = []
    s, vr, d = open_fmu(export("leaney-moog"),
                        logger=lambda e, n, st, c, m: messages.append(m.decode()))
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([vr["cylinder.chamber_length_1"]], [0.1])
    with pytest.raises(FMICallException):
        s.exitInitializationMode()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    (m,) = messages
    assert "components." not in m, m
    assert "cylinder.chamber_length_1 = 0.1" in m, m
    assert "chamber_length_1 must exceed half the stroke" in m, m
    assert "chamber_length_1chamber" not in m, m


def test_nan_sets_a_computed_initial_pressure_back(export):
    """Once cylinder.initial.p1 is set, NaN sets it back to computed: the
    chamber pressure at the start is the steady one again."""
    path = export("leaney-moog")
    s, vr, d = open_fmu(path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    computed = s.getReal([vr["p1"]])[0]
    s.setReal([vr["cylinder.initial.p1"]], [computed + 1e6])
    assert s.getReal([vr["p1"]])[0] == computed + 1e6
    s.setReal([vr["cylinder.initial.p1"]], [float("nan")])
    assert math.isnan(s.getReal([vr["cylinder.initial.p1"]])[0])
    s.exitInitializationMode()
    assert s.getReal([vr["p1"]])[0] == computed
    # a parameter that must have a value still refuses NaN
    with pytest.raises(FMICallException):
        s.setReal([vr["load.mass"]], [float("nan")])
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
