#!/bin/bash
# `refine --limit` on √3 and the butterflies (BENCHMARKS.md, "refine --limit on √3 and the
# butterflies"): an open scan (PyMeshLab's 56k-triangle bunny, the 10% of faces with the
# least x dropped: 50,554 triangles, two boundary loops) refined with and without --limit,
# three alternating runs of each binary given; the report's positions phase, the wall
# time and the peak RSS of each run, then the plain refinement's.
#   usage: xtask/scripts/split_limit_bench.sh NEW_SUBD [OLD_SUBD] [DIR]
# Needs `cargo xtask test` to have made target/python-env (numpy, pymeshlab).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
NEW=$(realpath "$1"); OLD=${2:+$(realpath "$2")}; DIR=${3:-/tmp/subd-split-limit}
PY=$ROOT/target/python-env/bin/python
mkdir -p "$DIR" && cd "$DIR"
"$PY" - <<'PY'
import pathlib, numpy as np, pymeshlab
src = pathlib.Path(pymeshlab.__file__).parent / "tests/sample_meshes/bunny.obj"
v, f = [], []
for line in open(src):
    if line.startswith("v "):
        v.append([float(x) for x in line.split()[1:4]])
    elif line.startswith("f "):
        f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
v, f = np.array(v), np.array(f)
centre = v[f].mean(1)
keep = f[centre[:, 0] > np.percentile(centre[:, 0], 10)]
used = np.unique(keep)
index = -np.ones(len(v), int)
index[used] = np.arange(len(used))
with open("open_bunny.obj", "w") as o:
    o.writelines("v %.17g %.17g %.17g\n" % tuple(p) for p in v[used])
    o.writelines("f %d %d %d\n" % tuple(t + 1) for t in index[keep])
PY
run() { # scheme levels binary [--limit]
  /usr/bin/time -f "%e s %M KB" "$3" refine --scheme "$1" --levels "$2" ${4:-} open_bunny.obj out.ply --json \
    > report.json 2> time.txt
  echo "$1 L$2 $3 ${4:-plain}: positions $(grep -o '"positions":[0-9.]*' report.json | cut -d: -f2) s, $(tail -1 time.txt)"
}
for case in "sqrt3 1" "sqrt3 2" "butterfly 1" "modified-butterfly 1" "butterfly 2"; do
  set -- $case
  for _ in 1 2 3; do
    for bin in $OLD $NEW; do run "$1" "$2" "$bin" --limit; done
  done
  run "$1" "$2" "$NEW"
done
