#!/bin/sh
# The ENTITY names of long-form EXPRESS schemas (ISO 10303-11 files, e.g. a protocol's
# mim_lf.exp), upper-cased and sorted, and which of them the reader's list lacks
# (crates/brep/src/step/read/entity_names.txt): how that list was made and is checked.
#
#   scripts/schema_names.sh SCHEMA.exp...          names missing from the list (none: exit 0)
#   NAMES_ONLY=1 scripts/schema_names.sh SCHEMA.exp  every name, one a line
set -eu
cd "$(dirname "$0")/.."
list=crates/brep/src/step/read/entity_names.txt
names=$(mktemp)
trap 'rm -f "$names"' EXIT
for f in "$@"; do
    # Comments (* ... *) (possibly over several lines) and -- to the line's end left out.
    perl -0777 -pe 's/\(\*.*?\*\)//gs; s/--[^\n]*//g' "$f" |
        grep -ioE '^[[:space:]]*ENTITY[[:space:]]+[A-Za-z0-9_]+' |
        awk '{ print toupper($2) }'
done | sort -u >"$names"
if [ -n "${NAMES_ONLY:-}" ]; then
    cat "$names"
    exit 0
fi
missing=$(grep -v '^#' "$list" | sort -u | comm -13 - "$names")
count=$(printf '%s' "$missing" | grep -c . || true)
echo "$(wc -l <"$names") entities in $*; $count missing from $list"
[ -z "$missing" ] || { printf '%s\n' "$missing"; exit 1; }
