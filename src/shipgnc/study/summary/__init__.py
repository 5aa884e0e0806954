"""Moved to :mod:`shipgnc.viz.study_summary`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.viz.study_summary as _moved

warnings.warn("shipgnc.study.summary is now shipgnc.viz.study_summary", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
