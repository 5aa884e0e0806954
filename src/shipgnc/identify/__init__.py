"""System identification from a logged run (``shipgnc identify``; docs: the module docstrings).

    from shipgnc.identify import read_log, identify_log
    log = read_log("runs/x/result.nc", required=("time", "rudder"), need_one_of=("yaw_rate", "heading"))
    ident = identify_log(log, "nomoto1")
    ident.parameters["K"].ci95, ident.nrmse_holdout, ident.vessel

:mod:`shipgnc.identify.logs` reads and checks CSV/NetCDF logs, :mod:`shipgnc.identify.fitting`
fits Nomoto 1/2 (through :mod:`shipgnc.analysis.identification`) and the linear 3-DOF model with
95 % confidence intervals and a held-out score, :mod:`shipgnc.viz.identify_report` draws the figure and
writes the vessel YAML.
"""

from shipgnc.identify.fitting import (
    MODELS,
    Identification,
    Parameter,
    identify_linear3dof,
    identify_log,
    identify_nomoto1,
    identify_nomoto2,
)
from shipgnc.identify.logs import DEFAULT_COLUMNS, ROLES, Log, parse_columns, read_log

__all__ = ["DEFAULT_COLUMNS", "MODELS", "ROLES", "Identification", "Log", "Parameter",
           "identify_linear3dof", "identify_log", "identify_nomoto1", "identify_nomoto2",
           "parse_columns", "read_log"]
