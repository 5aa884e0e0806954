"""Vessel models: frozen parameter dataclasses with pure, batched ``derivatives(x, u, d)``."""
from shipgnc.models.linear3dof import clarke83 as clarke83  # Clarke et al. (1983) linear model
