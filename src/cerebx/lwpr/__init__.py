"""Locally Weighted Projection Regression, written for cerebx (e.g. as the granular layer of cerebellar
modules whose input is continuous)."""

from cerebx.lwpr.model import LWPR
from cerebx.lwpr.schema import LWPRParams

__all__ = ["LWPR", "LWPRParams"]
