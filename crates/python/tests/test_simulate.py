"""Rig.simulate: equal to `hydrocyl simulate` on the same rig and command,
the energy ledger, pandas as an optional extra, and errors."""

import re
import sys
import types
import warnings

import numpy as np
import pytest

import hydrocyl
from conftest import path_of, read_csv, run_cli, write_command


def assert_equal_to_cli(run, csv):
    assert ["time", *run.names] == list(csv)
    np.testing.assert_array_equal(run.time, csv["time"])
    for name in run.names:
        scale = max(1.0, float(np.abs(csv[name]).max()))
        diff = float(np.abs(run[name] - csv[name]).max())
        assert diff <= 1e-12 * scale, (name, diff)


@pytest.mark.parametrize(
    "preset, level, solver",
    [("leaney-moog", 0.4, "dp45"), ("leaney-moog", -0.3, "rosenbrock"), ("wang-hybrid", 2.0, "dp45"),
     # the hybrid's algebraic node starts each solve from its last: the CLI
     # reads outputs during the solve, Python after it, and the same run
     # comes out only if reading leaves the circuit as it found it
     ("wang-hybrid", 2.0, "rosenbrock"), ("wang-hybrid", 2.0, "auto")],
)
def test_simulate_equals_the_cli(cli, tmp_path, preset, level, solver):
    t = np.linspace(0.0, 0.2, 401)
    u = np.where(t < 0.01, 0.0, level)
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u)
    run_cli(cli, "simulate", "--rig", preset, "--command", cmd, "--out", out, "--solver", solver)
    run = hydrocyl.Rig.load(preset).simulate(t, u, solver=solver)
    assert_equal_to_cli(run, read_csv(out))
    assert run.stats["steps"] > 0 and run.units["position"] == "m"


def test_simulate_with_set_equals_the_cli(cli, tmp_path, step):
    t, u = step
    rig = hydrocyl.Rig.load("leaney-moog")
    mass = path_of(rig, "mass")
    rig.set(mass, 60.5)
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u)
    run_cli(cli, "simulate", "--rig", "leaney-moog", "--set", f"{mass}=60.5", "--rtol", "1e-8",
            "--command", cmd, "--out", out)
    assert_equal_to_cli(rig.simulate(t, u, rtol=1e-8), read_csv(out))


def test_channels_are_numpy_arrays_by_name(step):
    t, u = step
    run = hydrocyl.Rig.load("leaney-moog").simulate(list(t), list(u))
    assert set(run.channels) == set(run.names) and "position" in run
    assert run["position"].shape == t.shape and run["position"].dtype == np.float64
    assert run.channels["position"] is run["position"] or np.array_equal(run.channels["position"], run["position"])
    assert run["position"][-1] > 0.0  # a positive command extends the rod
    with pytest.raises(KeyError, match="channels: command, position"):
        run["nope"]


def test_ledger_closes_and_is_absent_unless_asked(step):
    t, u = step
    rig = hydrocyl.Rig.load("leaney-moog")
    assert rig.simulate(t, u).ledger is None
    led = rig.simulate(t, u, ledger=True).ledger
    assert led["energy_in_j"] > 0.0
    assert abs(led["error"]) < 1e-3
    assert 0.0 < led["efficiency"] < 1.0
    assert sum(led["losses_j"].values()) < led["energy_in_j"]


def test_a_plastic_impact_is_the_mass_loss_in_the_ledger():
    # the piston runs into its stroke end at full spool: the kinetic energy the
    # impact destroys is the load's loss, and the load stores nothing at rest
    t = np.linspace(0.0, 1.0, 1001)
    rig = hydrocyl.Rig.load("leaney-moog")
    rig.set("cylinder.initial.position", 0.1)
    run = rig.simulate(t, np.ones_like(t), ledger=True, rtol=1e-9)
    led = run.ledger
    impact = run.diagnostics["load.stop_impact_energy_j"]
    assert led["losses_j"]["load"] == pytest.approx(impact, rel=1e-9)
    assert abs(led["storage_j"].get("load", 0.0)) < 1e-6
    assert abs(led["storage_error"]) < 1e-9
    assert "moving_walls_j" in led


