# Proof on concealed effects (target `detection_all`): scenarios of the virtual device carrying
# one effect whose contribution to z'' is a set fraction of the noise RMS, each diagnosed;
# detection table, confusion matrix, false-alarm rate under results/detection/{grid}/. Grid:
# config `detection.grid` (small: a laptop, minutes; full: a cluster, `--profile profiles/slurm`).
DETECTION = config.get("detection", {})
#: Each grid writes under its own directory, so that grids never mix their scenarios.
DET = f"results/detection/{DETECTION.get('grid', 'small')}"
DET_LOG = f"logs/detection/{DETECTION.get('grid', 'small')}"


def detection_grid():
    """The selected grid's settings (config detection.grids[detection.grid])."""
    if not DETECTION:
        raise ValueError("config has no `detection` section (see config/config.yaml)")
    return DETECTION["grids"][DETECTION["grid"]]


def detection_scenarios():
    """(effect, ratio, seed) of every scenario of the selected grid."""
    from harvester.grid.scoring import scenario_grid

    return scenario_grid(DETECTION)


def detection_files(kind, ext):
    return [f"{DET}/{kind}/{e}/r{r}_s{s}.{ext}" for e, r, s in detection_scenarios()]


def scenario_settings():
    """Overrides of harvester.synthetic.scenarios.ScenarioSettings beyond the rig and preprocessing."""
    return {"duration_s": float(detection_grid()["duration_s"]),
            "lead_in_s": float(DETECTION["lead_in_s"]), "seed": int(DETECTION["seed"])}


#: Wildcards of a scenario: effect name, ratio label (":g" format), seed.
SCENARIO_WILDCARDS = {"effect": "[a-z_]+", "ratio": "[0-9]+(\\.[0-9]+)?", "seed": "[0-9]+"}


localrules:
    detection_all,


rule detection_all:
    input:
        f"{DET}/detection_table.csv",
        f"{DET}/confusion_matrix.csv",
        f"{DET}/false_alarms.csv",
        f"{DET}/goal_summary.csv",
        f"{DET}/figures/detection_rates.png",


rule detection_scenario:
    output:
        recording=f"{DET}/scenarios/{{effect}}/r{{ratio}}_s{{seed}}.csv",
        truth=f"{DET}/scenarios/{{effect}}/r{{ratio}}_s{{seed}}.json",
    params:
        rig=config["rig"],
        preprocess=config["preprocess"],
        settings=lambda w: scenario_settings(),
        generator=lambda w: detection_grid().get("generator", "library"),
    wildcard_constraints:
        **SCENARIO_WILDCARDS,
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        f"{DET_LOG}/scenario_{{effect}}_r{{ratio}}_s{{seed}}.log",
    conda:
        ENV
    script:
        "../scripts/detection_scenario.py"


rule diagnose_scenario:
    input:
        recording=f"{DET}/scenarios/{{effect}}/r{{ratio}}_s{{seed}}.csv",
        truth=f"{DET}/scenarios/{{effect}}/r{{ratio}}_s{{seed}}.json",
    output:
        f"{DET}/diagnoses/{{effect}}/r{{ratio}}_s{{seed}}.json",
    params:
        fast=lambda w: bool(detection_grid()["fast"]),
        # a grid's recordings may be unfiltered (the literature generator's): its own low-pass
        lowpass_hz=lambda w: detection_grid().get("lowpass_hz", config["preprocess"]["lowpass_hz"]),
        preprocess=config["preprocess"],
    wildcard_constraints:
        **SCENARIO_WILDCARDS,
    threads: JOB_THREADS
    resources:
        mem_mb=3000,
        runtime=lambda w: 15 if detection_grid()["fast"] else 60,
    log:
        f"{DET_LOG}/diagnose_{{effect}}_r{{ratio}}_s{{seed}}.log",
    conda:
        ENV
    script:
        "../scripts/detection_diagnose.py"


rule detection_table:
    input:
        truths=lambda w: detection_files("scenarios", "json"),
        diagnoses=lambda w: detection_files("diagnoses", "json"),
    output:
        results=f"{DET}/scenario_results.csv",
        table=report(f"{DET}/detection_table.csv", caption="../report/detection_table.rst",
                     category="Concealed effects"),
        confusion=report(f"{DET}/confusion_matrix.csv",
                         caption="../report/detection_confusion.rst",
                         category="Concealed effects"),
        alarms=report(f"{DET}/false_alarms.csv", caption="../report/detection_false_alarms.rst",
                      category="Concealed effects"),
        summary=report(f"{DET}/goal_summary.csv", caption="../report/detection_summary.rst",
                       category="Concealed effects"),
    params:
        accepted=lambda w: DETECTION.get("accepted", {}),
        goal=lambda w: DETECTION["goal"],
    log:
        f"{DET_LOG}/table.log",
    conda:
        ENV
    script:
        "../scripts/detection_table.py"


rule detection_figure:
    input:
        table=f"{DET}/detection_table.csv",
        alarms=f"{DET}/false_alarms.csv",
        results=f"{DET}/scenario_results.csv",
    output:
        report(f"{DET}/figures/detection_rates.png", caption="../report/detection_rates.rst",
               category="Concealed effects"),
    params:
        goal=lambda w: DETECTION["goal"],
    log:
        f"{DET_LOG}/figure.log",
    conda:
        ENV
    script:
        "../scripts/detection_figure.py"
