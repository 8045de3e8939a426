"""How arrays are read: every entry point takes an unaligned, big-endian or
strided numpy array as its values (an unpickled array is often unaligned:
Dask's arrive so), and refuses complex numbers, booleans and elements that
are not numbers with an error naming the argument."""

import pickle
import re

import numpy as np
import pytest

import hydrocyl
from conftest import REPO, unaligned


def big_endian(a):
    out = np.asarray(a, dtype=">f8")
    assert out.dtype.byteorder == ">"
    return out


def strided(a):
    """`a` as every other element of an array twice its length."""
    a = np.asarray(a, dtype=np.float64)
    wide = np.zeros(2 * a.size)
    wide[::2] = a
    out = wide[::2]
    assert not out.flags.c_contiguous
    return out


LAYOUTS = [unaligned, big_endian, strided]


@pytest.fixture(scope="module")
def rig():
    return hydrocyl.Rig.load("leaney-moog")


@pytest.fixture(scope="module")
def command():
    t = np.linspace(0.0, 0.1, 201)
    return t, np.where(t < 0.01, 0.0, 0.5)


@pytest.fixture(scope="module")
def reference(rig, command):
    return rig.simulate(*command)


def same_run(a, b):
    assert a.names == b.names
    np.testing.assert_array_equal(a.time, b.time)
    for name in a.names:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("which", ["t", "u", "both"])
def test_simulate_reads_any_layout_as_its_values(rig, command, reference, layout, which):
    t, u = command
    args = {"t": t, "u": u}
    for k in (["t", "u"] if which == "both" else [which]):
        args[k] = layout(args[k])
    same_run(rig.simulate(args["t"], args["u"]), reference)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_simulate_batch_reads_any_layout_as_its_values(rig, command, layout):
    t, u = command
    masses = np.array([80.0, 120.0])
    path = next(p for p in rig.parameters() if p.endswith(".mass"))
    want = hydrocyl.simulate_batch(rig, t, u, {path: masses}, threads=1)
    got = hydrocyl.simulate_batch(rig, layout(t), layout(u), {path: layout(masses)}, threads=1)
    for name in want:
        np.testing.assert_array_equal(got[name], want[name], err_msg=name)
    np.testing.assert_array_equal(got.params[path], masses)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_xfactor_reads_any_layout_as_its_values(layout):
    travel = np.linspace(-1.5, 1.5, 31)
    want = hydrocyl.xfactor(1.9707, travel)
    np.testing.assert_array_equal(hydrocyl.xfactor(1.9707, layout(travel)), want)
    # any shape: a 2-D unaligned array keeps its shape
    got = hydrocyl.xfactor(1.9707, unaligned(travel[:30].reshape(5, 6)))
    np.testing.assert_array_equal(got, want[:30].reshape(5, 6))


def unaligned_state(obj):
    """The pickled state of a Run or BatchRun with every float array in it
    replaced by an unaligned copy."""
    ctor, (state,) = obj.__reduce__()
    state = dict(state)
    state["time"] = unaligned(state["time"])
    state["values"] = [unaligned(v) for v in state["values"]]
    return ctor, state


def test_a_run_from_unaligned_arrays_is_the_run_and_pickles(reference):
    ctor, state = unaligned_state(reference)
    run = ctor(state)
    same_run(run, reference)
    assert run.time.flags.aligned and not run.time.flags.writeable
    same_run(pickle.loads(pickle.dumps(run)), reference)


def test_a_batch_from_unaligned_arrays_is_the_batch_and_pickles(rig, command):
    t, u = command
    path = next(p for p in rig.parameters() if p.endswith(".mass"))
    batch = hydrocyl.simulate_batch(rig, t, u, {path: [80.0, 120.0]}, threads=1)
    ctor, state = unaligned_state(batch)
    back = ctor(state)
    for b in (back, pickle.loads(pickle.dumps(back))):
        np.testing.assert_array_equal(b.time, batch.time)
        for name in batch:
            np.testing.assert_array_equal(b[name], batch[name], err_msg=name)


def test_a_pickled_state_of_another_element_type_is_refused(reference):
    ctor, (state,) = reference.__reduce__()
    state = dict(state, time=state["time"].astype(np.complex128))
    with pytest.raises(ValueError, match="not the pickled state of a hydrocyl.Run: `time`"):
        ctor(state)


