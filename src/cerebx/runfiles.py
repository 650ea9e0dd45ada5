"""The files of a run folder, named in one place.

A run folder (Hydra's output directory) holds:

=======================  ===================================================================
``run.mcap``             the log (continuations add ``run.<n>.mcap`` segments, ``segments.json``)
``summary.json``         status, metrics per trial and timing, rewritten after every trial
``controller_state.npz`` the learned state at the end (``init_from`` starts from it); parts of a
                         composite controller keep ``controller_state.part<i>.npz`` beside it
``checkpoint.pkl``       the whole live loop every ``checkpoint_every`` trials (``resume``), with a
                         small JSON head ``checkpoint.pkl.json``, its large learned arrays in
                         ``checkpoint.<n>.arrays`` and the last changes to them in ``checkpoint.journal``
                         (``persistence/checkpoint.py``); all deleted when the run completes
``error.txt``            a sweep job refused before its run started: why
``robot/``, ``relay/``   a wall-clock run over a real link: the robot side's run folder and the delay
                         relay's counts and drawn delays (``injected.csv``)
``.hydra/``              Hydra's record of the composed config and the overrides
=======================  ===================================================================
"""

MCAP = "run.mcap"
SEGMENTS = "segments.json"
SUMMARY = "summary.json"
STATE = "controller_state.npz"
CHECKPOINT = "checkpoint.pkl"
CHECKPOINT_HEAD = CHECKPOINT + ".json"
ERROR = "error.txt"
HYDRA = ".hydra"
OVERRIDES = HYDRA + "/overrides.yaml"
ROBOT = "robot"
RELAY = "relay"
INJECTED = "injected.csv"


def part_state(state_name: str, i: int) -> str:
    """The state file of part ``i`` of a composite controller beside the run's state file."""
    stem, dot, suffix = state_name.rpartition(".")
    return f"{stem}.part{i}.{suffix}" if dot else f"{state_name}.part{i}"
