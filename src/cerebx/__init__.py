"""cerebx: declarative cerebellar motor-control experiments.

Data flow (one control step = 2 ms, ``loop/loop.py``): task reference + plant sensors -> link (R2C)
-> brain-side stages (the controller's parts) -> link (C2R) -> robot-side stages (receiver filter,
supervisor, ...) -> plant command -> physics -> recorder. Signals are named arrays that plants and
stages declare (``loop/signals.py``).
"""

__version__ = "0.1.0"

from cerebx import vectors as _vectors

_vectors.configure()  # before numba compiles anything: CEREBX_VECTOR_BITS (cerebx/vectors.py)
