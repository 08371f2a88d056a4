#!/bin/sh
# PrusaSlicer's G-code viewer on a Marlin program, screenshot to a PNG (issue 33: the viewer
# reads our programs fully). Starts Xvfb on display :77 (unless DISPLAY_NUMBER is set),
# opens PROGRAM in `prusa-gcodeviewer` (Debian's prusa-slicer), maximises its window, moves the
# top of its layer slider DOWN layers down (optional: to show a middle layer's infill) and
# saves the screen as OUT.png. Needs Xvfb, xdotool, xwd and Python 3 with Pillow (the XWD
# dump, 24 bits a pixel, converted to PNG).
#
#   scripts/gcodeviewer_screenshot.sh PROGRAM.gcode OUT.png [DOWN]
set -eu
program=$1
out=$2
down=${3:-}
display=":${DISPLAY_NUMBER:-77}"
Xvfb "$display" -screen 0 1600x1000x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
scratch=$(mktemp -d)
trap 'kill $xvfb 2>/dev/null; rm -rf "$scratch"' EXIT
export DISPLAY="$display" LANG=en_US.UTF-8 LC_ALL=en_US.UTF-8
sleep 2
prusa-gcodeviewer "$program" >"$scratch/viewer.log" 2>&1 &
viewer=$!
sleep 25
win=$(xdotool search --onlyvisible --name "G-code" | head -1)
xdotool windowmove "$win" 0 0 windowsize "$win" 1600 1000
sleep 5
xdotool mousemove 800 600 click 1 key z
sleep 3
if [ -n "$down" ]; then
    # The vertical slider's upper thumb, then the arrow key once a layer.
    xdotool mousemove 1538 40 click 1
    sleep 1
    xdotool key --repeat "$down" --delay 80 Down
    sleep 3
fi
xwd -root -silent >"$scratch/screen.xwd"
kill $viewer
python3 - "$scratch/screen.xwd" "$out" <<'PY'
import struct, sys
from PIL import Image
d = open(sys.argv[1], "rb").read()
h = struct.unpack(">25I", d[:100])
w, hgt, bpp, bpl, ncolors = h[4], h[5], h[11], h[12], h[19]
off = h[0] + 12 * ncolors
mode = {24: "BGR", 32: "BGRX"}[bpp]
Image.frombytes("RGB", (w, hgt), d[off:off + bpl * hgt], "raw", mode, bpl).save(sys.argv[2])
PY
echo "$out"
