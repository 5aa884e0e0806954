"""The composed loop's scoring step, as source: :mod:`shipgnc.sim.compose` writes it after the loop
body (:mod:`shipgnc.sim.loop_template`, whose free names it shares: the log columns ``c_*``, the
sizes ``nx``, ``nu``, ...). At every step, where the log would take its sample, each ship's
accumulators are updated from the values that sample would hold, so that a study scores its
members without logging every step (:mod:`shipgnc.sim.scored` runs it;
:mod:`shipgnc.analysis.accumulated` says which accumulators a metric set needs and finishes its
formulas from them).

An accumulator ``m`` reads log column ``ops[m, 0]`` in the time window ``span[m, 0] <= t <
span[m, 1]`` and keeps three numbers ``acc[3 m: 3 m + 3]`` of the ship. Its gate ``ops[m, 2]``
(−1: none) restricts it further to the ship's samples before (``2 j``) or from (``2 j + 1``) the
switch recorded by the ``SCORE_SWITCH`` accumulator ``j`` (listed before it). Its kind
``ops[m, 1]``:

* ``SCORE_MAX`` — the largest ``v · span[m, 2]`` (NaN once a sample is NaN, as ``numpy.max``);
* ``SCORE_MAX_ABS`` — the largest ``|v|`` (NaN as above);
* ``SCORE_SUM_SQUARES`` — ``Σ (v · span[m, 2])²`` in time order (``batchmath.time_sum`` of the
  squares, to the bit) and the number of samples;
* ``SCORE_LAST`` — the last value in the window, and 1 once there is one;
* ``SCORE_FIRST`` — the first value in the window, and 1 once there is one;
* ``SCORE_BAND_EXIT`` — settling bookkeeping for the band ``|v · span[m, 2]| <= span[m, 3]``:
  whether any sample was outside it, the time of the first sample after the last one outside
  (NaN while the latest is outside), whether the latest was outside;
* ``SCORE_SUM`` — ``Σ f(v)`` in time order, f by ``span[m, 3]``: 0 v, 1 sin v, 2 cos v, 3 |v|;
  and the number of samples;
* ``SCORE_COUNT`` — the number of samples with ``v · span[m, 2] >= span[m, 3]``, and of all;
* ``SCORE_SWITCH`` — 1 from the first sample with ``v > 0`` on (a switch), and the number of
  samples before it;
* ``SCORE_LAST_OUT`` — the number of samples up to and including the last one outside the band
  ``|v · span[m, 2]| < span[m, 3]`` (0 if none), and the number of samples;
* ``SCORE_SUM_TC`` — ``Σ (t − span[m, 3]) · v`` and the number of samples;
* ``SCORE_ARGMAX`` — the largest ``v · span[m, 2]`` (its first sample) and its time ``t``;
* ``SCORE_DIFF`` — over the steps between successive samples, Δv and Δt (the times as the log's
  ``time`` coordinate holds them, rounded to 10⁻⁹ s with numpy's ``round`` arithmetic), f by
  ``span[m, 3]``: 0 ``Σ (Δv/Δt)²``, 1 ``Σ |Δv|``, 2 the number of steps with
  ``|Δv|/Δt >= span[m, 2]``; the previous value and time in the other two numbers (the time NaN
  before the first sample: the builder starts it so);
* ``SCORE_WRAP_DIFF_SQUARES`` — ``Σ wrap(v − x_j)²`` over the samples where it is finite, x_j
  the state ``j = int(span[m, 3])`` (log column j), and the number of them.

Every value is the log's own arithmetic (:func:`column_value` is ``log_sample``'s), so a finished
figure equals the one computed from the logged series.

The step the loop calls, ``score_step``, is :func:`score_step_generic` (each accumulator's
kind, column and gate read from ``ops`` at every step: one loop for every plan of a
combination), or, for a study big enough to pay for its compile, the step written for one plan by
:func:`shipgnc.sim.scored.score_step_source` after this text: each accumulator's column, kind,
gate, function and index constants (straight-line code), its window and arguments read from
``span``. Both call the kinds' functions below in the accumulators' order, so their numbers are
the same to the bit (a NaN's sign bit aside: ∞ − ∞ may give the processor's default NaN in one
and a positive NaN in the other; no figure reads it).
"""
# ruff: noqa: F821

SCORE_MAX = 0
SCORE_MAX_ABS = 1
SCORE_SUM_SQUARES = 2
SCORE_LAST = 3
SCORE_FIRST = 4
SCORE_BAND_EXIT = 5
SCORE_SUM = 6
SCORE_COUNT = 7
SCORE_SWITCH = 8
SCORE_LAST_OUT = 9
SCORE_SUM_TC = 10
SCORE_ARGMAX = 11
SCORE_DIFF = 12
SCORE_WRAP_DIFF_SQUARES = 13


@inline
def column_value(c, x, cmd, u, ref, gout, sig, nsg, err):
    """The value log column ``c`` takes at this sample (the arithmetic of ``log_sample``)."""
    if c < c_cmd:
        return x[c]
    if c < c_app:
        return cmd[c - c_cmd]
    if c < c_ref:
        return u[c - c_app]
    if c < c_err:
        return ref[c - c_ref]
    if c < c_out:
        j = c - c_err
        e = x[err[j, 0]] - ref[err[j, 1]]
        return wrap(e) if err[j, 2] else e
    if c < c_sig:
        return gout[c - c_out]
    if c < c_nav:
        return sig[c - c_sig]
    return nsg[c - c_nav]


