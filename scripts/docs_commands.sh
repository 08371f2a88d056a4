#!/usr/bin/env bash
# Runs every concrete command the README and the reference pages (docs/plan.md, docs/profiles.md)
# give, on the bundled fixtures, with the given `features` binary, each in a scratch folder of its
# own, and prints one line per command: its exit code, the files it wrote and its last stderr or
# stdout line. Exit 1 when a command meant to succeed did not. The closing note of a change to the
# docs lists what it printed on the final commit (issue 32).
#
#   scripts/docs_commands.sh target/release/features
set -uo pipefail
bin=$(realpath "$1")
root=$(cd "$(dirname "$0")/.." && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
cp -r "$root/fixtures" "$scratch/fixtures"
failed=0
# `features` in the commands below is the binary given.
features() { "$bin" "$@"; }
# run EXPECTED-EXIT COMMAND...: COMMAND with `features` for the binary, in the scratch folder.
run() {
  local want=$1
  shift
  local log="$scratch/last.log"
  (cd "$scratch" && eval "$*") >"$log" 2>&1
  local rc=$?
  local last
  last=$(grep -v '^\s*$' "$log" | tail -1 | cut -c1-140)
  local mark=ok
  if [ "$rc" != "$want" ]; then mark=FAILED; failed=1; fi
  printf '%-6s exit %s  %s\n         %s\n' "$mark" "$rc" "$*" "$last"
}
# README: set up and run (the first command through the built binary), quick start, commands.
run 0 features plan fixtures/sphere_boss.step --machine delta5 -o out
run 0 features plan fixtures/sphere_boss.step --machine delta5 -o out   # again: replaces it
run 0 features plan fixtures/plate_boss_boss.step
run 0 features plan fixtures/sphere_boss.step --machine delta5 -o sphere.gcode
run 0 features plan fixtures/box.step --machine kuka -o cell/
run 0 features inspect fixtures/plate_boss_boss.step
run 0 features inspect fixtures/plate_boss_boss.step --json
run 0 features mesh fixtures/plate_boss_boss.step -o part.stl
run 0 features mesh fixtures/plate_boss_boss.step -o part.obj --tolerance 0.02
run 0 features extract fixtures/plate_boss_boss.step
run 0 features extract fixtures/plate_boss_boss.step --json
run 0 features extract fixtures/plate_boss_boss.step --export parts
run 0 features preview fixtures/plate_boss_boss.step -o preview.html
run 0 features profiles
run 0 features profiles show marlin
# docs/profiles.md: a profile shown, then given back.
run 0 features profiles show delta5 \> my.toml
run 0 features plan fixtures/plate_boss_boss.step --machine-profile my.toml -o mine
run 0 features profiles show process \> my_process.toml
run 0 features plan fixtures/plate_boss_boss.step --process my_process.toml -o mine
# docs/plan.md: options named there.
run 0 features plan fixtures/plate_boss_boss.step --set uniform_layer_height=0.1 -o set
run 0 features plan fixtures/plate_boss_boss.step --machine marlin --orient auto -o auto
run 0 features plan fixtures/plate_boss_boss.step --machine delta5 --strict -o strict
# A plan the machine cannot print (the plate in the air on its boss, without support material):
# refused with exit 2, its plan.json and preview written, no program.
run 2 features plan fixtures/plate_boss_boss.step --machine marlin --base-face 521 --set support_material=off -o refused
run 0 test -f refused/plan.json -a -f refused/preview.html -a ! -f refused/program.gcode
run 2 features plan fixtures/box.step -o -
exit $failed
