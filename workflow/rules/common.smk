# Shared helpers: paths of the study's files, target lists.
# Conda environment of every rule (used with --use-conda; `make study` uses .venv instead).
ENV = "../../envs/harvester.yaml"
RECORDS = ["training", "validation"]
# Records with the generator's voltage channel (rig.loaded_records): regenerated, verified and
# converted, not identified.
LOADED_RECORDS = list(config["rig"].get("loaded_records", {}))
RAW = config["data"]["raw_dir"]
MODELS = config["models"]
POSTERIOR_TABLE = {"linear": "table3", "tanh": "table5"}
POSTERIOR_FIGURE = {"linear": "fig06", "tanh": "fig08"}


def raw_files(record):
    return {"csv": f"{RAW}/{record}.csv", "meta": f"{RAW}/{record}.json"}


def posterior_table(model):
    """Path of a model's posterior table: table3/table5 for the paper's models."""
    number = POSTERIOR_TABLE.get(model, "table_posterior")
    return f"results/tables/{number}_{model}.csv"


def posterior_figure(model):
    number = POSTERIOR_FIGURE.get(model, "fig_posterior")
    return f"results/figures/{number}_{model}_posterior.png"


def all_outputs():
    return [
        "results/checks/raw_reproduced.txt",
        "results/figures/fig04_psd.png",
        "results/figures/fig05_time_history.png",
        "results/figures/fig_initial_damping_fit.png",
        "results/tables/table1_initial_estimates.csv",
        "results/tables/table2_priors_linear.csv",
        "results/tables/table4_priors_tanh.csv",
        *[posterior_table(m) for m in MODELS],
        *[posterior_figure(m) for m in MODELS],
        "results/tables/evidence.csv",
        "results/tables/bayes_factor.csv",
        "results/tables/validation.csv",
        "results/figures/fig07_linear_training.png",
        "results/figures/fig09_tanh_unseen_section.png",
        "results/figures/fig10_tanh_unseen_full.png",
        "results/tables/headline.csv",
        *[f"results/diagnosis/{m}/diagnosis.json" for m in MODELS],
        *[f"results/data/{r}_acc.csv" for r in LOADED_RECORDS],
    ]