def test_to_pandas_uses_pandas_when_there_and_says_so_when_not(step, monkeypatch):
    t, u = step
    run = hydrocyl.Rig.load("leaney-moog").simulate(t, u)
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas fails
    with pytest.raises(ImportError, match="needs pandas"):
        run.to_pandas()
    fake = types.ModuleType("pandas")
    fake.DataFrame = lambda columns: ("frame", columns)
    monkeypatch.setitem(sys.modules, "pandas", fake)
    kind, columns = run.to_pandas()
    assert kind == "frame" and list(columns) == ["time", *run.names]
    np.testing.assert_array_equal(columns["position"], run["position"])


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"solver": "euler"}, "solver: unknown method `euler` (use auto, dp45, rosenbrock, rk4 or exponential)"),
        ({"rtol": 0.0}, "rtol 0: must be in [1e-14, 1), e.g. 1e-6"),
        ({"rtol": 1e-300}, "rtol 1e-300: below 1e-14 (about 50 machine epsilons), a tolerance double precision "
                           "cannot meet; use a value in [1e-14, 1), e.g. 1e-6"),
        ({"rk4_step": -1.0}, "rk4_step -1: must be finite and > 0 [s], e.g. 2e-5"),
    ],
)
def test_bad_settings(step, kwargs, message):
    t, u = step
    with pytest.raises(ValueError) as e:
        hydrocyl.Rig.load("leaney-moog").simulate(t, u, **kwargs)
    assert str(e.value) == message


def test_bad_commands(step):
    t, u = step
    rig = hydrocyl.Rig.load("leaney-moog")
    u_nan = u.copy()
    u_nan[7] = np.nan
    with pytest.raises(ValueError, match="command sample 7: .*not finite"):
        rig.simulate(t, u_nan)
    t_back = t.copy()
    t_back[5] = t_back[4]
    with pytest.raises(ValueError, match="command sample 5: time .* does not increase"):
        rig.simulate(t_back, u)
    # t and u of different lengths: said so, not as a sample's fault
    # (it was `command sample 400: 401 times but 400 values`)
    with pytest.raises(ValueError) as e:
        rig.simulate(t, u[:-1])
    assert str(e.value) == "command (t, u): t has 401 samples but u has 400 (one command value per time)"
    with pytest.raises(ValueError, match=r"^command \(t, u\): t has 401 samples but u has 402"):
        hydrocyl.simulate_batch(rig, t, np.append(u, 0.0), {"load.mass": [50.0]})
    with pytest.raises(ValueError, match="at least two samples"):
        rig.simulate(t[:1], u[:1])


def test_solver_failure_is_a_simulation_error_with_time_and_state(cli, tmp_path, step):
    """An initial chamber pressure of 1e30 Pa is finite (the rig accepts it)
    but no step size meets the tolerance from there."""
    t, u = step
    rig = hydrocyl.Rig.load("leaney-moog")
    p1 = path_of(rig, "p1")
    rig.set(p1, 1e30)
    with pytest.raises(hydrocyl.SimulationError) as e:
        rig.simulate(t, u, solver="dp45")
    err = e.value
    assert err.time == t[0]
    assert err.state and all(np.isfinite(v) for v in err.state.values())
    assert 1e30 in err.state.values()
    assert f"at t = {err.time:g} s" in str(err) and "state at t" in str(err)
    # the CLI's line comes first
    cmd = tmp_path / "cmd.csv"
    write_command(cmd, t, u)
    code, _, line = run_cli(cli, "simulate", "--rig", "leaney-moog", "--set", f"{p1}=1e30", "--command", cmd,
                            "--solver", "dp45", "--out", tmp_path / "o.csv", expect_ok=False)
    assert code == 2 and line.startswith("simulation: solver dp45") and str(err).startswith(line)
    assert not isinstance(err, ValueError)


def test_a_solver_failure_in_mid_run_carries_the_state_before_it(cli, tmp_path):
    """A bristle stiffness of 1e9 N/m on the seal bench with RK4 at 0.1 ms:
    stable at rest, the step blows up once the imposed velocity makes the
    bristle fast (σ0 |v| h / Fc > 2.8, v > 0.14 mm/s): the solver stops in
    mid-run, and the error carries the last finite state the run reached
    before the failing step."""
    rig = hydrocyl.Rig.load("tudelft-seal-25")
    rig.set("friction.sigma0", 1e9)
    t = np.linspace(0.0, 0.2, 201)
    u = 0.01 * t / 0.2
    with pytest.raises(hydrocyl.SimulationError) as e:
        rig.simulate(t, u, solver="rk4", rk4_step=1e-4)
    err = e.value
    assert t[0] < err.time < t[-1]
    assert err.state and all(np.isfinite(v) for v in err.state.values())
    # the drive's position is the integral of the imposed velocity up to there
    x = next(v for k, v in err.state.items() if k.startswith("drive."))
    assert abs(x - 0.01 * err.time**2 / 0.4) < 1e-9
    assert f"state at t = {err.time} s" in str(err)
    # the CLI's line comes first
    cmd = tmp_path / "cmd.csv"
    write_command(cmd, t, u)
    code, _, line = run_cli(cli, "simulate", "--rig", "tudelft-seal-25", "--set", "friction.sigma0=1e9",
                            "--command", cmd, "--solver", "rk4", "--rk4-step", "1e-4",
                            "--out", tmp_path / "o.csv", expect_ok=False)
    # ... then the CLI's remedy in its own flags (Python's error carries the state instead)
    cause, remedy = line.split("; --rk4-step ", 1)
    assert code == 2 and cause.startswith("simulation: solver rk4") and str(err).startswith(cause)
    assert "is likely too large for this rig" in remedy


