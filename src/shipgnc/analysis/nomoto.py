"""The Nomoto reduction lives in :mod:`shipgnc.models.nomoto_reduction` (a model's analysis: the
models' layer) and document 003's printed (17)/(18) in :mod:`shipgnc.cases.cybership`; this module
keeps the old import path of the functions working."""

from shipgnc.models.nomoto_reduction import (
    NomotoI,
    NomotoII,
    SwayYawModel,
    davidson_schiff,
    first_order_reduction,
    nomoto_second_order,
)

__all__ = ["NomotoI", "NomotoII", "SwayYawModel", "davidson_schiff", "first_order_reduction",
           "nomoto_second_order"]