@inline
def running_max(acc, a, v):
    """``acc[a]`` ← max(acc[a], v), NaN sticking as in ``numpy.max``."""
    if not math.isnan(acc[a]) and (v > acc[a] or math.isnan(v)):
        acc[a] = v


# one function per kind, ``score_<kind>(acc, a, v, t, arg, level, f, x)``: accumulator ``a`` (its
# first number) updated with the sample ``v`` at ``t``; ``arg``, ``level`` its span's last two
# numbers, ``f`` the function, or the state, that the kind's ``span[m, 3]`` names (a constant of
# a plan's own step, ``int(level)`` in the generic one)

@inline
def score_max(acc, a, v, t, arg, level, f, x):
    running_max(acc, a, v * arg)


@inline
def score_max_abs(acc, a, v, t, arg, level, f, x):
    running_max(acc, a, abs(v))


@inline
def score_sum_squares(acc, a, v, t, arg, level, f, x):
    w = v * arg
    acc[a] = acc[a] + w * w
    acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_last(acc, a, v, t, arg, level, f, x):
    acc[a] = v
    acc[a + 1] = 1.0


@inline
def score_first(acc, a, v, t, arg, level, f, x):
    if acc[a + 1] == 0.0:
        acc[a] = v
        acc[a + 1] = 1.0


@inline
def score_band_exit(acc, a, v, t, arg, level, f, x):
    if abs(v * arg) > level:
        acc[a] = 1.0
        acc[a + 1] = math.nan
        acc[a + 2] = 1.0
    elif acc[a + 2] != 0.0:
        acc[a + 1] = t
        acc[a + 2] = 0.0


@inline
def score_sum(acc, a, v, t, arg, level, f, x):
    acc[a] = acc[a] + (v if f == 0 else math.sin(v) if f == 1 else
                       math.cos(v) if f == 2 else abs(v))
    acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_count(acc, a, v, t, arg, level, f, x):
    if v * arg >= level:
        acc[a] = acc[a] + 1.0
    acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_switch(acc, a, v, t, arg, level, f, x):
    if acc[a] == 0.0:
        if v > 0:
            acc[a] = 1.0
        else:
            acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_last_out(acc, a, v, t, arg, level, f, x):
    acc[a + 1] = acc[a + 1] + 1.0
    if not (abs(v * arg) < level):
        acc[a] = acc[a + 1]


@inline
def score_sum_tc(acc, a, v, t, arg, level, f, x):
    acc[a] = acc[a] + (t - level) * v
    acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_argmax(acc, a, v, t, arg, level, f, x):
    if v * arg > acc[a]:
        acc[a] = v * arg
        acc[a + 1] = t


@inline
def score_diff(acc, a, v, t, arg, level, f, x):
    tr = np.rint(t * 1e9) / 1e9  # time_coordinate(t): np.round(t, 9)
    if not math.isnan(acc[a + 2]):
        step = v - acc[a + 1]
        if f == 0:
            q = step / (tr - acc[a + 2])
            acc[a] = acc[a] + q * q
        elif f == 1:
            acc[a] = acc[a] + abs(step)
        elif abs(step) / (tr - acc[a + 2]) >= arg:
            acc[a] = acc[a] + 1.0
    acc[a + 1] = v
    acc[a + 2] = tr


@inline
def score_wrap_diff_squares(acc, a, v, t, arg, level, f, x):
    w = wrap(v - x[f])
    if not math.isnan(w):
        acc[a] = acc[a] + w * w
        acc[a + 1] = acc[a + 1] + 1.0


@inline
def score_step_generic(t, x, cmd, u, ref, gout, sig, nsg, err, ops, span, acc):
    """Update the ship's accumulators ``acc`` with the sample at time ``t`` (see the module)."""
    for m in range(ops.shape[0]):
        if not (t >= span[m, 0] and t < span[m, 1]):
            continue
        gate = ops[m, 2]
        if gate >= 0 and (acc[3 * (gate // 2)] != 0.0) != (gate % 2 == 1):
            continue
        v = column_value(ops[m, 0], x, cmd, u, ref, gout, sig, nsg, err)
        kind, a, arg, level = ops[m, 1], 3 * m, span[m, 2], span[m, 3]
        f = int(level)
        if kind == SCORE_MAX:
            score_max(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_MAX_ABS:
            score_max_abs(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_SUM_SQUARES:
            score_sum_squares(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_LAST:
            score_last(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_FIRST:
            score_first(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_BAND_EXIT:
            score_band_exit(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_SUM:
            score_sum(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_COUNT:
            score_count(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_SWITCH:
            score_switch(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_LAST_OUT:
            score_last_out(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_SUM_TC:
            score_sum_tc(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_ARGMAX:
            score_argmax(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_DIFF:
            score_diff(acc, a, v, t, arg, level, f, x)
        elif kind == SCORE_WRAP_DIFF_SQUARES:
            score_wrap_diff_squares(acc, a, v, t, arg, level, f, x)
