"""Cross-engine check: the same unbonded bed cut by the same disc and motion on LAMMPS and LIGGGHTS.

    PYTHONPATH=src .venv/bin/python bench/cross_engine.py [bench/cross_cut.yaml] [--seeds 12345 2 3]
        [--rolling 0.0] [--out /tmp/cross] [--cache DIR]

For each packing seed, :func:`deckgen.liggghts.cross_engine_cut` renders, runs (1 MPI rank each,
one engine at a time) and parses both engines; prints the steady-window means F_n, F_r, F_s of
both and their ratio LIGGGHTS / LAMMPS, then the means over the seeds and the ratio of the means,
and writes ``cross_engine.json`` in ``--out``. About 40 s per seed on an idle 2-core machine
(packing ~10 s, each cut ~15 s). Tolerance and numbers: docs/liggghts.md.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from deckgen.liggghts import CROSS_QUANTITIES, cross_engine_cut
from deckgen.spec import load_case

HERE = Path(__file__).resolve().parent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", nargs="?", default=str(HERE / "cross_cut.yaml"))
    ap.add_argument("--seeds", type=int, nargs="+", default=[12345, 2, 3])
    ap.add_argument("--rolling", type=float, default=None, help="override contact.rolling_friction")
    ap.add_argument("--out", default="/tmp/deckgen-cross")
    ap.add_argument("--cache", default=None)
    args = ap.parse_args()
    out = Path(args.out)
    rows = []
    for seed in args.seeds:
        over = {"packing": {"seed": seed}}
        if args.rolling is not None:
            over["contact"] = {"rolling_friction": args.rolling}
        case = load_case(args.case, overrides=over)
        r = cross_engine_cut(case, out / f"seed{seed}", cache=Path(args.cache) if args.cache else None)
        rows.append({"seed": seed, **r})
        print(f"seed {seed}: {r['lammps']['n_grains']} grains")
        for q in CROSS_QUANTITIES:
            print(f"  {q:30s} lammps {r['lammps'][q]:10.4g}  liggghts {r['liggghts'][q]:10.4g}  ratio {r['ratio'][q]:7.3f}")
    means = {eng: {q: statistics.fmean(r[eng][q] for r in rows) for q in CROSS_QUANTITIES} for eng in ("lammps", "liggghts")}
    print(f"mean over {len(rows)} beds:")
    for q in CROSS_QUANTITIES:
        a, b = means["lammps"][q], means["liggghts"][q]
        print(f"  {q:30s} lammps {a:10.4g}  liggghts {b:10.4g}  ratio {b / a if a else float('nan'):7.3f}")
    out.mkdir(parents=True, exist_ok=True)
    (out / "cross_engine.json").write_text(json.dumps({"case": args.case, "runs": rows, "means": means}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
