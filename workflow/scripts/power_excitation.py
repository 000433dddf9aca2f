"""Rule power_excitation: a shipped base-acceleration record the device never saw
(harvester.power.excitations), seeded from config power."""

from harvester.data.fileio import atomic_path
from harvester.power.excitations import make_excitation
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    name = sm.wildcards.excitation
    spec = sm.params.power["excitations"][name]
    exc = make_excitation(name, spec, float(sm.params.fs),
                          int(sm.params.power["seed"]) + int(spec["seed_offset"]))
    with atomic_path(sm.output[0]) as tmp:
        exc.frame().to_csv(tmp, index=False, float_format="%.8g")
    log.info("%s: %s, %.0f s, RMS %.3f m/s^2", name, exc.description, exc.duration_s,
             float((exc.base_acc ** 2).mean() ** 0.5))
