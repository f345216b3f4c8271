# Parse: per-run force, platen, damage and broken-bond tables plus a summary.


rule parse:
    input:
        result=f"{RESULTS}/{{case}}/run/run.json",
    output:
        summary=f"{RESULTS}/{{case}}/parsed/summary.json",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/parse/{{case}}.log",
    params:
        run_dir=lambda w, input: str(Path(input.result).parent),
        out=lambda w, output: str(Path(output.summary).parent),
    shell:
        "deckgen parse {params.run_dir} --out {params.out} > {log} 2>&1"
