#!/usr/bin/env bash
# cerebx's LWPR beside the reference C library (Klanke & Vijayakumar), built from its public source, on the
# same sample streams (the two tasks of `cerebx bench --lwpr`). Not part of `make test`: it needs a C compiler
# and the library's source (cloned from GitHub unless LWPR_SRC names a checkout).
#   scripts/lwpr_reference/run.sh            # per round and task the C library's line and cerebx's, then the
#                                            # median ratios (ROUNDS=5 rounds)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
src="${LWPR_SRC:-}"
if [ -z "$src" ]; then
  git clone --quiet --depth 1 https://github.com/ipab-slmc/lwpr "$work/lwpr"
  src="$work/lwpr"
fi
# the library's configure step only writes this header; single thread, no XML support
printf '#define HAVE_LIBEXPAT 0\n#define NUM_THREADS 1\n#define LIBRARY_API\n' > "$work/lwpr_config.h"
gcc -O2 -I"$work" -I"$src/include" -o "$work/drive" "$here/drive.c" \
  "$src/src/lwpr.c" "$src/src/lwpr_aux.c" "$src/src/lwpr_math.c" "$src/src/lwpr_mem.c" -lm -lpthread
python="${PYTHON:-$root/.venv/bin/python}"
# ROUNDS rounds (default 5), each cerebx's line then the library's per task, back to back: this host's speed
# drifts within seconds, so the ratio is taken per round and its median printed last
rounds="${ROUNDS:-5}"
for r in $(seq "$rounds"); do
  "$python" "$here/streams.py" "$work" > "$work/cerebx.jsonl"
  for task in cross_2d sine_1d; do
    echo "reference $task $("$work/drive" "$work/$task.bin")"
    echo "cerebx    $task $(grep "\"$task\"" "$work/cerebx.jsonl")"
  done
done | tee "$work/rounds.txt"
"$python" - "$work/rounds.txt" <<'PY'
import json, statistics, sys
rows = [line.split(None, 2) for line in open(sys.argv[1])]
for task in ("cross_2d", "sine_1d"):
    ref = [json.loads(j)["updates_per_s_wall"] for who, t, j in rows if who == "reference" and t == task]
    ours = [json.loads(j) for who, t, j in rows if who == "cerebx" and t == task]
    one = [o["update_per_s"] / r for o, r in zip(ours, ref)]
    many = [o["update_many_per_s"] / r for o, r in zip(ours, ref)]
    print(f"ratio {task}: one at a time {statistics.median(one):.2f} (rounds {min(one):.2f}-{max(one):.2f}), "
          f"whole stream {statistics.median(many):.2f} (rounds {min(many):.2f}-{max(many):.2f})")
PY
