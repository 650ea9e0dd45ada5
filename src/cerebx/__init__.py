"""cerebx: declarative cerebellar motor-control experiments.

Data flow (one control step = 2 ms): task reference -> plant sensors -> R2C delay channel ->
controller -> C2R delay channel -> plant-side torque filter + supervisor -> physics -> recorder.
"""

__version__ = "0.1.0"
