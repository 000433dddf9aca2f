"""The EMPS study: a real ball-screw drive (Janot, Gautier and Brunot 2019) identified inside
its digital position loop.

Modules: ``data`` (the .mat records, the controller), ``closed_loop`` (the model inside the
loop, the likelihood), ``idim`` (the benchmark authors' least squares), ``results`` (tables,
tracking bands, the evidence that names the missing physics), ``figures``.
"""

from harvester.emps.closed_loop import (BASELINE_TERMS, FREE_BASE, KNOWN, ClosedLoopProblem,
                                        ClosedLoopSimulation, closed_loop_fit,
                                        closed_loop_problem, correlation_time, emps_model_name,
                                        model_terms, simulate_closed_loop, temper_from)
from harvester.emps.data import (PARAMETERS, PUBLISHED, UNITS, ControllerCheck, EmpsRecord,
                                 ServoLoop, check_controller, disturbance_voltage, load_emps,
                                 to_recording)
from harvester.emps.idim import IdimFit, idim_ls
from harvester.emps.results import (CANDIDATES, TIE_NATS, VALIDATION_COLUMNS, TrackingBand,
                                    comparison_table, compare_terms, error_metrics,
                                    evidence_table, headline_table, parameters_table,
                                    summary_doc, tracking_band)

__all__ = ["BASELINE_TERMS", "CANDIDATES", "FREE_BASE", "KNOWN", "PARAMETERS", "PUBLISHED",
           "TIE_NATS", "UNITS", "VALIDATION_COLUMNS", "ClosedLoopProblem",
           "ClosedLoopSimulation", "ControllerCheck", "EmpsRecord", "IdimFit", "ServoLoop",
           "TrackingBand", "check_controller", "closed_loop_fit", "closed_loop_problem",
           "comparison_table", "compare_terms", "correlation_time", "disturbance_voltage",
           "emps_model_name", "error_metrics", "evidence_table", "headline_table", "idim_ls",
           "load_emps", "model_terms", "parameters_table", "simulate_closed_loop", "summary_doc",
           "temper_from", "to_recording", "tracking_band"]
