"""Waypoint paths and the leg tracker live in :mod:`shipgnc.paths` (core geometry, like
:mod:`shipgnc.frames`: vessel models and currents use them too); this module keeps the old import
path working."""

from shipgnc.paths import LegTracker, WaypointPath, leg_table, leg_value, track_leg

__all__ = ["LegTracker", "WaypointPath", "leg_table", "leg_value", "track_leg"]
