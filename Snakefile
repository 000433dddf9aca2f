# Reproduction of Green et al. (2015), "Probabilistic modelling of a rotational energy harvester",
# on recordings from a SIMULATED virtual rig (the paper's recordings are not public).
from snakemake.utils import min_version, validate

min_version("9.0")

configfile: "config/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")

report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/preprocess.smk"
include: "workflow/rules/initial.smk"
include: "workflow/rules/identify.smk"
include: "workflow/rules/validate.smk"
include: "workflow/rules/summary.smk"
include: "workflow/rules/diagnose.smk"
include: "workflow/rules/detection.smk"
include: "workflow/rules/emps.smk"


rule all:
    input:
        all_outputs(),
