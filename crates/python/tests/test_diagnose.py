"""diagnose: the report `hydrocyl diagnose --report` writes, from a CSV path
or a dict of arrays (or a list of those), on every rig the CLI diagnoses."""

import json
import pathlib
import re

import numpy as np
import pytest

import hydrocyl
from conftest import run_cli, unaligned

RECORD = "fixtures/measured/valve-internal_leakage.csv"
# the real records of spec/measured-data.md, beside the repository (as
# `cargo xtask validate` finds them)
SHARED_DATA = pathlib.Path(__file__).resolve().parents[4] / "shared" / "data"
SEALS = SHARED_DATA / "pneumatic_seal_friction_tudelft" / "csv_with_header"


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


def cli_report(cli, tmp_path, rig, *data, effects=None):
    """The CLI's `--report` JSON for `rig` (a preset name or file) on `data`."""
    out = tmp_path / "cli-report.json"
    args = ["diagnose", "--rig", rig, "--data", *data, "--report", out, "--quiet"]
    if effects:
        args += ["--effects", effects]
    run_cli(cli, *args)
    return json.loads(out.read_text())


def cli_error(cli, *args):
    """The CLI's error line for `args`, which it must refuse (exit 2)."""
    code, _, line = run_cli(cli, *args, expect_ok=False)
    assert code == 2, line
    return line


def seal(name):
    """A real TU Delft seal-friction record (`tudelft-seal-25`'s columns)."""
    path = SEALS / name
    if not path.is_file():
        pytest.skip(f"{path}: the shared real records are not present")
    return path


def test_the_hybrid_rig_is_diagnosed_and_finds_a_planted_leak(cli, tmp_path):
    # a record of wang-hybrid with a cross-piston leak planted (Cl = 5e-12
    # m^3/(s Pa)), run on a 2 V, 1.5 Hz drive voltage: the declared rig
    # (no leak) is the hybrid circuit, which the CLI diagnoses
    planted = hydrocyl.Rig.load("wang-hybrid")
    planted.set("cylinder.internal_leakage", 5e-12)
    t = np.linspace(0.0, 1.0, 1001)
    u = 2.0 * np.sin(2 * np.pi * 1.5 * t)
    run = planted.simulate(t, u)
    path = tmp_path / "hybrid.csv"
    cols = {"time": t, "command [V]": u, "position": run["position"], "p1": run["p1"], "p2": run["p2"]}
    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for i in range(len(t)):
            f.write(",".join(repr(float(c[i])) for c in cols.values()) + "\n")
    got = hydrocyl.diagnose(hydrocyl.Rig.load("wang-hybrid"), str(path))
    assert got["rig"] == "wang-hybrid"
    added = {e["id"]: e for e in got["effects_added"]}
    assert "internal_leakage" in added, got["effects_added"]
    # the leak coefficient found is the planted one
    (cl,) = added["internal_leakage"]["params"].values()
    assert cl == pytest.approx(5e-12, rel=0.05)
    assert comparable(got) == comparable(cli_report(cli, tmp_path, "wang-hybrid", path))


def test_a_friction_bench_preset_on_a_real_record_equals_the_cli_report(cli, tmp_path):
    path = seal("NAPN_1bar.csv")
    got = hydrocyl.diagnose(hydrocyl.Rig.load("tudelft-seal-25"), path)
    assert got["rig_kind"] == "friction-bench"
    # the record was read through the preset's `identify.columns`
    # (`time_ms`, `position_mm`, `force_N`, ...): every sample of the file
    assert got["samples"] == len(path.read_text().splitlines()) - 1
    assert got["nrmse_after"]["force"] <= got["nrmse_before"]["force"]
    want = cli_report(cli, tmp_path, "tudelft-seal-25", path)
    assert got["records"] == want["records"] == [str(path)]
    assert comparable(got) == comparable(want)


