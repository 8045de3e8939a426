"""Rig: loading, parameter paths (round trip, --set semantics), JSON, pickling,
and errors worded as the CLI words them."""

import copy
import math
import pickle

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
