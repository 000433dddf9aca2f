"""Rule emps_data: check the EMPS files, verify the controller law, IDIM-LS; data figure."""

from harvester import emps
from harvester.emps.figures import data_figure
from harvester.data.fileio import write_json
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    records = {role: emps.load_emps(sm.input[role], sm.params.sha256.get(role))
               for role in ("training", "validation")}
    out = {}
    for role, rec in records.items():
        check = emps.check_controller(rec)
        idim = emps.idim_ls(rec)
        out[role] = {
            "file": rec.name, "samples": len(rec), "dt_s": rec.dt,
            "gtau_N_per_V": rec.loop.gtau, "kp_per_s": rec.loop.kp, "kv_V_s_per_m": rec.loop.kv,
            "controller": check.to_dict(),
            "rms_tracking_error_um": float(1e6 * ((rec.qm - rec.qg) ** 2).mean() ** 0.5),
            "idim_ls": {"values": idim.values, "se": idim.se, "rel_error_pct": idim.rel_error},
        }
        log.info("%s: controller law residual %.3g %% of RMS vir (one-step velocity: %.3g %%), "
                 "gain factors %s, pulse gain %.4g V; IDIM-LS %s", rec.name,
                 100 * check.rel_residual, 100 * check.rel_residual_one_step, check.gains_scale,
                 check.pulse_gain, idim.values)
    out["closed_loop_natural_frequency_hz"] = records["training"].loop.natural_frequency_hz
    write_json(out, sm.output.summary)
    data_figure({"identification": records["training"], "validation (unseen)":
                 records["validation"]}, sm.output.figure)
