"""Add one more packing of the 33 mm unrelieved pairs (band, coarse r 0.16 mm, coarse r 0.3 mm) to the recorded
reports, pair windows and contact census, keeping every recorded row (session 42).

Until session 41 the reports and CSVs under ``shell_held`` were rewritten from all their run folders at once
(``deckgen.families report``, ``compare.py --pair-windows``, ``--contacts``). Run folders do not outlive a machine, so
a packing run later is added to what is recorded instead: its runs are reported on their own and combined with the
recorded report (``families.combine_tables``), and their windows and census rows are appended to the CSVs as text. A
run whose case is in a report or CSV already stops the script, and every table is built and checked before the
first file is written (a run that fails to parse, census or report leaves the recorded files as they were).

A packing that is not one of the family's (``cases/linear_ccs``: 12345, 202, 303) has no family case for its runs to
be variants of. Its two family rows (S 100 mm at p 1.9 and 7.6 mm) are taken from packing 303's rows of
``cases/linear_ccs/index.csv`` with the seed and name changed and no case file (``file`` empty). So that those factors
are the run's, each run's resolved case (spec.json) must be packing 303's diagnostic case of the same name tail
(``docs/families_runs/linear_fn_vs_p/lin_red_s100_p{1p9,7p6}_k303<tail>.yaml``) but for its name, packing seed and
per-atom dump interval (:data:`FREE_FIELDS`).
These rows are not in the family's index, so ``python -m deckgen.families combine --index`` refuses such a report;
combine it without ``--index``.

    python docs/families_runs/shell_held/add_packing.py --seed 404 /work/runs42/lin_red_s100_p{1p9,7p6}_k404_unrel{,_band,_s016}

Each argument is a folder ``X`` with ``X/run`` (the rendered run) and ``X/parsed`` (``deckgen parse``).
"""
from __future__ import annotations

import argparse
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
#: packing 303's diagnostic cases, the template each added run must equal but for its name and seed
TEMPLATE_CASES = ROOT / "docs" / "families_runs" / "linear_fn_vs_p"


def _compare():
    from deckgen.scriptload import load_script

    return load_script(HERE / "compare.py", "shell_held_compare")


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


#: the fields a run may change from its template case: the name, the packing and how often the grains are dumped (dumps
#: do not change a run: session 42's lin_red_s100_p1p9_k303_unrel_dumps gave the case-window F_n 110.915 N of
#: lin_red_s100_p1p9_k303_unrel; the contact census then has more frames)
FREE_FIELDS = ("name", "packing.seed", "outputs.dump_every")


def check_template(case: dict, seed: int, where: Path) -> str:
    """The name tail of a run of packing ``seed`` whose resolved case (spec.json's ``case``) is packing 303's diagnostic
    case of that tail but for :data:`FREE_FIELDS`; SystemExit naming the run and the fields otherwise."""
    from deckgen.families import _diff_keys
    from deckgen.spec import load_case, resolve_recorded, resolved_dict

    case = resolve_recorded(case)  # a run rendered before a field was added has no key for it: today's default
    name = case.get("name", "")
    tail = _tail(name, seed)
    if tail not in REPORTS:
        raise SystemExit(f"{where}: case tail {tail!r} has no report here (fix: one of {', '.join(REPORTS)})")
    p = name.removeprefix("lin_red_s100_p")[:3]
    template = TEMPLATE_CASES / f"lin_red_s100_p{p}_k{TEMPLATE_SEED}{tail}.yaml"
    ref = resolved_dict(load_case(template))
    diff = [k for k in _diff_keys(case, ref) if k not in FREE_FIELDS]
    if diff:
        raise SystemExit(f"{where}: differs from {template} in {', '.join(diff)}, not only in {', '.join(FREE_FIELDS)} "
                         "(fix: add runs of packing 303's diagnostic cases with another seed only)")
    if case["packing"]["seed"] != seed:
        raise SystemExit(f"{where}: packing.seed {case['packing']['seed']}, not {seed} (fix: --seed "
                         f"{case['packing']['seed']}, or pass the runs of packing {seed})")
    return tail


def _check_new(csv: Path, cases: set[str], column: str = "case") -> pd.DataFrame:
    if not csv.is_file():
        raise SystemExit(f"{csv}: missing (fix: run from a checkout that holds the recorded reports)")
    old = pd.read_csv(csv)
    clash = sorted(set(old[column]) & cases)
    if clash:
        raise SystemExit(f"{csv}: already holds {', '.join(clash)} (fix: these runs were added before; nothing written)")
    return old


