# Plot: PNG plots per run into <results>/plots.


rule plot:
    input:
        summary=f"{RESULTS}/{{case}}/parsed/summary.json",
    output:
        done=f"{RESULTS}/{{case}}/plots/done.txt",
    conda:
        "../envs/deckgen.yaml"
    log:
        f"{RESULTS}/logs/plot/{{case}}.log",
    params:
        parsed=lambda w, input: str(Path(input.summary).parent),
        out=f"{RESULTS}/plots",
    shell:
        "deckgen plot {params.parsed} --out {params.out} > {log} 2>&1 && echo done > {output.done}"
