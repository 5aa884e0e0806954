"""Moved to :mod:`shipgnc.viz.run_files`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.viz.run_files as _moved

warnings.warn("shipgnc.scenarios.write is now shipgnc.viz.run_files", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