def _appended_text(csv: Path, new: pd.DataFrame) -> str:
    """``csv``'s text with ``new``'s rows added (the recorded rows stay byte for byte); same columns, new cases only."""
    old = _check_new(csv, set(new["case"]))
    if list(old.columns) != list(new.columns):
        raise SystemExit(f"{csv}: columns {list(old.columns)} but the new rows have {list(new.columns)} (fix: the CSV "
                         "was written by another version of compare.py; rewrite it from its runs)")
    text = csv.read_text()
    return text + ("" if text.endswith("\n") else "\n") + new.to_csv(index=False, header=False, float_format="%.6g")


def main(argv: list[str] | None = None, reports: dict[str, Path] | None = None, pair_windows: Path | None = None,
         contacts: Path | None = None) -> int:
    """``reports``, ``pair_windows``, ``contacts``: other targets than the recorded ones (tests)."""
    from deckgen.families import combine_tables, family_table, report_table

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed", type=int, required=True, help="the packing seed of the runs")
    p.add_argument("runs", nargs="+", type=Path, help="folders X with X/run and X/parsed")
    args = p.parse_args(argv)
    cmp = _compare()
    reports = reports or REPORTS
    pair_windows = pair_windows or cmp.PAIR_WINDOWS_CSV
    contacts = contacts or cmp.CONTACTS_CSV
    if len(set(d.resolve() for d in args.runs)) != len(args.runs):
        raise SystemExit("a run folder is passed twice (fix: each run once)")
    by_report: dict[str, list[Path]] = {}
    names: dict[Path, str] = {}
    for d in args.runs:
        spec_path, summary = d / "run" / "spec.json", d / "parsed" / "summary.json"
        if not (spec_path.is_file() and summary.is_file()):
            raise SystemExit(f"{d}: needs run/spec.json and parsed/summary.json (fix: deckgen render CASE --out {d}/run, "
                             f"deckgen run {d}/run, deckgen parse {d}/run --out {d}/parsed)")
        case = json.loads(spec_path.read_text())["case"]
        names[d] = json.loads(summary.read_text())["case"]
        if names[d] != case["name"]:
            raise SystemExit(f"{summary}: case {names[d]!r} but {spec_path} is {case['name']!r} (fix: parse the run again)")
        by_report.setdefault(check_template(case, args.seed, spec_path), []).append(d)
    # build and check everything, then write
    writes: dict[Path, tuple[str, int]] = {}  # file -> (its new text, rows added)
    idx = packing_index(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        idx_path = Path(tmp) / "index.csv"
        idx.to_csv(idx_path, index=False)
        tables = {}
        for tail, dirs in by_report.items():
            recorded = reports[tail] / "family_table.csv"
            old = _check_new(recorded, {names[d] for d in dirs}, "variant_case")
            try:
                new = family_table(idx_path, [d / "parsed" for d in dirs], variants=True)
            except ValueError as exc:
                raise SystemExit(f"{reports[tail]}: {exc}") from None
            # columns deckgen's family table gained after the report was written (session 49: the indentation
            # break-off), empty for these runs: left out, so the recorded rows stay byte for byte
            extra = [c for c in new.columns if c not in old.columns]
            if extra and new[extra].isna().all().all():
                new = new.drop(columns=extra)
            clash = sorted(set(old["case"]) & set(new["case"]))
            if clash:  # combine_tables would keep the new row of a family case in both
                raise SystemExit(f"{recorded}: holds a run of the family cases {', '.join(clash)} already (fix: one run "
                                 "per family case and report)")
            new_csv = Path(tmp) / f"new{tail}.csv"
            new.to_csv(new_csv, index=False)
            tables[tail] = (combine_tables([recorded, new_csv]), len(old), len(new))
        windows = cmp.window_table([d / "parsed" for d in args.runs])
        if len(windows):
            writes[pair_windows] = (_appended_text(pair_windows, windows), len(windows))
        census_dirs = [d for tail, dirs in by_report.items() if tail in CENSUS_TAILS for d in dirs]
        if census_dirs:
            census = cmp.contact_table(census_dirs)
            writes[contacts] = (_appended_text(contacts, census), len(census))
        # the reports go through report_table (plots, trends) into a scratch folder first, then replace the recorded files
        staged = {}
        for tail, (table, n_old, n_new) in tables.items():
            out = Path(tmp) / f"report{tail}"
            report_table("linear_ccs", table, out)
            staged[tail] = out
        for tail, out in staged.items():
            for f in sorted(out.rglob("*")):
                if f.is_file():
                    dest = reports[tail] / f.relative_to(out)
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    dest.write_bytes(f.read_bytes())
            table, n_old, n_new = tables[tail]
            print(f"{reports[tail]}: {n_old} recorded + {n_new} new runs")
    for csv, (text, rows) in writes.items():
        csv.write_text(text)
        print(f"{csv}: +{rows} rows")
    return 0


if __name__ == "__main__":
    sys.exit(main())
