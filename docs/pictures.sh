#!/usr/bin/env bash
# Makes the pictures under docs/ with `subd render` (run from the repository root, with
# `subd` on PATH or SUBD set to the binary; OUT=DIR writes them elsewhere).
set -euo pipefail
subd=${SUBD:-subd}
out=${OUT:-docs}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
torus=examples/meshes/torus_creased.obj

# The creased torus: Catmull-Clark limit surface and its control cage.
"$subd" render "$torus" "$out"/torus_creased.png --limit --scheme catmull-clark --levels 4 \
    --cage --size 480x360 --view 20,55

# PIA: the fitted control mesh's limit surface passes through the input's vertices (dots).
"$subd" pia --scheme catmull-clark "$torus" "$tmp/fitted.obj"
"$subd" render "$tmp/fitted.obj" "$out"/pia_targets.png --limit --scheme catmull-clark \
    --levels 4 --points "$torus" --size 480x360 --view 20,55

# Adaptive Loop refinement of the torus cut into triangles (creases kept), where the
# dihedral angle passes 30°; faces coloured by their level.
awk '/^f /{print "f", $2, $3, $4; print "f", $2, $4, $5; next} {print}' "$torus" >"$tmp/tris.obj"
"$subd" adaptive --scheme loop --dihedral 30 --levels 4 "$tmp/tris.obj" "$tmp/adaptive.ply"
"$subd" render "$tmp/adaptive.ply" "$out"/adaptive_levels.png --wireframe --size 480x360 \
    --view 20,55

# The creased torus's patch table (isolation 3): regular B-spline patches coloured by depth,
# Gregory end caps red, each patch drawn on its own grid with its edges.
"$subd" render "$torus" "$out"/patches.png --patches --isolation 3 --wireframe --size 480x360 \
    --view 20,55
