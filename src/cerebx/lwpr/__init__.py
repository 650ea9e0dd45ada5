"""Locally Weighted Projection Regression, written for cerebx (the granular layer of the Capolei 2020
cerebellar modules)."""

from cerebx.lwpr.model import LWPR
from cerebx.lwpr.schema import LWPRParams

__all__ = ["LWPR", "LWPRParams"]
