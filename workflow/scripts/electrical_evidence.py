"""Rule electrical_evidence: evidence per electrical structure, the BMA weights, and the
identified constants beside the rig's truth (harvester.electrical, harvester.power)."""

import pandas as pd
from harvester.data.fileio import atomic_path, read_json, write_json
from harvester.electrical.identify import evidence_table, model_weights
from harvester.power.calibration import truth_table
from harvester.runlog import rule_log
from harvester.synthetic.electrical import electrical_truth

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    summaries = [read_json(p) for p in sm.input.evidence]
    table = evidence_table(summaries)
    weights = model_weights({s["structure"]: s["log_evidence"] for s in summaries})
    write_json({"weights": weights, "device": summaries[0]["device"]}, sm.output.weights)
    with atomic_path(sm.output.evidence) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", table.to_string(index=False))
    rig, truth = sm.params.rig, electrical_truth(sm.params.rig)
    values = {"c_m": rig["c_m"], "F_c": rig["friction"]["F_c"], "beta": rig["friction"]["beta"],
              "K_e": truth["K_e"], "R_s": truth["R_s"], "L_s": truth["L_s"]}
    posteriors = {s["structure"]: pd.read_csv(p) for s, p in zip(summaries, sm.input.samples)}
    params = truth_table(posteriors, values, float(sm.params.interval))
    with atomic_path(sm.output.parameters) as tmp:
        params.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", params.to_string(index=False))
