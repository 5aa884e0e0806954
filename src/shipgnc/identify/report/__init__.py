"""Moved to :mod:`shipgnc.viz.identify_report`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.viz.identify_report as _moved

warnings.warn("shipgnc.identify.report is now shipgnc.viz.identify_report", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
