"""canGetAndSetFMUstate / canSerializeFMUstate through FMPy: a state saved in
mid-run and restored (in the same instance, and serialized into a fresh one)
continues exactly as the run that was never interrupted — with the friction
and the stops in the modes they had."""

import shutil

import numpy as np
from fmpy import read_model_description

from test_cosim import open_fmu, start


def controller(s, vr, t, n, h=1e-3):
    """n steps of a P controller towards 50 mm from t; the outputs per step."""
    out = []
    for _ in range(n):
        x = s.getReal([vr["position"]])[0]
        s.setReal([vr["command"]], [float(np.clip(20.0 * (0.05 - x), -1.0, 1.0))])
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        out.append(s.getReal([vr[c] for c in ("position", "velocity", "p1", "p2")]))
    return t, np.array(out)


def test_a_restored_state_reproduces_the_continuation(export):
    path = export("leaney-moog")
    md = read_model_description(str(path))
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    s, vr, d = open_fmu(path)
    start(s)
    t, _ = controller(s, vr, 0.0, 200)
    state = s.getFMUstate()
    blob = s.serializeFMUstate(state)
    t_end, first = controller(s, vr, t, 300)
    assert np.abs(first[:, 1]).max() > 0.0
    s.setFMUstate(state)
    _, again = controller(s, vr, t, 300)
    np.testing.assert_array_equal(again, first)
    s.freeFMUstate(state)
    # the serialized state into another instance of the same FMU
    other, vr2, d2 = open_fmu(path, "other")
    start(other)
    restored = other.deSerializeFMUstate(blob)
    other.setFMUstate(restored)
    _, third = controller(other, vr2, t, 300)
    np.testing.assert_array_equal(third, first)
    other.freeFMUstate(restored)
    for inst, folder in ((s, d), (other, d2)):
        inst.terminate()
        inst.freeInstance()
        shutil.rmtree(folder, ignore_errors=True)


def test_a_friction_bench_state_restores_the_bristles(export):
    """The seal bench's LuGre bristle is a state: its force after a restore
    continues the one before."""
    s, vr, d = open_fmu(export("tudelft-seal-25"))
    start(s)
    h = 1e-3
    for k in range(100):
        s.setReal([vr["command"]], [0.005 * np.sin(0.05 * k)])
        s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
    state = s.getFMUstate()

    def go():
        f = []
        for k in range(100, 200):
            s.setReal([vr["command"]], [0.005 * np.sin(0.05 * k)])
            s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            f.append(s.getReal([vr["force"], vr["friction_force"]]))
        return np.array(f)

    first = go()
    s.setFMUstate(state)
    np.testing.assert_array_equal(go(), first)
    s.freeFMUstate(state)
    s.terminate()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
