"""One random stream per ship of a batch, behind the ``numpy.random.Generator`` calls the
disturbances use.

A batched run normally draws every ship's noise from one generator, so ship *i*'s noise depends on
how many ships share the batch. A study that splits its members into chunks (``shipgnc sweep``) needs
each member's result to be the same whatever the chunking: :class:`MemberStreams` holds one
generator per member (children of one :class:`numpy.random.SeedSequence`, see :func:`member_seeds`)
and answers ``standard_normal``, ``random`` and ``uniform`` for shapes whose leading axis is the
member axis by stacking each member's own draw. :func:`normal_steps` draws a run of steps' normals
at once, from either kind of generator, as the steps would draw them one by one.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require


def member_seeds(seed: int, n_members: int) -> list[np.random.SeedSequence]:
    """The independent streams of members ``0 .. n_members-1`` of a study seeded by ``seed``
    (``SeedSequence(seed).spawn(n_members)``: member *i*'s stream does not depend on the others)."""
    require(isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) and seed >= 0,
            "seed", seed, "must be a non-negative integer")
    return np.random.SeedSequence(int(seed)).spawn(int(n_members))


class MemberStreams:
    """A batch of generators, one per member; draws have the member axis first.

    ``streams[i]`` is member *i*'s :class:`numpy.random.Generator` (from a seed, a ``SeedSequence``
    or a generator, used as it is). ``standard_normal(shape)`` with
    ``shape = (n_members, *rest)`` returns member *i*'s ``standard_normal(rest)`` in row *i*; same for
    ``random`` and ``uniform``. A shape without the member axis first is refused (it would mix the
    streams).
    """

    def __init__(self, seeds):
        # a list is copied (a caller may change it); a lazy sequence (a study's seeds) is kept
        self._seeds = tuple(seeds) if isinstance(seeds, list) or not hasattr(seeds, "__len__") else seeds
        self._streams: list | None = None
        require(len(self._seeds) >= 1, "streams", len(self._seeds), "need at least one member")

    @property
    def streams(self) -> list[np.random.Generator]:
        """Each member's generator, made at the first draw (a run that draws nothing, e.g. a
        study without a random disturbance, makes none: ≈ 10 µs a member)."""
        if self._streams is None:
            self._streams = [np.random.default_rng(s) for s in self._seeds]
        return self._streams

    def __len__(self) -> int:
        return len(self._seeds)

    def _rest(self, shape) -> tuple[int, ...]:
        shape = (shape,) if np.ndim(shape) == 0 else tuple(int(s) for s in shape)
        require(len(shape) >= 1 and shape[0] == len(self), "draw shape", shape,
                f"must start with the member axis ({len(self)} members)")
        return shape[1:]

    def standard_normal(self, size) -> np.ndarray:
        rest = self._rest(size)
        return np.stack([g.standard_normal(rest) for g in self.streams])

    def standard_normal_steps(self, steps: int, size) -> np.ndarray:
        """``steps`` consecutive ``standard_normal(size)`` draws at once, shape (steps, *size):
        each member's ``steps`` draws are one draw of its generator (the same stream)."""
        rest = self._rest(size)
        return np.stack([g.standard_normal((int(steps), *rest)) for g in self.streams], axis=1)

    def random(self, size) -> np.ndarray:
        rest = self._rest(size)
        return np.stack([g.random(rest) for g in self.streams])

    def uniform(self, low=0.0, high=1.0, size=None) -> np.ndarray:
        require(size is not None, "uniform size", size, "must give the shape (member axis first)")
        rest = self._rest(size)
        return np.stack([g.uniform(low, high, rest) for g in self.streams])


def normal_steps(rng, steps: int, size) -> np.ndarray:
    """``np.stack([rng.standard_normal(size) for _ in range(steps)])`` in one draw per stream, to
    the bit: a ``Generator`` fills its output in order, so ``steps`` consecutive draws are one draw
    of shape (steps, *size); a :class:`MemberStreams` draws each member's steps from its own
    generator."""
    size = (size,) if np.ndim(size) == 0 else tuple(int(s) for s in size)
    if isinstance(rng, MemberStreams):
        return rng.standard_normal_steps(steps, size)
    return rng.standard_normal((int(steps), *size))


def is_generator(rng) -> bool:
    """True for a ``numpy.random.Generator`` or a :class:`MemberStreams`."""
    return isinstance(rng, (np.random.Generator, MemberStreams))
