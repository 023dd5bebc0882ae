"""Loop level 3 of the bench torus in one process, steady state: igl.loop (3 runs) and
subd with int64 and int32 faces (9 runs each), medians and the ratios to igl.

    python crates/python/bench/steady_state.py [--grid 224]

The table's workers (loop_bench.py) time each tool in a fresh process, whose first runs pay
for fresh pages; this times the same calls once the process holds its memory.
"""

import argparse
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from loop_bench import LEVELS, torus  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--grid", type=int, default=224, help="torus grid: 2 grid^2 triangles")
    args = parser.parse_args()
    import igl
    import subd

    v, f = torus(args.grid)
    v, f = np.ascontiguousarray(v, np.float64), np.ascontiguousarray(f, np.int64)

    def run_subd(dtype):
        mesh = subd.Mesh(v, f, accept_inconsistent_orientation=True)
        out = subd.refine(mesh, "loop", levels=LEVELS, index_dtype=dtype)
        return np.asarray(out.vertices, np.float64), np.asarray(out.faces)

    medians = {}
    for name, run, repeats in [("igl", lambda: igl.loop(v, f, LEVELS), 3),
                               ("subd int64", lambda: run_subd(np.int64), 9),
                               ("subd int32", lambda: run_subd(np.int32), 9)]:
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            out = run()
            times.append(time.perf_counter() - start)
            out = None  # noqa: F841  (freed before the next run)
        medians[name] = statistics.median(times)
        print(f"{name}: median {medians[name]:.4f} s, runs {[round(t, 3) for t in times]}")
    for name in ("subd int64", "subd int32"):
        print(f"{name}: {medians['igl'] / medians[name]:.1f}x igl.loop")


if __name__ == "__main__":
    main()
