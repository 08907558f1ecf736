"""The atlas on a Dask cluster: wall time of the same grid with a LocalCluster of 1 and of
2 worker processes (one thread each, a task's batch on one thread), and run here without
a client (all cores), measured in one run; the three results are checked equal.

    target/python/bin/python pendulum-py/bench/atlas_dask.py [--points-per-side 8] [--chunk 16]

The grid: the README's 20-link chain (L = 1 m, λ = 5.6237e-4 N·m·s per link), ω over
0.5–5 √(g/L) and R over 0.005–0.05 m, sudden start, 600 s each: the atlas of
docs/atlas.md, smaller. The clusters are started before the clock runs.
"""

import argparse
import time

import numpy as np
from distributed import Client, LocalCluster

import pendulum


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--points-per-side", type=int, default=8)
    parser.add_argument("--chunk", type=int, default=16)
    args = parser.parse_args()
    side = args.points_per_side
    chain = pendulum.Chain([0.05] * 20, [0.05] * 20, damping=5.6237e-4)
    grid = dict(omega=np.linspace(0.5, 5.0, side), scaled=True, radius=np.linspace(0.005, 0.05, side), duration=600.0)
    results = {}
    for workers in [1, 2]:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                client.wait_for_workers(workers)
                start = time.perf_counter()
                atlas = pendulum.atlas(chain, client=client, chunk=args.chunk, **grid)
                results[f"{workers} worker{'s' if workers > 1 else ''}"] = (time.perf_counter() - start, atlas)
    start = time.perf_counter()
    atlas = pendulum.atlas(chain, **grid)
    results["no client (all cores)"] = (time.perf_counter() - start, atlas)
    reference = results["1 worker"][1]
    for name, (seconds, atlas) in results.items():
        assert atlas.points == reference.points, f"{name}: not the same atlas"
        print(f"{name:>22}: {seconds:6.2f} s for {side * side} points ({args.chunk} per task)")
    one, two = results["1 worker"][0], results["2 workers"][0]
    print(f"2 workers / 1 worker: {one / two:.2f}× faster; nodes {np.unique(reference.nodes).tolist()}")


if __name__ == "__main__":
    main()
