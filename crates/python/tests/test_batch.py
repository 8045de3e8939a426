"""simulate_batch: equal to a loop of single runs, independent of the thread
count, errors naming the set, and the GIL released while it runs."""

import threading
import warnings

import numpy as np
import pytest

import hydrocyl
from conftest import path_of


@pytest.fixture
def sets():
    rig = hydrocyl.Rig.load("leaney-moog")
    mass, beta = path_of(rig, "mass"), path_of(rig, "bulk_modulus")
    n = 12
    return rig, {
        mass: np.linspace(0.5, 1.5, n) * rig.get(mass),
        beta: np.linspace(1.2, 0.8, n) * rig.get(beta),
    }


def test_batch_equals_a_loop_of_single_runs(step, sets):
    t, u = step
    rig, params = sets
    batch = hydrocyl.simulate_batch(rig, t, u, params)
    assert len(batch) == 12 and batch.ok.all() and batch.errors == [None] * 12
    np.testing.assert_array_equal(batch.time, t)
    for i in range(12):
        one = rig.copy()
        for path, values in params.items():
            one.set(path, float(values[i]))
        run = one.simulate(t, u)
        assert batch.names == run.names
        for name in run.names:
            np.testing.assert_array_equal(batch[name][i], run[name])
        assert batch.stats["steps"][i] == run.stats["steps"]
    # the runs differ: the parameters matter
    assert np.ptp(batch["position"][:, -1]) > 0.0


def test_batch_does_not_depend_on_the_thread_count(step, sets):
    t, u = step
    rig, params = sets
    one = hydrocyl.simulate_batch(rig, t, u, params, threads=1)
    many = hydrocyl.simulate_batch(rig, t, u, params, threads=3)
    default = hydrocyl.simulate_batch(rig, t, u, params)
    for name in one.names:
        np.testing.assert_array_equal(one[name], many[name])
        np.testing.assert_array_equal(one[name], default[name])


def test_channel_selection(step, sets):
    t, u = step
    rig, params = sets
    batch = hydrocyl.simulate_batch(rig, t, u, params, channels=["p1", "position"])
    assert batch.names == ["position", "p1"] and batch["p1"].shape == (12, len(t))
    # only the channels asked for are read, and they are the full runs'
    full = hydrocyl.simulate_batch(rig, t, u, params)
    for name in batch.names:
        np.testing.assert_array_equal(batch[name], full[name])
    with pytest.raises(KeyError, match="no channel `nope`"):
        hydrocyl.simulate_batch(rig, t, u, params, channels=["nope"])


def test_a_bad_set_names_its_run(step, sets):
    t, u = step
    rig, params = sets
    mass = path_of(rig, "mass")
    params[mass][3] = -1.0
    with pytest.raises(ValueError, match=r"^run 3 \(.*=-1\.0.*\): .*out of range"):
        hydrocyl.simulate_batch(rig, t, u, params)
    kept = hydrocyl.simulate_batch(rig, t, u, params, on_error="nan")
    assert list(kept.ok) == [i != 3 for i in range(12)]
    assert kept.errors[3].startswith("run 3") and np.isnan(kept["position"][3]).all()
    assert np.isfinite(kept["position"][2]).all()


def test_a_solver_failure_in_a_batch_is_a_simulation_error(step, sets):
    """Set 5 starts from a chamber pressure of 1e30 Pa, which no step size
    gets away from (see test_simulate)."""
    t, u = step
    rig, params = sets
    p1 = path_of(rig, "p1")
    params[p1] = np.full(12, 2e6)
    params[p1][5] = 1e30
    with pytest.raises(hydrocyl.SimulationError, match=r"^run 5 \(.*\): simulation: solver dp45: .*state at t") as e:
        hydrocyl.simulate_batch(rig, t, u, params, solver="dp45")
    assert e.value.time == 0.0 and 1e30 in e.value.state.values()
    kept = hydrocyl.simulate_batch(rig, t, u, params, on_error="nan")
    assert list(kept.ok) == [i != 5 for i in range(12)]


def test_a_set_whose_chamber_cavitates_is_kept_with_a_warning_naming_it():
    """The chapter-3 sawtooth's drop (see test_simulate) takes chamber 1 of
    the constant-B oil far below vacuum; with entrained air it does not. The
    set without air is kept (not an error) and warned of by its number."""
    t = np.round(np.arange(2001) * 1e-3, 3)
    u = 0.52 * (2.0 * np.mod(t / 1.5, 1.0) - 1.0)
    rig = hydrocyl.Rig.load("leaney-moog")
    params = {"cylinder.air_fraction": np.array([0.005, 0.0, 0.005])}
    with pytest.warns(hydrocyl.CavitationWarning) as w:
        batch = hydrocyl.simulate_batch(rig, t, u, params)
    assert [str(x.message).split(":")[0] for x in w] == ["run 1 (cylinder.air_fraction=0.0)"]
    assert "far below absolute vacuum (p1 of `cylinder`" in str(w[0].message)
    assert batch.ok.all() and batch.errors == [None] * 3
    assert batch["p1"][1].min() < -1.01325e6 < batch["p1"][0].min()


