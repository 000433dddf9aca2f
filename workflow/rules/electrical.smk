# The electrical half and the power it would make (issue 25; docs/electrical.md): the generator
# identified from the loaded records per electrical structure, the structures' evidence, power
# on excitations the device never saw with the design under uncertainty, and the held-out
# calibration. Target electrical_all (also in all).

ELECTRICAL = config["electrical"]
POWER = config["power"]
ELECTRICAL_PAGE = "Electrical half and power"
EXCITATIONS = list(POWER["excitations"])


def electrical_samples():
    return [f"results/electrical/samples_{s}.csv" for s in ELECTRICAL["structures"]]


def electrical_outputs():
    """The electrical study's results shown in the report; none without the paper study's
    group (its tanh posterior is the mechanical prior) or its loaded records."""
    if STUDY_GROUP is None or not set(ELECTRICAL["records"]) <= set(LOADED_RECORDS):
        return []
    return [
        "results/electrical/evidence.csv",
        "results/electrical/parameters.csv",
        *[f"results/power/{e}/{f}" for e in EXCITATIONS
          for f in ("curve.csv", "energy.csv", "design.json", "power_vs_load.png",
                    "energy.png")],
        "results/power/calibration/coverage.csv",
        "results/power/calibration/coverage.png",
    ]


rule electrical_all:
    input:
        electrical_outputs(),


rule electrical_identify:
    """TMCMC of one electrical structure on the loaded records, the tanh posterior as prior."""
    input:
        records=[f"results/data/{r}_acc.csv" for r in ELECTRICAL["records"]],
        metas=[f"{RAW}/{r}.json" for r in ELECTRICAL["records"]],
        mechanical=lambda w: study_posterior("tanh"),
    output:
        posterior="results/electrical/{structure}/posterior.nc",
        samples="results/electrical/samples_{structure}.csv",
        evidence="results/electrical/{structure}/evidence.json",
    wildcard_constraints:
        structure=one_of(ELECTRICAL["structures"]),
    params:
        electrical=ELECTRICAL,
        preprocess=config["preprocess"],
        sigma_prior=config["priors"]["sigma"],
    threads: 1
    log:
        "logs/electrical/identify_{structure}.log",
    conda:
        ENV
    script:
        "../scripts/electrical_identify.py"


rule electrical_evidence:
    input:
        evidence=[f"results/electrical/{s}/evidence.json" for s in ELECTRICAL["structures"]],
        samples=electrical_samples(),
    output:
        evidence=report("results/electrical/evidence.csv",
                        caption="../report/electrical_evidence.rst", category=ELECTRICAL_PAGE),
        parameters=report("results/electrical/parameters.csv",
                          caption="../report/electrical_parameters.rst",
                          category=ELECTRICAL_PAGE),
        weights="results/electrical/weights.json",
    params:
        rig=config["rig"],
        interval=ELECTRICAL.get("interval", 0.9),
    log:
        "logs/electrical/evidence.log",
    conda:
        ENV
    script:
        "../scripts/electrical_evidence.py"


rule power_excitation:
    output:
        "results/power/excitations/{excitation}.csv",
    wildcard_constraints:
        excitation=one_of(EXCITATIONS),
    params:
        power=POWER,
        fs=config["rig"]["daq"]["sampling_rate_hz"],
    log:
        "logs/power/excitation_{excitation}.log",
    conda:
        ENV
    script:
        "../scripts/power_excitation.py"


rule power_predict:
    input:
        samples=electrical_samples(),
        weights="results/electrical/weights.json",
        excitation="results/power/excitations/{excitation}.csv",
    output:
        curve=report("results/power/{excitation}/curve.csv",
                     caption="../report/electrical_power_curve.rst", category=ELECTRICAL_PAGE,
                     subcategory="{excitation}"),
        energy=report("results/power/{excitation}/energy.csv",
                      caption="../report/electrical_energy_table.rst",
                      category=ELECTRICAL_PAGE, subcategory="{excitation}"),
        design=report("results/power/{excitation}/design.json",
                      caption="../report/electrical_design.rst", category=ELECTRICAL_PAGE,
                      subcategory="{excitation}"),
        figure=report("results/power/{excitation}/power_vs_load.png",
                      caption="../report/electrical_power_vs_load.rst",
                      category=ELECTRICAL_PAGE, subcategory="{excitation}"),
        energy_figure=report("results/power/{excitation}/energy.png",
                             caption="../report/electrical_energy.rst",
                             category=ELECTRICAL_PAGE, subcategory="{excitation}"),
    wildcard_constraints:
        excitation=one_of(EXCITATIONS),
    params:
        power=POWER,
    threads: JOB_THREADS
    log:
        "logs/power/predict_{excitation}.log",
    conda:
        ENV
    script:
        "../scripts/power_predict.py"


rule power_calibration:
    input:
        samples=electrical_samples(),
        weights="results/electrical/weights.json",
        records=[f"results/data/{r}_acc.csv" for r in POWER["calibration"]["records"]],
        metas=[f"{RAW}/{r}.json" for r in POWER["calibration"]["records"]],
    output:
        windows="results/power/calibration/windows.csv",
        coverage=report("results/power/calibration/coverage.csv",
                        caption="../report/electrical_coverage.rst", category=ELECTRICAL_PAGE),
        figure=report("results/power/calibration/coverage.png",
                      caption="../report/electrical_coverage_figure.rst",
                      category=ELECTRICAL_PAGE),
    params:
        power=POWER,
        preprocess=config["preprocess"],
    threads: JOB_THREADS
    log:
        "logs/power/calibration.log",
    conda:
        ENV
    script:
        "../scripts/power_calibration.py"
