"""Rig: loading, parameter paths (round trip, --set semantics), JSON, pickling,
and errors worded as the CLI words them."""

import copy
import json
import math
import pathlib
import pickle
import threading
import time

import numpy as np
import pytest

import hydrocyl
from conftest import path_of, run_cli


def test_presets_load_and_list_their_parameters():
    assert set(hydrocyl.PRESETS) >= {"leaney-moog", "wang-hybrid"}
    for name in hydrocyl.PRESETS:
        rig = hydrocyl.Rig.load(name)
        ps = rig.parameters()
        assert ps, name
        assert all(v is None or isinstance(v, float) for v in ps.values())


def test_load_a_rig_file_equals_its_preset(repo):
    path = repo / "fixtures" / "rigs" / "leaney-moog.json"
    assert hydrocyl.Rig.load(str(path)) == hydrocyl.Rig.load("leaney-moog")


def test_parameters_round_trip():
    """Setting every parameter to the value it reports gives back the same
    parameters, and so does a rig rebuilt from its JSON or from a pickle."""
    for name in hydrocyl.PRESETS:
        rig = hydrocyl.Rig.load(name)
        ps = rig.parameters()
        other = hydrocyl.Rig.load(name)
        for path, value in ps.items():
            other.set(path, value)
            assert other.get(path) == value or (value is not None and math.isclose(other.get(path), value))
        assert other.parameters() == ps
        assert hydrocyl.Rig.from_json(rig.to_json()).parameters() == ps
        assert pickle.loads(pickle.dumps(rig)) == rig
        assert copy.deepcopy(rig) == rig


def test_set_changes_one_parameter_and_the_json():
    rig = hydrocyl.Rig.load("leaney-moog")
    path = path_of(rig, "mass")
    before = rig.parameters()
    rig.set(path, 50)
    after = rig.parameters()
    assert after[path] == 50.0
    assert {k: v for k, v in after.items() if k != path} == {k: v for k, v in before.items() if k != path}
    assert hydrocyl.Rig.from_json(rig.to_json()).get(path) == 50


def test_update_sets_several_and_checks_once():
    rig = hydrocyl.Rig.load("leaney-moog")
    ps = rig.parameters()
    a, b = [p for p in ps if p.startswith("cylinder.area")][:2]
    rig.update({a: ps[a] * 1.1, b: ps[b] * 1.1})
    assert rig.get(a) == pytest.approx(ps[a] * 1.1)


@pytest.mark.parametrize(
    "assignment",
    [
        (None, 1.0),  # unknown path
        ("mass", float("nan")),  # NaN
        ("mass", -5.0),  # out of range
        ("mass", "heavy"),  # a string for a number
    ],
)
def test_set_errors_are_the_cli_messages_and_leave_the_rig_alone(cli, tmp_path, assignment):
    word, value = assignment
    rig = hydrocyl.Rig.load("leaney-moog")
    path = path_of(rig, word) if word else "no.such.path"
    before = rig.to_json()
    with pytest.raises(ValueError) as e:
        rig.set(path, value)
    assert rig.to_json() == before
    text = {float: repr, str: str}[type(value)](value).replace("nan", "NaN")
    code, _, line = run_cli(cli, "simulate", "--rig", "leaney-moog", "--set", f"{path}={text}", "--print-rig", expect_ok=False)
    assert code == 2
    assert str(e.value) == line
    assert "\n" not in str(e.value)


def test_get_unknown_path_is_the_set_error():
    rig = hydrocyl.Rig.load("leaney-moog")
    missing = path_of(rig, "mass").rsplit(".", 1)[0] + ".no_such"
    with pytest.raises(ValueError) as got:
        rig.get(missing)
    with pytest.raises(ValueError) as set_:
        rig.set(missing, 1)
    assert str(got.value) == str(set_.value)


def test_bad_rig_path_is_the_cli_message(cli, tmp_path):
    missing = tmp_path / "nope.json"
    with pytest.raises(ValueError) as e:
        hydrocyl.Rig.load(str(missing))
    cmd = tmp_path / "c.csv"
    cmd.write_text("time,command\n0,0\n1,0\n")
    _, _, line = run_cli(cli, "simulate", "--rig", missing, "--command", cmd, "--out", tmp_path / "o.csv", expect_ok=False)
    assert str(e.value) == line


