#!/usr/bin/env python3
"""Speed of the Python bindings against the C++ loop (bench_python_peer, Google Benchmark):

- a vectorized exact signed-distance query over 1e6 points of the notched block (uniform in its
  bounds widened by 1 cm, the peer's distribution), best of 5, as a ratio to the C++ loop;
- the overhead of one call with a single point (its time minus one point's share of the above);
- a vectorized query with every output (closest point, normal, feature) for comparison.

    PYTHONPATH=build/python python3 bench/python/bench_python.py build-bench/bench/python/bench_python_peer
"""
import json
import pathlib
import subprocess
import sys
import time

import numpy as np

import pushgraph as pg

ROOT = pathlib.Path(__file__).resolve().parents[2]
shape = pg.Shape.load_json(str(ROOT / "data" / "shapes" / "notched_block.json"))
lo, hi = shape.bounds
points = np.random.default_rng(1).uniform(lo - 0.01, hi + 0.01, (1_000_000, 2))


def best(f, repeat=5):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


vectorized = best(lambda: shape.signed_distance(points))
full = best(lambda: shape.query(points), repeat=3)
one = points[:1]
calls = 20000
start = time.perf_counter()
for _ in range(calls):
    shape.signed_distance(one)
single = (time.perf_counter() - start) / calls
print("vectorized signed_distance, 1e6 points: %.1f ms (%.1f ns/point)" % (1e3 * vectorized, vectorized * 1e3))
print("vectorized query (all outputs), 1e6 points: %.1f ms (%.1f ns/point)" % (1e3 * full, full * 1e3))
print("one call with one point: %.2f us (overhead %.2f us beyond the point's own %.0f ns)"
      % (1e6 * single, 1e6 * (single - vectorized / 1e6), vectorized * 1e3))
if len(sys.argv) > 1:
    out = subprocess.run([sys.argv[1], "--benchmark_format=json"], check=True, capture_output=True, text=True).stdout
    cpp = json.loads(out)["benchmarks"][0]
    cpp_s = cpp["real_time"] / 1e3 if cpp["time_unit"] == "ms" else cpp["real_time"]
    print("C++ loop (bench_python_peer), 1e6 points: %.1f ms; Python vectorized / C++ = %.3f" % (1e3 * cpp_s, vectorized / cpp_s))
