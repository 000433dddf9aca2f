"""The tanh model identified by TMCMC on the study's own data recovers the virtual rig's truth."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from harvester.data.daq import read_raw_record, to_accelerations
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.problems import make_problem
from harvester.inference.posterior import posterior_theta
from harvester.inference.priors import prior_moments
from harvester.data.signals import filter_recording

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config/config.yaml").read_text())


@pytest.fixture(scope="module")
def tanh_posterior():
    raw, meta = read_raw_record(ROOT / "data/raw/training.csv", ROOT / "data/raw/training.json")
    pre = CONFIG["preprocess"]
    rec = filter_recording(to_accelerations(raw, meta), pre["lowpass_hz"], pre["filter_order"])
    rig = CONFIG["rig"]
    start = pre["training_lead_in"]
    problem = make_problem(rec, "tanh", {"M": rig["M"], "m": rig["m"], "k": rig["k"]},
                           window=(start, start + pre["training_samples"]),
                           output_filter=(pre["lowpass_hz"], pre["filter_order"]))
    # the paper's Table 1 means (our own initial estimates come from rules tested elsewhere)
    priors = prior_moments(CONFIG["priors"], {"c_m": 170.0, "F_c": 8.4})
    settings = TMCMCSettings(particles=300, chains=2, seed=5, mcmc_steps=3, target_accept=0.25)
    return problem, identify(problem, priors, settings)


#: How far the posterior sds of eq. (10) (2000 independent residuals) fall short of the
#: estimates' scatter on the paper's session: the RMS of (estimate - truth) / sd over 10 draws
#: of the mass channel's in-band error was 3.39, 3.16, 3.41 for c_m, F_c, beta
#: (``python benchmarks/bench_rig_session.py --realizations 10``, docs/measurements.md): the
#: 20 Hz low-pass correlates the residuals over about 6 samples.
OVERCONFIDENCE = 3.5


def test_tanh_model_recovers_rig_truth_within_widened_95_percent(tanh_posterior):
    """The truth lies within the 95 % interval widened by the measured overconfidence of the
    independent-residual likelihood (at the project's seed the plain interval misses F_c and
    beta: docs/measurements.md, the virtual rig calibrated to the paper)."""
    problem, idata = tanh_posterior
    theta = posterior_theta(idata)
    truth = {"c_m": CONFIG["rig"]["c_m"], "F_c": CONFIG["rig"]["friction"]["F_c"],
             "beta": CONFIG["rig"]["friction"]["beta"]}
    for i, name in enumerate(problem.parameter_names[:-1]):
        mean, sd = theta[:, i].mean(), theta[:, i].std()
        assert abs(mean - truth[name]) <= OVERCONFIDENCE * 1.96 * sd, \
            f"{name}: truth {truth[name]}, posterior {mean:.4g} (sd {sd:.3g})"


def test_sigma_is_the_residual_of_the_true_parameters(tanh_posterior):
    """sigma estimates the RMS misfit the rig's own parameters leave (noise after the filter,
    input noise, rocking leakage): nothing else is left for it to absorb."""
    problem, idata = tanh_posterior
    rig = CONFIG["rig"]
    truth = np.array([[rig["c_m"], rig["friction"]["F_c"], rig["friction"]["beta"], 1.0]])
    residual = problem.predict(truth)[0, problem.samples] - problem.observed
    rms = np.sqrt(np.mean(residual**2))
    assert idata.posterior["sigma"].values.mean() == pytest.approx(rms, rel=0.1)
