"""The tanh model identified by TMCMC on the study's own data recovers the virtual rig's truth."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from harvester.data.daq import read_raw_record, to_accelerations
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.problems import make_problem
from harvester.inference.posterior import adjusted_draws
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


def test_tanh_model_recovers_rig_truth_within_adjusted_95_percent(tanh_posterior):
    """The truth lies within the 95 % interval adjusted for correlated residuals (eq. (10)'s
    own interval misses F_c and beta at the project's seed: over 40 draws of the mass
    channel's in-band error it held the truth 52-60 % of the time, the adjusted one 90-95 %:
    ``python benchmarks/bench_rig_session.py --realizations 40``, docs/measurements.md)."""
    problem, idata = tanh_posterior
    truth = {"c_m": CONFIG["rig"]["c_m"], "F_c": CONFIG["rig"]["friction"]["F_c"],
             "beta": CONFIG["rig"]["friction"]["beta"]}
    adjusted = adjusted_draws(idata)
    assert set(adjusted) == set(truth)
    for name, x in adjusted.items():
        low, high = np.quantile(x, [0.025, 0.975])
        assert low <= truth[name] <= high, f"{name}: truth {truth[name]}, [{low:.4g}, {high:.4g}]"
        plain = idata.posterior[name].values.reshape(-1)
        assert x.mean() == pytest.approx(plain.mean(), rel=1e-9)
        assert x.std() > 1.5 * plain.std()  # eq. (10)'s residuals are correlated over ~6


def test_sigma_is_the_residual_of_the_true_parameters(tanh_posterior):
    """sigma estimates the RMS misfit the rig's own parameters leave (noise after the filter,
    input noise, rocking leakage): nothing else is left for it to absorb."""
    problem, idata = tanh_posterior
    rig = CONFIG["rig"]
    truth = np.array([[rig["c_m"], rig["friction"]["F_c"], rig["friction"]["beta"], 1.0]])
    residual = problem.predict(truth)[0, problem.samples] - problem.observed
    rms = np.sqrt(np.mean(residual**2))
    assert idata.posterior["sigma"].values.mean() == pytest.approx(rms, rel=0.1)
