#!/bin/sh
# Our estimated printing time against PrusaSlicer's for the same planar part: plans PART
# (default fixtures/plate_boss_boss.step) for the built-in Marlin profile, meshes it
# (`features mesh --tolerance 0.01`) and slices the STL with `prusa-slicer` ($PRUSA_SLICER)
# at the same layers (0.2 mm), beads (0.45 mm), 2 perimeters, 100 % rectilinear fill, speeds,
# retraction and motion limits as profiles/marlin.toml (40 mm/s printing, 20 on the first
# layer, 120 travel; 1000 / 1500 mm/s^2, jerk 10 mm/s, 200 mm/s caps; cooling slow-downs
# off), then prints each program's estimate and filament. Needs a release build of
# `features` ($FEATURES, else target/release/features).
#
# Sparse infill (issue 33): DENSITY (0-1, default 1: solid) and PATTERN (rectilinear, grid,
# triangles or gyroid; default rectilinear) set our infill_density / infill_pattern and
# PrusaSlicer's --fill-density / --fill-pattern alike, with 4 top and 3 bottom solid layers on
# both; SLICING (features, planar; default: the process default) is passed to ours.
#
#   [DENSITY=0.2 PATTERN=gyroid SLICING=planar] scripts/prusa_estimate.sh [PART.step]
set -eu
cd "$(dirname "$0")/.."
part=${1:-fixtures/plate_boss_boss.step}
features=${FEATURES:-target/release/features}
prusa=${PRUSA_SLICER:-prusa-slicer}
[ -x "$features" ] || cargo build --release -p features-cli
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
density=${DENSITY:-1}
pattern=${PATTERN:-rectilinear}
set -- --set "infill_density=$density" --set "infill_pattern=$pattern"
[ -n "${SLICING:-}" ] && set -- "$@" --set "slicing=$SLICING"
"$features" plan "$part" --machine marlin "$@" -o "$scratch/ours" >/dev/null
percent=$(awk -v d="$density" 'BEGIN { printf "%g%%", 100 * d }')
"$features" mesh "$part" --tolerance 0.01 -o "$scratch/part.stl" >/dev/null
w=0.45
"$prusa" --export-gcode --loglevel 1 --gcode-flavor marlin2 \
    --layer-height 0.2 --first-layer-height 0.2 --fill-density "$percent" --fill-pattern "$pattern" \
    --top-solid-layers 4 --bottom-solid-layers 3 \
    --perimeters 2 --perimeter-generator classic --extrusion-width $w \
    --first-layer-extrusion-width $w --perimeter-extrusion-width $w \
    --external-perimeter-extrusion-width $w --infill-extrusion-width $w \
    --solid-infill-extrusion-width $w --top-infill-extrusion-width $w \
    --nozzle-diameter 0.4 --filament-diameter 1.75 --skirts 0 --brim-width 0 --center 110,110 \
    --perimeter-speed 40 --external-perimeter-speed 40 --small-perimeter-speed 40 \
    --infill-speed 40 --solid-infill-speed 40 --top-solid-infill-speed 40 --gap-fill-speed 40 \
    --bridge-speed 40 --first-layer-speed 20 --travel-speed 120 \
    --retract-length 0.8 --retract-speed 35 --deretract-speed 35 --retract-lift 0.2 \
    --machine-limits-usage time_estimate_only \
    --machine-max-acceleration-extruding 1000 --machine-max-acceleration-retracting 1000 \
    --machine-max-acceleration-travel 1500 --machine-max-acceleration-x 1500 \
    --machine-max-acceleration-y 1500 --machine-max-jerk-x 10 --machine-max-jerk-y 10 \
    --machine-max-feedrate-x 200 --machine-max-feedrate-y 200 \
    --no-cooling --temperature 210 --bed-temperature 60 \
    -o "$scratch/prusa.gcode" "$scratch/part.stl" >/dev/null
for who in ours prusa; do
    case $who in
        ours) g="$scratch/ours/program.gcode" ;;
        prusa) g="$scratch/prusa.gcode" ;;
    esac
    t=$(grep -m1 '^; estimated printing time (normal mode)' "$g" | sed 's/.*= //')
    f=$(grep -m1 '^; filament used \[mm\]' "$g" | sed 's/.*= //')
    echo "$who: $t, filament $f mm"
done
