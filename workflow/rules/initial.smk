# Initial modelling (paper section "Initial modelling"): static friction, viscous damping, Table 1,
# priors; and the priors of any group from its training recording.


rule static_friction:
    input:
        csv=f"{RAW}/static_friction.csv",
        meta=f"{RAW}/static_friction.json",
        checked="results/checks/raw_checksums.txt",
    output:
        "results/initial/static_friction.json",
    params:
        k=config["rig"]["k"],
    log:
        "logs/static_friction.log",
    conda:
        ENV
    script:
        "../scripts/static_friction.py"


rule damping_fit:
    input:
        data="results/data/training_filtered.csv",
        static="results/initial/static_friction.json",
    output:
        fit="results/initial/damping_fit.json",
        figure=report("results/figures/fig_initial_damping_fit.png",
                      caption="../report/damping_fit.rst", category="Initial modelling"),
    params:
        rig=config["rig"],
        band=config["initial"]["damping_fit_band_hz"],
        lead_in=config["preprocess"]["training_lead_in"],
        samples=config["preprocess"]["training_samples"],
    log:
        "logs/damping_fit.log",
    conda:
        ENV
    script:
        "../scripts/damping_fit.py"


rule table1:
    input:
        static="results/initial/static_friction.json",
        damping="results/initial/damping_fit.json",
    output:
        table1=report("results/tables/table1_initial_estimates.csv",
                      caption="../report/table1.rst", category="Initial modelling"),
        table1_md="results/tables/table1_initial_estimates.md",
        table2=report("results/tables/table2_priors_linear.csv",
                      caption="../report/table2.rst", category="Initial modelling"),
        table4=report("results/tables/table4_priors_tanh.csv",
                      caption="../report/table4.rst", category="Initial modelling"),
        priors="results/initial/priors.json",
    params:
        rig=config["rig"],
        priors=config["priors"],
    log:
        "logs/table1.log",
    conda:
        ENV
    script:
        "../scripts/table1.py"


rule recording_priors:
    """A group's priors from its training recording: the sidecar's priors, the recording's FRF
    (harvester.initial.recording), the library's defaults (the paper study's group: rule
    table1)."""
    input:
        data=lambda w: training_csv(w.group),
        sidecar=lambda w: training_csv(w.group).replace(".csv", ".yaml"),
    output:
        f"{GROUP_DIR}/priors.json",
    wildcard_constraints:
        group=one_of(GENERIC_GROUPS),
    params:
        models=lambda w: group_models(w.group),
        settings=lambda w: group_params(w.group),
    log:
        "logs/groups/{group}/recording_priors.log",
    conda:
        ENV
    script:
        "../scripts/recording_priors.py"
