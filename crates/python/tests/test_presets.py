"""Every preset of the package's preset list, and every netlist file in
fixtures/rigs/, loads and runs through the package, and equals the CLI on
the same rig and command (so a preset added to `rig::PRESETS` is covered
without a test edit)."""

import json

import numpy as np
import pytest

import hydrocyl
from conftest import read_csv, run_cli, write_command


def command_for(rig):
    """A short input each rig kind reads, and its CSV column: the pump's
    drive voltage [V], a bench drive's velocity [m/s] (ramped), a
    closed-loop rig's position set-point [m] (`reference`), a valve's
    normalised demand."""
    spec = json.loads(rig.to_json())
    types = {c.get("type") for c in spec.get("components", {}).values()}
    t = np.linspace(0.0, 0.1, 201)
    if "imposed_motion" in types:
        return t, 0.01 * np.minimum(t / 0.05, 1.0), "command"
    if "position_controller" in types:
        return t, np.where(t < 0.01, 0.0, 0.01), "reference"
    pump = "pump" in spec.get("components", {})
    level = 2.0 if pump else 0.3
    return t, np.where(t < 0.01, 0.0, level), "command"


def netlist_files(repo):
    """Every rig file of fixtures/rigs/ a user runs (all netlists)."""
    files = sorted((repo / "fixtures/rigs").glob("*.json"))
    files += sorted((repo / "fixtures/rigs/examples").glob("*.json"))
    kinds = ("netlist",)
    return [f for f in files if json.loads(f.read_text()).get("kind") in kinds]


@pytest.mark.parametrize("name", hydrocyl.PRESETS)
def test_every_preset_runs_and_equals_the_cli(cli, tmp_path, name):
    rig = hydrocyl.Rig.load(name)
    assert rig.parameters(), name
    t, u, column = command_for(rig)
    run = rig.simulate(t, u, solver="rosenbrock")
    assert run.names and all(np.isfinite(run[c]).all() for c in run.names), name
    cmd, out = tmp_path / "cmd.csv", tmp_path / "out.csv"
    write_command(cmd, t, u, column)
    run_cli(cli, "simulate", "--rig", name, "--command", cmd, "--out", out, "--solver", "rosenbrock")
    csv = read_csv(out)
    assert ["time", *run.names] == list(csv)
    for c in run.names:
        scale = max(1.0, float(np.abs(csv[c]).max()))
        assert float(np.abs(run[c] - csv[c]).max()) <= 1e-12 * scale, (name, c)


def test_every_netlist_file_loads_and_runs(repo):
    files = netlist_files(repo)
    assert len(files) >= len(hydrocyl.PRESETS)
    for f in files:
        rig = hydrocyl.Rig.load(str(f))
        t, u, _ = command_for(rig)
        run = rig.simulate(t, u, solver="rosenbrock")
        assert all(np.isfinite(run[c]).all() for c in run.names), f.name


def test_variant_files_run_and_equal_the_cli(cli, repo, tmp_path):
    """The hybrid drive's chapter-9 variants (netlists `wang-hybrid-*.json`)
    load from any folder, run, and equal `hydrocyl simulate` on them."""
    files = [f for f in netlist_files(repo) if f.stem.startswith("wang-hybrid-")]
    assert files
    for f in files:
        rig = hydrocyl.Rig.load(str(f))
        t, u, column = command_for(rig)
        run = rig.simulate(t, u, solver="rosenbrock")
        cmd, out = tmp_path / "cmd.csv", tmp_path / f"{f.stem}.csv"
        write_command(cmd, t, u, column)
        run_cli(cli, "simulate", "--rig", f, "--command", cmd, "--out", out, "--solver", "rosenbrock")
        csv = read_csv(out)
        for c in run.names:
            scale = max(1.0, float(np.abs(csv[c]).max()))
            assert float(np.abs(run[c] - csv[c]).max()) <= 1e-12 * scale, (f.name, c)


def test_a_bench_preset_gives_the_load_cell_force():
    """tudelft-seal-25 at a constant imposed velocity, after the bristles
    settle: the load cell reads the chamber's p A2 plus the Coulomb level
    (LuGre's steady state, no viscous term in the preset)."""
    rig = hydrocyl.Rig.load("tudelft-seal-25")
    rig.set("chamber.pressure", 2e5)
    t = np.linspace(0.0, 0.5, 501)
    run = rig.simulate(t, np.full_like(t, 0.01), rtol=1e-9)
    area = np.pi * 0.0125**2
    assert abs(run["force"][-1] - (2e5 * area + 5.0)) < 1e-6
    np.testing.assert_allclose(run["position"], 0.01 * t, rtol=0, atol=1e-12)
