"""Add one more packing of the 33 mm unrelieved pairs (band, coarse r 0.16 mm, coarse r 0.3 mm) to the recorded
reports, pair windows and contact census, keeping every recorded row (session 42).

Until session 41 the reports and CSVs under ``shell_held`` were rewritten from all their run folders at once
(``deckgen.families report``, ``compare.py --pair-windows``, ``--contacts``). Run folders do not outlive a machine, so
a packing run later is added to what is recorded instead: its runs are reported on their own and combined with the
recorded report (``families.combine_tables``: a case keeps its recorded row), and their windows and census rows are
appended to the CSVs. A case already in a CSV stops the script (no silent overwrite).

A packing that is not one of the family's (``cases/linear_ccs``: 12345, 202, 303) has no family case for its runs to
be variants of. Its two family rows (S 100 mm at p 1.9 and 7.6 mm) are taken from packing 303's rows of
``cases/linear_ccs/index.csv`` with the seed and name changed and no case file (``file`` empty): the factors are the
family case's, the packing seed the run's own (checked against each run's spec.json).

    python docs/families_runs/shell_held/add_packing.py --seed 404 /work/runs42/lin_red_s100_p{1p9,7p6}_k404_unrel{,_band,_s016}

Each argument is a folder ``X`` with ``X/run`` (the rendered run) and ``X/parsed`` (``deckgen parse``).
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import tempfile
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
INDEX = ROOT / "cases" / "linear_ccs" / "index.csv"
#: report folder per case-name tail after ``lin_red_s100_p{1p9,7p6}_k<seed>``
REPORTS = {"_unrel_band": HERE / "linear_unrel_band", "_unrel_s016": HERE / "linear_unrel_s016",
           "_unrel": HERE / "linear_unrel"}
#: the runs of these tails go into the contact census (the r 0.3 mm pairs were never in it)
CENSUS_TAILS = ("_unrel_band", "_unrel_s016")
TEMPLATE_SEED = 303


def _compare():
    spec = importlib.util.spec_from_file_location("shell_held_compare", HERE / "compare.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def packing_index(seed: int) -> pd.DataFrame:
    """cases/linear_ccs/index.csv with two rows added: lin_red_s100_p{1p9,7p6}_k<seed>, packing 303's rows with the seed
    and the name changed and no case file."""
    idx = pd.read_csv(INDEX, keep_default_na=False)
    names = [f"lin_red_s100_p{p}_k{seed}" for p in ("1p9", "7p6")]
    if set(names) & set(idx["case"]):
        return idx  # a family packing: its cases are in the index already
    rows = idx[idx["case"].isin([f"lin_red_s100_p{p}_k{TEMPLATE_SEED}" for p in ("1p9", "7p6")])].copy()
    if len(rows) != 2:
        raise SystemExit(f"{INDEX}: no rows for packing {TEMPLATE_SEED} at S 100 mm (fix: python -m deckgen.families write)")
    rows["case"] = rows["case"].str.replace(f"_k{TEMPLATE_SEED}", f"_k{seed}", regex=False)
    rows["file"] = ""
    rows["packing_seed"] = seed
    return pd.concat([idx, rows], ignore_index=True)


def _tail(case: str, seed: int) -> str:
    for p in ("1p9", "7p6"):
        head = f"lin_red_s100_p{p}_k{seed}"
        if case.startswith(head):
            return case[len(head):]
    raise SystemExit(f"{case}: not a run of packing {seed} (fix: cases named lin_red_s100_p{{1p9,7p6}}_k{seed}<tail>)")


def _append(csv: Path, new: pd.DataFrame) -> None:
    """Append ``new``'s rows to ``csv`` as text (the recorded rows stay byte for byte), same columns, new cases only."""
    old = pd.read_csv(csv)
    if list(old.columns) != list(new.columns):
        raise SystemExit(f"{csv}: columns {list(old.columns)} but the new rows have {list(new.columns)}")
    clash = sorted(set(old["case"]) & set(new["case"]))
    if clash:
        raise SystemExit(f"{csv}: already holds {', '.join(clash)} (fix: these runs were added before)")
    text = csv.read_text()
    csv.write_text(text + ("" if text.endswith("\n") else "\n")
                   + new.to_csv(index=False, header=False, float_format="%.6g"))


