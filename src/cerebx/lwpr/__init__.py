"""Locally Weighted Projection Regression, written for cerebx (e.g. as the granular layer of cerebellar
modules whose input is continuous).

``LWPR`` (the model, numba kernels) is imported on first use, so that ``cerebx.lwpr.schema`` validates a
config without loading numba."""

from typing import Any

from cerebx.lwpr.schema import LWPRParams

__all__ = ["LWPR", "LWPRParams"]


def __getattr__(name: str) -> Any:
    if name == "LWPR":
        from cerebx.lwpr.model import LWPR

        return LWPR
    raise AttributeError(f"module 'cerebx.lwpr' has no attribute {name!r}")
