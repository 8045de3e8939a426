"""Regressions found with FMPy 0.3.32: parameters that a rig rule relates can
be set in any order (the set is checked as a whole at initialisation); a
communication point that is not a number is refused and the instance goes
on; the inputs carry their units; a refused solver parameter states its
rule."""

import shutil

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

from test_cosim import open_fmu, start


def starts(path):
    return {v.name: v.start for v in read_model_description(str(path)).modelVariables}


def long_stroke(path):
    """A stroke longer than twice either chamber: refused by the chambers'
    rule unless the chambers are lengthened too."""
    s = {k: float(v) for k, v in starts(path).items()
         if k.startswith("cylinder.") and v is not None}
    return 2.0 * max(s["cylinder.chamber_length_1"], s["cylinder.chamber_length_2"]) \
        + s["cylinder.stroke"]


def command_table(t_end):
    t = np.array([0.0, t_end])
    return np.array(list(zip(t, [0.2, 0.2])), dtype=[("time", float), ("command", float)])


def test_related_parameters_set_together_are_accepted(export):
    path = export("leaney-moog")
    stroke = long_stroke(path)
    res = simulate_fmu(str(path), stop_time=0.3, output_interval=1e-2,
                       input=command_table(0.3),
                       start_values={"cylinder.stroke": stroke,
                                     "cylinder.chamber_length_1": 0.6 * stroke,
                                     "cylinder.chamber_length_2": 0.6 * stroke})
    assert res["position"][-1] > 0.0


def test_an_inconsistent_set_is_refused_at_initialisation_naming_it(export):
    messages = []

    def logger(env, name, status, category, message):
        messages.append(message.decode())

    path = export("leaney-moog")
    stroke = long_stroke(path)
    s, vr, d = open_fmu(path, logger=logger)
    s.setReal([vr["cylinder.stroke"]], [stroke])  # accepted: fine on its own
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    with pytest.raises(FMICallException) as e:
        s.exitInitializationMode()
    assert e.value.status == 3  # fmi2Error
    last = messages[-1]
    assert last.startswith("fmi2ExitInitializationMode:"), messages
    assert "cylinder.stroke" in last and "chamber_length_1" in last, last
    # still in initialisation mode: corrected, it goes on
    s.setReal([vr["cylinder.chamber_length_1"], vr["cylinder.chamber_length_2"]],
              [0.6 * stroke, 0.6 * stroke])
    s.exitInitializationMode()
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    # a value wrong on its own is still refused when set
    s2, vr2, d2 = open_fmu(path, "b", logger=logger)
    with pytest.raises(FMICallException):
        s2.setReal([vr2["cylinder.stroke"]], [float("nan")])
    assert "cylinder.stroke" in messages[-1] and "finite" in messages[-1], messages[-1]
    for x, dx in ((s, d), (s2, d2)):
        x.freeInstance()
        shutil.rmtree(dx, ignore_errors=True)


def test_a_nan_communication_point_is_refused_and_the_instance_goes_on(export):
    messages = []

    def logger(env, name, status, category, message):
        messages.append(message.decode())

    s, vr, d = open_fmu(export("leaney-moog"), logger=logger)
    start(s)
    with pytest.raises(FMICallException) as e:
        s.doStep(currentCommunicationPoint=float("nan"), communicationStepSize=1e-3)
    assert e.value.status == 3
    assert "not finite" in messages[-1], messages
    s.setReal([vr["command"]], [0.2])
    for k in range(10):
        s.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
    assert s.getReal([vr["position"]])[0] > 0.0
    s.terminate()
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)


@pytest.mark.parametrize("rig, name, unit", [
    ("leaney-moog", "command", None),              # a normalised spool demand
    ("leaney-moog-closed-loop", "reference", "m"),  # a position set-point
    ("wang-hybrid", "command", "V"),                # a pump drive's voltage
    ("emps", "command", "m/s"),                     # the imposed rod velocity
    ("tudelft-seal-25", "command", "m/s"),
])
def test_inputs_carry_their_units(export, rig, name, unit):
    md = read_model_description(str(export(rig)))
    (v,) = [v for v in md.modelVariables if v.causality == "input"]
    assert (v.name, v.unit) == (name, unit)
    if unit:
        assert unit in [u.name for u in md.unitDefinitions]


def test_a_refused_solver_parameter_states_its_rule(export):
    messages = []

    def logger(env, name, status, category, message):
        messages.append(message.decode())

    s, vr, d = open_fmu(export("leaney-moog"), logger=logger)
    with pytest.raises(FMICallException):
        s.setReal([vr["solver.rtol"]], [0.0])
    assert "solver.rtol" in messages[-1] and "must be in [1e-14, 1)" in messages[-1], messages
    # below what double precision meets: refused as the CLI and Python refuse it
    with pytest.raises(FMICallException):
        s.setReal([vr["solver.rtol"]], [1e-300])
    assert "solver.rtol` = 1e-300 rejected: below 1e-14" in messages[-1], messages
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)


def test_a_unit_slip_in_a_parameter_is_a_warning_at_initialisation(export):
    """A bulk modulus written in bar (7000 for 7e8 Pa) is inside its range:
    the instance initialises and steps, with fmi2Warning and the CLI's
    warning logged (logging off: warnings are logged as errors are); the
    preset as shipped initialises with fmi2OK and logs nothing."""
    messages = []

    def logger(env, name, status, category, message):
        messages.append((status, message.decode()))

    path = export("leaney-moog")
    s, vr, d = open_fmu(path, logger=logger)
    s.setReal([vr["cylinder.bulk_modulus"]], [7000.0])
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    assert s.exitInitializationMode() == 1  # fmi2Warning
    assert messages == [(1, "fmi2ExitInitializationMode: rig `cylinder.bulk_modulus`: 7000 [Pa] "
                            "is far outside the usual 5e7 to 5e9 [Pa] of effective bulk modulus B "
                            "of the chambers: a value in bar? (7000 bar = 7e8 Pa)")]
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    s2, vr2, d2 = open_fmu(path, "b", logger=logger)
    messages.clear()
    s2.setupExperiment(startTime=0.0)
    s2.enterInitializationMode()
    assert s2.exitInitializationMode() == 0  # fmi2OK
    assert messages == []
    for x, dx in ((s, d), (s2, d2)):
        x.freeInstance()
        shutil.rmtree(dx, ignore_errors=True)
