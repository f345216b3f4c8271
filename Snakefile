# deckgen workflow: pack -> render -> run -> parse -> aggregate -> plot, one rule file per stage.
# Default target: the cases of workflow/config.yaml (the embedded smoke cases).


configfile: "workflow/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/pack.smk"
include: "workflow/rules/render.smk"
include: "workflow/rules/run.smk"
include: "workflow/rules/parse.smk"
include: "workflow/rules/aggregate.smk"
include: "workflow/rules/plot.smk"
include: "workflow/rules/calibrate.smk"
include: "workflow/rules/gap.smk"
include: "workflow/rules/families.smk"


rule all:
    input:
        tables(),
        plots(),
