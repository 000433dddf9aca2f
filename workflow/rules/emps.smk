# EMPS (real recordings, Janot, Gautier and Brunot 2019): the chain of a sheet's EMPS group
# (config/emps/recordings.tsv: its training and validation recordings), target emps_all.
# The drive is simulated inside its digital position loop (harvester.emps.closed_loop); the viscous baseline
# and baseline + each candidate term are identified by TMCMC, the evidence names the missing
# physics, the extended model's parameters are compared with the published ones and both models
# are validated on the unseen record (DATA_EMPS_PULSES). Settings: config emps.
from harvester.emps.results import SUMMARY_FIGURES

EMPS = config["emps"]
EMPS_BASELINE = "viscous"
EMPS_MODELS = [EMPS_BASELINE] + [f"viscous+{t}" for t in EMPS["candidates"]]
EMPS_EXTENDED = f"viscous+{EMPS['extended']}"
EMPS_SHOWN = [EMPS_BASELINE, EMPS_EXTENDED]
EMPS_RECORDS = ["training", "validation"]
#: The EMPS group's report page (its name in the sheet).
EMPS_PAGE = EMPS_GROUP or "emps"


def emps_file(role):
    """The EMPS group's recording of a role (training, validation), from the sheet."""
    if EMPS_GROUP is None:
        raise ValueError("no EMPS group in the recording sheet(s): add config/emps/recordings.tsv "
                         "to config recordings")
    grp = SHEET.groups[EMPS_GROUP]
    return SHEET.file(grp.training if role == "training" else grp.validation[0])


def emps_name(role):
    """The name in the sheet of the EMPS group's recording of a role (both: the two)."""
    if role == "both":
        return ", ".join(emps_name(r) for r in EMPS_RECORDS)
    if EMPS_GROUP is None:
        return role
    grp = SHEET.groups[EMPS_GROUP]
    return grp.training if role == "training" else grp.validation[0]


def emps_labels(result, model="-", role=None):
    """Columns of an EMPS result on the group's report page (as a generic group's)."""
    return lambda w: {"result": result, "model": model,
                      "recording": emps_name(role or w.get("record", "training"))}


#: The figures the EMPS diagnosis's summary page embeds.
EMPS_SUMMARY_FIGURES = list(SUMMARY_FIGURES)


def emps_outputs():
    """Everything the EMPS group's page shows (target emps_all)."""
    return [
        "results/emps/data.json",
        "results/emps/figures/data.png",
        "results/emps/priors.csv",
        "results/emps/figures/frf.png",
        "results/emps/diagnosis.csv",
        "results/emps/figures/evidence.png",
        "results/emps/parameters.csv",
        "results/emps/parameters_comparison.csv",
        "results/emps/figures/posterior.png",
        "results/emps/validation.csv",
        *expand("results/emps/figures/tracking_{record}{part}.png", record=EMPS_RECORDS,
                part=["", "_zoom"]),
        "results/emps/headline.csv",
        "results/emps/headline.html",
        "results/emps/summary.html",
    ]


rule emps_all:
    input:
        emps_outputs(),


rule emps_data:
    input:
        training=lambda w: emps_file("training"),
        validation=lambda w: emps_file("validation"),
    output:
        summary="results/emps/data.json",
        figure=report("results/emps/figures/data.png", caption="../report/emps_data.rst",
                      category=GROUP_PAGE, subcategory=EMPS_PAGE,
                      labels=emps_labels("1. data", "-", "both")),
    params:
        sha256=EMPS.get("sha256", {}),
    log:
        "logs/emps/data.log",
    conda:
        ENV
    script:
        "../scripts/emps_data.py"


rule emps_initial:
    input:
        training=lambda w: emps_file("training"),
        checked="results/emps/data.json",
    output:
        priors="results/emps/priors.json",
        table=report("results/emps/priors.csv", caption="../report/emps_priors.rst",
                     category=GROUP_PAGE, subcategory=EMPS_PAGE,
                     labels=emps_labels("2. initial modelling (priors)")),
        figure=report("results/emps/figures/frf.png", caption="../report/emps_frf.rst",
                      category=GROUP_PAGE, subcategory=EMPS_PAGE,
                      labels=emps_labels("2. initial modelling (FRF)")),
    params:
        frf=EMPS["frf"],
        priors=EMPS["priors"],
        stride=EMPS["stride"],
        temper=EMPS["temper"],
    log:
        "logs/emps/initial.log",
    conda:
        ENV
    script:
        "../scripts/emps_initial.py"


rule emps_tmcmc:
    input:
        training=lambda w: emps_file("training"),
        priors="results/emps/priors.json",
    output:
        "results/emps/posterior/{model}.nc",
    wildcard_constraints:
        model="viscous(\\+[a-z_]+)*",
    params:
        stride=EMPS["stride"],
        tmcmc=EMPS["tmcmc"],
    threads: JOB_THREADS
    resources:
        mem_mb=4000,
        runtime=60,
    log:
        "logs/emps/tmcmc_{model}.log",
    conda:
        ENV
    script:
        "../scripts/emps_tmcmc.py"


