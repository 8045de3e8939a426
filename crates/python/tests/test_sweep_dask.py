"""examples/python/sweep_dask.py on a LocalCluster of 2 worker processes
gives the figures of one simulate_batch in this process, exactly."""

import importlib.util

import distributed  # required: `cargo xtask test` installs it (no silent skip)
import numpy as np

import hydrocyl
from conftest import REPO


def load_example():
    spec = importlib.util.spec_from_file_location("sweep_dask", REPO / "examples" / "python" / "sweep_dask.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_sweep_on_two_workers_equals_one_process():
    sweep = load_example()
    rig = hydrocyl.Rig.load("leaney-moog")
    params = sweep.sample_parameters(rig, 60, seed=7)
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    try:
        with distributed.Client(cluster) as client:
            figures, tasks, _ = sweep.sweep(client, rig, params, chunk_size=16)
            workers = {w for w in client.run(lambda: 1)}
    finally:
        cluster.close()
    assert tasks == 4 and len(workers) == 2
    local = sweep.sweep_local(rig, params)
    assert set(local) == set(figures)
    for k in local:
        assert figures[k].shape == (60,)
        np.testing.assert_array_equal(figures[k], local[k])
    # the tolerances move the response: the figures are not all alike
    assert np.ptp(local["rise_time"]) > 0.0 and np.ptp(local["v_final"]) > 0.0


def test_main_runs_and_checks_equality(capsys):
    sweep = load_example()
    figures = sweep.main(["--n", "40", "--chunk", "10", "--workers", "2", "--compare"])
    out = capsys.readouterr().out
    assert "runs/s" in out and "equal to the sweep: True" in out and "overhead per task" in out
    assert len(figures["p_min"]) == 40