def test_a_netlists_identify_columns_read_the_record(cli, repo, tmp_path, report):
    # leaney-moog with `identify.columns` naming the position column
    # `x_mm [mm]`: its record, so written, gives the report of the record
    # in the format's own columns, from Python as from the CLI
    rig = json.loads(hydrocyl.Rig.load("leaney-moog").to_json())
    rig["identify"] = {"columns": {"position": "x_mm [mm]"}}
    rig_path = tmp_path / "mapped.json"
    rig_path.write_text(json.dumps(rig))
    lines = (repo / RECORD).read_text().splitlines()
    header = lines[0].split(",")
    x = header.index("position [mm]")
    header[x] = "x_mm [mm]"
    data = tmp_path / "mapped.csv"
    data.write_text("\n".join([",".join(header), *lines[1:]]) + "\n")
    # without the map, the record has no position column
    with pytest.raises(ValueError, match="position"):
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), data, effects="internal_leakage")
    got = hydrocyl.diagnose(hydrocyl.Rig.load(rig_path), data, effects="internal_leakage")
    assert [e["id"] for e in got["effects_added"]] == ["internal_leakage"]
    want = cli_report(cli, tmp_path, rig_path, data, effects="internal_leakage")
    assert comparable(got) == comparable(want)
    # the same numbers as the record in the format's own columns
    for k in ["nrmse_declared", "nrmse_before", "nrmse_after", "effects_added"]:
        assert got[k] == report[k], k


def test_two_records_of_a_bench_are_fitted_jointly_as_the_cli_fits_them(cli, tmp_path):
    # the first 1500 samples (15 s, some strokes) of the NAPN seal at 1 and 5 bar
    paths = []
    for name in ["NAPN_1bar.csv", "NAPN_5bar.csv"]:
        p = tmp_path / name
        p.write_text("\n".join(seal(name).read_text().splitlines()[:1501]) + "\n")
        paths.append(p)
    got = hydrocyl.diagnose(hydrocyl.Rig.load("tudelft-seal-25"), paths)
    assert got["records"] == [str(p) for p in paths]
    assert got["samples"] == 2 * 1500
    want = cli_report(cli, tmp_path, "tudelft-seal-25", *paths)
    assert comparable(got) == comparable(want)
    # a tuple is a list of records too, and gives the same report
    again = hydrocyl.diagnose(hydrocyl.Rig.load("tudelft-seal-25"), tuple(str(p) for p in paths))
    assert comparable(again) == comparable(got)


def test_a_record_given_twice_is_refused_as_the_cli_refuses_it(cli, repo, tmp_path):
    path = str(repo / RECORD)
    line = cli_error(cli, "diagnose", "--rig", "leaney-moog", "--data", path, path)
    with pytest.raises(ValueError) as e:
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), [path, path])
    # the CLI's message, its arguments named as Python's
    assert str(e.value) == line.replace("--data ", "record ").replace("(arguments ", "(records ")
    assert "the same file, given twice" in str(e.value)
    # a dict given twice is the same content
    header = (repo / RECORD).read_text().splitlines()[0].split(",")
    data = np.loadtxt(repo / RECORD, delimiter=",", skiprows=1)
    record = {h: data[:, i] for i, h in enumerate(header)}
    with pytest.raises(ValueError, match=r"^record 1 \(dict\) and record 2 \(dict\) \(records 1 and 2\): the same content"):
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), [record, dict(record)])


def test_a_circuit_takes_one_record_at_a_time_as_in_the_cli(cli, repo):
    a, b = str(repo / RECORD), str(repo / "fixtures/measured/valve-none.csv")
    line = cli_error(cli, "diagnose", "--rig", "leaney-moog", "--data", a, b)
    assert line.startswith("--data: a circuit rig is diagnosed on one record at a time (2 given)"), line
    with pytest.raises(ValueError) as e:
        hydrocyl.diagnose(hydrocyl.Rig.load("leaney-moog"), [a, b])
    assert str(e.value) == line.replace("--data: ", "record: ", 1)


def test_an_unsupported_rig_is_refused_with_the_cli_reason(cli, repo, tmp_path):
    # the emps bench's circuit without its identification section: neither
    # a friction bench nor a cylinder on a mass
    rig = json.loads((repo / "fixtures/rigs/emps.json").read_text())
    del rig["identify"]
    rig_path = tmp_path / "no-identify.json"
    rig_path.write_text(json.dumps(rig))
    line = cli_error(cli, "diagnose", "--rig", rig_path, "--data", repo / RECORD)
    prefix = f"--rig {rig_path}: "
    assert line.startswith(prefix), line
    with pytest.raises(ValueError) as e:
        hydrocyl.diagnose(hydrocyl.Rig.load(rig_path), str(repo / RECORD))
    assert str(e.value) == "rig: " + line[len(prefix):]
    assert "not supported for this rig kind" in str(e.value)
    assert "needs a `cylinder`" in str(e.value)