def entry_points(rig, command):
    """Each way an array argument `name` reaches the package: (name, call
    taking the array)."""
    t, u = command
    path = next(p for p in rig.parameters() if p.endswith(".mass"))
    return [
        ("t", lambda x: rig.simulate(x, u)),
        ("u", lambda x: rig.simulate(t, x)),
        ("t", lambda x: hydrocyl.simulate_batch(rig, x, u, {path: [100.0]})),
        ("u", lambda x: hydrocyl.simulate_batch(rig, t, x, {path: [100.0]})),
        (f'params["{path}"]', lambda x: hydrocyl.simulate_batch(rig, t, u, {path: x[:1]})),
        ("travel", lambda x: hydrocyl.xfactor(1.5, x)),
    ]


def test_complex_numbers_are_a_type_error_naming_the_argument(rig, command):
    for name, call in entry_points(rig, command):
        x = command[1].astype(np.complex128)
        with pytest.raises(TypeError, match=rf"^{re.escape(name)}: complex numbers are not accepted"):
            call(x)
        # a list holding a complex element too
        lst = list(command[1])
        lst[0] = 1 + 2j
        with pytest.raises(TypeError, match=rf"^{re.escape(name)}: complex numbers are not accepted"):
            call(lst)


def test_booleans_are_a_type_error_naming_the_argument(rig, command):
    for name, call in entry_points(rig, command):
        with pytest.raises(TypeError, match=rf"^{re.escape(name)}: booleans are not accepted as numbers"):
            call(command[1] > 0.1)


def test_an_element_that_is_not_a_number_is_named_with_its_index(rig, command):
    for name, call in entry_points(rig, command):
        x = command[1].astype(object)
        x[0] = None
        with pytest.raises(TypeError, match=rf"^{re.escape(name)}\[0\]: None is not a number"):
            call(x)
    # the index is where the element is; an object array of None and a list
    # holding a string or a bool are refused the same way
    t, u = command
    x = u.astype(object)
    x[7] = None
    with pytest.raises(TypeError, match=r"^u\[7\]: None is not a number \(a NoneType\)$"):
        rig.simulate(t, x)
    with pytest.raises(TypeError, match=r"^u\[0\]: None is not a number"):
        rig.simulate(t, np.full(t.size, None))
    x = u.astype(object)
    x[1] = "a"
    with pytest.raises(TypeError, match=r"^u\[1\]: 'a' is not a number \(a str\)$"):
        rig.simulate(t, x)
    # a list mixing numbers and strings is numpy's array of strings
    with pytest.raises(ValueError, match=r"^u: expected a 1-D array of numbers, got a list of <U\d+ \(not numbers\)$"):
        rig.simulate(t, [0.0, "a"] + [0.0] * (t.size - 2))
    with pytest.raises(TypeError, match=r"^u\[2\]: True is a bool, not a number$"):
        rig.simulate(t, [0.0, 0.5, True] + [0.5] * (t.size - 3))
    x = np.linspace(0, 1, 6).astype(object).reshape(2, 3)
    x[1, 2] = None
    with pytest.raises(TypeError, match=r"^travel\[1, 2\]: None is not a number"):
        hydrocyl.xfactor(1.5, x)


def test_ints_and_an_object_array_of_numbers_are_read_as_floats(rig, command, reference):
    t, u = command
    same_run(rig.simulate(t, u.astype(object)), reference)
    travel = np.arange(-2, 3)
    np.testing.assert_array_equal(hydrocyl.xfactor(1.5, travel), hydrocyl.xfactor(1.5, travel.astype(float)))


def test_strings_are_a_value_error_naming_the_argument(rig, command):
    t, _ = command
    with pytest.raises(ValueError, match=r"^u: expected a 1-D array of numbers, got a ndarray of <U3 \(not numbers\)$"):
        rig.simulate(t, np.full(t.size, "0.5"))


