# Unseen-data validation: the posterior predictive of every model of a group on each of its
# validation recordings; the paper study's on its training and unseen records (Figures 7, 9, 10
# and its validation metrics).


localrules:
    group_validation,


rule validate_recording:
    input:
        posterior=lambda w: group_posterior(w.group, w.model),
        data=lambda w: recording_csv(w.group, w.recording),
        sidecar=lambda w: recording_csv(w.group, w.recording).replace(".csv", ".yaml"),
    output:
        band=f"{GROUP_DIR}/validation/{{model}}/{{recording}}/predictive.csv",
        metrics=f"{GROUP_DIR}/validation/{{model}}/{{recording}}/validation.json",
        figure=report(f"{GROUP_DIR}/validation/{{model}}/{{recording}}/predictive.png",
                      caption="../report/group_validation.rst", category=GROUP_PAGE,
                      subcategory="{group}",
                      labels=lambda w: page_labels(w.group, "3. validation", w.model,
                                                   w.recording)),
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
        recording=one_of(generic_recordings()),
    params:
        predictive=lambda w: GROUPS[w.group]["predictive"],
        lead_in_s=lambda w: GROUPS[w.group]["validation_lead_in_s"],
    threads: JOB_THREADS
    resources:
        mem_mb=4000,
        runtime=30,
    log:
        "logs/groups/{group}/validate_{model}_{recording}.log",
    conda:
        ENV
    script:
        "../scripts/validate_recording.py"


rule group_validation:
    input:
        lambda w: [f"{validation_dir(w.group, m, r)}/validation.json" for m in group_models(w.group)
                   for r in SHEET.groups[w.group].validation],
    output:
        report(f"{GROUP_DIR}/validation.csv", caption="../report/group_validation_table.rst",
               category=GROUP_PAGE, subcategory="{group}",
               labels=lambda w: page_labels(w.group, "3. validation", "all",
                                            ", ".join(SHEET.groups[w.group].validation) or "-")),
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
    log:
        "logs/groups/{group}/validation.log",
    conda:
        ENV
    script:
        "../scripts/group_validation.py"


rule predictive:
    input:
        posterior=lambda w: study_posterior(w.model),
        data="results/data/{record}_filtered.csv",
        priors="results/initial/priors.json",
    output:
        "results/predictive/{model}_{record}.npz",
    params:
        lead_in=lambda w: config["preprocess"][f"{w.record}_lead_in"],
        samples=lambda w: config["preprocess"]["training_samples"] if w.record == "training" else None,
        predictive=config["predictive"],
    wildcard_constraints:
        record="|".join(RECORDS),
    threads: JOB_THREADS
    log:
        "logs/predictive_{model}_{record}.log",
    conda:
        ENV
    script:
        "../scripts/predictive.py"


rule validation_table:
    input:
        expand("results/predictive/{model}_{record}.npz", model=MODELS, record=RECORDS),
    output:
        report("results/tables/validation.csv", caption="../report/validation.rst",
               category="Validation"),
    log:
        "logs/validation_table.log",
    conda:
        ENV
    script:
        "../scripts/validation_table.py"


rule fig07_linear_training:
    input:
        "results/predictive/linear_training.npz",
        "results/predictive/tanh_training.npz",
    output:
        report("results/figures/fig07_linear_training.png", caption="../report/fig07.rst",
               category="Validation"),
        "results/tables/figure7_sticking.csv",
    params:
        title="Linear model against the training data (Figure 7)",
        window=None,
        rig=config["rig"],
        record="training",
        lead_in=config["preprocess"]["training_lead_in"],
        zoom_s=1.0,
        model="linear",
        compare="tanh",
    log:
        "logs/fig07.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"


rule fig09_tanh_unseen_section:
    input:
        "results/predictive/tanh_validation.npz",
    output:
        report("results/figures/fig09_tanh_unseen_section.png", caption="../report/fig09.rst",
               category="Validation"),
    params:
        title="Hyperbolic tangent model against a section of the unseen data (Figure 9)",
        window=config["predictive"]["short_window_s"],
        rig=config["rig"],
        record="validation",
        lead_in=config["preprocess"]["validation_lead_in"],
        zoom_s=None,
    log:
        "logs/fig09.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"


rule fig10_tanh_unseen_full:
    input:
        "results/predictive/tanh_validation.npz",
    output:
        report("results/figures/fig10_tanh_unseen_full.png", caption="../report/fig10.rst",
               category="Validation"),
    params:
        title="Hyperbolic tangent model against 80 s of unseen data (Figure 10)",
        window=None,
        rig=config["rig"],
        record="validation",
        lead_in=config["preprocess"]["validation_lead_in"],
        zoom_s=None,
    log:
        "logs/fig10.log",
    conda:
        ENV
    script:
        "../scripts/response_figure.py"
