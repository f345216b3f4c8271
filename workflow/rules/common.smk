# Path helpers, case loading and wildcard constraints shared by every stage.
from pathlib import Path

RESULTS = config.get("results", "results")
CASE_FILES = {Path(p).stem: p for p in config["cases"]}
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
    return expand(f"{RESULTS}/{{case}}/plots/done.txt", case=list(CASE_FILES))
