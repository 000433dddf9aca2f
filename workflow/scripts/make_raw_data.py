"""Regenerate the SIMULATED raw recordings from the virtual rig, with SHA256SUMS.

Snakemake: rule ``regenerate_raw_data``. Command line:
``python workflow/scripts/make_raw_data.py config/config.yaml data/raw``.
"""

# No `from __future__ import annotations`: Snakemake prepends its preamble to this file.
import sys

import yaml

from harvester.study.dataset import make_raw_data
from harvester.runlog import rule_log, setup

if __name__ == "__main__":
    if "snakemake" in globals():
        with rule_log(snakemake):  # noqa: F821
            make_raw_data(snakemake.config, snakemake.output[0])  # noqa: F821
    elif len(sys.argv) != 3:
        sys.exit("usage: make_raw_data.py CONFIG.yaml OUT_DIR")
    else:
        setup()
        with open(sys.argv[1], encoding="utf-8") as fh:
            make_raw_data(yaml.safe_load(fh), sys.argv[2])