rule emps_diagnosis:
    input:
        expand("results/emps/posterior/{model}.nc", model=EMPS_MODELS),
    output:
        table=report("results/emps/diagnosis.csv", caption="../report/emps_diagnosis.rst",
                     category=GROUP_PAGE, subcategory=EMPS_PAGE,
                     labels=emps_labels("3. evidence (table)", "all")),
        named="results/emps/named_physics.json",
        figure=report("results/emps/figures/evidence.png", caption="../report/emps_evidence.rst",
                      category=GROUP_PAGE, subcategory=EMPS_PAGE,
                      labels=emps_labels("3. evidence (figure)", "all")),
    params:
        models=EMPS_MODELS,
        extended=EMPS["extended"],
    log:
        "logs/emps/diagnosis.log",
    conda:
        ENV
    script:
        "../scripts/emps_diagnosis.py"


rule emps_parameters:
    input:
        posterior=f"results/emps/posterior/{EMPS_EXTENDED}.nc",
        data="results/emps/data.json",
    output:
        parameters=report("results/emps/parameters.csv", caption="../report/emps_parameters.rst",
                          category=GROUP_PAGE, subcategory=EMPS_PAGE,
                          labels=emps_labels("4. posterior (table)", EMPS_EXTENDED)),
        comparison=report("results/emps/parameters_comparison.csv",
                          caption="../report/emps_comparison.rst", category=GROUP_PAGE,
                          subcategory=EMPS_PAGE,
                          labels=emps_labels("4. posterior (published values)", EMPS_EXTENDED)),
        figure=report("results/emps/figures/posterior.png", caption="../report/emps_posterior.rst",
                      category=GROUP_PAGE, subcategory=EMPS_PAGE,
                      labels=emps_labels("4. posterior (figure)", EMPS_EXTENDED)),
    log:
        "logs/emps/parameters.log",
    conda:
        ENV
    script:
        "../scripts/emps_parameters.py"


rule emps_predictive:
    input:
        posterior="results/emps/posterior/{model}.nc",
        record=lambda w: emps_file(w.record),
        priors="results/emps/priors.json",
    output:
        band="results/emps/predictive/{model}_{record}.npz",
        metrics="results/emps/predictive/{model}_{record}.json",
    wildcard_constraints:
        model="viscous(\\+[a-z_]+)*",
        record="|".join(EMPS_RECORDS),
    params:
        predictive=EMPS["predictive"],
    threads: JOB_THREADS
    log:
        "logs/emps/predictive_{model}_{record}.log",
    conda:
        ENV
    script:
        "../scripts/emps_predictive.py"


rule emps_validation:
    input:
        expand("results/emps/predictive/{model}_{record}.json", model=EMPS_SHOWN,
               record=EMPS_RECORDS),
    output:
        report("results/emps/validation.csv", caption="../report/emps_validation.rst",
               category=GROUP_PAGE, subcategory=EMPS_PAGE,
               labels=emps_labels("5. validation (table)", ", ".join(EMPS_SHOWN), "validation")),
    log:
        "logs/emps/validation.log",
    conda:
        ENV
    script:
        "../scripts/emps_validation.py"


rule emps_tracking_figure:
    input:
        bands=expand("results/emps/predictive/{model}_{{record}}.npz", model=EMPS_SHOWN),
        metrics=expand("results/emps/predictive/{model}_{{record}}.json", model=EMPS_SHOWN),
    output:
        full=report("results/emps/figures/tracking_{record}.png",
                    caption="../report/emps_tracking.rst", category=GROUP_PAGE,
                    subcategory=EMPS_PAGE,
                    labels=emps_labels("5. validation (figure)", ", ".join(EMPS_SHOWN))),
        zoom=report("results/emps/figures/tracking_{record}_zoom.png",
                    caption="../report/emps_tracking.rst", category=GROUP_PAGE,
                    subcategory=EMPS_PAGE,
                    labels=emps_labels("5. validation (zoom)", ", ".join(EMPS_SHOWN))),
    wildcard_constraints:
        record="|".join(EMPS_RECORDS),
    params:
        models=EMPS_SHOWN,
        zoom=EMPS["predictive"]["zoom_s"],
        title=lambda w: ("Identification record DATA_EMPS" if w.record == "training"
                         else "Unseen record DATA_EMPS_PULSES (force pulses added)"),
    log:
        "logs/emps/tracking_figure_{record}.log",
    conda:
        ENV
    script:
        "../scripts/emps_tracking_figure.py"


rule emps_headline:
    input:
        comparison="results/emps/parameters_comparison.csv",
        evidence="results/emps/diagnosis.csv",
        named="results/emps/named_physics.json",
        validation="results/emps/validation.csv",
        posteriors=expand("results/emps/posterior/{model}.nc", model=EMPS_MODELS),
        figures=expand("results/emps/figures/{name}", name=EMPS_SUMMARY_FIGURES),
    output:
        csv="results/emps/headline.csv",
        html=report("results/emps/headline.html", caption="../report/emps_headline.rst",
                    category=GROUP_PAGE, subcategory=EMPS_PAGE,
                    labels=emps_labels("0. headline", "all")),
        summary=report("results/emps/summary.html", caption="../report/emps_summary.rst",
                       category=GROUP_PAGE, subcategory=EMPS_PAGE,
                       labels=emps_labels("0. diagnosis summary", "all")),
    params:
        models=EMPS_MODELS,
        baseline=EMPS_BASELINE,
        extended=EMPS_EXTENDED,
    log:
        "logs/emps/headline.log",
    conda:
        ENV
    script:
        "../scripts/emps_headline.py"
