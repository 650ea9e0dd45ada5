#!/usr/bin/env bash
# cerebx's LWPR beside the reference C library (Klanke & Vijayakumar), built from its public source, on the
# same sample streams (the two tasks of `cerebx bench --lwpr`). Not part of `make test`: it needs a C compiler
# and the library's source (cloned from GitHub unless LWPR_SRC names a checkout).
#   scripts/lwpr_reference/run.sh            # per round and task the C library's line (a C loop), cerebx's and
#                                            # the library's through Python (binding.c, the loop cerebx is timed
#                                            # in), then the median ratios (ROUNDS=5 rounds)
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
# the library as a Python module too (binding.c), for the same one-at-a-time loop cerebx is timed in
pyinc="$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
npinc="$("$python" -c 'import numpy; print(numpy.get_include())')"
ext="$("$python" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')"
gcc -O2 -shared -fPIC -I"$work" -I"$src/include" -I"$pyinc" -I"$npinc" -o "$work/lwpr_c$ext" "$here/binding.c" \
  "$src/src/lwpr.c" "$src/src/lwpr_aux.c" "$src/src/lwpr_math.c" "$src/src/lwpr_mem.c" -lm -lpthread
# ROUNDS rounds (default 5), each cerebx's line then the library's per task, back to back: this host's speed
# drifts within seconds, so the ratio is taken per round and its median printed last
rounds="${ROUNDS:-5}"
for r in $(seq "$rounds"); do
  "$python" "$here/streams.py" "$work" > "$work/cerebx.jsonl"
  "$python" "$here/through_python.py" "$work" > "$work/binding.jsonl"
  for task in cross_2d sine_1d; do
    echo "reference $task $("$work/drive" "$work/$task.bin")"
    echo "cerebx    $task $(grep "\"$task\"" "$work/cerebx.jsonl")"
    echo "binding   $task $(grep "\"$task\"" "$work/binding.jsonl")"
  done
done | tee "$work/rounds.txt"
"$python" - "$work/rounds.txt" <<'PY'
import json, statistics, sys
rows = [line.split(None, 2) for line in open(sys.argv[1])]
for task in ("cross_2d", "sine_1d"):
    ref = [json.loads(j)["updates_per_s_wall"] for who, t, j in rows if who == "reference" and t == task]
    ours = [json.loads(j) for who, t, j in rows if who == "cerebx" and t == task]
    lib = [json.loads(j) for who, t, j in rows if who == "binding" and t == task]
    one = [o["update_per_s"] / r for o, r in zip(ours, ref)]
    many = [o["update_many_per_s"] / r for o, r in zip(ours, ref)]
    py = [b["cerebx_update_per_s"] / b["update_per_s"] for b in lib]
    print(f"ratio {task}: one at a time {statistics.median(one):.2f} (rounds {min(one):.2f}-{max(one):.2f}), "
          f"whole stream {statistics.median(many):.2f} (rounds {min(many):.2f}-{max(many):.2f}); "
          f"one at a time from Python, in turns with the library through binding.c {statistics.median(py):.2f} "
          f"(rounds {min(py):.2f}-{max(py):.2f})")
PY
