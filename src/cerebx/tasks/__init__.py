"""Tasks: desired joint trajectories, one trial = one period."""
