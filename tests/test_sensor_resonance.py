"""A resonance of the output's sensor is not a mode of the device (name.sensor): on a linear
device read through a mass accelerometer resonating at 8 Hz (the literature generator's
``accelerometer``, a time-domain filter written apart from the test's frequency-domain one),
the sensor's reading is found and beats the best-fitting mode in the device; on a device
with a real second mass at 8 Hz, the mode beats every sensor reading."""

from types import SimpleNamespace

import numpy as np
import pytest

from harvester.data.signals import lowpass
from harvester.diagnosis.name.results import CandidateResult, ConfirmSettings
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.name.sensor import (fit_sensor, hold_against_sensor,
                                             read_resonance, sensor_response)
from harvester.inference.likelihood import DAQ_OVERSAMPLE
from harvester.inference.map_fit import ChainProblem, baseline_state, fit_map
from harvester.model.structures import structure
from harvester.synthetic.literature import accelerometer
from harvester.synthetic.measured import TABLE1_KNOWN

from latent_records import C_M, FS, LOWPASS_HZ, rk4_record

TEMPER = 0.15  # about 2 x 16 Hz / 256 Hz independent samples per sample (map_fit docstring)


@pytest.fixture(scope="module")
def device():
    truth = rk4_record(lambda z, v, t: 0.0, seconds=8.0)
    return truth, 0.02 * np.random.default_rng(1).standard_normal(truth["y"].size)


def chain(truth, terms: str, output: np.ndarray) -> ChainProblem:
    n = output.size
    return ChainProblem(structure(terms), lowpass(truth["y"], FS, LOWPASS_HZ, 8), output,
                        1.0 / FS, dict(TABLE1_KNOWN), (int(FS), n - int(FS / 2)),
                        temper=TEMPER, lowpass_hz=LOWPASS_HZ, oversample=DAQ_OVERSAMPLE)


def mode_result(truth, output) -> CandidateResult:
    problem = chain(truth, "linear+unmodelled_mode", output)
    mp = fit_map(problem, {}, seed=0)
    fit = ModelFit(problem.structure, problem, mp.samples(20, 0), np.zeros(2))
    return CandidateResult("unmodelled_mode", fit, 100.0, 0.5, 6.0, True)


def test_sensor_response_is_second_order():
    h = sensor_response(np.array([0.0, 8.0, 80.0]), 8.0, 0.1)
    assert h[0] == 1.0 and abs(h[1]) == pytest.approx(5.0) and abs(h[2]) < 0.011


def test_sensor_resonance_is_the_sensors(device):
    truth, noise = device
    read = accelerometer(truth["a"] + truth["y"], FS, 8.0, 0.1) - truth["y"]
    output = lowpass(read + noise, FS, LOWPASS_HZ, 8)
    state = baseline_state(chain(truth, "linear", output), np.array([[C_M, 0.05]]))
    f_s, zeta, sensor, gain = fit_sensor(state, LOWPASS_HZ)
    assert f_s == pytest.approx(8.0, rel=0.01) and zeta == pytest.approx(0.1, rel=0.05)
    assert sensor.startswith("the mass accelerometer")
    mode = mode_result(truth, output)
    reading = read_resonance(state, "unmodelled_mode", mode.fit.problem,
                             mode.fit.samples.mean(axis=0), LOWPASS_HZ, ConfirmSettings())
    assert reading.conclusion == "sensor", reading.sentence()
    assert reading.sensor_gain > reading.device_gain + reading.margin
    other = CandidateResult("hysteresis", mode.fit, 50.0, 0.5, 6.0, True)
    rnd = SimpleNamespace(confirmed=[mode, other], state=state, screen=None,
                          detection=SimpleNamespace(significant=True))
    held, notes = hold_against_sensor(rnd, lambda s: mode.fit.problem, LOWPASS_HZ,
                                      ConfirmSettings())
    assert held.conclusion == "sensor" and not mode.accepted and other.accepted
    assert "not a mode of the device" in notes[0]
    # another accepted effect (its fit here the mode's) is held against the sensor the same way
    other.accepted = True
    rnd.confirmed = [other]
    held, notes = hold_against_sensor(rnd, lambda s: mode.fit.problem, LOWPASS_HZ,
                                      ConfirmSettings())
    assert held.conclusion == "sensor" and not other.accepted
    assert "not hysteresis" in notes[0] and "hysteresis not named" in notes[0]
    # nothing accepted: the round's best fit (a mode here) is what the sensor is held against
    mode.accepted = other.accepted = False
    best = SimpleNamespace(effect="hysteresis", failed=False, max_loglike=1.0,
                           theta=mode.fit.samples.mean(axis=0))
    rnd.screen = SimpleNamespace(candidates=[best])
    held, notes = hold_against_sensor(rnd, lambda s: mode.fit.problem, LOWPASS_HZ,
                                      ConfirmSettings())
    assert held.conclusion == "sensor" and "the mismatch is the output sensor's" in notes[0]