def test_bad_batch_inputs(step, sets):
    t, u = step
    rig, params = sets
    (a, va), (b, vb) = params.items()
    with pytest.raises(ValueError, match="values, but"):
        hydrocyl.simulate_batch(rig, t, u, {a: va, b: vb[:-1]})
    with pytest.raises(ValueError, match="no parameter sets"):
        hydrocyl.simulate_batch(rig, t, u, {})
    with pytest.raises(ValueError, match="unknown rig parameter `no.such`"):
        hydrocyl.simulate_batch(rig, t, u, {"no.such": [1.0]})
    with pytest.raises(ValueError, match="solver: unknown method"):
        hydrocyl.simulate_batch(rig, t, u, params, solver="euler")
    with pytest.raises(ValueError, match="threads"):
        hydrocyl.simulate_batch(rig, t, u, params, threads=0)


@pytest.mark.parametrize("threads", [0, -1])
def test_a_thread_count_below_one_is_a_value_error_naming_it(step, sets, threads):
    t, u = step
    rig, params = sets
    with pytest.raises(ValueError) as e:
        hydrocyl.simulate_batch(rig, t, u, params, threads=threads)
    assert str(e.value) == f"threads: {threads} is not a thread count (must be at least 1)"


def test_two_python_threads_run_batches_at_the_same_time(sets):
    """With the GIL released, two threads' batches overlap in time (each
    batch reports the interval it computed in, measured in Rust); with the
    GIL held they could only run one after the other."""
    rig, params = sets
    t = np.linspace(0.0, 1.0, 2001)
    u = 0.4 * np.sin(2 * np.pi * 5 * t)
    big = {k: np.repeat(v, 20) for k, v in params.items()}  # 240 runs, ~0.1-1 s
    barrier = threading.Barrier(2)
    out = [None, None]

    def work(k):
        barrier.wait()
        out[k] = hydrocyl.simulate_batch(rig, t, u, big, threads=1, channels=["position"])

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    (a0, a1), (b0, b1) = out[0].interval_s, out[1].interval_s
    overlap = min(a1, b1) - max(a0, b0)
    shorter = min(a1 - a0, b1 - b0)
    assert overlap > 0.5 * shorter, (out[0].interval_s, out[1].interval_s)
    np.testing.assert_array_equal(out[0]["position"], out[1]["position"])


def test_a_batch_names_a_parameter_out_of_range_as_rig_set_does():
    """The batch's sets are checked as `rig.set` checks its value, and the
    parameter is named as `--set` takes it (not by its JSON path)."""
    rig = hydrocyl.Rig.load("leaney-moog")
    path = next(p for p in rig.parameters() if p.endswith(".mass"))
    with pytest.raises(ValueError) as single:
        rig.set(path, -1.0)
    assert f"'{path}'" in str(single.value) or f"`{path}`" in str(single.value), single.value
    t = np.linspace(0.0, 0.05, 51)
    u = np.where(t < 0.01, 0.0, 0.4)
    with pytest.raises(ValueError) as batch:
        hydrocyl.simulate_batch(rig, t, u, {path: [rig.get(path), -1.0]})
    assert str(batch.value) == f"run 1 ({path}=-1.0): {single.value}"
    kept = hydrocyl.simulate_batch(rig, t, u, {path: [rig.get(path), -1.0]}, on_error="nan")
    assert kept.errors[1] == f"run 1 ({path}=-1.0): {single.value}"


@pytest.mark.parametrize("preset", ["leaney-moog", "wang-hybrid"])
def test_a_batch_carries_the_units_of_its_channels_as_a_run_does(preset):
    """batch.units is {channel: unit} as run.units (the CLI header's:
    `command` in V on a pump rig), for the channels kept, in their order."""
    rig = hydrocyl.Rig.load(preset)
    t = np.linspace(0.0, 0.02, 41)
    u = np.zeros_like(t)
    run = rig.simulate(t, u)
    mass = path_of(rig, "mass")
    batch = hydrocyl.simulate_batch(rig, t, u, {mass: [rig.get(mass)] * 2})
    assert list(batch.units.items()) == list(run.units.items())
    kept = hydrocyl.simulate_batch(rig, t, u, {mass: [rig.get(mass)]}, channels=["p1", "position"])
    assert list(kept.units.items()) == [("position", "m"), ("p1", "Pa")]


def test_a_unit_slip_is_a_parameter_warning_naming_the_set_and_the_unit_meant():
    """A bulk modulus written in bar (7000 for 7e8 Pa) is inside its range
    and runs; the set is warned of by its number, with the CLI's message
    (`hydrocyl simulate --set cylinder.bulk_modulus=7000`), and so is
    `Rig.simulate` on it. The preset as shipped is not."""
    assert issubclass(hydrocyl.ParameterWarning, UserWarning)
    t = np.linspace(0.0, 0.1, 101)
    u = np.full(101, 0.1)
    rig = hydrocyl.Rig.load("leaney-moog")
    params = {"cylinder.bulk_modulus": np.array([7e8, 7000.0])}
    with pytest.warns(hydrocyl.ParameterWarning) as w:
        batch = hydrocyl.simulate_batch(rig, t, u, params)
    assert [str(x.message) for x in w] == [
        "run 1 (cylinder.bulk_modulus=7000.0): rig `cylinder.bulk_modulus`: 7000 [Pa] is far "
        "outside the usual 5e7 to 5e9 [Pa] of effective bulk modulus B of the chambers: "
        "a value in bar? (7000 bar = 7e8 Pa)"
    ]
    assert batch.ok.all()
    rig.set("cylinder.bulk_modulus", 7000.0)
    with pytest.warns(hydrocyl.ParameterWarning, match=r"^rig `cylinder.bulk_modulus`: 7000 \[Pa\]"):
        run = rig.simulate(t, u)
    assert len(run.time) == 101
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hydrocyl.Rig.load("leaney-moog").simulate(t, u)
