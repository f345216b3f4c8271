# Discrepancy workflow (issue #5, docs/discrepancy.md), on demand, not part of the default target:
#   snakemake results/gap/<name>/report.json   for a study listed under `gap:` in the config
#       (gap: {<name>: {measured: CSV, base: CASE, backend: fast|dem}})
#   snakemake results/gap/seed002_demo/report.json   real data: seed 002 RCM forces vs a linear model
#   snakemake results/gap/dem_example/report.json    DEM end to end: a hidden free-rolling disc, three candidates (slow; 5 packing
#       seeds for the measured rows and 3 others for every model case; 92 engine runs)
# Engine runs use one rank each, gap_ranks of them at a time (default 1).

GAP = config.get("gap", {})
GAP_RANKS = config.get("gap_ranks", 1)


wildcard_constraints:
    study="[a-z][a-z0-9_]*",


rule gap_seed002_demo:
    input:
        base="cases/gap/rcm_linear_base.yaml",
    output:
        report=f"{RESULTS}/gap/seed002_demo/report.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/gap/seed002_demo.log",
    params:
        out=lambda w, output: str(Path(output.report).parent),
    shell:
        "python -m deckgen.gap.examples seed002 --base {input.base} --out {params.out} > {log} 2>&1"


rule gap_dem_measured:
    input:
        base="cases/gap/dem_base.yaml",
    output:
        csv=f"{RESULTS}/gap/dem_example/measured.csv",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/gap/dem_measured.log",
    benchmark:
        f"{RESULTS}/benchmarks/gap/dem_measured.tsv"
    threads: GAP_RANKS
    params:
        runs=f"{RESULTS}/gap/dem_runs",
        cache=f"{RESULTS}/.cache",
    shell:
        "python -m deckgen.gap.examples dem-measured --base {input.base} --out {output.csv} "
        "--runs {params.runs} --cache {params.cache} --set kinematics.spin=rolling "
        "--penetrations 1.0,1.5,2.0,2.5 --seeds 101,404,505,606,707 --ranks 1 --jobs {threads} > {log} 2>&1"


rule gap_dem_example:
    input:
        measured=f"{RESULTS}/gap/dem_example/measured.csv",
        base="cases/gap/dem_base.yaml",
    output:
        report=f"{RESULTS}/gap/dem_example/report.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/gap/dem_example.log",
    benchmark:
        f"{RESULTS}/benchmarks/gap/dem_example.tsv"
    threads: GAP_RANKS
    params:
        out=lambda w, output: str(Path(output.report).parent),
        runs=f"{RESULTS}/gap/dem_runs",
        cache=f"{RESULTS}/.cache",
    shell:
        "deckgen gap --measured {input.measured} --base {input.base} --out {params.out} --backend dem "
        "--candidates free_rolling,wear_flat,tilt --packing-seeds 12345,202,303 --runs {params.runs} --ranks 1 --jobs {threads} "
        "--cache {params.cache} "
        "> {log} 2>&1"


rule gap:
    input:
        measured=lambda w: GAP[w.study]["measured"],
        base=lambda w: GAP[w.study]["base"],
    output:
        report=f"{RESULTS}/gap/{{study}}/report.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/gap/{{study}}.log",
    threads: GAP_RANKS
    params:
        out=lambda w, output: str(Path(output.report).parent),
        backend=lambda w: GAP[w.study].get("backend", "fast"),
        cache=f"{RESULTS}/.cache",
    shell:
        "deckgen gap --measured {input.measured} --base {input.base} --out {params.out} "
        "--backend {params.backend} --ranks {threads} --cache {params.cache} > {log} 2>&1"


ruleorder: gap_seed002_demo > gap_dem_example > gap
