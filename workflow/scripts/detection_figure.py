"""Rule detection_figure: rate named correctly against the contribution-to-noise ratio, and
each scenario's outcome against its information."""

import pandas as pd

from harvester.grid.scoring import detection_figure
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    goal = sm.params.goal
    detection_figure(pd.read_csv(sm.input.table), pd.read_csv(sm.input.alarms), sm.output[0],
                     goal["ratio"], goal["named_rate"], goal["false_alarm_rate"],
                     results=pd.read_csv(sm.input.results))
    log.info("wrote %s", sm.output[0])