def test_device_mode_is_the_devices(device):
    truth, noise = device
    clean = chain(truth, "linear+unmodelled_mode", truth["a"]).simulate(
        np.array([C_M, 8.0, 0.05, 1.0, 1.0, 0.02])).rel_acc[0]
    output = lowpass(clean + noise, FS, LOWPASS_HZ, 8)
    state = baseline_state(chain(truth, "linear", output), np.array([[C_M, 0.05]]))
    mode = mode_result(truth, output)
    reading = read_resonance(state, "unmodelled_mode", mode.fit.problem,
                             mode.fit.samples.mean(axis=0), LOWPASS_HZ, ConfirmSettings())
    assert reading.conclusion == "device", reading.sentence()
    rnd = SimpleNamespace(confirmed=[mode], state=state, screen=None,
                          detection=SimpleNamespace(significant=True))
    held, notes = hold_against_sensor(rnd, lambda s: mode.fit.problem, LOWPASS_HZ,
                                      ConfirmSettings())
    assert held.conclusion == "device" and mode.accepted
    assert notes[0].startswith("the resonance is the device's")


def test_generator_reads_the_mass_through_its_accelerometer():
    """The literature generator's sensor option changes the output channel alone."""
    from harvester.synthetic.literature import generate
    plain = generate("none", 1, duration_s=8.0)
    read = generate("none", 1, duration_s=8.0, sensor_resonance=(45.0, 0.05))
    assert np.array_equal(plain.recording["base_acc"], read.recording["base_acc"])
    change = read.recording["rel_acc"] - plain.recording["rel_acc"]
    assert read.truth["sensor_resonance"]["change_to_noise"] == pytest.approx(
        np.std(change[int(read.truth["lead_in_s"] * 256):]) / read.truth["noise_rms_rel_acc"],
        rel=0.05)
    assert read.truth["sensor_resonance"]["change_to_noise"] > 0.1


def test_a_reading_without_a_resonance_rules_the_sensor_out(device, monkeypatch):
    """A best sensor reading whose damping lies on the span's top is no resonance: the
    device's effect keeps its name whatever the gains (LuGre's record, measurements.md)."""
    import harvester.diagnosis.name.sensor as sensor
    truth, noise = device
    output = lowpass(truth["a"] + noise, FS, LOWPASS_HZ, 8)
    state = baseline_state(chain(truth, "linear", output), np.array([[C_M, 0.05]]))
    monkeypatch.setattr(sensor, "fit_sensor", lambda st, f: (15.0, 0.25, "the output's sensor",
                                                             60.0))
    monkeypatch.setattr(sensor, "device_gain", lambda st, p, th: 40.0)
    reading = sensor.read_resonance(state, "hysteresis", None, None, LOWPASS_HZ,
                                    ConfirmSettings())
    assert reading.conclusion == "device" and "no resonance" in reading.sentence()
    monkeypatch.setattr(sensor, "fit_sensor", lambda st, f: (15.0, 0.05, "the output's sensor",
                                                             60.0))
    assert sensor.read_resonance(state, "hysteresis", None, None, LOWPASS_HZ,
                                 ConfirmSettings()).conclusion == "sensor"
    # the round's best fit (nothing accepted) that beats the sensor rules it out, in words too
    monkeypatch.setattr(sensor, "device_gain", lambda st, p, th: 600.0)
    best = sensor.read_resonance(state, "inertia_error", None, None, LOWPASS_HZ,
                                 ConfirmSettings(), accepted=False)
    assert best.conclusion == "device"
    assert best.sentence().startswith("the mismatch is not the output sensor's")


