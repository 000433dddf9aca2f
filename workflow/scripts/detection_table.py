"""Rule detection_table: detection table, confusion matrix and false-alarm rate."""

from harvester.grid.scoring import (confusion_matrix, detection_table, false_alarms, goal_summary,
                                 results_table)
from harvester.data.fileio import atomic_path, read_json
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    goal = sm.params.goal
    pairs = [(read_json(t), read_json(d)) for t, d in zip(sm.input.truths, sm.input.diagnoses)]
    results = results_table(pairs, sm.params.accepted)
    table = detection_table(results, goal["ratio"], goal["named_rate"])
    alarms = false_alarms(results, goal["false_alarm_rate"])
    summary = goal_summary(results, goal["named_rate"])
    for frame, path in ((results, sm.output.results), (table, sm.output.table),
                        (summary, sm.output.summary),
                        (confusion_matrix(results), sm.output.confusion),
                        (alarms, sm.output.alarms)):
        with atomic_path(path) as tmp:
            frame.to_csv(tmp, index=False, float_format="%.4g")
    log.info("%d scenarios; named correctly at ratio %g:\n%s", len(results), goal["ratio"],
             table[table["ratio"] == goal["ratio"]].to_string(index=False))
    log.info("all effects pooled (nameable: information >= log(1/alpha)):\n%s",
             summary.to_string(index=False))
    log.info("false alarms:\n%s", alarms.to_string(index=False))
