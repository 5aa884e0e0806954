"""Moved to :mod:`shipgnc.viz.trial_figures`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.viz.trial_figures as _moved

warnings.warn("shipgnc.trials.figures is now shipgnc.viz.trial_figures", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
