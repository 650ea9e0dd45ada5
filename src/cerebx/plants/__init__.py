"""Plants: MuJoCo models driven by joint torques at the 2 ms control step."""
