"""Run warnings: a command beyond the maximum speed of the pump it drives,
or a spool demand beyond the spool's stroke, is warned of as the CLI warns
of it (one text, from the library), once per run, and in a batch naming the
run."""

import subprocess
import warnings

import numpy as np

import hydrocyl
from conftest import path_of, write_command


def pump_step(level):
    t = np.linspace(0.0, 0.5, 501)
    return t, np.where(t < 0.1, 0.0, level)


def recorded(call):
    """The warnings `call()` raises (every one, not deduplicated) and its
    result."""
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out = call()
    return [x for x in w if issubclass(x.category, hydrocyl.RatingWarning)], out


def cli_warning(cli, tmp_path, t, u, rig="wang-hybrid", words="maximum speed"):
    """The CLI's warning holding `words` on the command (t, u), after its
    file name."""
    cmd = tmp_path / "cmd.csv"
    write_command(cmd, t, u)
    p = subprocess.run([cli, "simulate", "--rig", rig, "--command", cmd, "--out", tmp_path / "out.csv"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    prefix = f"hydrocyl: warning: {cmd}: "
    lines = [line for line in p.stderr.splitlines() if words in line]
    assert len(lines) == 1 and lines[0].startswith(prefix), p.stderr
    return lines[0][len(prefix):]


def test_a_command_beyond_the_pumps_rating_warns_with_the_clis_text(cli, tmp_path):
    assert issubclass(hydrocyl.RatingWarning, UserWarning)
    t, u = pump_step(30.0)
    expected = cli_warning(cli, tmp_path, t, u)
    assert expected.startswith(f"{np.count_nonzero(u)} command samples beyond the maximum speed of `pump`")
    w, run = recorded(lambda: hydrocyl.Rig.load("wang-hybrid").simulate(t, u))
    assert [str(x.message) for x in w] == [f"command (t, u): {expected}"]
    assert run["position"].size == t.size  # the run is returned


def test_a_command_within_the_rating_does_not_warn():
    w, _ = recorded(lambda: hydrocyl.Rig.load("wang-hybrid").simulate(*pump_step(2.0)))
    assert w == []


def test_a_batch_warns_once_for_each_run_beyond_the_rating_naming_it():
    rig = hydrocyl.Rig.load("wang-hybrid")
    t, u = pump_step(30.0)
    path = path_of(rig, "max_speed")
    rated = rig.get(path)
    single, _ = recorded(lambda: rig.simulate(t, u))
    # run 0's pump is rated ten times faster: within its rating
    w, batch = recorded(lambda: hydrocyl.simulate_batch(rig, t, u, {path: [10 * rated, rated, rated]}))
    assert batch.ok.all()
    assert [str(x.message) for x in w] == [f"run {i} ({path}={rated!r}): {single[0].message}" for i in (1, 2)]


def test_a_batch_checks_each_run_against_its_own_rigs_rating():
    """The limit is the run's rig's, not the base rig's: a set that rates
    an unrated pump makes its run warn; one that rates it ten times faster
    does not."""
    rig = hydrocyl.Rig.load("wang-hybrid")
    t, u = pump_step(30.0)
    path = path_of(rig, "max_speed")
    rated = rig.get(path)
    single, _ = recorded(lambda: rig.simulate(t, u))
    unrated = rig.copy()
    unrated.set(path, None)
    quiet, _ = recorded(lambda: unrated.simulate(t, u))
    assert quiet == [] and len(single) == 1
    w, batch = recorded(lambda: hydrocyl.simulate_batch(unrated, t, u, {path: [10 * rated, rated]}))
    assert batch.ok.all()
    assert [str(x.message) for x in w] == [f"run 1 ({path}={rated!r}): {single[0].message}"]


def test_the_rating_warning_can_be_made_an_error():
    t, u = pump_step(30.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", hydrocyl.RatingWarning)
        try:
            hydrocyl.Rig.load("wang-hybrid").simulate(t, u)
        except hydrocyl.RatingWarning as e:
            assert "maximum speed" in str(e)
        else:
            raise AssertionError("no RatingWarning raised")


def test_a_spool_demand_beyond_the_stroke_warns_with_the_clis_text(cli, tmp_path):
    t = np.linspace(0.0, 0.1, 201)
    u = np.where(t < 0.01, 0.0, 1.5)
    expected = cli_warning(cli, tmp_path, t, u, rig="leaney-moog", words="outside ±1")
    assert expected.startswith(f"{np.count_nonzero(u)} command samples outside ±1")
    w, _ = recorded(lambda: hydrocyl.Rig.load("leaney-moog").simulate(t, u))
    assert [str(x.message) for x in w] == [f"command (t, u): {expected}"]
    within, _ = recorded(lambda: hydrocyl.Rig.load("leaney-moog").simulate(t, u / 2))
    assert within == []

