# Path helpers, case loading and wildcard constraints shared by every stage.
from pathlib import Path

RESULTS = config.get("results", "results")
#: the cases of the default target (workflow/config.yaml)
DEFAULT_CASES = {Path(p).stem: p for p in config["cases"]}
#: case families (cases/<family>/{full,reduced}/*.yaml, written by python -m deckgen.families write);
#: their runs go through the same per-case rules, targets family_<family>_<scale> (rules/families.smk)
FAMILIES = config.get("families", ["indentation_asymmetric", "linear_ccs", "rotary", "odc"])
FAMILY_SCALES = ["full", "reduced"]
FAMILY_CASES = {
    (fam, scale): {p.stem: str(p) for p in sorted(Path("cases", fam, scale).glob("*.yaml"))}
    for fam in FAMILIES
    for scale in FAMILY_SCALES
}


def _trend_subset(fam):
    """Reduced cases marked trend_subset in cases/<family>/index.csv (deckgen.families.TREND_SUBSETS)."""
    import csv

    index = Path("cases", fam, "index.csv")
    if not index.is_file():
        return {}
    with index.open() as fh:
        names = [r["case"] for r in csv.DictReader(fh) if r.get("trend_subset") == "1"]
    return {n: FAMILY_CASES[(fam, "reduced")][n] for n in names if n in FAMILY_CASES[(fam, "reduced")]}


#: scale "trends": the reduced cases that carry the seeds' trends at the least cost (family_<family>_trends)
for _fam in FAMILIES:
    FAMILY_CASES[(_fam, "trends")] = _trend_subset(_fam)
FAMILY_SCALES = ["full", "reduced", "trends"]
CASE_FILES = dict(DEFAULT_CASES)
for _cases in FAMILY_CASES.values():
    for _name, _path in _cases.items():
        if _name in CASE_FILES and CASE_FILES[_name] != _path:
            raise ValueError(f"case name {_name} is used by {CASE_FILES[_name]} and {_path}: rename one")
        CASE_FILES[_name] = _path
TABLE_KINDS = [
    "forces_timeseries",
    "forces_summary",
    "platen_timeseries",
    "platen_summary",
    "damage_summary",
    "broken_bonds_timeseries",
]


wildcard_constraints:
    case="[a-z][a-z0-9_\-]*",


def case_file(wildcards):
    return CASE_FILES[wildcards.case]


def engine_args():
    cmd = config.get("engine_cmd") or ""
    if cmd:
        return f"--engine-cmd '{cmd}'"
    return f"--ranks {config.get('ranks', 2)}"


def tables():
    return expand(
        f"{RESULTS}/tables/{{kind}}.{{ext}}", kind=TABLE_KINDS, ext=["csv", "parquet"]
    )


def plots():
    return expand(f"{RESULTS}/{{case}}/plots/done.txt", case=list(DEFAULT_CASES))


#: the rocks of issue #3 (cases/materials/<rock>.yaml)
CAL_ROCKS = ["savonniere_limestone", "concrete", "sandstone", "colorado_red_granite"]
CAL_STUDIES = f"{RESULTS}/calibration/studies"


def calib_engine_args():
    """UCS and BTS of a point side by side on half the ranks each (1-rank runs share 2 cores best)."""
    if config.get("engine_cmd"):
        return engine_args()
    ranks = int(config.get("ranks", 2))
    return f"--jobs 2 --ranks {max(1, ranks // 2)}" if ranks >= 2 else "--ranks 1"


def family_case_names(wildcards):
    """Case names of one family and scale (rules/families.smk)."""
    return list(FAMILY_CASES[(wildcards.family, wildcards.scale)])


# issue #3 item 6: a rock's card and its calibration set-ups at other grain sizes (rule calibration_resolution)
RESOLUTION_SIZES = ("coarse", "fine")


def resolution_cards(wildcards):
    cards = [f"{RESULTS}/calibration/{wildcards.rock}/card.yaml"]
    cards += [f"{RESULTS}/calibration/{size}/{wildcards.rock}/card.yaml" for size in RESOLUTION_SIZES
              if Path(f"cases/materials/{size}/{wildcards.rock}.yaml").is_file()]
    if len(cards) == 1:
        raise ValueError(f"resolution_{wildcards.rock}: no cases/materials/coarse/{wildcards.rock}.yaml or "
                         f"cases/materials/fine/{wildcards.rock}.yaml (fix: add a set-up at another grain size)")
    return cards
