#!/usr/bin/env python3
"""Simulates a push of the project's notched block, estimates it with the QS graph and draws
the estimate against the ground truth and the raw camera (matplotlib, written to a PNG).

    python3 examples/python/estimate_push.py [out/estimate_push.png]
"""
import pathlib
import sys

import numpy as np

import pushgraph as pg

ROOT = pathlib.Path(__file__).resolve().parents[2]
out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/estimate_push.png")

block = pg.Shape.load_json(str(ROOT / "data" / "shapes" / "notched_block.json"))
finger = pg.Shape.disk(0.005)
push = pg.simulate(block, finger, push_angle=0.7, offset=0.01, distance=0.06, seed=3)
result = pg.estimate(push, model="qs")  # batch, with every marginal covariance

m = result["metrics"]
print("object position RMS %.2f mm (camera %.2f mm), force RMS %.3f N (sensor %.3f N), %d steps in %.2f s"
      % (1e3 * m["object_position_rms"], 1e3 * m["measured_object_position_rms"], m["force_rms"],
         m["measured_force_rms"], len(result["t"]), result["solver"]["time_s"]))
for w in result["warnings"]:
    print("warning:", w)

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed (Debian: python3-matplotlib): no picture")
    sys.exit(0)

fig, (ax, ax_err) = plt.subplots(1, 2, figsize=(11, 4.5))
rings = [r for p in block.polygons()["polygons"] for r in [p["outer"], *p["holes"]]]
for k in range(0, len(result["t"]), 60):  # the object's outline and holes at every 60th estimated pose
    x, y, th = result["object_pose"][k]
    c, s = np.cos(th), np.sin(th)
    for ring in rings:
        placed = ring @ np.array([[c, s], [-s, c]]) + (x, y)
        ax.fill(placed[:, 0], placed[:, 1], fc="none", ec="tab:blue", lw=0.8)
truth = push["ground_truth"]["object_pose"]
camera = push["measured"]["object_pose"]
ax.plot(truth["pose"][:, 0], truth["pose"][:, 1], "k-", lw=1, label="ground truth")
ax.plot(camera["pose"][:, 0], camera["pose"][:, 1], "r.", ms=3, label="camera")
ax.plot(result["object_pose"][:, 0], result["object_pose"][:, 1], "b-", lw=1, label="QS estimate")
ax.plot(result["finger_pose"][:, 0], result["finger_pose"][:, 1], "g-", lw=1, label="finger")
ax.set_aspect("equal")
ax.legend(fontsize=8)
ax.set_title("notched block pushed by a 5 mm finger")
sigma = np.sqrt(result["object_pose_cov"][:, 0, 0] + result["object_pose_cov"][:, 1, 1])
gt = np.stack([np.interp(result["t"], truth["t"], truth["pose"][:, i]) for i in range(2)], axis=1)
ax_err.plot(result["t"], 1e3 * np.linalg.norm(result["object_pose"][:, :2] - gt, axis=1), label="|error|")
ax_err.plot(result["t"], 1e3 * sigma, "--", label="1-sigma (marginal covariance)")
ax_err.set_xlabel("t (s)")
ax_err.set_ylabel("object position (mm)")
ax_err.legend(fontsize=8)
out.parent.mkdir(parents=True, exist_ok=True)
fig.tight_layout()
fig.savefig(out, dpi=110)
print("wrote", out)
