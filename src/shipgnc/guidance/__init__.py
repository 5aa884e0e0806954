"""Guidance: references for the controller (schedules, waypoint paths, LOS, heading reference
models)."""
