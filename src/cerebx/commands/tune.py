"""``cerebx tune``: Ziegler-Nichols PD gains on the simulated plant."""

from cerebx.tuning import main  # noqa: F401 - the command's entry
