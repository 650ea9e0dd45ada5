"""Controllers: map (desired state, delayed sensor message) to stamped torque commands."""
