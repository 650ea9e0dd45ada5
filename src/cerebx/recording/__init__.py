"""One run.mcap and one summary.json per run."""
