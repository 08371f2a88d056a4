#!/bin/sh
# Our estimated printing time against PrusaSlicer's for the same planar part: plans PART
# (default fixtures/plate_boss_boss.step) for the built-in Marlin profile, meshes it
# (`features mesh --tolerance 0.01`) and slices the STL with `prusa-slicer` ($PRUSA_SLICER)
# at the same layers (0.2 mm), beads (0.45 mm apart, the same section: see w below), 2 perimeters, 100 % rectilinear fill, speeds,
# retraction and motion limits as profiles/marlin.toml (40 mm/s printing, 20 on the first
# layer, 120 travel; 1000 / 1500 mm/s^2, jerk 10 mm/s, 200 mm/s caps; cooling slow-downs
# off; support where overhangs pass 50 degrees from vertical, as ours: 0.2 mm contact gap,
# 0.5 mm beside the part, lines 2.25 mm apart with 2 interface layers 0.64 mm apart, on both;
# no skirt on either), then prints each program's estimate and the filament of the part and of its support
# (scripts/filament_by_type.awk: by ;TYPE:, the skirt and the start G-code's purge line left out).
# KEEP=DIR keeps both programs there. Needs a release build of
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
set -- --set "infill_density=$density" --set "infill_pattern=$pattern" --set skirt_loops=0
[ -n "${SLICING:-}" ] && set -- "$@" --set "slicing=$SLICING"
"$features" plan "$part" --machine marlin "$@" -o "$scratch/ours" >/dev/null
percent=$(awk -v d="$density" 'BEGIN { printf "%g%%", 100 * d }')
"$features" mesh "$part" --tolerance 0.01 -o "$scratch/part.stl" >/dev/null
# The same bead: ours is 0.45 mm wide, its lines 0.45 mm apart, its section 0.45 x 0.2 mm.
# PrusaSlicer's extrusion width is the outer width of a section with rounded sides, its lines
# (width - h (1 - pi/4)) apart, so 0.45 would lay its lines 0.407 mm apart and 11 % more of
# them for the same filament. Given 0.45 + h (1 - pi/4) = 0.493 mm it lays ours: the same
# spacing and section. PRUSA_WIDTH overrides it.
w=${PRUSA_WIDTH:-$(awk 'BEGIN { printf "%.3f", 0.45 + 0.2 * (1 - atan2(1, 1)) }')}
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
    --support-material --support-material-auto --support-material-threshold 40 \
    --support-material-contact-distance 0.2 --support-material-xy-spacing 0.5 \
    --support-material-spacing 1.8 --support-material-interface-layers 2 \
    --support-material-interface-spacing 0.19 --no-support-material-with-sheath \
    --no-dont-support-bridges \
    --no-cooling --temperature 210 --bed-temperature 60 \
    -o "$scratch/prusa.gcode" "$scratch/part.stl" >/dev/null
for who in ours prusa; do
    case $who in
        ours) g="$scratch/ours/program.gcode" ;;
        prusa) g="$scratch/prusa.gcode" ;;
    esac
    t=$(grep -m1 '^; estimated printing time (normal mode)' "$g" | sed 's/.*= //')
    f=$(awk -f scripts/filament_by_type.awk "$g" | tail -1 | sed 's/^ *//')
    echo "$who: $t, filament: $f"
    [ -n "${KEEP:-}" ] && mkdir -p "$KEEP" && cp "$g" "$KEEP/$who.gcode"
done