def test_a_panic_becomes_a_runtime_error():
    with pytest.raises(RuntimeError, match="internal error .*deliberate test panic"):
        hydrocyl._panic_for_test()


@pytest.mark.parametrize(
    "preset, level, column",
    [("leaney-moog", 0.4, "command"), ("wang-hybrid", 2.0, "command"), ("leaney-moog-closed-loop", 0.01, "reference")],
)
def test_units_are_those_of_the_cli_header(cli, tmp_path, preset, level, column):
    """run.units agrees with the CLI's output header (`command [V]` on the
    pump rig, once `-` in Python; the closed-loop set-point in m)."""
    t = np.linspace(0.0, 0.05, 51)
    u = np.where(t < 0.01, 0.0, level)
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u, column)
    run_cli(cli, "simulate", "--rig", preset, "--command", cmd, "--out", out)
    header = out.read_text().splitlines()[0].split(",")
    units = {m.group(1): m.group(2) or "" for m in (re.fullmatch(r"(.*?)(?: \[(.*)\])?", h) for h in header)}
    run = hydrocyl.Rig.load(preset).simulate(t, u)
    assert units.pop("time") == "s"
    assert run.units == units
    assert run.units["command"] == ("V" if preset == "wang-hybrid" else "-")
    if column == "reference":
        assert run.units["reference"] == "m"


@pytest.mark.parametrize("arg", ["t", "u"])
@pytest.mark.parametrize("bad", ["2-D", "0-D", "None"])
def test_a_command_that_is_not_1d_is_a_one_line_value_error_naming_it(step, arg, bad):
    t, u = step
    value = {"2-D": np.stack([t, t]), "0-D": np.float64(1.0), "None": None}[bad]
    args = {"t": t, "u": u, arg: value}
    rig = hydrocyl.Rig.load("leaney-moog")
    for call in (
        lambda: rig.simulate(args["t"], args["u"]),
        lambda: hydrocyl.simulate_batch(rig, args["t"], args["u"], {"load.mass": [100.0]}),
    ):
        with pytest.raises(ValueError) as e:
            call()
        message = str(e.value)
        assert message.startswith(f"{arg}: ") and "1-D array" in message, message
        assert "\n" not in message


def test_iterating_a_run_or_a_batch_gives_the_channel_names(step):
    t, u = step
    rig = hydrocyl.Rig.load("leaney-moog")
    run = rig.simulate(t, u)
    assert list(run) == run.names == run.keys()
    assert [k for k in run] == run.names and dict(run.channels).keys() == set(run)
    batch = hydrocyl.simulate_batch(rig, t, u, {"load.mass": [90.0, 110.0]})
    assert list(batch) == batch.names and len(batch) == 2


def test_the_default_solver_is_the_clis_auto(cli, tmp_path, repo):
    """Python's default solver is `auto`, as the CLI's `--solver`; the stub
    lists every solver the package accepts."""
    assert 'solver="auto"' in hydrocyl.Rig.simulate.__text_signature__
    assert 'solver="auto"' in hydrocyl.simulate_batch.__text_signature__
    rig = hydrocyl.Rig.load("tudelft-seal-25")
    t = np.linspace(0.0, 0.2, 201)
    u = 0.01 * t / 0.2
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u)
    run_cli(cli, "simulate", "--rig", "tudelft-seal-25", "--command", cmd, "--out", out)
    assert_equal_to_cli(rig.simulate(t, u), read_csv(out))
    default, auto = rig.simulate(t, u).stats, rig.simulate(t, u, solver="auto").stats
    assert {k: v for k, v in default.items() if k != "wall_s"} == {k: v for k, v in auto.items() if k != "wall_s"}
    stub = (repo / "crates" / "python" / "hydrocyl.pyi").read_text()
    listed = re.findall(r'"(\w+)"', re.search(r"Solver = Literal\[(.*?)\]", stub).group(1))
    with pytest.raises(ValueError) as e:
        rig.simulate(t, u, solver="euler")
    accepted = re.findall(r"\w+", str(e.value).split("(use ")[1])
    assert sorted(listed) == sorted(w for w in accepted if w != "or")
    for name in listed:
        rig.simulate(t, u, solver=name)
    assert stub.count('solver: Solver = "auto"') == 2


