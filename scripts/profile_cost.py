"""Where a profile's time and disk go: per study, its runs' simulated and wall seconds (from their summaries) and
their size on disk, longest first.

    .venv/bin/python scripts/profile_cost.py runs/report/full
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict
from pathlib import Path


def study_costs(root: Path) -> list[tuple[str, int, float, float, int]]:
    """(study, completed runs, simulated s, wall s, bytes) per study folder of ``root``, most wall time first."""
    rows: dict[str, list[float]] = defaultdict(lambda: [0, 0.0, 0.0, 0])
    for summary in root.glob("*/*/summary.json"):
        s = json.loads(summary.read_text())
        row = rows[summary.parent.parent.name]
        row[0] += s.get("status") == "completed"
        row[1] += float(s.get("sim_seconds") or 0.0)
        row[2] += float(s.get("wall_seconds") or 0.0)
        row[3] += sum(f.stat().st_size for f in summary.parent.rglob("*") if f.is_file())
    return sorted(((k, int(v[0]), v[1], v[2], int(v[3])) for k, v in rows.items()), key=lambda r: -r[3])


def main(argv: list[str]) -> int:
    root = Path(argv[0]) if argv else Path("runs/report/full")
    rows = study_costs(root)
    print(f"{'study':40s} {'runs':>4s} {'sim s':>9s} {'wall s':>8s} {'x real':>6s} {'GB':>6s}")
    for name, n, sim, wall, size in rows:
        print(f"{name:40s} {n:4d} {sim:9.0f} {wall:8.0f} {sim / max(wall, 1e-9):6.1f} {size / 1e9:6.2f}")
    sim, wall, size = (sum(r[i] for r in rows) for i in (2, 3, 4))
    print(f"{'all':40s} {sum(r[1] for r in rows):4d} {sim:9.0f} {wall:8.0f} {sim / max(wall, 1e-9):6.1f} "
          f"{size / 1e9:6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
