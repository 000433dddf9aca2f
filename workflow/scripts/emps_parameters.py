"""Rule emps_parameters: identified M, Fv, Fc, offset beside the published values; figure."""

from harvester import emps
from harvester.emps.figures import posterior_figure
from harvester.data.fileio import atomic_path, read_json
from harvester.runlog import rule_log
from harvester.inference.posterior import read_posterior

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    idata = read_posterior(sm.input.posterior)
    table = emps.parameters_table(idata)
    idim = read_json(sm.input.data)["training"]["idim_ls"]["values"]
    comparison = emps.comparison_table(table, idim)
    for df, out in ((table, sm.output.parameters), (comparison, sm.output.comparison)):
        with atomic_path(out) as tmp:
            df.to_csv(tmp, index=False, float_format="%.6g")
    samples = {row.parameter: idata.posterior[emps.PARAMETERS[row.parameter]].values.reshape(-1)
               for row in table.itertuples()}
    posterior_figure(samples, emps.PUBLISHED, idim, sm.output.figure,
                     f"Posterior of {idata.posterior.attrs['model']}")
    log.info("\n%s", comparison.to_string(index=False))