def test_a_run_that_is_not_physical_is_a_simulation_error():
    """A fixed rk4 step far too long for the rig blows up (a non-finite
    value, or a chamber pressure below the liquid's tension limit of
    -1000 bar). It is a SimulationError naming the sample and the remedy,
    as the CLI's line."""
    t = np.linspace(0.0, 0.5, 501)
    u = 0.2 * np.sin(4.0 * np.pi * t)
    rig = hydrocyl.Rig.load("leaney-moog")
    with pytest.raises(hydrocyl.SimulationError) as e:
        rig.simulate(t, u, solver="rk4", rk4_step=0.1)
    err = e.value
    assert "the rk4 solution is unstable" in str(err) and "rk4_step 0.1" in str(err)
    assert err.time in t and err.state
    # the same rig with a sound step runs
    assert np.isfinite(rig.simulate(t, u, solver="rk4").time).all()


def test_a_ledger_over_a_form_that_does_not_conserve_energy_says_whose():
    t = np.linspace(0.0, 0.3, 301)
    u = np.full_like(t, 0.5)
    led = hydrocyl.Rig.load("leaney-moog").simulate(t, u, ledger=True, rtol=1e-9).ledger
    assert led["not_energy_consistent"] == [] and abs(led["error"]) < 1e-12
    led = hydrocyl.Rig.load("leaney-moog-generalised").simulate(t, u, ledger=True, rtol=1e-9).ledger
    assert led["not_energy_consistent"] == ["cylinder"]


def chapter3_sawtooth(seconds=6.0):
    """The chapter-3 sawtooth (crates/studies/src/chapter3.rs): u from -0.52
    to +0.52, period 1.5 s, 1-ms samples."""
    t = np.round(np.arange(int(round(seconds * 1000)) + 1) * 1e-3, 3)
    return t, 0.52 * (2.0 * np.mod(t / 1.5, 1.0) - 1.0)


def test_a_chamber_far_below_vacuum_warns_and_returns_the_run(cli, tmp_path):
    """The sawtooth's drop reverses a 100 kg load at ~0.3 m/s: chamber 1 of
    the constant-B oil falls to -14.9 bar with any method (docs/models.md
    section 3). Not an error: a CavitationWarning (a UserWarning) with the
    CLI's facts in Python's words, and the run, the same as the CLI writes."""
    assert issubclass(hydrocyl.CavitationWarning, UserWarning)
    t, u = chapter3_sawtooth()
    rig = hydrocyl.Rig.load("leaney-moog")
    with pytest.warns(hydrocyl.CavitationWarning) as w:
        run = rig.simulate(t, u)
    assert len(w) == 1
    msg = str(w[0].message)
    for part in ["a chamber pressure fell far below absolute vacuum (p1 of `cylinder` fell below -1.01325e6 Pa at t = 1.505 s",
                 "lowest -1.4885e6 Pa at t = 1.507 s", "has left its range from then on", "cavitates",
                 "rig.set('cylinder.air_fraction', 0.005)", "a smaller rtol or solver='rosenbrock'"]:
        assert part in msg, (part, msg)
    assert np.isfinite(run["p1"]).all() and -1.49e6 < run["p1"].min() < -1.48e6
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u)
    code, _, _ = run_cli(cli, "simulate", "--rig", "leaney-moog", "--command", cmd, "--out", out)
    assert code == 0
    assert_equal_to_cli(run, read_csv(out))
    # a fixed step is told how to find whether it is to blame
    with pytest.warns(hydrocyl.CavitationWarning, match=r"a smaller rk4_step than 0\.0005 tells whether the rk4 step"):
        rig.simulate(t, u, solver="rk4", rk4_step=5e-4)
    # the warning filters apply: as an error it is raised
    with warnings.catch_warnings():
        warnings.simplefilter("error", hydrocyl.CavitationWarning)
        with pytest.raises(hydrocyl.CavitationWarning):
            rig.simulate(t, u)
    # the remedy it names removes it
    rig.set("cylinder.air_fraction", 0.005)
    with warnings.catch_warnings():
        warnings.simplefilter("error", hydrocyl.CavitationWarning)
        assert rig.simulate(t, u)["p1"].min() > -1.01325e6
