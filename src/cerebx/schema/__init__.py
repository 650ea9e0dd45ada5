"""Typed configuration: Pydantic v2 models, strict (unknown keys rejected) and frozen."""
