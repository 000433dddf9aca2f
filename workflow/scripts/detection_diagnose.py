"""Rule diagnose_scenario: the diagnosis of one scenario's recording (JSON)."""

from harvester.data.daq import read_recording
from harvester.grid.scoring import run_diagnosis
from harvester.data.fileio import read_json, write_json
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    truth = read_json(sm.input.truth)
    recording = read_recording(sm.input.recording)
    fs = 1.0 / float(recording["time"].iloc[1] - recording["time"].iloc[0])
    result = run_diagnosis(recording, truth["baseline"], truth["known"],
                           seed=int(sm.wildcards.seed), fast=sm.params.fast,
                           lead_in=int(round(truth["settings"]["lead_in_s"] * fs)),
                           lowpass_hz=sm.params.lowpass_hz,
                           filter_order=sm.params.preprocess["filter_order"])
    result["scenario"] = {k: truth[k] for k in ("effect", "ratio", "seed", "baseline")}
    write_json(result, sm.output[0])
    log.info("%s r=%s seed %s: %s, missing %s (%.1f s)", truth["effect"], truth["ratio"],
             truth["seed"], result["verdict"], result["missing"], result["runtime_s"])
