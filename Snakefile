# The harvester workflow: the recordings of a sheet (config `recordings`, config/README.md)
# identified, compared by evidence, validated on unseen data and diagnosed, group by group. The
# shipped sheets reproduce Green et al. (2015), "Probabilistic modelling of a rotational energy
# harvester", on recordings from a SIMULATED virtual rig (the paper's recordings are not
# public), and the EMPS benchmark (real recordings).
from pathlib import Path

from snakemake.utils import min_version, validate

min_version("9.0")


# The project's settings; a working directory's own config/config.yaml over them, if it has one
# (`--directory .test`: the small test configuration).
configfile: f"{workflow.basedir}/config/config.yaml"


if Path("config/config.yaml").is_file():

    configfile: "config/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/preprocess.smk"
include: "workflow/rules/initial.smk"
include: "workflow/rules/identify.smk"
include: "workflow/rules/validate.smk"
include: "workflow/rules/benchmark.smk"
include: "workflow/rules/summary.smk"
include: "workflow/rules/diagnose.smk"
include: "workflow/rules/detection.smk"
include: "workflow/rules/emps.smk"
include: "workflow/rules/electrical.smk"


rule all:
    input:
        all_outputs(),
        electrical_outputs(),
