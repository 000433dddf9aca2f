"""Rule power_predict: power vs load with its band, energy over the record, the optimal loads
and the gain of halving the friction, on one excitation (harvester.power)."""

from dataclasses import replace
from pathlib import Path

from harvester.power.excitations import describe, read_excitation
from harvester.power.run import load_posteriors, power_study, write_power_study
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    name, cfg = sm.wildcards.excitation, sm.params.power
    exc = replace(read_excitation(sm.input.excitation, name),
                  description=describe(name, cfg["excitations"][name]))
    study = power_study(*load_posteriors(sm.input.samples, sm.input.weights), exc, cfg)
    written = write_power_study(study, Path(sm.output.curve).parent, cfg)
    log.info("%s: wrote %s; %s", name, ", ".join(written), study["design"])
