"""The fit on unseen data before and after (``document.unseen_fit``): the baseline and the
improved model on the validation record or the recording's held-out tail, and the judgement
of the baseline's fit against the recording's own noise floor (``detect.floor``)."""

from __future__ import annotations

from harvester.diagnosis.detect.floor import problem_floor
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.name.rounds import Round
from harvester.diagnosis.name.verdict import FitJudgement
from harvester.diagnosis.prepare.analysis import Analysis, BaselineStart
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.report.document import UnseenFit, unseen_fit


def unseen_comparison(a: Analysis, start: BaselineStart, improved: ModelFit | None,
                      settings: DiagnosisSettings
                      ) -> tuple[UnseenFit | None, UnseenFit | None, list[str]]:
    """The baseline and the improved model on unseen data: the validation record, or the
    recording's held-out tail (none when too short)."""
    if a.validation is not None:
        v = a.validation
        lead = int(round(settings.lead_in_s / a.dt))
        u, y, t = v.iloc[:, 1].to_numpy(), v.iloc[:, 2].to_numpy(), v["time"].to_numpy()
        section, data = (lead, len(v) - int(round(0.5 * a.fs))), "validation"
    elif a.hold < a.end - 8:
        rec = a.recording
        u, y, t = rec.iloc[:, 1].to_numpy(), rec.iloc[:, 2].to_numpy(), a.time
        section, data = (a.hold, a.end), "holdout"
    else:
        return None, None, []
    n, seed = settings.predictive_samples, settings.seed
    try:
        before = unseen_fit(start.detection_problem, start.samples, u, y, t, section, data, n,
                            seed)
        after = before if improved is None else unseen_fit(
            improved.problem, improved.samples, u, y, t, section, data, n, seed)
    except RuntimeError as err:
        return None, None, [f"unseen-data comparison failed: {err}"]
    return before, after, []


def fit_judgement(start: BaselineStart, first: Round, before: UnseenFit | None,
                  after: UnseenFit | None) -> FitJudgement:
    """The baseline's share of the unseen output explained (1 - NRMSE^2), the improved
    model's, and the baseline's residual over the analysed window against the recording's own
    noise floor in the likelihood's band (``floor.output_floor``)."""
    p = start.detection_problem
    found = problem_floor(p)
    share = None if before is None else 1.0 - before.nrmse ** 2
    improved = None if after is None else 1.0 - after.nrmse ** 2
    return FitJudgement(share, None if before is None else before.nrmse,
                        None if before is None else before.data, first.detection.sigma, found,
                        improved)
