"""Load-case sets: a scene template over a wave scatter diagram, with spectral fatigue
damage and long-term extremes (the design checks of :mod:`stochcable.design`)::

    scatter = read_scatter("scatter.csv")               # sea states and probabilities
    result = run_cases(scene, scatter, fatigue=LineFatigue("dnv-studless",
                                                            nominal_diameter=0.076))
    case_dataset(result).to_netcdf("cases.nc")

A set can also be planned first (:func:`plan_cases`: validated, its chunks fixed), its
chunks solved anywhere and stored (:func:`stochcable.cases.plan.chunk_to_bytes`), and
the results assembled from them in any order (:func:`assemble_cases`) — how the
service's batch jobs survive a restart.
"""

from stochcable.cases.fatigue_settings import LineFatigue
from stochcable.cases.plan import CasePlan, plan_cases
from stochcable.cases.results import case_dataset, case_document, case_summary_csv
from stochcable.cases.run import CaseRow, CaseSetResult, LineTotals, assemble_cases, run_cases
from stochcable.cases.scatter import (
    ScatterDiagram,
    SeaState,
    jonswap_gamma_dnv,
    read_scatter,
    scatter_from_matrix,
    scatter_from_rows,
    tz_over_tp,
)

__all__ = [
    "LineFatigue",
    "CaseRow",
    "CaseSetResult",
    "LineTotals",
    "run_cases",
    "CasePlan",
    "plan_cases",
    "assemble_cases",
    "case_dataset",
    "case_document",
    "case_summary_csv",
    "ScatterDiagram",
    "SeaState",
    "jonswap_gamma_dnv",
    "read_scatter",
    "scatter_from_matrix",
    "scatter_from_rows",
    "tz_over_tp",
]
