//! The machine profile's own G-code (`start_gcode`, `end_gcode` of the Marlin and delta5
//! profiles): its `{placeholder}`s, checked when the profile is read and filled in when a
//! program is written.
//!
//! A placeholder is a name in braces, `{nozzle_temperature}`; [`PLACEHOLDERS`] lists the
//! names, each with what it is. Any other name in braces is a profile error naming the key and
//! the placeholder, so a misspelt one never reaches the machine as text.

/// The placeholders a profile's start and end G-code may hold, with what each stands for.
pub const PLACEHOLDERS: [(&str, &str); 16] = [
    ("nozzle_temperature", "nozzle_temperature, whole degrees"),
    ("bed_temperature", "bed_temperature, whole degrees"),
    ("bed_x", "bed_size X (mm)"),
    ("bed_y", "bed_size Y (mm)"),
    ("bed_z", "bed_size Z (mm)"),
    ("x_min", "machine X of the bed's left edge"),
    ("x_max", "machine X of the bed's right edge"),
    ("y_min", "machine Y of the bed's front edge"),
    ("y_max", "machine Y of the bed's back edge"),
    ("print_feed", "print_speed in mm/min"),
    ("first_layer_feed", "first_layer_speed in mm/min"),
    ("travel_feed", "travel_speed in mm/min"),
    ("retraction_length", "retraction_length (mm)"),
    ("retraction_feed", "retraction_speed in mm/min"),
    (
        "first_layer_z",
        "machine Z of the first layer's beads (the Marlin post's; 0.3 mm for delta5)",
    ),
    (
        "purge_e",
        "filament (mm) of a 100 mm purge line, bead_width wide and first_layer_z thick (Eq. 1)",
    ),
];

/// The purge line's thickness (mm) where the post does not give the first layer's: the
/// delta5 post, and [`crate::MachineProfile::start_gcode_text`].
pub const PURGE_THICKNESS: f64 = 0.3;

/// The Marlin profile's start G-code when a profile leaves `start_gcode` out (the built-in
/// `profiles/marlin.toml` writes the same).
pub const MARLIN_START: &str = "M140 S{bed_temperature} ; bed
M104 S{nozzle_temperature} ; nozzle
G28 ; home all axes
; G29 ; bed levelling: uncomment on a printer with a probe
M190 S{bed_temperature} ; wait for the bed
M109 S{nozzle_temperature} ; wait for the nozzle
G92 E0
G0 X{x_min} Y{y_min} Z{first_layer_z} F{travel_feed} ; purge line along the bed's front edge
G1 X100 E{purge_e} F{first_layer_feed}
G0 Z2 F{travel_feed}
";

/// The Marlin profile's end G-code when a profile leaves `end_gcode` out. The post has
/// retracted and lifted the nozzle before it.
pub const MARLIN_END: &str = "M107 ; fan off
M104 S0 ; nozzle off
M140 S0 ; bed off
G28 X0 Y0 ; home X and Y
M84 ; motors off
";

/// The delta5 profile's start G-code when a profile leaves `start_gcode` out.
pub const DELTA5_START: &str = "M140 S{bed_temperature} ; bed
M104 S{nozzle_temperature} ; nozzle
G28 ; home all axes, B and C included
M190 S{bed_temperature} ; wait for the bed
M109 S{nozzle_temperature} ; wait for the nozzle
G92 E0
G0 X-50 Y-80 Z0.3 F{travel_feed} ; purge line on the table, inside its disc
G1 X50 E{purge_e} F{first_layer_feed}
G0 Z2 F{travel_feed}
";

/// The delta5 profile's end G-code when a profile leaves `end_gcode` out. The post has
/// retracted, lifted the nozzle to the safe height and levelled the bed before it.
pub const DELTA5_END: &str = "M107 ; fan off
M104 S0 ; nozzle off
M140 S0 ; bed off
G28 ; home
M84 ; motors off
";

/// The first `{name}` of `text` that is not a placeholder, or an unclosed brace.
pub(crate) fn unknown_placeholder(text: &str) -> Option<String> {
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        let after = &rest[open + 1..];
        let Some(close) = after.find('}') else {
            return Some(format!("`{{` without `}}` in `{}`", line_of(rest, open)));
        };
        let name = &after[..close];
        if !PLACEHOLDERS.iter().any(|(known, _)| *known == name) {
            return Some(format!(
                "unknown placeholder `{{{name}}}` (known: {})",
                PLACEHOLDERS
                    .iter()
                    .map(|(k, _)| *k)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        rest = &after[close + 1..];
    }
    None
}

/// The line of `text` holding byte `at`.
fn line_of(text: &str, at: usize) -> &str {
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let end = text[at..].find('\n').map_or(text.len(), |i| at + i);
    text[start..end].trim()
}

/// `text` with every `{name}` replaced by its value in `values`; a name without a value is
/// left as it is (the profile check refuses those first).
pub(crate) fn expand(text: &str, values: &[(&str, String)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find('}').and_then(|close| {
            let name = &after[..close];
            values
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| (close, v))
        }) {
            Some((close, v)) => {
                out.push_str(v);
                rest = &after[close + 1..];
            }
            None => {
                out.push('{');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placeholders_are_checked_and_filled() {
        for text in [MARLIN_START, MARLIN_END, DELTA5_START, DELTA5_END] {
            assert_eq!(unknown_placeholder(text), None);
        }
        let e = unknown_placeholder("M104 S{nozzle_temp}").unwrap();
        assert!(
            e.contains("{nozzle_temp}") && e.contains("nozzle_temperature"),
            "{e}"
        );
        assert!(unknown_placeholder("M104 S{nozzle_temperature").is_some());
        let v = [("bed_x", "220".to_string())];
        assert_eq!(expand("G0 X{bed_x} {bed_x}", &v), "G0 X220 220");
        assert_eq!(expand("{other}", &v), "{other}");
    }
}
