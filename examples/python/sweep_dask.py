#!/usr/bin/env python3
"""Monte-Carlo of the leaney-moog valve rig's step response on a Dask cluster.

The bulk modulus, the moving mass and the valve underlap vary uniformly over
their tolerance ranges (TOLERANCES); every sample is one run of the rig on the
same step of the valve command. The samples are drawn up front from one seed
and cut into chunks; each Dask task runs one chunk with
``hydrocyl.simulate_batch`` and returns per-run step-response figures, which
the client puts back in sample order. The result is therefore the same as one
``simulate_batch`` over all samples in one process, on any cluster size.

    python examples/python/sweep_dask.py                  # LocalCluster, 2 workers
    python examples/python/sweep_dask.py --n 2000 --workers 1
    python examples/python/sweep_dask.py tcp://head:8786  # an existing cluster

Prints runs/s of the sweep, of ``simulate_batch`` in this process (``--compare``),
the overhead per task, and the spread of the step-response figures.
"""

import argparse
import time

import numpy as np

import hydrocyl

#: Relative half-widths of the uniform tolerance ranges, by the word that
#: names the parameter in its path (found with ``rig.parameters()``).
TOLERANCES = {"bulk_modulus": 0.20, "mass": 0.10, "underlap": 0.30}

#: The command: 0 until STEP_AT [s], then STEP_TO (normalised spool demand);
#: the response is sampled every DT [s] up to T_END [s].
STEP_AT, STEP_TO, T_END, DT = 0.01, 0.5, 0.15, 2.5e-4


def find_path(rig, word):
    """The one parameter path whose last segment starts with ``word``."""
    hits = [p for p in rig.parameters() if p.rsplit(".", 1)[-1].startswith(word)]
    if len(hits) != 1:
        raise ValueError(f"{word}: expected one parameter path, found {hits}")
    return hits[0]


def step_command():
    """Output times [s] and the valve command on them."""
    t = np.arange(0.0, T_END + DT / 2, DT)
    return t, np.where(t < STEP_AT, 0.0, STEP_TO)


def sample_parameters(rig, n, seed):
    """``{path: (n,) values}``: uniform within each tolerance of the rig's value."""
    rng = np.random.default_rng(seed)
    params = {}
    for word, tol in TOLERANCES.items():
        path = find_path(rig, word)
        nominal = rig.get(path)
        params[path] = nominal * (1.0 + tol * rng.uniform(-1.0, 1.0, n))
    return params


def step_figures(batch):
    """Per-run figures of the velocity step response (arrays of length N):
    final velocity [m/s], 10-90 % rise time [s], overshoot [-], lowest
    chamber pressure [Pa gauge]."""
    t, v = batch.time, batch["velocity"]
    after = t >= STEP_AT
    v_end = v[:, -1]
    rel = v[:, after] / v_end[:, None]
    t_after = t[after]
    t10 = t_after[np.argmax(rel >= 0.1, axis=1)]
    t90 = t_after[np.argmax(rel >= 0.9, axis=1)]
    p_min = np.minimum(batch["p1"].min(axis=1), batch["p2"].min(axis=1))
    return {
        "v_final": v_end,
        "rise_time": t90 - t10,
        "overshoot": rel.max(axis=1) - 1.0,
        "p_min": p_min,
    }


def run_chunk(rig, params, threads=1):
    """One Dask task: ``simulate_batch`` on a chunk of parameter sets; the
    figures and the seconds spent computing them."""
    start = time.perf_counter()
    t, u = step_command()
    batch = hydrocyl.simulate_batch(
        rig, t, u, params, channels=["velocity", "p1", "p2"], threads=threads
    )
    return step_figures(batch), time.perf_counter() - start


def chunks(params, size):
    """The parameter sets cut into consecutive chunks of ``size``."""
    n = len(next(iter(params.values())))
    return [{k: v[i : i + size] for k, v in params.items()} for i in range(0, n, size)]


def sweep(client, rig, params, chunk_size, threads=1):
    """The figures of every parameter set, computed on the cluster in chunks;
    also the task count and the seconds spent inside the tasks."""
    rig_f = client.scatter(rig, broadcast=True)
    futures = [client.submit(run_chunk, rig_f, c, threads, pure=False) for c in chunks(params, chunk_size)]
    results = client.gather(futures)
    figures = {k: np.concatenate([r[0][k] for r in results]) for k in results[0][0]}
    return figures, len(results), sum(r[1] for r in results)


def sweep_local(rig, params, threads=None):
    """The same figures from one ``simulate_batch`` in this process."""
    t, u = step_command()
    return step_figures(
        hydrocyl.simulate_batch(rig, t, u, params, channels=["velocity", "p1", "p2"], threads=threads)
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scheduler", nargs="?", help="address of a Dask scheduler (default: start a LocalCluster)")
    ap.add_argument("--n", type=int, default=10_000, help="number of runs (default 10000)")
    ap.add_argument("--chunk", type=int, default=250, help="runs per Dask task (default 250)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    ap.add_argument("--threads", type=int, default=1, help="threads per worker and per task (default 1)")
    ap.add_argument("--seed", type=int, default=2019)
    ap.add_argument("--compare", action="store_true", help="also time simulate_batch in this process and check equality")
    args = ap.parse_args(argv)
    if args.n < 1 or args.chunk < 1 or args.workers < 1 or args.threads < 1:
        ap.error("--n, --chunk, --workers and --threads must be at least 1")

    from dask.distributed import Client, LocalCluster

    rig = hydrocyl.Rig.load("leaney-moog")
    params = sample_parameters(rig, args.n, args.seed)
    cluster = None
    if args.scheduler is None:
        cluster = LocalCluster(
            n_workers=args.workers, threads_per_worker=args.threads, processes=True, dashboard_address=None
        )
    client = Client(args.scheduler or cluster)
    try:
        n_workers = len(client.scheduler_info()["workers"])
        client.run(lambda: __import__("hydrocyl"))  # import once per worker, outside the timing
        start = time.perf_counter()
        figures, tasks, busy = sweep(client, rig, params, args.chunk, args.threads)
        wall = time.perf_counter() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    slots = n_workers * args.threads
    print(f"sweep: {args.n} runs in {tasks} tasks on {n_workers} workers x {args.threads} threads: "
          f"{wall:.2f} s, {args.n / wall:.0f} runs/s")
    print(f"overhead per task: {1e3 * max(wall * slots - busy, 0.0) / tasks:.1f} ms "
          f"(wall x slots - time inside tasks, per task)")
    for k, v in figures.items():
        p5, p50, p95 = np.percentile(v, [5, 50, 95])
        print(f"  {k:10s} 5% {p5:.4g}  50% {p50:.4g}  95% {p95:.4g}")
    if args.compare:
        start = time.perf_counter()
        local = sweep_local(rig, params)
        wall = time.perf_counter() - start
        same = all(np.array_equal(local[k], figures[k]) for k in figures)
        print(f"simulate_batch in one process: {args.n / wall:.0f} runs/s; equal to the sweep: {same}")
        if not same:
            raise SystemExit("the cluster's figures differ from the single-process ones")
    return figures


if __name__ == "__main__":
    main()
