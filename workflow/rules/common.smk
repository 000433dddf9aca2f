# Shared helpers: the recording sheet and its groups, each group's settings and files, the
# paper study's paths, target lists.
from pathlib import Path

import yaml
from snakemake.logging import logger

from harvester.data.sheet import EMPS, load_sheets, recording_header
from harvester.groups import group_settings

# Conda environment of every rule (used with --use-conda; `make study` uses .venv instead).
ENV = "../../envs/harvester.yaml"

# Threads of a rule that integrates many models (TMCMC, predictive bounds, diagnosis): one.
# The study has many such jobs that do not wait on each other, and two one-thread jobs on two
# cores finished in 0.78x the time of the same two jobs one after the other on two threads each
# (docs/measurements.md, "The study and the test suite"); with more cores, more jobs run at once.
JOB_THREADS = 1

# ---------------------------------------------------------------- the paper study's records
RECORDS = ["training", "validation"]
# Records with the generator's voltage channel (rig.loaded_records): regenerated, verified and
# converted, not identified.
LOADED_RECORDS = list(config["rig"].get("loaded_records", {}))
RAW = config["data"]["raw_dir"]
MODELS = config["models"]
POSTERIOR_TABLE = {"linear": "table3", "tanh": "table5"}
POSTERIOR_FIGURE = {"linear": "fig06", "tanh": "fig08"}

# ---------------------------------------------------------------- the recording sheet(s)
# config `recordings` (config/README.md): read, checked against the schema of a row and as a
# whole at start-up; relative paths: the working directory, then the workflow's directory.
SHEET = load_sheets(
    config["recordings"],
    yaml.safe_load(Path(workflow.basedir, "workflow/schemas/recordings.schema.yaml").read_text()),
    bases=(Path.cwd(), Path(workflow.basedir)),
    reserved=LOADED_RECORDS,
)
GROUPS = {name: group_settings(config, name) for name in SHEET.groups}
GENERIC_GROUPS = [g for g, grp in SHEET.groups.items() if grp.chain != EMPS]
EMPS_GROUP = next((g for g, grp in SHEET.groups.items() if grp.chain == EMPS), None)
#: Groups trained on the Silverbox benchmark's own record: its tests beside the published
#: errors (rule silverbox_benchmark).
BENCHMARK_GROUPS = [g for g in GENERIC_GROUPS
                    if Path(SHEET.file(SHEET.groups[g].training)).name == "SNLS80mV.mat"]
STUDY_GROUPS = [g for g, s in GROUPS.items() if s["study"] == "paper"]
STUDY_GROUP = STUDY_GROUPS[0] if STUDY_GROUPS else None
#: Where each group's files go.
GROUP_DIR = "results/groups/{group}"
#: The report's page of every recording group.
GROUP_PAGE = "Recording groups"


def page_labels(group, result, model, recording=None):
    """Columns of a result on its group's report page: what it is (numbered in the order of
    the chain), the model and the recording (default: the group's training recording)."""
    return {"result": result, "model": model,
            "recording": recording or SHEET.groups[group].training}


def check_groups():
    """What the sheet cannot say alone: the paper study's group is the study's two records;
    an EMPS group takes no identification settings."""
    if len(STUDY_GROUPS) > 1:
        raise ValueError(f"config groups: {STUDY_GROUPS} are all marked study: paper; one is")
    if STUDY_GROUP is not None:
        grp = SHEET.groups[STUDY_GROUP]
        kinds = {SHEET.row(r)["kind"] for r in (grp.training, *grp.validation)}
        if (grp.training, grp.validation, kinds) != ("training", ("validation",), {"raw_daq"}):
            raise ValueError(
                f"{grp.sheet}: group {STUDY_GROUP} is the paper study (config groups."
                f"{STUDY_GROUP}.study: paper): its rows are the rig's raw_daq records 'training' "
                f"(role training) and 'validation' (role validation); found {grp.training}, "
                f"{list(grp.validation)} of kinds {sorted(kinds)}")
        GROUPS[STUDY_GROUP]["priors"] = "results/initial/priors.json"
    for name in GROUPS:
        if name == EMPS_GROUP and (config.get("groups") or {}).get(name):
            raise ValueError(f"config groups.{name}: {name} is an EMPS group, whose settings "
                             "are config emps")


