"""Reports: the end-of-run console summary and the figure/table report built from run logs."""