def test_a_mode_above_the_likelihoods_band_is_not_named():
    """confirm.judge: a mode with the evidence to be accepted whose frequency lies above the
    band the likelihood compares (the base_disp -> rel_acc records' 83-109 Hz above 81.9 Hz)
    is not named, said so, and leaves the round's top to the next; one inside it is named."""
    from types import SimpleNamespace

    from harvester.diagnosis.name.confirm import judge

    from harvester.diagnosis.name.results import ConfirmSettings

    from harvester.diagnosis.name.skips import skip_reason
    from harvester.inference.priors import PriorSpec
    from harvester.model.structures import structure as named_structure
    s = named_structure("tanh+unmodelled_mode")
    names = list(s.free_parameters) + ["sigma"]
    priors = {n: PriorSpec(n, 0.0, 1e3, "-", lower=-np.inf) for n in s.free_parameters}

    def fit(log_evidence, f_mode):
        rows = np.full((200, len(names)), 0.5)
        rows[:, names.index("f_mode")] = np.random.default_rng(1).normal(f_mode, 1.5, 200)
        return SimpleNamespace(log_evidence=log_evidence, log_evidence_se=0.05, names=names,
                               priors=priors, samples=rows, structure=s,
                               problem=SimpleNamespace(known={"M": 1.0, "m": 1.0},
                                                       band_hz=81.92))

    base, cs = fit(0.0, 10.0), ConfirmSettings()
    above = judge("unmodelled_mode", fit(60.0, 85.4), base, cs)
    assert not above.accepted and set(above.beyond_band) == {"f_mode"}
    assert above.at_limit == {"f_mode": "upper"} and above.unshown
    assert "above the 81.9 Hz band the likelihood compares" in above.unresolved_sentence()
    inside = judge("unmodelled_mode", fit(60.0, 18.2), base, cs)
    assert inside.accepted and not inside.beyond_band
    screened = SimpleNamespace(failed=False, pulled={}, bound=47.0, beyond_band={},
                               importance_ceiling=lambda sigmas: None)
    assert skip_reason(screened, [above], cs, 1) is None  # not counted in the round's top


def test_a_mode_whose_best_fit_lies_above_the_band_is_not_sampled():
    """skips.skip_reason: a screened mode whose MAP puts f_mode above the likelihood's band
    would not be named, so its TMCMC is not spent (the Bouc-Wen records' 104-218 Hz); the same
    fit with f_mode inside the band is sampled."""
    from types import SimpleNamespace

    from harvester.diagnosis.name.results import ConfirmSettings

    from harvester.diagnosis.name.skips import skip_reason
    from harvester.diagnosis.name.screen import Screened
    names = ("k", "f_mode", "zeta_mode", "mass_mode", "drive_base", "sigma")

    def screened(f_mode):
        theta = np.array([1.0, f_mode, 0.02, 0.3, 0.0, 0.1])
        return Screened("unmodelled_mode", names, theta, 0.0, 200.0, 230.0, False, 0, 0.0,
                        problem=SimpleNamespace(band_hz=81.92))

    cs = ConfirmSettings()
    above = screened(103.9)
    assert above.beyond_band == {"f_mode": (103.9, 81.92)}
    assert "f_mode at 103.9 Hz, above the 81.9 Hz band" in skip_reason(above, [], cs, 3)
    assert above.to_dict()["map_beyond_band_hz"]["f_mode"]["map"] == 103.9
    inside = screened(41.8)
    assert not inside.beyond_band and skip_reason(inside, [], cs, 3) is None