check_groups()


def group_of(recording):
    return SHEET.group_of(recording)


def generic_recordings():
    return [r for g in GENERIC_GROUPS for r in SHEET.recordings(group=g)]


def one_of(names):
    """Wildcard constraint matching exactly these names (a never-matching one if none)."""
    return "|".join(names) if names else "(?!x)x"


# ---------------------------------------------------------------- a recording's files
def raw_files(record):
    """A raw_daq recording's CSV and JSON: the sheet's, or the rig's in data.raw_dir; the
    checksum check of data.raw_dir before converting a file of it."""
    if record in SHEET.table.index and SHEET.row(record)["kind"] == "raw_daq":
        files = {"csv": SHEET.file(record), "meta": SHEET.raw_meta(record)}
    else:
        files = {"csv": f"{RAW}/{record}.csv", "meta": f"{RAW}/{record}.json"}
    if Path(files["csv"]).resolve().parent == Path(RAW).resolve():
        files["checked"] = "results/checks/raw_checksums.txt"
    return files


def lowpass_settings(record):
    """(cut-off Hz, order) of the workflow's low-pass of a recording: its group's, or the
    paper study's preprocessing for the rig's records."""
    if record in SHEET.table.index:
        s = GROUPS[group_of(record)]
        return s["lowpass_hz"], s["filter_order"]
    return config["preprocess"]["lowpass_hz"], config["preprocess"]["filter_order"]


def converted_file(record):
    """A recording in the recording format: a converted CSV as the sheet gives it, or a
    raw_daq recording converted (rule convert)."""
    if record in SHEET.table.index and SHEET.row(record)["kind"] == "converted":
        return SHEET.file(record)
    if record in SHEET.table.index and SHEET.row(record)["kind"] == "public":
        return public_csv(record)
    return f"results/data/{record}_acc.csv"


def public_csv(record):
    """A public recording read into the recording format (rule convert_public), its sidecar
    beside it."""
    return f"results/data/{record}_public.csv"


def prepare_inputs(wildcards):
    """What rule prepare_recording checks: the recording after the workflow's conversion and
    low-pass, and the sheet's sidecar."""
    rec = wildcards.recording
    if group_of(rec) != wildcards.group:
        raise ValueError(f"recording {rec} is in group {group_of(rec)}, not {wildcards.group}")
    lowpass, _ = lowpass_settings(rec)
    files = {"data": f"results/data/{rec}_filtered.csv" if lowpass else converted_file(rec)}
    if SHEET.sidecar(rec):
        files["sidecar"] = SHEET.sidecar(rec)
    elif SHEET.row(rec)["kind"] == "public":
        files["sidecar"] = public_csv(rec).replace(".csv", ".yaml")
    return files


def recording_csv(group, recording):
    """A group's recording as prepared (sidecar beside it: same name, .yaml)."""
    return f"{GROUP_DIR}/data/{{recording}}.csv".format(group=group, recording=recording)


def training_csv(group):
    return recording_csv(group, SHEET.groups[group].training)


# ---------------------------------------------------------------- a group's files
def group_priors_file(group):
    """The priors a group is identified with: config groups.<group>.priors, the study's
    initial modelling for the paper study's group, else its recording's (rule
    recording_priors)."""
    return GROUPS[group]["priors"] or f"results/groups/{group}/priors.json"


def model_file(group, model, name):
    return f"results/groups/{group}/models/{model}/{name}"


def group_posterior(group, model):
    return model_file(group, model, "posterior.nc")


def study_posterior(model):
    """The paper study's posterior of a model: its group's identification."""
    if STUDY_GROUP is None:
        raise ValueError("the paper study's rules need the group of config/recordings.tsv "
                         "with `study: paper` in config groups")
    return group_posterior(STUDY_GROUP, model)


def group_models(group):
    return GROUPS[group]["models"]


def group_params(group, *sections):
    """A group's window (lead-in, seconds fitted, filter order) and the config sections a rule
    needs: only these, so that a change elsewhere (e.g. the diagnosis's budget) re-runs no
    identification."""
    keys = ("lead_in_s", "fit_seconds", "filter_order", *sections)
    return {k: GROUPS[group][k] for k in keys}


def validation_dir(group, model, recording):
    return f"results/groups/{group}/validation/{model}/{recording}"


