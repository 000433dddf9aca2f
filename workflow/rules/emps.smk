# EMPS (real recordings, Janot, Gautier and Brunot 2019): a study of its own, target emps_all.
# The drive is simulated inside its digital position loop (harvester.emps.closed_loop); the viscous baseline
# and baseline + each candidate term are identified by TMCMC, the evidence names the missing
# physics, the extended model's parameters are compared with the published ones and both models
# are validated on the unseen DATA_EMPS_PULSES record.
EMPS = config["emps"]
EMPS_BASELINE = "viscous"
EMPS_MODELS = [EMPS_BASELINE] + [f"viscous+{t}" for t in EMPS["candidates"]]
EMPS_EXTENDED = f"viscous+{EMPS['extended']}"
EMPS_SHOWN = [EMPS_BASELINE, EMPS_EXTENDED]
EMPS_RECORDS = ["training", "validation"]


rule emps_all:
    input:
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
        expand("results/emps/figures/tracking_{record}{part}.png", record=EMPS_RECORDS,
               part=["", "_zoom"]),
        "results/emps/headline.csv",
        "results/emps/headline.html",


rule emps_data:
    input:
        training=EMPS["training"],
        validation=EMPS["validation"],
    output:
        summary="results/emps/data.json",
        figure=report("results/emps/figures/data.png", caption="../report/emps_data.rst",
                      category="EMPS", subcategory="1. Data"),
    params:
        sha256=EMPS["sha256"],
    log:
        "logs/emps/data.log",
    conda:
        ENV
    script:
        "../scripts/emps_data.py"


rule emps_initial:
    input:
        training=EMPS["training"],
        checked="results/emps/data.json",
    output:
        priors="results/emps/priors.json",
        table=report("results/emps/priors.csv", caption="../report/emps_priors.rst",
                     category="EMPS", subcategory="2. Initial modelling"),
        figure=report("results/emps/figures/frf.png", caption="../report/emps_frf.rst",
                      category="EMPS", subcategory="2. Initial modelling"),
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
        training=EMPS["training"],
        priors="results/emps/priors.json",
    output:
        "results/emps/posterior/{model}.nc",
    wildcard_constraints:
        model="viscous(\\+[a-z_]+)*",
    params:
        stride=EMPS["stride"],
        tmcmc=EMPS["tmcmc"],
    threads: 2
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
                     category="EMPS", subcategory="3. Missing physics"),
        named="results/emps/named_physics.json",
        figure=report("results/emps/figures/evidence.png", caption="../report/emps_evidence.rst",
                      category="EMPS", subcategory="3. Missing physics"),
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
                          category="EMPS", subcategory="4. Parameters"),
        comparison=report("results/emps/parameters_comparison.csv",
                          caption="../report/emps_comparison.rst", category="EMPS",
                          subcategory="4. Parameters"),
        figure=report("results/emps/figures/posterior.png", caption="../report/emps_posterior.rst",
                      category="EMPS", subcategory="4. Parameters"),
    log:
        "logs/emps/parameters.log",
    conda:
        ENV
    script:
        "../scripts/emps_parameters.py"


rule emps_predictive:
    input:
        posterior="results/emps/posterior/{model}.nc",
        record=lambda w: EMPS[w.record],
        priors="results/emps/priors.json",
    output:
        band="results/emps/predictive/{model}_{record}.npz",
        metrics="results/emps/predictive/{model}_{record}.json",
    wildcard_constraints:
        model="viscous(\\+[a-z_]+)*",
        record="|".join(EMPS_RECORDS),
    params:
        predictive=EMPS["predictive"],
    threads: 2
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
               category="EMPS", subcategory="5. Validation"),
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
                    caption="../report/emps_tracking.rst", category="EMPS",
                    subcategory="5. Validation"),
        zoom=report("results/emps/figures/tracking_{record}_zoom.png",
                    caption="../report/emps_tracking.rst", category="EMPS",
                    subcategory="5. Validation"),
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
    output:
        csv="results/emps/headline.csv",
        html=report("results/emps/headline.html", caption="../report/emps_headline.rst",
                    category="EMPS", subcategory="0. Headline numbers"),
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
