"""Runs and batch runs as results: read-only arrays (handed out without
copying, so nobody may change what the next reader gets), pickling bit for
bit (Dask's process and distributed schedulers ship them), and the
`channels` and `threads` arguments of simulate_batch."""

import pickle

import dask
import numpy as np
import pytest

import hydrocyl


@pytest.fixture
def rig():
    return hydrocyl.Rig.load("leaney-moog")


@pytest.fixture
def batch(rig, step):
    t, u = step
    mass = np.linspace(80.0, 120.0, 4)
    p1 = np.full(4, 2e6)
    p1[2] = 1e30  # a solver failure: its row NaN, its error kept
    return hydrocyl.simulate_batch(
        rig, t, u, {"load.mass": mass, "cylinder.initial.p1": p1}, solver="dp45", on_error="nan"
    )


def same_array(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def every_array_of_a_run(run):
    yield "time", run.time
    yield "run[position]", run["position"]
    for k, v in run.channels.items():
        yield f"channels[{k}]", v


def every_array_of_a_batch(b):
    yield "time", b.time
    yield "batch[position]", b["position"]
    yield "ok", b.ok
    for k, v in b.channels.items():
        yield f"channels[{k}]", v
    for k, v in b.params.items():
        yield f"params[{k}]", v
    for k, v in b.stats.items():
        yield f"stats[{k}]", v


def assert_read_only(arrays):
    for name, a in arrays:
        assert not a.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            a[(0,) * a.ndim] = 123.0
        # and it stays read-only: the array does not own its buffer
        with pytest.raises(ValueError):
            a.flags.writeable = True


def test_a_runs_arrays_are_read_only_and_unchanged(rig, step):
    t, u = step
    run = rig.simulate(t, u)
    before = run["position"].copy()
    assert_read_only(every_array_of_a_run(run))
    np.testing.assert_array_equal(run["position"], before)
    # a copy is the user's to change
    mine = run["position"].copy()
    mine[0] = 123.0
    assert run["position"][0] == before[0]


def test_a_batchs_arrays_are_read_only(batch):
    before = batch["position"].copy()
    assert_read_only(every_array_of_a_batch(batch))
    np.testing.assert_array_equal(batch["position"], before)
    # the params dict is a new one each time: changing it changes nothing
    d = batch.params
    d.clear()
    assert batch.params


def assert_same_run(a, b):
    assert a.names == b.names and list(a.units.items()) == list(b.units.items())
    assert same_array(a.time, b.time)
    for name in a.names:
        assert same_array(a[name], b[name]), name
    assert a.stats == b.stats and list(a.stats) == list(b.stats)
    assert a.diagnostics == b.diagnostics
    assert a.ledger == b.ledger
    assert repr(a) == repr(b)


def assert_same_batch(a, b):
    assert a.names == b.names and len(a) == len(b)
    assert list(a.units.items()) == list(b.units.items())
    assert same_array(a.time, b.time) and same_array(a.ok, b.ok)
    for name in a.names:
        assert same_array(a[name], b[name]), name
    for k in a.params:
        assert same_array(a.params[k], b.params[k]), k
    assert list(a.stats) == list(b.stats)
    for k in a.stats:
        assert same_array(a.stats[k], b.stats[k]), k
    assert a.errors == b.errors and a.interval_s == b.interval_s
    assert repr(a) == repr(b)


@pytest.mark.parametrize("ledger", [False, True])
def test_a_run_pickles_bit_for_bit(rig, step, ledger):
    t, u = step
    run = rig.simulate(t, u, ledger=ledger)
    for protocol in (2, pickle.HIGHEST_PROTOCOL):
        back = pickle.loads(pickle.dumps(run, protocol=protocol))
        assert type(back) is hydrocyl.Run
        assert_same_run(run, back)
        assert_read_only(every_array_of_a_run(back))


def test_a_batch_pickles_bit_for_bit(batch):
    assert list(batch.ok) == [True, True, False, True] and batch.errors[2]
    back = pickle.loads(pickle.dumps(batch))
    assert type(back) is hydrocyl.BatchRun
    assert_same_batch(batch, back)
    assert_read_only(every_array_of_a_batch(back))


def test_a_dask_process_scheduler_returns_runs_and_batches(rig, step):
    t, u = step
    params = {"load.mass": np.linspace(80.0, 120.0, 3)}
    run, batch = dask.compute(
        dask.delayed(hydrocyl.Rig.simulate)(rig, t, u, ledger=True),
        dask.delayed(hydrocyl.simulate_batch)(rig, t, u, params),
        scheduler="processes",
        num_workers=2,
    )
    assert type(run) is hydrocyl.Run and type(batch) is hydrocyl.BatchRun
    here = rig.simulate(t, u, ledger=True)
    for name in here.names:
        assert same_array(run[name], here[name]), name
    assert run.ledger == here.ledger
    local = hydrocyl.simulate_batch(rig, t, u, params)
    for name in local.names:
        assert same_array(batch[name], local[name]), name


def test_channels_as_one_string_is_a_type_error_naming_it(rig, step):
    t, u = step
    for bad, got in [("position", "a str ('position')"), ([1], "an element that is a int"), (3, "a int")]:
        with pytest.raises(TypeError) as e:
            hydrocyl.simulate_batch(rig, t, u, {"load.mass": [100.0]}, channels=bad)
        message = str(e.value)
        assert message.startswith("channels: expected a list of names, got ") and got in message, message
    # any iterable of names is a list of names
    b = hydrocyl.simulate_batch(rig, t, u, {"load.mass": [100.0]}, channels=("p1", "position"))
    assert b.names == ["position", "p1"]


def test_an_unknown_channel_lists_the_channels_in_the_runs_order(rig, step):
    t, u = step
    names = rig.simulate(t, u).names
    with pytest.raises(KeyError) as e:
        hydrocyl.simulate_batch(rig, t, u, {"load.mass": [100.0]}, channels=["nope"])
    assert f"no channel `nope` (channels: {', '.join(names)})" in str(e.value)
    assert names[:5] == ["command", "position", "velocity", "p1", "p2"]


@pytest.mark.parametrize("threads", [1025, 100000, 10**9, 10**30])
def test_a_huge_thread_count_is_a_value_error_naming_it(rig, step, threads):
    t, u = step
    assert hydrocyl.MAX_THREADS == 1024
    with pytest.raises(ValueError) as e:
        hydrocyl.simulate_batch(rig, t, u, {"load.mass": [100.0, 110.0]}, threads=threads)
    message = str(e.value)
    assert message.startswith(f"threads: {threads} is more than {hydrocyl.MAX_THREADS} threads"), message


def test_more_threads_than_runs_use_one_per_run(rig, step):
    """threads up to MAX_THREADS is taken, and no more threads than runs
    are started (two runs here: the result is that of threads=1)."""
    t, u = step
    params = {"load.mass": [100.0, 110.0]}
    many = hydrocyl.simulate_batch(rig, t, u, params, threads=hydrocyl.MAX_THREADS)
    one = hydrocyl.simulate_batch(rig, t, u, params, threads=1)
    for name in one.names:
        assert same_array(many[name], one[name])
    with pytest.raises(TypeError, match="^threads: expected an int or None, got a str"):
        hydrocyl.simulate_batch(rig, t, u, params, threads="4")
