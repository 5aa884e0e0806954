"""Vessel models: frozen parameter dataclasses with pure, batched ``derivatives(x, u, d)``."""
