"""diagnose: the report `hydrocyl diagnose --report` writes, from a CSV path
or a dict of arrays."""

import json
import re

import numpy as np
import pytest

import hydrocyl
from conftest import run_cli, unaligned

RECORD = "fixtures/measured/valve-internal_leakage.csv"


def comparable(report):
    """The report without its timings and record names."""
    return {k: v for k, v in report.items() if k not in ("elapsed_s", "wall_times_s", "records")}


@pytest.fixture(scope="module")
def report(repo):
    return hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), str(repo / RECORD), effects=["internal_leakage"])


def test_diagnose_equals_the_cli_report(cli, repo, tmp_path, report):
    out = tmp_path / "report.json"
    run_cli(cli, "diagnose", "--rig", "leaney-moog", "--data", repo / RECORD, "--effects", "internal_leakage",
            "--report", out, "--quiet")
    assert comparable(report) == comparable(json.loads(out.read_text()))
    assert [e["id"] for e in report["effects_added"]] == ["internal_leakage"]
    assert report["nrmse_after"]["position"] < report["nrmse_before"]["position"]


def test_effects_as_one_string_is_a_one_element_list(repo, report):
    got = hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), str(repo / RECORD), effects="internal_leakage")
    assert comparable(got) == comparable(report)


def test_effects_of_another_type_is_a_type_error_naming_it(repo):
    with pytest.raises(TypeError, match="effects: a list of effect ids or one id as a string"):
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), str(repo / RECORD), effects=3)


def test_a_dict_record_gives_the_same_report(repo, report):
    path = repo / RECORD
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    record = {h: data[:, i] for i, h in enumerate(header)}
    got = hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), record, effects=["internal_leakage"])
    assert comparable(got) == comparable(report)


def test_a_dict_record_of_unaligned_arrays_gives_the_same_report(repo, report):
    path = repo / RECORD
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    record = {h: unaligned(data[:, i]) for i, h in enumerate(header)}
    got = hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), record, effects=["internal_leakage"])
    assert comparable(got) == comparable(report)


def test_a_dict_record_column_of_complex_numbers_is_a_type_error_naming_it(repo):
    path = repo / RECORD
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    record = {h: data[:, i] for i, h in enumerate(header)}
    record[header[1]] = record[header[1]].astype(np.complex128)
    with pytest.raises(TypeError, match=rf"column '{re.escape(header[1])}': complex numbers are not accepted"):
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), record, effects=["internal_leakage"])


def test_diagnose_errors(repo):
    rig = hydrocyl.Rig.load("leaney-moog")
    with pytest.raises(ValueError, match="min_share 2: must be in"):
        hydrocyl.diagnose(rig, str(repo / RECORD), min_share=2)
    with pytest.raises(ValueError, match="effects: unknown effect 'gremlins'"):
        hydrocyl.diagnose(rig, str(repo / RECORD), effects=["gremlins"])
    with pytest.raises(ValueError):  # not the valve-cylinder circuit
        hydrocyl.diagnose(hydrocyl.Rig.load("wang-hybrid"), str(repo / RECORD))
    t = np.linspace(0, 1, 50)
    with pytest.raises(ValueError, match="position"):
        hydrocyl.diagnose(rig, {"time": t, "command": 0 * t})
    with pytest.raises(ValueError, match="no-such.csv"):
        hydrocyl.diagnose(rig, str(repo / "no-such.csv"))
    # a dict record's columns are named in quotes, as the CSV readers name them
    with pytest.raises(ValueError) as e:
        hydrocyl.diagnose(rig, {"time": t, "command": t[:-2], "position": t})
    assert str(e.value) == "record (dict; row 2 = element 0): column 'command' has 48 values, column 'time' 50"
    with pytest.raises(ValueError, match=r"^record \(dict; row 2 = element 0\): column 'p1 \[bar\]': expected a 1-D array"):
        hydrocyl.diagnose(rig, {"time": t, "p1 [bar]": np.zeros((2, 2))})


@pytest.mark.parametrize("window", [1, 0, -1])
def test_a_window_below_two_is_a_value_error_naming_it(repo, window):
    # a half-width of 1 (3 samples) interpolates the order-3 smoother's 4 coefficients
    with pytest.raises(ValueError) as e:
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), str(repo / RECORD), window=window)
    assert str(e.value).startswith(f"window {window}: must be at least 2: the order-3 smoother")
