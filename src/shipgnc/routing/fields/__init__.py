"""Moved to :mod:`shipgnc.environment.fields`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.environment.fields as _moved

warnings.warn("shipgnc.routing.fields is now shipgnc.environment.fields", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
