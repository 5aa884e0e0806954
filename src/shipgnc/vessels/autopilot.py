"""A heading autopilot for catalogue vessels: PID on the heading error with the trim rudder.

    δ_c = δ₀ − K_P wrap(ψ − ψ_d) − K_D r − K_I ∫ wrap(ψ − ψ_d) dt,     |δ_c| ≤ δ_max

(Fossen 2021, §15.3: PID heading autopilot; the signs are those of a vessel whose positive rudder
turns the bow to starboard, as every catalogue vessel's). δ₀ is the trim rudder of steady
straight running (the ``delta`` of ``model.straight_state()``), a feed-forward of the constant
side-force terms some models have (the Mariner's Y₀, N₀). The integral runs only while the command
is within the rudder limit (conditional integration, no wind-up). Further inputs of the vessel
(e.g. the KVLCC2's propeller command ``n_c``) are held at ``hold``.

Reads the catalogue state layout (``psi`` at index 2, ``r`` at 5; :mod:`shipgnc.vessels.base`)
and the reference ``psi_d`` (e.g. :class:`~shipgnc.guidance.schedule.CourseSchedule`).

:func:`course_autopilot` is the ``course`` controller's builder for a vessel that declares a rudder
state (the registry's ``rudder-state`` capability: every catalogue vessel).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal

#: the PD gains of ``controller: {type: course}`` left out: K_P [rad/rad], K_D [s]
DEFAULT_KP, DEFAULT_KD = 1.0, 10.0


class HeadingAutopilot:
    """PID heading autopilot (module docstring), sampled every ``Ts`` seconds."""

    continuous = False
    reference_names = ("psi_d",)
    signals: tuple[Signal, ...] = ()

    def __init__(self, Kp: float, Kd: float, Ki: float = 0.0, *, Ts: float, delta_max: float,
                 trim: float = 0.0, hold=()):
        for name, value in (("Kp", Kp), ("Kd", Kd), ("Ki", Ki)):
            require(isinstance(value, (int, float)) and math.isfinite(value) and value >= 0,
                    f"controller.{name}", value, "must be a finite number >= 0")
        require(isinstance(Ts, (int, float)) and math.isfinite(Ts) and Ts > 0, "controller.Ts",
                Ts, "must be > 0 s")
        require(0 < delta_max <= math.pi / 2, "controller.delta_max", delta_max,
                "need 0 < delta_max <= pi/2 rad")
        self.Kp, self.Kd, self.Ki = float(Kp), float(Kd), float(Ki)
        self.Ts, self.delta_max, self.trim = float(Ts), float(delta_max), float(trim)
        self.hold = tuple(float(h) for h in hold)
        self._z = np.zeros(())

    def reset(self, batch_shape) -> None:
        self._z = np.zeros(tuple(batch_shape))

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """One sample for every ship: the batch of :func:`heading_autopilot_step`."""
        command, _ = kernel_step(self, t, measurement, reference, 1 + len(self.hold))
        return command

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`heading_autopilot_step`); the integral is
        the per-ship state."""
        state = np.broadcast_to(self._z, tuple(batch_shape)).reshape(-1, 1)

        def restore(z):
            self._z = np.asarray(z[:, 0]).reshape(tuple(batch_shape)).copy()

        return Kernel(heading_autopilot_step,
                      flat(self.Kp, self.Kd, self.Ki, self.trim, self.delta_max, self.Ts,
                           len(self.hold), *self.hold),
                      state, restore=restore)


@kernel_function
def heading_autopilot_step(t, x, ref, z, p, cmd, sig):
    """The PID heading autopilot for one ship (Fossen 2021, §15.3)::

        δ_c = clip(δ₀ − K_P e − K_D r − K_I z, −δ_max, δ_max),   e = wrap(ψ − ψ_d)

    z += Ts e only while the command is within the limit (conditional integration); the vessel's
    further inputs held. p = [K_P, K_D, K_I, δ₀, δ_max, Ts, n_hold, hold...], z = [∫e dt]."""
    e = wrap(x[2] - ref[0])
    raw = p[3] - p[0] * e - p[1] * x[5] - p[2] * z[0]
    dmax = p[4]
    delta_c = min(max(raw, -dmax), dmax)
    if p[2] != 0.0 and raw == delta_c:
        z[0] = z[0] + p[5] * e
    cmd[0] = delta_c
    for j in range(int(p[6])):
        cmd[1 + j] = p[7 + j]


def course_autopilot(cfg, model, scenario=None) -> HeadingAutopilot:
    """The heading autopilot of a ``course`` controller section ``cfg`` on a vessel with a rudder
    state (``scenario`` unused: the gains are the section's).

    ``variant: pd`` with ``Kp`` [rad of rudder per rad of heading error] and ``Kd`` [s] (defaults
    1.0 and 10.0 s; gains whose linearised loop is unstable or has a phase margin under 30° get a
    note), or ``design: auto`` with ``bandwidth`` [rad/s] and ``zeta``: gains designed for the
    vessel (:mod:`shipgnc.vessels.autopilot_design`). The vessel's trim rudder is the feed-forward
    δ₀ and its other inputs (propeller) are held at their straight-run values."""
    from shipgnc.vessels.autopilot_design import check_loop, design_autopilot, design_model
    from shipgnc.vessels.scenario import straight_inputs

    if cfg.variant != "pd":
        raise ConfigError(f"controller.variant = {cfg.variant!r}: document 003's sliding-mode laws "
                          "are designed on CyberShip II; a vessel with a rudder state is steered by "
                          "variant 'pd' (Kp, Kd, or design: auto)")
    inputs = straight_inputs(model)
    if getattr(cfg, "design", None) == "auto":
        design = design_autopilot(model, bandwidth=cfg.bandwidth, sample_time=cfg.Ts,
                                  **({} if cfg.zeta is None else {"zeta": cfg.zeta}))
        Kp, Kd = design.Kp, design.Kd
        notes = [f"designed autopilot: Kp = {Kp:.4g}, Kd = {Kd:.4g} s; {design.check.describe()}"]
    else:
        Kp = DEFAULT_KP if cfg.Kp is None else cfg.Kp
        Kd = DEFAULT_KD if cfg.Kd is None else cfg.Kd
        notes = []
        try:
            check = check_loop(design_model(model), Kp, Kd)
        except ConfigError:  # no linear design model (e.g. a pure integrator): nothing to note
            check = None
        if check is not None and check.poor:
            notes.append(f"the autopilot's gains (Kp = {Kp:g}, Kd = {Kd:g} s) leave the linearised "
                         f"loop with poor margins ({check.describe()}); controller: "
                         "{type: course, design: auto} designs gains for this vessel")
    pilot = HeadingAutopilot(Kp, Kd, Ts=cfg.Ts, delta_max=float(model.delta_max),
                             trim=float(inputs[0]), hold=tuple(inputs[1:]))
    pilot.notes = notes
    return pilot