def number_arguments(rig, command):
    """(argument name, call with that argument set to x) for every argument
    that is one real number."""
    t, u = command
    rec = str(REPO / "fixtures/measured/valve-none.csv")
    batch = lambda **kw: hydrocyl.simulate_batch(rig, t, u, {"load.mass": [50.0]}, **kw)  # noqa: E731
    return [
        ("gamma", lambda x: hydrocyl.xfactor(x, [0.0])),
        ("rtol", lambda x: rig.simulate(t, u, rtol=x)),
        ("rk4_step", lambda x: rig.simulate(t, u, solver="rk4", rk4_step=x)),
        ("h_max", lambda x: rig.simulate(t, u, h_max=x)),
        ("rtol", lambda x: batch(rtol=x)),
        ("rk4_step", lambda x: batch(solver="rk4", rk4_step=x)),
        ("h_max", lambda x: batch(h_max=x)),
        ("min_share", lambda x: hydrocyl.diagnose(rig, rec, min_share=x)),
        ("holdout", lambda x: hydrocyl.diagnose(rig, rec, holdout=x)),
    ]


@pytest.mark.parametrize(
    "bad, why",
    [
        ("1e-6", r"expected a number, got a str \('1e-6'\)"),
        (np.array([1e-6, 1e-5]), r"expected a number, got a 1-D array of shape \(2\)"),
        (1 + 0j, r"complex numbers are not accepted"),
        (True, r"booleans are not accepted as numbers"),
    ],
)
def test_an_argument_that_is_not_one_number_is_a_type_error_naming_it(rig, command, bad, why):
    """A number argument given as a str, an array, a complex or a bool is a
    TypeError that names the argument, as an array argument's is (not
    PyO3's bare `must be real number, not str`)."""
    for name, call in number_arguments(rig, command):
        with pytest.raises(TypeError, match=rf"^{re.escape(name)}: {why}"):
            call(bad)


def test_a_number_argument_takes_ints_and_numpy_scalars(rig, command, reference):
    t, u = command
    same_run(rig.simulate(t, u, rtol=np.float64(1e-6), h_max=np.float64(0.01)), reference)
    same_run(rig.simulate(t, u, h_max=np.array(0.01)), reference)
    assert hydrocyl.xfactor(2, [0.0]) == hydrocyl.xfactor(np.int64(2), [0.0]) == hydrocyl.xfactor(2.0, [0.0])


@pytest.mark.parametrize(
    "call, name, what",
    [
        (lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, {1: [50.0]}), "params", "parameter path"),
        (lambda rig, t, u: rig.update({("load", "mass"): 50.0}), "values", "parameter path"),
        (lambda rig, t, u: hydrocyl.diagnose(rig, {"time": t, 2: u}), "record", "column name"),
    ],
)
def test_a_key_that_is_not_a_str_is_a_type_error_naming_the_argument(rig, command, call, name, what):
    t, u = command
    with pytest.raises(TypeError, match=rf"^{name}: a key is a {what} \(a str\), got .* \(an? (int|tuple)\)$"):
        call(rig, t, u)


@pytest.mark.parametrize(
    "name, call, why",
    [
        ("ledger", lambda rig, t, u: rig.simulate(t, u, ledger=1), r"expected True or False, got 1 \(an int\)"),
        ("ledger", lambda rig, t, u: rig.simulate(t, u, ledger="yes"), r"expected True or False, got 'yes' \(a str\)"),
        ("window", lambda rig, t, u: hydrocyl.diagnose(rig, "rec.csv", window=3.5), r"expected an int \(samples\) or None, got 3\.5 \(a float\)"),
        ("window", lambda rig, t, u: hydrocyl.diagnose(rig, "rec.csv", window=True), r"expected an int \(samples\) or None, got True \(a bool\)"),
        ("path", lambda rig, t, u: rig.set(5, 1.0), r"expected a str, got 5 \(an int\)"),
        ("path", lambda rig, t, u: rig.get(None), r"expected a str, got None"),
        ("text", lambda rig, t, u: hydrocyl.Rig.from_json(b"{}"), r"expected a str, got b'\{\}' \(a bytes\)"),
        ("solver", lambda rig, t, u: rig.simulate(t, u, solver=3), r"expected a str, got 3 \(an int\)"),
        ("solver", lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, [{}], solver=None), r"expected a str, got None"),
        ("on_error", lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, [{}], on_error=True), r"expected a str, got True \(a bool\)"),
    ],
)
def test_an_argument_of_another_type_is_a_type_error_naming_it(rig, command, name, call, why):
    """A str, bool or int argument of another type is a TypeError naming
    the argument, not PyO3's bare `'None' is not an instance of 'str'`."""
    t, u = command
    with pytest.raises(TypeError, match=rf"^{name}: {why}") as e:
        call(rig, t, u)
    # the message is one line (PyO3 adds a note, shown in tracebacks only)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize(
    "call, why",
    [
        (lambda rig, t, u: rig.simulate(t, u, solver="dopri"), r"^solver: unknown method `dopri` \(use auto, dp45, rosenbrock, rk4 or exponential\)"),
        (lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, [{}], solver="DP45"), r"^solver: unknown method `DP45`"),
        (lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, [{}], on_error="ignore"), r"^on_error: `ignore` is not `raise` or `nan`"),
    ],
)
def test_an_unknown_solver_or_on_error_is_a_value_error_naming_it(rig, command, call, why):
    t, u = command
    with pytest.raises(ValueError, match=why) as e:
        call(rig, t, u)
    # one line (PyO3's note naming the argument shows in tracebacks only)
    assert "\n" not in str(e.value)


