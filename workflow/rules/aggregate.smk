# Aggregate: one tidy table per kind across all runs, as CSV and parquet.


rule aggregate:
    input:
        expand(f"{RESULTS}/{{case}}/parsed/summary.json", case=list(DEFAULT_CASES)),
    output:
        tables(),
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/aggregate.log",
    params:
        dirs=expand(f"{RESULTS}/{{case}}/parsed", case=list(DEFAULT_CASES)),
        out=lambda w, output: str(Path(output[0]).parent),
    shell:
        "deckgen aggregate {params.dirs} --out {params.out} > {log} 2>&1"
