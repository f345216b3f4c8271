# Case families of the seed studies (issue #4): cases/<family>/{full,reduced}/*.yaml run through the
# per-case rules (pack -> render -> run -> parse -> plot); per family and scale the runs are aggregated
# (deckgen aggregate) and reported (factors, grains, wall time, forces; force-vs-factor plots):
#   snakemake --cores 2 family_odc_reduced        (or family_<family>_<scale>)
#   snakemake --cores 2 family_odc_trends         (the reduced cases that carry the seeds' trends, cheapest)
# Outputs: <results>/families/<family>_<scale>/{tables/*.csv|parquet, family_table.csv, plots/*.png}.
# Not part of the default target.


wildcard_constraints:
    family="|".join(FAMILIES),
    scale="full|reduced|trends",


rule family_aggregate:
    input:
        lambda w: expand(f"{RESULTS}/{{case}}/parsed/summary.json", case=family_case_names(w)),
    output:
        f"{RESULTS}/families/{{family}}_{{scale}}/tables/forces_summary.csv",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/families/{{family}}_{{scale}}_aggregate.log",
    params:
        dirs=lambda w: expand(f"{RESULTS}/{{case}}/parsed", case=family_case_names(w)),
        out=lambda w, output: str(Path(output[0]).parent),
    shell:
        "deckgen aggregate {params.dirs} --out {params.out} > {log} 2>&1"


rule family_report:
    input:
        tables=f"{RESULTS}/families/{{family}}_{{scale}}/tables/forces_summary.csv",
        plots=lambda w: expand(f"{RESULTS}/{{case}}/plots/done.txt", case=family_case_names(w)),
        index="cases/{family}/index.csv",
    output:
        f"{RESULTS}/families/{{family}}_{{scale}}/family_table.csv",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/families/{{family}}_{{scale}}_report.log",
    params:
        dirs=lambda w: expand(f"{RESULTS}/{{case}}/parsed", case=family_case_names(w)),
        out=lambda w, output: str(Path(output[0]).parent),
    shell:
        "python -m deckgen.families report --family {wildcards.family} --index {input.index} "
        "--out {params.out} {params.dirs} > {log} 2>&1"


for _fam in FAMILIES:
    for _scale in FAMILY_SCALES:

        rule:
            name:
                f"family_{_fam}_{_scale}"
            input:
                f"{RESULTS}/families/{_fam}_{_scale}/family_table.csv",
