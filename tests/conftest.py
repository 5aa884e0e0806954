"""Test configuration: headless matplotlib, numpy errors surface as failures."""

import matplotlib

matplotlib.use("Agg")
