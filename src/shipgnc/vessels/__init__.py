"""The vessel catalogue (``shipgnc vessels``): named manoeuvring models for scenarios and trials,
e.g.::

    from shipgnc.vessels import get_vessel, VESSELS, VesselEntry
    model = get_vessel("mariner-cst").build(speed_mps=7.7175)
    x0 = model.straight_state(7.7175)

Every model has the states ``north, east, psi, u, v, r, delta`` (+ e.g. ``n``) and the first
input ``delta_c`` (:mod:`shipgnc.vessels.base`).
"""

from shipgnc.vessels.catalogue import VESSELS, VesselEntry, get_vessel, register

__all__ = ["VESSELS", "VesselEntry", "get_vessel", "register"]
