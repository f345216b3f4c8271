"""Whole-cycle mean force of long (44 mm) ODC cuts over every window of 1/90 s inside the steady window.

1/90 s is one cycle at 90 Hz and two or three at 180 and 270 Hz (the x4 frequencies of the long cuts), so every
window holds whole cycles of each run; for the straight cut it is the same 22.2 mm of travel. The spread of the
means over the window's start shows how much of a difference between two runs is the phase of chipping rather
than the kinematics. Usage: python cycle_spread.py <run dir with parsed/>...  (prints one line per run)
"""
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

PERIOD_S = 1.0 / 90.0


def spread(run: Path, period_s: float = PERIOD_S) -> dict:
    s = json.loads((run / "parsed" / "summary.json").read_text())
    ts = pd.read_parquet(run / "parsed" / "timeseries.parquet", columns=["time_s", "force_magnitude_N"])
    t, f = ts["time_s"].to_numpy(), ts["force_magnitude_N"].to_numpy()
    t0, t1 = s["steady_start_s"], s["steady_end_s"]
    starts = t[(t >= t0) & (t + period_s <= t1 + 1e-12)]
    means = np.array([f[(t >= a) & (t < a + period_s)].mean() for a in starts])
    return {"run": run.name, "windows": len(means), "min": means.min(), "median": float(np.median(means)),
            "max": means.max(), "first": means[0]}


if __name__ == "__main__":
    for d in sys.argv[1:]:
        r = spread(Path(d))
        print(f"{r['run']}: {r['windows']} windows of 1/90 s, mean |F| min {r['min']:.1f} median {r['median']:.1f} "
              f"max {r['max']:.1f} N (window at the steady start {r['first']:.1f} N)")
