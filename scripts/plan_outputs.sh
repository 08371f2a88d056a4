#!/usr/bin/env bash
# Plans every fixture (marlin, delta5, kuka) and every part of ../shared/corpus (marlin) with the
# given `features` binary and writes each run's outputs into OUT/<part>.<machine>/ with its exit
# code and stderr. Run it with the binaries of two commits and `diff -r` the two folders: the
# restructurings that must not change behaviour are checked this way (issue 15).
#
#   scripts/plan_outputs.sh target/release/features /tmp/before
set -uo pipefail
bin=$(realpath "$1"); out=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
run() { # part machine
  local part=$1 machine=$2 name
  name=$(basename "$part" .step).$machine
  local dir="$out/$name"
  rm -rf "$dir"; mkdir -p "$dir"
  # Relative paths so both runs print the same source; 300 s bounds a runaway part.
  # PLAN_ARGS: extra arguments for the binary (a newer one: --allow-collisions).
  (cd "$root" && timeout 300 "$bin" plan "$part" --machine "$machine" --keep-going --allow-unreachable ${PLAN_ARGS:-} -o "$dir" \
      >"$dir/stdout" 2>"$dir/stderr"; echo $? >"$dir/rc")
  # The stdout line names the output folder, which differs between runs.
  sed -i "s#$dir#OUT#" "$dir/stdout"
}
for f in "$root"/fixtures/*.step; do
  for m in marlin delta5 kuka; do run "fixtures/$(basename "$f")" "$m"; done
done
for f in "$root"/../shared/corpus/*.step; do
  run "../shared/corpus/$(basename "$f")" marlin
done
echo "plans written to $out: $(ls "$out" | wc -l) runs"
