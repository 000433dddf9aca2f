"""Rule detection_scenario: one concealed-effect scenario (recording CSV and truth JSON)."""

from harvester.grid.generators import make_scenario_files
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    t = make_scenario_files(sm.params.generator, sm.wildcards.effect, float(sm.wildcards.ratio),
                            int(sm.wildcards.seed), sm.params.settings, sm.params.rig,
                            sm.params.preprocess, sm.output.recording, sm.output.truth)
    log.info("%s generator: contribution %.4g x noise RMS, peak %.3g x noise RMS, unabsorbed "
             "%.3g x noise RMS", sm.params.generator, t["contribution_ratio"],
             t["peak_to_noise"], t.get("unabsorbed_to_noise", 0.0))