def test_malformed_rig_file(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "valve-cylinder", ')
    with pytest.raises(ValueError, match="not valid JSON"):
        hydrocyl.Rig.load(str(bad))
    with pytest.raises(ValueError, match="unknown rig kind"):
        hydrocyl.Rig.from_json('{"kind": "teapot"}')


def test_set_rejects_values_that_are_not_parameters():
    rig = hydrocyl.Rig.load("leaney-moog")
    with pytest.raises(TypeError):
        rig.set(path_of(rig, "mass"), [1, 2])


def test_a_numpy_bool_or_complex_is_not_read_as_a_number_and_errors_name_the_path():
    """numpy's bool and complex scalars are what Python's are: a bool is
    refused for a number (`np.True_` was set as 1.0, `True` refused), a
    complex is refused (np.complex128(3+1j) was set as 3.0, the imaginary
    part dropped with only a ComplexWarning); a value that is not one
    number names the path; the rig is left unchanged."""
    import warnings

    rig = hydrocyl.Rig.load("leaney-moog")
    before = rig.get("load.mass")
    with pytest.raises(ValueError) as py_bool:
        rig.set("load.mass", True)
    with pytest.raises(ValueError) as np_bool:
        rig.set("load.mass", np.True_)
    assert str(np_bool.value) == str(py_bool.value)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for z in (3 + 1j, np.complex128(3 + 1j), np.array(3 + 0j)):
            with pytest.raises(TypeError, match=r"^rig `load.mass`: .* is complex; a parameter is a real number$"):
                rig.set("load.mass", z)
            with pytest.raises(TypeError, match=r"^rig `load.mass`: .* is complex"):
                rig.update({"load.mass": z})
    with pytest.raises(TypeError, match=r"^rig `load.mass`: expected a number, got a 1-D array of shape \(2\)"):
        rig.set("load.mass", np.array([1.0, 2.0]))
    with pytest.raises(TypeError, match=r"^rig `load.mass`: a parameter is a number, a string, a bool or None, not dict$"):
        rig.set("load.mass", {"a": 1})
    assert rig.get("load.mass") == before
    # numpy's numbers and 0-D arrays are numbers
    for x in (np.float32(60.5), np.int64(61), np.array(62.0)):
        rig.set("load.mass", x)
        assert rig.get("load.mass") == float(x)


def test_describe_gives_each_parameters_value_unit_and_meaning_from_the_registry(cli):
    """`describe()` (documented, once missing): `{path: {value, unit, doc}}`
    for every parameter, the unit and meaning those of the component
    registry, as `hydrocyl components --type <type>` prints them."""
    rig = hydrocyl.Rig.load("leaney-moog")
    described = rig.describe()
    assert list(described) == list(rig.parameters())
    assert described["load.mass"] == {"value": 100.0, "unit": "kg", "doc": "moving mass m"}
    types = {name: c["type"] for name, c in json.loads(rig.to_json())["components"].items()}
    tables = {}
    for path, entry in described.items():
        assert set(entry) == {"value", "unit", "doc"}, path
        assert entry["value"] == rig.parameters()[path], path
        component, name = path.split(".", 1)
        ty = types[component]
        if ty not in tables:
            tables[ty] = run_cli(cli, "components", "--type", ty)[1].splitlines()
        row = f"| `{name}` | {entry['unit']} |"
        assert any(line.startswith(row) and line.endswith(f"| {entry['doc']} |") for line in tables[ty]), path
    assert described["cylinder.initial.p1"]["value"] is None
    assert described["cylinder.initial.p1"]["unit"] == "Pa"


def test_null_parameters_are_none_and_stay_null_through_update():
    """`cylinder.initial.p1` is `null` in the preset (computed from the
    steady state): parameters() and get() give None, and
    `update(parameters())` keeps it null, so it still follows the supply."""
    rig = hydrocyl.Rig.load("leaney-moog")
    p1 = "cylinder.initial.p1"
    assert rig.parameters()[p1] is None and rig.get(p1) is None
    again = rig.copy()
    again.update(again.parameters())
    assert again.get(p1) is None and again.parameters() == rig.parameters()
    t = np.linspace(0.0, 0.01, 11)
    u = np.zeros_like(t)
    start = again.simulate(t, u)["p1"][0]
    again.set("supply.pressure", 2 * rig.get("supply.pressure"))
    assert again.simulate(t, u)["p1"][0] > 1.5 * start
    # a number freezes it, None makes it computed again
    again.set(p1, 3e6)
    assert again.get(p1) == 3e6
    again.set(p1, None)
    assert again.get(p1) is None


def test_set_while_another_thread_simulates_succeeds_and_leaves_the_run_alone():
    """`simulate` and `simulate_batch` release the GIL; a `set` from another
    thread meanwhile succeeds (once `RuntimeError: Already borrowed`) and
    does not change the run, which simulates the rig as it was."""
    rig = hydrocyl.Rig.load("leaney-moog")
    mass = path_of(rig, "mass")
    t = np.linspace(0.0, 0.1, 201)
    u = np.where(t < 0.01, 0.0, 0.4)
    settings = dict(solver="rk4", rk4_step=2e-7)  # 5e5 steps: long enough to overlap
    expected = rig.copy().simulate(t, u, **settings)
    for call in (
        lambda: rig.simulate(t, u, **settings),
        lambda: hydrocyl.simulate_batch(rig, t, u, {"supply.pressure": [7e6]}, **settings),
    ):
        rig.set(mass, 100.0)
        out, started = {}, threading.Event()

        def work():
            started.set()
            out["run"] = call()

        worker = threading.Thread(target=work)
        worker.start()
        started.wait()
        time.sleep(0.05)
        during = 0
        while worker.is_alive():
            rig.set(mass, 50.0 + during)
            during += worker.is_alive()
            time.sleep(0.01)
        worker.join()
        assert during > 0
        assert rig.get(mass) > 50.0
        got = out["run"]
        position = got["position"] if got["position"].ndim == 1 else got["position"][0]
        np.testing.assert_array_equal(position, expected["position"])


def test_from_json_reads_the_text_as_load_reads_a_file(repo, tmp_path):
    """from_json and load share one reader: an older `valve-cylinder` file
    becomes its netlist, a duplicate key is refused with its line, a
    retired `hybrid-variant` names the netlists that replace it."""
    legacy = repo / "fixtures" / "legacy" / "festo-hanging-load.rig.json"
    from_text = hydrocyl.Rig.from_json(legacy.read_text())
    assert from_text.kind == "netlist"
    assert from_text == hydrocyl.Rig.load(str(legacy))
    lines = (repo / "fixtures" / "rigs" / "leaney-moog.json").read_text().splitlines()
    assert lines[2].lstrip().startswith('"name"')
    duplicated = "\n".join([*lines[:3], lines[2], *lines[3:]])
    retired = '{"kind": "hybrid-variant"}'
    for text, message in [(duplicated, r"`name`: duplicate key .*\(line 4 of "), (retired, "hybrid-variant` kind is retired")]:
        f = tmp_path / "rig.json"
        f.write_text(text)
        with pytest.raises(ValueError, match=message) as from_file:
            hydrocyl.Rig.load(str(f))
        with pytest.raises(ValueError, match=message) as from_text:
            hydrocyl.Rig.from_json(text)
        assert str(from_text.value).replace("JSON text", str(f)) == str(from_file.value)
        assert "\n" not in str(from_text.value)


def test_load_takes_a_path_like(repo):
    path = repo / "fixtures" / "rigs" / "leaney-moog.json"
    assert hydrocyl.Rig.load(pathlib.Path(path)) == hydrocyl.Rig.load(str(path))
    with pytest.raises(ValueError, match="not a preset"):
        hydrocyl.Rig.load(pathlib.Path("no-such-rig.json"))


def flatten(prefix, value):
    """{path: value} of a nested dict that `get` gave for `prefix`."""
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            out.update(flatten(f"{prefix}.{k}", v))
        return out
    return {prefix: value}


def test_get_on_an_inner_path_gives_its_parameters_as_a_dict():
    for name in hydrocyl.PRESETS:
        rig = hydrocyl.Rig.load(name)
        ps = rig.parameters()
        inner = {p.rsplit(".", k)[0] for p in ps for k in range(1, p.count(".") + 1)}
        assert inner, name
        for prefix in inner:
            got = rig.get(prefix)
            assert isinstance(got, dict), (name, prefix)
            under = {p: v for p, v in ps.items() if p.startswith(prefix + ".")}
            # every parameter under it, nested as the paths are
            assert flatten(prefix, got) == under, (name, prefix)
    rig = hydrocyl.Rig.load("leaney-moog")
    cylinder = rig.get("cylinder")
    assert cylinder["area_1"] == rig.get("cylinder.area_1")
    assert cylinder["initial"]["p1"] is None and rig.get("cylinder.initial") == cylinder["initial"]
    assert rig.get("valve.orifice") == {k: rig.get(f"valve.orifice.{k}") for k in ("cd", "density", "dp_transition")}
    assert rig.get("valve")["orifice"]["cd"] == rig.get("valve.orifice.cd")
    # a prefix of a name is not a path
    with pytest.raises(ValueError, match="unknown rig parameter"):
        rig.get("cyl")


@pytest.mark.parametrize("preset", ["leaney-moog", "wang-hybrid", "emps"])
def test_to_json_is_what_print_rig_prints(cli, preset):
    # every parameter written out, defaults filled in, as --print-rig does
    # (it used to give the preset's file as written, defaults left out)
    rig = hydrocyl.Rig.load(preset)
    path = path_of(rig, "mass")
    rig.set(path, 42.0)
    _, out, _ = run_cli(cli, "simulate", "--rig", preset, "--set", f"{path}=42", "--print-rig")
    assert json.loads(rig.to_json()) == json.loads(out)
