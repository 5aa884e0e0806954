"""Standard manoeuvring trials (IMO MSC.137(76); ``docs/trials.md``): turning circle, zig-zag,
spiral (direct and reverse), pull-out, stopping, and the criteria report — batched: every ship of
a trial (sides, rudder angles, speeds, several trials at once) is one integration.

    from shipgnc.trials import turning_circle, pull_out, run_all
    from shipgnc.trials.zigzag import zigzag
    from shipgnc.trials.spiral import spiral
    res = turning_circle("mariner-cst")          # JSON-ready dict (+ "_history" for figures)

(The modules ``zigzag``, ``spiral`` and ``stopping`` hold functions of the same name.)
"""

from shipgnc.trials.core import TrialShip, prepare
from shipgnc.trials.imo import criteria, run_all
from shipgnc.trials.pullout import pull_out
from shipgnc.trials.turning import turning_circle
from shipgnc.trials.zigzag import ZigZag

__all__ = ["TrialShip", "ZigZag", "criteria", "prepare", "pull_out", "run_all", "turning_circle"]
