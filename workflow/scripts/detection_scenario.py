"""Rule detection_scenario: one concealed-effect scenario (recording CSV and truth JSON)."""

from harvester.runlog import rule_log
from harvester.synthetic.scenarios import ScenarioSettings, make_scenario, write_scenario

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    settings = ScenarioSettings.from_config({"rig": sm.params.rig,
                                             "preprocess": sm.params.preprocess},
                                            **sm.params.settings)
    scenario = make_scenario(sm.wildcards.effect, float(sm.wildcards.ratio),
                             int(sm.wildcards.seed), settings, rig_cfg=sm.params.rig)
    write_scenario(scenario, sm.output.recording, sm.output.truth)
    t = scenario.truth
    log.info("contribution %.4g x noise RMS (%.4g m/s^2), peak %.3g x noise RMS, unabsorbed "
             "%.3g x noise RMS", t["contribution_ratio"], t["noise_rms"], t["peak_to_noise"],
             t.get("unabsorbed_to_noise", 0.0))