def diagnosable(group):
    """Whether a group's diagnosis runs: config groups.<group>.diagnose (default true) and a
    training recording the diagnosis takes (every kind: input base_acc, base_disp or force,
    output rel_acc or rel_disp). M, m, k not known are identified (their priors the group's);
    with a base input one of them must be known (eq. 1 fixes only ratios to a mass)."""
    s = GROUPS[group]
    if not s["diagnose"]:
        return False
    if group == STUDY_GROUP or isinstance(s["diagnose"], list):  # asked for by name
        return True
    rec = SHEET.groups[group].training
    force = SHEET.row(rec)["kind"] == "converted" and \
        "force" in recording_header(SHEET.file(rec))
    known = set()
    if s["priors"]:
        known = set(yaml.safe_load(Path(s["priors"]).read_text())["known"]) \
            if Path(s["priors"]).exists() else {"M", "m", "k"}
    elif SHEET.sidecar(rec):
        known = set(yaml.safe_load(Path(SHEET.sidecar(rec)).read_text()) or {})
    if not force and not {"M", "m", "k"} & known:
        logger.warning(f"group {group}: no diagnosis (with a base input it needs one of M, m, "
                       f"k in the sidecar of {rec}); set groups.{group}.diagnose: false to "
                       "silence this")
        return False
    return True


DIAGNOSED = {g: diagnosable(g) for g in GENERIC_GROUPS}


def diagnosed_model(group, model):
    """Whether a model of a diagnosed group is diagnosed: all, or those config
    groups.<group>.diagnose lists."""
    asked = GROUPS[group]["diagnose"]
    return model in asked if isinstance(asked, list) else bool(asked)


def diagnosis_file(group, model, name="diagnosis.json"):
    return f"results/groups/{group}/diagnosis/{model}/{name}"


def group_links(group):
    """Pages a group's diagnosis summary links to (text, href from the summary): a benchmark
    group's benchmark tests beside the published results (rule silverbox_benchmark)."""
    if group not in BENCHMARK_GROUPS:
        return []
    return [("The benchmark's own tests: this group's models beside the published results "
             "(benchmark.html)", "../../benchmark.html")]


def diagnosis_inputs(group, model):
    """A diagnosis's recording, its posterior and priors, and the group's first validation
    recording (none: the diagnosis holds out the recording's last quarter)."""
    grp = SHEET.groups[group]
    files = {"data": training_csv(group), "posterior": group_posterior(group, model),
             "priors": group_priors_file(group)}
    if grp.validation:
        files["validation"] = recording_csv(group, grp.validation[0])
    return files


def group_outputs(group):
    """Everything a generic group's page shows."""
    grp = SHEET.groups[group]
    out = [f"results/groups/{group}/evidence.html", f"results/groups/{group}/validation.csv"]
    out += [recording_csv(group, r).replace(".csv", ".check.json")
            for r in (grp.training, *grp.validation)]
    for m in group_models(group):
        out += [model_file(group, m, n) for n in ("summary.csv", "posterior_pairs.png")]
        out += [f"{validation_dir(group, m, r)}/predictive.png" for r in grp.validation]
        if DIAGNOSED[group] and diagnosed_model(group, m):
            out.append(diagnosis_file(group, m, "summary.html"))
    if group in BENCHMARK_GROUPS:
        out.append(f"results/groups/{group}/benchmark.csv")
    return out


# ---------------------------------------------------------------- the paper study
def posterior_table(model):
    """Path of a model's posterior table: table3/table5 for the paper's models."""
    number = POSTERIOR_TABLE.get(model, "table_posterior")
    return f"results/tables/{number}_{model}.csv"


def posterior_figure(model):
    number = POSTERIOR_FIGURE.get(model, "fig_posterior")
    return f"results/figures/{number}_{model}_posterior.png"


def study_outputs():
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
        *[f"results/data/{r}_acc.csv" for r in LOADED_RECORDS],
    ]


def all_outputs():
    """Every group's page (the EMPS group's: the EMPS study) and the paper study's figures
    and tables when its group is in the sheet."""
    out = []
    for group in SHEET.groups:
        out += emps_outputs() if group == EMPS_GROUP else group_outputs(group)
    if STUDY_GROUP is not None:
        out += study_outputs()
    return out
