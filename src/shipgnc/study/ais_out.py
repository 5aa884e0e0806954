"""A collision-avoidance run written as an NMEA AIS log for a chart plotter: the own ship as
``!AIVDO``, its targets as ``!AIVDM`` (:func:`shipgnc.ais.write.write_log`: position reports at the
ITU-R M.1371-5 intervals of each ship's speed and rate of turn, static data every 6 minutes).

The own ship's motion is the run's: position (north, east), course over ground
χ = ψ + atan2(v, u) and speed √(u² + v²) (no current), heading ψ. The targets are their true tracks
(what the ships did, whatever the own ship saw of them; a vessel target, integrated in the run, its
logged states). Positions are placed on the earth with the
local plane about ``origin`` (lat, lon) [deg]; a situation turned to the sweep's frame (own course 0)
is turned back by ``rotation``, so the log shows it as the file gave it.

Identities: a target keeps its MMSI if it has one (a logged or trafficgen target), else it and the
own ship take MMSIs of MID 100 — Maritime Identification Digits run from 201 to 775 (ITU-R M.585,
the ITU's MID table), so no country, and no real ship, has them: the own ship 100000000, target j
100000001 + j.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from shipgnc.errors import ConfigError

#: the own ship's MMSI in a written log (MID 100: allocated to no country)
OWN_MMSI = 100_000_000


def target_mmsis(tracks) -> list[int]:
    """One MMSI per target: its own, else 100000001 + j (MID 100); a repeat is a ConfigError."""
    mmsis = [int(tr.mmsi) or OWN_MMSI + 1 + j for j, tr in enumerate(tracks)]
    if len(set(mmsis)) != len(mmsis) or OWN_MMSI in mmsis:
        raise ConfigError(f"targets' MMSIs {mmsis}: every ship of an AIS log needs its own "
                          f"(the own ship is {OWN_MMSI})")
    return mmsis


def _turned(north, east, angle: float):
    c, s = math.cos(angle), math.sin(angle)
    return c * north - s * east, s * north + c * east


def own_motion(ds, rotation: float = 0.0) -> dict[str, np.ndarray]:
    """The own ship of a one-ship result ``ds`` (dims ``time`` only) as ``write_log``'s dict:
    north, east [m], sog [m/s], cog, heading [rad], turned by ``rotation`` [rad]."""
    from shipgnc.guidance.colav import course_over_ground

    psi, u = ds["psi"].values, ds["u"].values
    v = ds["v"].values if "v" in ds else np.zeros_like(u)
    north, east = _turned(ds["north"].values, ds["east"].values, rotation)
    return {"north": north, "east": east, "sog": np.hypot(u, v),
            "cog": np.mod(course_over_ground.py_func(psi, u, v) + rotation, 2 * np.pi),
            "heading": np.mod(psi + rotation, 2 * np.pi)}


def write_run_log(path, ds, targets, origin, *, rotation: float = 0.0, names=None,
                  own_dims=None, tag_blocks: bool = True) -> Path:
    """Write one run (``ds``: one ship, dims ``time``) and its ``targets`` (true
    :class:`~shipgnc.colav.tracks.TargetTrack`, or vessel targets: their states in ``ds``) as
    an AIS log at ``path`` (module docstring); ``names``: the own ship's, then the targets'
    (default: OWN SHIP and the tracks' labels);
    ``own_dims``: the own ship's (length, beam) [m] for its static data (None: not given)."""
    from shipgnc.ais.write import write_log
    from shipgnc.study.encounters import rotated

    t = ds["time"].values
    keep = np.isfinite(ds["north"].values)  # a masked (diverged) member: up to its last sample
    if not keep.any():
        raise ConfigError(f"{path}: the run has no finite own-ship position to write")
    ds = ds.isel(time=np.flatnonzero(keep))
    t = t[keep]
    tracks = [_logged(tr, ds, j) for j, tr in enumerate(targets)]
    tracks = [rotated(tr, rotation) if rotation else tr for tr in tracks]
    if names is None:
        names = ["OWN SHIP", *(tr.label for tr in tracks)]
    lengths = [own_dims, *((tr.length, tr.beam) for tr in tracks)]
    return write_log(path, t, own_motion(ds, rotation), tracks, origin, OWN_MMSI,
                     target_mmsis(tracks), names=names, lengths=lengths, tag_blocks=tag_blocks)


def _logged(track, ds, j: int):
    """Target j as a track: a vessel target (integrated in the run) from its states in ``ds``
    (``target_north``, ``target_east``, ``target_sog``, ``target_cog`` at every logged time), a
    track as it is."""
    from shipgnc.colav.tracks import TargetTrack
    from shipgnc.guidance.vessel_targets import VesselTarget

    if not isinstance(track, VesselTarget):
        return track
    sog, cog = ds["target_sog"].values[:, j], ds["target_cog"].values[:, j]
    return TargetTrack(ds["time"].values, ds["target_north"].values[:, j],
                       ds["target_east"].values[:, j], sog * np.cos(cog), sog * np.sin(cog),
                       mmsi=track.mmsi, name=track.name, length=track.length, beam=track.beam,
                       source="vessel")


def scenario_logs(run, path) -> list[Path]:
    """``shipgnc run --ais-log PATH`` for a ``guidance: colav`` scenario: the run at ``path``; a
    scenario with several runs (``runs:``) writes one file per run, ``PATH`` with ``-<run>`` before
    its suffix, with that run's own targets. The origin: the AIS log's
    (``guidance.ais_log.origin``), else (0°, 0°)."""
    sc = run.scenario
    g = sc.guidance
    if g is None or g.type != "colav":
        raise ConfigError(f"--ais-log: scenario {sc.name!r} has no ships to meet (it needs "
                          "guidance type colav)")
    setup = run.setup
    origin = g.ais_log.origin if g.ais_log is not None and g.ais_log.origin else (0.0, 0.0)
    tracks = setup.guidance.members[0]
    path = Path(path)
    ds = run.result
    dim = next((d for d in ds["north"].dims if d != "time"), None)
    if dim is None:
        return [write_run_log(path, ds, tracks, origin)]
    out = []
    for key in ds[dim].values:
        one = ds.sel({dim: key})
        own = run.setups.get(str(key)) if run.setups else None  # each run's own targets
        out.append(write_run_log(path.with_name(f"{path.stem}-{key}{path.suffix}"), one,
                                 own.guidance.members[0] if own is not None else tracks, origin))
    return out


def member_log(path, member, *, backend: str = "auto", ais=None) -> Path:
    """``shipgnc encounters --ais-log PATH``: one sweep member
    (:class:`~shipgnc.study.encounters.Member`) run again alone, seeing its targets as in the
    sweep (``ais``, drawn by the member's situation and variant), logged at every step (the sweep
    logs every 10th: its 5 s would stretch the 2–6 s reporting intervals), written at ``path``."""
    from shipgnc.study.encounters import run_members

    sweep = run_members([member], backend=backend, log_every=1, keep_results=True,
                        compliance=False, ais=ais)
    (_, ds), = sweep.results
    dim = next((d for d in ds["north"].dims if d != "time"), None)
    one = ds.isel({dim: 0}) if dim is not None else ds
    sit = member.situation
    return write_run_log(path, one, sit.targets, sit.origin, rotation=member.rotation,
                         own_dims=(sit.own_length, sit.own_width))