def test_the_str_defaults_stay_in_the_text_signatures():
    """`solver` and `on_error` are read by functions that name them in
    their errors; their defaults are still shown in the signatures."""
    assert 'solver="auto"' in hydrocyl.Rig.simulate.__text_signature__
    assert 'solver="auto"' in hydrocyl.simulate_batch.__text_signature__
    assert 'on_error="raise"' in hydrocyl.simulate_batch.__text_signature__


def test_an_int_window_may_be_a_numpy_int(rig):
    rec = str(REPO / "fixtures/measured/valve-none.csv")
    with pytest.raises(ValueError, match=r"^window 1: must be at least 2"):
        hydrocyl.diagnose(rig, rec, window=np.int64(1))


class TableLike:
    """A table that is not a dict but has `keys()` and `[]` (as a pandas
    DataFrame: `dict(table)` is its columns)."""

    def __init__(self, columns):
        self._columns = dict(columns)

    def keys(self):
        return list(self._columns)

    def __getitem__(self, k):
        return self._columns[k]


def test_a_mapping_that_is_not_a_dict_is_read_as_its_items(rig, command, reference):
    """`params`, `rig.update`'s values and a `diagnose` record are typed
    Mapping: a mappingproxy, a collections.abc.Mapping or a DataFrame-like
    table (keys() and []) is read as the dict of its items, not refused as
    `'mappingproxy' object is not an instance of 'dict'`."""
    import collections.abc
    import types

    class Frozen(collections.abc.Mapping):
        def __init__(self, d):
            self._d = dict(d)

        def __getitem__(self, k):
            return self._d[k]

        def __iter__(self):
            return iter(self._d)

        def __len__(self):
            return len(self._d)

    t, u = command
    sets = {"load.mass": np.array([40.0, 60.0])}
    want = hydrocyl.simulate_batch(rig, t, u, sets)
    for wrap in (types.MappingProxyType, Frozen, TableLike):
        got = hydrocyl.simulate_batch(rig, t, u, wrap(sets))
        np.testing.assert_array_equal(got["position"], want["position"])
        one = rig.copy()
        one.update(wrap({"load.mass": 40.0}))
        assert one.get("load.mass") == 40.0
    # a record read as the dict of its columns (not refused as no path)
    with pytest.raises(ValueError, match=r"^record \(dict; row 2 = element 0\): only 3 samples"):
        hydrocyl.diagnose(rig, TableLike({"time": t[:3], "command": u[:3], "position": u[:3]}))


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda rig, t, u: hydrocyl.simulate_batch(rig, t, u, [("load.mass", [50.0])]), "params"),
        (lambda rig, t, u: rig.update([("load.mass", 50.0)]), "values"),
    ],
)
def test_a_list_of_pairs_for_a_mapping_is_a_type_error_naming_it(rig, command, call, name):
    t, u = command
    with pytest.raises(TypeError, match=rf"^{name}: expected a dict of .*, got \[\('load.mass'"):
        call(rig, t, u)