def main(argv: list[str] | None = None) -> int:
    from deckgen.families import combine_tables, family_table, report_table

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed", type=int, required=True, help="the packing seed of the runs")
    p.add_argument("runs", nargs="+", type=Path, help="folders X with X/run and X/parsed")
    args = p.parse_args(argv)
    by_report: dict[str, list[Path]] = {}
    for d in args.runs:
        spec_path, summary = d / "run" / "spec.json", d / "parsed" / "summary.json"
        if not (spec_path.is_file() and summary.is_file()):
            raise SystemExit(f"{d}: needs run/spec.json and parsed/summary.json (fix: deckgen render/run/parse into it)")
        case = json.loads(spec_path.read_text())["case"]
        if case["packing"]["seed"] != args.seed:
            raise SystemExit(f"{spec_path}: packing.seed {case['packing']['seed']}, not {args.seed}")
        tail = _tail(case["name"], args.seed)
        if tail not in REPORTS:
            raise SystemExit(f"{d}: case tail {tail!r} has no report here (fix: one of {', '.join(REPORTS)})")
        by_report.setdefault(tail, []).append(d)
    cmp = _compare()
    names = {d: json.loads((d / "parsed" / "summary.json").read_text())["case"] for d in args.runs}
    # every clash is found before anything is written
    for tail, dirs in by_report.items():
        recorded = REPORTS[tail] / "family_table.csv"
        clash = sorted(set(pd.read_csv(recorded)["variant_case"]) & {names[d] for d in dirs})
        if clash:
            raise SystemExit(f"{recorded}: already holds {', '.join(clash)} (fix: these runs were added before)")
    census_dirs = [d for tail, dirs in by_report.items() if tail in CENSUS_TAILS for d in dirs]
    for csv, dirs in ((cmp.PAIR_WINDOWS_CSV, args.runs), (cmp.CONTACTS_CSV, census_dirs)):
        clash = sorted(set(pd.read_csv(csv)["case"]) & {names[d] for d in dirs})
        if clash:
            raise SystemExit(f"{csv}: already holds {', '.join(clash)} (fix: these runs were added before)")
    idx = packing_index(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        idx_path = Path(tmp) / "index.csv"
        idx.to_csv(idx_path, index=False)
        for tail, dirs in by_report.items():
            report = REPORTS[tail]
            new = family_table(idx_path, [d / "parsed" for d in dirs], variants=True)
            new_csv = Path(tmp) / f"new{tail}.csv"
            new.to_csv(new_csv, index=False)
            recorded = report / "family_table.csv"
            n_old = len(pd.read_csv(recorded))
            table = combine_tables([recorded, new_csv])
            if len(table) != n_old + len(new):
                raise SystemExit(f"{recorded}: a new run's family case is in the report already (fix: another seed)")
            report_table("linear_ccs", table, report)
            print(f"{report.relative_to(ROOT)}: {n_old} recorded + {len(new)} new runs")
    windows = cmp.window_table([d / "parsed" for d in args.runs])
    _append(cmp.PAIR_WINDOWS_CSV, windows)
    print(f"{cmp.PAIR_WINDOWS_CSV.relative_to(ROOT)}: +{len(windows)} rows")
    if census_dirs:
        contacts = cmp.contact_table(census_dirs)
        _append(cmp.CONTACTS_CSV, contacts)
        print(f"{cmp.CONTACTS_CSV.relative_to(ROOT)}: +{len(contacts)} rows")
    return 0


if __name__ == "__main__":
    sys.exit(main())
