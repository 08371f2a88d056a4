# Filament (mm) a Marlin program extrudes under each ";TYPE:" (relative M83 or absolute M82
# extrusion, G92 resets honoured; moves of the filament alone, retractions and their restores,
# left out: a program's last retraction is never restored), then the part's
# (every type but Skirt/Brim and support) and the support's.
#   awk -f scripts/filament_by_type.awk program.gcode
BEGIN { rel = 0; e = 0; type = "(none)" }
/^M83/ { rel = 1 }
/^M82/ { rel = 0 }
/^;TYPE:/ { type = substr($0, 7) }
/^G92/ { for (i = 2; i <= NF; i++) if ($i ~ /^E/) e = substr($i, 2) + 0 }
/^G[0-3][ ;]/ || /^G[0-3]$/ {
    moves = 0
    for (i = 2; i <= NF; i++) {
        if ($i ~ /^;/) break
        if ($i ~ /^[XY]/) moves = 1
    }
    for (i = 2; i <= NF; i++) {
        if ($i ~ /^;/) break
        if ($i ~ /^E/) {
            v = substr($i, 2) + 0
            d = rel ? v : v - e
            if (!rel) e = v
            if (moves) by[type] += d
        }
    }
}
END {
    for (t in by) { printf "  %-32s %10.2f\n", t, by[t] }
    for (t in by) {
        if (t ~ /Support/) sup += by[t]
        else if (t != "Skirt/Brim" && t != "(none)" && t != "Custom") part += by[t]
    }
    printf "  part %.2f mm, support %.2f mm\n", part, sup
}
