#!/bin/sh
# Makes docs/preview.png, the README's picture of a plan's preview.html: plans a bundled part
# (default fixtures/sphere_boss.step on the 5-axis delta5 printer) with a release build of
# `features` ($FEATURES, else target/release/features) into a scratch folder and takes a
# screenshot of its preview.html with headless Chromium ($CHROMIUM, else chromium), with the
# flags tests/preview.rs uses (SwiftShader's WebGL, no GPU needed).
#
#   scripts/preview_screenshot.sh [PART.step [MACHINE [OUT.png]]]
set -eu
cd "$(dirname "$0")/.."
part=${1:-fixtures/sphere_boss.step}
machine=${2:-delta5}
png=${3:-docs/preview.png}
features=${FEATURES:-target/release/features}
chromium=${CHROMIUM:-chromium}
[ -x "$features" ] || cargo build --release -p features-cli
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
"$features" plan "$part" --machine "$machine" -o "$scratch/plan"
mkdir -p "$(dirname "$png")"
"$chromium" --headless --no-sandbox --disable-dev-shm-usage --enable-unsafe-swiftshader \
    --use-angle=swiftshader --window-size=1200,800 --virtual-time-budget=15000 \
    --hide-scrollbars --screenshot="$(pwd)/$png" "file://$scratch/plan/preview.html" 2>/dev/null
echo "$png: preview of $part planned for $machine"
