"""The per-member random streams live in :mod:`shipgnc.streams` (core: every layer draws from
them); this module keeps the old import path working."""

from shipgnc.streams import MemberStreams, is_generator, member_seeds

__all__ = ["MemberStreams", "is_generator", "member_seeds"]
