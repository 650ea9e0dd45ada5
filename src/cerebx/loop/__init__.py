"""The closed loop: clock, phases, delay channels, plant-side torque filter and supervisor."""
