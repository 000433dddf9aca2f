"""Rule table1: Table 1 (initial estimates), Tables 2 and 4 (priors) and the priors file."""

from dataclasses import asdict
from types import SimpleNamespace

from harvester.data.fileio import atomic_path, read_json, write_json
from harvester.initial.static_friction import StaticFrictionEstimate
from harvester.inference.priors import prior_moments
from harvester.study.tables import prior_table
from harvester.runlog import rule_log
from harvester.model.structures import structure
from harvester.study.tables import render_table, table1, table1_notes, table1_values

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    static = StaticFrictionEstimate(**read_json(sm.input.static))
    damping = SimpleNamespace(**read_json(sm.input.damping))
    t1 = table1(static, damping, sm.params.rig)
    ours = table1_values(t1)
    specs = prior_moments(sm.params.priors, ours)
    outputs = {sm.output.table1: t1}
    for model, out in (("linear", sm.output.table2), ("tanh", sm.output.table4)):
        names = list(structure(model).free_parameters) + ["sigma"]
        outputs[out] = prior_table(names, specs)
    for path, df in outputs.items():
        with atomic_path(path) as tmp:
            df.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.table1_md) as tmp:
        tmp.write_text(render_table(t1, "Table 1. Initial parameter estimates",
                                    table1_notes(static, damping, sm.params.rig)))
    write_json({"known": {k: ours[k] for k in ("M", "m", "k")},
                "priors": {n: asdict(s) for n, s in specs.items()}}, sm.output.priors)
    log.info("\n%s", t1.to_string(index=False))
