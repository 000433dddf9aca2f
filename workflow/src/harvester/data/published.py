"""Published results the project sets its own beside, each read in its source (issue 64).

The Silverbox benchmark (``data.public.SILVERBOX_TESTS``): free-run RMS errors in mV on its
three tests (``multisine``, ``arrow_full``, ``arrow_no_extrapolation``), the strongest found
per method family, with where each figure stands (repository, commit and file, or the
reference and its table), whether its test and metric are ours, and what it is (a tutorial
model is said to be one). :data:`SILVERBOX_NOT_SHOWN` holds figures that were found quoted
but could not be read in their source here, or that come from an unfinished run: they are
named with the reason and never tabulated.

How the sources were read (docs/peers.md, "Published Silverbox results"): each notebook's
printed output and each JSON file's ``rmse`` fields at the commit given; the benchmark site's
table from a screenshot of it; PNLSS's and the BLA's from Table I of Cruz et al. (2025), a
stored text of the accepted manuscript, which tabulates them from their own papers.
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: The kinds of model a row holds.
BLACK_BOX = "black-box"
GREY_BOX = "grey-box"


@dataclass(frozen=True)
class Published:
    """One published result: ``errors`` per test (mV; only the tests the source gives)."""

    method: str
    kind: str
    errors: dict[str, float]
    source: str
    same_test: str
    notes: str = ""


_SUBNET_NB = ("github.com/GerbenBeintema/SS-encoder-WH-Silver 6b531a1 (the authors' trained "
              "models), 'SS encoder Silverbox.ipynb', cell 'Main Results Silverbox'")
_SUBNET_TEST = ("the arrow as ours (samples 100-40575 of SNLS80mV.mat; without extrapolation "
                "its first 32000); RMS over the whole test, the state from its encoder "
                "(ours skips the first 50 samples)")
_NLB = ("Champneys, Beintema, Toth, Schoukens, Rogers, Baseline results for selected "
        "nonlinear system identification benchmarks (2024, arXiv 2405.10779); "
        "github.com/MDCHAMP/nonlinear_baselines 73d8445, data_NN/SB_{}_NN.json, "
        "test_1/test_2/test_3 'rmse' (V, x 1000)")
_NLB_TEST = ("the benchmark loader's three tests, as ours; simulated from the input alone "
             "(the network sees input lags only), scored after its first {} samples "
             "(ours: 50)")


_CRUZ = ("Cruz, Renczes, Runacres, Decuyper, State-Space Kolmogorov Arnold Networks for "
         "Interpretable Nonlinear System Identification, IEEE Control Systems Letters 2025, "
         "doi:10.1109/LCSYS.2025.3578019, Table I, 'RMSE [V]' {} (their ref. {})")
_CRUZ_TEST = ("their test set: 40000 samples of filtered Gaussian noise of growing amplitude, "
              "extrapolation included (the arrow in full); its cut and any samples skipped "
              "are not stated")


def _baseline(name: str, skipped: int, errors: tuple[float, float, float]) -> Published:
    """A recurrent-network baseline of Champneys et al. (cross-validated size and lags;
    ``skipped``: the test's first samples its lags take, not scored)."""
    return Published(f"{name} (baseline, Champneys et al. 2024)", BLACK_BOX,
                     dict(zip(("multisine", "arrow_full", "arrow_no_extrapolation"), errors)),
                     _NLB.format(name), _NLB_TEST.format(skipped),
                     "a baseline set up to be beaten, not a tuned model")


#: The published rows, strongest first within each family.
SILVERBOX_PUBLISHED: tuple[Published, ...] = (
    Published("PNLSS, polynomial nonlinear state space (Paduart et al., Automatica 2010), as "
              "tabulated by Cruz et al. 2025", BLACK_BOX, {"arrow_full": 0.3},
              _CRUZ.format("0.0003", "[18], Paduart et al. 2010"), _CRUZ_TEST,
              "one significant figure (0.0003 V: 0.25-0.35 mV); Paduart et al.'s own table "
              "was not read here"),
    Published("SUBNET / SS encoder, as the benchmark site lists it", BLACK_BOX,
              {"multisine": 0.36, "arrow_full": 1.4, "arrow_no_extrapolation": 0.32},
              "nonlinearbenchmark.org results table (Silverbox tab), as captured in "
              "github.com/wilsonrljr/sysidentpy-data 7271536, book/assets/silver_sota.png",
              "the benchmark's three tests", "the screenshot cuts the cell after '0.32'; "
              "its column says RMSE without a unit (mV, as the notebook below)"),
    Published("SUBNET / SS encoder nx = 4 (Beintema, Toth, Schoukens, L4DC 2021)", BLACK_BOX,
              {"arrow_full": 1.406, "arrow_no_extrapolation": 0.316}, _SUBNET_NB, _SUBNET_TEST,
              "deep state-space model, trained for up to 4000 epochs"),
    Published("SUBNET / SS encoder nx = 8 (same notebook)", BLACK_BOX,
              {"arrow_full": 2.001, "arrow_no_extrapolation": 0.307}, _SUBNET_NB, _SUBNET_TEST,
              "deep state-space model; its multisine error is not printed"),
    _baseline("OLSTM", 1, (1.515, 2.385, 1.075)),
    _baseline("LSTM", 1, (1.504, 2.678, 0.960)),
    _baseline("GRU", 1, (1.490, 2.802, 0.947)),
    _baseline("RNN", 31, (1.640, 4.875, 1.732)),
    Published("best linear approximation (BLA), as tabulated by Cruz et al. 2025", BLACK_BOX,
              {"arrow_full": 13.5}, _CRUZ.format("0.0135", "[16], Marconato et al., IFAC "
                                                 "2012"), _CRUZ_TEST,
              "a linear model (this study's linear model: 13.8 mV there)"),
    Published("polynomial NARX by FROLS (SysIdentPy tutorial)", BLACK_BOX,
              {"multisine": 7.727, "arrow_full": 4.148, "arrow_no_extrapolation": 2.229},
              "github.com/wilsonrljr/sysidentpy 76b75e4, docs/en/user-guide/tutorials/"
              "silver-box-system.md, results table",
              "the benchmark's three tests after the loader's 50-sample window, as ours",
              "a TUTORIAL model: its text calls the configuration a possibly suboptimal "
              "starting point and declines to rank it against external results"),
)


@dataclass(frozen=True)
class NotShown:
    """A figure found quoted but not tabulated, and why."""

    method: str
    reference: str
    reason: str = field(default="")


#: Quoted figures left out of the table (module docstring).
SILVERBOX_NOT_SHOWN: tuple[NotShown, ...] = (
    NotShown("SUBNET nx = 8 re-run: 5.787 / 2.038 mV (arrow full / without extrapolation)",
             "github.com/GerbenBeintema/SS-encoder-WH-Silver 808f589, same notebook",
             "an unfinished run: its training log shows 'Stopping early due to a "
             "KeyboardInterrupt' after 4 of 4000 epochs"),
)
