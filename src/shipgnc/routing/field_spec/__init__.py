"""Moved to :mod:`shipgnc.environment.field_spec`; the old name stays that module for one release.

(A package, not a file, so that version control follows the module to its new place.)
"""

import sys
import warnings

import shipgnc.environment.field_spec as _moved

warnings.warn("shipgnc.routing.field_spec is now shipgnc.environment.field_spec", DeprecationWarning,
              stacklevel=2)
sys.modules[__name__] = _moved
