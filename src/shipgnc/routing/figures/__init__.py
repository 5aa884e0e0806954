"""Moved to :mod:`shipgnc.viz.route_figures`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.viz.route_figures as _moved

warnings.warn("shipgnc.routing.figures is now shipgnc.viz.route_figures", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
