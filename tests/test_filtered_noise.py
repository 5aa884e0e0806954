"""Wave noise of note 000-A11 and the cross current of A10."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.signal

from shipgnc.environment.current import CrossCurrent
from shipgnc.environment.filtered_noise import SecondOrderNoise
from shipgnc.errors import ConfigError
from shipgnc.paths import WaypointPath
from shipgnc.streams import MemberStreams


def realisation(noise, h, n, ships=1, seed=1):
    return noise.sequence(np.arange(n) * h, (ships,), np.random.default_rng(seed))


@pytest.mark.parametrize("h", [0.3, 1.0, 2.5])
def test_held_rms_is_the_step_average_of_sigma(h):
    """The filter keeps var(w) = σ² (A11's scaling of q); the value held over a step is w's exact
    average over it, whose variance 2(P₁₁ − (ΦP)₁₁)/h² is σ² less what the averaging removes."""
    noise = SecondOrderNoise(sigma=2.0, period=8.0, zeta=0.1)
    assert noise.held_variance(1e-3) == pytest.approx(4.0, rel=1e-4)  # h → 0: the point value
    # the same variance from the spectrum side: S_w·sinc²(ωh/2), folded, integrated to Nyquist
    f = np.linspace(0.0, 0.5 / h, 200_001)
    assert noise.held_variance(h) == pytest.approx(
        np.trapezoid(noise.step_average_psd(f, h), f), rel=1e-3)
    assert noise.held_variance(h) < 4.0
    w = realisation(noise, h, 4000, ships=50)[1:]  # the first value is the point sample w(0)
    # 200 000 correlated samples; the relative standard error of the variance is a few per cent
    assert np.sqrt(np.mean(w**2)) == pytest.approx(math.sqrt(noise.held_variance(h)), rel=0.03)
    assert abs(np.mean(w)) < 0.1


def test_spectrum_peaks_at_the_filter_frequency():
    """A lightly damped filter (ζ = 0.1) concentrates the power near ω₀ = 2π/T₀."""
    noise = SecondOrderNoise(sigma=1.0, period=8.0, zeta=0.1)
    h = 0.25
    w = realisation(noise, h, 40_000)[:, 0]
    f, pxx = scipy.signal.welch(w, fs=1.0 / h, nperseg=4096)
    assert f[np.argmax(pxx)] == pytest.approx(1.0 / 8.0, rel=0.05)
    # Parseval: the one-sided density integrates to the variance
    assert np.trapezoid(pxx, f) == pytest.approx(np.var(w), rel=0.05)


def test_same_seed_same_sea_and_call_equals_sequence():
    noise = SecondOrderNoise(sigma=1.0, period=8.0, zeta=0.1)
    a = realisation(noise, 0.3, 100, ships=3, seed=5)
    b = realisation(noise, 0.3, 100, ships=3, seed=5)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, realisation(noise, 0.3, 100, ships=3, seed=6))
    noise.reset((3,), np.random.default_rng(5))
    np.testing.assert_array_equal(np.stack([noise(0.3 * k) for k in range(100)]), a)
    assert not np.allclose(a[:, 0], a[:, 1])  # each ship its own realisation


@pytest.mark.parametrize("streams", [False, True])
@pytest.mark.parametrize("step", [None, 0.3])
def test_a_run_of_calls_at_once_is_the_calls_to_the_bit(step, streams):
    """``at_times`` (one draw, one compiled pass) returns what the calls return and leaves the
    state as they leave it: continued in chunks (the compiled loop's table), after an irregular
    call (a skipped step, a repeated time), with two batch axes, from one generator or from one
    stream per member (a study's :class:`~shipgnc.streams.MemberStreams`)."""
    def rng():
        return MemberStreams([11, 12, 13, 14]) if streams else np.random.default_rng(11)

    def pair():
        a, b = (SecondOrderNoise(sigma=0.7, period=8.0, zeta=0.1, step=step) for _ in range(2))
        a.reset((4, 3), rng())
        b.reset((4, 3), rng())
        return a, b

    times = np.arange(0, 500) * 0.3
    calls, chunks = pair()
    expected = np.stack([calls(t) for t in times])
    got = np.concatenate([chunks.at_times(times[k:k + 64]) for k in range(0, times.size, 64)])
    np.testing.assert_array_equal(got, expected)
    assert got.shape == (500, 4, 3)
    # after the chunks the state is the calls' state: the next values agree too
    np.testing.assert_array_equal(chunks.at_times(times[-1] + 0.3 * np.arange(1, 4)),
                                  np.stack([calls(times[-1] + 0.3 * k) for k in range(1, 4)]))
    # far from t = 0, t_k − t_{k−1} rounds to other cache keys than dt's (0.3 and 0.299999999999
    # from t ≈ 4097 s): each key's transition is the one of the first step that has it
    late = np.arange(13600, 13760) * 0.3
    calls, at_once = pair()
    np.testing.assert_array_equal(at_once.at_times(late), np.stack([calls(t) for t in late]))
    assert len(calls._avg_cache) >= 2
    for key, (G, L) in calls._avg_cache.items():
        np.testing.assert_array_equal(at_once._avg_cache[key][0], G)
        np.testing.assert_array_equal(at_once._avg_cache[key][1], L)
    irregular = np.concatenate([times[:10], times[9:10], times[12:40], [12.05], times[41:60]])
    calls, at_once = pair()
    np.testing.assert_array_equal(at_once.at_times(irregular), np.stack([calls(t) for t in irregular]))
    assert at_once.at_times([]).shape == (0, 4, 3)
    # the compiled pass steps its own copy of the state, not the array a point value w(t0)
    # handed out is a view of (a repeated first time, then regular steps)
    tiny = np.array([0.0, 0.0, 1e-10, 2e-10, 3e-10, 4e-10])
    calls, at_once = pair()
    np.testing.assert_array_equal(at_once.at_times(tiny), np.stack([calls(t) for t in tiny]))
    with pytest.raises(ConfigError, match="reset"):
        SecondOrderNoise(sigma=0.7, period=8.0, zeta=0.1).at_times([])


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"sigma": -1.0, "period": 8.0, "zeta": 0.1}, "wave_sigma"),
    ({"sigma": 1.0, "period": 0.0, "zeta": 0.1}, "wave_period"),
    ({"sigma": 1.0, "period": 8.0, "zeta": math.nan}, "wave_zeta"),
])
def test_bad_noise_settings(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        SecondOrderNoise(**kwargs)


def test_cross_current_turns_with_the_active_leg():
    path = WaypointPath(np.array([[0.0, 0.0], [1000.0, 0.0], [1000.0, 1000.0]]))  # north, then east
    current = CrossCurrent(2.0, path)
    current.reset((2,))
    x = np.array([[500.0, 0.0, 0, 0, 0], [1001.0, 10.0, 0, 0, 0]])  # on leg 1; past its end
    c = current(0.0, x)
    np.testing.assert_allclose(c[0], [0.0, 2.0], atol=1e-12)  # leg 1 (north): across = east
    np.testing.assert_allclose(c[1], [-2.0, 0.0], atol=1e-12)  # leg 2 (east): across = south
    glob = CrossCurrent(2.0, path, frame="global")
    glob.reset((2,))
    np.testing.assert_allclose(glob(0.0, x), [[0.0, 2.0], [0.0, 2.0]])
    with pytest.raises(ConfigError, match="current_frame"):
        CrossCurrent(2.0, path, frame="body")
