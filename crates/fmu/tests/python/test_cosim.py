"""Co-simulation through FMPy's low-level API: a Python P controller closes
the position loop through the FMU's input, step by step; two instances side
by side with different parameters give the two single-instance results;
bad parameters are refused with a message naming them."""

import shutil

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, defaultCallbacks, fmi2CallbackFunctions,
                        fmi2CallbackLoggerTYPE)


def open_fmu(path, name="drive", logger=None):
    md = read_model_description(str(path))
    d = extract(str(path))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=d,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    callbacks = None
    if logger:
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        callbacks.allocateMemory = defaultCallbacks.allocateMemory
        callbacks.freeMemory = defaultCallbacks.freeMemory
        slave._keep_callbacks = callbacks  # ctypes callbacks must outlive the instance
    slave.instantiate(callbacks=callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return slave, vr, d


def start(s):
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()


def test_p_controller_closes_the_position_loop(export):
    s, vr, d = open_fmu(export("leaney-moog"))
    start(s)
    ref, kp, h = 0.05, 20.0, 1e-3  # 50 mm; 20 /m: full command at 50 mm error
    t, y = 0.0, []
    for _ in range(1500):
        x = s.getReal([vr["position"]])[0]
        y.append(x)
        u = float(np.clip(kp * (ref - x), -1.0, 1.0))
        s.setReal([vr["command"]], [u])
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
    s.terminate()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    y = np.array(y)
    assert y[0] == 0.0
    assert abs(y[-1] - ref) < 1e-3, y[-1]        # settled within 1 mm
    assert y.max() < ref * 1.2, y.max()          # no large overshoot
    assert y[100] > 0.0                          # it moved from the start


def test_a_closed_loop_rig_takes_its_reference_as_input(export):
    """The closed-loop preset's FMU: the input is the set-point `reference`,
    the controller's output is the `command` output (direct feedthrough:
    u = Kp (r - x) at a fixed state), and the drive settles at the P
    controller's steady state, within a few mm of the set-point."""
    path = export("leaney-moog-closed-loop")
    md = read_model_description(str(path))
    by_name = {v.name: v for v in md.modelVariables}
    assert by_name["reference"].causality == "input"
    assert by_name["command"].causality == "output"
    assert "command" not in [v.name for v in md.modelVariables if v.causality == "input"]
    s, vr, d = open_fmu(path)
    start(s)
    ref, h = 0.03, 1e-3
    t = 0.0
    for _ in range(1500):
        s.setReal([vr["reference"]], [ref])
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
    x, u = s.getReal([vr["position"], vr["command"]])
    s.terminate()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    kp = 10.0  # the preset's gain [1/m]
    assert abs(u - np.clip(kp * (ref - x), -1, 1)) < 1e-3, (u, x)  # the controller's law
    assert abs(x - ref) < 5e-3, x                                   # settled near the set-point


def run_alone(path, mass, n=300, h=1e-3):
    s, vr, d = open_fmu(path)
    s.setReal([vr["load.mass"]], [mass])
    start(s)
    s.setReal([vr["command"]], [0.3])
    out = []
    for k in range(n):
        s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
        out.append(s.getReal([vr["position"], vr["p1"]]))
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    return np.array(out)


def test_two_instances_side_by_side(export):
    path = export("leaney-moog")
    alone_a, alone_b = run_alone(path, 100.0), run_alone(path, 10.0)
    assert not np.array_equal(alone_a, alone_b)
    (a, vr, da), (b, _, db) = open_fmu(path, "a"), open_fmu(path, "b")
    a.setReal([vr["load.mass"]], [100.0])
    b.setReal([vr["load.mass"]], [10.0])
    for s in (a, b):
        start(s)
        s.setReal([vr["command"]], [0.3])
    out_a, out_b = [], []
    for k in range(300):
        for s, out in ((a, out_a), (b, out_b)):
            s.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
            out.append(s.getReal([vr["position"], vr["p1"]]))
    np.testing.assert_array_equal(np.array(out_a), alone_a)
    np.testing.assert_array_equal(np.array(out_b), alone_b)
    for s, d in ((a, da), (b, db)):
        s.freeInstance()
        shutil.rmtree(d, ignore_errors=True)


def test_bad_parameter_is_an_error_naming_it(export):
    messages = []

    def logger(env, name, status, category, message):
        messages.append(message.decode())

    s, vr, d = open_fmu(export("leaney-moog"), logger=logger)
    try:
        s.setReal([vr["cylinder.area_2"]], [-1e-3])
        raise AssertionError("a negative area was accepted")
    except FMICallException as e:
        assert e.status == 3  # fmi2Error
    assert any("cylinder.area_2" in m for m in messages), messages
    # the instance is still usable with good values
    s.setReal([vr["cylinder.area_2"]], [6e-4])
    start(s)
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
    s.doStep(currentCommunicationPoint=1e-6, communicationStepSize=1.0)
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
