#!/usr/bin/env bash
# cerebx's LWPR beside the reference C library (Klanke & Vijayakumar), built from its public source, on the
# same sample streams (the two tasks of `cerebx bench --lwpr`). Not part of `make test`: it needs a C compiler
# and the library's source (cloned from GitHub unless LWPR_SRC names a checkout).
#   scripts/lwpr_reference/run.sh            # prints, per task, the C library's line and cerebx's line
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
"$python" "$here/streams.py" "$work" > "$work/cerebx.jsonl"
for task in cross_2d sine_1d; do
  echo "reference $task $("$work/drive" "$work/$task.bin")"
  echo "cerebx    $task $(grep "\"$task\"" "$work/cerebx.jsonl")"
done
