"""``deckgen`` command line: the per-case path without Snakemake.

    deckgen validate CASE...             check case files, one line per problem
    deckgen schema [--out FILE]          write the JSON schema of case files
    deckgen pack CASE                    make (or reuse) the packing, print its statistics
    deckgen render CASE --out DIR        pack if needed, write the run folder (deck, data, spec.json)
    deckgen run DIR                      run the engine on a rendered folder
    deckgen parse DIR --out DIR          force/damage tables and summary of one run
    deckgen aggregate DIR... --out DIR   one tidy table per kind across runs
    deckgen plot DIR --out DIR           PNG plots of one parsed run
    deckgen stl CASE --out FILE          the case's cutter as a binary STL
    deckgen gap --measured CSV --base CASE --out DIR [--backend fast|dem]
                                         discrepancy loop: name the missing effect (docs/discrepancy.md)

User mistakes end in one line ``deckgen: error: ...`` and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

from deckgen import __version__


def _cache(args: argparse.Namespace) -> Path | None:
    return Path(args.cache) if getattr(args, "cache", None) else None


def _command(args: argparse.Namespace) -> list[str] | None:
    from deckgen.runner import engine_command

    if getattr(args, "engine_cmd", None):
        return shlex.split(args.engine_cmd)
    if getattr(args, "ranks", None):
        return engine_command(args.ranks)
    return None


def cmd_validate(args: argparse.Namespace) -> int:
    from deckgen.spec import SpecError, load_case

    bad = 0
    for path in args.cases:
        try:
            case = load_case(path)
        except SpecError as exc:
            print(str(exc), file=sys.stderr)
            bad += 1
            continue
        print(f"{path}: ok ({case.test}, engine {case.engine}, name {case.name})")
    return 2 if bad else 0


def cmd_schema(args: argparse.Namespace) -> int:
    from deckgen.spec import schema_text

    text = schema_text()
    if args.out:
        Path(args.out).write_text(text)
        print(f"wrote {args.out}")
    else:
        sys.stdout.write(text)
    return 0


def cmd_pack(args: argparse.Namespace) -> int:
    from deckgen.packing import ensure_packing, load_packing
    from deckgen.spec import load_case

    case = load_case(args.case)
    folder = ensure_packing(case, _cache(args), progress=not args.no_progress, command=_command(args))
    _, info = load_packing(folder)
    if args.info:
        Path(args.info).parent.mkdir(parents=True, exist_ok=True)
        Path(args.info).write_text(json.dumps(info, indent=2, sort_keys=True) + "\n")
    s = info["stats"]
    print(f"{args.case}: packing {info['key']} in {folder}: {s['n_grains']} grains, solid fraction "
          f"{s['solid_fraction']:.4f}, mean coordination {s['coordination_mean']:.2f} "
          f"({s['coordination_mean_no_rattlers']:.2f} without {100 * s['rattler_fraction']:.1f} % rattlers), "
          f"mean overlap {100 * s['overlap_mean_rel']:.2f} %")
    return 0


def cmd_render(args: argparse.Namespace) -> int:
    from deckgen.deck import render_case
    from deckgen.spec import SpecError, load_case

    case = load_case(args.case)
    if args.engine and args.engine != case.engine:
        from pydantic import ValidationError

        try:  # validated again: some fields are engine-specific (e.g. packing.fine_zone is LAMMPS only)
            case = type(case).model_validate({**case.model_dump(mode="json"), "engine": args.engine})
        except ValidationError as exc:
            print(f"{args.case}: --engine {args.engine}: {exc.errors()[0]['msg']}", file=sys.stderr)
            return 2
    if case.engine == "liggghts":
        from deckgen import liggghts as lg

        try:
            spec = lg.render_liggghts(case, Path(args.out), bed=args.bed, cache=_cache(args), command=_command(args))
        except SpecError as exc:
            raise SpecError(f"{args.case}: {exc}") from None
        d = spec["derived"]
        what = (f"{d['n_grains']} grains" if not d.get("n_grains_is_estimate") and d.get("n_grains")
                else "grains inserted by LIGGGHTS")
        print(f"{args.case}: rendered {args.out}/{lg.DECK} for LIGGGHTS: {what}, dt {d['dt_s']:.3g} s, "
              f"about {d['expected_steps_total']} steps")
        return 0
    spec = render_case(case, Path(args.out), cache=_cache(args), progress=not args.no_progress, command=_command(args))
    d = spec["derived"]
    print(f"{args.case}: rendered {args.out}/in.deck: {d['n_grains']} grains, {d['n_bonds']} bonds in "
          f"{d['n_bond_types']} types, dt {d['dt_s']:.3g} s, about {d['expected_steps']} steps")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from deckgen.runner import run_deck

    run_dir = Path(args.dir)
    spec_file = run_dir / "spec.json"
    expected, engine = None, "lammps"
    if spec_file.is_file():
        spec = json.loads(spec_file.read_text())
        expected, engine = spec["derived"].get("expected_steps"), spec.get("engine", "lammps")
    if engine == "liggghts":
        from deckgen.liggghts import run_liggghts

        res = run_liggghts(run_dir, ranks=args.ranks, command=shlex.split(args.engine_cmd) if args.engine_cmd else None,
                           progress=not args.no_progress)
    else:
            res = run_deck(run_dir, args.deck, expected_steps=expected, command=_command(args),
                       progress=not args.no_progress, label=run_dir.name)
    pss = f"{res.particle_steps_per_s:.3g}" if res.particle_steps_per_s else "n/a"
    print(f"{run_dir}: {res.steps} steps, {res.atoms} atoms, {res.wall_s:.1f} s wall, {pss} particle-steps/s")
    return 0


def cmd_parse(args: argparse.Namespace) -> int:
    from deckgen.results import parse_run

    summary = parse_run(Path(args.dir), Path(args.out), steady_window=args.steady_window,
                        breakoff_min_grains=args.breakoff_min_grains)
    keys = [k for k in ("peak_stress_Pa", "youngs_modulus_Pa", "force_normal_N_mean_steady", "force_normal_N_peak",
                        "bonds_broken") if k in summary]
    print(f"{args.dir}: " + ", ".join(f"{k} {summary[k]:.4g}" for k in keys))
    return 0


def cmd_contacts(args: argparse.Namespace) -> int:
    from deckgen.contacts import census_of_parsed

    t = census_of_parsed(Path(args.dir), Path(args.parsed))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    t.to_csv(out, index=False)
    touch = t[t["force_z_hertz_N"] > 0]
    share = touch["detached_share_z_1"].mean() if len(touch) else float("nan")
    print(f"{args.dir}: {len(t)} dumped steps, {len(touch)} with contact; chips and debris carry {share:.3g} of the "
          f"rebuilt normal load on average (wrote {out})")
    return 0


def cmd_aggregate(args: argparse.Namespace) -> int:
    from deckgen.results import aggregate

    paths = aggregate([Path(d) for d in args.dirs], Path(args.out))
    print(f"wrote {len(paths)} tables to {args.out}")
    return 0


def cmd_plot(args: argparse.Namespace) -> int:
    from deckgen.plots import plot_run

    files = plot_run(Path(args.dir), Path(args.out))
    print(f"wrote {len(files)} plots to {args.out}")
    return 0


def cmd_stl(args: argparse.Namespace) -> int:
    from deckgen.deck import cutter_params
    from deckgen.geometry import build_cutter, cutter_summary, write_stl
    from deckgen.spec import MM, SpecError, load_case

    case = load_case(args.case)
    kind, params = cutter_params(case)
    try:
        mesh = build_cutter(kind, params, offset=args.offset_mm * MM)
    except ValueError as exc:
        raise SpecError(f"{args.case}: cutter: {exc}") from None
    write_stl(mesh, args.out)
    s = cutter_summary(mesh)
    print(f"wrote {args.out}: {kind}, diameter {s['diameter_m'] / MM:.3f} mm, width {s['width_m'] / MM:.3f} mm, "
          f"{s['n_triangles']} triangles, watertight {s['watertight']}")
    return 0


def cmd_gap(args: argparse.Namespace) -> int:
    from deckgen.gap import gap
    from deckgen.spec import SpecError

    cands = [c.strip() for c in args.candidates.split(",") if c.strip()] if args.candidates else None
    if args.noise_cv is not None and not (0 < args.noise_cv < 1):
        raise SpecError(f"--noise-cv {args.noise_cv:g}: must lie in (0, 1) (fix: e.g. 0.05 for 5 % scatter)")
    seeds = None
    if args.packing_seeds:
        try:
            seeds = [int(v) for v in args.packing_seeds.split(",") if v.strip()]
        except ValueError:
            raise SpecError(f"--packing-seeds {args.packing_seeds!r}: not a list of integers (fix: e.g. 12345,202,303)") from None
    rep = gap(args.measured, args.base, args.out, backend=args.backend, candidates=cands, noise_cv=args.noise_cv,
              command=_command(args), cache=_cache(args), runs=Path(args.runs) if args.runs else None,
              packing_seeds=seeds, jobs=args.jobs)
    print(f"{args.measured}: {rep['cases']} cases, {rep['rows']} rows, backend {rep['backend']}: "
          f"named effect {rep['named_effect'] or 'none'} ({rep['verdict']})")
    print(f"  {rep['reason']}")
    for r in rep["responses"]:
        b, a = rep["gap_before"][r], rep["gap_after"][r]
        print(f"  {r}: RMSE {b['rmse']:.4g} -> {a['rmse']:.4g} N, MAPE {b['mape']:.3g} -> {a['mape']:.3g} %")
    print(f"wrote {args.out}/report.json, report.md, parity.png, residuals.png")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="deckgen", description="Bonded-particle DEM decks for rock cutting.")
    p.add_argument("--version", action="version", version=f"deckgen {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    def engine_opts(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--engine-cmd", help="engine command line, e.g. 'mpirun -np 2 lmp' (default: the venv's)")
        sp.add_argument("--ranks", type=int, help="MPI ranks for the default engine command")
        sp.add_argument("--cache", help="packing cache folder (default: $DECKGEN_CACHE or .deckgen-cache)")
        sp.add_argument("--no-progress", action="store_true", help="no progress bar")

    s = sub.add_parser("validate", help="check case files")
    s.add_argument("cases", nargs="+")
    s.set_defaults(func=cmd_validate)
    s = sub.add_parser("schema", help="write the case JSON schema")
    s.add_argument("--out")
    s.set_defaults(func=cmd_schema)
    s = sub.add_parser("pack", help="make or reuse the packing of a case")
    s.add_argument("case")
    s.add_argument("--info", help="also write the packing statistics (JSON) here")
    engine_opts(s)
    s.set_defaults(func=cmd_pack)
    s = sub.add_parser("render", help="render a case into a run folder")
    s.add_argument("case")
    s.add_argument("--out", required=True)
    s.add_argument("--engine", choices=["lammps", "liggghts"])
    s.add_argument("--bed", choices=["packing", "settle"], default="packing",
                   help="liggghts cutting: the case's packing (as LAMMPS; default) or a bed LIGGGHTS inserts and settles")
    engine_opts(s)
    s.set_defaults(func=cmd_render)
    s = sub.add_parser("run", help="run the engine in a rendered folder")
    s.add_argument("dir")
    s.add_argument("--deck", default="in.deck")
    engine_opts(s)
    s.set_defaults(func=cmd_run)
    s = sub.add_parser("parse", help="tables and summary of one run")
    s.add_argument("dir")
    s.add_argument("--out", required=True)
    s.add_argument("--steady-window", nargs=2, type=float, metavar=("START", "END"), default=None,
                   help="cutting runs: read the means over these fractions of the travel instead of the case's "
                        "outputs.steady_window (the summary records the window and its source)")
    s.add_argument("--breakoff-min-grains", type=int, default=None, metavar="N",
                   help="indentation runs: read the chip's break-off as the first piece of N grains instead of the "
                        "case's outputs.breakoff_min_grains (the summary records the size and its source)")
    s.set_defaults(func=cmd_parse)
    s = sub.add_parser("contacts", help="what carries the cutter's load at each dumped step: body, chips or debris")
    s.add_argument("dir", help="run folder (shell cutter)")
    s.add_argument("--parsed", required=True, help="its `deckgen parse` folder")
    s.add_argument("--out", required=True, help="CSV to write")
    s.set_defaults(func=cmd_contacts)
    s = sub.add_parser("aggregate", help="one table per kind across parsed runs")
    s.add_argument("dirs", nargs="+")
    s.add_argument("--out", required=True)
    s.set_defaults(func=cmd_aggregate)
    s = sub.add_parser("plot", help="plots of one parsed run")
    s.add_argument("dir")
    s.add_argument("--out", required=True)
    s.set_defaults(func=cmd_plot)
    s = sub.add_parser("stl", help="write the cutter of a case as STL")
    s.add_argument("case")
    s.add_argument("--out", required=True)
    s.add_argument("--offset-mm", type=float, default=0.0, help="inward offset (e.g. the shell radius)")
    s.set_defaults(func=cmd_stl)
    s = sub.add_parser("gap", help="discrepancy loop: find, name, add and show the missing effect")
    s.add_argument("--measured", required=True, help="MEASURED.csv: factor columns = spec field paths, "
                   "response columns = force table names (N), optional replicate")
    s.add_argument("--base", required=True, help="base case YAML (the current model)")
    s.add_argument("--out", required=True, help="output folder (report.json, report.md, PNG plots)")
    s.add_argument("--backend", default="fast", help="fast (reduced model, seconds) or dem (LAMMPS decks)")
    s.add_argument("--candidates", help="comma-separated catalogue ids to consider (default: all)")
    s.add_argument("--noise-cv", type=float, help="relative scatter to assume when there are no replicates")
    s.add_argument("--runs", help="dem backend: folder of the (cached) runs (default: OUT/dem_runs)")
    s.add_argument("--packing-seeds", help="dem backend: run every case on these packing seeds (comma-separated, "
                   ">= 2) and compare their mean; their standard error joins the noise")
    s.add_argument("--jobs", type=int, default=1, choices=[1, 2, 3, 4],
                   help="dem backend: engine runs at a time (use with --ranks 1)")
    engine_opts(s)
    s.set_defaults(func=cmd_gap)
    return p


def main(argv: list[str] | None = None) -> int:
    from deckgen.parse.common import ParseError
    from deckgen.render import DeckError
    from deckgen.runner import EngineError, stop_engines_on_sigterm
    from deckgen.spec import SpecError

    stop_engines_on_sigterm()
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (SpecError, DeckError, ParseError, EngineError, FileNotFoundError) as exc:
        print(f"deckgen: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("deckgen: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
