"""Rule damping_fit: initial c_m by equivalent linearisation of Coulomb friction, FRF fit."""

from harvester.data.daq import read_recording
from harvester.plots.data import fig_damping_fit
from harvester.data.fileio import read_json, write_json
from harvester.initial.damping import fit_viscous_damping
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rig, start = sm.params.rig, sm.params.lead_in
    rec = read_recording(sm.input.data).iloc[: start + sm.params.samples]
    F_c = read_json(sm.input.static)["F_c"]
    fit = fit_viscous_damping(rec, rig["M"], rig["m"], rig["k"], F_c, tuple(sm.params.band),
                              lead_in=start, source=sm.input.data)
    write_json({"c_m": fit.c_m, "c_eq": fit.c_eq, "sigma_v": fit.sigma_v, "F_c": fit.F_c,
                "residual": fit.residual, "band_hz": fit.band_hz}, sm.output.fit)
    fig_damping_fit(fit, sm.output.figure)
    log.info("c_m = %.1f N s/m (c_eq = %.1f, sigma_v = %.4f m/s)", fit.c_m, fit.c_eq, fit.sigma_v)
