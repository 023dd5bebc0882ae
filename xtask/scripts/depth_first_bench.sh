#!/bin/bash
# Depth-first refinement at a billion faces (BENCHMARKS.md, "Depth-first refinement"):
# Catmull-Clark level 6 of a 250,000-quad torus and Loop level 7 of a 124,000-triangle open
# grid written as binary PLY, each against `dd` writing the same number of bytes to the same
# disk in the same run, both timed to the end of `sync`. Needs ~51 GB free in DIR and
# takes ~15 minutes on 2 cores.
#   usage: xtask/scripts/depth_first_bench.sh [DIR]   (after `cargo build --release`)
set -euo pipefail
SUBD=$(cd "$(dirname "$0")/../.." && pwd)/target/release/subd
DIR=${1:-/tmp/subd-depth-first}
mkdir -p "$DIR" && cd "$DIR"
python3 - <<'PY'
import math, struct
def write(path, pts, faces):
    with open(path, 'wb') as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(pts)}\n"
                 "property double x\nproperty double y\nproperty double z\n"
                 f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        f.write(b''.join(struct.pack('<3d', *p) for p in pts))
        f.write(b''.join(struct.pack('<B%di' % len(t), len(t), *t) for t in faces))
def torus(m, n, path):
    pts = []
    for j in range(n):
        for i in range(m):
            u, v = 2 * math.pi * i / m, 2 * math.pi * j / n
            pts.append(((3 + math.cos(v)) * math.cos(u), (3 + math.cos(v)) * math.sin(u),
                        math.sin(v) + 0.05 * math.sin(7 * u)))
    faces = [(j * m + i, j * m + (i + 1) % m, ((j + 1) % n) * m + (i + 1) % m, ((j + 1) % n) * m + i)
             for j in range(n) for i in range(m)]
    write(path, pts, faces)
def open_triangles(m, n, path):
    pts = [(i / m * 4, j / n * 4, 0.3 * math.sin(12 * i / m) * math.cos(8 * j / n))
           for j in range(n + 1) for i in range(m + 1)]
    faces = []
    for j in range(n):
        for i in range(m):
            a = j * (m + 1) + i
            faces += [(a, a + 1, a + m + 2), (a, a + m + 2, a + m + 1)]
    write(path, pts, faces)
torus(500, 500, 'quads250k.ply')
open_triangles(250, 248, 'open124k.ply')
PY
run() { # name, subd arguments
  local name=$1; shift
  rm -f out.ply; sync
  local t0; t0=$(date +%s.%N)
  /usr/bin/time -f "%e s %M KB" -o "$name.time" "$SUBD" refine "$@" out.ply --json > "$name.json"
  sync
  local t1; t1=$(date +%s.%N)
  local bytes; bytes=$(stat -c %s out.ply)
  echo "$name subd: $(echo "$t1 - $t0" | bc) s with sync; $(cat "$name.time"); $bytes bytes"
  rm -f out.ply; sync
  t0=$(date +%s.%N)
  dd if=/dev/zero of=dd.bin bs=8M count=$((bytes / 8388608)) 2>/dev/null
  sync
  t1=$(date +%s.%N)
  echo "$name dd: $(echo "$t1 - $t0" | bc) s with sync"
  rm -f dd.bin; sync
}
run cc6 quads250k.ply --levels 6 --scheme catmull-clark
run loop7 open124k.ply --levels 7 --scheme loop
